//! Textures as the renderer samples them: decoded once to floats, read with glTF's sampler
//! rules (wrap modes per axis, bilinear unless the sampler asks for nearest).
//!
//! Sampling matches what a GPU does with the same sampler and no mipmaps, so that a preview and
//! a real renderer disagree only where minification aliasing shows (which `--ssaa` reduces).

use glam::{Vec2, Vec4};

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

/// How a texture is read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Sampler {
    pub wrap_s: Wrap,
    pub wrap_t: Wrap,
    /// `magFilter` NEAREST: the author wants hard texel edges.
    pub nearest: bool,
}

impl Sampler {
    /// The sampler a glTF `samplers[i]` object describes (absent fields take glTF's defaults).
    pub fn from_json(s: Option<&serde_json::Value>) -> Sampler {
        let get = |k: &str| s.and_then(|s| s.get(k)).and_then(|v| v.as_u64());
        Sampler {
            wrap_s: Wrap::from_gl(get("wrapS")),
            wrap_t: Wrap::from_gl(get("wrapT")),
            nearest: get("magFilter") == Some(9728),
        }
    }
}

/// A decoded image, row 0 at the top (glTF's UV origin is the image's top-left corner).
#[derive(Debug, Clone)]
pub struct Texture {
    pub width: usize,
    pub height: usize,
    /// RGBA, linear when decoded with `srgb = true`, raw encoded values otherwise.
    pub texels: Vec<Vec4>,
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

impl Texture {
    /// Decodes image bytes (any format [`crate::format::image`] reads, under its texture limits).
    /// Colour textures are sRGB-encoded in glTF and are linearised here; data textures (normal
    /// maps) must keep their encoded values, so `srgb` is false.
    pub fn decode(bytes: &[u8], srgb: bool) -> crate::error::Faulty<Texture> {
        let img = crate::format::image::decode(bytes)?;
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
        Ok(Texture { width: w, height: h, texels })
    }

    /// A texture from texels, row 0 at the top.
    pub fn from_texels(width: usize, height: usize, texels: Vec<Vec4>) -> Option<Texture> {
        (width > 0 && height > 0 && texels.len() == width * height).then_some(Texture { width, height, texels })
    }

    fn texel(&self, s: &Sampler, x: i64, y: i64) -> Vec4 {
        let x = s.wrap_s.apply(x, self.width as i64);
        let y = s.wrap_t.apply(y, self.height as i64);
        self.texels[y * self.width + x]
    }

    /// Samples at `uv` (texel centres at half-integers, as on a GPU). Non-finite UVs read texel 0.
    pub fn sample(&self, s: &Sampler, uv: Vec2) -> Vec4 {
        let uv = if uv.is_finite() { uv } else { Vec2::ZERO };
        // Keep the float->int conversion in range; beyond this every wrap mode is periodic anyway
        // or clamped, and f32 has no fractional part left.
        let x = (uv.x as f64 * self.width as f64 - 0.5).clamp(-1e15, 1e15);
        let y = (uv.y as f64 * self.height as f64 - 0.5).clamp(-1e15, 1e15);
        if s.nearest {
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
        let s = Sampler { wrap_s: Wrap::Clamp, wrap_t: Wrap::Clamp, nearest: false };
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
