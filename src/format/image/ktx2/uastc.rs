//! Plain UASTC (no RDO), encoded block by block with the Basis Universal encoder's own block
//! function, on every core, each distinct block once.
//!
//! UASTC blocks are coded independently: the encoder's `basis_compressor` runs
//! `basisu::encode_uastc` on each 4x4 block of each level and concatenates the results. The
//! compressor also copies every image twice (into its slice images, then into a block list),
//! builds a `.basis` file with checksums, and waits for every block of a level before it starts
//! the next, each step on one thread. Calling the block function directly gives the same bytes
//! (tested against the compressor below) without those steps, and lets a block that repeats in
//! its row (flat areas: a baked map's background, its UV padding) be encoded once.
//!
//! At pack levels 2-4 the block's ETC1 hints (what a transcoder to ETC1 follows instead of
//! searching) are the encoder's search's answers found by `etc1_hints.rs` in a fraction of its
//! time: the encoder is asked for its cheapest hints and these are written over them, at the bit
//! offsets the block's mode gives.
//!
//! RDO passes over a whole level and ETC1S shares codebooks across levels, so both stay with
//! the compressor (`write.rs`).

use super::etc1_hints;
use super::Level;
use rayon::prelude::*;
use std::collections::HashMap;

/// One UASTC block as the encoder writes it (`basist::uastc_block`, a 16-byte union whose
/// widest member is a `uint64_t`).
#[repr(C, align(8))]
#[derive(Clone, Copy)]
struct Block([u8; 16]);

extern "C" {
    /// `void basisu::encode_uastc(const uint8_t* pRGBAPixels, basist::uastc_block& output_block,
    /// uint32_t flags)` of the Basis Universal 1.16 sources `basis-universal-sys` 0.3 builds: 16
    /// RGBA8 pixels row by row, the block out (a reference is a pointer in the C ABI), the pack
    /// flags. Thread-safe (the compressor calls it from its worker threads) once the encoder is
    /// initialised. A different signature is a different symbol: the link fails, never the call.
    #[link_name = "_ZN6basisu12encode_uastcEPKhRN6basist11uastc_blockEj"]
    fn basisu_encode_uastc(pixels: *const u8, block: *mut Block, flags: u32);

    /// `bool basist::unpack_uastc(const basist::uastc_block& blk, basist::color32* pPixels, bool
    /// srgb)`: a block's 16 RGBA8 pixels, as every transcoder decodes them.
    #[link_name = "_ZN6basist12unpack_uastcERKNS_11uastc_blockEPNS_7color32Eb"]
    fn basist_unpack_uastc(block: *const Block, pixels: *mut [u8; 4], srgb: bool) -> bool;
}

/// Pack flags asking for the encoder's cheapest ETC1 hints (one trial: no flip, differential
/// colours, the first bias), which `etc1_hints` then replaces with the full search's.
const CHEAPEST_ETC1_HINTS: u32 = 128 | 256;

/// The solid-colour mode: its ETC1 hint is a colour, not a search, so the encoder's stays.
const SOLID_MODE: usize = 8;

/// Per UASTC mode: its code (read from bit 0 up) and the code's length.
const MODE_CODES: [(u8, u32); 19] = [
    (0x1, 4),
    (0x35, 6),
    (0x1D, 5),
    (0x3, 5),
    (0x13, 5),
    (0xB, 5),
    (0x1B, 5),
    (0x7, 5),
    (0x17, 5),
    (0xF, 5),
    (0x2, 3),
    (0x0, 2),
    (0x6, 3),
    (0x1F, 5),
    (0xD, 5),
    (0x5, 7),
    (0x15, 6),
    (0x25, 6),
    (0x9, 4),
];

/// Per mode: whether it stores the two BC1 hint bits (which precede the ETC1 hints) and an
/// ETC1 bias.
const HAS_BC1_HINT0: [bool; 19] =
    [true, true, true, true, true, true, true, true, false, true, true, true, true, true, true, true, true, true, true];
const HAS_BC1_HINT1: [bool; 19] = [
    true, true, true, true, true, true, true, true, false, true, false, false, false, true, true, true, true, true,
    true,
];
const HAS_ETC1_BIAS: [bool; 19] = [
    true, true, true, true, true, true, true, true, false, true, false, false, false, true, true, true, true, true,
    true,
];

/// The UASTC blocks of every level (level 0 first), at pack level 0-4.
pub(super) fn encode(levels: &[Level], level: u32) -> Vec<Vec<u8>> {
    basis_universal::encoder_init();
    let flags = level.min(basis_universal::UASTC_QUALITY_MAX);
    // Every block row of every level is one task, so small levels do not wait for large ones.
    let rows: Vec<(usize, u32)> =
        levels.iter().enumerate().flat_map(|(k, l)| (0..l.height.div_ceil(4)).map(move |r| (k, r))).collect();
    let encoded: Vec<Vec<u8>> = rows.par_iter().map(|&(k, r)| row(&levels[k], r, flags)).collect();
    let mut out: Vec<Vec<u8>> = levels.iter().map(|l| Vec::with_capacity(blocks(l) * 16)).collect();
    for ((k, _), r) in rows.iter().zip(encoded) {
        out[*k].extend_from_slice(&r);
    }
    out
}

fn blocks(l: &Level) -> usize {
    l.width.div_ceil(4) as usize * l.height.div_ceil(4) as usize
}

/// One row of blocks. A block that already appeared in the row is copied, not encoded again.
fn row(l: &Level, by: u32, flags: u32) -> Vec<u8> {
    let across = l.width.div_ceil(4);
    let mut out = Vec::with_capacity(across as usize * 16);
    let mut seen: HashMap<[u8; 64], Block> = HashMap::new();
    for bx in 0..across {
        let px = pixels(l, bx, by);
        let block = *seen.entry(px).or_insert_with(|| block(&px, flags));
        out.extend_from_slice(&block.0);
    }
    out
}

/// The RGBA pixels of block (`bx`, `by`), alpha 255; past the right or bottom edge the last
/// column or row repeats, as the compressor pads a level whose sides are not multiples of 4.
fn pixels(l: &Level, bx: u32, by: u32) -> [u8; 64] {
    let mut px = [255u8; 64];
    for y in 0..4 {
        let sy = (by * 4 + y).min(l.height - 1) as usize;
        for x in 0..4 {
            let sx = (bx * 4 + x).min(l.width - 1) as usize;
            let s = (sy * l.width as usize + sx) * 3;
            let d = (y * 4 + x) as usize * 4;
            px[d..d + 3].copy_from_slice(&l.rgb[s..s + 3]);
        }
    }
    px
}

/// The UASTC block of 16 RGBA pixels at pack flags `flags`, as the encoder writes it.
fn block(px: &[u8; 64], flags: u32) -> Block {
    let encode = |flags: u32| {
        let mut b = Block([0; 16]);
        // SAFETY: `px` holds the 16 RGBA pixels the function reads, `b` the 16 bytes it writes,
        // and `encoder_init` has run (see `encode`).
        unsafe { basisu_encode_uastc(px.as_ptr(), &mut b, flags) };
        b
    };
    if !etc1_hints::LEVELS.contains(&flags) {
        return encode(flags);
    }
    let mut b = encode(flags | CHEAPEST_ETC1_HINTS);
    match with_full_etc1_hints(&mut b, px, flags) {
        true => b,
        // A block the transcoder cannot read back is the encoder's to hint.
        false => encode(flags),
    }
}

/// The block's mode, read from its first bits.
fn mode(b: &Block) -> Option<usize> {
    MODE_CODES.iter().position(|&(code, bits)| b.0[0] & ((1u8 << bits) - 1) == code)
}

/// Writes over `b`'s ETC1 hints the ones the encoder's full search at pack level `level` finds;
/// false if `b` is not a block the transcoder reads.
fn with_full_etc1_hints(b: &mut Block, px: &[u8; 64], level: u32) -> bool {
    let Some(m) = mode(b) else { return false };
    if m == SOLID_MODE {
        return true;
    }
    let mut decoded = [[0u8; 4]; 16];
    // SAFETY: `b` is a whole block and `decoded` holds the 16 pixels the function writes.
    if !unsafe { basist_unpack_uastc(b, decoded.as_mut_ptr(), false) } {
        return false;
    }
    let source: [[u8; 4]; 16] = std::array::from_fn(|i| [px[4 * i], px[4 * i + 1], px[4 * i + 2], px[4 * i + 3]]);
    let h = etc1_hints::hints(&source, &decoded, HAS_ETC1_BIAS[m], level);
    let mut at = MODE_CODES[m].1 + u32::from(HAS_BC1_HINT0[m]) + u32::from(HAS_BC1_HINT1[m]);
    let mut put = |value: u32, bits: u32| {
        for i in 0..bits {
            let (byte, bit) = ((at + i) as usize / 8, (at + i) % 8);
            b.0[byte] = (b.0[byte] & !(1 << bit)) | ((((value >> i) & 1) as u8) << bit);
        }
        at += bits;
    };
    put(u32::from(h.flip), 1);
    put(u32::from(h.diff), 1);
    put(u32::from(h.inten[0]), 3);
    put(u32::from(h.inten[1]), 3);
    if HAS_ETC1_BIAS[m] {
        put(u32::from(h.bias), 5);
    }
    true
}

#[cfg(test)]
mod tests {
    use super::super::tests::blocks;
    use super::*;

    /// The encoder's own block, its hints from its full search.
    fn encoders(px: &[u8; 64], level: u32) -> Block {
        let mut b = Block([0; 16]);
        // SAFETY: as in `row`.
        unsafe { basisu_encode_uastc(px.as_ptr(), &mut b, level) };
        b
    }

    fn ours(px: &[u8; 64], level: u32) -> Block {
        block(px, level)
    }

    #[test]
    fn etc1_hints_are_the_encoders_at_every_level() {
        basis_universal::encoder_init();
        let blocks = blocks();
        let mut modes = [0usize; 19];
        for level in 0..=4 {
            for px in &blocks {
                let theirs = encoders(px, level);
                assert_eq!(ours(px, level).0, theirs.0, "pack level {level}, block {px:?}");
                if let Some(m) = mode(&theirs) {
                    modes[m] += 1;
                }
            }
        }
        // The blocks reach the solid mode, modes with a bias and modes without one.
        assert!(modes[SOLID_MODE] > 0, "{modes:?}");
        assert!((0..19).filter(|&m| m != SOLID_MODE && modes[m] > 0).any(|m| HAS_ETC1_BIAS[m]), "{modes:?}");
        assert!((0..19).filter(|&m| m != SOLID_MODE && modes[m] > 0).any(|m| !HAS_ETC1_BIAS[m]), "{modes:?}");
    }

    /// Blocks of maps other tools wrote: Khronos's mirror-test normal map (a PNG and a JPEG of
    /// it) and a colour texture, each a `side` x `side` piece from (`x`, `y`).
    #[test]
    fn etc1_hints_are_the_encoders_on_other_tools_maps() {
        basis_universal::encoder_init();
        let pieces = [
            ("fixtures/ktx2/mirror_normal.png", 192, 160, 128),
            ("fixtures/lossy/mirror_normal.q80.jpg", 900, 700, 96),
            ("fixtures/spot/spot_texture.png", 300, 300, 96),
        ];
        for (file, x0, y0, side) in pieces {
            let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
            let img = image::open(&path).unwrap().to_rgba8();
            let blocks: Vec<[u8; 64]> = (0..side / 4 * (side / 4))
                .map(|i| {
                    let (bx, by) = (x0 + 4 * (i % (side / 4)), y0 + 4 * (i / (side / 4)));
                    let mut px = [0u8; 64];
                    for p in 0..16 {
                        px[4 * p..4 * p + 4].copy_from_slice(&img.get_pixel(bx + p as u32 % 4, by + p as u32 / 4).0);
                    }
                    px
                })
                .collect();
            for level in [2, 3] {
                let differ = blocks.par_iter().filter(|px| ours(px, level).0 != encoders(px, level).0).count();
                assert_eq!(differ, 0, "{file}, pack level {level}: {differ} of {} blocks differ", blocks.len());
            }
            let slowest = &blocks[..blocks.len() / 16];
            assert!(slowest.par_iter().all(|px| ours(px, 4).0 == encoders(px, 4).0), "{file}, pack level 4");
        }
    }

    #[test]
    fn a_mode_code_names_one_mode() {
        for byte in 0..=255u8 {
            let b = Block([byte, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]);
            let matching = MODE_CODES.iter().filter(|&&(code, bits)| byte & ((1u8 << bits) - 1) == code).count();
            assert!(matching <= 1, "{byte:#x}");
            assert_eq!(mode(&b).is_some(), matching == 1);
        }
    }
}
