//! glTF's metallic-roughness BRDF for direct lights, as three.js's `MeshStandardMaterial` writes
//! it (`BRDF_GGX` and `BRDF_Lambert` in its `bsdfs` and `lights_physical_pars_fragment` chunks):
//! GGX distribution, height-correlated Smith-GGX visibility, Schlick's Fresnel with
//! `F0 = mix(0.04, baseColor, metallic)` and `F90 = 1`, and a Lambert diffuse lobe of
//! `baseColor * (1 - metallic)` that is not weighted by `1 - F` (three.js does not).
//!
//! Outgoing radiance per light is `(N·L) * color * (diffuse / π + F V D)`: three.js's
//! physically based light units, so a white Lambert surface facing a light of intensity π shows 1.
//!
//! Where three.js differs: it floors roughness at 0.0525 here too, but also adds a
//! "geometry roughness" from the screen-space derivatives of the interpolated vertex normal (zero
//! on a flat surface), and it evaluates Schlick's `(1 - VoH)^5` by a spherical-Gaussian fit.

use glam::Vec3;
use std::f32::consts::PI;

/// The lowest roughness three.js shades with: below it the GGX peak is narrower than a pixel.
pub const MIN_ROUGHNESS: f32 = 0.0525;

/// One fragment's material, after its textures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Surface {
    /// Linear RGB.
    pub base_color: Vec3,
    pub metallic: f32,
    /// Perceptual roughness, as glTF stores it (`alpha = roughness^2`).
    pub roughness: f32,
}

impl Surface {
    /// The colour of the Lambert lobe.
    pub fn diffuse(&self) -> Vec3 {
        self.base_color * (1.0 - self.metallic)
    }

    fn f0(&self) -> Vec3 {
        Vec3::splat(0.04).lerp(self.base_color, self.metallic)
    }

    fn alpha(&self) -> f32 {
        let r = self.roughness.clamp(MIN_ROUGHNESS, 1.0);
        r * r
    }
}

/// GGX (Trowbridge-Reitz) normal distribution.
pub fn d_ggx(alpha: f32, noh: f32) -> f32 {
    let a2 = alpha * alpha;
    let d = noh * noh * (a2 - 1.0) + 1.0;
    a2 / (PI * d * d)
}

/// Height-correlated Smith-GGX visibility, `G / (4 N·L N·V)`.
pub fn v_smith_ggx_correlated(alpha: f32, nol: f32, nov: f32) -> f32 {
    let a2 = alpha * alpha;
    let gv = nol * (a2 + (1.0 - a2) * nov * nov).sqrt();
    let gl = nov * (a2 + (1.0 - a2) * nol * nol).sqrt();
    0.5 / (gv + gl).max(1e-6)
}

/// Schlick's Fresnel with `F90 = 1`.
pub fn f_schlick(f0: Vec3, voh: f32) -> Vec3 {
    let f = (1.0 - voh).clamp(0.0, 1.0).powi(5);
    f0 + (Vec3::ONE - f0) * f
}

/// Radiance towards `v` from a light of unit colour along `l`, for unit `n`, `l`, `v`.
pub fn direct(n: Vec3, l: Vec3, v: Vec3, s: &Surface) -> Vec3 {
    let nol = n.dot(l).clamp(0.0, 1.0);
    if nol <= 0.0 {
        return Vec3::ZERO;
    }
    let h = (l + v).normalize_or_zero();
    let nov = n.dot(v).clamp(0.0, 1.0);
    let noh = n.dot(h).clamp(0.0, 1.0);
    let voh = v.dot(h).clamp(0.0, 1.0);
    let alpha = s.alpha();
    let spec = f_schlick(s.f0(), voh) * (v_smith_ggx_correlated(alpha, nol, nov) * d_ggx(alpha, noh));
    nol * (s.diffuse() / PI + spec)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At normal incidence on a dielectric: D = 1/(π α²), V = 1/(4 α) ... evaluated in closed form.
    #[test]
    fn head_on_dielectric_matches_the_closed_form() {
        let s = Surface { base_color: Vec3::splat(0.5), metallic: 0.0, roughness: 0.5 };
        let a = 0.25f32;
        let want = 0.5 / PI + 0.04 * (1.0 / (PI * a * a)) * (0.5 / 2.0);
        let got = direct(Vec3::Z, Vec3::Z, Vec3::Z, &s);
        assert!((got.x - want).abs() < 1e-5, "{got} vs {want}");
    }

    /// GGX is normalised: ∫ D (n·h) dω = 1 over the hemisphere.
    #[test]
    fn ggx_projects_to_one() {
        let alpha = 0.3f32;
        let n = 20000;
        let mut sum = 0.0f64;
        for i in 0..n {
            let t = (i as f64 + 0.5) / n as f64 * std::f64::consts::FRAC_PI_2;
            sum += d_ggx(alpha, t.cos() as f32) as f64 * t.cos() * t.sin() * 2.0 * std::f64::consts::PI;
        }
        sum *= std::f64::consts::FRAC_PI_2 / n as f64;
        assert!((sum - 1.0).abs() < 1e-3, "{sum}");
    }
}
