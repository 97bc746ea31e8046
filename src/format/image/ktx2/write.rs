//! KTX2 files written: Basis Universal UASTC under Zstandard, or ETC1S under BasisLZ, with the
//! mip levels the caller made (KHR_texture_basisu's payloads).
//!
//! The `basis-universal` crate wraps the encoder's `.basis` output only, not its KTX2 writer, and
//! is built without Zstandard. The codec data is the same in both containers (see `basis.rs`), so
//! the `.basis` file is taken apart here: its slices become the KTX2 levels (UASTC compressed with
//! libzstd at basisu's level, see docs/dependencies.md), and for ETC1S its codebooks and tables
//! become the supercompression global data.
//!
//! Plain UASTC is encoded block by block (`uastc.rs`). For RDO and ETC1S the levels are handed to
//! the encoder's compressor as user mipmaps (`m_source_mipmap_images`), with its own mipmap
//! generation off: what is stored is what the caller built.

use basis_universal::{BasisTextureFormat, ColorSpace, Compressor, CompressorParams};
use rayon::prelude::*;

/// The Basis Universal codec and its quality.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Codec {
    /// UASTC at pack level 0 (fastest) to 4 (slowest, best); `rdo`: the rate-distortion
    /// lambda (basisu's `-uastc_rdo_l`, 1 its default; larger is smaller and worse), none for
    /// plain UASTC.
    Uastc { level: u32, rdo: Option<f32> },
    /// ETC1S at quality 1 to 255.
    Etc1s { quality: u32 },
}

impl Codec {
    /// Refuses a level or quality the encoder does not have, which it would clamp without a
    /// word; an RDO lambda must be a positive number.
    pub fn check(&self) -> crate::Result<()> {
        use crate::error::{Error, Setting, Words};
        let (q, range, what) = match *self {
            Codec::Uastc { level, .. } => (level, 0..=basis_universal::UASTC_QUALITY_MAX, "UASTC levels are"),
            Codec::Etc1s { quality } => {
                (quality, basis_universal::ETC1S_QUALITY_MIN..=basis_universal::ETC1S_QUALITY_MAX, "ETC1S quality is")
            }
        };
        if !range.contains(&q) {
            let (lo, hi) = (range.start(), range.end());
            let msg = Words::new().given(Setting::Ktx2Quality, q).text(format!(": {what} {lo} to {hi}"));
            return Err(Error::setting(Setting::Ktx2Quality, Some(q.to_string()), msg));
        }
        match *self {
            Codec::Uastc { rdo: Some(l), .. } if !(l.is_finite() && l > 0.0) => {
                Err(Error::usage(format!("UASTC's rate-distortion lambda {l} is not a positive number")))
            }
            _ => Ok(()),
        }
    }
}

/// The largest side the Basis Universal encoder takes (`BASISU_MAX_SUPPORTED_TEXTURE_DIMENSION`).
pub const MAX_SIDE: u32 = 16384;

use super::basis::{u16_at, u24_at, u32_at, HEADER, SLICE};
use super::{Level, BASIS_LZ, ZSTD};
/// basisu's own Zstandard level for UASTC (`-ktx2_zstandard_level`, default 6).
const ZSTD_LEVEL: i32 = 6;
/// The encoder splits its RDO pass into `min(4, threads)` runs, each with its own dictionary, so
/// its bytes depend on the thread count below 4: RDO encodes always get a pool of at least 4.
const RDO_THREADS: u32 = 4;
const WRITER: &str = concat!("bumpbake ", env!("CARGO_PKG_VERSION"));

/// The encoder's `.basis` file of `levels` (level 0 first).
fn basis_file(levels: &[Level], codec: Codec, threads: u32) -> crate::error::Faulty<Vec<u8>> {
    let mut p = CompressorParams::new();
    match codec {
        Codec::Uastc { level, rdo } => {
            p.set_basis_format(BasisTextureFormat::UASTC4x4);
            // The crate's `set_uastc_quality_level` ORs the level into flags that already hold
            // the default level (2), so 0 and 1 would not take and 4 would become 6: the level
            // bits (`cPackUASTCLevelMask`) are replaced instead.
            let level = level.min(basis_universal::UASTC_QUALITY_MAX) as i32;
            // SAFETY: `p.0` is the live parameter block `CompressorParams::new` made.
            unsafe {
                let flags = basis_universal::sys::compressor_params_get_pack_uastc_flags(p.0);
                basis_universal::sys::compressor_params_set_pack_uastc_flags(p.0, (flags & !0xF) | level);
            }
            p.set_rdo_uastc(rdo);
        }
        Codec::Etc1s { quality } => {
            p.set_basis_format(BasisTextureFormat::ETC1S);
            p.set_etc1s_quality_level(
                quality.clamp(basis_universal::ETC1S_QUALITY_MIN, basis_universal::ETC1S_QUALITY_MAX),
            );
        }
    }
    // Normal maps are data: no perceptual weighting, no sRGB, and no rate-distortion trade that
    // moves directions to save bits.
    p.tune_for_normal_maps();
    p.set_color_space(ColorSpace::Linear);
    p.set_mip_color_space(ColorSpace::Linear);
    p.set_generate_mipmaps(false);
    let (base, rest) = levels.split_first().ok_or("no level to encode")?;
    p.source_image_mut(0).init(base.rgb, base.width, base.height, 3);
    for (k, l) in rest.iter().enumerate() {
        p.source_mipmap_image_mut(0, k as u32).init(l.rgb, l.width, l.height, 3);
    }
    let threads = if matches!(codec, Codec::Uastc { rdo: Some(_), .. }) { threads.max(RDO_THREADS) } else { threads };
    let mut c = Compressor::new(threads.max(1));
    // SAFETY: `p` outlives `c`'s use of it (both live to the end of this function), as `init` needs.
    unsafe {
        if !c.init(&p) {
            return Err("the Basis Universal encoder refused its parameters".into());
        }
        c.process().map_err(|e| format!("the Basis Universal encoder failed ({e:?})"))?;
    }
    Ok(c.basis_file().to_vec())
}

/// The slices of a `.basis` file, by level: (offset, length), checked against the file.
fn slices(file: &[u8], levels: usize) -> crate::error::Faulty<Vec<(usize, usize)>> {
    let bad = || "the Basis Universal encoder wrote a file bumpbake does not understand".to_string();
    if file.len() < HEADER || u24_at(file, 14) != levels {
        return Err(bad().into());
    }
    let descs = u32_at(file, 65);
    let mut out = vec![(0, 0); levels];
    for i in 0..levels {
        let d = descs + i * SLICE;
        let desc = file.get(d..d + SLICE).ok_or_else(bad)?;
        let (level, ofs, len) = (desc[3] as usize, u32_at(desc, 13), u32_at(desc, 17));
        if level >= levels || ofs.checked_add(len).is_none_or(|e| e > file.len()) {
            return Err(bad().into());
        }
        out[level] = (ofs, len);
    }
    Ok(out)
}

/// A data format descriptor for a 4x4-block Basis payload, RGB, linear.
fn dfd(uastc: bool) -> Vec<u8> {
    let mut d = Vec::with_capacity(44);
    d.extend_from_slice(&44u32.to_le_bytes());
    d.extend_from_slice(&0u32.to_le_bytes()); // vendor Khronos, basic block
    d.extend_from_slice(&2u16.to_le_bytes()); // version 1.3
    d.extend_from_slice(&40u16.to_le_bytes()); // block size: 24 + one sample
    let (model, plane0, bits) = if uastc { (166u8, 16u8, 127u8) } else { (163, 0, 63) };
    // Primaries BT.709, transfer linear (normals are data), straight alpha.
    d.extend_from_slice(&[model, 1, 1, 0, 3, 3, 0, 0, plane0, 0, 0, 0, 0, 0, 0, 0]);
    d.extend_from_slice(&0u16.to_le_bytes());
    d.extend_from_slice(&[bits, 0, 0, 0, 0, 0]); // channel RGB
    d.extend_from_slice(&0u32.to_le_bytes());
    d.extend_from_slice(&u32::MAX.to_le_bytes());
    d
}

fn kvd() -> Vec<u8> {
    let entry = format!("KTXwriter\0{WRITER}\0");
    let mut d = Vec::new();
    d.extend_from_slice(&(entry.len() as u32).to_le_bytes());
    d.extend_from_slice(entry.as_bytes());
    d.resize(d.len().div_ceil(4) * 4, 0);
    d
}

/// A KTX2 file of `levels` (level 0 first, each half the one before as KTX2 sizes them).
/// `threads`: the compressor's (RDO and ETC1S; plain UASTC runs on rayon's pool); the bytes do
/// not depend on it.
pub fn encode(levels: &[Level], codec: Codec, threads: u32) -> crate::error::Faulty<Vec<u8>> {
    if let Some(l) = levels.first().filter(|l| l.width > MAX_SIDE || l.height > MAX_SIDE) {
        return Err(format!(
            "a {}x{} map is larger than Basis Universal encodes ({MAX_SIDE} texels a side)",
            l.width, l.height
        )
        .into());
    }
    for l in levels {
        if l.width == 0 || l.height == 0 || l.rgb.len() != l.width as usize * l.height as usize * 3 {
            return Err(format!("a {}x{} level with {} bytes of RGB", l.width, l.height, l.rgb.len()).into());
        }
    }
    let n = levels.len();
    let uastc = matches!(codec, Codec::Uastc { .. });
    // Per level: the stored bytes and, for UASTC, the blocks' length before Zstandard.
    let (data, raw, sgd): (Vec<Vec<u8>>, Vec<usize>, Vec<u8>) = match codec {
        Codec::Uastc { level, rdo } => {
            let blocks = match rdo {
                None => super::uastc::encode(levels, level),
                Some(_) => {
                    let basis = basis_file(levels, codec, threads)?;
                    slices(&basis, n)?.iter().map(|&(o, l)| basis[o..o + l].to_vec()).collect()
                }
            };
            let data = blocks
                .par_iter()
                .map(|b| zstd::bulk::compress(b, ZSTD_LEVEL))
                .collect::<std::io::Result<Vec<_>>>()
                .map_err(|e| format!("Zstandard failed: {e}"))?;
            (data, blocks.iter().map(Vec::len).collect(), Vec::new())
        }
        Codec::Etc1s { .. } => {
            let basis = basis_file(levels, codec, threads)?;
            let parts = slices(&basis, n)?;
            let (ep_ofs, ep_len) = (u32_at(&basis, 41), u24_at(&basis, 45));
            let (sel_ofs, sel_len) = (u32_at(&basis, 50), u24_at(&basis, 54));
            let (tab_ofs, tab_len) = (u32_at(&basis, 57), u32_at(&basis, 61));
            let within = |o: usize, l: usize| basis.get(o..o + l).ok_or("the encoder's codebooks lie outside its file");
            let mut g = Vec::new();
            g.extend_from_slice(&u16_at(&basis, 39).to_le_bytes());
            g.extend_from_slice(&u16_at(&basis, 48).to_le_bytes());
            for v in [ep_len, sel_len, tab_len, 0] {
                g.extend_from_slice(&(v as u32).to_le_bytes());
            }
            for &(_, l) in &parts {
                // Flags 0 (an I-frame), RGB slice the whole level, no alpha slice.
                for v in [0u32, 0, l as u32, 0, 0] {
                    g.extend_from_slice(&v.to_le_bytes());
                }
            }
            g.extend_from_slice(within(ep_ofs, ep_len)?);
            g.extend_from_slice(within(sel_ofs, sel_len)?);
            g.extend_from_slice(within(tab_ofs, tab_len)?);
            // BasisLZ levels declare no uncompressed length.
            (parts.iter().map(|&(o, l)| basis[o..o + l].to_vec()).collect(), vec![0; n], g)
        }
    };
    let dfd = dfd(uastc);
    let kvd = kvd();
    let dfd_ofs = 80 + 24 * n;
    let kvd_ofs = dfd_ofs + dfd.len();
    let sgd_ofs = if sgd.is_empty() { 0 } else { (kvd_ofs + kvd.len()).div_ceil(8) * 8 };
    let mut at = if sgd.is_empty() { kvd_ofs + kvd.len() } else { sgd_ofs + sgd.len() };
    // Supercompressed levels need no alignment; the smallest is stored first.
    let mut offsets = vec![0usize; n];
    for k in (0..n).rev() {
        offsets[k] = at;
        at += data[k].len();
    }
    if at > u32::MAX as usize * 4 {
        return Err("the KTX2 file would exceed 16 GB".into());
    }
    let mut f = Vec::with_capacity(at);
    f.extend_from_slice(&[0xAB, b'K', b'T', b'X', b' ', b'2', b'0', 0xBB, 0x0D, 0x0A, 0x1A, 0x0A]);
    let scheme = if uastc { ZSTD } else { BASIS_LZ };
    let (w, h) = (levels[0].width, levels[0].height);
    for v in [0u32, 1, w, h, 0, 0, 1, n as u32, scheme, dfd_ofs as u32, dfd.len() as u32, kvd_ofs as u32] {
        f.extend_from_slice(&v.to_le_bytes());
    }
    f.extend_from_slice(&(kvd.len() as u32).to_le_bytes());
    f.extend_from_slice(&(sgd_ofs as u64).to_le_bytes());
    f.extend_from_slice(&(sgd.len() as u64).to_le_bytes());
    for k in 0..n {
        for v in [offsets[k], data[k].len(), raw[k]] {
            f.extend_from_slice(&(v as u64).to_le_bytes());
        }
    }
    f.extend_from_slice(&dfd);
    f.extend_from_slice(&kvd);
    if !sgd.is_empty() {
        f.resize(sgd_ofs, 0);
        f.extend_from_slice(&sgd);
    }
    for d in data.iter().rev() {
        f.extend_from_slice(d);
    }
    debug_assert_eq!(f.len(), at);
    Ok(f)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The block-by-block encoder (`uastc.rs`) gives the compressor's bytes, on levels whose
    /// sides are not multiples of 4 and on rows with repeated (flat) blocks.
    #[test]
    fn plain_uastc_blocks_are_the_compressors() {
        let texels = |w: u32, h: u32| -> Vec<u8> {
            (0..w * h)
                .flat_map(|i| {
                    let (x, y) = (i % w, i / w);
                    // The left half flat, the right half a pattern that changes in every texel.
                    if x < w / 2 {
                        [128, 128, 255]
                    } else {
                        [(x * 29 + y * 7) as u8, (x * y * 3 + 50) as u8, (200 + (x ^ y) % 55) as u8]
                    }
                })
                .collect()
        };
        let sizes: Vec<(u32, u32)> = vec![(37, 23), (18, 11), (9, 5), (4, 2), (2, 1), (1, 1)];
        let maps: Vec<Vec<u8>> = sizes.iter().map(|&(w, h)| texels(w, h)).collect();
        let levels: Vec<Level> =
            sizes.iter().zip(&maps).map(|(&(width, height), rgb)| Level { width, height, rgb }).collect();
        for level in 0..=2 {
            let basis = basis_file(&levels, Codec::Uastc { level, rdo: None }, 2).unwrap();
            let theirs: Vec<&[u8]> =
                slices(&basis, levels.len()).unwrap().iter().map(|&(o, l)| &basis[o..o + l]).collect();
            let ours = super::super::uastc::encode(&levels, level);
            assert!(ours.iter().map(Vec::as_slice).eq(theirs), "pack level {level}");
        }
    }

    /// RDO splits its pass by thread count below 4; the bytes must not follow the machine.
    #[test]
    fn rdo_bytes_do_not_depend_on_the_thread_count() {
        let (w, h) = (64u32, 32u32);
        // Smooth ramps with a little texture: content RDO can trade bits on.
        let rgb: Vec<u8> = (0..w * h)
            .flat_map(|i| {
                let (x, y) = (i % w, i / w);
                [(x * 3 + (x * y) % 5) as u8, (y * 6 + (x + y) % 3) as u8, 220]
            })
            .collect();
        let levels = [Level { width: w, height: h, rgb: &rgb }];
        let codec = Codec::Uastc { level: 1, rdo: Some(1.0) };
        let one = encode(&levels, codec, 1).unwrap();
        for threads in [2, 3, 8] {
            assert!(encode(&levels, codec, threads).unwrap() == one, "{threads} threads");
        }
        let plain = encode(&levels, Codec::Uastc { level: 1, rdo: None }, 1).unwrap();
        assert!(plain != one, "RDO changed nothing");
    }
}
