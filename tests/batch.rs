//! Many inputs at once, JSON Lines records, depfiles.

mod common;
use common::*;

#[test]
fn one_corrupt_file_among_good_ones() {
    let d = scratch_dir("batch_in");
    let v = validated_dir("batch");
    std::fs::copy(fixture("khronos/NormalTangentTest.glb"), d.join("a.glb")).unwrap();
    std::fs::write(d.join("b.glb"), b"glTF\x02\0\0\0").unwrap();
    std::fs::copy(fixture("khronos/NormalTangentMirrorTest.glb"), d.join("c.glb")).unwrap();
    let o = run(&["tangents", s(&d.join("a.glb")), s(&d.join("b.glb")), s(&d.join("c.glb")), "--out-dir", s(&v), "-j", "2", "--json"]);
    assert_eq!(o.status.code(), Some(2), "a failed file makes the batch fail");
    let lines: Vec<serde_json::Value> = String::from_utf8(o.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 3, "one record per file, in input order");
    assert_eq!(lines[0]["status"], "ok");
    assert_eq!(lines[0]["generated"], 1);
    assert_eq!(lines[1]["status"], "error");
    assert!(lines[1]["error"].as_str().unwrap().contains("b.glb"));
    assert_eq!(lines[2]["status"], "ok");
    assert!(v.join("a.glb").exists() && v.join("c.glb").exists());
    assert!(!v.join("b.glb").exists());
    let o = run(&["tangents", s(&d.join("a.glb")), s(&d.join("b.glb")), "--out-dir", s(&v)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("2 files: 1 written, 1 failed") && err.contains("b.glb"), "{err}");
}

#[test]
fn several_inputs_need_an_out_dir() {
    let f = fixture("khronos/NormalTangentTest.glb");
    let o = run(&["tangents", s(&f), s(&f), "-o", "x.glb"]);
    assert_eq!(o.status.code(), Some(2));
    let d = scratch_dir("batch_dup");
    let o = run(&["tangents", s(&f), s(&f), "--out-dir", s(&d)]);
    assert_eq!(o.status.code(), Some(2), "two inputs writing one output are refused");
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 0);
}

#[test]
fn depfile_lists_every_input_read() {
    let v = validated_dir("depfile");
    let out = v.join("spot.gltf");
    let dep = v.join("spot.d");
    run_ok(&["tangents", s(&fixture("spot/spot.obj")), "-o", s(&out), "--depfile", s(&dep), "-q"]);
    let text = std::fs::read_to_string(&dep).unwrap();
    let (target, deps) = text.split_once(": ").unwrap();
    assert_eq!(target, s(&out));
    for f in ["spot/spot.obj", "spot/spot.mtl", "spot/spot_texture.png"] {
        assert!(deps.contains(s(&fixture(f))), "{f} in {text}");
    }
}
