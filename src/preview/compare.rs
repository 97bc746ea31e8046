//! Pipeline error: how far a cheap asset (coarse mesh + normal map + tangents) renders from the
//! true surface (fine geometry with its own normals), seen from the same camera.
//!
//! The measure is the angle between the two renders' shading normals per pixel, plus the PSNR of
//! the shaded images and the ratio of their mean brightness. The two renders may differ in
//! options too ([`compare_with`]): a supersampled truth without mips against what a renderer
//! draws with them. Pixels near silhouettes are left out: there the two meshes legitimately
//! cover different pixels (the normal map cannot move an outline), and one bad outline pixel
//! would otherwise dominate the maximum.

use super::{render, Camera, Frame, Options, Prepared, View};
use crate::scene::Scene;
use crate::Result;
use serde::Serialize;

/// What the difference image shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DiffKind {
    /// Shading-normal angle as a heat ramp: black 0°, red 5°, yellow 10°, white 20° and over.
    #[default]
    Angle,
    /// Absolute difference of the shaded images, times 4.
    Shaded,
}

/// Summary of per-pixel angles, in degrees.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct AngleStats {
    pub mean: f64,
    pub p95: f64,
    pub max: f64,
}

/// The result of [`compare`].
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Comparison {
    pub width: u32,
    pub height: u32,
    /// Pixels both renders cover fully, away from silhouettes and depth discontinuities.
    pub pixels_compared: usize,
    /// Covered by at least one render but left out as silhouette or discontinuity.
    pub pixels_excluded: usize,
    /// Shading-normal angle between the renders (`None` when no pixel was compared).
    pub normal_angle_deg: Option<AngleStats>,
    /// PSNR of the 8-bit shaded images over the compared pixels (`None` when identical or empty).
    pub psnr_db: Option<f64>,
    /// Mean 8-bit display value (all three channels) over the compared pixels, of the reference
    /// and of the candidate (`None` when no pixel was compared).
    pub mean_reference: Option<f64>,
    pub mean_candidate: Option<f64>,
    /// `mean_candidate / mean_reference`: above 1, the candidate draws brighter.
    pub brightness_ratio: Option<f64>,
    /// Mean relative luminance (Rec. 709 weights of the 8-bit values decoded to linear) over the
    /// compared pixels: the light that reaches the eye, which a prefiltered texture can keep and
    /// which display values bend (a truth that varies from pixel to pixel has a darker mean
    /// display value than its smooth mean, by the sRGB curve's bend).
    pub mean_luminance_reference: Option<f64>,
    pub mean_luminance_candidate: Option<f64>,
    /// `mean_luminance_candidate / mean_luminance_reference`.
    pub luminance_ratio: Option<f64>,
}

/// Pixels within this many of an edge are not compared.
pub const EDGE_MARGIN: i64 = 2;
/// Neighbouring depths that differ by more than this fraction are a discontinuity.
pub const DEPTH_JUMP: f32 = 0.02;

/// Renders `reference` and `candidate` shaded from a camera framed on the reference and measures
/// the difference; returns the numbers and the difference image.
pub fn compare(reference: &Scene, candidate: &Scene, opts: &Options, kind: DiffKind) -> Result<(Comparison, Frame)> {
    compare_with(reference, opts, candidate, opts, kind)
}

/// [`compare`] with the reference rendered with its own options (mips, supersampling); size,
/// camera, lights and view are `opts`'.
pub fn compare_with(
    reference: &Scene,
    reference_opts: &Options,
    candidate: &Scene,
    opts: &Options,
    kind: DiffKind,
) -> Result<(Comparison, Frame)> {
    opts.check()?;
    reference_opts.check()?;
    let a = Prepared::new(reference)?;
    let b = Prepared::new(candidate)?;
    let cam = Camera::framed(a.bounds, &opts.camera, opts.width, opts.height);
    let o = Options { view: View::Shaded, ..opts.clone() };
    let ro = Options { mips: reference_opts.mips, ssaa: reference_opts.ssaa, ..o.clone() };
    let fa = render(&a, &cam, &ro);
    let fb = render(&b, &cam, &o);
    Ok(measure(&fa, &fb, kind))
}

/// Which pixels are compared.
pub fn mask(a: &Frame, b: &Frame) -> Vec<bool> {
    let (w, h) = (a.width as i64, a.height as i64);
    let idx = |x: i64, y: i64| (y * w + x) as usize;
    let full = |f: &Frame, i: usize| f.coverage[i] >= 1.0;
    let mut edge = vec![false; (w * h) as usize];
    for y in 0..h {
        for x in 0..w {
            let i = idx(x, y);
            let mut e = full(a, i) != full(b, i);
            for (dx, dy) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || ny < 0 || nx >= w || ny >= h {
                    continue;
                }
                let j = idx(nx, ny);
                for f in [a, b] {
                    if full(f, i) != full(f, j)
                        || (full(f, i) && (f.depth[i] - f.depth[j]).abs() > DEPTH_JUMP * f.depth[i])
                    {
                        e = true;
                    }
                }
            }
            edge[i] = e;
        }
    }
    let mut ok = vec![false; (w * h) as usize];
    for y in 0..h {
        for x in 0..w {
            let i = idx(x, y);
            if !(full(a, i) && full(b, i)) {
                continue;
            }
            let mut near = false;
            'n: for ny in (y - EDGE_MARGIN).max(0)..=(y + EDGE_MARGIN).min(h - 1) {
                for nx in (x - EDGE_MARGIN).max(0)..=(x + EDGE_MARGIN).min(w - 1) {
                    if edge[idx(nx, ny)] {
                        near = true;
                        break 'n;
                    }
                }
            }
            ok[i] = !near;
        }
    }
    ok
}

fn angle_deg(a: glam::Vec3, b: glam::Vec3) -> f64 {
    let (a, b) = (a.as_dvec3().normalize_or_zero(), b.as_dvec3().normalize_or_zero());
    a.cross(b).length().atan2(a.dot(b)).to_degrees()
}

fn heat(deg: f64) -> [f32; 3] {
    let t = (deg / 20.0).clamp(0.0, 1.0) as f32;
    // black -> red (5°) -> yellow (10°) -> white (20°)
    let r = (t * 4.0).min(1.0);
    let g = ((t - 0.25) * 4.0).clamp(0.0, 1.0);
    let b = ((t - 0.5) * 2.0).clamp(0.0, 1.0);
    [r, g, b]
}

/// Statistics and difference image of two frames of the same size.
pub fn measure(a: &Frame, b: &Frame, kind: DiffKind) -> (Comparison, Frame) {
    let ok = mask(a, b);
    let mut angles = Vec::new();
    let mut se = 0.0f64;
    let (mut sum_a, mut sum_b) = (0.0f64, 0.0f64);
    let (mut lum_a, mut lum_b) = (0.0f64, 0.0f64);
    let mut diff = Frame {
        width: a.width,
        height: a.height,
        rgb: Vec::new(),
        normal: Vec::new(),
        coverage: Vec::new(),
        depth: Vec::new(),
    };
    let mut excluded = 0;
    let q = |x: f32| (x.clamp(0.0, 1.0) * 255.0).round() as f64;
    let luminance = |c: [f32; 3]| -> f64 {
        [0.2126, 0.7152, 0.0722]
            .iter()
            .zip(c)
            .map(|(w, x)| w * super::texture::srgb_to_linear((q(x) / 255.0) as f32) as f64)
            .sum()
    };
    for (i, &both) in ok.iter().enumerate() {
        let covered = a.coverage[i] > 0.0 || b.coverage[i] > 0.0;
        let c = if both {
            let deg = angle_deg(a.normal[i], b.normal[i]);
            angles.push(deg);
            lum_a += luminance(a.rgb[i]);
            lum_b += luminance(b.rgb[i]);
            for k in 0..3 {
                se += (q(a.rgb[i][k]) - q(b.rgb[i][k])).powi(2);
                sum_a += q(a.rgb[i][k]);
                sum_b += q(b.rgb[i][k]);
            }
            match kind {
                DiffKind::Angle => heat(deg),
                DiffKind::Shaded => [0, 1, 2].map(|k| ((a.rgb[i][k] - b.rgb[i][k]).abs() * 4.0).min(1.0)),
            }
        } else if covered {
            excluded += 1;
            [0.3, 0.3, 0.32]
        } else {
            super::views::BACKGROUND
        };
        diff.rgb.push(c);
        diff.normal.push(glam::Vec3::ZERO);
        diff.coverage.push(ok[i] as u8 as f32);
        diff.depth.push(f32::INFINITY);
    }
    let n = angles.len();
    let stats = (n > 0).then(|| {
        let mean = angles.iter().sum::<f64>() / n as f64;
        let max = angles.iter().cloned().fold(0.0, f64::max);
        let mut sorted = angles.clone();
        sorted.sort_by(|x, y| x.total_cmp(y));
        let p95 = sorted[((n as f64 * 0.95).ceil() as usize).clamp(1, n) - 1];
        AngleStats { mean, p95, max }
    });
    let mse = if n > 0 { se / (3 * n) as f64 } else { 0.0 };
    let psnr = (mse > 0.0).then(|| 10.0 * (255.0f64 * 255.0 / mse).log10());
    let mean = |sum: f64| (n > 0).then(|| sum / (3 * n) as f64);
    let (mean_a, mean_b) = (mean(sum_a), mean(sum_b));
    let (lum_a, lum_b) = (mean(3.0 * lum_a), mean(3.0 * lum_b));
    (
        Comparison {
            width: a.width,
            height: a.height,
            pixels_compared: n,
            pixels_excluded: excluded,
            normal_angle_deg: stats,
            psnr_db: psnr,
            mean_reference: mean_a,
            mean_candidate: mean_b,
            brightness_ratio: mean_a.zip(mean_b).filter(|(a, _)| *a > 0.0).map(|(a, b)| b / a),
            mean_luminance_reference: lum_a,
            mean_luminance_candidate: lum_b,
            luminance_ratio: lum_a.zip(lum_b).filter(|(a, _)| *a > 0.0).map(|(a, b)| b / a),
        },
        diff,
    )
}
