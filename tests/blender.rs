//! Files Blender's own glTF exporter wrote (`fixtures/blender`, made by `make.py` there): a
//! skinned, shape-keyed, normal-mapped sphere with a JPEG normal map, exported with tangents and
//! morph tangents, once plain and once with Draco; and the same file with its map turned into
//! lossy WebP by glTF-Transform. Every command runs on them.

mod common;
use common::*;
use serde_json::Value;
use std::path::{Path, PathBuf};

fn blender(name: &str) -> PathBuf {
    fixture(&format!("blender/{name}"))
}

/// A GLB split into its JSON and binary chunks, to be edited and written back.
fn open_glb(path: &Path) -> Gltf {
    let b = std::fs::read(path).unwrap();
    let jl = u32::from_le_bytes(b[12..16].try_into().unwrap()) as usize;
    let json: Value = serde_json::from_slice(&b[20..20 + jl]).unwrap();
    let bl = u32::from_le_bytes(b[20 + jl..24 + jl].try_into().unwrap()) as usize;
    Gltf { json, bin: b[28 + jl..28 + jl + bl].to_vec() }
}

/// Per corner of primitive 0: a target's stream, or zero where the target does not have it.
fn target_corners(scene: &bumpbake::scene::Scene, name: &str) -> Vec<[f32; 3]> {
    let p = scene.primitive(P0).unwrap();
    let s = p.targets[0].iter().find(|(n, _)| n == name).unwrap_or_else(|| panic!("no target {name}"));
    let v: Vec<[f32; 3]> = s.1.to_f32();
    p.indices.iter().map(|&i| v[i as usize]).collect()
}

fn add(a: [f32; 4], d: [f32; 3]) -> [f32; 4] {
    [a[0] + d[0], a[1] + d[1], a[2] + d[2], a[3]]
}

/// Our morph TANGENT deltas against a reference from Blender itself: `sphere_twisted.glb` is the
/// same sphere with its shape key applied, exported with Blender's MikkTSpace tangents. Base plus
/// delta must be those tangents, corner for corner, to Blender's 4-decimal rounding.
/// (Blender's own morph deltas in `sphere.glb` are not this: they turn the base tangent by the
/// normal's rotation, backwards, and miss the morphed tangent by up to 41 degrees.)
#[test]
fn morph_tangent_deltas_match_blender_mikktspace_on_the_morphed_mesh() {
    let v = validated_dir("blender_morph");
    let out = v.join("sphere.glb");
    run_ok(&["tangents", s(&blender("sphere.glb")), "-o", s(&out), "--overwrite", "-q"]);
    let ours = load(&out);
    let twisted = load(&blender("sphere_twisted.glb"));
    let base = corner_attr::<4>(&ours, P0, "TANGENT");
    let delta = target_corners(&ours, "TANGENT");
    let moved: Vec<[f32; 3]> = corner_attr::<3>(&ours, P0, "POSITION")
        .iter()
        .zip(target_corners(&ours, "POSITION"))
        .map(|(p, d)| [p[0] + d[0], p[1] + d[1], p[2] + d[2]])
        .collect();
    assert_eq!(moved, corner_attr::<3>(&twisted, P0, "POSITION"), "the corners correspond");
    let reference = corner_attr::<4>(&twisted, P0, "TANGENT");
    let blender_base = corner_attr::<4>(&load(&blender("sphere.glb")), P0, "TANGENT");
    let (mut worst_base, mut worst_morph) = (0.0f64, 0.0f64);
    for c in 0..base.len() {
        worst_base = worst_base.max(angle(base[c], blender_base[c]).to_degrees());
        worst_morph = worst_morph.max(angle(add(base[c], delta[c]), reference[c]).to_degrees());
        assert_eq!(base[c][3], reference[c][3], "corner {c}: handedness");
    }
    // Blender writes tangents with 4 decimals: up to about 0.006 degrees.
    assert!(worst_base < 0.01, "base tangents off Blender's by {worst_base} degrees");
    assert!(worst_morph < 0.01, "morphed tangents off Blender's MikkTSpace by {worst_morph} degrees");
}

fn luma(path: &Path) -> Vec<f64> {
    let img = image::open(path).unwrap().to_rgb8();
    img.pixels().map(|p| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64).collect()
}

fn mean_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum::<f64>() / a.len() as f64
}

/// The JPEG and the lossy-WebP variants draw alike, and both unlike the sphere without its map:
/// preview draws with the WebP normal map (EXT_texture_webp, no fallback image).
#[test]
fn preview_draws_the_jpeg_and_webp_normal_maps() {
    let d = scratch_dir("blender_preview");
    let mut bare = open_glb(&blender("sphere.glb"));
    bare.json["materials"][0].as_object_mut().unwrap().remove("normalTexture");
    bare.write_glb(&d.join("bare.glb"));
    let mut l = Vec::new();
    for input in [blender("sphere.glb"), blender("sphere_webp.glb"), d.join("bare.glb")] {
        let img = d.join(format!("{}.png", input.file_stem().unwrap().to_string_lossy()));
        let o = run_ok(&["preview", s(&input), "-o", s(&img), "--size", "96x96", "--light", "dir:-1,-1,-1"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!err.contains("drawn without"), "{err}");
        l.push(luma(&img));
    }
    let (jpeg_webp, jpeg_bare) = (mean_abs_diff(&l[0], &l[1]), mean_abs_diff(&l[0], &l[2]));
    // Measured: 0.34 (lossy WebP against JPEG) and 6.6 (no map) levels of 255.
    assert!(jpeg_webp * 4.0 < jpeg_bare, "JPEG vs WebP {jpeg_webp}, JPEG vs no map {jpeg_bare}");
}

/// validate checks the mesh and the JPEG / WebP normal map (OpenGL, as Blender writes), tangents
/// keeps Blender's valid tangents, bake and inspect run; every output is Khronos-valid.
#[test]
fn every_command_runs_on_the_blender_exports() {
    let v = validated_dir("blender_all");
    for name in ["sphere.glb", "sphere_webp.glb"] {
        let input = blender(name);
        let o = run(&["validate", s(&input), "--format", "json"]);
        assert_eq!(o.status.code(), Some(0), "{name}: {}", String::from_utf8_lossy(&o.stdout));
        let r: Value = serde_json::from_slice(&o.stdout).unwrap();
        let subjects = r["files"][0]["subjects"].as_array().unwrap();
        let image = subjects.iter().find(|s| s["kind"] == "image").expect("the normal map is checked");
        assert_eq!(image["convention"]["convention"], "opengl", "{name}: {image}");
        assert!(subjects.iter().any(|s| s["kind"] == "primitive"), "{name}: the mesh is checked");

        let kept = v.join(format!("kept_{name}"));
        let o = run_ok(&["tangents", s(&input), "-o", s(&kept), "--json"]);
        let rep: Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(rep["primitives"][0]["action"], "kept", "{rep}");
        run_ok(&["bake", s(&input), "-o", s(&v.join(format!("baked_{name}"))), "-q"]);
        run_ok(&["inspect", s(&input)]);
    }
}

/// Blender's Draco export (sequential encoding, skinned): decoded on reading, so tangents are
/// written uncompressed (kept, or MikkTSpace on the decoded mesh), `validate` checks the frames and
/// the map, and `preview` draws it.
#[test]
fn draco_export_is_decoded() {
    let v = validated_dir("blender_draco");
    let input = blender("sphere_draco.glb");
    for overwrite in [false, true] {
        let out = v.join(format!("draco_{overwrite}.glb"));
        let mut args = vec!["tangents", s(&input), "-o", s(&out), "-q"];
        if overwrite {
            args.push("--overwrite");
        }
        run_ok(&args);
        let scene = load(&out);
        assert!(!scene.json.to_string().contains("KHR_draco_mesh_compression"), "written uncompressed");
        let ours = corner_attr::<4>(&scene, P0, "TANGENT");
        let plain = corner_attr::<4>(&load(&blender("sphere.glb")), P0, "TANGENT");
        assert_eq!(ours.len(), plain.len());
    }
    let o = run(&["validate", s(&input), "--format", "json"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stdout));
    let r: Value = serde_json::from_slice(&o.stdout).unwrap();
    let subjects = r["files"][0]["subjects"].as_array().unwrap();
    assert!(subjects.iter().any(|s| s["kind"] == "image"), "the normal map is checked: {r}");
    assert!(subjects.iter().any(|s| s["kind"] == "primitive" && s["findings"].as_array().is_none_or(|f| f.is_empty())));
    let png = scratch_dir("blender_draco").join("sphere_draco.png");
    run_ok(&["preview", s(&input), "-o", s(&png)]);
    assert!(png.exists());
}
