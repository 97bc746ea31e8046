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
