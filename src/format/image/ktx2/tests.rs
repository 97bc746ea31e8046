use super::*;

/// A one-level 2D KTX2 file of a plain vkFormat, uncompressed (a minimal data format descriptor).
fn plain_file(vk: u32, type_size: u32, w: u32, h: u32, channels: usize, data: &[u8]) -> Vec<u8> {
    let mut dfd = Vec::new();
    let block_len = 24 + 16 * channels;
    dfd.extend_from_slice(&((4 + block_len) as u32).to_le_bytes());
    dfd.extend_from_slice(&0u32.to_le_bytes());
    dfd.extend_from_slice(&2u16.to_le_bytes());
    dfd.extend_from_slice(&(block_len as u16).to_le_bytes());
    dfd.extend_from_slice(&[1, 1, 1, 0, 0, 0, 0, 0, (type_size as usize * channels) as u8, 0, 0, 0, 0, 0, 0, 0]);
    for (k, id) in [0u8, 1, 2, 15].iter().take(channels).enumerate() {
        dfd.extend_from_slice(&((k as u32 * 8 * type_size) as u16).to_le_bytes());
        dfd.extend_from_slice(&[(8 * type_size - 1) as u8, *id, 0, 0, 0, 0]);
        dfd.extend_from_slice(&0u32.to_le_bytes());
        dfd.extend_from_slice(&u32::MAX.to_le_bytes());
    }
    let dfd_ofs = 12 + 68 + 24;
    let level_ofs = (dfd_ofs + dfd.len()).div_ceil(16) * 16;
    let mut f = vec![0xAB, b'K', b'T', b'X', b' ', b'2', b'0', 0xBB, 0x0D, 0x0A, 0x1A, 0x0A];
    for v in [vk, type_size, w, h, 0, 0, 1, 1, 0, dfd_ofs as u32, dfd.len() as u32, 0, 0] {
        f.extend_from_slice(&v.to_le_bytes());
    }
    for v in [0u64, 0, level_ofs as u64, data.len() as u64, data.len() as u64] {
        f.extend_from_slice(&v.to_le_bytes());
    }
    f.extend_from_slice(&dfd);
    f.resize(level_ofs, 0);
    f.extend_from_slice(data);
    f
}

#[test]
fn plain_texels_decode_exactly_and_two_channels_rebuild_z() {
    let data: Vec<u8> = (0..4 * 2 * 4).map(|i| (i * 7) as u8).collect();
    let img = decode_within(&plain_file(37, 1, 4, 2, 4, &data), &Limits::TEXTURE).unwrap();
    assert_eq!(img.as_rgba8().unwrap().as_raw(), &data);
    // x = y = 128 (0.0039): z is 1, stored as 255; x = 255, y = 128: z is 0, stored as 128.
    let img = decode_within(&plain_file(16, 1, 2, 1, 2, &[128, 128, 255, 128]), &Limits::TEXTURE).unwrap();
    assert_eq!(img.as_rgb8().unwrap().as_raw(), &[128, 128, 255, 255, 128, 128]);
}

#[test]
fn half_floats_convert_exactly() {
    assert_eq!(f16_to_f32(0x3C00), 1.0);
    assert_eq!(f16_to_f32(0xC000), -2.0);
    assert_eq!(f16_to_f32(0x0001), 2f32.powi(-24));
    assert_eq!(f16_to_f32(0x3555), 0.333_251_95);
    assert!(f16_to_f32(0x7C00).is_infinite() && f16_to_f32(0x7E00).is_nan());
}

#[test]
fn sizes_are_refused_from_the_header_before_anything_is_read() {
    // Claims 100000 x 100000 RGBA8 and holds 4 bytes: refused by size, not by its data.
    let f = plain_file(37, 1, 100_000, 100_000, 4, &[0; 4]);
    let e = decode_within(&f, &Limits::TEXTURE).unwrap_err().to_string();
    assert!(e.contains("100000x100000"), "{e}");
    let e = decode_within(&f, &Limits::file(1000)).unwrap_err().to_string();
    assert!(e.contains("(max_pixels)"), "{e}");
}

#[test]
fn malformed_files_are_one_line_of_words() {
    let good = plain_file(37, 1, 4, 2, 4, &[9; 32]);
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (good[..good.len() - 1].to_vec(), "ends early"),
        (good[..60].to_vec(), "ends early"),
        (plain_file(37, 1, 4, 2, 4, &[9; 31]), "holds 31 bytes"),
        (plain_file(37, 2, 4, 2, 4, &[9; 32]), "typeSize"),
        (plain_file(145, 1, 4, 4, 4, &[9; 16]), "BC1-BC7 block format, which bumpbake does not decode"),
    ];
    for (bytes, words) in cases {
        let e = decode_within(&bytes, &Limits::TEXTURE).unwrap_err().to_string();
        assert!(e.contains(words) && !e.contains('\n') && !e.contains("Err("), "{e}");
    }
    assert!(not_decoded(&plain_file(145, 1, 4, 4, 4, &[9; 16])).is_some());
    assert!(not_decoded(&good).is_none() && not_decoded(&good[..60]).is_none());
}

#[test]
fn a_basis_header_is_the_size_the_transcoder_expects() {
    let f = basis::tests_support::empty_uastc(8, 4);
    assert_eq!(f.len(), 77 + 23 + 2 * 16);
    assert_eq!(&f[..2], b"sB");
}

/// Banded transcoding gives the pixels of one call, on a level whose bands end mid-block.
#[test]
fn banded_uastc_transcoding_matches_one_call() {
    use super::write::{encode, Codec};
    // 150 blocks a row: bands of 54 block rows, the last one 21 rows and a partial block.
    let (w, h) = (600u32, 297u32);
    let rgb: Vec<u8> =
        (0..w * h).flat_map(|i| [(i % w * 7 + i / w) as u8, ((i / w * 5) ^ (i % w)) as u8, 200]).collect();
    let file = encode(&[Level { width: w, height: h, rgb: &rgb }], Codec::Uastc { level: 0, rdo: None }, 2).unwrap();
    let p = parse(&file).unwrap();
    let level = p.reader.levels().next().unwrap();
    let blocks = unpack(level.data, level.uncompressed_byte_length, 150 * 75 * 16, p.supercompression).unwrap();
    let banded = basis::uastc(&blocks, w, h, false).unwrap();
    assert_eq!(banded.len(), (w * h * 4) as usize);
    assert!(banded == basis::tests_support::uastc_whole(&blocks, w, h));
}

/// Blocks of the kinds that reach every branch of the ETC1 hint search (`etc1_hints.rs`): noise, smooth and sharp
/// normal-map blocks (blue near 255, where the tables clamp), near-black and near-white,
/// greys, two-colour splits either way, and a few flat ones.
pub(super) fn blocks() -> Vec<[u8; 64]> {
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    let mut out = Vec::new();
    for kind in 0..8 {
        for _ in 0..60 {
            let (a, b) = (next(), next());
            let mut px = [255u8; 64];
            for i in 0..16 {
                let (x, y) = ((i % 4) as i32, (i / 4) as i32);
                let r = (next() >> 32) as i32;
                let c = |base: u64, k: u32| ((base >> k) & 255) as i32;
                let rgb: [i32; 3] = match kind {
                    0 => [r & 255, (r >> 8) & 255, (r >> 16) & 255],
                    1 => [c(a, 0) / 2 + 64 + x * 3, c(a, 8) / 2 + 64 + y * 3, 250 - (r & 7)],
                    2 => [128 + (r & 31) - 16, 128 + ((r >> 5) & 31) - 16, 255 - ((r >> 10) & 15)],
                    3 => [c(a, 0) % 12 + x, c(a, 8) % 12 + y, (r & 7)],
                    4 => [255 - (r & 15), 250 - x - y, 240 + ((r >> 4) & 15)],
                    5 => {
                        let g = c(a, 0) + (r & 7) - 3;
                        [g, g, g]
                    }
                    6 => {
                        let side = if a & 1 == 0 { x < 2 } else { y < 2 };
                        let base = if side { a } else { b };
                        [c(base, 0), c(base, 8), c(base, 16)]
                    }
                    _ => [c(a, 0), c(a, 8), c(a, 16)],
                };
                for k in 0..3 {
                    px[4 * i + k] = rgb[k].clamp(0, 255) as u8;
                }
            }
            out.push(px);
        }
    }
    out
}
