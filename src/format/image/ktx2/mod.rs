//! KTX2, the texture container of production glTF (KHR_texture_basisu), read into the same
//! [`DynamicImage`] every other image format becomes, so that every command that reads pixels
//! reads KTX2 through the image reader ([`super`]).
//!
//! What is decoded: Basis Universal (ETC1S with BasisLZ, UASTC with or without Zstandard),
//! transcoded to RGBA8 (`basis.rs`), and the plain formats a normal, height or colour map uses
//! (8-bit R/RG/RGB/RGBA, UNORM and SRGB; 16-bit UNORM R/RG/RGB/RGBA; float16/32 R and RGBA)
//! with no, Zstandard or zlib supercompression. Only the base mip level of a 2D texture is read
//! by the commands: it is the one a texture check or a bake works on ([`decode_levels_within`]
//! reads them all, for checking what `write.rs` wrote). Block-compressed formats (BC*, ETC2, ASTC)
//! and arrays, cube maps and volumes are named and refused; a glTF texture with a fallback source
//! then falls back to it.
//!
//! Two-channel maps (RG8, RG16, and Basis files whose data format descriptor says the two
//! channels are red and green: a BC5-style normal map) carry only x and y; z is rebuilt as
//! `sqrt(1 - x² - y²)`, as a renderer sampling them does, so the checks see a whole normal.
//!
//! SRGB formats are read as stored (no transfer function applied), as PNGs with an sRGB chunk are:
//! a normal or height map's bytes are data, and an sRGB label on one is a mistake the texel checks
//! see for themselves.
//!
//! Nothing is trusted: the size is checked against the caller's limits from the header before
//! anything is allocated, every decompressed length is bounded by what the header says the level
//! holds, and every malformed file is one line of words.

mod basis;
mod etc1_hints;
mod uastc;
mod write;

pub use write::{encode, Codec, MAX_SIDE};

use super::{check_size_within, Limits};
use image::{DynamicImage, ImageBuffer, Luma, Rgb, Rgba};

/// One level to encode: RGB8 texels, row-major from the top row.
pub struct Level<'a> {
    pub width: u32,
    pub height: u32,
    pub rgb: &'a [u8],
}

/// How a KTX2 file stores its base level, as far as bumpbake is concerned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Payload {
    /// ETC1S blocks with BasisLZ supercompression.
    Etc1s,
    /// UASTC blocks, raw or under Zstandard.
    Uastc,
    /// Uncompressed texels of a vkFormat bumpbake reads.
    Plain(Plain),
}

/// An uncompressed vkFormat bumpbake reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Plain {
    vk_format: u32,
    channels: u8,
    sample: Sample,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Sample {
    U8,
    U16,
    F16,
    F32,
}

impl Sample {
    fn bytes(self) -> usize {
        match self {
            Sample::U8 => 1,
            Sample::U16 | Sample::F16 => 2,
            Sample::F32 => 4,
        }
    }
}

fn plain(vk_format: u32) -> Option<Plain> {
    let (channels, sample) = match vk_format {
        9 | 15 => (1, Sample::U8),  // R8_UNORM, R8_SRGB
        16 | 22 => (2, Sample::U8), // R8G8_UNORM, R8G8_SRGB
        23 | 29 => (3, Sample::U8), // R8G8B8_UNORM, R8G8B8_SRGB
        37 | 43 => (4, Sample::U8), // R8G8B8A8_UNORM, R8G8B8A8_SRGB
        70 => (1, Sample::U16),     // R16_UNORM
        77 => (2, Sample::U16),     // R16G16_UNORM
        84 => (3, Sample::U16),     // R16G16B16_UNORM
        91 => (4, Sample::U16),     // R16G16B16A16_UNORM
        76 => (1, Sample::F16),     // R16_SFLOAT
        97 => (4, Sample::F16),     // R16G16B16A16_SFLOAT
        100 => (1, Sample::F32),    // R32_SFLOAT
        109 => (4, Sample::F32),    // R32G32B32A32_SFLOAT
        _ => return None,
    };
    Some(Plain { vk_format, channels, sample })
}

/// A vkFormat's name, for messages (those bumpbake reads, and the block formats a texture may
/// come in; others by number).
fn vk_format_name(v: u32) -> String {
    let name = match v {
        9 => "R8_UNORM",
        15 => "R8_SRGB",
        16 => "R8G8_UNORM",
        22 => "R8G8_SRGB",
        23 => "R8G8B8_UNORM",
        29 => "R8G8B8_SRGB",
        37 => "R8G8B8A8_UNORM",
        43 => "R8G8B8A8_SRGB",
        70 => "R16_UNORM",
        77 => "R16G16_UNORM",
        84 => "R16G16B16_UNORM",
        91 => "R16G16B16A16_UNORM",
        76 => "R16_SFLOAT",
        97 => "R16G16B16A16_SFLOAT",
        100 => "R32_SFLOAT",
        109 => "R32G32B32A32_SFLOAT",
        131..=146 => "a BC1-BC7 block format",
        147..=156 => "an ETC2/EAC block format",
        157..=184 => "an ASTC block format",
        _ => return format!("vkFormat {v}"),
    };
    name.to_string()
}

/// The formats bumpbake reads from KTX2, for messages.
const READS: &str = "Basis Universal ETC1S/UASTC, and 8-bit, 16-bit and float R/RG/RGB/RGBA";

/// A KTX2 file's header, checked enough to decode it.
struct Parsed<'a> {
    width: u32,
    height: u32,
    payload: Payload,
    /// 0 none, 1 BasisLZ, 2 Zstandard, 3 zlib.
    supercompression: u32,
    /// Whether a two-channel map's z is to be rebuilt.
    two_channel: TwoChannel,
    reader: ::ktx2::Reader<&'a [u8]>,
}

/// Where the x and y of a two-channel map are after decoding to RGBA.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum TwoChannel {
    No,
    /// x in red, y in green.
    RedGreen,
    /// x in red (and green, blue), y in alpha: Basis' RRRG / ETC1S with an alpha slice of green.
    RedAlpha,
    /// UASTC's RG label: libktx stores such maps as RRRG, the label's name says R and G. Y is in
    /// alpha when green repeats red everywhere, else in green.
    Either,
}

const NONE: u32 = 0;
const BASIS_LZ: u32 = 1;
const ZSTD: u32 = 2;
const ZLIB: u32 = 3;

/// KTX2 data format descriptor colour models.
const MODEL_ETC1S: u32 = 163;
const MODEL_UASTC: u32 = 166;

fn parse(bytes: &[u8]) -> crate::error::Faulty<Parsed<'_>> {
    let reader = ::ktx2::Reader::new(bytes).map_err(|e| match e {
        ::ktx2::ParseError::UnexpectedEnd => {
            "cannot decode as KTX2: the file ends early or its index points past its end".to_string()
        }
        e => format!("cannot decode as KTX2: {e}"),
    })?;
    let h = reader.header();
    if h.pixel_depth > 1 || h.face_count != 1 || h.layer_count > 1 {
        return Err(format!(
            "a KTX2 {}, which bumpbake does not decode (it reads 2D textures)",
            if h.pixel_depth > 1 {
                "volume texture"
            } else if h.face_count != 1 {
                "cube map"
            } else {
                "texture array"
            }
        )
        .into());
    }
    let supercompression = h.supercompression_scheme.map_or(NONE, |s| s.value());
    let model = reader.basic_dfd().and_then(|d| d.color_model).map_or(0, |m| m.value() as u32);
    let ids: Vec<u8> =
        reader.basic_dfd().map(|d| d.sample_information.iter().map(|s| s.channel_type).collect()).unwrap_or_default();
    let (payload, two_channel) = match h.format.map(|f| f.value()) {
        None if model == MODEL_ETC1S => {
            // Sample channel ids: RGB 0, RRR 3, GGG 4, AAA 15. An RRR + GGG file (toktx
            // --normal_mode, basisu -separate_rg_to_color_alpha) has x in colour, y in alpha.
            let tc = if ids == [3, 4] { TwoChannel::RedAlpha } else { TwoChannel::No };
            (Payload::Etc1s, tc)
        }
        None if model == MODEL_UASTC => {
            // The one sample's channel id: RGB 0, RGBA 3, RRR 4, RRRG 5, RG 6.
            let tc = match ids.first() {
                Some(5) => TwoChannel::RedAlpha,
                Some(6) => TwoChannel::Either,
                _ => TwoChannel::No,
            };
            (Payload::Uastc, tc)
        }
        None => {
            return Err(format!(
                "a KTX2 image with no vkFormat and data format model {model}, which bumpbake does not decode (it reads {READS})"
            ).into())
        }
        Some(v) => match plain(v) {
            Some(p) => {
                if p.sample.bytes() as u32 != h.type_size {
                    return Err(format!(
                        "cannot decode as KTX2: its typeSize is {} but {} has {}-byte samples",
                        h.type_size,
                        vk_format_name(v),
                        p.sample.bytes()
                    ).into());
                }
                let tc = if p.channels == 2 { TwoChannel::RedGreen } else { TwoChannel::No };
                (Payload::Plain(p), tc)
            }
            None => {
                return Err(format!(
                    "a KTX2 image in {}, which bumpbake does not decode (it reads {READS})",
                    vk_format_name(v)
                ).into())
            }
        },
    };
    let allowed = match payload {
        Payload::Etc1s => supercompression == BASIS_LZ,
        Payload::Uastc | Payload::Plain(_) => matches!(supercompression, NONE | ZSTD | ZLIB),
    };
    if !allowed {
        let name = match supercompression {
            NONE => "none".to_string(),
            BASIS_LZ => "BasisLZ".to_string(),
            ZSTD => "Zstandard".to_string(),
            ZLIB => "zlib".to_string(),
            s => format!("scheme {s}"),
        };
        let what = match payload {
            Payload::Etc1s => "ETC1S".to_string(),
            Payload::Uastc => "UASTC".to_string(),
            Payload::Plain(p) => vk_format_name(p.vk_format),
        };
        return Err(format!("cannot decode as KTX2: {what} data with supercompression {name} is not valid KTX2").into());
    }
    Ok(Parsed { width: h.pixel_width, height: h.pixel_height, payload, supercompression, two_channel, reader })
}

/// The size a KTX2 header claims, checked against `limits`; nothing is decoded.
pub fn dimensions_within(bytes: &[u8], limits: &Limits) -> crate::error::Faulty<(u32, u32)> {
    let p = parse(bytes)?;
    check_size_within(p.width, p.height, limits)?;
    Ok((p.width, p.height))
}

/// What the header says: size, `grey`/`RGB`/`RGBA` as decoded, bits per channel as decoded, and
/// the variant in words (for `inspect`).
pub fn describe(bytes: &[u8]) -> crate::error::Faulty<(u32, u32, &'static str, u16, String)> {
    let p = parse(bytes)?;
    let (colour, bits) = match p.payload {
        Payload::Etc1s | Payload::Uastc if p.two_channel != TwoChannel::No => ("RGB", 8),
        Payload::Etc1s | Payload::Uastc => ("RGBA", 8),
        Payload::Plain(pl) => {
            let bits = match pl.sample {
                Sample::U8 => 8,
                Sample::U16 => 16,
                Sample::F16 | Sample::F32 => 32,
            };
            let colour = match (pl.channels, pl.sample) {
                (1, Sample::F16 | Sample::F32) => "RGB",
                (1, _) => "grey",
                (2 | 3, _) => "RGB",
                _ => "RGBA",
            };
            (colour, bits)
        }
    };
    Ok((p.width, p.height, colour, bits, variant(&p)))
}

/// The variant in words: `UASTC + Zstandard`, `R8G8_UNORM + zlib`.
fn variant(p: &Parsed) -> String {
    let what = match p.payload {
        Payload::Etc1s => "Basis Universal ETC1S".to_string(),
        Payload::Uastc => "Basis Universal UASTC".to_string(),
        Payload::Plain(pl) => vk_format_name(pl.vk_format),
    };
    let how = match p.supercompression {
        BASIS_LZ => " + BasisLZ",
        ZSTD => " + Zstandard",
        ZLIB => " + zlib",
        _ => "",
    };
    format!("{what}{how}")
}

/// Why a KTX2 file will not be decoded, when its header says so (a variant bumpbake does not
/// read); `None` when it is one bumpbake decodes or is too broken to tell (then decoding it
/// gives the error).
pub fn not_decoded(bytes: &[u8]) -> Option<String> {
    match parse(bytes) {
        Err(e) if !e.to_string().starts_with("cannot decode") => Some(e.to_string()),
        _ => None,
    }
}

/// Decodes the base level of a KTX2 image, after checking its size against `limits`.
pub fn decode_within(bytes: &[u8], limits: &Limits) -> crate::error::Faulty<DynamicImage> {
    let p = parse(bytes)?;
    check_size_within(p.width, p.height, limits)?;
    let level = p.reader.levels().next().ok_or("cannot decode as KTX2: it has no mip level")?;
    decode_level(&p, 0, level)
}

/// Decodes every mip level of a KTX2 image (level 0 first, sized as KTX2 sizes them), after
/// checking the base size against `limits`.
pub fn decode_levels_within(bytes: &[u8], limits: &Limits) -> crate::error::Faulty<Vec<DynamicImage>> {
    let p = parse(bytes)?;
    check_size_within(p.width, p.height, limits)?;
    let levels: Vec<_> = p.reader.levels().collect();
    if levels.is_empty() {
        return Err("cannot decode as KTX2: it has no mip level".into());
    }
    levels.into_iter().enumerate().map(|(k, level)| decode_level(&p, k, level)).collect()
}

fn decode_level(p: &Parsed, k: usize, level: ::ktx2::Level) -> crate::error::Faulty<DynamicImage> {
    let (w, h) = ((p.width >> k).max(1), (p.height >> k).max(1));
    let rgba = match p.payload {
        Payload::Etc1s => basis::etc1s(&p.reader, k, level.data, w, h)?,
        Payload::Uastc => {
            let blocks = (w as usize).div_ceil(4) * (h as usize).div_ceil(4) * 16;
            let data = unpack(level.data, level.uncompressed_byte_length, blocks, p.supercompression)?;
            basis::uastc(&data, w, h, p.two_channel != TwoChannel::No)?
        }
        Payload::Plain(pl) => {
            let len = w as usize * h as usize * pl.channels as usize * pl.sample.bytes();
            let data = unpack(level.data, level.uncompressed_byte_length, len, p.supercompression)?;
            return Ok(plain_image(&data, w, h, pl));
        }
    };
    Ok(match p.two_channel {
        TwoChannel::No => {
            DynamicImage::ImageRgba8(ImageBuffer::from_raw(w, h, rgba).ok_or("cannot decode as KTX2: short image")?)
        }
        tc => {
            let green_is_red = || rgba.chunks_exact(4).all(|t| t[1] == t[0]);
            let y = if tc == TwoChannel::RedAlpha || (tc == TwoChannel::Either && green_is_red()) { 3 } else { 1 };
            let rgb = rgba.chunks_exact(4).flat_map(|t| with_z(t[0], t[y])).collect();
            DynamicImage::ImageRgb8(ImageBuffer::from_raw(w, h, rgb).ok_or("cannot decode as KTX2: short image")?)
        }
    })
}

/// The base level's bytes, decompressed if need be; exactly `expected` of them. Decompression
/// stops past `expected` bytes, whatever the stream or the index claims.
fn unpack(data: &[u8], uncompressed: u64, expected: usize, scheme: u32) -> crate::error::Faulty<Vec<u8>> {
    use std::io::Read;
    let out = match scheme {
        NONE => {
            if data.len() != expected {
                return Err(format!(
                    "cannot decode as KTX2: its base level holds {} bytes where its size needs {expected}",
                    data.len()
                )
                .into());
            }
            return Ok(data.to_vec());
        }
        ZSTD => {
            let mut dec = ruzstd::decoding::StreamingDecoder::new(data)
                .map_err(|e| format!("cannot decode as KTX2: its Zstandard data is malformed ({e})"))?;
            let mut out = Vec::with_capacity(expected.min(1 << 26));
            (&mut dec)
                .take(expected as u64 + 1)
                .read_to_end(&mut out)
                .map_err(|e| format!("cannot decode as KTX2: its Zstandard data is malformed ({e})"))?;
            out
        }
        _ => miniz_oxide::inflate::decompress_to_vec_zlib_with_limit(data, expected + 1)
            .map_err(|e| format!("cannot decode as KTX2: its zlib data is malformed ({:?})", e.status))?,
    };
    if out.len() != expected || uncompressed != expected as u64 {
        return Err(format!(
            "cannot decode as KTX2: its base level inflates to {} bytes (the index says {uncompressed}) where its size needs {expected}",
            out.len()
        ).into());
    }
    Ok(out)
}

/// A unit normal's z from 8-bit x and y, as the texel of an RGB map.
fn with_z(x: u8, y: u8) -> [u8; 3] {
    let (fx, fy) = (x as f64 / 127.5 - 1.0, y as f64 / 127.5 - 1.0);
    let z = (1.0 - fx * fx - fy * fy).max(0.0).sqrt();
    [x, y, ((z + 1.0) * 127.5).round() as u8]
}

fn with_z16(x: u16, y: u16) -> [u16; 3] {
    let (fx, fy) = (x as f64 / 32767.5 - 1.0, y as f64 / 32767.5 - 1.0);
    let z = (1.0 - fx * fx - fy * fy).max(0.0).sqrt();
    [x, y, ((z + 1.0) * 32767.5).round() as u16]
}

fn f16_to_f32(h: u16) -> f32 {
    let sign = ((h >> 15) as u32) << 31;
    let exp = ((h >> 10) & 0x1f) as u32;
    let man = (h & 0x3ff) as u32;
    match exp {
        0 => {
            // Subnormal (or zero): man x 2^-24, exact in f32.
            let v = man as f32 / 16_777_216.0;
            if sign != 0 {
                -v
            } else {
                v
            }
        }
        31 => f32::from_bits(sign | 0x7f80_0000 | (man << 13)),
        e => f32::from_bits(sign | ((e + 112) << 23) | (man << 13)),
    }
}

/// Texels of a plain format, little-endian as KTX2 stores them, as the image type that keeps
/// their precision: single-channel floats become grey RGB floats (there is no grey float image).
fn plain_image(d: &[u8], w: u32, h: u32, p: Plain) -> DynamicImage {
    let u16s = || d.chunks_exact(2).map(|c| u16::from_le_bytes([c[0], c[1]]));
    let floats: Box<dyn Fn() -> Vec<f32>> = match p.sample {
        Sample::F16 => Box::new(|| u16s().map(f16_to_f32).collect()),
        _ => Box::new(|| d.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()),
    };
    // The lengths were checked against w x h x channels by `unpack`: from_raw cannot fail.
    match (p.channels, p.sample) {
        (1, Sample::U8) => DynamicImage::ImageLuma8(ImageBuffer::<Luma<u8>, _>::from_raw(w, h, d.to_vec()).unwrap()),
        (2, Sample::U8) => {
            let v = d.chunks_exact(2).flat_map(|t| with_z(t[0], t[1])).collect();
            DynamicImage::ImageRgb8(ImageBuffer::<Rgb<u8>, _>::from_raw(w, h, v).unwrap())
        }
        (3, Sample::U8) => DynamicImage::ImageRgb8(ImageBuffer::from_raw(w, h, d.to_vec()).unwrap()),
        (_, Sample::U8) => DynamicImage::ImageRgba8(ImageBuffer::from_raw(w, h, d.to_vec()).unwrap()),
        (1, Sample::U16) => {
            DynamicImage::ImageLuma16(ImageBuffer::<Luma<u16>, _>::from_raw(w, h, u16s().collect()).unwrap())
        }
        (2, Sample::U16) => {
            let v: Vec<u16> = u16s().collect();
            let v = v.chunks_exact(2).flat_map(|t| with_z16(t[0], t[1])).collect();
            DynamicImage::ImageRgb16(ImageBuffer::<Rgb<u16>, _>::from_raw(w, h, v).unwrap())
        }
        (3, Sample::U16) => DynamicImage::ImageRgb16(ImageBuffer::from_raw(w, h, u16s().collect()).unwrap()),
        (_, Sample::U16) => {
            DynamicImage::ImageRgba16(ImageBuffer::<Rgba<u16>, _>::from_raw(w, h, u16s().collect()).unwrap())
        }
        (1, _) => {
            let v = floats().into_iter().flat_map(|g| [g, g, g]).collect();
            DynamicImage::ImageRgb32F(ImageBuffer::from_raw(w, h, v).unwrap())
        }
        (_, _) => DynamicImage::ImageRgba32F(ImageBuffer::from_raw(w, h, floats()).unwrap()),
    }
}

#[cfg(test)]
mod tests;
