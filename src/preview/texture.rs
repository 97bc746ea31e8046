//! Textures as the renderer samples them: decoded once to floats, read with glTF's sampler
//! rules (wrap modes per axis, magnification and minification filters) from a mip chain.
//!
//! The level is chosen as OpenGL and Vulkan choose it for isotropic filtering (`docs/preview.md`,
//! "Mip levels"): `λ = log2(ρ)`, `ρ` the longer of the two texel-space steps one screen sample
//! makes along x and along y. Where the chain comes from is [`Mips`].

use glam::{Vec2, Vec4};
use std::sync::OnceLock;

/// glTF wrap modes (`wrapS`, `wrapT`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Wrap {
    #[default]
    Repeat,
    Clamp,
    Mirror,
}

impl Wrap {
    /// The mode a glTF sampler code names; unknown codes fall back to glTF's default (repeat).
    pub fn from_gl(code: Option<u64>) -> Wrap {
        match code {
            Some(33071) => Wrap::Clamp,
            Some(33648) => Wrap::Mirror,
            _ => Wrap::Repeat,
        }
    }

    /// Maps a texel index onto `0..n`.
    fn apply(self, i: i64, n: i64) -> usize {
        let r = match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Clamp => i.clamp(0, n - 1),
            Wrap::Mirror => {
                let m = i.rem_euclid(2 * n);
                if m >= n {
                    2 * n - 1 - m
                } else {
                    m
                }
            }
        };
        r as usize
    }
}

/// Where a texture's mip levels come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Mips {
    /// Level 0 only, with the magnification filter: what the supersampled truth uses.
    Off,
    /// The renderer's own chain: each level the 2x2 box average of the one above, stored at the
    /// source's precision, as `glGenerateMipmap` (and so three.js) does with a PNG.
    Box,
    /// The file's own levels when it has them (KTX2), else [`Mips::Box`].
    #[default]
    File,
}

/// glTF `minFilter`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MinFilter {
    Nearest,
    Linear,
    NearestMipmapNearest,
    LinearMipmapNearest,
    NearestMipmapLinear,
    /// Trilinear; also what an unspecified `minFilter` gets (three.js and most engines).
    #[default]
    LinearMipmapLinear,
}

impl MinFilter {
    pub fn from_gl(code: Option<u64>) -> MinFilter {
        match code {
            Some(9728) => MinFilter::Nearest,
            Some(9729) => MinFilter::Linear,
            Some(9984) => MinFilter::NearestMipmapNearest,
            Some(9985) => MinFilter::LinearMipmapNearest,
            Some(9986) => MinFilter::NearestMipmapLinear,
            _ => MinFilter::LinearMipmapLinear,
        }
    }

    /// Within a level: nearest texel (or bilinear).
    fn nearest_texel(self) -> bool {
        matches!(self, MinFilter::Nearest | MinFilter::NearestMipmapNearest | MinFilter::NearestMipmapLinear)
    }

    fn mipmapped(self) -> bool {
        !matches!(self, MinFilter::Nearest | MinFilter::Linear)
    }

    /// Between levels: blend the two nearest levels (or take the nearest one).
    fn between_levels(self) -> bool {
        matches!(self, MinFilter::NearestMipmapLinear | MinFilter::LinearMipmapLinear)
    }
}

/// How a texture is read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Sampler {
    pub wrap_s: Wrap,
    pub wrap_t: Wrap,
    /// `magFilter` NEAREST: the author wants hard texel edges.
    pub nearest: bool,
    pub min: MinFilter,
}

impl Sampler {
    /// The sampler a glTF `samplers[i]` object describes (absent fields take glTF's defaults).
    pub fn from_json(s: Option<&serde_json::Value>) -> Sampler {
        let get = |k: &str| s.and_then(|s| s.get(k)).and_then(|v| v.as_u64());
        Sampler {
            wrap_s: Wrap::from_gl(get("wrapS")),
            wrap_t: Wrap::from_gl(get("wrapT")),
            nearest: get("magFilter") == Some(9728),
            min: MinFilter::from_gl(get("minFilter")),
        }
    }

    /// The λ at or below which the magnification filter applies (OpenGL 4.6, 8.15: 0.5 where a
    /// LINEAR magnification meets a NEAREST_MIPMAP minification, else 0).
    fn mag_threshold(&self) -> f32 {
        let nearest_mips = matches!(self.min, MinFilter::NearestMipmapNearest | MinFilter::NearestMipmapLinear);
        if !self.nearest && nearest_mips {
            0.5
        } else {
            0.0
        }
    }
}

/// How far the texture coordinates move per screen sample, along screen x and screen y.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Footprint {
    pub dx: Vec2,
    pub dy: Vec2,
}

/// One image of a chain, row 0 at the top (glTF's UV origin is the image's top-left corner).
#[derive(Debug, Clone, PartialEq)]
pub struct Level {
    pub width: usize,
    pub height: usize,
    /// RGBA, linear when decoded with `srgb = true`, raw encoded values otherwise.
    pub texels: Vec<Vec4>,
}

impl Level {
    fn texel(&self, s: &Sampler, x: i64, y: i64) -> Vec4 {
        let x = s.wrap_s.apply(x, self.width as i64);
        let y = s.wrap_t.apply(y, self.height as i64);
        self.texels[y * self.width + x]
    }

    /// Texel centres at half-integers, as on a GPU. Non-finite UVs read texel 0.
    fn sample(&self, s: &Sampler, uv: Vec2, nearest: bool) -> Vec4 {
        let uv = if uv.is_finite() { uv } else { Vec2::ZERO };
        // Keep the float->int conversion in range; beyond this every wrap mode is periodic anyway
        // or clamped, and f32 has no fractional part left.
        let x = (uv.x as f64 * self.width as f64 - 0.5).clamp(-1e15, 1e15);
        let y = (uv.y as f64 * self.height as f64 - 0.5).clamp(-1e15, 1e15);
        if nearest {
            return self.texel(s, (x + 0.5).floor() as i64, (y + 0.5).floor() as i64);
        }
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let a = self.texel(s, x0, y0);
        let b = self.texel(s, x0 + 1, y0);
        let c = self.texel(s, x0, y0 + 1);
        let d = self.texel(s, x0 + 1, y0 + 1);
        (a * (1.0 - fx) + b * fx) * (1.0 - fy) + (c * (1.0 - fx) + d * fx) * fy
    }

    /// The next level down: `max(1, floor(n / 2))` a side, each texel the mean of the 2x2 block
    /// above it (an odd last row or column is left out, as a 2x2 box filter does), rounded to
    /// `quantum` when the source is stored at that precision.
    pub fn box_down(&self, quantum: Option<f32>) -> Level {
        let (w, h) = ((self.width / 2).max(1), (self.height / 2).max(1));
        let at = |x: usize, y: usize| self.texels[y.min(self.height - 1) * self.width + x.min(self.width - 1)];
        let texels = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w * 2, i / w * 2);
                let m = (at(x, y) + at(x + 1, y) + at(x, y + 1) + at(x + 1, y + 1)) * 0.25;
                match quantum {
                    Some(q) => (m / q).round() * q,
                    None => m,
                }
            })
            .collect();
        Level { width: w, height: h, texels }
    }
}

/// A decoded texture: level 0, the file's own lower levels, and the box chain made when first
/// needed.
#[derive(Debug)]
pub struct Texture {
    pub base: Level,
    /// Levels 1.. as stored in the file (KTX2); empty for formats without mips.
    pub file_levels: Vec<Level>,
    /// Stored precision of the texels (1/255 for 8-bit data), which the box chain keeps.
    quantum: Option<f32>,
    box_levels: OnceLock<Vec<Level>>,
}

/// sRGB transfer function, decoding direction.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// sRGB transfer function, encoding direction.
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.0031308 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

fn level_of(img: &image::DynamicImage, srgb: bool) -> crate::error::Faulty<Level> {
    let rgba = img.to_rgba32f();
    let (w, h) = (rgba.width() as usize, rgba.height() as usize);
    if w == 0 || h == 0 {
        return Err("image has no pixels".into());
    }
    let texels = rgba
        .pixels()
        .map(|p| {
            let c = |x: f32| if srgb { srgb_to_linear(x) } else { x };
            Vec4::new(c(p[0]), c(p[1]), c(p[2]), p[3])
        })
        .collect();
    Ok(Level { width: w, height: h, texels })
}

impl Texture {
    /// Decodes image bytes (any format [`crate::format::image`] reads, under its texture limits;
    /// every level of a KTX2). Colour textures are sRGB-encoded in glTF and are linearised here;
    /// data textures (normal maps) must keep their encoded values, so `srgb` is false.
    pub fn decode(bytes: &[u8], srgb: bool) -> crate::error::Faulty<Texture> {
        use crate::format::image::{ktx2, Kind, Limits};
        let imgs = if Kind::sniff(bytes) == Kind::Ktx2 {
            ktx2::decode_levels_within(bytes, &Limits::TEXTURE)?
        } else {
            vec![crate::format::image::decode(bytes)?]
        };
        // Linear 8-bit data is stored as such on a GPU, at every level it makes; sRGB levels are
        // averaged in linear and stored encoded, which floats stand in for here.
        let eight_bit = imgs[0].color().bytes_per_pixel() == imgs[0].color().channel_count();
        let quantum = (eight_bit && !srgb).then_some(1.0 / 255.0);
        let mut levels = imgs.iter().map(|i| level_of(i, srgb)).collect::<crate::error::Faulty<Vec<_>>>()?;
        let base = levels.remove(0);
        Ok(Texture { base, file_levels: levels, quantum, box_levels: OnceLock::new() })
    }

    /// A texture from texels, row 0 at the top.
    pub fn from_texels(width: usize, height: usize, texels: Vec<Vec4>) -> Option<Texture> {
        Texture::from_levels(vec![Level { width, height, texels }])
    }

    /// A texture from a chain as a file would hold it (level 0 first); texels are kept as given.
    pub fn from_levels(mut levels: Vec<Level>) -> Option<Texture> {
        let ok = levels.iter().all(|l| l.width > 0 && l.height > 0 && l.texels.len() == l.width * l.height);
        if levels.is_empty() || !ok {
            return None;
        }
        let base = levels.remove(0);
        Some(Texture { base, file_levels: levels, quantum: None, box_levels: OnceLock::new() })
    }

    pub fn width(&self) -> usize {
        self.base.width
    }

    pub fn height(&self) -> usize {
        self.base.height
    }

    /// Levels 1.. of the chain `mips` selects (empty for [`Mips::Off`]).
    pub fn lower_levels(&self, mips: Mips) -> &[Level] {
        match mips {
            Mips::Off => &[],
            Mips::File if !self.file_levels.is_empty() => &self.file_levels,
            Mips::File | Mips::Box => self.box_levels.get_or_init(|| {
                let n = crate::normalmap::mips::level_count(self.base.width, self.base.height);
                let mut out: Vec<Level> = Vec::with_capacity(n.saturating_sub(1));
                for _ in 1..n {
                    let next = out.last().unwrap_or(&self.base).box_down(self.quantum);
                    out.push(next);
                }
                out
            }),
        }
    }

    /// Samples level 0 at `uv` with the magnification filter.
    pub fn sample(&self, s: &Sampler, uv: Vec2) -> Vec4 {
        self.base.sample(s, uv, s.nearest)
    }

    /// `λ = log2(ρ)` for a footprint, `ρ` in level-0 texels per screen sample.
    pub fn lod(&self, f: &Footprint) -> f32 {
        let size = Vec2::new(self.base.width as f32, self.base.height as f32);
        let rho = (f.dx * size).length().max((f.dy * size).length());
        rho.log2()
    }

    /// Samples at `uv` with the level the footprint calls for, from the chain `mips` selects.
    pub fn sample_lod(&self, s: &Sampler, uv: Vec2, f: &Footprint, mips: Mips) -> Vec4 {
        let lambda = self.lod(f);
        // No usable footprint (degenerate or non-finite): read level 0 as if magnified.
        if mips == Mips::Off || lambda.is_nan() || lambda <= s.mag_threshold() {
            return self.sample(s, uv);
        }
        let nearest = s.min.nearest_texel();
        let lower = if s.min.mipmapped() { self.lower_levels(mips) } else { &[] };
        let level = |k: usize| if k == 0 { &self.base } else { &lower[k - 1] };
        let q = lower.len() as f32;
        let lambda = lambda.min(q);
        if !s.min.between_levels() {
            // OpenGL 4.6 (8.14): d = ceil(λ + 1/2) - 1 for λ > 1/2.
            let d = if lambda <= 0.5 { 0.0 } else { (lambda + 0.5).ceil() - 1.0 };
            return level(d.min(q) as usize).sample(s, uv, nearest);
        }
        let d1 = lambda.floor();
        let t = lambda - d1;
        let a = level(d1 as usize).sample(s, uv, nearest);
        if t == 0.0 {
            return a;
        }
        let b = level((d1 as usize + 1).min(lower.len())).sample(s, uv, nearest);
        a * (1.0 - t) + b * t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_modes() {
        assert_eq!(Wrap::Repeat.apply(-1, 4), 3);
        assert_eq!(Wrap::Repeat.apply(5, 4), 1);
        assert_eq!(Wrap::Clamp.apply(-3, 4), 0);
        assert_eq!(Wrap::Clamp.apply(9, 4), 3);
        assert_eq!(Wrap::Mirror.apply(4, 4), 3);
        assert_eq!(Wrap::Mirror.apply(-1, 4), 0);
        assert_eq!(Wrap::Mirror.apply(7, 4), 0);
    }

    #[test]
    fn bilinear_between_texel_centres() {
        let t = Texture::from_texels(2, 1, vec![Vec4::ZERO, Vec4::ONE]).unwrap();
        let s = Sampler { wrap_s: Wrap::Clamp, wrap_t: Wrap::Clamp, ..Default::default() };
        assert!((t.sample(&s, Vec2::new(0.5, 0.5)).x - 0.5).abs() < 1e-6);
        assert!((t.sample(&s, Vec2::new(0.25, 0.5)).x - 0.0).abs() < 1e-6);
        assert!((t.sample(&s, Vec2::new(0.75, 0.5)).x - 1.0).abs() < 1e-6);
        // repeat wraps the left edge onto the right texel
        let r = Sampler::default();
        assert!((t.sample(&r, Vec2::new(0.0, 0.5)).x - 0.5).abs() < 1e-6);
        assert!(t.sample(&r, Vec2::new(f32::NAN, 0.5)).is_finite());
        assert!(t.sample(&r, Vec2::new(1e30, -1e30)).is_finite());
    }
}
