//! Basis Universal payloads of a KTX2 file, transcoded to RGBA8 by Binomial's transcoder (the
//! `basis-universal` crate).
//!
//! The crate wraps the transcoder of `.basis` files, not its KTX2 one. The two containers hold the
//! same codec data: a `.basis` file is a header, one descriptor per slice, the ETC1S codebooks and
//! Huffman tables, and the slices' bytes; KTX2 keeps the codebooks and tables in its
//! supercompression global data and the slices in its mip levels. So the base level is rewrapped
//! as a one-image `.basis` file in memory (layout in `basisu_file_headers.h`) and handed to the
//! `.basis` transcoder. Every offset and length copied from the KTX2 file is checked against the
//! bytes first, and the `.basis` header is built from checked values only; the checksums the
//! transcoder does not verify on this path are left zero.

use basis_universal::{TranscodeParameters, Transcoder, TranscoderTextureFormat};

/// `sizeof(basis_file_header)` and `sizeof(basis_slice_desc)`: packed little-endian fields.
pub(super) const HEADER: usize = 77;
pub(super) const SLICE: usize = 23;
/// The `.basis` version the vendored transcoder reads (`BASISD_SUPPORTED_BASIS_VERSION`).
const VERSION: u16 = 0x13;

const FLAG_ETC1S: u16 = 1;
const FLAG_HAS_ALPHA_SLICES: u16 = 4;
const SLICE_HAS_ALPHA: u8 = 1;
const SLICE_IFRAME: u8 = 2;

fn broken(what: &str) -> String {
    format!("cannot decode as KTX2: its Basis Universal data is malformed ({what})")
}

/// One slice to put in the `.basis` file.
struct Slice<'a> {
    alpha: bool,
    data: &'a [u8],
}

/// Little-endian writer of `basisu::packed_uint<N>` fields.
struct Out(Vec<u8>);

impl Out {
    fn put(&mut self, v: u64, n: usize) -> crate::error::Faulty<()> {
        if n < 8 && v >> (8 * n) != 0 {
            return Err(broken("a length too large for a .basis field").into());
        }
        self.0.extend_from_slice(&v.to_le_bytes()[..n]);
        Ok(())
    }
}

/// Codebooks and tables of an ETC1S file (empty for UASTC).
#[derive(Default)]
struct Codebooks<'a> {
    endpoints: u16,
    selectors: u16,
    endpoint_data: &'a [u8],
    selector_data: &'a [u8],
    tables: &'a [u8],
}

/// A one-image, one-level `.basis` file.
fn basis_file(etc1s: bool, w: u32, h: u32, cb: &Codebooks, slices: &[Slice]) -> crate::error::Faulty<Vec<u8>> {
    if w > u16::MAX as u32 || h > u16::MAX as u32 {
        return Err(format!(
            "a KTX2 Basis Universal image of {w}x{h} pixels, wider or taller than the transcoder reads (65535)"
        )
        .into());
    }
    let descs = HEADER + SLICE * slices.len();
    let endpoint_ofs = descs;
    let selector_ofs = endpoint_ofs + cb.endpoint_data.len();
    let tables_ofs = selector_ofs + cb.selector_data.len();
    let mut slice_ofs = tables_ofs + cb.tables.len();
    let total = slice_ofs + slices.iter().map(|s| s.data.len()).sum::<usize>();
    if total > u32::MAX as usize {
        return Err(broken("more than 4 GB of data").into());
    }
    let mut o = Out(Vec::with_capacity(total));
    let (flags, format) = match (etc1s, slices.len() == 2) {
        (true, true) => (FLAG_ETC1S | FLAG_HAS_ALPHA_SLICES, 0),
        (true, false) => (FLAG_ETC1S, 0),
        (false, _) => (0, 1),
    };
    o.put(u64::from(u16::from_le_bytes([b's', b'B'])), 2)?; // m_sig: ('B' << 8) | 's'
    o.put(VERSION.into(), 2)?;
    o.put(HEADER as u64, 2)?;
    o.put(0, 2)?; // header CRC16, not checked when transcoding
    o.put((total - HEADER) as u64, 4)?;
    o.put(0, 2)?; // data CRC16, likewise
    o.put(slices.len() as u64, 3)?;
    o.put(1, 3)?; // images
    o.put(format, 1)?;
    o.put(flags.into(), 2)?;
    o.put(0, 1)?; // 2D
    o.put(0, 3)?; // µs per frame
    o.put(0, 4)?; // reserved
    o.put(0, 4)?; // userdata0
    o.put(0, 4)?; // userdata1
    o.put(cb.endpoints.into(), 2)?;
    o.put(endpoint_ofs as u64, 4)?;
    o.put(cb.endpoint_data.len() as u64, 3)?;
    o.put(cb.selectors.into(), 2)?;
    o.put(selector_ofs as u64, 4)?;
    o.put(cb.selector_data.len() as u64, 3)?;
    o.put(tables_ofs as u64, 4)?;
    o.put(cb.tables.len() as u64, 4)?;
    o.put(HEADER as u64, 4)?; // slice descriptors follow the header
    o.put(0, 4)?; // extended data
    o.put(0, 4)?;
    debug_assert_eq!(o.0.len(), HEADER);
    for s in slices {
        o.put(0, 3)?; // image
        o.put(0, 1)?; // level
        o.put(u64::from(SLICE_IFRAME | if s.alpha { SLICE_HAS_ALPHA } else { 0 }), 1)?;
        o.put(w.into(), 2)?;
        o.put(h.into(), 2)?;
        o.put(w.div_ceil(4).into(), 2)?;
        o.put(h.div_ceil(4).into(), 2)?;
        o.put(slice_ofs as u64, 4)?;
        o.put(s.data.len() as u64, 4)?;
        o.put(0, 2)?; // slice CRC16, not checked
        slice_ofs += s.data.len();
    }
    for part in [cb.endpoint_data, cb.selector_data, cb.tables] {
        o.0.extend_from_slice(part);
    }
    for s in slices {
        o.0.extend_from_slice(s.data);
    }
    Ok(o.0)
}

fn transcode(file: &[u8], w: u32, h: u32) -> crate::error::Faulty<Vec<u8>> {
    let mut t = Transcoder::new();
    if !t.validate_header(file) {
        return Err(broken("its header does not describe its data").into());
    }
    t.prepare_transcoding(file).map_err(|_| broken("its codebooks or tables do not decode"))?;
    let params = TranscodeParameters {
        image_index: 0,
        level_index: 0,
        decode_flags: None,
        output_row_pitch_in_blocks_or_pixels: None,
        output_rows_in_pixels: None,
    };
    let out = t
        .transcode_image_level(file, TranscoderTextureFormat::RGBA32, params)
        .map_err(|_| broken("its blocks do not decode"))?;
    t.end_transcoding();
    let want = w as usize * h as usize * 4;
    if out.len() < want {
        return Err(broken("the transcoder returned fewer pixels than the image has").into());
    }
    Ok(out[..want].to_vec())
}

/// UASTC blocks (already out of any Zstandard) to RGBA8. `alpha`: the file's alpha channel
/// carries data (RGBA, or a two-channel map's y).
///
/// UASTC blocks are independent, so a large level is cut into bands of block rows and the bands
/// transcoded on every core; the pixels are the same as one call's.
pub(super) fn uastc(blocks: &[u8], w: u32, h: u32, alpha: bool) -> crate::error::Faulty<Vec<u8>> {
    use rayon::prelude::*;
    const BLOCK: usize = 16;
    const BAND_BLOCKS: usize = 8192;
    let row = w.div_ceil(4) as usize * BLOCK;
    let rows = h.div_ceil(4) as usize;
    let band_rows = (BAND_BLOCKS * BLOCK / row.max(1)).max(1);
    if rows <= band_rows || blocks.len() != row * rows {
        let file = basis_file(false, w, h, &Codebooks::default(), &[Slice { alpha, data: blocks }])?;
        return transcode(&file, w, h);
    }
    let bands = blocks
        .par_chunks(band_rows * row)
        .enumerate()
        .map(|(i, data)| {
            let bh = (h - (i * band_rows * 4) as u32).min((band_rows * 4) as u32);
            let file = basis_file(false, w, bh, &Codebooks::default(), &[Slice { alpha, data }])?;
            transcode(&file, w, bh)
        })
        .collect::<crate::error::Faulty<Vec<_>>>()?;
    Ok(bands.concat())
}

pub(super) fn u16_at(b: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([b[at], b[at + 1]])
}
pub(super) fn u24_at(b: &[u8], at: usize) -> usize {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], 0]) as usize
}
pub(super) fn u32_at(b: &[u8], at: usize) -> usize {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]) as usize
}

/// ETC1S/BasisLZ: the codebooks and tables from the supercompression global data, level
/// `index`'s RGB (and alpha) slice from its level data, to RGBA8.
pub(super) fn etc1s(
    reader: &::ktx2::Reader<&[u8]>,
    index: usize,
    level: &[u8],
    w: u32,
    h: u32,
) -> crate::error::Faulty<Vec<u8>> {
    let sgd = reader.supercompression_global_data();
    // endpointCount u16, selectorCount u16, then endpoints/selectors/tables/extended byte lengths.
    const FIXED: usize = 20;
    const IMAGE_DESC: usize = 20;
    if sgd.len() < FIXED {
        return Err(broken("its global data is shorter than its header").into());
    }
    let images = reader.header().level_count.max(1) as usize;
    let lengths = [u32_at(sgd, 4), u32_at(sgd, 8), u32_at(sgd, 12), u32_at(sgd, 16)];
    let want = lengths.iter().try_fold(FIXED + images * IMAGE_DESC, |a, &l| a.checked_add(l));
    if want != Some(sgd.len()) {
        return Err(broken("its global data's lengths do not add up to its size").into());
    }
    let data_start = FIXED + images * IMAGE_DESC;
    let (e, s, t) = (lengths[0], lengths[1], lengths[2]);
    let cb = Codebooks {
        endpoints: u16_at(sgd, 0),
        selectors: u16_at(sgd, 2),
        endpoint_data: &sgd[data_start..data_start + e],
        selector_data: &sgd[data_start + e..data_start + e + s],
        tables: &sgd[data_start + e + s..data_start + e + s + t],
    };
    // One image descriptor per level, level 0 first: flags, rgb offset/length, alpha offset/length.
    if index >= images {
        return Err(broken("a level without an image descriptor").into());
    }
    let d = FIXED + index * IMAGE_DESC;
    let slice_of = |ofs: usize, len: usize| -> crate::error::Faulty<&[u8]> {
        ofs.checked_add(len)
            .and_then(|end| level.get(ofs..end))
            .ok_or_else(|| broken("a slice lies outside its level").into())
    };
    let rgb = slice_of(u32_at(sgd, d + 4), u32_at(sgd, d + 8))?;
    let alpha_len = u32_at(sgd, d + 16);
    let mut slices = vec![Slice { alpha: false, data: rgb }];
    if alpha_len > 0 {
        slices.push(Slice { alpha: true, data: slice_of(u32_at(sgd, d + 12), alpha_len)? });
    }
    let file = basis_file(true, w, h, &cb, &slices)?;
    transcode(&file, w, h)
}

#[cfg(test)]
pub(super) mod tests_support {
    /// The one-call transcode `uastc` cuts into bands.
    pub fn uastc_whole(blocks: &[u8], w: u32, h: u32) -> Vec<u8> {
        let slice = super::Slice { alpha: false, data: blocks };
        super::transcode(&super::basis_file(false, w, h, &super::Codebooks::default(), &[slice]).unwrap(), w, h)
            .unwrap()
    }

    /// A `.basis` file of `w` x `h` zero UASTC blocks.
    pub fn empty_uastc(w: u32, h: u32) -> Vec<u8> {
        let blocks = vec![0u8; (w.div_ceil(4) * h.div_ceil(4) * 16) as usize];
        super::basis_file(false, w, h, &super::Codebooks::default(), &[super::Slice { alpha: false, data: &blocks }])
            .unwrap()
    }
}
