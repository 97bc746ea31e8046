//! Rays against the [`Bvh`]: the hit nearest the ray's origin within `[-back, front]`.
//!
//! Triangles are tested with the watertight algorithm of Woop, Benthin and Wald (JCGT 2013): a
//! ray through a shared edge or vertex hits at least one of the triangles there, so grazing rays
//! and rays through mesh vertices do not slip through HIGH. Edge values that come out exactly
//! zero in f32 are recomputed in f64, as the paper advises. Degenerate triangles never hit.

use super::bvh::{Bvh, WideNode};
use glam::{BVec4A, Vec3A, Vec4};

/// A ray prepared for the watertight test (its shear is computed once).
#[derive(Debug, Clone, Copy)]
pub struct Ray {
    pub origin: Vec3A,
    pub dir: Vec3A,
    inv: Vec3A,
    k: [usize; 3],
    /// The origin's coordinates in the order `k` (x, y, then the dominant axis).
    o: [f32; 3],
    shear: [f32; 3],
    /// Whether only triangles whose front faces the ray's far end (`origin + dir`) are hit.
    front_only: bool,
}

impl Ray {
    /// `dir` must be finite and non-zero (its length is what `t` is measured in).
    pub fn new(origin: Vec3A, dir: Vec3A) -> Ray {
        let a = dir.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let shear = [dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]];
        let o = [origin[kx], origin[ky], origin[kz]];
        Ray { origin, dir, inv: dir.recip(), k: [kx, ky, kz], o, shear, front_only: false }
    }

    /// The ray, hitting only triangles whose front (the side their corners wind
    /// counter-clockwise seen from, as glTF and OBJ wind them) faces the way `dir` points from,
    /// that is, towards `origin + dir`: as if the ray came from beyond that end, whichever side
    /// of the origin the hit lies on.
    pub fn front_faces_only(self) -> Ray {
        Ray { front_only: true, ..self }
    }

    /// The reciprocal of `dir`, for the box tests.
    pub(super) fn inv(&self) -> Vec3A {
        self.inv
    }

    /// Per axis, whether the ray has no part of it: a component so small that its reciprocal
    /// overflows counts as none, since the ray then stays in the slab it starts in (or out of
    /// it) however far it goes. The box test needs a case of its own for such an axis.
    fn flat_axes(&self) -> [bool; 3] {
        [self.inv.x.is_infinite(), self.inv.y.is_infinite(), self.inv.z.is_infinite()]
    }

    /// Whether the ray has a part of every axis (nearly every ray has; see `flat_axes`).
    pub fn has_every_axis(&self) -> bool {
        !self.flat_axes().contains(&true)
    }
}

/// Where a ray met HIGH.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Signed distance along the ray (in units of its direction's length).
    pub t: f32,
    /// The triangle's index in the input.
    pub id: u32,
    /// Its index in the tree's leaf order (for [`Bvh::corners`] and [`Bvh::index`]).
    pub slot: u32,
    /// Barycentric weights of the triangle's three corners.
    pub bary: [f32; 3],
}

impl Hit {
    /// The order hits are preferred in: nearer the origin, then the lower triangle index, so
    /// duplicate triangles and ties resolve the same way on every run.
    fn better_than(&self, o: &Hit) -> bool {
        let (a, b) = (self.t.abs(), o.t.abs());
        a < b || (a == b && (self.id < o.id || (self.id == o.id && self.t > o.t)))
    }
}

/// The watertight test; hits from both sides count, unless the ray takes front faces only.
///
/// Corners are read by axis straight from `corners` (`corners[i][k]` is one load): a vector register indexed
/// by a run-time axis goes through memory, and that store and reload cost more than the test.
#[inline(always)]
pub fn intersect(ray: &Ray, corners: &[[f32; 3]; 3]) -> Option<(f32, [f32; 3])> {
    let [kx, ky, kz] = ray.k;
    let [sx, sy, sz] = ray.shear;
    let [ox, oy, oz] = ray.o;
    let sheared = |p: &[f32; 3]| {
        let z = p[kz] - oz;
        (p[kx] - ox - sx * z, p[ky] - oy - sy * z, z)
    };
    let (ax, ay, az) = sheared(&corners[0]);
    let (bx, by, bz) = sheared(&corners[1]);
    let (cx, cy, cz) = sheared(&corners[2]);
    let mut u = cx * by - cy * bx;
    let mut v = ax * cy - ay * cx;
    let mut w = bx * ay - by * ax;
    if u == 0.0 || v == 0.0 || w == 0.0 {
        let (ax, ay, bx, by, cx, cy) = (ax as f64, ay as f64, bx as f64, by as f64, cx as f64, cy as f64);
        u = (cx * by - cy * bx) as f32;
        v = (ax * cy - ay * cx) as f32;
        w = (bx * ay - by * ax) as f32;
    }
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    // The sheared frame keeps handedness (the ray's `k` swaps two axes when `dir` points down
    // its dominant one), so the sign of the edge functions' sum says which side the ray meets:
    // negative, the front of a counter-clockwise triangle facing `origin + dir`.
    if ray.front_only && det > 0.0 {
        return None;
    }
    let t = within_box(ray, corners, (u * sz * az + v * sz * bz + w * sz * cz) / det);
    let inv = 1.0 / det;
    Some((t, [u * inv, v * inv, w * inv]))
}

/// `t` moved into the part of the ray that the box of the triangle with corners `c` holds, as
/// the tree's box test computes that part ([`hit_lanes`]: the same operations, the same margin).
///
/// On a sliver seen nearly edge on, `t` from the edge functions can be off by far more than
/// the box test's margin (a thousandth, on a sliver a ten-thousandth wide): a hit would then
/// lie nearer than its own box, and a box holding an equally near triangle of lower index (a
/// duplicate) would be dropped as farther than the best hit. Inside its box, a hit is never
/// nearer than the box of any node that holds it, so the tree finds what a test of every
/// triangle finds. A hit already inside, as nearly every one is, keeps its `t`.
#[inline(always)]
fn within_box(ray: &Ray, c: &[[f32; 3]; 3], t: f32) -> f32 {
    let (p, q, r) = (Vec3A::from(c[0]), Vec3A::from(c[1]), Vec3A::from(c[2]));
    let t0 = (p.min(q).min(r) - ray.origin) * ray.inv;
    let t1 = (p.max(q).max(r) - ray.origin) * ray.inv;
    // An axis the ray has no part of: the box test asks only whether the origin is inside.
    let flat = !ray.inv.is_finite_mask();
    let near = Vec3A::select(flat, Vec3A::NEG_INFINITY, t0.min(t1)).max_element();
    let far = Vec3A::select(flat, Vec3A::INFINITY, t0.max(t1)).min_element();
    let near = near * (1.0 - BOX_MARGIN.copysign(near));
    let far = far * (1.0 + BOX_MARGIN.copysign(far));
    t.max(near).min(far)
}

/// A node or a leaf still to visit, and how far its part of the ray lies from the origin: one
/// whose gap is beyond the best hit so far is dropped without another box test.
#[derive(Clone, Copy)]
struct Todo {
    child: u32,
    /// 0 for a node, else the leaf's triangle count.
    count: u32,
    gap: f32,
}

/// The nodes and leaves a ray has still to visit: one per thread, reused ray after ray.
#[derive(Default)]
pub struct Stack(Vec<Todo>);

/// The hit nearest the ray's origin with `t` in `[-back, front]`.
///
/// The tree is four-wide: a node's four children are slab-tested at once, one lane each, and
/// visited nearest first. A child is dropped only once its part of the ray lies farther from the
/// origin than the best hit; which hit wins never depends on the order: see `Hit::better_than`.
///
/// The box test is watertight, so the tree finds what a test of every triangle finds
/// (`tests/nearest.rs`): each box's part of the ray is widened by a rounding margin (see
/// [`BOX_MARGIN`]), and an axis the ray has no part of is tested by where the origin lies, not
/// by `0 * inf`, which is NaN for a ray lying in a box's face.
pub fn nearest(bvh: &Bvh, ray: &Ray, back: f32, front: f32, stack: &mut Stack) -> Option<Hit> {
    if bvh.is_empty() {
        return None;
    }
    let boxes = Boxes::of(ray);
    // Nearly every ray has a part of every axis: their walk leaves out the test for one that
    // has none.
    if !ray.has_every_axis() {
        walk::<true>(bvh, ray, &boxes, (-back, front), &mut stack.0)
    } else {
        walk::<false>(bvh, ray, &boxes, (-back, front), &mut stack.0)
    }
}

/// [`nearest`]'s walk, from the root, over `(lo, hi)`; `FLAT` when the ray has no part of some
/// axis.
#[inline(always)]
fn walk<const FLAT: bool>(
    bvh: &Bvh,
    ray: &Ray,
    boxes: &Boxes,
    (mut lo, mut hi): (f32, f32),
    stack: &mut Vec<Todo>,
) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    stack.clear();
    let mut todo = Todo { child: 0, count: 0, gap: 0.0 };
    loop {
        if let Some(next) = visit::<FLAT>(bvh, ray, todo, boxes, &mut lo, &mut hi, &mut best, stack) {
            todo = next;
            continue;
        }
        // The next node or leaf that can still hold a hit as near as the best.
        loop {
            let Some(t) = stack.pop() else { return best };
            if t.gap <= hi.max(-lo) {
                todo = t;
                break;
            }
        }
    }
}

/// How much each box's part of the ray is widened, relative to its ends' distances: PBRT's
/// `2 * gamma(3)` (Pharr, Jakob and Humphreys, *Physically Based Rendering*, 4th ed., 6.8.2).
/// A slab distance `(bound - origin) * (1 / dir)` is three roundings from the exact one, each
/// within a relative `eps`, so the computed entry and exit lie within `gamma(3)` of their exact
/// values: entry moved towards the origin and exit away from it by twice that, a hit on a box's
/// face, edge or corner is never outside its box's part of the ray.
pub const BOX_MARGIN: f32 = 2.0 * gamma(3);

/// PBRT's bound on `n` roundings' relative error, `n * eps / (1 - n * eps)`, `eps` half an ulp.
const fn gamma(n: u32) -> f32 {
    let e = f32::EPSILON * 0.5 * n as f32;
    e / (1.0 - e)
}

/// What every box test of one ray shares: its origin and reciprocal direction, one lane per
/// child, and which axes it has no part of.
struct Boxes {
    o: [Vec4; 3],
    inv: [Vec4; 3],
    flat: [bool; 3],
}

impl Boxes {
    fn of(ray: &Ray) -> Boxes {
        let o = [Vec4::splat(ray.origin.x), Vec4::splat(ray.origin.y), Vec4::splat(ray.origin.z)];
        let inv = [Vec4::splat(ray.inv.x), Vec4::splat(ray.inv.y), Vec4::splat(ray.inv.z)];
        Boxes { o, inv, flat: ray.flat_axes() }
    }
}

/// Which of node `n`'s child boxes the ray's part `[lo, hi]` meets (lanes past `n.lanes` have no
/// child), and how far each box's part of the ray lies from the origin; `FLAT` when the ray has
/// no part of some axis.
#[inline(always)]
fn hit_lanes<const FLAT: bool>(n: &WideNode, boxes: &Boxes, lo: f32, hi: f32) -> (BVec4A, Vec4) {
    let Boxes { o, inv, flat } = boxes;
    let slab = |a: usize| {
        if FLAT && flat[a] {
            // Faces included: a ray lying in a face is in the box. Outside, an empty part whose
            // ends stay finite through the margin below.
            let inside = n.min[a].cmple(o[a]) & n.max[a].cmpge(o[a]);
            let (full, none) = (Vec4::splat(f32::INFINITY), Vec4::splat(f32::MAX));
            return (Vec4::select(inside, -full, none), Vec4::select(inside, full, -none));
        }
        let t0 = (n.min[a] - o[a]) * inv[a];
        let t1 = (n.max[a] - o[a]) * inv[a];
        (t0.min(t1), t0.max(t1))
    };
    let ((ax, bx), (ay, by), (az, bz)) = (slab(0), slab(1), slab(2));
    // Widened by scaling, not by adding a multiple of the magnitude, so that an infinite end
    // stays infinite instead of becoming `inf - inf`.
    let m = Vec4::splat(BOX_MARGIN);
    let (near, far) = (ax.max(ay).max(az), bx.min(by).min(bz));
    let near = (near * (Vec4::ONE - m.copysign(near))).max(Vec4::splat(lo));
    let far = (far * (Vec4::ONE + m.copysign(far))).min(Vec4::splat(hi));
    // The gap: `near` when the part is ahead, `-far` when behind, else 0 (branch-free: the
    // lanes hit have `near <= far`).
    (near.cmple(far), near.max(-far).max(Vec4::ZERO))
}

/// Tests leaf-order triangle `k` against the ray's part `[lo, hi]`, keeping the best hit and
/// narrowing the part to what can still beat it.
#[inline(always)]
pub(super) fn test_leaf(bvh: &Bvh, ray: &Ray, k: usize, lo: &mut f32, hi: &mut f32, best: &mut Option<Hit>) {
    let Some((t, bary)) = intersect(ray, bvh.corners(k)) else { return };
    if t < *lo || t > *hi {
        return;
    }
    let h = Hit { t, id: bvh.ids[k], slot: k as u32, bary };
    if best.as_ref().is_none_or(|b| h.better_than(b)) {
        *best = Some(h);
        // Nothing farther than this hit can win; equal distances still can (lower index), so
        // the range stays closed.
        *lo = lo.max(-t.abs());
        *hi = hi.min(t.abs());
    }
}

/// Tests a leaf's triangles, or a four-wide node's boxes: the children hit are pushed, farthest
/// first, except the nearest, which is returned to be visited next.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn visit<const FLAT: bool>(
    bvh: &Bvh,
    ray: &Ray,
    todo: Todo,
    boxes: &Boxes,
    lo: &mut f32,
    hi: &mut f32,
    best: &mut Option<Hit>,
    stack: &mut Vec<Todo>,
) -> Option<Todo> {
    if todo.count > 0 {
        for k in todo.child as usize..(todo.child + todo.count) as usize {
            test_leaf(bvh, ray, k, lo, hi, best);
        }
        return None;
    }
    let n = &bvh.nodes[todo.child as usize];
    let (hits, gaps) = hit_lanes::<FLAT>(n, boxes, *lo, *hi);
    let mask = hits.bitmask() & n.lanes;
    if mask == 0 {
        return None;
    }
    let gaps = gaps.to_array();
    let kid = |lane: usize| Todo { child: n.child[lane], count: n.count[lane] as u32, gap: gaps[lane] };
    let (next, rest) = nearest_first(mask, &gaps);
    stack.extend(rest.map(kid));
    Some(kid(next))
}

/// The order a walk takes the children in `mask` (bit `k` for child `k`, at least one) at
/// distances `dist`: the nearest is visited next (ties: the lower lane), the others, returned
/// farthest first, are pushed so that they pop nearest first.
#[inline(always)]
pub(super) fn nearest_first(mut mask: u32, dist: &[f32; 4]) -> (usize, impl Iterator<Item = usize>) {
    let mut next = mask.trailing_zeros() as usize;
    mask &= mask - 1;
    let mut rest = [next; 3];
    let mut len = 0;
    while mask != 0 {
        let mut l = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        if dist[l] < dist[next] {
            std::mem::swap(&mut l, &mut next);
        }
        let mut i = len;
        while i > 0 && dist[rest[i - 1]] <= dist[l] {
            rest[i] = rest[i - 1];
            i -= 1;
        }
        rest[i] = l;
        len += 1;
    }
    (next, rest.into_iter().take(len))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> [[f32; 3]; 3] {
        [a, b, c]
    }

    #[test]
    fn hits_inside_and_reports_barycentrics() {
        let t = tri([0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]);
        let r = Ray::new(Vec3A::new(0.25, 0.25, 0.0), Vec3A::Z);
        let (d, b) = intersect(&r, &t).unwrap();
        assert!((d - 1.0).abs() < 1e-6);
        assert!((b[0] - 0.5).abs() < 1e-6 && (b[1] - 0.25).abs() < 1e-6 && (b[2] - 0.25).abs() < 1e-6);
        let behind = Ray::new(Vec3A::new(0.25, 0.25, 2.0), Vec3A::Z);
        assert!((intersect(&behind, &t).unwrap().0 + 1.0).abs() < 1e-6);
        assert!(intersect(&Ray::new(Vec3A::new(0.8, 0.8, 0.0), Vec3A::Z), &t).is_none());
    }

    /// A ray exactly through the shared edge of two triangles hits one of them.
    #[test]
    fn shared_edges_are_watertight() {
        let a = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let b = tri([1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]);
        let d = Vec3A::new(0.001, -0.0007, -1.0).normalize();
        for k in 1..100 {
            let s = k as f32 / 100.0;
            // Aimed at the edge point (s, 1 - s, 0), from one unit back along the ray.
            let r = Ray::new(Vec3A::new(s, 1.0 - s, 0.0) - d, d);
            assert!(intersect(&r, &a).is_some() || intersect(&r, &b).is_some(), "slipped through at {s}");
        }
    }

    /// A counter-clockwise triangle faces the way its normal points: taken with front faces
    /// only, a ray meets it when its front faces the ray's far end, along every axis, either
    /// way, and whichever side of the origin it lies on.
    #[test]
    fn front_faces_only_keeps_the_triangles_facing_the_far_end() {
        let base = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        for axis in 0..3 {
            // The triangle in the plane across `axis`, its normal along `+axis`.
            let tri = base.map(|p: [f32; 3]| std::array::from_fn(|a| p[(a + 5 - axis) % 3]));
            let mut nrm = [0.0; 3];
            nrm[axis] = 1.0;
            let n = Vec3A::from(nrm);
            let inside = Vec3A::from(tri[0]).lerp(Vec3A::from(tri[1]), 0.25).lerp(Vec3A::from(tri[2]), 0.25);
            for dir in
                [n, -n, (n + Vec3A::new(0.1, 0.2, 0.3)).normalize(), (-n + Vec3A::new(0.2, 0.1, 0.3)).normalize()]
            {
                let faces_far_end = n.dot(dir) > 0.0;
                for side in [1.0f32, -1.0] {
                    let r = Ray::new(inside - dir * side, dir);
                    assert!(intersect(&r, &tri).is_some());
                    let got = intersect(&r.front_faces_only(), &tri).is_some();
                    assert_eq!(got, faces_far_end, "axis {axis}, dir {dir}, hit at t = {side}");
                }
            }
        }
    }

    #[test]
    fn degenerate_triangles_never_hit() {
        let t = tri([0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [2.0, 0.0, 1.0]);
        assert!(intersect(&Ray::new(Vec3A::new(0.5, 0.0, 0.0), Vec3A::Z), &t).is_none());
        let p = tri([0.3, 0.3, 1.0], [0.3, 0.3, 1.0], [0.3, 0.3, 1.0]);
        assert!(intersect(&Ray::new(Vec3A::new(0.3, 0.3, 0.0), Vec3A::Z), &p).is_none());
    }

    /// The nearest hit on either side of the origin wins; beyond the range, nothing.
    #[test]
    fn nearest_on_either_side() {
        let sheet = |z: f32| [Vec3A::new(-1.0, -1.0, z), Vec3A::new(1.0, -1.0, z), Vec3A::new(0.0, 1.0, z)];
        let tris: Vec<[Vec3A; 3]> = [0.5f32, -0.2, 0.9, -0.7].iter().map(|&z| sheet(z)).collect();
        let (bvh, _) = crate::transfer::bvh::tests::soup(&tris);
        let r = Ray::new(Vec3A::ZERO, Vec3A::Z);
        let h = nearest(&bvh, &r, 1.0, 1.0, &mut Stack::default()).unwrap();
        assert_eq!((h.id, h.t), (1, -0.2));
        assert_eq!(nearest(&bvh, &r, 0.1, 0.6, &mut Stack::default()).unwrap().id, 0);
        assert!(nearest(&bvh, &r, 0.1, 0.4, &mut Stack::default()).is_none());
    }
}
