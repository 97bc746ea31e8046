//! Rays walked through the [`Bvh`] sixteen at a time: neighbouring texels' rays meet nearly the
//! same nodes (sixteen of a tile visit nine times fewer distinct nodes than their visits summed
//! on a 600k HIGH at 1024²), so a packet visits each node once for all its rays that meet the
//! box, and tests each child box against eight rays at once, one ray a lane of an eight-wide
//! vector (two vectors for sixteen).
//!
//! Each ray keeps its own part of the line and its own best hit, and is dropped from a subtree
//! only by its own box test or its own best hit, with the box test [`raycast::nearest`] makes
//! (the same operations in the same order, a ray a lane instead of a child a lane); which hit
//! wins never depends on the order the nodes are visited in (`Hit::better_than`), so every ray
//! gets the hit `nearest` gives it, bit for bit (`tests/nearest.rs`).
//!
//! Eight-wide vectors need AVX, chosen at run time; without it, and for a packet with a ray
//! that has no part of some axis, each ray walks alone with [`raycast::nearest`].

use super::bvh::Bvh;
use super::raycast::{self, Hit, Ray};

/// The most rays walked together.
pub const PACKET: usize = 16;

/// Eight-wide vectors a packet's rays fill.
const HALVES: usize = PACKET / 8;

/// A node or a leaf still to visit, the rays that still meet it, and how far its part of each of
/// them lies from its origin.
#[derive(Clone, Copy)]
struct Entry {
    gaps: [f32; PACKET],
    child: u32,
    /// 0 for a node, else the leaf's triangle count.
    count: u32,
    /// Bit `i` for ray `i`.
    rays: u32,
}

/// What a thread reuses packet after packet: the nodes and leaves still to visit.
#[derive(Default)]
pub struct PacketStack {
    entries: Vec<Entry>,
    single: raycast::Stack,
}

/// For each `(ray, back, front)` of `rays` (at most [`PACKET`]), what
/// [`raycast::nearest`]`(bvh, ray, back, front, ..)` gives, into `out` at the same place.
pub fn nearest_packet(bvh: &Bvh, rays: &[(Ray, f32, f32)], out: &mut [Option<Hit>], stack: &mut PacketStack) {
    assert!(rays.len() <= PACKET && out.len() == rays.len());
    #[cfg(target_arch = "x86_64")]
    if rays.len() > 1 && avx() && rays.iter().all(|r| r.0.has_every_axis()) && !bvh.is_empty() {
        // SAFETY: the CPU has AVX (`avx`).
        unsafe { wide::walk(bvh, rays, out, &mut stack.entries) };
        return;
    }
    for (o, &(ray, back, front)) in out.iter_mut().zip(rays) {
        *o = raycast::nearest(bvh, &ray, back, front, &mut stack.single);
    }
}

#[cfg(target_arch = "x86_64")]
fn avx() -> bool {
    static AVX: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *AVX.get_or_init(|| std::arch::is_x86_feature_detected!("avx"))
}

#[cfg(target_arch = "x86_64")]
mod wide {
    use super::{Entry, HALVES, PACKET};
    use crate::transfer::bvh::{Bvh, WideNode};
    use crate::transfer::raycast::{nearest_first, test_leaf, Hit, Ray, BOX_MARGIN};
    use std::arch::x86_64::*;

    /// The rays' origins and reciprocal directions by axis, a ray a lane.
    struct Rays<'a> {
        rays: &'a [(Ray, f32, f32)],
        o: [[__m256; 3]; HALVES],
        inv: [[__m256; 3]; HALVES],
        /// Each ray's part of the line still to search; `hi[i] = lo[i] = 0` past the last ray.
        lo: [f32; PACKET],
        hi: [f32; PACKET],
    }

    /// The walk of [`super::nearest_packet`]. Its rays all have a part of every axis.
    #[target_feature(enable = "avx")]
    pub(super) fn walk(bvh: &Bvh, rays: &[(Ray, f32, f32)], out: &mut [Option<Hit>], stack: &mut Vec<Entry>) {
        let lane = |h: usize, f: &dyn Fn(&Ray) -> f32| {
            let mut v = [0.0f32; 8];
            for (x, r) in v.iter_mut().zip(rays.iter().skip(8 * h)) {
                *x = f(&r.0);
            }
            // SAFETY: `v` holds eight floats.
            unsafe { _mm256_loadu_ps(v.as_ptr()) }
        };
        let o = std::array::from_fn(|h| [lane(h, &|r| r.origin.x), lane(h, &|r| r.origin.y), lane(h, &|r| r.origin.z)]);
        let inv = std::array::from_fn(|h| [lane(h, &|r| r.inv().x), lane(h, &|r| r.inv().y), lane(h, &|r| r.inv().z)]);
        let mut p = Rays { rays, o, inv, lo: [0.0; PACKET], hi: [0.0; PACKET] };
        for (i, &(_, back, front)) in rays.iter().enumerate() {
            (p.lo[i], p.hi[i]) = (-back, front);
        }
        out.iter_mut().for_each(|o| *o = None);
        stack.clear();
        let mut todo = Entry { gaps: [0.0; PACKET], child: 0, count: 0, rays: u32::MAX >> (32 - rays.len()) };
        loop {
            if todo.count > 0 {
                for k in todo.child as usize..(todo.child + todo.count) as usize {
                    let mut m = todo.rays;
                    while m != 0 {
                        let i = m.trailing_zeros() as usize;
                        m &= m - 1;
                        test_leaf(bvh, &p.rays[i].0, k, &mut p.lo[i], &mut p.hi[i], &mut out[i]);
                    }
                }
            } else if let Some(next) = node(bvh, &p, &bvh.nodes[todo.child as usize], todo.rays, stack) {
                todo = next;
                continue;
            }
            // The next node or leaf that some ray can still find a hit in as near as its best.
            loop {
                let Some(mut t) = stack.pop() else { return };
                for h in 0..HALVES {
                    // SAFETY: eight floats each from `8 * h`.
                    let (gaps, lo, hi) = unsafe {
                        (
                            _mm256_loadu_ps(t.gaps.as_ptr().add(8 * h)),
                            _mm256_loadu_ps(p.lo.as_ptr().add(8 * h)),
                            _mm256_loadu_ps(p.hi.as_ptr().add(8 * h)),
                        )
                    };
                    let reach = _mm256_max_ps(hi, neg(lo));
                    t.rays &= !((_mm256_movemask_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(gaps, reach)) as u32) << (8 * h));
                }
                if t.rays != 0 {
                    todo = t;
                    break;
                }
            }
        }
    }

    #[inline]
    #[target_feature(enable = "avx")]
    fn neg(v: __m256) -> __m256 {
        _mm256_xor_ps(v, _mm256_set1_ps(-0.0))
    }

    /// `m` with `s`'s signs, as `glam::Vec4::copysign`.
    #[inline]
    #[target_feature(enable = "avx")]
    fn copysign(m: __m256, s: __m256) -> __m256 {
        let sign = _mm256_set1_ps(-0.0);
        _mm256_or_ps(_mm256_andnot_ps(sign, m), _mm256_and_ps(s, sign))
    }

    /// Tests node `n`'s child boxes against the rays `rays` (the operations of
    /// `raycast::hit_lanes`, a ray a lane): the children some ray meets are pushed, farthest
    /// first, except the nearest, returned to be visited next (`raycast::nearest_first`). A
    /// child's distance is the least of the rays' that meet it.
    #[inline]
    #[target_feature(enable = "avx")]
    fn node(bvh: &Bvh, p: &Rays, n: &WideNode, rays: u32, stack: &mut Vec<Entry>) -> Option<Entry> {
        let m = _mm256_set1_ps(BOX_MARGIN);
        let one = _mm256_set1_ps(1.0);
        // SAFETY: eight floats each from `8 * h`.
        let parts: [_; HALVES] = std::array::from_fn(|h| unsafe {
            (_mm256_loadu_ps(p.lo.as_ptr().add(8 * h)), _mm256_loadu_ps(p.hi.as_ptr().add(8 * h)))
        });
        let mut kids = [Entry { gaps: [0.0; PACKET], child: 0, count: 0, rays: 0 }; 4];
        let mut least = [f32::INFINITY; 4];
        let mut mask = 0u32;
        for lane in 0..4 {
            if n.lanes & 1 << lane == 0 {
                continue;
            }
            let k = &mut kids[lane];
            for (h, (&(lo, hi), (o, inv))) in parts.iter().zip(p.o.iter().zip(&p.inv)).enumerate() {
                if rays >> (8 * h) & 0xff == 0 {
                    continue;
                }
                let slab = |a: usize| {
                    let t0 = _mm256_mul_ps(_mm256_sub_ps(_mm256_set1_ps(n.min[a][lane]), o[a]), inv[a]);
                    let t1 = _mm256_mul_ps(_mm256_sub_ps(_mm256_set1_ps(n.max[a][lane]), o[a]), inv[a]);
                    (_mm256_min_ps(t0, t1), _mm256_max_ps(t0, t1))
                };
                let ((ax, bx), (ay, by), (az, bz)) = (slab(0), slab(1), slab(2));
                let near = _mm256_max_ps(_mm256_max_ps(ax, ay), az);
                let far = _mm256_min_ps(_mm256_min_ps(bx, by), bz);
                let near = _mm256_max_ps(_mm256_mul_ps(near, _mm256_sub_ps(one, copysign(m, near))), lo);
                let far = _mm256_min_ps(_mm256_mul_ps(far, _mm256_add_ps(one, copysign(m, far))), hi);
                let hit = _mm256_cmp_ps::<_CMP_LE_OS>(near, far);
                let r = (_mm256_movemask_ps(hit) as u32) << (8 * h) & rays;
                if r == 0 {
                    continue;
                }
                let gaps = _mm256_max_ps(_mm256_max_ps(near, neg(far)), _mm256_setzero_ps());
                // SAFETY: eight floats from `8 * h`.
                unsafe { _mm256_storeu_ps(k.gaps.as_mut_ptr().add(8 * h), gaps) };
                k.rays |= r;
                least[lane] = least[lane].min(hmin(_mm256_blendv_ps(_mm256_set1_ps(f32::INFINITY), gaps, hit)));
            }
            if k.rays != 0 {
                (k.child, k.count) = (n.child[lane], n.count[lane] as u32);
                bvh.prefetch(k.child, k.count);
                mask |= 1 << lane;
            }
        }
        if mask == 0 {
            return None;
        }
        let (next, rest) = nearest_first(mask, &least);
        stack.extend(rest.map(|l| kids[l]));
        Some(kids[next])
    }

    /// The least of `v`'s eight lanes.
    #[inline]
    #[target_feature(enable = "avx")]
    fn hmin(v: __m256) -> f32 {
        let m = _mm_min_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps::<1>(v));
        let m = _mm_min_ps(m, _mm_movehl_ps(m, m));
        let m = _mm_min_ss(m, _mm_shuffle_ps::<1>(m, m));
        _mm_cvtss_f32(m)
    }
}
