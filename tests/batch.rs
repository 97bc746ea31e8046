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
    let o = run(&[
        "tangents",
        s(&d.join("a.glb")),
        s(&d.join("b.glb")),
        s(&d.join("c.glb")),
        "--out-dir",
        s(&v),
        "-j",
        "2",
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(2), "a failed file makes the batch fail");
    let lines: Vec<serde_json::Value> =
        String::from_utf8(o.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 3, "one record per file, in input order");
    assert_eq!(lines[0]["status"], "ok");
    assert!(lines.iter().all(|l| l["schema"] == "bumpbake-tangents/1"), "every record names its schema");
    assert_eq!(lines[0]["generated"], 1);
    for key in [
        "input",
        "output",
        "primitives",
        "kept",
        "skipped",
        "vertices_in",
        "vertices_out",
        "fallback_frames",
        "notes",
        "written",
        "timings_ms",
    ] {
        assert!(lines[0].get(key).is_some(), "documented field {key}");
    }
    assert_eq!(lines[1]["exit_code"], 2);
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

#[test]
fn normalmap_batch_writes_the_good_maps_and_names_the_bad_one() {
    let d = scratch_dir("nm_batch_in");
    let out = scratch_dir("nm_batch_out");
    std::fs::copy(fixture("bake/bumps.png"), d.join("a.png")).unwrap();
    std::fs::write(d.join("b.png"), b"\x89PNG\r\n\x1a\nbroken").unwrap();
    image::GrayImage::from_pixel(3, 3, image::Luma([7])).save(d.join("c.png")).unwrap();
    let o = run(&[
        "normalmap",
        s(&d.join("a.png")),
        s(&d.join("b.png")),
        s(&d.join("c.png")),
        "--out-dir",
        s(&out),
        "--json",
        "-j",
        "2",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let recs: Vec<serde_json::Value> =
        String::from_utf8(o.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(recs.iter().map(|r| r["status"].as_str().unwrap()).collect::<Vec<_>>(), ["ok", "error", "ok"]);
    assert!(recs[0]["timings_ms"]["stages"].as_array().unwrap().len() >= 2);
    assert!(recs[1]["error"].as_str().unwrap().contains("b.png"));
    let flat = image::open(out.join("c.png")).unwrap().to_rgb8();
    assert!(flat.pixels().all(|p| p.0 == [128, 128, 255]), "constant height is flat");
    assert!(out.join("a.png").exists() && !out.join("b.png").exists());
}

#[test]
fn bake_batch_with_out_dir() {
    let d = scratch_dir("bake_batch_in");
    let v = validated_dir("bake_batch");
    for name in ["torus.obj", "torus.mtl", "bumps.png"] {
        std::fs::copy(fixture(&format!("bake/{name}")), d.join(name)).unwrap();
    }
    std::fs::copy(d.join("torus.obj"), d.join("torus2.obj")).unwrap();
    let o = run(&["bake", s(&d.join("torus.obj")), s(&d.join("torus2.obj")), "--out-dir", s(&v), "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read(v.join("torus.glb")).unwrap(), std::fs::read(v.join("torus2.glb")).unwrap());
}

#[test]
fn validate_batch_goes_on_past_an_unusable_file() {
    let d = scratch_dir("validate_batch");
    std::fs::write(d.join("bad.glb"), b"glTF").unwrap();
    let good = fixture("khronos/NormalTangentMirrorTest.glb");
    let o = run(&["validate", s(&good), s(&d.join("bad.glb")), s(&good), "--format", "json", "-j", "2"]);
    assert_eq!(o.status.code(), Some(2), "an unusable file makes the run exit 2");
    let rep: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(rep["files"].as_array().unwrap().len(), 2, "both good files are reported: {rep}");
    assert!(String::from_utf8_lossy(&o.stderr).contains("bad.glb"));
}

#[test]
#[cfg(target_os = "linux")] // peak memory is read from /proc
fn bench_command_reports_the_whole_commands_time_and_peak_memory() {
    let input = fixture("khronos/NormalTangentTest.glb");
    let o = run(&["bench", "command", s(&input), "--runs", "2", "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(r["runs"], 2);
    assert_eq!(r["input_bytes"], std::fs::metadata(&input).unwrap().len());
    // The output is the input with tangents (it has none): larger.
    assert!(r["output_bytes"].as_u64().unwrap() > r["input_bytes"].as_u64().unwrap());
    let peak = r["peak_kib"].as_u64().unwrap();
    assert!(peak > 1000, "a process's resident set is megabytes, not {peak} KiB");
    let ratio = r["peak_over_input"].as_f64().unwrap();
    assert!((ratio - peak as f64 * 1024.0 / r["input_bytes"].as_f64().unwrap()).abs() < 1e-9);
    assert!(r["min_s"].as_f64().unwrap() <= r["median_s"].as_f64().unwrap());
    // A file that is not a mesh is the command's error, reported as one line.
    let bad =
        run(&["bench", "command", s(&fixture("khronos/NormalTangentTest.mesh0.prim0.tangents.txt")), "--runs", "1"]);
    assert_eq!(bad.status.code(), Some(2));
}
