//! Handedness: does `w` agree with the triangle's orientation in the normal texture's UV space?
//!
//! The conventions define the bitangent as `B = cross(N, t) * w`, and the shader multiplies the
//! map's `+Y` (image up) by it, so `B` must point the way the image's up direction runs across the
//! triangle. glTF's UVs run v down (OBJ's are turned so at load), so up is `-dP/dv`.
//!
//! MikkTSpace decides the sign from the UV winding alone, which is the same thing when the triangle
//! is wound counter-clockwise around its normals. On a triangle wound against its own normals the
//! two disagree; there the expected sign is left undefined rather than accusing either.

use super::frames::{Explained, PrimData};
use super::{Code, Example, Finding, Subject, Worst};
use glam::{DVec2, DVec3};

/// |cos| of (cross(N, T), B_up) below which the orientation is too close to call.
const MIN_ORIENTATION: f64 = 0.05;

fn d3(v: [f32; 3]) -> DVec3 {
    DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
}

/// The `w` each corner should carry (+1, -1) or 0 where the triangle gives no clear answer
/// (degenerate, wound against its normals, missing data).
pub fn expected_w(d: &PrimData, ex: &Explained) -> Vec<i8> {
    let mut out = vec![0i8; d.indices.len()];
    let (Some(uv), Some(normals)) = (&d.uvs, &d.normals) else { return out };
    for (k, tri) in d.indices.chunks_exact(3).enumerate() {
        if ex.degenerate_tri[k] {
            continue;
        }
        let p = [0, 1, 2].map(|j| d3(d.positions[tri[j] as usize]));
        let t = [0, 1, 2].map(|j| DVec2::new(uv[tri[j] as usize][0] as f64, uv[tri[j] as usize][1] as f64));
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let (d1, d2) = (t[1] - t[0], t[2] - t[0]);
        let r = d1.x * d2.y - d2.x * d1.y;
        if r == 0.0 || !r.is_finite() {
            continue;
        }
        let dpdu = (e1 * d2.y - e2 * d1.y) / r;
        let dpdv = (e2 * d1.x - e1 * d2.x) / r;
        let up = -dpdv;
        // MikkTSpace's own answer: positive UV area means orientation preserved (reference sign
        // +1), stored as glTF's `w`.
        let mikk_w = crate::tangent::gltf_w(if r > 0.0 { 1.0 } else { -1.0 }) as i8;
        for (j, &v) in tri.iter().enumerate() {
            let n = d3(normals[v as usize]);
            let b = n.cross(dpdu);
            let denom = b.length() * up.length();
            if denom.is_nan() || denom <= 0.0 || !denom.is_finite() {
                continue;
            }
            let cos = b.dot(up) / denom;
            if cos.abs() < MIN_ORIENTATION {
                continue;
            }
            let geo: i8 = if cos > 0.0 { 1 } else { -1 };
            if geo == mikk_w {
                out[3 * k + j] = geo;
            }
        }
    }
    out
}

/// Mirror seams left shared: one vertex used by triangles of both orientations can hold only one
/// `w`, so one side always shades with its bitangent reversed.
pub fn check_seams(d: &PrimData, expected: &[i8], ex: &mut Explained, s: &mut Subject) {
    let nv = d.positions.len();
    let mut first = vec![[u32::MAX; 2]; nv];
    for (c, &e) in expected.iter().enumerate() {
        let v = d.indices[c] as usize;
        if e == 0 || ex.bad_vertex[v] {
            continue;
        }
        let slot = &mut first[v][if e > 0 { 0 } else { 1 }];
        if *slot == u32::MAX {
            *slot = (c / 3) as u32;
        }
    }
    let oriented = first.iter().filter(|f| f[0] != u32::MAX || f[1] != u32::MAX).count();
    let shared: Vec<bool> = first.iter().map(|f| f[0] != u32::MAX && f[1] != u32::MAX).collect();
    let count = shared.iter().filter(|&&x| x).count();
    let mut worst = Worst::default();
    for (v, f) in first.iter().enumerate().filter(|(v, _)| shared[*v]) {
        worst.push(1.0 / (1.0 + v as f64), || Example {
            kind: "vertex",
            index: v as u64,
            at: None,
            detail: format!("triangle {} needs w = +1 here, triangle {} needs w = -1", f[0], f[1]),
        });
    }
    for (c, &v) in d.indices.iter().enumerate() {
        if shared[v as usize] {
            ex.corner[c] = true;
        }
    }
    s.check(Code::TANGENT_SEAM_SHARED, (count > 0).then(|| {
        Finding::new(Code::TANGENT_SEAM_SHARED, count, oriented, "vertices", format!("{count} of {oriented} vertices are shared by triangles of both UV orientations (an unsplit mirror seam)"))
            .examples(worst.into_examples())
    }));
}

/// Corners whose stored `w` disagrees with the orientation the UVs give the triangle.
pub fn check_w_vs_uv(d: &PrimData, expected: &[i8], ex: &mut Explained, s: &mut Subject) {
    let Some(t) = &d.tangents else { return };
    let (mut count, mut total) = (0, 0);
    let mut worst = Worst::default();
    for (c, &e) in expected.iter().enumerate() {
        let v = d.indices[c] as usize;
        if e == 0 || !ex.open(c, v) {
            continue;
        }
        total += 1;
        let w = t[v][3];
        if (w > 0.0) != (e > 0) {
            count += 1;
            ex.corner[c] = true;
            worst.push(1.0 / (1.0 + c as f64), || Example {
                kind: "corner",
                index: c as u64,
                at: None,
                detail: format!("triangle {} vertex {v}: w = {w}, the UV orientation needs {e:+}", c / 3),
            });
        }
    }
    s.check(Code::TANGENT_W_MISMATCH_UV, (count > 0).then(|| {
        Finding::new(Code::TANGENT_W_MISMATCH_UV, count, total, "corners", format!("{count} of {total} corners have w opposite to their triangle's orientation in UV space: the bitangent points down the image"))
            .examples(worst.into_examples())
    }));
}
