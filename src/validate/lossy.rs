//! Fair judgement of normal maps that went through a lossy codec.
//!
//! JPEG, lossy WebP and the Basis Universal codecs (ETC1S, UASTC) move every texel a little.
//! A correct map stays correct on the whole, but a few texels at sharp edges land more than 10%
//! off unit length, where a lossless map never does. The rule (derived in `docs/validate.md`):
//!
//! - model the decoded texel as `c + q + e`, with `q` the 8-bit rounding of the original
//!   (variance 1/12 level^2) and `e` the codec's error, of RMS at most [`CODEC_RMS_LEVELS`] per
//!   channel (PSNR 36 dB: JPEG at quality 80 and above, lossy WebP, ETC1S and UASTC reach it on
//!   normal maps, measured in `docs/validate.md`);
//! - the length of a unit normal then moves by `d ~ n . delta`, `delta = 2 (q + e) / 255`, so
//!   `E[d^2] <= sigma^2 = (2/255)^2 (eps^2 + 1/12)` whatever the error's distribution;
//! - Chebyshev: at most `sigma^2 / 0.1^2` of the texels can be more than 0.1 off ([`allowance`]),
//!   and the median `|d|` is at most `sqrt(2) sigma` ([`median_bound`]).
//!
//! A map within both bounds gets one info finding (`NORMALMAP_CODEC_NOISE`) for its scattered
//! texels; a map outside either has an error the codec cannot explain (a colour-managed export,
//! a height or packed map) and is reported as a lossless one would be.

/// How an image's texels were coded, as its bytes tell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Codec {
    /// PNG, lossless WebP, TIFF, OpenEXR, plain KTX2: the texels are what was written.
    Lossless,
    Jpeg,
    /// WebP with a `VP8 ` (lossy) bitstream.
    WebP,
    /// KTX2 holding Basis Universal ETC1S (BasisLZ).
    Etc1s,
    /// KTX2 holding Basis Universal UASTC.
    Uastc,
    /// KTX2 holding a block-compressed format (BC, ETC2, EAC, ASTC).
    Block,
}

/// The RMS error per channel, in 8-bit levels, that the accepted lossy codings stay within.
pub const CODEC_RMS_LEVELS: f64 = 4.0;
/// Texels further than this from unit length are "not unit" (the lossless rule).
pub const UNIT_TOLERANCE: f64 = 0.1;

impl Codec {
    /// Tells the coding from the image's bytes (never from a name or mimeType).
    pub fn sniff(b: &[u8]) -> Codec {
        let at = |o: usize, m: &[u8]| b.get(o..o + m.len()) == Some(m);
        let u32_at = |o: usize| b.get(o..o + 4).map(|s| u32::from_le_bytes([s[0], s[1], s[2], s[3]]));
        if at(0, &[0xFF, 0xD8, 0xFF]) {
            return Codec::Jpeg;
        }
        if at(0, b"RIFF") && at(8, b"WEBP") {
            // Chunks after the header: the first image bitstream says which coding it is.
            let mut o = 12usize;
            while let (Some(fourcc), Some(len)) = (b.get(o..o + 4), u32_at(o + 4)) {
                match fourcc {
                    b"VP8 " => return Codec::WebP,
                    b"VP8L" => return Codec::Lossless,
                    _ => {}
                }
                let Some(next) = o.checked_add(8 + len as usize + (len as usize & 1)) else { break };
                o = next;
            }
            return Codec::Lossless;
        }
        if at(0, &[0xAB, b'K', b'T', b'X', b' ', b'2', b'0', 0xBB, 0x0D, 0x0A, 0x1A, 0x0A]) {
            const BASIS_LZ: u32 = 1;
            const MODEL_ETC1S: u8 = 163;
            const MODEL_UASTC: u8 = 166;
            let vk_format = u32_at(12).unwrap_or(0);
            if u32_at(44) == Some(BASIS_LZ) {
                return Codec::Etc1s;
            }
            // The data format descriptor's colour model, 12 bytes into the descriptor.
            let model = u32_at(48).and_then(|dfd| b.get(dfd as usize + 12).copied());
            return match (vk_format, model) {
                (0, Some(MODEL_ETC1S)) => Codec::Etc1s,
                (0, Some(MODEL_UASTC)) => Codec::Uastc,
                // VK_FORMAT_BC1_RGB_UNORM_BLOCK .. VK_FORMAT_ASTC_12x12_SRGB_BLOCK.
                (131..=184, _) => Codec::Block,
                _ => Codec::Lossless,
            };
        }
        Codec::Lossless
    }

    pub fn is_lossy(self) -> bool {
        self != Codec::Lossless
    }

    /// The coding's name, for messages.
    pub fn name(self) -> &'static str {
        match self {
            Codec::Lossless => "lossless",
            Codec::Jpeg => "JPEG",
            Codec::WebP => "lossy WebP",
            Codec::Etc1s => "ETC1S",
            Codec::Uastc => "UASTC",
            Codec::Block => "block-compressed",
        }
    }
}

/// The RMS length error `sigma` of a unit normal stored in 8 bits after the coding.
pub fn sigma(codec: Codec) -> f64 {
    let eps = if codec.is_lossy() { CODEC_RMS_LEVELS } else { 0.0 };
    2.0 / 255.0 * (eps * eps + 1.0 / 12.0).sqrt()
}

/// The share of texels the coding may leave more than [`UNIT_TOLERANCE`] off unit length.
/// Lossless: none (8-bit rounding moves a unit vector by at most `sqrt(3)/255` = 0.0068).
pub fn allowance(codec: Codec) -> f64 {
    if codec.is_lossy() {
        (sigma(codec) / UNIT_TOLERANCE).powi(2)
    } else {
        0.0
    }
}

/// The largest median `|length - 1|` the coding explains.
pub fn median_bound(codec: Codec) -> f64 {
    std::f64::consts::SQRT_2 * sigma(codec)
}

/// The median of `|length - 1|` over the texels (0 for none); reorders `devs`.
pub fn median_abs(devs: &mut [f32]) -> f64 {
    if devs.is_empty() {
        return 0.0;
    }
    let mid = devs.len() / 2;
    let (_, m, _) = devs.select_nth_unstable_by(mid, |a, b| a.abs().total_cmp(&b.abs()));
    m.abs() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bounds_follow_from_four_levels() {
        // (2/255)^2 (16 + 1/12) / 0.01 = 9.9%; sqrt(2) sigma = 0.045.
        assert!((allowance(Codec::Jpeg) - 0.0989).abs() < 5e-4, "{}", allowance(Codec::Jpeg));
        assert!((median_bound(Codec::WebP) - 0.0448).abs() < 5e-4, "{}", median_bound(Codec::WebP));
        assert_eq!(allowance(Codec::Lossless), 0.0);
    }

    #[test]
    fn codings_are_told_by_their_bytes() {
        assert_eq!(Codec::sniff(&[0xFF, 0xD8, 0xFF, 0xE0]), Codec::Jpeg);
        let webp = |chunk: &[u8]| [b"RIFF\0\0\0\0WEBP".as_slice(), chunk, &[4, 0, 0, 0, 0, 0, 0, 0]].concat();
        assert_eq!(Codec::sniff(&webp(b"VP8 ")), Codec::WebP);
        assert_eq!(Codec::sniff(&webp(b"VP8L")), Codec::Lossless);
        assert_eq!(Codec::sniff(b"\x89PNG\r\n\x1a\n"), Codec::Lossless);
        let mut ktx = vec![0xAB, b'K', b'T', b'X', b' ', b'2', b'0', 0xBB, 0x0D, 0x0A, 0x1A, 0x0A];
        ktx.resize(80, 0);
        ktx[44] = 1;
        assert_eq!(Codec::sniff(&ktx), Codec::Etc1s);
        ktx[44] = 2;
        ktx[48] = 64;
        ktx[76] = 166;
        assert_eq!(Codec::sniff(&ktx), Codec::Uastc);
        ktx[76] = 0;
        ktx[12] = 37; // VK_FORMAT_R8G8B8A8_UNORM
        assert_eq!(Codec::sniff(&ktx), Codec::Lossless);
    }
}
