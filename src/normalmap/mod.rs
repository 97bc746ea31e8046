//! Height maps to tangent-space normal maps, following `docs/conventions.md`:
//! `n = normalize(-S·dh/dx, -S·dh/dy_up, 1)` with `x` right and `y_up` towards the top row,
//! OpenGL/glTF `+Y` unless DirectX output is asked for, and rounding (never truncation) when
//! encoding.
//!
//! The pipeline keeps memory at about input + output + one float plane: the decoded image is
//! turned into a [`HeightPlane`] and dropped, then [`encode_normals`] runs the filter and the
//! encoder row by row straight into the output buffer (no plane of float normals in between).
//! [`normals_from_height`] is the float route for callers (`bake`) that want the vectors.
//!
//! Library entry points:
//! - [`load_height`]: any PNG/JPEG/WebP/TIFF/EXR to a height plane, refusing oversized headers first.
//! - [`normals_from_height`] / [`height_to_normal`]: float unit normals.
//! - [`encode_normals`]: filter + encode in one pass; [`encode_plane`] for float normals.
//! - [`write_normal_image`], [`png_bytes`]: files; [`decode_normal_image`]: back to vectors.
//! - [`convert_file`]: the whole `bumpbake normalmap` command.
//! - [`mips::build`], [`ktx2_bytes`]: mip chains from the full-resolution normals, and KTX2.
//! - [`Flatness`]: the largest tilt of a map's texels, the one rule for "(nearly) flat" that `bake`,
//!   `normalmap` and `validate` share.

mod encode;
mod filter;
mod height;
mod io;
mod ktx2;
pub mod mips;
mod relief;
mod rows;
mod spectral;
pub mod specular_aa;

pub use encode::{
    decode16, decode8, encode_normals, encode_normals_into, encode_plane, quantize16, quantize8, Depth, EncodeOptions,
    NormalData, NormalImage,
};
pub use filter::wrap_index;
pub use height::{height_from_image, Channel, HeightPlane};
pub use io::{
    colour_words, convert_file, decode_normal_image, image_bytes, load_height, load_normal_image, open_image,
    png_bytes, write_normal_image, Convert, Converted, OutputFormat, PngSettings, DEFAULT_MAX_PIXELS,
};
pub use ktx2::{ktx2_bytes, measure, LevelError, DEFAULT_ETC1S_QUALITY, DEFAULT_UASTC_LEVEL};
pub use relief::{steepest_slope, Flatness, Verdict, EXACT_FLAT_DEG, NEARLY_FLAT_DEG};
pub use rows::unit_normal;

use crate::progress::Reporter;
use serde::Serialize;

/// How the height derivative is estimated. Every filter is scaled to the true derivative per
/// texel; they differ in how well they follow high frequencies, how much they smooth noise and
/// what they cost (see `docs/normalmap.md` for the measured table).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Filter {
    /// `[-1 0 1]/2`: sharpest 3-tap, no smoothing, most sensitive to noise.
    Central,
    /// `[1 -8 0 8 -1]/12`: fourth-order accurate, no smoothing.
    Central4,
    /// 3x3 Sobel: central difference smoothed by `[1 2 1]/4`.
    #[default]
    Sobel,
    /// 3x3 Scharr: smoothing `[3 10 3]/16`, more rotation-invariant than Sobel.
    Scharr,
    /// 3x3 Prewitt: smoothing `[1 1 1]/3`.
    Prewitt,
    /// 5x5 Sobel: `[-1 -2 0 2 1]/8` ⊗ `[1 4 6 4 1]/16`, smoothest.
    Sobel5,
    /// FFT derivative: exact for band-limited periodic heights; costs an extra float plane.
    Spectral,
}

impl Filter {
    pub const ALL: [Filter; 7] = [
        Filter::Central,
        Filter::Central4,
        Filter::Sobel,
        Filter::Scharr,
        Filter::Prewitt,
        Filter::Sobel5,
        Filter::Spectral,
    ];
    pub fn name(self) -> &'static str {
        match self {
            Filter::Central => "central",
            Filter::Central4 => "central4",
            Filter::Sobel => "sobel",
            Filter::Scharr => "scharr",
            Filter::Prewitt => "prewitt",
            Filter::Sobel5 => "sobel5",
            Filter::Spectral => "spectral",
        }
    }
}

/// What lies beyond the image edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Wrap {
    /// The opposite edge: for tiling textures.
    Repeat,
    /// The edge texel repeated: no slope invented beyond the edge. Right for standalone maps.
    #[default]
    Clamp,
    /// Reflected, edge texel included (GL_MIRRORED_REPEAT).
    Mirror,
}

/// Which way `+Y` points in the encoded map.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Convention {
    /// `+Y` up (OpenGL, glTF, Blender): the project's convention.
    #[default]
    Opengl,
    /// `+Y` down (DirectX, Unreal): `n.y` negated before encoding, nothing else.
    Directx,
}

impl Convention {
    /// The factor `n.y` is multiplied by when going between this convention and OpenGL.
    pub fn y_sign(self) -> f32 {
        match self {
            Convention::Opengl => 1.0,
            Convention::Directx => -1.0,
        }
    }

    /// The words reports use for this convention.
    pub fn describe(self) -> &'static str {
        match self {
            Convention::Opengl => "OpenGL (+Y)",
            Convention::Directx => "DirectX (-Y)",
        }
    }
}

/// How heights become normals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// `S`: texels of surface height per unit of `h`. Use [`Options::physical_strength`] for
    /// metres.
    pub strength: f32,
    pub filter: Filter,
    pub wrap: Wrap,
    /// The map holds depth: use `1 - h`.
    pub invert: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options { strength: 1.0, filter: Filter::default(), wrap: Wrap::default(), invert: false }
    }
}

impl Options {
    /// `S = height_range / texel_size`, both in the same unit (metres).
    pub fn physical_strength(height_range: f64, texel_size: f64) -> f32 {
        (height_range / texel_size) as f32
    }

    /// The strength a caller asked for: `strength` alone, or `height_range` and `texel_size`
    /// together ([`Options::physical_strength`]), or the default; refused (a usage error naming
    /// the setting) when both ways are given, when one of the pair is missing, or when a value is
    /// not a finite length (the texel size positive) or the strength is negative.
    pub fn strength_from(
        strength: Option<f32>,
        height_range: Option<f64>,
        texel_size: Option<f64>,
    ) -> crate::error::Result<f32> {
        use crate::error::{Error, Setting, Words};
        let refuse = |s: Setting, v: String, rest: &str| {
            Err(Error::setting(s, Some(v.clone()), Words::new().given(s, v).text(rest)))
        };
        let s = match (strength, height_range, texel_size) {
            (Some(_), Some(_), _) | (Some(_), _, Some(_)) => {
                let w = Words::new().name(Setting::Strength).text(" cannot be given with ").name(Setting::HeightRange);
                let w = w.text(" and ").name(Setting::TexelSize).text(": give one or the other");
                return Err(Error::setting(Setting::Strength, None, w));
            }
            (None, Some(_), None) | (None, None, Some(_)) => {
                let w = Words::new().name(Setting::HeightRange).text(" and ").name(Setting::TexelSize);
                let w = w.text(" go together: give both, or ").name(Setting::Strength).text(" alone");
                return Err(Error::setting(Setting::HeightRange, None, w));
            }
            (Some(s), None, None) => s,
            (None, Some(range), Some(texel)) => {
                if !(texel.is_finite() && texel > 0.0) {
                    return refuse(Setting::TexelSize, texel.to_string(), ": must be a positive length");
                }
                if !(range.is_finite() && range >= 0.0) {
                    return refuse(Setting::HeightRange, range.to_string(), ": must be zero or a positive length");
                }
                Options::physical_strength(range, texel)
            }
            (None, None, None) => Options::default().strength,
        };
        if !(s.is_finite() && s >= 0.0) {
            let w = Words::new().given(Setting::Strength, s).text(": must be finite and not negative (use ");
            return Err(Error::setting(
                Setting::Strength,
                Some(s.to_string()),
                w.on(Setting::Invert).text(" for depth maps)"),
            ));
        }
        Ok(s)
    }
    /// The strength with the inversion folded in: `d(1-h) = -dh`.
    pub(crate) fn signed_strength(&self) -> f32 {
        if self.invert {
            -self.strength
        } else {
            self.strength
        }
    }
}

/// Unit tangent-space normals, OpenGL convention, row-major from the top row, `z > 0`.
#[derive(Clone, Debug, PartialEq)]
pub struct NormalPlane {
    pub width: usize,
    pub height: usize,
    pub data: Vec<[f32; 3]>,
}

impl NormalPlane {
    pub fn get(&self, x: usize, y: usize) -> [f32; 3] {
        self.data[y * self.width + x]
    }
}

/// Float unit normals for every texel of `height` (OpenGL convention).
pub fn normals_from_height(height: &HeightPlane, opts: &Options, progress: &Reporter) -> NormalPlane {
    let (w, h) = (height.width, height.height);
    let mut data = vec![[0.0f32; 3]; w * h];
    let s = opts.signed_strength();
    rows::for_each_row(
        height,
        opts,
        &mut data,
        w,
        progress,
        || (),
        |_, _, gx, gy, out, _| {
            for ((o, &dx), &dy) in out.iter_mut().zip(gx).zip(gy) {
                *o = unit_normal(dx, dy, s);
            }
        },
    );
    NormalPlane { width: w, height: h, data }
}

/// The height's slope at every texel, `[dh/dx, dh/dy_up]` per texel of `height` (x right, y
/// towards the top row), through `opts`' filter and wrap; `opts.strength` and `invert` do not
/// apply. For conversions whose scale varies over the map ([`crate::bake::surface`]).
pub fn gradients(height: &HeightPlane, opts: &Options) -> Vec<[f32; 2]> {
    let mut data = vec![[0.0f32; 2]; height.width * height.height];
    let (w, none) = (height.width, Reporter::none());
    rows::for_each_row(
        height,
        opts,
        &mut data,
        w,
        &none,
        || (),
        |_, _, gx, gy, out, _| {
            for ((o, &dx), &dy) in out.iter_mut().zip(gx).zip(gy) {
                *o = [dx, dy];
            }
        },
    );
    data
}

/// The name other commands use: [`normals_from_height`] without progress.
pub fn height_to_normal(height: &HeightPlane, opts: &Options) -> NormalPlane {
    normals_from_height(height, opts, &Reporter::none())
}
