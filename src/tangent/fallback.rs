//! Making every frame usable. MikkTSpace has no answer for some corners (degenerate triangles
//! with no neighbour to borrow from) and can give frames that are not orthogonal to a normal that
//! is not unit length. Each such corner gets a substitute frame, and every substitution is counted
//! with its reason ([`FallbackCounts`]: `undefined` when the reference gave nothing, `invalid` when
//! what it gave was unusable).
//!
//! The substitute frame, in order of preference:
//! 1. the tangent of another corner of the same triangle with a valid frame, then of the first
//!    corner with a valid frame at the same vertex, projected onto the plane orthogonal to this
//!    corner's normal (Gram-Schmidt) and normalised, keeping the lender's `w`;
//! 2. otherwise the coordinate axis least aligned with the normal, projected the same way, with
//!    the reference's `w` if it gave one and `+1` if not.
//!
//! Every test is relative to the vectors' own scale: vectors are divided by their largest
//! component before they are normalised, so a frame or normal of length 1e-30 (a microscopic
//! triangle's unnormalised cross product) is treated like one of length 1, and a projection is
//! refused only when what is left of the tangent is below [`PARALLEL_TOLERANCE`] of its length.
//! The only absolute tolerances are those for frames that are already meant to be unit
//! ([`UNIT_TOLERANCE`], [`ORTHO_TOLERANCE`]).

use super::frames::Frames;
use glam::Vec3;

/// Tolerances a frame must meet to leave the tool unchanged.
pub const UNIT_TOLERANCE: f32 = 1e-4;
pub const ORTHO_TOLERANCE: f32 = 1e-3;
/// A tangent whose component orthogonal to the normal is shorter than this fraction of its own
/// length is taken as parallel to the normal (about 0.06 degrees from it).
pub const PARALLEL_TOLERANCE: f32 = 1e-3;

/// `v` scaled to unit length, whatever its magnitude (tiny or huge vectors do not underflow or
/// overflow), or `None` when it is zero or not finite.
pub fn unit(v: Vec3) -> Option<Vec3> {
    if !v.is_finite() {
        return None;
    }
    let m = v.abs().max_element();
    if m == 0.0 {
        return None;
    }
    let u = (v / m).normalize();
    u.is_finite().then_some(u)
}

/// Why corners were given a substitute frame.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct FallbackCounts {
    /// The reference gave no frame (degenerate triangle, no neighbour to borrow from).
    pub undefined: usize,
    /// The reference's frame was not finite, not unit, or not orthogonal to the normal.
    pub invalid: usize,
    /// Of those, how many borrowed a neighbour's tangent (the rest used a fixed axis).
    pub borrowed: usize,
}

impl FallbackCounts {
    pub fn total(&self) -> usize {
        self.undefined + self.invalid
    }
    pub fn add(&mut self, o: &FallbackCounts) {
        self.undefined += o.undefined;
        self.invalid += o.invalid;
        self.borrowed += o.borrowed;
    }
}

/// True when `t` is a frame the conventions accept for normal `n`.
pub fn is_valid(t: [f32; 4], n: Vec3) -> bool {
    is_valid_unit(t, unit(n))
}

/// [`is_valid`] given the normal's [`unit`] vector.
fn is_valid_unit(t: [f32; 4], n: Option<Vec3>) -> bool {
    let v = Vec3::new(t[0], t[1], t[2]);
    let Some(n) = n else { return false };
    v.is_finite()
        && (v.length() - 1.0).abs() <= UNIT_TOLERANCE
        && (t[3] == 1.0 || t[3] == -1.0)
        && v.dot(n).abs() <= ORTHO_TOLERANCE
}

/// The unit vector orthogonal to `n` nearest to `t`, if `t` is far enough from parallel
/// ([`PARALLEL_TOLERANCE`], relative to `t`'s length). Scale-free in both `t` and `n`; a zero or
/// non-finite `n` has no orthogonal plane and gives `None`.
pub fn orthogonalise(t: Vec3, n: Vec3) -> Option<Vec3> {
    let n = unit(n)?;
    let t = unit(t)?;
    let p = t - n * n.dot(t);
    let len = p.length();
    (len > PARALLEL_TOLERANCE).then(|| p / len).filter(|v| v.is_finite())
}

/// A unit vector orthogonal to `n`, from the coordinate axis least aligned with it.
pub fn any_orthogonal(n: Vec3) -> Vec3 {
    let Some(n) = unit(n) else { return Vec3::X };
    let a = n.abs();
    let axis = if a.x <= a.y && a.x <= a.z {
        Vec3::X
    } else if a.y <= a.z {
        Vec3::Y
    } else {
        Vec3::Z
    };
    orthogonalise(axis, n).unwrap_or(Vec3::X)
}

/// Where [`repair`] finds each corner's normal and vertex.
#[derive(Debug, Clone, Copy)]
pub struct CornerNormals<'a> {
    pub normals: &'a [[f32; 3]],
    /// Corner -> index into `normals`: also the index list the frames were made for.
    pub normal_of: &'a [u32],
    /// Corner -> vertex: corners of one vertex lend to each other.
    pub vertex: &'a [u32],
}

/// Replaces every unusable corner frame. `frames` are per corner (three per triangle), already in
/// the output's `w` convention; a replaced corner gets a value of its own.
pub fn repair(frames: &mut Frames, at: CornerNormals) -> FallbackCounts {
    use rayon::prelude::*;
    let mut counts = FallbackCounts::default();
    // Unit normals, once per normal rather than once per corner.
    let units: Vec<Option<Vec3>> = at.normals.par_iter().with_min_len(1 << 12).map(|&n| unit(Vec3::from(n))).collect();
    let ok =
        |c: usize| frames.get(c, at.normal_of[c]).is_some_and(|t| is_valid_unit(t, units[at.normal_of[c] as usize]));
    let bad: Vec<usize> = (0..at.normal_of.len()).into_par_iter().with_min_len(1 << 12).filter(|&c| !ok(c)).collect();
    if bad.is_empty() {
        return counts;
    }
    let mut bad_flag = vec![false; at.normal_of.len()];
    bad.iter().for_each(|&c| bad_flag[c] = true);
    // First valid corner of each vertex, to lend from across triangles.
    let n_vertices = at.vertex.iter().map(|&v| v as usize + 1).max().unwrap_or(0);
    let mut by_vertex = vec![usize::MAX; n_vertices];
    for (c, (&v, &bad)) in at.vertex.iter().zip(&bad_flag).enumerate() {
        let v = v as usize;
        if by_vertex[v] == usize::MAX && !bad {
            by_vertex[v] = c;
        }
    }
    // Only valid corners lend and only invalid ones change, so the order of repairs is free.
    let mut repaired = Vec::with_capacity(bad.len());
    for &c in &bad {
        let original = frames.get(c, at.normal_of[c]);
        match original {
            Some(_) => counts.invalid += 1,
            None => counts.undefined += 1,
        }
        let n = Vec3::from(at.normals[at.normal_of[c] as usize]);
        let tri = c / 3 * 3;
        let lenders = (tri..tri + 3)
            .filter(|&k| k != c && !bad_flag[k])
            .chain(Some(by_vertex[at.vertex[c] as usize]).filter(|&k| k != usize::MAX));
        let chosen = lenders
            .filter_map(|k| frames.get(k, at.normal_of[k]))
            .find_map(|t| orthogonalise(Vec3::new(t[0], t[1], t[2]), n).map(|v| [v.x, v.y, v.z, t[3]]));
        repaired.push(match chosen {
            Some(f) => {
                counts.borrowed += 1;
                f
            }
            None => {
                let w = if original.is_some_and(|t| t[3] < 0.0) { -1.0 } else { 1.0 };
                let v = any_orthogonal(n);
                [v.x, v.y, v.z, w]
            }
        });
    }
    for (&c, v) in bad.iter().zip(repaired) {
        frames.set(c, v);
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `repair` on frames with `None` as `w = 0`, one normal per corner.
    fn fix(f: &[Option<[f32; 4]>], normals: &[Vec3], vertex: &[u32]) -> (Vec<[f32; 4]>, FallbackCounts) {
        let n: Vec<[f32; 3]> = normals.iter().map(|v| v.to_array()).collect();
        let ids: Vec<u32> = (0..n.len() as u32).collect();
        let mut frames = Frames::from_flat(&ids, f.iter().map(|t| t.unwrap_or([0.0; 4])).collect());
        let c = repair(&mut frames, CornerNormals { normals: &n, normal_of: &ids, vertex });
        (frames.to_flat(&ids), c)
    }

    #[test]
    fn undefined_corner_borrows_from_its_triangle() {
        let n = Vec3::Z;
        let f = vec![Some([1.0, 0.0, 0.0, -1.0]), None, Some([0.0, 0.0, 1.0, 1.0])];
        let (out, c) = fix(&f, &[n, n, n], &[0, 1, 2]);
        assert_eq!(out[1], [1.0, 0.0, 0.0, -1.0]);
        // Parallel to the normal: invalid, borrows the first corner's tangent.
        assert_eq!(out[2], [1.0, 0.0, 0.0, -1.0]);
        assert_eq!(c, FallbackCounts { undefined: 1, invalid: 1, borrowed: 2 });
    }

    #[test]
    fn lone_corner_gets_an_axis_orthogonal_to_its_normal() {
        let n = Vec3::new(1.0, 1.0, 0.0).normalize();
        let f = vec![None, None, None];
        let (out, c) = fix(&f, &[n, n, n], &[0, 1, 2]);
        for t in out {
            assert!(is_valid(t, n), "{t:?}");
        }
        assert_eq!(c.undefined, 3);
        assert_eq!(c.borrowed, 0);
    }

    #[test]
    fn thresholds_are_relative_to_scale() {
        // A microscopic triangle's unnormalised normal and tangent: still a valid frame.
        let n = Vec3::new(0.0, 0.0, 1e-30);
        assert_eq!(unit(n), Some(Vec3::Z));
        assert_eq!(orthogonalise(Vec3::new(1e-25, 0.0, 1e-25), n), Some(Vec3::X));
        assert!(is_valid([1.0, 0.0, 0.0, 1.0], n));
        assert_eq!(any_orthogonal(n), Vec3::X);
        // Huge vectors do not overflow.
        let big = Vec3::new(3e38, 3e38, 0.0);
        assert!((unit(big).unwrap().length() - 1.0).abs() < 1e-6);
        assert!(orthogonalise(big, Vec3::Z).is_some());
        // Nearly parallel (within the tolerance) is parallel, whatever the length.
        assert_eq!(orthogonalise(Vec3::new(1e-4, 0.0, 1.0) * 1e-20, Vec3::Z), None);
        assert!(orthogonalise(Vec3::new(1e-2, 0.0, 1.0) * 1e-20, Vec3::Z).is_some());
        assert_eq!(unit(Vec3::ZERO), None);
        assert_eq!(unit(Vec3::new(f32::NAN, 0.0, 1.0)), None);
        assert_eq!(orthogonalise(Vec3::X, Vec3::ZERO), None);
    }

    #[test]
    fn reasons_are_counted_apart_and_w_follows_the_lender_or_the_reference() {
        let n = Vec3::Z;
        // Triangle 0: one valid corner (w = -1), one undefined, one non-unit.
        // Triangle 1: every corner invalid (NaN, w = -1) and no valid corner at its vertices.
        let f = vec![
            Some([0.0, 1.0, 0.0, -1.0]),
            None,
            Some([2.0, 0.0, 0.0, 1.0]),
            Some([f32::NAN, 0.0, 0.0, -1.0]),
            Some([f32::NAN, 0.0, 0.0, -1.0]),
            None,
        ];
        let (out, c) = fix(&f, &[n; 6], &[0, 1, 2, 3, 4, 5]);
        assert_eq!(c, FallbackCounts { undefined: 2, invalid: 3, borrowed: 2 });
        assert_eq!(out[1], [0.0, 1.0, 0.0, -1.0]);
        assert_eq!(out[2], [0.0, 1.0, 0.0, -1.0]);
        assert_eq!(out[3], [1.0, 0.0, 0.0, -1.0], "fixed axis, the reference's w");
        assert_eq!(out[5], [1.0, 0.0, 0.0, 1.0], "fixed axis, +1 without a reference w");
        for t in out {
            assert!(is_valid(t, n));
        }
    }

    #[test]
    fn lender_across_triangles_at_the_same_vertex() {
        let n = Vec3::Y;
        let f = vec![Some([1.0, 0.0, 0.0, 1.0]), None, None, None, None, None];
        // Corner 4 is vertex 0 again: it borrows corner 0's frame through the vertex.
        let (out, c) = fix(&f, &[n; 6], &[0, 1, 2, 3, 0, 5]);
        assert_eq!(out[4], [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(c.undefined, 5);
        assert_eq!(c.borrowed, 3);
    }

    #[test]
    fn zero_normal_still_gives_a_unit_tangent() {
        let v = any_orthogonal(Vec3::ZERO);
        assert_eq!(v, Vec3::X);
    }
}
