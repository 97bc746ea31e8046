//! Visibility: which triangle covers each sample, and where on it.
//!
//! The rasteriser only resolves visibility (a "visibility buffer"); shading happens afterwards,
//! once per visible sample. That keeps the cost of the seeds' per-fragment model independent of
//! overdraw, and it makes the output deterministic: tiles are rasterised in parallel, but each
//! tile visits its triangles in scene order and keeps the first of equal depths.
//!
//! Coverage uses edge functions in `f64` on `f32` inputs, where every product is exact, so the
//! two triangles that share an edge compute exactly opposite values on it: no cracks, no
//! double-shaded seams that depend on the order of evaluation.

use super::camera::Camera;
use super::gather::{Draw, Material};
use glam::{Vec3, Vec4};
use rayon::prelude::*;

/// No triangle at this sample.
pub const EMPTY: u32 = u32::MAX;

/// What one sample sees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Index into [`Raster::prims`], or [`EMPTY`].
    pub prim: u32,
    /// Perspective-correct barycentrics of vertices 1 and 2 (vertex 0 gets the rest).
    pub b: [f32; 2],
    /// View-space distance along the view axis (clip `w`).
    pub depth: f32,
}

const NONE: Sample = Sample { prim: EMPTY, b: [0.0; 2], depth: f32::INFINITY };

/// A screen-space triangle: either a whole scene triangle or a piece of one cut by the near plane.
#[derive(Debug, Clone)]
pub struct Prim {
    /// Per vertex: screen x, screen y (pixels, y down), NDC z, 1/w.
    pub v: [[f32; 4]; 3],
    pub draw: u32,
    pub tri: u32,
    /// The camera sees its back (only kept for double-sided materials).
    pub back: bool,
    /// For pieces of a clipped triangle: barycentrics of each piece vertex in the whole triangle.
    pub sub: Option<Box<[Vec3; 3]>>,
}

impl Prim {
    /// Barycentrics in the scene triangle from barycentrics in this piece.
    pub fn whole_bary(&self, b: [f32; 2]) -> Vec3 {
        let local = Vec3::new(1.0 - b[0] - b[1], b[0], b[1]);
        match &self.sub {
            None => local,
            Some(s) => s[0] * local.x + s[1] * local.y + s[2] * local.z,
        }
    }

    /// Barycentrics in the scene triangle of this prim's corner `k`.
    pub fn whole_bary_of_corner(&self, k: usize) -> Vec3 {
        match &self.sub {
            None => [Vec3::X, Vec3::Y, Vec3::Z][k],
            Some(s) => s[k],
        }
    }
}

/// The visibility buffer of one image.
#[derive(Debug, Clone)]
pub struct Raster {
    pub width: u32,
    pub height: u32,
    pub prims: Vec<Prim>,
    /// Row-major, `width * height`.
    pub samples: Vec<Sample>,
}

const TILE: u32 = 32;

/// Rasterises every draw as `cam` sees it into a `width` x `height` sample grid.
pub fn rasterise(draws: &[Draw], materials: &[Material], cam: &Camera, width: u32, height: u32) -> Raster {
    let prims = setup_all(draws, materials, cam, width, height);
    let samples = resolve(&prims, width, 0..height);
    Raster { width, height, prims, samples }
}

/// Every triangle that may be seen, as screen-space prims of a `width` x `height` sample grid.
pub fn setup_all(draws: &[Draw], materials: &[Material], cam: &Camera, width: u32, height: u32) -> Vec<Prim> {
    let (wf, hf) = (width as f32, height as f32);
    let clip: Vec<Vec<Vec4>> =
        draws.par_iter().map(|d| d.positions.par_iter().map(|&p| cam.clip(p)).collect()).collect();
    draws
        .par_iter()
        .enumerate()
        .flat_map(|(di, d)| {
            let two_sided = materials.get(d.material).map(|m| m.double_sided).unwrap_or(false);
            let clip = &clip[di];
            d.triangles.par_iter().enumerate().flat_map_iter(move |(ti, t)| {
                let c = [clip[t[0] as usize], clip[t[1] as usize], clip[t[2] as usize]];
                setup(c, wf, hf).into_iter().filter_map(move |(v, sub)| {
                    let area = (v[1][0] - v[0][0]) as f64 * (v[2][1] - v[0][1]) as f64
                        - (v[2][0] - v[0][0]) as f64 * (v[1][1] - v[0][1]) as f64;
                    // Screen y points down, so glTF's counter-clockwise front faces have area < 0.
                    let back = area > 0.0;
                    if area == 0.0 || !area.is_finite() || (back && !two_sided) {
                        return None;
                    }
                    Some(Prim { v, draw: di as u32, tri: ti as u32, back, sub })
                })
            })
        })
        .collect()
}

/// The samples of rows `rows` of a grid `width` wide (row-major, `rows.len() * width`). Each
/// sample's answer depends only on the prims' order, so resolving an image in bands of rows gives
/// the same samples as resolving it whole.
pub fn resolve(prims: &[Prim], width: u32, rows: std::ops::Range<u32>) -> Vec<Sample> {
    let (top, height) = (rows.start, rows.end);
    let (tx, ty) = (width.div_ceil(TILE), (height - top).div_ceil(TILE));
    let mut bins: Vec<Vec<u32>> = vec![Vec::new(); (tx * ty) as usize];
    for (i, p) in prims.iter().enumerate() {
        let Some((x0, y0, x1, y1)) = pixel_box(p, width, height) else { continue };
        if y1 < top {
            continue;
        }
        let y0 = y0.max(top);
        for by in (y0 - top) / TILE..=(y1 - top) / TILE {
            for bx in x0 / TILE..=x1 / TILE {
                bins[(by * tx + bx) as usize].push(i as u32);
            }
        }
    }
    let tiles: Vec<Vec<Sample>> = bins
        .par_iter()
        .enumerate()
        .map(|(k, bin)| {
            let (bx, by) = (k as u32 % tx, k as u32 / tx);
            let y0 = top + by * TILE;
            raster_tile(prims, bin, bx * TILE, y0, (bx * TILE + TILE).min(width), (y0 + TILE).min(height))
        })
        .collect();
    let mut samples = vec![NONE; (width * (height - top)) as usize];
    for (k, tile) in tiles.iter().enumerate() {
        let (bx, by) = (k as u32 % tx, k as u32 / tx);
        let (x0, y0) = (bx * TILE, by * TILE);
        let tw = (x0 + TILE).min(width) - x0;
        for (r, row) in tile.chunks(tw as usize).enumerate() {
            let at = ((y0 + r as u32) * width + x0) as usize;
            samples[at..at + tw as usize].copy_from_slice(row);
        }
    }
    samples
}

/// Inclusive pixel range a triangle may cover, or `None` when it misses the image.
fn pixel_box(p: &Prim, width: u32, height: u32) -> Option<(u32, u32, u32, u32)> {
    let xs = [p.v[0][0], p.v[1][0], p.v[2][0]];
    let ys = [p.v[0][1], p.v[1][1], p.v[2][1]];
    let (minx, maxx) =
        (xs.iter().cloned().fold(f32::INFINITY, f32::min), xs.iter().cloned().fold(f32::NEG_INFINITY, f32::max));
    let (miny, maxy) =
        (ys.iter().cloned().fold(f32::INFINITY, f32::min), ys.iter().cloned().fold(f32::NEG_INFINITY, f32::max));
    // Sample centres are at +0.5: the first centre >= min is ceil(min - 0.5).
    let x0 = (minx - 0.5).ceil().max(0.0);
    let y0 = (miny - 0.5).ceil().max(0.0);
    let x1 = (maxx - 0.5).floor().min(width as f32 - 1.0);
    let y1 = (maxy - 0.5).floor().min(height as f32 - 1.0);
    (x0 <= x1 && y0 <= y1).then_some((x0 as u32, y0 as u32, x1 as u32, y1 as u32))
}

fn raster_tile(prims: &[Prim], bin: &[u32], tx0: u32, ty0: u32, tx1: u32, ty1: u32) -> Vec<Sample> {
    let tw = (tx1 - tx0) as usize;
    let mut out = vec![NONE; tw * (ty1 - ty0) as usize];
    let mut zbuf = vec![f32::INFINITY; out.len()];
    for &pi in bin {
        let p = &prims[pi as usize];
        let Some((x0, y0, x1, y1)) = pixel_box(p, tx1, ty1) else { continue };
        let (x0, y0) = (x0.max(tx0), y0.max(ty0));
        if x0 > x1 || y0 > y1 {
            continue;
        }
        let [a, b, c] = p.v;
        let (ax, ay, bx, by, cx, cy) = (a[0] as f64, a[1] as f64, b[0] as f64, b[1] as f64, c[0] as f64, c[1] as f64);
        let area = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay);
        let inv_area = 1.0 / area;
        for py in y0..=y1 {
            let sy = py as f64 + 0.5;
            for px in x0..=x1 {
                let sx = px as f64 + 0.5;
                let e0 = (cx - bx) * (sy - by) - (cy - by) * (sx - bx);
                let e1 = (ax - cx) * (sy - cy) - (ay - cy) * (sx - cx);
                let e2 = (bx - ax) * (sy - ay) - (by - ay) * (sx - ax);
                let (l0, l1, l2) = (e0 * inv_area, e1 * inv_area, e2 * inv_area);
                if l0 < 0.0 || l1 < 0.0 || l2 < 0.0 {
                    continue;
                }
                let z = (l0 * a[2] as f64 + l1 * b[2] as f64 + l2 * c[2] as f64) as f32;
                let k = (py - ty0) as usize * tw + (px - tx0) as usize;
                if !(-1.0..=1.0).contains(&z) || z >= zbuf[k] {
                    continue;
                }
                // Perspective-correct: interpolate attribute/w and 1/w linearly in screen space.
                let (q0, q1, q2) = (l0 * a[3] as f64, l1 * b[3] as f64, l2 * c[3] as f64);
                let s = q0 + q1 + q2;
                if s <= 0.0 || !s.is_finite() {
                    continue;
                }
                zbuf[k] = z;
                out[k] = Sample { prim: pi, b: [(q1 / s) as f32, (q2 / s) as f32], depth: (1.0 / s) as f32 };
            }
        }
    }
    out
}

type Piece = ([[f32; 4]; 3], Option<Box<[Vec3; 3]>>);

/// Clips a clip-space triangle against the near plane (`z > -w`) and maps it to the screen.
/// Triangles wholly outside one frustum plane are dropped; the others are left to the depth
/// test and the pixel box.
fn setup(c: [Vec4; 3], w: f32, h: f32) -> Vec<Piece> {
    if c.iter().any(|v| !v.is_finite()) {
        return Vec::new();
    }
    let out = |f: &dyn Fn(Vec4) -> bool| c.iter().all(|&v| f(v));
    if out(&|v| v.x > v.w)
        || out(&|v| v.x < -v.w)
        || out(&|v| v.y > v.w)
        || out(&|v| v.y < -v.w)
        || out(&|v| v.z > v.w)
        || out(&|v| v.z < -v.w)
    {
        return Vec::new();
    }
    let screen = |v: Vec4| -> [f32; 4] {
        let iw = 1.0 / v.w;
        [(v.x * iw * 0.5 + 0.5) * w, (0.5 - v.y * iw * 0.5) * h, v.z * iw, iw]
    };
    let d: [f32; 3] = [c[0].z + c[0].w, c[1].z + c[1].w, c[2].z + c[2].w];
    if d.iter().all(|&x| x >= 0.0) {
        return vec![([screen(c[0]), screen(c[1]), screen(c[2])], None)];
    }
    // Sutherland-Hodgman on one plane, carrying barycentrics of the whole triangle.
    let bary = [Vec3::X, Vec3::Y, Vec3::Z];
    let mut poly: Vec<(Vec4, Vec3)> = Vec::with_capacity(4);
    for i in 0..3 {
        let j = (i + 1) % 3;
        if d[i] >= 0.0 {
            poly.push((c[i], bary[i]));
        }
        if (d[i] >= 0.0) != (d[j] >= 0.0) {
            let t = d[i] / (d[i] - d[j]);
            poly.push((c[i].lerp(c[j], t), bary[i].lerp(bary[j], t)));
        }
    }
    let mut pieces = Vec::new();
    for k in 1..poly.len().saturating_sub(1) {
        let (p0, p1, p2) = (poly[0], poly[k], poly[k + 1]);
        if p0.0.w <= 0.0 || p1.0.w <= 0.0 || p2.0.w <= 0.0 {
            continue;
        }
        pieces.push(([screen(p0.0), screen(p1.0), screen(p2.0)], Some(Box::new([p0.1, p1.1, p2.1]))));
    }
    pieces
}
