//! Texture footprints: how far each UV set moves from one screen sample to the next, which is
//! what a GPU's `dFdx`/`dFdy` give its sampler to choose a mip level.
//!
//! Computed analytically from the triangle's setup rather than by differencing neighbouring
//! samples, so a sample at a triangle's edge (whose neighbour lies on another triangle or on
//! nothing) gets the same answer as one in the middle. Perspective-correct attributes are
//! `u = Σ lᵢ qᵢ uᵢ / Σ lᵢ qᵢ` with `lᵢ` the screen-linear barycentrics and `qᵢ = 1/wᵢ`, so
//! `∂u/∂x = w · Σ (∂lᵢ/∂x) qᵢ (uᵢ - u)`, `w` the sample's clip `w` (its view depth).

use super::gather::Draw;
use super::raster::{Prim, Sample};
use super::texture::Footprint;
use glam::{DVec2, Vec2};

/// The derivatives of both UV sets per screen sample (zero for a set the draw lacks).
pub fn footprints(p: &Prim, d: &Draw, tri: [u32; 3], s: &Sample) -> [Footprint; 2] {
    let [a, b, c] = p.v.map(|v| DVec2::new(v[0] as f64, v[1] as f64));
    let area = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    // ∂lᵢ/∂(x, y) from the edge functions the rasteriser evaluates.
    let dl = [
        DVec2::new(-(c.y - b.y), c.x - b.x) / area,
        DVec2::new(-(a.y - c.y), a.x - c.x) / area,
        DVec2::new(-(b.y - a.y), b.x - a.x) / area,
    ];
    let q = p.v.map(|v| v[3] as f64);
    let local = [1.0 - s.b[0] as f64 - s.b[1] as f64, s.b[0] as f64, s.b[1] as f64];
    let depth = s.depth as f64;
    std::array::from_fn(|set| {
        let uvs = &d.uvs[set];
        if uvs.is_empty() || !area.is_finite() || area == 0.0 {
            return Footprint::default();
        }
        // UVs at the prim's own corners (a clipped piece's corners lie inside the triangle).
        let corner = |k: usize| -> DVec2 {
            let w = p.whole_bary_of_corner(k);
            (0..3).map(|i| uvs[tri[i] as usize].as_dvec2() * w[i] as f64).sum()
        };
        let uv_k = [corner(0), corner(1), corner(2)];
        let uv: DVec2 = (0..3).map(|k| uv_k[k] * local[k]).sum();
        let (mut dx, mut dy) = (DVec2::ZERO, DVec2::ZERO);
        for k in 0..3 {
            let rel = (uv_k[k] - uv) * q[k];
            dx += rel * dl[k].x;
            dy += rel * dl[k].y;
        }
        let f = Footprint { dx: (dx * depth).as_vec2(), dy: (dy * depth).as_vec2() };
        if f.dx.is_finite() && f.dy.is_finite() {
            f
        } else {
            Footprint { dx: Vec2::ZERO, dy: Vec2::ZERO }
        }
    })
}
