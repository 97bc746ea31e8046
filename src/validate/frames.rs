//! Checks on the stored frames alone (no UVs needed): what every renderer assumes of a TANGENT
//! before it builds a bitangent from it, plus degenerate triangles.
//!
//! Vertices that fail here are marked bad, and the corners of triangles with mixed `w` are marked
//! explained, so that the handedness and conformance checks after these do not report the same
//! broken data a second time under another name.

use super::{Code, Example, Finding, Subject, Worst};
use glam::DVec3;

/// The Khronos glTF-Validator's unit-length tolerance for VEC3 data (`|len - 1|`).
pub const KHRONOS_UNIT_TOLERANCE: f64 = 0.00674;
/// |cos| between tangent and normal above which the tangent counts as parallel (about 8°).
pub const PARALLEL_COS: f64 = 0.99;
/// |cos| between tangent and normal above which it is not orthogonal (1°, the default
/// conformance threshold: a frame tilted further shades visibly differently).
pub const ORTHO_COS: f64 = 0.017452406;

/// The per-primitive data every check reads: a triangle list, decoded to floats once.
#[derive(Debug, Clone, Default)]
pub struct PrimData {
    pub positions: Vec<[f32; 3]>,
    pub normals: Option<Vec<[f32; 3]>>,
    /// The UV set the normal texture reads.
    pub uvs: Option<Vec<[f32; 2]>>,
    pub tangents: Option<Vec<[f32; 4]>>,
    /// Three per triangle, each in range.
    pub indices: Vec<u32>,
    /// How coarsely the file stores what the checks compare (zero for floats).
    pub quant: Quant,
}

/// Quantization steps (KHR_mesh_quantization) of the data a frame check compares, each in the
/// units the check sees (positions as decoded, UVs after the normal texture's transform). A stored
/// value is within half a step of the value that was quantized; the checks widen their tolerances
/// by exactly what that explains (docs/validate.md derives each bound) and by nothing more.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Quant {
    pub position: f64,
    pub normal: f64,
    pub uv: f64,
    pub tangent: f64,
}

impl Quant {
    /// The largest angle between a unit vector and its quantized copy: each of three components
    /// moves by at most half a step, so the vector by `sqrt(3)/2 * step`.
    pub fn vector_angle(step: f64) -> f64 {
        (3f64.sqrt() / 2.0 * step).min(1.0).asin()
    }

    /// The most a quantized unit vector's length can differ from 1.
    pub fn unit_slack(&self) -> f64 {
        3f64.sqrt() / 2.0 * self.tangent
    }

    /// The angle the stored tangent and normal may each be off by.
    pub fn frame_angle(&self) -> f64 {
        Self::vector_angle(self.tangent) + Self::vector_angle(self.normal)
    }

    /// Per vertex, the angle (radians) by which the triangles around it may turn their MikkTSpace
    /// direction because their corners were rounded, and per triangle whether rounding may have
    /// flipped its orientation in UV space (and so its `w`).
    ///
    /// A triangle's tangent is the direction along which u grows; moving one corner by `e` turns
    /// it, to first order, by at most `e / h` where `h` is the altitude from that corner, so three
    /// corners give at most `3 e / h_min`. In UV space `e = sqrt(2)/2 * step`, in space
    /// `e = sqrt(3)/2 * step`. Its orientation can flip only if a corner can cross the opposite
    /// side, that is `h_min <= 2 e` in UV space. MikkTSpace averages the triangles around a
    /// vertex, and around every other vertex at the same position, so each vertex takes the
    /// largest turn of all of those. Empty when nothing is quantized.
    pub fn slack(&self, positions: &[[f32; 3]], uvs: &[[f32; 2]], indices: &[u32]) -> (Vec<f64>, Vec<bool>) {
        if self.position == 0.0 && self.uv == 0.0 {
            return (Vec::new(), Vec::new());
        }
        let e_uv = 2f64.sqrt() / 2.0 * self.uv;
        let e_p = 3f64.sqrt() / 2.0 * self.position;
        let mut turn = vec![0.0f64; positions.len()];
        let mut may_flip = Vec::with_capacity(indices.len() / 3);
        for t in indices.chunks_exact(3) {
            let [a, b, c] = [t[0] as usize, t[1] as usize, t[2] as usize];
            let h_p = min_altitude([positions[a], positions[b], positions[c]].map(d3));
            let h_uv = min_altitude([uvs[a], uvs[b], uvs[c]].map(|v| DVec3::new(v[0] as f64, v[1] as f64, 0.0)));
            may_flip.push(h_uv <= 2.0 * e_uv);
            let x = 3.0 * e_p / h_p + 3.0 * e_uv / h_uv;
            let x = if x.is_finite() { x.min(std::f64::consts::PI) } else { std::f64::consts::PI };
            for v in [a, b, c] {
                turn[v] = turn[v].max(x);
            }
        }
        let mut by_position: std::collections::HashMap<[u32; 3], f64> = std::collections::HashMap::new();
        for (p, &x) in positions.iter().zip(&turn) {
            let m = by_position.entry(p.map(f32::to_bits)).or_insert(0.0);
            *m = m.max(x);
        }
        for (p, x) in positions.iter().zip(turn.iter_mut()) {
            *x = by_position[&p.map(f32::to_bits)];
        }
        (turn, may_flip)
    }
}

/// The smallest altitude of a triangle: twice its area over its longest side (0 if degenerate).
fn min_altitude(p: [DVec3; 3]) -> f64 {
    let area2 = (p[1] - p[0]).cross(p[2] - p[0]).length();
    let longest = (p[1] - p[0]).length().max((p[2] - p[1]).length()).max((p[0] - p[2]).length());
    if longest > 0.0 {
        area2 / longest
    } else {
        0.0
    }
}

/// What earlier checks already explained, so later ones skip it.
#[derive(Debug, Clone)]
pub struct Explained {
    pub bad_vertex: Vec<bool>,
    pub corner: Vec<bool>,
    /// Triangles with zero area in space or in UV space: they have no defined frame.
    pub degenerate_tri: Vec<bool>,
}

impl Explained {
    pub fn new(vertices: usize, corners: usize) -> Self {
        Explained {
            bad_vertex: vec![false; vertices],
            corner: vec![false; corners],
            degenerate_tri: vec![false; corners / 3],
        }
    }
    /// True when a corner is left for the checks that come after.
    pub fn open(&self, c: usize, v: usize) -> bool {
        !self.corner[c] && !self.bad_vertex[v] && !self.degenerate_tri[c / 3]
    }
}

fn d3(v: [f32; 3]) -> DVec3 {
    DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
}

fn fmt_t(t: [f32; 4]) -> String {
    format!("({:.4}, {:.4}, {:.4}, w {})", t[0], t[1], t[2], t[3])
}

/// A vector as `(x, y, z)`, however many components.
fn fmt_v(v: &[f32]) -> String {
    let parts: Vec<String> = v.iter().map(|x| format!("{x:.4}")).collect();
    format!("({})", parts.join(", "))
}

/// Finite, unit, `w = ±1`, not parallel to and orthogonal to the normal: per vertex.
pub fn check_vectors(d: &PrimData, ex: &mut Explained, s: &mut Subject) {
    let Some(t) = &d.tangents else { return };
    let n = t.len();
    let (mut nonfinite, mut nonunit, mut badw, mut parallel, mut skew) = (0, 0, 0, 0, 0);
    let (mut w_nf, mut w_nu, mut w_w, mut w_par, mut w_skew) =
        (Worst::default(), Worst::default(), Worst::default(), Worst::default(), Worst::default());
    let mut worst_skew_deg = 0.0f64;
    let unit_tol = KHRONOS_UNIT_TOLERANCE.max(d.quant.unit_slack());
    // Quantized tangents and normals each lean by up to their step's angle.
    let ortho_cos = (ORTHO_COS.asin() + d.quant.frame_angle()).min(std::f64::consts::FRAC_PI_2).sin();
    for (v, &tv) in t.iter().enumerate() {
        let ex_v = |detail: String| Example { kind: "vertex", index: v as u64, at: None, detail };
        if !tv.iter().all(|x| x.is_finite()) {
            nonfinite += 1;
            ex.bad_vertex[v] = true;
            w_nf.push(1.0, || ex_v(format!("tangent {}", fmt_t(tv))));
            continue;
        }
        let xyz = d3([tv[0], tv[1], tv[2]]);
        let len = xyz.length();
        if (len - 1.0).abs() > unit_tol {
            nonunit += 1;
            ex.bad_vertex[v] = true;
            w_nu.push((len - 1.0).abs(), || ex_v(format!("tangent {} has length {len:.5}", fmt_t(tv))));
        }
        if tv[3] != 1.0 && tv[3] != -1.0 {
            badw += 1;
            ex.bad_vertex[v] = true;
            w_w.push((tv[3].abs() as f64 - 1.0).abs(), || ex_v(format!("w = {}", tv[3])));
        }
        let Some(normals) = &d.normals else { continue };
        let nv = d3(normals[v]);
        if ex.bad_vertex[v] || !nv.is_finite() || nv.length() == 0.0 || len == 0.0 {
            continue;
        }
        let cos = (xyz.dot(nv) / (len * nv.length())).abs();
        if cos > PARALLEL_COS {
            parallel += 1;
            ex.bad_vertex[v] = true;
            w_par.push(cos, || {
                ex_v(format!(
                    "tangent {} vs normal {}: {:.2}° apart",
                    fmt_t(tv),
                    fmt_v(&normals[v]),
                    cos.min(1.0).acos().to_degrees()
                ))
            });
        } else if cos > ortho_cos {
            skew += 1;
            ex.bad_vertex[v] = true;
            let off = cos.min(1.0).asin().to_degrees();
            worst_skew_deg = worst_skew_deg.max(off);
            w_skew.push(cos, || {
                ex_v(format!("tangent {} is {off:.2}° off the plane of normal {}", fmt_t(tv), fmt_v(&normals[v])))
            });
        }
    }
    s.check(
        Code::TANGENT_NOT_FINITE,
        (nonfinite > 0).then(|| {
            Finding::new(
                Code::TANGENT_NOT_FINITE,
                nonfinite,
                n,
                "vertices",
                format!("{nonfinite} of {n} tangents contain NaN or infinity"),
            )
            .examples(w_nf.into_examples())
        }),
    );
    s.check(
        Code::TANGENT_NOT_UNIT,
        (nonunit > 0).then(|| {
            Finding::new(
                Code::TANGENT_NOT_UNIT,
                nonunit,
                n,
                "vertices",
                format!("{nonunit} of {n} tangents are not unit length (|len - 1| > {unit_tol:.5})"),
            )
            .examples(w_nu.into_examples())
        }),
    );
    s.check(
        Code::TANGENT_W_INVALID,
        (badw > 0).then(|| {
            Finding::new(
                Code::TANGENT_W_INVALID,
                badw,
                n,
                "vertices",
                format!("{badw} of {n} tangents have w other than +1.0 or -1.0"),
            )
            .examples(w_w.into_examples())
        }),
    );
    if d.normals.is_some() {
        s.check(
            Code::TANGENT_PARALLEL_NORMAL,
            (parallel > 0).then(|| {
                Finding::new(
                    Code::TANGENT_PARALLEL_NORMAL,
                    parallel,
                    n,
                    "vertices",
                    format!("{parallel} of {n} tangents are (nearly) parallel to their normal: the frame collapses"),
                )
                .examples(w_par.into_examples())
            }),
        );
        s.check(Code::TANGENT_NOT_ORTHOGONAL, (skew > 0).then(|| {
            Finding::new(Code::TANGENT_NOT_ORTHOGONAL, skew, n, "vertices", format!("{skew} of {n} tangents are more than 1° off the plane orthogonal to their normal (worst {worst_skew_deg:.2}°)"))
                .examples(w_skew.into_examples())
                .metric("max_angle_deg", worst_skew_deg)
        }));
    }
}

/// Triangles whose three corners do not share one `w`: interpolation shrinks and flips the
/// bitangent across the triangle.
pub fn check_w_mixed(d: &PrimData, ex: &mut Explained, s: &mut Subject) {
    let Some(t) = &d.tangents else { return };
    let mut count = 0;
    let mut worst = Worst::default();
    let tris = d.indices.len() / 3;
    for (k, tri) in d.indices.chunks_exact(3).enumerate() {
        if tri.iter().any(|&v| ex.bad_vertex[v as usize]) || ex.corner[3 * k..3 * k + 3].iter().any(|&c| c) {
            continue;
        }
        let w = [t[tri[0] as usize][3], t[tri[1] as usize][3], t[tri[2] as usize][3]];
        if w[0] != w[1] || w[1] != w[2] {
            count += 1;
            ex.corner[3 * k..3 * k + 3].iter_mut().for_each(|c| *c = true);
            worst.push(1.0 / (1.0 + k as f64), || Example {
                kind: "triangle",
                index: k as u64,
                at: None,
                detail: format!("vertices {} {} {} have w {} {} {}", tri[0], tri[1], tri[2], w[0], w[1], w[2]),
            });
        }
    }
    s.check(
        Code::TANGENT_W_MIXED,
        (count > 0).then(|| {
            Finding::new(
                Code::TANGENT_W_MIXED,
                count,
                tris,
                "triangles",
                format!("{count} of {tris} triangles have corners with different w: the bitangent flips inside them"),
            )
            .examples(worst.into_examples())
        }),
    );
}

/// Zero-area, zero-UV-area (when `with_uvs`: the UVs belong to a normal texture) and sliver
/// triangles. Marks the first two as having no defined frame.
pub fn check_degenerate(d: &PrimData, with_uvs: bool, ex: &mut Explained, s: &mut Subject) {
    let uvs = d.uvs.as_ref().filter(|_| with_uvs);
    let tris = d.indices.len() / 3;
    let (mut zero, mut zero_uv, mut sliver) = (0, 0, 0);
    let (mut wz, mut wu, mut ws) = (Worst::default(), Worst::default(), Worst::default());
    for (k, tri) in d.indices.chunks_exact(3).enumerate() {
        let p = [d3(d.positions[tri[0] as usize]), d3(d.positions[tri[1] as usize]), d3(d.positions[tri[2] as usize])];
        let (e1, e2, e3) = (p[1] - p[0], p[2] - p[0], p[2] - p[1]);
        let area2 = e1.cross(e2).length();
        let sum_sq = e1.length_squared() + e2.length_squared() + e3.length_squared();
        let tri_ex = |detail: String| Example { kind: "triangle", index: k as u64, at: None, detail };
        if sum_sq == 0.0 || area2 <= 1e-12 * sum_sq {
            zero += 1;
            ex.degenerate_tri[k] = true;
            wz.push(1.0 / (1.0 + k as f64), || tri_ex(format!("vertices {} {} {}", tri[0], tri[1], tri[2])));
            continue;
        }
        // 1 for an equilateral triangle, 0 for a needle.
        let quality = 2.0 * 3f64.sqrt() * area2 / sum_sq;
        if quality < 1e-3 {
            sliver += 1;
            ws.push(1.0 / quality, || {
                tri_ex(format!("vertices {} {} {}, quality {quality:.2e} (1 = equilateral)", tri[0], tri[1], tri[2]))
            });
        }
        if let Some(uv) = uvs {
            let t = [uv[tri[0] as usize], uv[tri[1] as usize], uv[tri[2] as usize]];
            let (a, b) = (
                [(t[1][0] - t[0][0]) as f64, (t[1][1] - t[0][1]) as f64],
                [(t[2][0] - t[0][0]) as f64, (t[2][1] - t[0][1]) as f64],
            );
            let cross = (a[0] * b[1] - a[1] * b[0]).abs();
            let scale = a[0] * a[0] + a[1] * a[1] + b[0] * b[0] + b[1] * b[1];
            if !cross.is_finite() || scale == 0.0 || cross <= 1e-12 * scale {
                zero_uv += 1;
                ex.degenerate_tri[k] = true;
                wu.push(1.0 / (1.0 + k as f64), || {
                    tri_ex(format!(
                        "vertices {} {} {}, UVs {} {} {}",
                        tri[0],
                        tri[1],
                        tri[2],
                        fmt_v(&t[0]),
                        fmt_v(&t[1]),
                        fmt_v(&t[2])
                    ))
                });
            }
        }
    }
    s.check(
        Code::TRIANGLE_DEGENERATE,
        (zero > 0).then(|| {
            Finding::new(
                Code::TRIANGLE_DEGENERATE,
                zero,
                tris,
                "triangles",
                format!("{zero} of {tris} triangles have zero area"),
            )
            .examples(wz.into_examples())
        }),
    );
    if uvs.is_some() {
        s.check(
            Code::TRIANGLE_UV_DEGENERATE,
            (zero_uv > 0).then(|| {
                Finding::new(
                    Code::TRIANGLE_UV_DEGENERATE,
                    zero_uv,
                    tris,
                    "triangles",
                    format!("{zero_uv} of {tris} triangles have zero area in the normal map's UV space"),
                )
                .examples(wu.into_examples())
            }),
        );
    }
    s.check(
        Code::TRIANGLE_SLIVER,
        (sliver > 0).then(|| {
            Finding::new(
                Code::TRIANGLE_SLIVER,
                sliver,
                tris,
                "triangles",
                format!("{sliver} of {tris} triangles are slivers (quality below 1e-3)"),
            )
            .examples(ws.into_examples())
        }),
    );
}
