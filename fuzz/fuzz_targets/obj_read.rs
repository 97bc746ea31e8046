#![no_main]
//! OBJ bytes through the reader, the tangent pipeline and the writer (in memory).
use libfuzzer_sys::fuzz_target;
#[path = "common.rs"]
mod common;

fuzz_target!(|data: &[u8]| {
    common::exercise("/nonexistent-bumpbake-fuzz/in.obj", data);
});
