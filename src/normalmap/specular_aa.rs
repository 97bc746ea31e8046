//! Specular antialiasing: the roughness a normal map's mip level must carry so that what the
//! level's averaging loses (bumps smaller than a texel) stays in the material instead of vanishing.
//!
//! A level-k texel of the normal map is the mean of the level-0 unit normals under it; its length
//! `L` falls below 1 as they spread. Renderers normalise the sampled normal again and draw a
//! surface smoother and shinier than the full-resolution one. Toksvig's estimate of the spread,
//! `variance = (1 - L) / L`, widens the level's GGX roughness as Kaplanyan and Tokuyoshi's normal
//! filtering does in Unity HDRP (`NormalFiltering`) and Filament (`normalFiltering`):
//!
//! `a' = sqrt(saturate(a^2 + min(2 * variance, threshold^2)))`, with `a = roughness^2`.
//!
//! The threshold caps the widening (HDRP and Filament both default to 0.2): a footprint whose
//! normals cancel (`L` near 0) would otherwise turn the material fully rough.
//!
//! The roughness under a level-k texel is itself a mix of level-0 lobes. Lobe widths add as
//! variances, so the level's base is the footprint's mean of `a^2` (not of roughness), the same
//! footprints the normal level used ([`super::mips::scalar_levels`]).

use super::mips::{self, MipLevel};
use serde::Serialize;

/// The widening cap when none is given: HDRP's and Filament's default.
pub const DEFAULT_THRESHOLD: f32 = 0.2;

/// Toksvig's variance of the normals under a texel whose mean normal has length `len`.
pub fn variance(len: f32) -> f32 {
    let l = len.clamp(1e-6, 1.0);
    (1.0 - l) / l
}

/// The roughness (perceptual, as glTF stores it) of a texel whose lobes have mean `a^2` of
/// `alpha_sq` and whose mean normal has length `len`.
pub fn widen(alpha_sq: f32, len: f32, threshold: f32) -> f32 {
    let added = (2.0 * variance(len)).min(threshold * threshold);
    (alpha_sq + added).clamp(0.0, 1.0).sqrt().sqrt()
}

/// One level of the widened roughness chain.
#[derive(Clone, Debug, PartialEq)]
pub struct RoughnessLevel {
    pub width: usize,
    pub height: usize,
    /// Perceptual roughness per texel, row-major from the top row.
    pub roughness: Vec<f32>,
    /// What the footprint's own roughness would be without the normal map's variance.
    pub base: Vec<f32>,
}

/// What specular antialiasing added to one level, for the report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RoughnessAdded {
    pub level: usize,
    /// Mean and largest roughness added over the level's texels.
    pub mean: f64,
    pub max: f64,
}

/// The roughness chain for a normal chain: `roughness0` is the level-0 perceptual roughness at
/// the normal map's resolution (row-major, one value per texel).
pub fn roughness_levels(normals: &[MipLevel], roughness0: &[f32], threshold: f32) -> Vec<RoughnessLevel> {
    let Some(first) = normals.first() else { return Vec::new() };
    let (w, h) = (first.width, first.height);
    assert_eq!(roughness0.len(), w * h, "one roughness per level-0 texel");
    let alpha_sq: Vec<f32> = roughness0.iter().map(|&r| r.clamp(0.0, 1.0).powi(4)).collect();
    mips::scalar_levels(&alpha_sq, w, h)
        .into_iter()
        .zip(normals)
        .map(|(base_sq, n)| {
            let roughness = base_sq.iter().zip(&n.mean_length).map(|(&a2, &l)| widen(a2, l, threshold)).collect();
            let base = base_sq.iter().map(|&a2| a2.clamp(0.0, 1.0).sqrt().sqrt()).collect();
            RoughnessLevel { width: n.width, height: n.height, roughness, base }
        })
        .collect()
}

/// Per level, the roughness added over the footprint's own.
pub fn added(levels: &[RoughnessLevel]) -> Vec<RoughnessAdded> {
    levels
        .iter()
        .enumerate()
        .map(|(k, l)| {
            let d: Vec<f64> = l.roughness.iter().zip(&l.base).map(|(&r, &b)| (r - b) as f64).collect();
            let mean = d.iter().sum::<f64>() / d.len().max(1) as f64;
            RoughnessAdded { level: k, mean, max: d.iter().copied().fold(0.0, f64::max) }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_footprint_keeps_its_roughness() {
        for r in [0.0f32, 0.15, 0.5, 1.0] {
            assert!((widen(r.powi(4), 1.0, DEFAULT_THRESHOLD) - r).abs() < 1e-6, "{r}");
        }
    }

    /// Worked by hand: roughness 0.15 under normals of mean length 0.99 (2·variance 0.0202, under the cap 0.04).
    #[test]
    fn widening_follows_the_formula() {
        let var = (1.0 - 0.99f64) / 0.99;
        let a = 0.15f64 * 0.15;
        let want = (a * a + 2.0 * var).sqrt().sqrt();
        assert!((widen(0.15f32.powi(4), 0.99, DEFAULT_THRESHOLD) as f64 - want).abs() < 1e-6);
        assert!((variance(0.5) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn the_threshold_caps_the_widening() {
        // Normals that cancel: alpha' = sqrt(a^2 + t^2), so roughness' = (a^2 + t^2)^(1/4).
        let t = 0.2f32;
        let want = (0.15f32.powi(4) + t * t).sqrt().sqrt();
        assert!((widen(0.15f32.powi(4), 0.0, t) - want).abs() < 1e-6);
        assert!(widen(1.0, 0.0, 1.0) <= 1.0);
    }

    /// A checkerboard of ±30° tilts: every level above 0 has L = cos 30°, so its roughness is the
    /// widened one, and level 0 is the input.
    #[test]
    fn levels_widen_by_the_normal_levels_variance() {
        let t = 30f32.to_radians();
        let (a, b) = ([t.sin(), 0.0, t.cos()], [-t.sin(), 0.0, t.cos()]);
        let n: Vec<[f32; 3]> = (0..64).map(|i| if (i % 8 + i / 8) % 2 == 0 { a } else { b }).collect();
        let normals = mips::build(&n, 8, 8);
        let r = roughness_levels(&normals, &[0.3; 64], 1.0);
        assert_eq!(r.len(), 4);
        assert!(r[0].roughness.iter().all(|&v| (v - 0.3).abs() < 1e-6));
        let want = widen(0.3f32.powi(4), t.cos(), 1.0);
        for l in &r[1..] {
            assert!(l.roughness.iter().all(|&v| (v - want).abs() < 1e-5), "{:?}", l.roughness);
            assert!(l.base.iter().all(|&v| (v - 0.3).abs() < 1e-5));
        }
        let add = added(&r);
        assert_eq!(add[0].max, 0.0);
        assert!((add[1].mean - (want - 0.3) as f64).abs() < 1e-5);
    }

    /// Lobes mix as variances: half 0.2 and half 0.6 is (mean of a^2)^(1/4), not 0.4.
    #[test]
    fn a_mixed_footprint_averages_alpha_squared() {
        let n = vec![[0.0f32, 0.0, 1.0]; 2];
        let normals = mips::build(&n, 2, 1);
        let r = roughness_levels(&normals, &[0.2, 0.6], DEFAULT_THRESHOLD);
        let want = ((0.2f32.powi(4) + 0.6f32.powi(4)) / 2.0).sqrt().sqrt();
        assert!((r[1].roughness[0] - want).abs() < 1e-6);
    }

    /// A unit normal's length can fall an ulp short of 1; level 0 must not read that as spread,
    /// or a mirror (roughness 0) would leave at 0.02.
    #[test]
    fn level_0_keeps_a_mirror_a_mirror() {
        let rgb: Vec<u8> = (0..64 * 64u32).flat_map(|i| [(i * 37 % 256) as u8, (i * 91 % 256) as u8, 250]).collect();
        let short = mips::unit_normals(&rgb).iter().any(|n| {
            let l = n.iter().map(|&c| c as f64 * c as f64).sum::<f64>().sqrt();
            (l as f32) < 1.0
        });
        assert!(short, "the sample has no unit normal an ulp short");
        let r = roughness_levels(&mips::build_rgb(&rgb, 64, 64), &[0.0; 64 * 64], DEFAULT_THRESHOLD);
        assert!(r[0].roughness.iter().all(|&v| v == 0.0));
        assert!(r[1].roughness.iter().all(|&v| v > 0.0));
    }
}
