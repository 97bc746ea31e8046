//! OBJ's smoothing groups (`s N`, `s off`): in a file without `vn`, which faces share their
//! corners' normals. They become normals and per-corner normal indices, as `vn` lines would have
//! been, so every reader after this one (the Scene, HIGH) takes them as the file's own.

use crate::format::mesh::{Statement, StoredMesh};
use crate::scene::normals::grouped_normals;

/// The group of the faces before a file's first `s`: smooth together, as every face of a file
/// without `s` is.
const BEFORE_ANY: u64 = u64::MAX;

/// Each triangle's smoothing group (0: none, the face flat), when the groups say more than "all
/// smooth together": a face in no group, or faces in two groups or more.
fn groups(statements: &[(u32, Statement)], triangles: usize) -> Option<Vec<u64>> {
    if !statements.iter().any(|(_, s)| matches!(s, Statement::Smooth(_))) {
        return None;
    }
    let mut out = vec![BEFORE_ANY; triangles];
    let (mut current, mut from) = (BEFORE_ANY, 0);
    for (at, s) in statements {
        if let Statement::Smooth(g) = s {
            let at = (*at as usize).min(triangles);
            out[from..at].fill(current);
            (current, from) = (*g, at);
        }
    }
    out[from..].fill(current);
    let first = *out.first()?;
    (first == 0 || out.iter().any(|&g| g != first)).then_some(out)
}

/// Gives `d` the normals its smoothing groups describe, when it has no `vn` and its groups say
/// more than "all smooth together" (otherwise the reader's smooth normals are those already);
/// returns how many of them had no direction (only faces without area) and point along +Z.
pub fn normals_from_groups(d: &mut StoredMesh) -> usize {
    if !d.normals.is_empty() {
        return 0;
    }
    let Some(g) = groups(&d.statements, d.triangles.len()) else { return 0 };
    let (normals, index, fixed) = grouped_normals(&d.positions, &d.triangles, &g);
    (d.normals, d.normal_triangles) = (normals, index);
    fixed
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::obj::parse::parse_bytes;
    use std::path::Path;

    fn read(s: &str) -> StoredMesh {
        let mut d = parse_bytes(Path::new("t.obj"), s.as_bytes(), &Default::default()).unwrap();
        normals_from_groups(&mut d);
        d
    }

    /// Two faces of a roof meeting at a ridge, 90 degrees apart, and a corner's normal.
    const ROOF: &str = "v 0 0 0\nv 1 0 0\nv 1 1 1\nv 0 1 1\nv 1 2 0\nv 0 2 0\n";

    fn corner(d: &StoredMesh, t: usize, k: usize) -> [f32; 3] {
        d.normals[d.normal_triangles[t][k] as usize]
    }

    #[test]
    fn one_group_shares_normals_across_the_ridge() {
        // Two groups, so the normals are made here; the ridge's faces are both in group 1.
        let d = read(&format!("{ROOF}s 2\nf 1 2 3\ns 1\nf 1 3 4\nf 4 3 5\nf 4 5 6\n"));
        let h = std::f32::consts::FRAC_1_SQRT_2;
        // Vertex 3 (index 2) on the ridge: the two slopes' normals weighted by the faces' angles
        // there (54.7 and 90 degrees), the same from both faces.
        let (a, b) = ((1.0f32 / 3f32.sqrt()).acos(), std::f32::consts::FRAC_PI_2);
        let want = (glam::Vec3::new(0.0, -h, h) * a + glam::Vec3::new(0.0, h, h) * b).normalize();
        let ridge = corner(&d, 1, 1);
        assert!((glam::Vec3::from(ridge) - want).length() < 1e-6, "{ridge:?} {want}");
        assert_eq!(d.normal_triangles[1][1], d.normal_triangles[2][1]);
        // Group 2's face keeps its own normal at the same vertex: the first slope's.
        let own = corner(&d, 0, 2);
        assert!((own[1] + h).abs() < 1e-6 && (own[2] - h).abs() < 1e-6, "{own:?}");
    }

    #[test]
    fn off_makes_faces_flat_and_one_group_changes_nothing() {
        let d = read(&format!("{ROOF}s off\nf 1 2 3\nf 1 3 4\nf 4 3 5\nf 4 5 6\n"));
        let h = std::f32::consts::FRAC_1_SQRT_2;
        for t in 0..4 {
            let want = if t < 2 { [0.0, -h, h] } else { [0.0, h, h] };
            for k in 0..3 {
                let n = corner(&d, t, k);
                assert!((0..3).all(|a| (n[a] - want[a]).abs() < 1e-6), "face {t}: {n:?}");
            }
        }
        // `s 1` everywhere, `s 0` read as `off`, junk read as none (as Blender does).
        assert!(read(&format!("{ROOF}s 1\nf 1 2 3\nf 1 3 4\n")).normals.is_empty());
        assert_eq!(read(&format!("{ROOF}s 0\nf 1 2 3\nf 1 3 4\n")).normals.len(), 2);
        assert_eq!(read(&format!("{ROOF}s junk\nf 1 2 3\nf 1 3 4\n")).normals.len(), 2);
        // A file's own `vn` win.
        let vn = read(&format!("{ROOF}vn 0 0 1\ns off\nf 1//1 2//1 3//1\n"));
        assert_eq!(vn.normals, vec![[0.0, 0.0, 1.0]]);
    }

    #[test]
    fn faces_before_the_first_s_are_smooth_together() {
        let d = read(&format!("{ROOF}f 1 2 3\nf 1 3 4\ns off\nf 4 3 5\nf 4 5 6\n"));
        let up = corner(&d, 0, 2);
        let h = std::f32::consts::FRAC_1_SQRT_2;
        // Vertex 3 in the first two faces (one plane): their normal; the flat faces' own after.
        assert!((up[1] + h).abs() < 1e-6 && (up[2] - h).abs() < 1e-6, "{up:?}");
        assert_eq!(d.normals.len(), 4 + 2);
    }
}
