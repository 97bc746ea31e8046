//! Every image bumpbake decodes, whichever command asks (`preview` textures, `validate`'s
//! normal-map checks, `normalmap` and `bake` inputs, OBJ bump-map classification), is recognised
//! and decoded here, so that all of them read the same formats and refuse the same files the same
//! way.
//!
//! Formats are told by their magic bytes, never by a file name or a glTF `mimeType`: PNG, JPEG,
//! WebP (lossy and lossless), TIFF, OpenEXR and KTX2 (Basis Universal and the plain formats:
//! `ktx2/`) are decoded; the other formats glTF extensions allow, and the KTX2 variants
//! not read, are named in the error, so that callers can say plainly what was not read.
//!
//! Decoding does not trust the file. An image header can claim any size (a 100-byte PNG can say
//! it is 200000 x 200000 pixels); decoding it blindly would try to allocate 160 GB. The header is
//! read first, sizes past the [`Limits`] are refused before anything is allocated, and the decoder
//! runs under [`image::Limits`] so that its own allocations stay bounded too. Errors are one line of
//! plain words: the format's name and what is wrong, never the decoder's debug text.
//!
//! Commands that only carry images along (`tangents` copies or embeds them byte for byte) never
//! decode them at all.

pub mod ktx2;

use crate::error::{Fault, Faulty, Setting, Words};
use crate::scene::texture_images::TextureImage;
use image::{DynamicImage, ImageDecoder, ImageError, ImageFormat, ImageReader};
use std::io::Cursor;

/// Longest side of a glTF texture accepted, in pixels.
pub const MAX_SIDE: u32 = 16384;
/// Most pixels of a glTF texture accepted (8192 x 8192).
pub const MAX_PIXELS: u64 = 8192 * 8192;
/// Most bytes a decoder may allocate at once for a glTF texture.
pub const MAX_ALLOC: u64 = 768 * 1024 * 1024;

/// What an image may claim before it is refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    pub max_side: u32,
    pub max_pixels: u64,
    /// Bytes the decoder may allocate at once.
    pub max_alloc: u64,
    /// The setting that raises the limit, for the message.
    pub option: Option<Setting>,
}

impl Limits {
    /// glTF textures (`preview`, `validate`, OBJ bump maps).
    pub const TEXTURE: Limits =
        Limits { max_side: MAX_SIDE, max_pixels: MAX_PIXELS, max_alloc: MAX_ALLOC, option: None };

    /// Image files given by the caller, up to `max_pixels` ([`Setting::MaxPixels`]). The decoder's
    /// own buffers are bounded to what that many RGBA float pixels need (16 bytes each).
    pub fn file(max_pixels: u64) -> Limits {
        let max_alloc = max_pixels.saturating_mul(16).max(1 << 24);
        Limits { max_side: u32::MAX, max_pixels, max_alloc, option: Some(Setting::MaxPixels) }
    }
}

/// An image format, as its bytes tell it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Png,
    Jpeg,
    WebP,
    Tiff,
    OpenExr,
    /// KTX2 (KHR_texture_basisu's container).
    Ktx2,
    Gif,
    Bmp,
    Dds,
    Avif,
    /// Nothing bumpbake recognises.
    Unknown,
}

/// The formats bumpbake decodes, for messages.
pub const DECODED: &str = "PNG, JPEG, WebP, TIFF, OpenEXR, KTX2";

impl Kind {
    /// Recognises a format by its first bytes.
    pub fn sniff(b: &[u8]) -> Kind {
        let at = |o: usize, m: &[u8]| b.get(o..o + m.len()) == Some(m);
        if at(0, b"\x89PNG\r\n\x1a\n") {
            Kind::Png
        } else if at(0, &[0xFF, 0xD8, 0xFF]) {
            Kind::Jpeg
        } else if at(0, b"RIFF") && at(8, b"WEBP") {
            Kind::WebP
        } else if at(0, b"II*\0") || at(0, b"MM\0*") {
            Kind::Tiff
        } else if at(0, &[0x76, 0x2F, 0x31, 0x01]) {
            Kind::OpenExr
        } else if at(0, &[0xAB, b'K', b'T', b'X', b' ', b'2', b'0', 0xBB, 0x0D, 0x0A, 0x1A, 0x0A]) {
            Kind::Ktx2
        } else if at(0, b"GIF87a") || at(0, b"GIF89a") {
            Kind::Gif
        } else if at(0, b"BM") {
            Kind::Bmp
        } else if at(0, b"DDS ") {
            Kind::Dds
        } else if at(4, b"ftypavif") || at(4, b"ftypavis") {
            Kind::Avif
        } else {
            Kind::Unknown
        }
    }

    /// The decoded format a file name's extension claims, if any (for messages only: formats are
    /// told by their bytes).
    pub fn from_extension(path: &std::path::Path) -> Option<Kind> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "png" => Some(Kind::Png),
            "jpg" | "jpeg" => Some(Kind::Jpeg),
            "webp" => Some(Kind::WebP),
            "tif" | "tiff" => Some(Kind::Tiff),
            "exr" => Some(Kind::OpenExr),
            "ktx2" => Some(Kind::Ktx2),
            _ => None,
        }
    }

    /// The format's name, in words.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Png => "PNG",
            Kind::Jpeg => "JPEG",
            Kind::WebP => "WebP",
            Kind::Tiff => "TIFF",
            Kind::OpenExr => "OpenEXR",
            Kind::Ktx2 => "KTX2",
            Kind::Gif => "GIF",
            Kind::Bmp => "BMP",
            Kind::Dds => "DDS",
            Kind::Avif => "AVIF",
            Kind::Unknown => "an unknown format",
        }
    }

    /// Whether [`decode`] reads this format (for KTX2, some of its variants: [`not_decoded_why`]).
    pub fn is_decoded(self) -> bool {
        self.format().is_some() || self == Kind::Ktx2
    }

    fn format(self) -> Option<ImageFormat> {
        match self {
            Kind::Png => Some(ImageFormat::Png),
            Kind::Jpeg => Some(ImageFormat::Jpeg),
            Kind::WebP => Some(ImageFormat::WebP),
            Kind::Tiff => Some(ImageFormat::Tiff),
            Kind::OpenExr => Some(ImageFormat::OpenExr),
            _ => None,
        }
    }
}

/// Why a format is not decoded, in words.
fn not_decoded(kind: Kind) -> String {
    match kind {
        Kind::Unknown => format!("not an image in a format bumpbake reads ({DECODED})"),
        k => format!("a {} image, which bumpbake does not decode (it reads {DECODED})", k.name()),
    }
}

/// One line of plain words for a decoder's error. The `image` crate's own messages name formats
/// by their Rust names (`Jpeg`, `Some(Png)`), so only the underlying cause is kept.
fn describe(kind: Kind, e: ImageError) -> Fault {
    // Some decoders quote their message (a string's debug form); the quotes are not words.
    let one_line = |s: String| s.split_whitespace().collect::<Vec<_>>().join(" ").trim_matches('"').to_string();
    let name = kind.name();
    let words = match &e {
        ImageError::Decoding(d) => match std::error::Error::source(d) {
            Some(cause) => format!("cannot decode as {name}: {}", one_line(cause.to_string())),
            None => format!("cannot decode as {name}: the data is malformed"),
        },
        ImageError::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            format!("cannot decode as {name}: the file ends early (truncated)")
        }
        ImageError::IoError(io) => format!("cannot decode as {name}: {}", one_line(io.to_string())),
        ImageError::Limits(_) => format!("cannot decode as {name}: it needs more memory than bumpbake allows"),
        ImageError::Unsupported(_) => {
            format!("cannot decode as {name}: it uses a {name} feature bumpbake's decoder does not support")
        }
        ImageError::Parameter(p) => format!("cannot decode as {name}: {}", one_line(p.to_string())),
        ImageError::Encoding(_) => format!("cannot decode as {name}"),
    };
    Fault::caused_by(words, e)
}

/// Why bumpbake will not decode these bytes, when their header says so: a format it does not
/// read, or a KTX2 variant it does not read (a block-compressed vkFormat, a cube map). `None`
/// for everything else, broken files included: decoding those says what is wrong.
pub fn not_decoded_why(bytes: &[u8]) -> Option<String> {
    match Kind::sniff(bytes) {
        Kind::Ktx2 => ktx2::not_decoded(bytes),
        Kind::Unknown => None,
        k if !k.is_decoded() => Some(not_decoded(k)),
        _ => None,
    }
}

fn reader<R: std::io::BufRead + std::io::Seek>(head: &[u8], source: R) -> Faulty<(Kind, ImageReader<R>)> {
    let kind = Kind::sniff(head);
    let format = kind.format().ok_or_else(|| not_decoded(kind))?;
    let mut r = ImageReader::new(source);
    r.set_format(format);
    Ok((kind, r))
}

fn decoder_limits(l: &Limits) -> image::Limits {
    let mut out = image::Limits::default();
    out.max_image_width = Some(l.max_side);
    out.max_image_height = Some(l.max_side);
    out.max_alloc = Some(l.max_alloc);
    out
}

/// The size an image's header claims, checked against the texture limits; nothing is decoded.
pub fn dimensions(bytes: &[u8]) -> Faulty<(u32, u32)> {
    dimensions_within(bytes, &Limits::TEXTURE)
}

/// [`dimensions`] under other limits.
pub fn dimensions_within(bytes: &[u8], limits: &Limits) -> Faulty<(u32, u32)> {
    if Kind::sniff(bytes) == Kind::Ktx2 {
        return ktx2::dimensions_within(bytes, limits);
    }
    let (kind, mut r) = reader(bytes, Cursor::new(bytes))?;
    // Only the header is read here; the size checks below give the clearer message.
    let mut header_only = image::Limits::default();
    header_only.max_alloc = Some(limits.max_alloc);
    r.limits(header_only);
    let (w, h) = r.into_dimensions().map_err(|e| describe(kind, e))?;
    check_size_within(w, h, limits)?;
    Ok((w, h))
}

/// What an image's header says, in words.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Header {
    pub kind: Kind,
    pub width: u32,
    pub height: u32,
    /// `grey`, `grey+alpha`, `RGB` or `RGBA`.
    pub colour: &'static str,
    pub bits_per_channel: u16,
    /// How the pixels are stored, where the format has variants (KTX2: `Basis Universal UASTC +
    /// Zstandard`, `R8G8_UNORM + zlib`).
    pub variant: Option<String>,
}

/// Reads only the header: format, size and sample layout. Nothing is decoded and the size is not
/// checked against the limits (describing a huge image is fine; decoding it is not).
pub fn header(bytes: &[u8]) -> Faulty<Header> {
    if Kind::sniff(bytes) == Kind::Ktx2 {
        let (width, height, colour, bits_per_channel, variant) = ktx2::describe(bytes)?;
        return Ok(Header { kind: Kind::Ktx2, width, height, colour, bits_per_channel, variant: Some(variant) });
    }
    let (kind, mut r) = reader(bytes, Cursor::new(bytes))?;
    let mut header_only = image::Limits::default();
    header_only.max_alloc = Some(MAX_ALLOC);
    r.limits(header_only);
    let decoder = r.into_decoder().map_err(|e| describe(kind, e))?;
    let (width, height) = decoder.dimensions();
    let ct = decoder.color_type();
    let colour = match (ct.has_color(), ct.has_alpha()) {
        (false, false) => "grey",
        (false, true) => "grey+alpha",
        (true, false) => "RGB",
        (true, true) => "RGBA",
    };
    let bits_per_channel = ct.bits_per_pixel() / ct.channel_count() as u16;
    Ok(Header { kind, width, height, colour, bits_per_channel, variant: None })
}

/// Refuses empty images and those past the texture limits.
pub fn check_size(w: u32, h: u32) -> Faulty<()> {
    check_size_within(w, h, &Limits::TEXTURE)
}

pub fn check_size_within(w: u32, h: u32, l: &Limits) -> Faulty<()> {
    if w == 0 || h == 0 {
        return Err(format!("image is {w}x{h} pixels (empty)").into());
    }
    let pixels = w as u64 * h as u64;
    if let (Some(option), true) = (l.option, pixels > l.max_pixels) {
        let msg = format!("image is {w}x{h} = {pixels} pixels, more than the limit of {} (", l.max_pixels);
        return Err(Words::from(msg).name(option).text(")").into());
    }
    if w > l.max_side || h > l.max_side || pixels > l.max_pixels {
        let side = if l.max_side == u32::MAX { String::new() } else { format!("at most {} per side and ", l.max_side) };
        return Err(format!(
            "image claims {w}x{h} = {pixels} pixels, more than bumpbake decodes ({side}{} pixels)",
            l.max_pixels
        )
        .into());
    }
    Ok(())
}

/// Decodes a glTF texture after checking its header, under [`Limits::TEXTURE`].
pub fn decode(bytes: &[u8]) -> Faulty<DynamicImage> {
    decode_within(bytes, &Limits::TEXTURE)
}

/// Decodes an image after checking its header against `limits`.
pub fn decode_within(bytes: &[u8], limits: &Limits) -> Faulty<DynamicImage> {
    if Kind::sniff(bytes) == Kind::Ktx2 {
        return ktx2::decode_within(bytes, limits);
    }
    dimensions_within(bytes, limits)?;
    if Kind::sniff(bytes) == Kind::Jpeg && !jpeg_is_whole(bytes) {
        return Err("cannot decode as JPEG: the file ends early (truncated)".into());
    }
    let (kind, r) = reader(bytes, Cursor::new(bytes))?;
    decode_reader(kind, r, limits)
}

/// Whether a JPEG's last scan is followed by its end-of-image marker. The JPEG decoder fills the
/// missing part of a truncated file with grey and reports success; a truncated normal or height
/// map must be refused instead. Entropy-coded data cannot hold `FF D9` (an `FF` byte there is
/// stuffed as `FF 00`), so the marker after the last start-of-scan is the image's real end.
fn jpeg_is_whole(b: &[u8]) -> bool {
    let last_scan = b.windows(2).rposition(|w| w == [0xFF, 0xDA]);
    last_scan.is_some_and(|s| b[s..].windows(2).any(|w| w == [0xFF, 0xD9]))
}

/// Decodes from a reader whose header has been recognised; the size is checked from the header
/// before any pixel buffer is allocated.
fn decode_reader<R: std::io::BufRead + std::io::Seek>(
    kind: Kind,
    mut r: ImageReader<R>,
    limits: &Limits,
) -> Faulty<DynamicImage> {
    r.limits(decoder_limits(limits));
    let decoder = r.into_decoder().map_err(|e| describe(kind, e))?;
    let (w, h) = decoder.dimensions();
    check_size_within(w, h, limits)?;
    DynamicImage::from_decoder(decoder).map_err(|e| describe(kind, e))
}

/// Reads and decodes an image file given on the command line; errors name the file.
pub fn read_file(path: &std::path::Path, max_pixels: u64) -> crate::error::Result<DynamicImage> {
    use crate::error::Error;
    use std::io::{Read, Seek};
    let open = |e: std::io::Error| Error::input(path, format!("cannot open: {e}"));
    let mut file = std::io::BufReader::with_capacity(1 << 16, std::fs::File::open(path).map_err(open)?);
    let mut head = Vec::with_capacity(16);
    (&mut file).take(16).read_to_end(&mut head).map_err(open)?;
    file.rewind().map_err(open)?;
    if Kind::sniff(&head) == Kind::Unknown {
        if let Some(named) = Kind::from_extension(path) {
            let m = format!("cannot decode as {0}: the file does not start as a {0} file does", named.name());
            return Err(Error::input(path, m));
        }
    }
    let limits = Limits::file(max_pixels);
    if matches!(Kind::sniff(&head), Kind::Jpeg | Kind::Ktx2) {
        // Whole in memory: a JPEG to check its end, a KTX2 to follow its index; both are small
        // beside their pixels.
        let bytes = std::fs::read(path).map_err(open)?;
        return decode_within(&bytes, &limits).map_err(|m| Error::in_file(path, m));
    }
    let (kind, r) = reader(&head, file).map_err(|m| Error::in_file(path, m))?;
    decode_reader(kind, r, &limits).map_err(|m| Error::in_file(path, m))
}

/// Whether the file starts like a PNG (read from its first bytes only).
pub fn file_is_png(path: &std::path::Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 8];
    std::fs::File::open(path).and_then(|mut f| f.read_exact(&mut head)).is_ok() && Kind::sniff(&head) == Kind::Png
}

/// The image of `texture` to decode, with its bytes: the first of
/// [`Scene::texture_images`](crate::scene::Scene::texture_images) not in a format bumpbake
/// knows and does not decode. Also returns the images passed over, with
/// their formats and why, so that callers can say what was not read.
pub fn texture_image_to_decode(scene: &crate::scene::Scene, texture: usize) -> crate::error::Result<TextureChoice> {
    let mut choice = TextureChoice::default();
    for ti in scene.texture_images(texture) {
        let bytes = scene.image_bytes(ti.image)?;
        // Bytes in no format at all are a broken image, for the decoder to refuse: only
        // formats (and KTX2 variants) known and not decoded are passed over.
        match not_decoded_why(&bytes) {
            None if choice.chosen.is_none() => choice.chosen = Some((ti, bytes)),
            None => {}
            Some(why) => choice.passed_over.push((ti, Kind::sniff(&bytes), why)),
        }
    }
    Ok(choice)
}

/// What [`texture_image_to_decode`] found.
#[derive(Debug, Default)]
pub struct TextureChoice {
    /// The image to decode and its encoded bytes.
    pub chosen: Option<(TextureImage, Vec<u8>)>,
    /// Images of the texture in formats bumpbake does not decode, and why.
    pub passed_over: Vec<(TextureImage, Kind, String)>,
}

impl TextureChoice {
    /// One line on the images passed over, if any (`texture` names the texture).
    pub fn note(&self, texture: usize) -> Option<String> {
        if self.passed_over.is_empty() {
            return None;
        }
        let what: Vec<String> = self
            .passed_over
            .iter()
            .map(|(ti, k, why)| match ti.extension {
                Some(ext) => format!("image {} ({}, {ext}) not decoded: {why}", ti.image, k.name()),
                None => format!("image {} ({}) not decoded: {why}", ti.image, k.name()),
            })
            .collect();
        let then = match &self.chosen {
            Some((ti, _)) => format!("image {} is used instead", ti.image),
            None => "the texture is left out".to_string(),
        };
        Some(format!("texture {texture}: {}; {then}", what.join("; ")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn encoded(format: ImageFormat) -> Vec<u8> {
        let img = image::RgbImage::from_fn(8, 8, |x, y| image::Rgb([x as u8 * 30, y as u8 * 30, 255]));
        let mut c = Cursor::new(Vec::new());
        img.write_to(&mut c, format).unwrap();
        c.into_inner()
    }

    #[test]
    fn sizes_past_the_limits_are_refused_before_decoding() {
        assert!(check_size(200_000, 200_000).unwrap_err().to_string().contains("200000x200000"));
        assert!(check_size(MAX_SIDE + 1, 1).is_err());
        assert!(check_size(0, 5).is_err());
        assert!(check_size(MAX_SIDE, MAX_SIDE).is_err(), "too many pixels in all");
        assert!(check_size(8192, 8192).is_ok());
        assert!(check_size_within(100, 100, &Limits::file(9_999))
            .unwrap_err()
            .to_string()
            .contains("limit of 9999 (max_pixels)"));
    }

    #[test]
    fn garbage_is_not_an_image() {
        assert!(decode(b"").is_err());
        assert!(decode(b"hello world, not an image").unwrap_err().to_string().contains("PNG, JPEG, WebP"));
        assert!(decode(b"\x89PNG\r\n\x1a\n").is_err());
    }

    #[test]
    fn every_format_is_sniffed_and_decoded_to_its_pixels() {
        for (format, kind) in
            [(ImageFormat::Png, Kind::Png), (ImageFormat::Jpeg, Kind::Jpeg), (ImageFormat::WebP, Kind::WebP)]
        {
            let bytes = encoded(format);
            assert_eq!(Kind::sniff(&bytes), kind);
            let h = header(&bytes).unwrap();
            assert_eq!((h.kind, h.width, h.height, h.colour, h.bits_per_channel), (kind, 8, 8, "RGB", 8));
            let img = decode(&bytes).unwrap().to_rgb8();
            assert_eq!(img.dimensions(), (8, 8));
            // JPEG is lossy: within a few steps of the source; the others exactly.
            let tol = if kind == Kind::Jpeg { 12 } else { 0 };
            let p = img.get_pixel(5, 2).0;
            assert!(p[0].abs_diff(150) <= tol && p[1].abs_diff(60) <= tol && p[2].abs_diff(255) <= tol, "{p:?}");
        }
    }

    #[test]
    fn formats_not_decoded_and_broken_files_are_named_in_words() {
        let ktx2 = [0xAB, b'K', b'T', b'X', b' ', b'2', b'0', 0xBB, 0x0D, 0x0A, 0x1A, 0x0A, 0, 0, 0, 0];
        let e = decode(&ktx2).unwrap_err();
        assert!(e.to_string().starts_with("cannot decode as KTX2: the file ends early"), "{e}");
        let e = decode(b"GIF89a\x01\x00\x01\x00").unwrap_err();
        assert!(e.to_string().starts_with("a GIF image"), "{e}");
        let jpeg = encoded(ImageFormat::Jpeg);
        // Cut anywhere in its scan, a JPEG still "decodes" (the rest grey): it must be refused.
        for cut in [jpeg.len() / 3, jpeg.len() - 2] {
            let e = decode(&jpeg[..cut]).unwrap_err();
            assert!(e.to_string().starts_with("cannot decode as JPEG"), "{e}");
        }
        let webp = encoded(ImageFormat::WebP);
        let e = decode(&webp[..webp.len() - 10]).unwrap_err();
        assert!(e.to_string().starts_with("cannot decode as WebP"), "{e}");
        for e in [decode(&jpeg[..40]).unwrap_err(), decode(&webp[..20]).unwrap_err()] {
            let words = e.to_string();
            assert!(!words.contains("Some(") && !words.contains("Jpeg") && !words.contains("WebP)"), "{e}");
            // The decoder's own error stays reachable underneath the words.
            assert!(std::error::Error::source(&e).is_some(), "{e}");
        }
    }
}
