//! `bake --from` on a scene Blender 5.0.1 exported (`fixtures/blender_scene/make.py`): LOW and HIGH
//! under a rotated, translated, scaled parent, each with its own object transform, HIGH's mesh
//! data halved under an object scale of 2; HIGH also as Blender's world-space OBJ and binary PLY
//! (quads). Each bakes the map the same objects bake at the origin: byte for byte through glTF's
//! node transforms, within one 8-bit level from the world-space OBJ and PLY (their vertices went
//! through Blender's float arithmetic once more).

mod common;
use common::{fixture, load, record_input, run_ok, s, validated_dir};
use serde_json::Value;
use std::path::Path;

fn bake(low: &Path, high: &Path, out: &Path) -> Value {
    let args = ["bake", s(low), "--from", s(high), "-o", s(out), "--size", "64", "--json"];
    serde_json::from_slice(&run_ok(&args).stdout).unwrap()
}

fn map_of(out: &Path) -> image::RgbImage {
    let sc = load(out);
    let t = sc.json.pointer("/materials/0/normalTexture/index").unwrap().as_u64().unwrap();
    let img = sc.texture_image(t as usize).unwrap();
    image::load_from_memory(&sc.image_bytes(img).unwrap()).unwrap().to_rgb8()
}

/// Largest channel difference and how many texels differ at all.
fn diff(a: &image::RgbImage, b: &image::RgbImage) -> (u8, usize) {
    a.pixels().zip(b.pixels()).fold((0, 0), |(most, n), (p, q)| {
        let d = (0..3).map(|c| p.0[c].abs_diff(q.0[c])).max().unwrap();
        (most.max(d), n + (d > 0) as usize)
    })
}

#[test]
fn blender_scene_with_object_transforms_bakes_the_plain_map() {
    let dir = validated_dir("blender_scene");
    let scene = |p: &str| fixture(&format!("blender_scene/{p}"));
    let plain_out = dir.join("plain.glb");
    let r = bake(&scene("plain/torus_low.glb"), &scene("plain/torus_high.glb"), &plain_out);
    record_input(&plain_out, &scene("plain/torus_low.glb"), &[]);
    assert_eq!(r["transfer"]["counts"]["missed_rays"], 0, "{r}");
    let plain = map_of(&plain_out);
    // The map is not flat: the comparison below means something.
    assert!(plain.pixels().any(|p| p.0[0].abs_diff(128) > 20), "the plain map is flat");

    let low = scene("moved/torus_low.glb");
    for (high, most) in [("glb", 0), ("obj", 1), ("ply", 1)] {
        let out = dir.join(format!("moved_from_{high}.glb"));
        let r = bake(&low, &scene(&format!("moved/torus_high.{high}")), &out);
        record_input(&out, &low, &[]);
        assert_eq!(r["transfer"]["counts"]["missed_rays"], 0, "{high}: {r}");
        // The node named torus_low pairs with the HIGH part torus_high: a glTF node, an OBJ
        // object and a PLY file's name alike.
        let pairs = &r["transfer"]["pairs"];
        assert_eq!(pairs[0]["low"][0], "torus_low", "{high}: {r}");
        assert_eq!(pairs[0]["high"][0], "torus_high", "{high}: {r}");
        let (d, n) = diff(&plain, &map_of(&out));
        assert!(d <= most, "from {high}: {n} texels differ, by up to {d} levels");
    }
}
