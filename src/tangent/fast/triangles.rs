//! Per-triangle first-order tangents and the reference's triangle order: non-degenerate
//! triangles first, then degenerate ones, each in input order.

use super::math::{length, normalized_or_zero, not_zero, scale, sub, V3};
use super::Corners;
use rayon::prelude::*;

/// Per-triangle state, indexed by the *internal* triangle index (position in [`Self::order`]).
pub(crate) struct Triangles {
    /// Internal index -> input face index. The first `n_good` are non-degenerate.
    pub order: Order,
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
    orient: bool,
    gwa: bool,
}

/// The unnormalised first-order tangent and bitangent of face `f`, and twice its signed UV area.
#[inline]
fn raw(c: &Corners, f: usize) -> (V3, V3, f32) {
    let v = [c.pos(3 * f), c.pos(3 * f + 1), c.pos(3 * f + 2)];
    let tx = [c.uv(3 * f), c.uv(3 * f + 1), c.uv(3 * f + 2)];
    let d_tx = [[tx[1][0] - tx[0][0], tx[1][1] - tx[0][1]], [tx[2][0] - tx[0][0], tx[2][1] - tx[0][1]]];
    let d_v = [sub(v[1], v[0]), sub(v[2], v[0])];
    let signed_area_double = d_tx[0][0] * d_tx[1][1] - d_tx[0][1] * d_tx[1][0];
    let s = sub(scale(d_tx[1][1], d_v[0]), scale(d_tx[0][1], d_v[1]));
    let t = {
        let a = scale(-d_tx[1][0], d_v[0]);
        let b = scale(d_tx[0][0], d_v[1]);
        [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
    };
    (s, t, signed_area_double)
}

/// `s` and `t` normalised and signed by the UV orientation, zero where the area vanishes.
#[inline]
fn signed_unit(s: V3, t: V3, signed_area_double: f32) -> (V3, V3) {
    if not_zero(signed_area_double.abs()) {
        let sign = if signed_area_double > 0.0 { 1.0f32 } else { -1.0f32 };
        (scale(sign, normalized_or_zero(s)), scale(sign, normalized_or_zero(t)))
    } else {
        ([0.0; 3], [0.0; 3])
    }
}

/// `generate_triangle_info_list` of the reference, for one non-degenerate triangle, less the
/// first-order vectors ([`first_order`]).
fn info(c: &Corners, f: usize) -> Info {
    let (s, t, signed_area_double) = raw(c, f);
    let area_double = signed_area_double.abs();
    let gwa = !(not_zero(area_double) && not_zero(length(s) / area_double) && not_zero(length(t) / area_double));
    Info { orient: signed_area_double > 0.0, gwa }
}

/// The reference's triangle order: internal index -> input face. Not stored when no triangle is
/// degenerate (the order is then the input's).
pub(crate) struct Order {
    faces: Vec<u32>,
    n: usize,
}

impl Order {
    #[inline]
    pub(crate) fn at(&self, t: usize) -> u32 {
        if self.faces.is_empty() {
            t as u32
        } else {
            self.faces[t]
        }
    }
    pub(crate) fn len(&self) -> usize {
        self.n
    }
}

impl Triangles {
    pub(crate) fn build(c: &Corners) -> Self {
        let n_faces = c.n_faces();
        let degen: Vec<bool> = (0..n_faces).into_par_iter().map(|f| degenerate(c, f)).collect();
        let n_good = degen.iter().filter(|&&d| !d).count();
        let mut faces = Vec::new();
        if n_good < n_faces {
            faces.reserve_exact(n_faces);
            faces.extend((0..n_faces).filter(|&f| !degen[f]).map(|f| f as u32));
            faces.extend((0..n_faces).filter(|&f| degen[f]).map(|f| f as u32));
        }
        let order = Order { faces, n: n_faces };
        // The first-order vectors are not kept (24 bytes a triangle, the engine's largest
        // array): the sums recompute them from the corners, which costs less than the memory.
        let (orient, gwa): (Vec<bool>, Vec<bool>) = (0..n_good)
            .into_par_iter()
            .map(|t| {
                let i = info(c, order.at(t) as usize);
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
    let (s, t, a) = raw(c, f);
    signed_unit(s, t, a)
}
