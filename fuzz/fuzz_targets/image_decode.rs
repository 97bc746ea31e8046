#![no_main]
//! Image bytes through the guarded decoder every command that reads pixels uses.
use bumpbake::format::image as guarded;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(img) = guarded::decode(data) {
        assert!(img.width() > 0 && img.height() > 0);
        assert!(img.width() as u64 * img.height() as u64 <= guarded::MAX_PIXELS);
    }
});
