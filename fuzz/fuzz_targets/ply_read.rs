#![no_main]
//! PLY bytes through the reader (the Scene glue and the HighMesh fast path), the tangent
//! pipeline and the writer (in memory).
use libfuzzer_sys::fuzz_target;
#[path = "common.rs"]
mod common;

fuzz_target!(|data: &[u8]| {
    let path = std::path::Path::new("/nonexistent-bumpbake-fuzz/in.ply");
    if let Ok(m) = bumpbake::format::ply::parse(path, data) {
        let _ = bumpbake::transfer::high::from_ply(path, m);
    }
    common::exercise("/nonexistent-bumpbake-fuzz/in.ply", data);
});
