//! Bad input ends with exit 2, one line naming the file and the problem, no output, no panic.

mod common;
use common::*;
use serde_json::json;
use std::path::{Path, PathBuf};

/// Runs `tangents` on `input` and checks the failure contract; returns the message.
fn fails_cleanly(input: &Path, expect: &str) -> String {
    let dir = input.parent().unwrap().join("out");
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("o.glb");
    let o = run(&["tangents", s(input), "-o", s(&out)]);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(2), "{}: exit code; stderr: {err}", input.display());
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    assert!(err.contains(&*input.to_string_lossy()), "names the file: {err}");
    assert!(err.to_lowercase().contains(&expect.to_lowercase()), "says '{expect}': {err}");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "nothing written for {}", input.display());
    err
}

fn good_glb() -> Vec<u8> {
    std::fs::read(fixture("khronos/NormalTangentTest.glb")).unwrap()
}

fn case(name: &str) -> PathBuf {
    scratch_dir(&format!("bad_{name}"))
}

fn simple(g: &mut Gltf) {
    let (pos, nrm, uv, idx) = grid(1);
    let p = g.floats(&pos, Some(34962));
    let n = g.floats(&nrm, Some(34962));
    let t = g.floats(&uv, Some(34962));
    let i = g.indices(&idx);
    let tex = g.texture();
    let m = g.material(json!({ "normalTexture": { "index": tex } }));
    g.mesh(json!({ "attributes": { "POSITION": p, "NORMAL": n, "TEXCOORD_0": t }, "indices": i, "material": m }));
}

#[test]
fn truncated_empty_and_wrong_magic_glb() {
    let d = case("glb");
    let b = good_glb();
    let f = d.join("truncated.glb");
    std::fs::write(&f, &b[..b.len() / 2]).unwrap();
    fails_cleanly(&f, "truncated");
    let f = d.join("empty.glb");
    std::fs::write(&f, b"").unwrap();
    fails_cleanly(&f, "truncated");
    let f = d.join("magic.glb");
    let mut m = b.clone();
    m[0..4].copy_from_slice(b"gLTF");
    std::fs::write(&f, &m).unwrap();
    fails_cleanly(&f, "magic");
}

#[test]
fn broken_json_and_gltf_1() {
    let d = case("json");
    let f = d.join("broken.gltf");
    std::fs::write(&f, b"{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [").unwrap();
    fails_cleanly(&f, "invalid JSON");
    let f = d.join("v1.gltf");
    std::fs::write(&f, br#"{"asset": {"version": "1.0"}}"#).unwrap();
    fails_cleanly(&f, "version 1.0");
}

#[test]
fn index_out_of_range() {
    let d = case("index");
    let mut g = Gltf::new();
    simple(&mut g);
    // Point the last index past the four vertices.
    let n = g.bin.len();
    g.bin[n - 2..].copy_from_slice(&9u16.to_le_bytes());
    let f = d.join("index.glb");
    g.write_glb(&f);
    fails_cleanly(&f, "out of range");
}

#[test]
fn missing_buffer_file_and_escaping_uri() {
    let d = case("missing");
    let mut g = Gltf::new();
    simple(&mut g);
    let f = g.write_gltf(&d, "m");
    std::fs::remove_file(d.join("m.bin")).unwrap();
    fails_cleanly(&f, "m.bin");
    let mut g = Gltf::new();
    simple(&mut g);
    g.json["buffers"] = json!([{ "byteLength": g.bin.len(), "uri": "../secret.bin" }]);
    let f = d.join("escape.gltf");
    std::fs::write(&f, serde_json::to_vec(&g.json).unwrap()).unwrap();
    fails_cleanly(&f, "outside");
    g.json["buffers"] = json!([{ "byteLength": g.bin.len(), "uri": "data:application/octet-stream;base64,@@@" }]);
    let f = d.join("b64.gltf");
    std::fs::write(&f, serde_json::to_vec(&g.json).unwrap()).unwrap();
    fails_cleanly(&f, "base64");
}

#[test]
fn accessor_past_its_buffer() {
    let d = case("accessor");
    let mut g = Gltf::new();
    simple(&mut g);
    g.json["accessors"][0]["count"] = json!(1000);
    let f = d.join("acc.glb");
    g.write_glb(&f);
    fails_cleanly(&f, "accessor 0");
}

#[test]
fn nan_position() {
    let d = case("nan");
    let mut g = Gltf::new();
    simple(&mut g);
    g.bin[0..4].copy_from_slice(&f32::NAN.to_le_bytes());
    let f = d.join("nan.glb");
    g.write_glb(&f);
    fails_cleanly(&f, "not finite");
    let f = d.join("nan.obj");
    std::fs::write(&f, "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    fails_cleanly(&f, "non-finite");
}

#[test]
fn obj_garbage_and_out_of_range_faces() {
    let d = case("obj");
    let f = d.join("range.obj");
    std::fs::write(&f, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n").unwrap();
    fails_cleanly(&f, "OBJ");
    let f = d.join("garbage.obj");
    std::fs::write(&f, "v 0 zero 0\nf 1 2 3\n").unwrap();
    fails_cleanly(&f, "OBJ");
    let f = d.join("nomtl.obj");
    std::fs::write(&f, "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    fails_cleanly(&f, "gone.mtl");
}

#[test]
fn failed_run_in_place_leaves_the_input_untouched() {
    let d = case("inplace");
    let f = d.join("same.glb");
    let b = good_glb();
    let cut = &b[..b.len() - 100];
    std::fs::write(&f, cut).unwrap();
    let o = run(&["tangents", s(&f), "-o", s(&f)]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(std::fs::read(&f).unwrap(), cut);
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1, "no temporary left behind");
}

#[test]
fn unknown_output_extension_is_a_usage_error() {
    let d = case("ext");
    let o = run(&["tangents", s(&fixture("khronos/NormalTangentTest.glb")), "-o", s(&d.join("x.fbx"))]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains(".gltf or .glb"));
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 0);
}
