//! Every input a fuzz target ever crashed on (`fuzz/regressions/TARGET/`), replayed through the
//! same steps as the target, so a fixed crash stays fixed without a nightly toolchain.

use bumpbake::format::WriteOptions;
use bumpbake::scene::ReadOptions;
use bumpbake::tangent::apply::{apply, ApplyOptions};
use std::path::{Path, PathBuf};

fn inputs(target: &str) -> Vec<PathBuf> {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/regressions").join(target);
    let mut v: Vec<PathBuf> = std::fs::read_dir(&d).map(|r| r.map(|e| e.unwrap().path()).collect()).unwrap_or_default();
    v.sort();
    v
}

fn exercise(path: &str, data: &[u8]) {
    let Ok(mut scene) = bumpbake::format::read_bytes(Path::new(path), data, &ReadOptions::default()) else { return };
    for r in scene.primitives() {
        let _ = scene.primitive(r);
    }
    if apply(&mut scene, &ApplyOptions { all: true, ..Default::default() }).is_ok() {
        let _ =
            bumpbake::format::write(&scene, Path::new("/nonexistent-bumpbake-fuzz/out.glb"), &WriteOptions::default());
    }
}

#[test]
fn gltf_read_regressions() {
    for f in inputs("gltf_read") {
        exercise("/nonexistent-bumpbake-fuzz/in.gltf", &std::fs::read(&f).unwrap());
    }
}

#[test]
fn obj_read_regressions() {
    for f in inputs("obj_read") {
        exercise("/nonexistent-bumpbake-fuzz/in.obj", &std::fs::read(&f).unwrap());
    }
}

#[test]
fn image_decode_regressions() {
    for f in inputs("image_decode") {
        let _ = bumpbake::format::image::decode(&std::fs::read(&f).unwrap());
    }
}

#[test]
fn ktx2_read_regressions() {
    for f in inputs("ktx2_read") {
        let _ = bumpbake::format::image::decode(&std::fs::read(&f).unwrap());
    }
}

#[test]
fn draco_decode_regressions() {
    for f in inputs("draco_decode") {
        let _ = bumpbake::format::gltf::draco::decode_and_read(&std::fs::read(&f).unwrap());
    }
}
