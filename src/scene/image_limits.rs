//! Decoding images without trusting them. An image header can claim any size (a 100-byte PNG can
//! say it is 200000 x 200000 pixels); decoding it blindly would try to allocate 160 GB. Every
//! image bumpbake decodes goes through [`decode`], which reads the header first, refuses sizes
//! past [`MAX_SIDE`] / [`MAX_PIXELS`] before anything is allocated, and decodes under
//! [`image::Limits`] so that a decoder's own allocations stay bounded too.
//!
//! Commands that only carry images along (`tangents` copies or embeds them byte for byte) never
//! decode them at all.

use image::{DynamicImage, ImageReader, Limits};
use std::io::Cursor;

/// Longest side accepted, in pixels.
pub const MAX_SIDE: u32 = 16384;
/// Most pixels accepted (8192 x 8192).
pub const MAX_PIXELS: u64 = 8192 * 8192;
/// Most bytes a decoder may allocate at once.
pub const MAX_ALLOC: u64 = 768 * 1024 * 1024;

/// The limits every decode runs under.
pub fn limits() -> Limits {
    let mut l = Limits::default();
    l.max_image_width = Some(MAX_SIDE);
    l.max_image_height = Some(MAX_SIDE);
    l.max_alloc = Some(MAX_ALLOC);
    l
}

fn reader(bytes: &[u8]) -> Result<ImageReader<Cursor<&[u8]>>, String> {
    let r =
        ImageReader::new(Cursor::new(bytes)).with_guessed_format().map_err(|e| format!("cannot read image: {e}"))?;
    if r.format().is_none() {
        return Err("not an image in a format bumpbake reads (PNG, TIFF, OpenEXR)".into());
    }
    Ok(r)
}

/// The size an image's header claims, checked against the limits; nothing is decoded.
pub fn dimensions(bytes: &[u8]) -> Result<(u32, u32), String> {
    let mut r = reader(bytes)?;
    // Only the header is read here; the size checks below give the clearer message.
    let mut header_only = Limits::default();
    header_only.max_alloc = Some(MAX_ALLOC);
    r.limits(header_only);
    let (w, h) = r.into_dimensions().map_err(|e| format!("unreadable image header: {e}"))?;
    check_size(w, h)?;
    Ok((w, h))
}

/// Refuses empty and oversized images.
pub fn check_size(w: u32, h: u32) -> Result<(), String> {
    if w == 0 || h == 0 {
        return Err(format!("image is {w}x{h} pixels (empty)"));
    }
    if w > MAX_SIDE || h > MAX_SIDE || w as u64 * h as u64 > MAX_PIXELS {
        return Err(format!(
            "image claims {w}x{h} pixels, more than bumpbake decodes (at most {MAX_SIDE} per side and {MAX_PIXELS} pixels)"
        ));
    }
    Ok(())
}

/// Why an image in a format bumpbake does not read is refused, in words.
pub fn unsupported_format(format: image::ImageFormat) -> String {
    let name = format.extensions_str().first().map(|e| e.to_uppercase()).unwrap_or_else(|| "this format's".into());
    format!("{name} images cannot be read (bumpbake reads PNG, TIFF and EXR); convert it to PNG")
}

/// A decoding error in words: the image crate names unsupported formats by their Rust names.
pub fn decode_error_words(e: &image::ImageError) -> String {
    if let image::ImageError::Unsupported(u) = e {
        if let image::error::ImageFormatHint::Exact(f) = u.format_hint() {
            return unsupported_format(f);
        }
    }
    e.to_string().split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Decodes an image after checking its header, under [`limits`].
pub fn decode(bytes: &[u8]) -> Result<DynamicImage, String> {
    dimensions(bytes)?;
    let mut r = reader(bytes)?;
    r.limits(limits());
    r.decode().map_err(|e| format!("cannot decode image: {}", decode_error_words(&e)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_past_the_limits_are_refused_before_decoding() {
        assert!(check_size(200_000, 200_000).unwrap_err().contains("200000x200000"));
        assert!(check_size(MAX_SIDE + 1, 1).is_err());
        assert!(check_size(0, 5).is_err());
        assert!(check_size(MAX_SIDE, MAX_SIDE).is_err(), "too many pixels in all");
        assert!(check_size(8192, 8192).is_ok());
    }

    #[test]
    fn garbage_is_not_an_image() {
        assert!(decode(b"").is_err());
        assert!(decode(b"hello world, not an image").is_err());
        assert!(decode(b"\x89PNG\r\n\x1a\n").is_err());
    }
}
