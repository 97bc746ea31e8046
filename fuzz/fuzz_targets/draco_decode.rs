#![no_main]
//! Draco streams (the bytes a KHR_draco_mesh_compression primitive points at) through `draco-core`
//! and everything bumpbake reads out of a decoded mesh: every value of every attribute, every face.
//! Seeds: glTF-Transform's and Blender's streams (`fuzz/seeds/draco_decode`).
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok((points, faces)) = bumpbake::format::gltf::draco::decode_and_read(data) {
        assert!(points <= 1 << 20 && faces <= 1 << 20, "inside the fuzzing limits");
    }
});
