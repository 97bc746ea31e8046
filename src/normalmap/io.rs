//! Files in and out. Inputs are refused on their header's size before any pixel buffer is
//! allocated; outputs are written whole or not at all ([`crate::output::write_atomic`]).

use super::{
    encode_normals, height_from_image, Channel, Depth, EncodeOptions, HeightPlane, NormalData,
    NormalImage,
};
use super::{Convention, NormalPlane, Options, Progress};
use crate::error::{Error, Result};
use crate::report::Timings;
use image::{DynamicImage, ExtendedColorType, ImageDecoder, ImageEncoder, ImageReader, Limits};
use std::io::Cursor;
use std::path::{Path, PathBuf};

/// 16384 x 16384: the largest texture most GPUs take.
pub const DEFAULT_MAX_PIXELS: u64 = 268_435_456;

/// One line, however the decoder formats its error.
fn one_line(e: impl std::fmt::Display) -> String {
    e.to_string()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

/// Opens and decodes an image, refusing it first if its header claims more than `max_pixels`.
pub fn open_image(path: &Path, max_pixels: u64) -> Result<DynamicImage> {
    let reader = ImageReader::open(path)
        .map_err(|e| Error::input(path, format!("cannot open: {}", one_line(e))))?;
    let mut reader = reader
        .with_guessed_format()
        .map_err(|e| Error::input(path, format!("cannot read: {}", one_line(e))))?;
    if reader.format().is_none() {
        return Err(Error::input(path, "not a PNG, TIFF or EXR image"));
    }
    // The pixel count is checked below from the header; this only bounds the decoder's own
    // buffers (RGBA f32 is 16 bytes a pixel) so that the check is not undone by a default.
    let mut limits = Limits::no_limits();
    limits.max_alloc = Some(max_pixels.saturating_mul(16).max(1 << 24));
    reader.limits(limits);
    let what = match reader.format() {
        Some(image::ImageFormat::Png) => "cannot decode as PNG".to_string(),
        Some(image::ImageFormat::Tiff) => "cannot decode as TIFF".to_string(),
        Some(image::ImageFormat::OpenExr) => "cannot decode as EXR".to_string(),
        other => format!("cannot decode as {other:?}"),
    };
    let decoder = reader
        .into_decoder()
        .map_err(|e| Error::input(path, format!("{what}: {}", one_line(e))))?;
    let (w, h) = decoder.dimensions();
    let pixels = w as u64 * h as u64;
    if pixels == 0 {
        return Err(Error::input(path, format!("image is {w}x{h}: no pixels")));
    }
    if pixels > max_pixels {
        return Err(Error::input(
            path,
            format!("image is {w}x{h} = {pixels} pixels, more than the limit of {max_pixels} (--max-pixels)"),
        ));
    }
    DynamicImage::from_decoder(decoder)
        .map_err(|e| Error::input(path, format!("{what}: {}", one_line(e))))
}

/// Reads a height map: PNG (8/16-bit gray, gray+alpha, RGB, RGBA), TIFF, or EXR.
pub fn load_height(path: &Path, channel: Channel, max_pixels: u64) -> Result<HeightPlane> {
    let img = open_image(path, max_pixels)?;
    height_from_image(&img, channel).map_err(|m| Error::input(path, m))
}

/// Reads an encoded normal map (RGB or RGBA; 8-bit, 16-bit or float) without decoding texels.
pub fn load_normal_image(path: &Path, max_pixels: u64) -> Result<NormalImage> {
    let img = open_image(path, max_pixels)?;
    let (width, height) = (img.width() as usize, img.height() as usize);
    let (channels, data) = match img {
        DynamicImage::ImageRgb8(b) => (3, NormalData::U8(b.into_raw())),
        DynamicImage::ImageRgba8(b) => (4, NormalData::U8(b.into_raw())),
        DynamicImage::ImageRgb16(b) => (3, NormalData::U16(b.into_raw())),
        DynamicImage::ImageRgba16(b) => (4, NormalData::U16(b.into_raw())),
        DynamicImage::ImageRgb32F(b) => (3, NormalData::F32(b.into_raw())),
        DynamicImage::ImageRgba32F(b) => (4, NormalData::F32(b.into_raw())),
        other => {
            return Err(Error::input(
                path,
                format!(
                    "a normal map must be RGB or RGBA, this is {:?}",
                    other.color()
                ),
            ))
        }
    };
    Ok(NormalImage {
        width,
        height,
        channels,
        data,
    })
}

/// Reads a normal map and decodes it to vectors (`n = 2·texel - 1`, OpenGL convention,
/// not renormalised). `convention` is the one the file was written in.
pub fn decode_normal_image(
    path: &Path,
    convention: Convention,
    max_pixels: u64,
) -> Result<NormalPlane> {
    Ok(load_normal_image(path, max_pixels)?.decode(convention))
}

/// What an output file name asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputFormat {
    Png,
    Tiff,
    Exr,
}

impl OutputFormat {
    pub fn from_path(path: &Path) -> Result<OutputFormat> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        match ext.as_str() {
            "png" => Ok(OutputFormat::Png),
            "tif" | "tiff" => Ok(OutputFormat::Tiff),
            "exr" => Ok(OutputFormat::Exr),
            _ => Err(Error::usage(format!(
                "{}: unsupported output format: name it .png, .tif or .exr",
                path.display()
            ))),
        }
    }
    /// The sample depth for `--bits` (None: the format's default).
    pub fn depth(self, path: &Path, bits: Option<u8>) -> Result<Depth> {
        match (self, bits) {
            (OutputFormat::Exr, None) => Ok(Depth::Float),
            (OutputFormat::Exr, Some(_)) => Err(Error::usage(format!(
                "{}: EXR output is 32-bit float; --bits is for PNG and TIFF",
                path.display()
            ))),
            (_, None | Some(8)) => Ok(Depth::Bits8),
            (_, Some(16)) => Ok(Depth::Bits16),
            (_, Some(b)) => Err(Error::usage(format!("--bits {b}: use 8 or 16"))),
        }
    }
}

/// PNG writer settings. Fast deflate with the `Up` filter was measured fastest for normal maps
/// at a size within a few percent of adaptive filtering (see `docs/normalmap.md`).
#[derive(Clone, Copy, Debug)]
pub struct PngSettings {
    pub compression: png::Compression,
    pub filter: png::Filter,
}

impl Default for PngSettings {
    fn default() -> Self {
        PngSettings {
            compression: png::Compression::Fast,
            filter: png::Filter::Up,
        }
    }
}

/// PNG bytes of a normal map (8- or 16-bit RGB/RGBA). Float maps cannot be PNG.
pub fn png_bytes(img: &NormalImage, settings: PngSettings) -> std::result::Result<Vec<u8>, String> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, img.width as u32, img.height as u32);
    enc.set_color(if img.channels == 4 {
        png::ColorType::Rgba
    } else {
        png::ColorType::Rgb
    });
    enc.set_compression(settings.compression);
    enc.set_filter(settings.filter);
    let result = match &img.data {
        NormalData::U8(d) => {
            enc.set_depth(png::BitDepth::Eight);
            enc.write_header().and_then(|mut w| {
                w.write_image_data(d)?;
                w.finish()
            })
        }
        NormalData::U16(d) => {
            enc.set_depth(png::BitDepth::Sixteen);
            let be: Vec<u8> = d.iter().flat_map(|v| v.to_be_bytes()).collect();
            enc.write_header().and_then(|mut w| {
                w.write_image_data(&be)?;
                w.finish()
            })
        }
        NormalData::F32(_) => {
            return Err("a float normal map cannot be written as PNG: use .exr".into())
        }
    };
    result.map_err(one_line)?;
    Ok(out)
}

fn image_bytes(
    img: &NormalImage,
    format: OutputFormat,
    png: PngSettings,
) -> std::result::Result<Vec<u8>, String> {
    let (w, h) = (img.width as u32, img.height as u32);
    let rgba = img.channels == 4;
    match (format, &img.data) {
        (OutputFormat::Png, _) => png_bytes(img, png),
        (OutputFormat::Tiff, NormalData::U8(d)) => {
            let mut c = Cursor::new(Vec::new());
            let ct = if rgba {
                ExtendedColorType::Rgba8
            } else {
                ExtendedColorType::Rgb8
            };
            image::codecs::tiff::TiffEncoder::new(&mut c)
                .write_image(d, w, h, ct)
                .map_err(one_line)?;
            Ok(c.into_inner())
        }
        (OutputFormat::Tiff, NormalData::U16(d)) => {
            let mut c = Cursor::new(Vec::new());
            let ct = if rgba {
                ExtendedColorType::Rgba16
            } else {
                ExtendedColorType::Rgb16
            };
            let bytes: Vec<u8> = d.iter().flat_map(|v| v.to_ne_bytes()).collect();
            image::codecs::tiff::TiffEncoder::new(&mut c)
                .write_image(&bytes, w, h, ct)
                .map_err(one_line)?;
            Ok(c.into_inner())
        }
        (OutputFormat::Exr, NormalData::F32(d)) => {
            let mut c = Cursor::new(Vec::new());
            let ct = if rgba {
                ExtendedColorType::Rgba32F
            } else {
                ExtendedColorType::Rgb32F
            };
            let bytes: Vec<u8> = d.iter().flat_map(|v| v.to_ne_bytes()).collect();
            image::codecs::openexr::OpenExrEncoder::new(&mut c)
                .write_image(&bytes, w, h, ct)
                .map_err(one_line)?;
            Ok(c.into_inner())
        }
        (OutputFormat::Exr, _) => Err("EXR output takes float normals".into()),
        (OutputFormat::Tiff, NormalData::F32(_)) => {
            Err("float TIFF output is not supported: use .exr".into())
        }
    }
}

/// Writes a normal map in the format its extension names, atomically.
pub fn write_normal_image(path: &Path, img: &NormalImage, png: PngSettings) -> Result<()> {
    let format = OutputFormat::from_path(path)?;
    let bytes = image_bytes(img, format, png).map_err(|m| Error::output(path, m))?;
    crate::output::write_atomic(path, &bytes)
}

/// The whole `bumpbake normalmap` command.
#[derive(Clone, Debug)]
pub struct Convert {
    pub input: PathBuf,
    pub output: PathBuf,
    pub channel: Channel,
    pub max_pixels: u64,
    pub options: Options,
    /// `depth` is taken from the output name and `--bits` by the caller.
    pub encode: EncodeOptions,
    pub png: PngSettings,
}

/// Runs [`Convert`]: decode, filter + encode, serialise, write. Returns the stage timings
/// (`decode`, `filter`, `encode`, `write`, in ms). Nothing is written unless all succeeds.
pub fn convert_file(c: &Convert, progress: Progress) -> Result<Timings> {
    let format = OutputFormat::from_path(&c.output)?;
    let mut t = Timings::default();
    let height = t.time("decode", || load_height(&c.input, c.channel, c.max_pixels))?;
    let img = t.time("filter", || {
        encode_normals(&height, &c.options, &c.encode, progress)
    });
    drop(height);
    let bytes = t
        .time("encode", || image_bytes(&img, format, c.png))
        .map_err(|m| Error::output(&c.output, m))?;
    drop(img);
    t.time("write", || crate::output::write_atomic(&c.output, &bytes))?;
    Ok(t)
}
