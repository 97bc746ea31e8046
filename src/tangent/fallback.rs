//! Making every frame usable. MikkTSpace has no answer for some corners (degenerate triangles
//! with no neighbour to borrow from) and can give frames that are not orthogonal to a normal that
//! is not unit length. Each such corner gets a unit tangent orthogonal to its normal, borrowed from
//! a neighbour where one exists (keeping its handedness), otherwise built from the axis least
//! aligned with the normal. Every substitution is counted.

use glam::Vec3;

/// Tolerances a frame must meet to leave the tool unchanged.
pub const UNIT_TOLERANCE: f32 = 1e-4;
pub const ORTHO_TOLERANCE: f32 = 1e-3;

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
    let v = Vec3::new(t[0], t[1], t[2]);
    let n = n.normalize_or_zero();
    v.is_finite()
        && (v.length() - 1.0).abs() <= UNIT_TOLERANCE
        && (t[3] == 1.0 || t[3] == -1.0)
        && n != Vec3::ZERO
        && v.dot(n).abs() <= ORTHO_TOLERANCE
}

/// The unit vector orthogonal to `n` nearest to `t`, if `t` is far enough from parallel.
pub fn orthogonalise(t: Vec3, n: Vec3) -> Option<Vec3> {
    let n = n.normalize_or_zero();
    let p = t - n * n.dot(t);
    let len = p.length();
    (len.is_finite() && len > 1e-3 * t.length().max(f32::MIN_POSITIVE)).then(|| p / len).filter(|v| v.is_finite())
}

/// A unit vector orthogonal to `n`, from the coordinate axis least aligned with it.
pub fn any_orthogonal(n: Vec3) -> Vec3 {
    let n = n.normalize_or_zero();
    if n == Vec3::ZERO || !n.is_finite() {
        return Vec3::X;
    }
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

/// Replaces every unusable corner frame. `frames` and `normals` are per corner (three per
/// triangle); `vertex` gives each corner's vertex, so that corners of one vertex can lend to
/// each other. Frames already carry the output's `w` convention.
pub fn repair(frames: &mut [Option<[f32; 4]>], normals: &[Vec3], vertex: &[u32]) -> (Vec<[f32; 4]>, FallbackCounts) {
    let mut counts = FallbackCounts::default();
    let ok: Vec<bool> = frames.iter().zip(normals).map(|(f, &n)| f.map(|t| is_valid(t, n)).unwrap_or(false)).collect();
    // First valid corner of each vertex, to lend from across triangles.
    let n_vertices = vertex.iter().map(|&v| v as usize + 1).max().unwrap_or(0);
    let mut by_vertex = vec![usize::MAX; n_vertices];
    for (c, &good) in ok.iter().enumerate() {
        if good && by_vertex[vertex[c] as usize] == usize::MAX {
            by_vertex[vertex[c] as usize] = c;
        }
    }
    let mut out = Vec::with_capacity(frames.len());
    for c in 0..frames.len() {
        if ok[c] {
            out.push(frames[c].expect("valid frames exist"));
            continue;
        }
        match frames[c] {
            None => counts.undefined += 1,
            Some(_) => counts.invalid += 1,
        }
        let n = normals[c];
        let tri = c / 3 * 3;
        let lenders = (tri..tri + 3).filter(|&k| k != c && ok[k]).chain(Some(by_vertex[vertex[c] as usize]).filter(|&k| k != usize::MAX));
        let mut chosen = None;
        for k in lenders {
            let t = frames[k].expect("valid frames exist");
            if let Some(v) = orthogonalise(Vec3::new(t[0], t[1], t[2]), n) {
                chosen = Some([v.x, v.y, v.z, t[3]]);
                break;
            }
        }
        match chosen {
            Some(f) => {
                counts.borrowed += 1;
                out.push(f);
            }
            None => {
                let w = frames[c].map(|t| if t[3] < 0.0 { -1.0 } else { 1.0 }).unwrap_or(1.0);
                let v = any_orthogonal(n);
                out.push([v.x, v.y, v.z, w]);
            }
        }
    }
    (out, counts)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn undefined_corner_borrows_from_its_triangle() {
        let n = Vec3::Z;
        let mut f = vec![Some([1.0, 0.0, 0.0, -1.0]), None, Some([0.0, 0.0, 1.0, 1.0])];
        let (out, c) = repair(&mut f, &[n, n, n], &[0, 1, 2]);
        assert_eq!(out[1], [1.0, 0.0, 0.0, -1.0]);
        // Parallel to the normal: invalid, borrows the first corner's tangent.
        assert_eq!(out[2], [1.0, 0.0, 0.0, -1.0]);
        assert_eq!(c, FallbackCounts { undefined: 1, invalid: 1, borrowed: 2 });
    }

    #[test]
    fn lone_corner_gets_an_axis_orthogonal_to_its_normal() {
        let n = Vec3::new(1.0, 1.0, 0.0).normalize();
        let mut f = vec![None, None, None];
        let (out, c) = repair(&mut f, &[n, n, n], &[0, 1, 2]);
        for t in out {
            assert!(is_valid(t, n), "{t:?}");
        }
        assert_eq!(c.undefined, 3);
        assert_eq!(c.borrowed, 0);
    }

    #[test]
    fn zero_normal_still_gives_a_unit_tangent() {
        let v = any_orthogonal(Vec3::ZERO);
        assert_eq!(v, Vec3::X);
    }
}
