//! Per-triangle first-order tangents and the reference's triangle order: non-degenerate
//! triangles first, then degenerate ones, each in input order.

use super::math::{length, normalized_or_zero, not_zero, scale, sub, V3};
use super::Corners;
use rayon::prelude::*;

/// Per-triangle state, indexed by the *internal* triangle index (position in [`Self::order`]).
pub(crate) struct Triangles {
    /// Internal index -> input face index. The first `n_good` are non-degenerate.
    pub order: Vec<u32>,
    pub n_good: usize,
    /// UV orientation (`signed area > 0`). Mutable: "group with anything" triangles take the
    /// orientation of the first group that reaches them.
    pub orient: Vec<bool>,
    /// "Group with anything": the UV mapping gives this triangle no usable tangent.
    pub gwa: Vec<bool>,
}

/// A triangle is degenerate when two of its corner positions compare equal (f32 `==`).
fn degenerate(c: &Corners, f: usize) -> bool {
    let p = [c.pos(3 * f), c.pos(3 * f + 1), c.pos(3 * f + 2)];
    p[0] == p[1] || p[1] == p[2] || p[2] == p[0]
}

struct Info {
    s: V3,
    t: V3,
    orient: bool,
    gwa: bool,
}

/// `generate_triangle_info_list` of the reference, for one non-degenerate triangle.
fn info(c: &Corners, f: usize) -> Info {
    let v = [c.pos(3 * f), c.pos(3 * f + 1), c.pos(3 * f + 2)];
    let tx = [c.uv(3 * f), c.uv(3 * f + 1), c.uv(3 * f + 2)];
    let d_tx = [
        [tx[1][0] - tx[0][0], tx[1][1] - tx[0][1]],
        [tx[2][0] - tx[0][0], tx[2][1] - tx[0][1]],
    ];
    let d_v = [sub(v[1], v[0]), sub(v[2], v[0])];
    let signed_area_double = d_tx[0][0] * d_tx[1][1] - d_tx[0][1] * d_tx[1][0];
    let area_double = signed_area_double.abs();
    let s = sub(scale(d_tx[1][1], d_v[0]), scale(d_tx[0][1], d_v[1]));
    let t = {
        let a = scale(-d_tx[1][0], d_v[0]);
        let b = scale(d_tx[0][0], d_v[1]);
        [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
    };
    let orient = signed_area_double > 0.0;
    let mut out = Info { s: [0.0; 3], t: [0.0; 3], orient, gwa: true };
    if not_zero(area_double) {
        let sign = if orient { 1.0f32 } else { -1.0f32 };
        out.s = scale(sign, normalized_or_zero(s));
        out.t = scale(sign, normalized_or_zero(t));
        let s_mag = length(s) / area_double;
        let t_mag = length(t) / area_double;
        if not_zero(s_mag) && not_zero(t_mag) {
            out.gwa = false;
        }
    }
    out
}

impl Triangles {
    pub(crate) fn build(c: &Corners) -> Self {
        let n_faces = c.n_faces();
        let degen: Vec<bool> = (0..n_faces).into_par_iter().map(|f| degenerate(c, f)).collect();
        let n_good = degen.iter().filter(|&&d| !d).count();
        let mut order = Vec::with_capacity(n_faces);
        order.extend((0..n_faces).filter(|&f| !degen[f]).map(|f| f as u32));
        order.extend((0..n_faces).filter(|&f| degen[f]).map(|f| f as u32));
        // The first-order vectors are not kept (24 bytes a triangle, the engine's largest
        // array): the sums recompute them from the corners, which costs less than the memory.
        let (orient, gwa): (Vec<bool>, Vec<bool>) = order[..n_good]
            .par_iter()
            .map(|&f| {
                let i = info(c, f as usize);
                (i.orient, i.gwa)
            })
            .unzip();
        Triangles { order, n_good, orient, gwa }
    }
}

/// Normalised, orientation-signed first-order tangent (`s`) and bitangent (`t`) of input face
/// `f` (non-degenerate); zero where the UV area vanishes. Recomputed on each call, bit for bit
/// the same every time.
#[inline]
pub(crate) fn first_order(c: &Corners, f: usize) -> (V3, V3) {
    let i = info(c, f);
    (i.s, i.t)
}
