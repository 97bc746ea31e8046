//! `bumpbake inspect`: the facts a bump-mapping pipeline cares about, as text and JSON.

mod common;
use common::*;

#[test]
fn inspect_json_names_attributes_tangent_need_and_images() {
    let o = run_ok(&[
        "inspect",
        s(&fixture("khronos/NormalTangentTest.glb")),
        s(&fixture("khronos/NormalTangentMirrorTest.glb")),
        "--json",
    ]);
    let recs: Vec<serde_json::Value> =
        String::from_utf8(o.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(recs.len(), 2);
    let a = &recs[0];
    assert_eq!(a["format"], "glb");
    let p = &a["primitives"][0];
    assert_eq!(p["vertices"], 3983);
    assert_eq!(p["triangles"], 7774);
    assert_eq!(p["has_tangents"], false);
    assert_eq!(p["tangents_needed_from"], "TEXCOORD_0");
    assert_eq!(a["materials"][0]["normal_image"], 2);
    assert_eq!(a["images"][2]["width"], 2048);
    assert_eq!(a["images"][2]["bits_per_channel"], 8);
    assert_eq!(recs[1]["primitives"][0]["has_tangents"], true);
    let text = String::from_utf8(run_ok(&["inspect", s(&fixture("khronos/NormalTangentTest.glb"))]).stdout).unwrap();
    assert!(text.contains("tangents: MISSING; needed (normal texture reads TEXCOORD_0)"), "{text}");
}

#[test]
fn inspect_sees_a_16_bit_image_and_an_obj_height_map() {
    let d = scratch_dir("inspect_obj");
    let h = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(3, 2, |x, _| image::Luma([x as u16 * 1000]));
    h.save(d.join("h.png")).unwrap();
    std::fs::write(d.join("m.mtl"), "newmtl m\nbump h.png\nmap_Kd h.png\n").unwrap();
    std::fs::write(
        d.join("t.obj"),
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n",
    )
    .unwrap();
    let o = run_ok(&["inspect", s(&d.join("t.obj")), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["images"][0]["bits_per_channel"], 16);
    assert_eq!(v["images"][0]["width"], 3);
    assert!(v["materials"][0]["height_map"].as_str().unwrap().ends_with("h.png"));
}

/// A bad file among good ones is reported in its place (a record or a line of its own) and the
/// files after it are still inspected; the run exits with the worst code (2), as validate does.
#[test]
fn inspect_reports_every_file_when_one_is_bad() {
    let d = scratch_dir("inspect_bad_among_good");
    let good = fixture("khronos/NormalTangentTest.glb");
    std::fs::write(d.join("bad.glb"), b"glTF\x02\0\0\0").unwrap();
    std::fs::write(d.join("bad.obj"), "v 0 0 0\nf 1 2 3\n").unwrap();
    let bad = d.join("bad.glb");
    let o = run(&["inspect", "--json", s(&good), s(&bad), s(&good), s(&d.join("bad.obj"))]);
    assert_eq!(o.status.code(), Some(2), "the worst code: an unusable file");
    let recs: Vec<serde_json::Value> =
        String::from_utf8(o.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(recs.len(), 4, "one record per file, in input order");
    assert!(recs.iter().all(|r| r["schema"] == "bumpbake-inspect/1"));
    for i in [0, 2] {
        assert_eq!(recs[i]["file"], s(&good));
        assert_eq!(recs[i]["primitives"][0]["vertices"], 3983);
        assert!(recs[i].get("status").is_none(), "ok records stay as the schema first wrote them");
    }
    for (i, name) in [(1, "bad.glb"), (3, "bad.obj")] {
        assert_eq!(recs[i]["status"], "error");
        assert_eq!(recs[i]["exit_code"], 2);
        assert!(recs[i]["file"].as_str().unwrap().ends_with(name));
        let e = recs[i]["error"].as_str().unwrap();
        assert!(e.contains(name) && !e.contains('\n'), "one line naming the file: {e}");
    }
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("4 files: 2 inspected, 2 failed"), "{err}");

    // As text: both good files on stdout, each bad one a line on stderr.
    let o = run(&["inspect", s(&good), s(&bad), s(&good)]);
    assert_eq!(o.status.code(), Some(2));
    let out = String::from_utf8(o.stdout).unwrap();
    assert_eq!(out.matches("tangents: MISSING; needed (normal texture reads TEXCOORD_0)").count(), 2, "{out}");
    let err = String::from_utf8_lossy(&o.stderr);
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 2, "{err}");
    assert!(lines[0].starts_with("bumpbake: ") && lines[0].contains("bad.glb"), "{err}");
    assert_eq!(lines[1], format!("3 files: 2 inspected, 1 failed ({})", bad.display()));

    // Alone, a bad file is the command's error, as before.
    let o = run(&["inspect", s(&bad)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(o.stdout.is_empty());
}
