//! `bumpbake normalmap … -o NORMAL.ktx2`: the 8-bit map, its mip chain built from the
//! full-resolution normals (`mips.rs`), Basis Universal encoded, and every level read back to
//! measure what the codec did to it.

use super::mips::{self, MipLevel};
use crate::format::image::ktx2::{self, Codec, Level};
use crate::format::image::Limits;
use crate::timings::Timings;
use rayon::prelude::*;
use serde::Serialize;

/// UASTC pack level when none is given: the encoder's own default, its best speed/quality trade.
pub const DEFAULT_UASTC_LEVEL: u32 = 2;
/// ETC1S quality when none is given: the encoder's default.
pub const DEFAULT_ETC1S_QUALITY: u32 = 128;

/// How one stored level compares with the ideal averaged normals it was made from.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LevelError {
    pub level: usize,
    pub width: usize,
    pub height: usize,
    /// Angle between the texels as a GPU decodes them (after the codec) and the renormalised
    /// average of the level-0 normals under them: mean and 99th percentile, degrees.
    pub mean_deg: f64,
    pub p99_deg: f64,
    /// The mean length of the averages before renormalising (1: every footprint flat); specular
    /// antialiasing reads variance `(1 - L) / L` from it.
    pub mean_length: f64,
}

/// The KTX2 bytes of an RGB8 normal map (`w` x `h`) and the per-level error. Timed stages:
/// `mips`, `encode` (Basis Universal + Zstandard), `check` (transcoding every level back).
pub fn ktx2_bytes(
    rgb: &[u8],
    w: usize,
    h: usize,
    codec: Codec,
    t: &mut Timings,
) -> crate::error::Faulty<(Vec<u8>, Vec<LevelError>)> {
    let levels: Vec<MipLevel> = t.time("mips", || mips::build_rgb(rgb, w, h));
    let input: Vec<Level> =
        levels.iter().map(|l| Level { width: l.width as u32, height: l.height as u32, rgb: &l.rgb }).collect();
    let threads = rayon::current_num_threads() as u32;
    let bytes = t.time("encode", || ktx2::encode(&input, codec, threads))?;
    let report = t.time("check", || measure(&bytes, &levels))?;
    Ok((bytes, report))
}

/// Every level of `bytes` transcoded and compared with `levels`' ideal normals.
pub fn measure(bytes: &[u8], levels: &[MipLevel]) -> crate::error::Faulty<Vec<LevelError>> {
    let stored = ktx2::decode_levels_within(bytes, &Limits::file(u64::MAX))?;
    if stored.len() != levels.len() {
        return Err(
            format!("the KTX2 written holds {} levels where {} were encoded", stored.len(), levels.len()).into()
        );
    }
    Ok(stored
        .par_iter()
        .zip(levels)
        .enumerate()
        .map(|(k, (img, l))| {
            let rgb = img.to_rgb8();
            let (mean_deg, p99_deg) = mips::angular_error(rgb.as_raw(), &l.ideal);
            let mean_length = l.mean_length.iter().map(|&v| v as f64).sum::<f64>() / l.mean_length.len().max(1) as f64;
            LevelError { level: k, width: l.width, height: l.height, mean_deg, p99_deg, mean_length }
        })
        .collect())
}
