//! Unit normals to texels: `c = round((n·0.5 + 0.5)·max)`, rounding to nearest, never
//! truncating (a truncating encoder turns a flat normal into (127,127,254), tilting every flat
//! texel by half a degree). Float output stores the same `n·0.5 + 0.5` unrounded, so every
//! format decodes the same way: `n = 2·texel - 1`.

use super::rows;
use super::{Convention, HeightPlane, NormalPlane, Options};
use crate::progress::Reporter;

/// Sample type of the encoded map.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Depth {
    #[default]
    Bits8,
    Bits16,
    Float,
}

/// How normals are written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct EncodeOptions {
    pub depth: Depth,
    pub convention: Convention,
    /// Store the height (after `invert`) in alpha, for parallax mapping.
    pub alpha_height: bool,
}

/// Texels of an encoded normal map.
#[derive(Clone, Debug, PartialEq)]
pub enum NormalData {
    U8(Vec<u8>),
    U16(Vec<u16>),
    F32(Vec<f32>),
}

/// An encoded normal map: interleaved RGB or RGBA, row-major from the top row.
#[derive(Clone, Debug, PartialEq)]
pub struct NormalImage {
    pub width: usize,
    pub height: usize,
    /// 3 (RGB) or 4 (RGBA, height in alpha).
    pub channels: usize,
    pub data: NormalData,
}

/// The exact `round((v·0.5 + 0.5)·255)`: the product and sum are exact in f64 for any f32 `v`
/// (24 + 8 significant bits), so `floor(t + 0.5)` below is round-half-up of the true value,
/// with no libm call (which is what `f32::round` costs without SSE4.1).
#[inline(always)]
pub fn quantize8(v: f32) -> u8 {
    ((v as f64) * 127.5 + 128.0) as u8
}

/// `round((v·0.5 + 0.5)·65535)`, exact as [`quantize8`].
#[inline(always)]
pub fn quantize16(v: f32) -> u16 {
    ((v as f64) * 32767.5 + 32768.0) as u16
}

/// `2·c/255 - 1`.
#[inline]
pub fn decode8(c: u8) -> f32 {
    (c as f32) * (2.0 / 255.0) - 1.0
}

/// `2·c/65535 - 1`.
#[inline]
pub fn decode16(c: u16) -> f32 {
    (c as f32) * (2.0 / 65535.0) - 1.0
}

#[inline(always)]
fn alpha8(h: f32) -> u8 {
    ((h.clamp(0.0, 1.0) as f64) * 255.0 + 0.5) as u8
}

#[inline(always)]
fn alpha16(h: f32) -> u16 {
    ((h.clamp(0.0, 1.0) as f64) * 65535.0 + 0.5) as u16
}

/// The height as stored in alpha: what the normals describe, so `1 - h` when inverted.
#[inline(always)]
fn stored_height(h: f32, invert: bool) -> f32 {
    if invert {
        1.0 - h
    } else {
        h
    }
}

/// Writes one row of `CH`-channel texels from unit normals produced by `normal(x)`.
#[inline(always)]
fn write_row<T: Copy, const CH: usize>(
    out: &mut [T],
    ysign: f32,
    normal: impl Fn(usize) -> [f32; 3],
    q: impl Fn(f32) -> T,
    alpha: impl Fn(usize) -> T,
) {
    for (x, px) in out.chunks_exact_mut(CH).enumerate() {
        let n = normal(x);
        px[0] = q(n[0]);
        px[1] = q(ysign * n[1]);
        px[2] = q(n[2]);
        if CH == 4 {
            px[CH - 1] = alpha(x);
        }
    }
}

fn float_texel(v: f32) -> f32 {
    v * 0.5 + 0.5
}

fn channels(enc: &EncodeOptions) -> usize {
    if enc.alpha_height {
        4
    } else {
        3
    }
}

/// Runs the filter and encodes in one pass, straight into the output buffer: the whole
/// `normalmap` command's work between decoding and writing.
pub fn encode_normals(height: &HeightPlane, opts: &Options, enc: &EncodeOptions, progress: &Reporter) -> NormalImage {
    let mut img = NormalImage { width: 0, height: 0, channels: 0, data: NormalData::U8(Vec::new()) };
    encode_normals_into(height, opts, enc, progress, &mut img);
    img
}

/// [`encode_normals`] into an existing image, reusing its buffer when the sample type matches:
/// for callers that convert many maps, and for timing the filter without the cost of the
/// operating system handing over fresh pages.
pub fn encode_normals_into(
    height: &HeightPlane,
    opts: &Options,
    enc: &EncodeOptions,
    progress: &Reporter,
    img: &mut NormalImage,
) {
    let old = std::mem::replace(&mut img.data, NormalData::U8(Vec::new()));
    img.data = match (enc.depth, old) {
        (Depth::Bits8, NormalData::U8(mut v)) => {
            fused(height, opts, enc, progress, &mut v, quantize8, alpha8);
            NormalData::U8(v)
        }
        (Depth::Bits8, _) => NormalData::U8(fused_new(height, opts, enc, progress, quantize8, alpha8)),
        (Depth::Bits16, NormalData::U16(mut v)) => {
            fused(height, opts, enc, progress, &mut v, quantize16, alpha16);
            NormalData::U16(v)
        }
        (Depth::Bits16, _) => NormalData::U16(fused_new(height, opts, enc, progress, quantize16, alpha16)),
        (Depth::Float, NormalData::F32(mut v)) => {
            fused(height, opts, enc, progress, &mut v, float_texel, |h| h);
            NormalData::F32(v)
        }
        (Depth::Float, _) => NormalData::F32(fused_new(height, opts, enc, progress, float_texel, |h| h)),
    };
    img.width = height.width;
    img.height = height.height;
    img.channels = channels(enc);
}

fn fused_new<T: Copy + Send + Sync + Default>(
    height: &HeightPlane,
    opts: &Options,
    enc: &EncodeOptions,
    progress: &Reporter,
    q: impl Fn(f32) -> T + Sync + Copy,
    qa: impl Fn(f32) -> T + Sync + Copy,
) -> Vec<T> {
    let mut v = Vec::new();
    fused(height, opts, enc, progress, &mut v, q, qa);
    v
}

/// Normals go to three float planes first, then to samples plane by plane, then are
/// interleaved: each step is a simple loop the compiler vectorises, where one fused
/// interleaved loop stays scalar (measured 1.6x slower).
fn fused<T: Copy + Send + Sync + Default>(
    height: &HeightPlane,
    opts: &Options,
    enc: &EncodeOptions,
    progress: &Reporter,
    out: &mut Vec<T>,
    q: impl Fn(f32) -> T + Sync + Copy,
    qa: impl Fn(f32) -> T + Sync + Copy,
) {
    if height.width == 0 || height.height == 0 {
        out.clear();
        return;
    }
    let rows = rows::Rows::new(height, opts);
    fused_rows(&rows, height, opts, enc, 0, height.height, progress, out, q, qa);
}

/// Rows `y0..y0 + n` of the encoded map into `out` (resized to fit).
#[allow(clippy::too_many_arguments)]
fn fused_rows<T: Copy + Send + Sync + Default>(
    rows: &rows::Rows,
    height: &HeightPlane,
    opts: &Options,
    enc: &EncodeOptions,
    y0: usize,
    n: usize,
    progress: &Reporter,
    out: &mut Vec<T>,
    q: impl Fn(f32) -> T + Sync + Copy,
    qa: impl Fn(f32) -> T + Sync + Copy,
) {
    let (w, ch) = (height.width, channels(enc));
    let (s, ysign, invert) = (opts.signed_strength(), enc.convention.y_sign(), opts.invert);
    let zero = T::default();
    out.resize(w * n * ch, zero);
    let state = || {
        let n: [Vec<f32>; 3] = std::array::from_fn(|_| vec![0.0f32; w]);
        let c: [Vec<T>; 4] = std::array::from_fn(|_| vec![zero; w]);
        (n, c)
    };
    rows.run(y0, out, w * ch, progress, state, |y, x0, gx, gy, row, (n, c)| {
        let len = gx.len();
        rows::unit_normals_planar(gx, gy, s, ysign, n);
        for k in 0..3 {
            for (o, &v) in c[k][..len].iter_mut().zip(&n[k][..len]) {
                *o = q(v);
            }
        }
        if ch == 4 {
            let hrow = &height.data[y * w + x0..y * w + x0 + len];
            for (o, &v) in c[3].iter_mut().zip(hrow) {
                *o = qa(stored_height(v, invert));
            }
            for (x, px) in row.chunks_exact_mut(4).enumerate() {
                px.copy_from_slice(&[c[0][x], c[1][x], c[2][x], c[3][x]]);
            }
        } else {
            for (x, px) in row.chunks_exact_mut(3).enumerate() {
                px.copy_from_slice(&[c[0][x], c[1][x], c[2][x]]);
            }
        }
    });
}

/// Filters and encodes a map strip by strip into a reused buffer, for writers that stream
/// (PNG): the whole encoded map never exists, and the strip buffer's pages are touched once.
pub(crate) struct Strips<'a> {
    rows: rows::Rows<'a>,
    height: &'a HeightPlane,
    opts: Options,
    enc: EncodeOptions,
    pub u8s: Vec<u8>,
    pub u16s: Vec<u16>,
}

impl<'a> Strips<'a> {
    pub fn new(height: &'a HeightPlane, opts: &Options, enc: &EncodeOptions) -> Strips<'a> {
        Strips {
            rows: rows::Rows::new(height, opts),
            height,
            opts: *opts,
            enc: *enc,
            u8s: Vec::new(),
            u16s: Vec::new(),
        }
    }
    /// Encodes rows `y0..y0 + n` into `u8s` (8-bit) or `u16s` (16-bit).
    pub fn encode(&mut self, y0: usize, n: usize, progress: &Reporter) {
        let (r, h, o, e) = (&self.rows, self.height, &self.opts, &self.enc);
        match e.depth {
            Depth::Bits8 => fused_rows(r, h, o, e, y0, n, progress, &mut self.u8s, quantize8, alpha8),
            Depth::Bits16 => fused_rows(r, h, o, e, y0, n, progress, &mut self.u16s, quantize16, alpha16),
            Depth::Float => unreachable!("float maps are not streamed"),
        }
    }
}

/// Encodes float normals (OpenGL convention, as [`NormalPlane`] holds them). `heights` fills
/// alpha when `enc.alpha_height` is set (as given: invert it first if it is a depth map).
pub fn encode_plane(normals: &NormalPlane, enc: &EncodeOptions, heights: Option<&HeightPlane>) -> NormalImage {
    let enc = EncodeOptions { alpha_height: enc.alpha_height && heights.is_some(), ..*enc };
    let data = match enc.depth {
        Depth::Bits8 => NormalData::U8(from_plane(normals, &enc, heights, 0u8, quantize8, alpha8)),
        Depth::Bits16 => NormalData::U16(from_plane(normals, &enc, heights, 0u16, quantize16, alpha16)),
        Depth::Float => NormalData::F32(from_plane(normals, &enc, heights, 0f32, float_texel, |h| h)),
    };
    NormalImage { width: normals.width, height: normals.height, channels: channels(&enc), data }
}

fn from_plane<T: Copy + Send + Sync>(
    normals: &NormalPlane,
    enc: &EncodeOptions,
    heights: Option<&HeightPlane>,
    zero: T,
    q: impl Fn(f32) -> T + Sync + Copy,
    qa: impl Fn(f32) -> T + Sync + Copy,
) -> Vec<T> {
    use rayon::prelude::*;
    let (w, h, ch) = (normals.width, normals.height, channels(enc));
    let ysign = enc.convention.y_sign();
    let mut out = vec![zero; w * h * ch];
    if w > 0 {
        out.par_chunks_mut(w * ch).enumerate().for_each(|(y, row)| {
            let normal = |x: usize| normals.data[y * w + x];
            match heights {
                Some(hp) if ch == 4 => write_row::<_, 4>(row, ysign, normal, q, |x| qa(hp.data[y * w + x])),
                _ => write_row::<_, 3>(row, ysign, normal, q, |_| zero),
            }
        });
    }
    out
}

impl NormalImage {
    /// Decodes every texel back to a vector, `n = 2·texel - 1`, in OpenGL convention (the
    /// `convention` the map was written in is undone). Not renormalised: a validator wants to
    /// see how far from unit the stored vectors are.
    pub fn decode(&self, convention: Convention) -> NormalPlane {
        let ch = self.channels;
        let ys = convention.y_sign();
        let data = match &self.data {
            NormalData::U8(d) => {
                d.chunks_exact(ch).map(|p| [decode8(p[0]), ys * decode8(p[1]), decode8(p[2])]).collect()
            }
            NormalData::U16(d) => {
                d.chunks_exact(ch).map(|p| [decode16(p[0]), ys * decode16(p[1]), decode16(p[2])]).collect()
            }
            NormalData::F32(d) => {
                d.chunks_exact(ch).map(|p| [2.0 * p[0] - 1.0, ys * (2.0 * p[1] - 1.0), 2.0 * p[2] - 1.0]).collect()
            }
        };
        NormalPlane { width: self.width, height: self.height, data }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding_is_to_nearest() {
        assert_eq!(quantize8(0.0), 128);
        assert_eq!(quantize8(-0.0), 128);
        assert_eq!(quantize8(1.0), 255);
        assert_eq!(quantize8(-1.0), 0);
        assert_eq!(quantize16(0.0), 32768);
        assert_eq!(quantize16(1.0), 65535);
        assert_eq!(quantize16(-1.0), 0);
        // Against f64 round() over a dense sweep: exact agreement, no truncation anywhere.
        for i in -100_000..=100_000 {
            let v = i as f32 / 100_000.0;
            let t = ((v as f64) * 0.5 + 0.5) * 255.0;
            assert_eq!(quantize8(v), t.round() as u8, "v = {v}");
            let t = ((v as f64) * 0.5 + 0.5) * 65535.0;
            assert_eq!(quantize16(v), t.round() as u16, "v = {v}");
        }
    }

    #[test]
    fn decode_inverts_encode_within_half_a_step() {
        for c in 0..=255u8 {
            assert_eq!(quantize8(decode8(c)), c);
        }
        for c in (0..=65535u16).step_by(7) {
            assert_eq!(quantize16(decode16(c)), c);
        }
    }

    #[test]
    fn plane_and_fused_encoders_agree() {
        let hp = HeightPlane::from_fn(9, 5, |x, y| ((x * 7 + y * 3) % 11) as f32 / 10.0);
        let opts = Options { strength: 3.0, ..Options::default() };
        for depth in [Depth::Bits8, Depth::Bits16, Depth::Float] {
            for convention in [Convention::Opengl, Convention::Directx] {
                let enc = EncodeOptions { depth, convention, alpha_height: true };
                let fused = encode_normals(&hp, &opts, &enc, &Reporter::none());
                let planed = encode_plane(&crate::normalmap::height_to_normal(&hp, &opts), &enc, Some(&hp));
                assert_eq!(fused, planed);
            }
        }
    }
}
