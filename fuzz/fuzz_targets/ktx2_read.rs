#![no_main]
//! KTX2 bytes through the guarded image reader: the container parser, Zstandard and zlib
//! inflation, and the Basis Universal transcoder (ETC1S and UASTC) behind it. Seeds: UASTC,
//! ETC1S and plain files (`fuzz/seeds/ktx2_read`); anything decoded is inside the limits.
use bumpbake::format::image as guarded;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // Every input is taken as KTX2: the identifier is forced so that mutations go to the header,
    // the index and the payload rather than to the magic bytes.
    const ID: [u8; 12] = [0xAB, b'K', b'T', b'X', b' ', b'2', b'0', 0xBB, 0x0D, 0x0A, 0x1A, 0x0A];
    let mut bytes = data.to_vec();
    if bytes.len() >= 12 {
        bytes[..12].copy_from_slice(&ID);
    }
    if let Ok(img) = guarded::decode(&bytes) {
        assert!(img.width() > 0 && img.height() > 0);
        assert!(img.width() as u64 * img.height() as u64 <= guarded::MAX_PIXELS);
    }
    let _ = guarded::header(&bytes);
});
