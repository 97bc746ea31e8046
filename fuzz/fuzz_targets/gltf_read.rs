#![no_main]
//! glTF and GLB bytes through the reader, the tangent pipeline and the writer (in memory).
use libfuzzer_sys::fuzz_target;
#[path = "common.rs"]
mod common;

fuzz_target!(|data: &[u8]| {
    // GLB is recognised by its magic; anything else is taken as glTF JSON.
    common::exercise("/nonexistent-bumpbake-fuzz/in.gltf", data);
});
