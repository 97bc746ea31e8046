//! Rays against the [`Bvh`]: the hit nearest the ray's origin within `[-back, front]`.
//!
//! Triangles are tested with the watertight algorithm of Woop, Benthin and Wald (JCGT 2013): a
//! ray through a shared edge or vertex hits at least one of the triangles there, so grazing rays
//! and rays through mesh vertices do not slip through HIGH. Edge values that come out exactly
//! zero in f32 are recomputed in f64, as the paper advises. Degenerate triangles never hit.

use super::bvh::Bvh;
use glam::Vec3A;

/// A ray prepared for the watertight test (its shear is computed once).
#[derive(Debug, Clone, Copy)]
pub struct Ray {
    pub origin: Vec3A,
    pub dir: Vec3A,
    inv: Vec3A,
    k: [usize; 3],
    shear: [f32; 3],
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
        Ray { origin, dir, inv: dir.recip(), k: [kx, ky, kz], shear }
    }
}

/// Where a ray met HIGH.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Signed distance along the ray (in units of its direction's length).
    pub t: f32,
    /// The triangle's index in the input.
    pub id: u32,
    /// Its index in the tree's leaf order (into [`Bvh::tris`]).
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

/// The watertight test; hits from both sides count.
#[inline]
pub fn intersect(ray: &Ray, v: &[Vec3A; 3]) -> Option<(f32, [f32; 3])> {
    let [kx, ky, kz] = ray.k;
    let [sx, sy, sz] = ray.shear;
    let a = v[0] - ray.origin;
    let b = v[1] - ray.origin;
    let c = v[2] - ray.origin;
    let (ax, ay) = (a[kx] - sx * a[kz], a[ky] - sy * a[kz]);
    let (bx, by) = (b[kx] - sx * b[kz], b[ky] - sy * b[kz]);
    let (cx, cy) = (c[kx] - sx * c[kz], c[ky] - sy * c[kz]);
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
    let t = (u * sz * a[kz] + v * sz * b[kz] + w * sz * c[kz]) / det;
    let inv = 1.0 / det;
    Some((t, [u * inv, v * inv, w * inv]))
}

/// The slab test: the part of `[lo, hi]` inside the node's box, if any.
#[inline]
fn slab(ray: &Ray, min: &[f32; 3], max: &[f32; 3], lo: f32, hi: f32) -> Option<(f32, f32)> {
    let t0 = (Vec3A::from(*min) - ray.origin) * ray.inv;
    let t1 = (Vec3A::from(*max) - ray.origin) * ray.inv;
    // NaN (0 * inf, a ray in the box's plane) must not narrow the range: max/min drop it.
    let near = t0.min(t1).max_element().max(lo);
    let far = t0.max(t1).min_element().min(hi);
    (near <= far).then_some((near, far))
}

/// How far the interval `[a, b]` is from 0.
#[inline]
fn gap(a: f32, b: f32) -> f32 {
    if a > 0.0 {
        a
    } else if b < 0.0 {
        -b
    } else {
        0.0
    }
}

/// The hit nearest the ray's origin with `t` in `[-back, front]`.
pub fn nearest(bvh: &Bvh, positions: &[[f32; 3]], ray: &Ray, back: f32, front: f32) -> Option<Hit> {
    if bvh.is_empty() {
        return None;
    }
    let mut best: Option<Hit> = None;
    let (mut lo, mut hi) = (-back, front);
    // Nodes still to visit, with how far their part of the ray lies from the origin: a node
    // whose gap is beyond the best hit so far is dropped without another box test.
    let mut stack = [(0u32, 0.0f32); 96];
    let mut sp = 0;
    let root = &bvh.nodes[0];
    slab(ray, &root.min, &root.max, lo, hi)?;
    let mut node = 0usize;
    loop {
        let n = &bvh.nodes[node];
        if n.n > 0 {
            for k in n.a as usize..(n.a + n.n) as usize {
                if let Some((t, bary)) = intersect(ray, &bvh.corners(positions, k)) {
                    if t < lo || t > hi {
                        continue;
                    }
                    let h = Hit { t, id: bvh.ids[k], slot: k as u32, bary };
                    if best.as_ref().map(|b| h.better_than(b)).unwrap_or(true) {
                        best = Some(h);
                        // Nothing farther than this hit can win; equal distances still can
                        // (lower index), so the range stays closed.
                        lo = lo.max(-t.abs());
                        hi = hi.min(t.abs());
                    }
                }
            }
        } else {
            let (l, r) = (node + 1, n.a as usize);
            let sl = slab(ray, &bvh.nodes[l].min, &bvh.nodes[l].max, lo, hi).map(|(a, b)| gap(a, b));
            let sr = slab(ray, &bvh.nodes[r].min, &bvh.nodes[r].max, lo, hi).map(|(a, b)| gap(a, b));
            match (sl, sr) {
                (Some(a), Some(b)) => {
                    let (first, second, g) = if a <= b { (l, r, b) } else { (r, l, a) };
                    if sp < stack.len() {
                        stack[sp] = (second as u32, g);
                        sp += 1;
                    }
                    node = first;
                    continue;
                }
                (Some(_), None) => {
                    node = l;
                    continue;
                }
                (None, Some(_)) => {
                    node = r;
                    continue;
                }
                (None, None) => {}
            }
        }
        // Pop the next node that can still hold a hit as near as the best.
        loop {
            if sp == 0 {
                return best;
            }
            sp -= 1;
            let (c, g) = stack[sp];
            if g <= hi.max(-lo) {
                node = c as usize;
                break;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> [Vec3A; 3] {
        [a.into(), b.into(), c.into()]
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
        let (bvh, pos) = crate::transfer::bvh::tests::soup(&tris);
        let r = Ray::new(Vec3A::ZERO, Vec3A::Z);
        let h = nearest(&bvh, &pos, &r, 1.0, 1.0).unwrap();
        assert_eq!((h.id, h.t), (1, -0.2));
        assert_eq!(nearest(&bvh, &pos, &r, 0.1, 0.6).unwrap().id, 0);
        assert!(nearest(&bvh, &pos, &r, 0.1, 0.4).is_none());
    }
}
