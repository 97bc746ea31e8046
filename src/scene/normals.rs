//! Vertex and face normals for meshes that come without them, robust to any triangle size.

/// `v` multiplied by the power of two that brings its largest component into [1, 2). Exact in
/// floating point, so directions computed from scaled edges are bit-identical to unscaled ones for
/// ordinary meshes, while edges of 1e-20 (whose cross product would underflow to zero) or 1e30
/// (which would overflow) still give their true direction.
fn pow2_scaled(v: glam::Vec3) -> glam::Vec3 {
    let m = v.abs().max_element();
    if m == 0.0 || !m.is_finite() {
        return v;
    }
    // `floor(log2(m))` read from the bits, exactly (`log2` can round up below a power of two)
    // and in a fraction of the time: a subnormal's is its highest set bit's, 2^-149 apart.
    let (bits, biased) = (m.to_bits(), (m.to_bits() >> 23) as i32);
    let e = if biased == 0 { bits.ilog2() as i32 - 149 } else { biased - 127 };
    // Two steps: 2^149 alone does not fit in an f32.
    v * pow2(-(e / 2)) * pow2(-(e - e / 2))
}

/// `2^k`, for `k` from -126 to 127.
fn pow2(k: i32) -> f32 {
    f32::from_bits(((k + 127) as u32) << 23)
}

/// The unit normal of triangle `(a, b, c)` in counter-clockwise order, whatever its size, or
/// `None` when it has no area (in float32).
pub(crate) fn face_normal(a: glam::Vec3, b: glam::Vec3, c: glam::Vec3) -> Option<glam::Vec3> {
    let n = pow2_scaled(pow2_scaled(b - a).cross(pow2_scaled(c - a)));
    let n = n.normalize_or_zero();
    (n != glam::Vec3::ZERO && n.is_finite()).then_some(n)
}

/// Angle-weighted vertex normals over shared position indices. Returns per-corner normals and
/// how many corners had none (only degenerate faces around them).
pub fn smooth_normals(positions: &[f32], indices: &[u32]) -> (Vec<[f32; 3]>, usize) {
    let p = |i: u32| glam::Vec3::from_slice(&positions[i as usize * 3..i as usize * 3 + 3]);
    let acc = accumulate(positions.len() / 3, p, indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]));
    let mut fixed = 0;
    let out = indices
        .iter()
        .map(|&i| {
            unit_or_z(acc[i as usize]).unwrap_or_else(|| {
                fixed += 1;
                [0.0, 0.0, 1.0]
            })
        })
        .collect();
    (out, fixed)
}

/// The same normals once per vertex rather than per corner (for meshes too large to hold
/// three normals a triangle); vertices with none get +Z.
pub fn smooth_vertex_normals(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<[f32; 3]> {
    let p = |i: u32| glam::Vec3::from(positions[i as usize]);
    let acc = accumulate(positions.len(), p, triangles.iter().copied());
    acc.into_iter().map(|n| unit_or_z(n).unwrap_or([0.0, 0.0, 1.0])).collect()
}

/// Each vertex's sum of face normals weighted by the face's angle there.
fn accumulate(
    vertices: usize,
    p: impl Fn(u32) -> glam::Vec3,
    triangles: impl Iterator<Item = [u32; 3]>,
) -> Vec<glam::Vec3> {
    let mut acc = vec![glam::Vec3::ZERO; vertices];
    for t in triangles {
        for (k, w) in corner_weights(t.map(&p)).into_iter().flatten().enumerate() {
            acc[t[k] as usize] += w;
        }
    }
    acc
}

/// What triangle `(a, b, c)` adds to each corner's normal: its face normal weighted by the
/// corner's angle; `None` for a triangle without area.
fn corner_weights([a, b, c]: [glam::Vec3; 3]) -> Option<[glam::Vec3; 3]> {
    let n = face_normal(a, b, c)?;
    Some([(a, b, c), (b, c, a), (c, a, b)].map(|(o, u, v)| {
        let e1 = pow2_scaled(u - o).normalize_or_zero();
        let e2 = pow2_scaled(v - o).normalize_or_zero();
        n * e1.dot(e2).clamp(-1.0, 1.0).acos()
    }))
}

/// A normal being summed: its group, and the next normal of the same position.
struct Slot {
    sum: glam::Vec3,
    group: u64,
    next: u32,
}

/// Normals shared only within a smoothing group (OBJ's `s`): `groups` gives each triangle's, 0
/// for none. A vertex's normal in a group is the angle-weighted sum over that group's faces
/// around it; a face in no group is flat. Returns the normals and each triangle's three indices
/// into them, and how many normals had no direction (only faces without area): they point
/// along +Z.
pub fn grouped_normals(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    groups: &[u64],
) -> (Vec<[f32; 3]>, Vec<[u32; 3]>, usize) {
    // Per position, its first normal; each normal links to the position's next (a position has
    // as many as the groups around it, rarely more than a few).
    let mut head = vec![u32::MAX; positions.len()];
    let mut slots: Vec<Slot> = Vec::new();
    let mut index = Vec::with_capacity(triangles.len());
    for (t, &g) in triangles.iter().zip(groups) {
        let p = t.map(|i| glam::Vec3::from(positions[i as usize]));
        if g == 0 {
            let sum = face_normal(p[0], p[1], p[2]).unwrap_or_default();
            slots.push(Slot { sum, group: 0, next: u32::MAX });
            index.push([slots.len() as u32 - 1; 3]);
            continue;
        }
        let ids = t.map(|i| {
            let mut k = head[i as usize];
            while k != u32::MAX && slots[k as usize].group != g {
                k = slots[k as usize].next;
            }
            if k == u32::MAX {
                slots.push(Slot { sum: glam::Vec3::ZERO, group: g, next: head[i as usize] });
                k = slots.len() as u32 - 1;
                head[i as usize] = k;
            }
            k
        });
        if let Some(w) = corner_weights(p) {
            (0..3).for_each(|k| slots[ids[k] as usize].sum += w[k]);
        }
        index.push(ids);
    }
    let mut fixed = 0;
    let normals = slots
        .into_iter()
        .map(|s| {
            unit_or_z(s.sum).unwrap_or_else(|| {
                fixed += 1;
                [0.0, 0.0, 1.0]
            })
        })
        .collect();
    (normals, index, fixed)
}

fn unit_or_z(sum: glam::Vec3) -> Option<[f32; 3]> {
    let n = pow2_scaled(sum).normalize_or_zero();
    (n != glam::Vec3::ZERO && n.is_finite()).then(|| n.to_array())
}

/// One normal per face, from per-corner positions; faces without area get +Z.
pub fn flat_normals(pos: &[[f32; 3]]) -> (Vec<[f32; 3]>, usize) {
    let mut fixed = 0;
    let mut out = Vec::with_capacity(pos.len());
    for t in pos.chunks_exact(3) {
        let n = match face_normal(glam::Vec3::from(t[0]), glam::Vec3::from(t[1]), glam::Vec3::from(t[2])) {
            Some(n) => n.to_array(),
            None => {
                fixed += 3;
                [0.0, 0.0, 1.0]
            }
        };
        out.extend([n, n, n]);
    }
    (out, fixed)
}

pub(crate) fn unit_or_up(n: [f32; 3]) -> [f32; 3] {
    let v = pow2_scaled(glam::Vec3::from(n)).normalize_or_zero();
    if v == glam::Vec3::ZERO || !v.is_finite() {
        [0.0, 0.0, 1.0]
    } else {
        v.to_array()
    }
}

/// [`unit_or_up`] on every normal of `ns`, in place. Eight at a time where all eight are
/// ordinary (finite, their largest component a normal float, a finite nonzero result): the same
/// operations in the same order, so the same bits, written without a branch so that the
/// compiler vectorises them; any other eight go through [`unit_or_up`] one by one. HIGH's 5.1M
/// normals at 10M triangles took 45 ms of the read on both cores one by one
/// (`docs/transfer-history.md`).
pub(crate) fn unit_or_up_all(ns: &mut [[f32; 3]]) {
    let mut chunks = ns.chunks_exact_mut(8);
    for c in &mut chunks {
        if !unit8(c) {
            c.iter_mut().for_each(|n| *n = unit_or_up(*n));
        }
    }
    chunks.into_remainder().iter_mut().for_each(|n| *n = unit_or_up(*n));
}

/// Eight normals made unit as [`unit_or_up`] makes them (`pow2_scaled`, then glam's
/// `normalize_or_zero`, spelled out), written back only when all eight are ordinary.
#[inline]
fn unit8(c: &mut [[f32; 3]]) -> bool {
    let mut out = [[0f32; 3]; 8];
    let mut ordinary = true;
    for (o, &[x, y, z]) in out.iter_mut().zip(c.iter()) {
        let max = |a: f32, b: f32| if a > b { a } else { b };
        let m = max(x.abs(), max(y.abs(), z.abs()));
        let biased = (m.to_bits() >> 23) as i32;
        let e = biased - 127;
        let (s1, s2) = (pow2(-(e / 2)), pow2(-(e - e / 2)));
        let (x, y, z) = (x * s1 * s2, y * s1 * s2, z * s1 * s2);
        let rcp = 1.0 / ((x * x) + (y * y) + (z * z)).sqrt();
        let v = [x * rcp, y * rcp, z * rcp];
        let finite = v.iter().fold(true, |f, c| f & c.is_finite());
        let nonzero = v.iter().fold(false, |f, &c| f | (c != 0.0));
        ordinary &= (1..=254).contains(&biased) & rcp.is_finite() & (rcp > 0.0) & finite & nonzero;
        *o = v;
    }
    if ordinary {
        c.copy_from_slice(&out);
    }
    ordinary
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// Eight at a time gives the bits one by one gives, on ordinary normals and on every kind of
    /// extreme among them (zero, subnormal, huge, infinite, NaN).
    #[test]
    fn unit_eight_at_a_time_is_unit_one_by_one() {
        let mut rng = crate::test_rng::XorShift64(0x0DDB_1A5E_5BAD_5EED);
        let odd = [0.0, -0.0, 1e-40, -1e-45, 3e38, f32::MAX, f32::INFINITY, f32::NAN, 1e-20, 1e20];
        let mut ns: Vec<[f32; 3]> = (0..100_003)
            .map(|_| {
                let x = rng.next();
                [0, 1, 2].map(|k| {
                    let r = x >> (20 * k);
                    if r.is_multiple_of(50) {
                        odd[(r >> 8) as usize % odd.len()]
                    } else {
                        ((r >> 8) % 2_000_001) as f32 / 1e6 - 1.0
                    }
                })
            })
            .collect();
        let want: Vec<[u32; 3]> = ns.iter().map(|&n| unit_or_up(n).map(f32::to_bits)).collect();
        unit_or_up_all(&mut ns);
        // The eight-at-a-time path is taken on ordinary normals, and declines an extreme one.
        let mut ordinary = [[1.0, -2.0, 3.0]; 8];
        assert!(unit8(&mut ordinary) && ordinary[7] == unit_or_up([1.0, -2.0, 3.0]));
        ordinary[3][1] = f32::NAN;
        assert!(!unit8(&mut ordinary));
        let got: Vec<[u32; 3]> = ns.iter().map(|n| n.map(f32::to_bits)).collect();
        assert_eq!(got, want);
    }

    #[test]
    fn face_normals_are_scale_free() {
        for s in [1e-30f32, 1e-20, 1e-6, 1.0, 1e6, 1e30] {
            let n = face_normal(Vec3::ZERO, Vec3::new(s, 0.0, 0.0), Vec3::new(0.0, s, 0.0));
            let n = n.unwrap_or_else(|| panic!("scale {s}: no normal"));
            assert!((n - Vec3::Z).length() < 1e-6, "scale {s}: {n:?}");
        }
        // Sliver: 1e-7 high over a unit base.
        let n = face_normal(Vec3::ZERO, Vec3::X, Vec3::new(0.5, 1e-7, 0.0)).unwrap();
        assert!((n - Vec3::Z).length() < 1e-6, "{n:?}");
        assert_eq!(face_normal(Vec3::ZERO, Vec3::X, Vec3::X * 2.0), None);
        assert_eq!(face_normal(Vec3::ONE, Vec3::ONE, Vec3::ONE), None);
    }

    /// The largest component lands in [1, 2) by an exact power of two, from the smallest
    /// subnormal to the largest float, next to powers of two too.
    #[test]
    fn scaled_into_one_to_two_exactly() {
        let mut ms = vec![f32::from_bits(1), 1e-40, f32::MIN_POSITIVE, 1.0, f32::MAX];
        for k in -149..=127 {
            let p = 2f64.powi(k) as f32;
            ms.extend([p, f32::from_bits(p.to_bits() + 1), f32::from_bits(p.to_bits().saturating_sub(1))]);
        }
        for m in ms.into_iter().filter(|m| *m > 0.0 && m.is_finite()) {
            let v = Vec3::new(-m, m * 0.25, 0.0);
            let s = pow2_scaled(v);
            assert!((1.0..2.0).contains(&s.abs().max_element()), "{m:e}: {s:?}");
            let f = f64::from(s.x) / f64::from(v.x);
            assert_eq!(f.to_bits() & ((1 << 52) - 1), 0, "{m:e}: scaled by {f:e}, not a power of two");
            assert_eq!(f64::from(s.y), f64::from(v.y) * f, "{m:e}");
        }
    }

    #[test]
    fn scaling_by_powers_of_two_is_exact() {
        let v = Vec3::new(0.3, -1.7, 2.9);
        let a = v.cross(Vec3::new(1.1, 0.2, -0.4)).normalize();
        let b = pow2_scaled(pow2_scaled(v).cross(pow2_scaled(Vec3::new(1.1, 0.2, -0.4)))).normalize();
        assert_eq!(a, b);
    }
}

/// What reading did to a primitive's NORMAL stream. glTF wants unit normals; a zero or non-finite
/// one has no direction a renderer or MikkTSpace can use, so it is treated as missing.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct NormalRepair {
    /// Normals that were zero or not finite (NaN, infinity).
    pub unusable: usize,
    /// Float normals of another length than 1 (beyond [`NORMAL_UNIT_TOLERANCE`]), brought to it.
    pub renormalised: usize,
    /// Every normal was unusable: NORMAL is gone, and the stages make flat normals as the glTF
    /// spec asks of a client for a primitive without NORMAL.
    pub dropped: bool,
}

/// How far from 1 a float normal's length may be: the Khronos glTF-Validator's tolerance for
/// unit vectors.
pub const NORMAL_UNIT_TOLERANCE: f32 = 0.00674;

impl NormalRepair {
    /// Whether anything was changed.
    pub fn any(&self) -> bool {
        self.unusable > 0 || self.renormalised > 0
    }

    /// The report's words for it, if anything was changed.
    pub fn describe(&self) -> Option<String> {
        let mut parts = Vec::new();
        if self.dropped {
            parts.push(format!(
                "all {} normals were zero or not finite: treated as a missing NORMAL (flat normals made)",
                self.unusable
            ));
        } else if self.unusable > 0 {
            parts.push(format!(
                "{} normals were zero or not finite: replaced by the angle-weighted normal of the faces around them",
                self.unusable
            ));
        }
        if self.renormalised > 0 {
            parts.push(format!("{} normals were not unit length: normalised", self.renormalised));
        }
        (!parts.is_empty()).then(|| parts.join("; "))
    }
}

/// Makes `p`'s NORMAL usable (see [`NormalRepair`]). `p` is a triangle list when it is a surface;
/// zero or non-finite normals of other modes become +Z.
pub fn repair_normals(p: &mut super::Primitive) -> NormalRepair {
    let mut r = NormalRepair::default();
    let Some(s) = p.attr("NORMAL") else { return r };
    let float = s.format.component_type == super::accessor::FLOAT;
    let len = |n: &[f32; 3]| (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let unusable = |n: &[f32; 3]| {
        let l = len(n);
        !l.is_finite() || l < 1e-12 || !n.iter().all(|c| c.is_finite())
    };
    let off_unit = |n: &[f32; 3]| float && (len(n) - 1.0).abs() > NORMAL_UNIT_TOLERANCE;
    // Read where stored (float normals are borrowed): almost every file needs nothing, and a
    // copy of a large mesh's normals would only raise every command's peak memory.
    if !s.as_f32::<3>().iter().any(|n| unusable(n) || off_unit(n)) {
        return r;
    }
    let mut values: Vec<[f32; 3]> = s.to_f32();
    let mut bad = Vec::new();
    for (i, n) in values.iter_mut().enumerate() {
        if unusable(n) {
            bad.push(i);
        } else if off_unit(n) {
            let l = len(n);
            *n = [n[0] / l, n[1] / l, n[2] / l];
            r.renormalised += 1;
        }
    }
    r.unusable = bad.len();
    if !r.any() {
        return r;
    }
    if r.unusable == values.len() {
        r.dropped = true;
        r.renormalised = 0;
        p.remove_attr("NORMAL");
        return r;
    }
    if r.unusable > 0 {
        let positions = p.positions();
        let triangles: Vec<[u32; 3]> = if p.mode == 4 && positions.len() == values.len() {
            p.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
        } else {
            Vec::new()
        };
        let smooth = if triangles.is_empty() { Vec::new() } else { smooth_vertex_normals(&positions, &triangles) };
        for i in bad {
            values[i] = smooth.get(i).copied().unwrap_or([0.0, 0.0, 1.0]);
        }
    }
    let template = p.attr("NORMAL").and_then(|s| s.template.clone());
    let mut fixed = super::Stream::from_f32("VEC3", &values);
    fixed.template = template;
    p.set_attr("NORMAL", fixed);
    r
}

#[cfg(test)]
mod repair_tests {
    use super::*;
    use crate::scene::{Primitive, Stream};

    fn quad(normals: &[[f32; 3]]) -> Primitive {
        let pos = [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        Primitive {
            attributes: vec![
                ("POSITION".into(), Stream::from_f32("VEC3", &pos)),
                ("NORMAL".into(), Stream::from_f32("VEC3", normals)),
            ],
            targets: Vec::new(),
            indices: vec![0, 1, 2, 0, 2, 3],
            mode: 4,
        }
    }

    #[test]
    fn zero_and_nan_normals_take_the_faces_normal_and_long_ones_are_normalised() {
        let mut p = quad(&[[0.0, 0.0, 0.0], [f32::NAN, 0.0, 1.0], [0.0, 0.0, 2.0], [0.0, 0.0, 1.0]]);
        let r = repair_normals(&mut p);
        assert_eq!(r, NormalRepair { unusable: 2, renormalised: 1, dropped: false });
        assert_eq!(p.attr("NORMAL").unwrap().to_f32::<3>(), vec![[0.0, 0.0, 1.0]; 4]);
    }

    #[test]
    fn all_zero_normals_are_a_missing_normal() {
        let mut p = quad(&[[0.0; 3]; 4]);
        let r = repair_normals(&mut p);
        assert_eq!(r, NormalRepair { unusable: 4, renormalised: 0, dropped: true });
        assert!(p.attr("NORMAL").is_none());
    }

    #[test]
    fn unit_normals_are_left_as_stored() {
        let mut p = quad(&[[0.0, 0.0, 1.0]; 4]);
        let before = p.clone();
        assert!(!repair_normals(&mut p).any());
        assert_eq!(p, before);
    }
}
