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
//! RDO passes over a whole level and ETC1S shares codebooks across levels, so both stay with
//! the compressor (`write.rs`).

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
}

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
        let block = *seen.entry(px).or_insert_with(|| {
            let mut b = Block([0; 16]);
            // SAFETY: `px` holds the 16 RGBA pixels the function reads, `b` the 16 bytes it
            // writes, and `encoder_init` has run (see `encode`).
            unsafe { basisu_encode_uastc(px.as_ptr(), &mut b, flags) };
            b
        });
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
