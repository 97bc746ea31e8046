//! `bumpbake bake` end to end: every output validates (bumpbake --strict and Khronos), has
//! tangents exactly where a normal texture is used, and nothing from the leave-out list.

mod common;
use bumpbake::scene::{PrimRef, Scene};
use common::*;
use serde_json::json;
use std::path::Path;

/// `bumpbake validate --strict` passes.
fn assert_validates(out: &Path) {
    let o = run(&["validate", "--strict", s(out)]);
    assert_eq!(o.status.code(), Some(0), "validate --strict {}: {}", out.display(), String::from_utf8_lossy(&o.stderr));
}

/// Tangents where a normal texture reads them and nowhere else; no unused UV sets, no
/// `_BITANGENT`, no unreferenced materials, textures, images or samplers.
fn assert_nothing_unneeded(scene: &Scene) {
    let mut used = (std::collections::BTreeSet::new(), std::collections::BTreeSet::new());
    for r in scene.primitives() {
        let pj = scene.prim_json(r);
        let attrs = pj["attributes"].as_object().unwrap();
        let normal_set = scene.normal_texcoord(r);
        assert_eq!(
            attrs.contains_key("TANGENT"),
            normal_set.is_some(),
            "{r:?}: TANGENT exactly where a normal texture is"
        );
        assert!(!attrs.contains_key("_BITANGENT"), "{r:?}: no bitangents unless asked");
        let mat = scene.material_of(r);
        let sets: Vec<u64> =
            attrs.keys().filter_map(|k| k.strip_prefix("TEXCOORD_")).map(|k| k.parse().unwrap()).collect();
        let text = mat.map(|m| m.to_string()).unwrap_or_default();
        for k in sets {
            let read = (k == 0 && text.contains("\"index\"")) || text.contains(&format!("\"texCoord\":{k}"));
            assert!(read, "{r:?}: TEXCOORD_{k} is read by a texture");
        }
        if let Some(m) = pj.get("material") {
            used.0.insert(m.as_u64().unwrap());
        }
    }
    let count = |k: &str| scene.json.get(k).and_then(|a| a.as_array()).map(|a| a.len()).unwrap_or(0);
    assert_eq!(used.0.len(), count("materials"), "every material is used");
    let text = scene.json["materials"].to_string();
    for t in 0..count("textures") {
        assert!(text.contains(&format!("\"index\":{t}")), "texture {t} is used");
        used.1.insert(scene.json["textures"][t]["source"].as_u64().unwrap());
    }
    assert_eq!(used.1.len(), count("images"), "every image is shown");
}

#[test]
fn torus_obj_with_mtl_height_map() {
    let v = validated_dir("bake_torus");
    let out = v.join("torus.glb");
    let o = run_ok(&["bake", s(&fixture("bake/torus.obj")), "-o", s(&out), "--json"]);
    let rep: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(rep["maps"][0]["source"], "height");
    assert_validates(&out);
    let scene = load(&out);
    assert_nothing_unneeded(&scene);
    assert!(scene.json["materials"][0].get("normalTexture").is_some());
    // The bump map's -bm 6 multiplies the strength: compare with a map made at strength 6 directly.
    let d = scratch_dir("bake_torus_nm");
    let nm = d.join("n.png");
    run_ok(&["normalmap", s(&fixture("bake/bumps.png")), "-o", s(&nm), "--strength", "6", "--wrap", "repeat"]);
    let img = scene.json["materials"][0]["normalTexture"]["index"].as_u64().unwrap() as usize;
    let src = scene.texture_image(img).unwrap();
    let embedded = image::load_from_memory(&scene.image_bytes(src).unwrap()).unwrap().to_rgb8();
    assert_eq!(embedded, image::open(&nm).unwrap().to_rgb8(), "the embedded map is normalmap's, at -bm strength");
}

#[test]
fn obj_with_quads_and_no_normals_and_a_height_flag() {
    let d = scratch_dir("bake_quads_in");
    let v = validated_dir("bake_quads");
    std::fs::write(d.join("q.obj"), "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 2 0\nvt 2 1\nf 1/1 2/2 3/3 4/4\nf 2/2 5/5 6/6 3/3\n").unwrap();
    let out = v.join("q.gltf");
    run_ok(&["bake", s(&d.join("q.obj")), "--height", s(&fixture("bake/bumps.png")), "-o", s(&out), "-q"]);
    assert_validates(&out);
    let scene = load(&out);
    assert_nothing_unneeded(&scene);
    assert_eq!(scene.primitive(P0).unwrap().indices.len(), 12);
    for (t, n) in corner_attr::<4>(&scene, P0, "TANGENT").into_iter().zip(corner_attr::<3>(&scene, P0, "NORMAL")) {
        assert_valid_frame(t, n, "quad corner");
        assert_eq!(n, [0.0, 0.0, 1.0]);
    }
}

/// Three materials, one chosen for the height map; the others lose the tangents, UV sets and
/// bitangents nothing reads, and an unused material, duplicate image and sampler go.
fn multi_material_scene(dir: &Path) -> std::path::PathBuf {
    let mut g = Gltf::new();
    let (pos, nrm, uv, idx) = grid(2);
    let tex_a = g.texture();
    let tex_b = g.texture(); // same bytes as tex_a's image: deduplicated
    g.json["samplers"] = json!([{ "wrapS": 10497 }, { "wrapS": 33071 }]);
    g.json["textures"][0]["sampler"] = json!(0);
    let stone =
        g.material(json!({ "name": "Stone", "pbrMetallicRoughness": { "baseColorTexture": { "index": tex_a } } }));
    let wood =
        g.material(json!({ "name": "Wood", "pbrMetallicRoughness": { "baseColorTexture": { "index": tex_b } } }));
    let plain = g.material(json!({ "name": "Plain" }));
    let _unused = g.material(json!({ "name": "Unused" }));
    for m in [stone, wood, plain] {
        let p = g.floats(&pos, Some(34962));
        let n = g.floats(&nrm, Some(34962));
        let t0 = g.floats(&uv, Some(34962));
        let t1 = g.floats(&uv, Some(34962));
        let tan = g.floats(&vec![[1.0f32, 0.0, 0.0, 1.0]; pos.len()], Some(34962));
        let bit = g.floats(&vec![[0.0f32, 1.0, 0.0]; pos.len()], Some(34962));
        let i = g.indices(&idx);
        g.mesh(json!({ "attributes": { "POSITION": p, "NORMAL": n, "TEXCOORD_0": t0, "TEXCOORD_1": t1, "TANGENT": tan, "_BITANGENT": bit }, "indices": i, "material": m }));
    }
    g.write_gltf(dir, "multi")
}

#[test]
fn gltf_scene_with_several_materials_one_gets_the_map() {
    let d = scratch_dir("bake_multi_in");
    let v = validated_dir("bake_multi");
    let input = multi_material_scene(&d);
    let out = v.join("multi.glb");
    let o = run_ok(&[
        "bake",
        s(&input),
        "--height",
        s(&fixture("bake/bumps.png")),
        "--material",
        "Stone",
        "-o",
        s(&out),
        "--json",
    ]);
    let rep: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let removed: Vec<String> =
        rep["removed"].as_array().unwrap().iter().map(|r| r["what"].as_str().unwrap().to_string()).collect();
    for want in [
        "mesh 1 primitive 0: TANGENT",
        "mesh 2 primitive 0: TANGENT",
        "mesh 0 primitive 0: _BITANGENT",
        "mesh 0 primitive 0: TEXCOORD_1",
        "mesh 2 primitive 0: TEXCOORD_0",
        "material 3 'Unused'",
        "image 1",
        "sampler 1",
    ] {
        assert!(removed.iter().any(|r| r.starts_with(want)), "{want} left out: {removed:#?}");
    }
    assert!(rep["removed_bytes"].as_u64().unwrap() > 0);
    assert_validates(&out);
    let scene = load(&out);
    assert_nothing_unneeded(&scene);
    assert_eq!(scene.json["materials"].as_array().unwrap().len(), 3);
    assert!(scene.json["materials"][0].get("normalTexture").is_some());
    assert!(scene.json["materials"][1].get("normalTexture").is_none());
}

#[test]
fn leaving_out_does_not_change_what_is_drawn() {
    let d = scratch_dir("bake_same_in");
    let v = validated_dir("bake_same");
    let input = multi_material_scene(&d);
    let (all, lean) = (d.join("keep_all.glb"), v.join("lean.glb"));
    let args = |out: &Path, extra: &[&str]| {
        let mut a = vec![
            "bake".to_string(),
            s(&input).into(),
            "--height".into(),
            s(&fixture("bake/bumps.png")).into(),
            "--material".into(),
            "Stone".into(),
            "-o".into(),
            s(out).into(),
            "-q".into(),
        ];
        a.extend(extra.iter().map(|x| x.to_string()));
        a
    };
    let o = bin().args(args(&all, &["--keep-all"])).output().unwrap();
    assert!(o.status.success());
    let o = bin().args(args(&lean, &[])).output().unwrap();
    assert!(o.status.success());
    let (a, b) = (load(&all), load(&lean));
    assert_eq!(a.primitives(), b.primitives());
    for r in a.primitives() {
        // What a renderer draws: positions, normals, the UV sets textures read, tangents where a
        // normal map uses them, the material's textures' image bytes.
        let mut names = vec!["POSITION", "NORMAL", "TEXCOORD_0"];
        if b.normal_texcoord(r).is_some() {
            names.push("TANGENT");
        }
        if b.prim_json(r)["material"] == json!(2) {
            names.retain(|n| *n != "TEXCOORD_0");
        }
        for n in names {
            let ca = corner_attr::<4>(&a, r, n);
            let cb = corner_attr::<4>(&b, r, n);
            assert_eq!(ca, cb, "{r:?} {n}");
        }
        let mat = |sc: &Scene, r: PrimRef| sc.material_of(r).cloned().unwrap();
        let (ma, mb) = (mat(&a, r), mat(&b, r));
        assert_eq!(ma["name"], mb["name"]);
        for ptr in ["/pbrMetallicRoughness/baseColorTexture/index", "/normalTexture/index"] {
            let img = |sc: &Scene, m: &serde_json::Value| {
                m.pointer(ptr)
                    .and_then(|t| t.as_u64())
                    .map(|t| sc.image_bytes(sc.texture_image(t as usize).unwrap()).unwrap())
            };
            assert_eq!(img(&a, &ma), img(&b, &mb), "{r:?} {ptr}");
        }
    }
    assert!(std::fs::metadata(&lean).unwrap().len() < std::fs::metadata(&all).unwrap().len());
}

#[test]
fn khronos_normal_tangent_test_with_its_own_normal_map() {
    let v = validated_dir("bake_ntt");
    let out = v.join("ntt.glb");
    let o = run_ok(&["bake", s(&fixture("khronos/NormalTangentTest.glb")), "-o", s(&out), "--json"]);
    let rep: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(rep["maps"][0]["source"], "existing");
    assert_validates(&out);
    let scene = load(&out);
    assert_nothing_unneeded(&scene);
    // Image 1 of the original is not used by any texture... unless it is: either way, what remains
    // is exactly what materials read (checked above). Tangents match the reference.
    let r = reference(&fixture("khronos/NormalTangentTest.mesh0.prim0.tangents.txt"));
    let t = corner_attr::<4>(&scene, P0, "TANGENT");
    for c in 0..t.len() {
        assert!(angle(t[c], r[c]) < 1e-5 || r[c][0].is_nan(), "corner {c}");
    }
}

#[test]
fn directx_normal_map_is_converted_and_a_wrong_declaration_refused() {
    let d = scratch_dir("bake_dx_in");
    let v = validated_dir("bake_dx");
    let gl = d.join("gl.png");
    let dx = d.join("dx.png");
    run_ok(&["normalmap", s(&fixture("bake/bumps.png")), "-o", s(&gl), "--strength", "3", "--wrap", "repeat"]);
    run_ok(&[
        "normalmap",
        s(&fixture("bake/bumps.png")),
        "-o",
        s(&dx),
        "--strength",
        "3",
        "--wrap",
        "repeat",
        "--convention",
        "directx",
    ]);
    let out = v.join("dx.glb");
    let o = run_ok(&["bake", s(&fixture("bake/torus.obj")), "--normal", s(&dx), "-o", s(&out), "--json"]);
    let rep: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(rep["maps"][0]["convention"]["converted"], true, "{rep}");
    assert_validates(&out);
    let scene = load(&out);
    let t = scene.json["materials"][0]["normalTexture"]["index"].as_u64().unwrap() as usize;
    let embedded =
        image::load_from_memory(&scene.image_bytes(scene.texture_image(t).unwrap()).unwrap()).unwrap().to_rgb8();
    // Green c -> 255 - c negates the decoded n.y exactly; it differs from encoding -n.y afresh
    // only where rounding met a tie (n.y = 0 encodes to 128 both ways), by one step.
    let want = image::open(&gl).unwrap().to_rgb8();
    for (p, q) in embedded.pixels().zip(want.pixels()) {
        assert_eq!((p[0], p[2]), (q[0], q[2]), "red and blue untouched");
        assert!((p[1] as i32 - q[1] as i32).abs() <= 1, "green {} vs {}", p[1], q[1]);
    }
    let o = run(&[
        "bake",
        s(&fixture("bake/torus.obj")),
        "--normal",
        s(&dx),
        "--convention",
        "opengl",
        "-o",
        s(&d.join("no.glb")),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("looks like DirectX"));
    assert!(!d.join("no.glb").exists());
}

#[test]
fn bake_is_deterministic_across_runs_and_threads() {
    let v = validated_dir("bake_det");
    let (a, b) = (v.join("a.glb"), v.join("b.glb"));
    run_ok(&["bake", s(&fixture("bake/torus.obj")), "-o", s(&a), "-q"]);
    let o = bin()
        .env("RAYON_NUM_THREADS", "1")
        .args(["bake", s(&fixture("bake/torus.obj")), "-o", s(&b), "-q"])
        .output()
        .unwrap();
    assert!(o.status.success());
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

#[test]
fn external_images_and_depfile() {
    let v = validated_dir("bake_ext");
    let out = v.join("torus.gltf");
    let dep = v.join("torus.d");
    run_ok(&["bake", s(&fixture("bake/torus.obj")), "-o", s(&out), "--images", "external", "--depfile", s(&dep), "-q"]);
    let scene = load(&out);
    let uri = scene.json["images"][0]["uri"].as_str().unwrap().to_string();
    assert!(v.join(&uri).exists(), "{uri} written beside the .gltf");
    let deps = std::fs::read_to_string(&dep).unwrap();
    for f in ["bake/torus.obj", "bake/torus.mtl", "bake/bumps.png"] {
        assert!(deps.contains(s(&fixture(f))), "{f} in {deps}");
    }
}

/// `bake` reports what it did with an MTL height map, not advice to run itself; `tangents`, which
/// leaves the height map alone, is the command that points to `bake`.
#[test]
fn height_map_note_only_where_the_map_is_not_converted() {
    let v = validated_dir("bake_torus_note");
    let out = v.join("torus.glb");
    let o = run_ok(&["bake", s(&fixture("bake/torus.obj")), "-o", s(&out)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("height map from"), "bake says it converted the height map: {err}");
    assert!(!err.contains("bumpbake bake"), "bake does not advise running bake: {err}");
    // `tangents` keeps the UV set no texture reads yet: its output is checked apart from bake's.
    let out = validated_dir("tangents_torus_note").join("torus.glb");
    let o = run_ok(&["tangents", s(&fixture("bake/torus.obj")), "-o", s(&out)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("'bumps.png' is a height map") && err.contains("`bumpbake bake` converts it"), "{err}");
}

/// A mesh without UVs cannot carry a map: exit 2 with one line naming the file and the way out,
/// and no output (it used to write a normal texture reading a TEXCOORD_0 that does not exist).
#[test]
fn mesh_without_uvs_and_a_height_map_is_refused() {
    let d = scratch_dir("bake_no_uvs");
    let input = d.join("no_uvs.obj");
    std::fs::write(&input, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
    let out = d.join("no_uvs.glb");
    let o = run(&["bake", s(&input), "--height", s(&fixture("bake/bumps.png")), "-o", s(&out)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains(s(&input)) && err.contains("no UV coordinates") && err.contains("vt lines"), "{err}");
    assert!(!out.exists(), "nothing written");
}

/// A primitive with two UV sets whose only texture reads set 1: set 0 goes, set 1 becomes set 0
/// and the texture reads it there (the Khronos validator reported the unused set).
#[test]
fn uv_set_read_alone_becomes_set_0() {
    let d = scratch_dir("bake_uv1_in");
    let v = validated_dir("bake_uv1");
    run_ok(&["normalmap", s(&fixture("bake/bumps.png")), "-o", s(&d.join("n.png")), "--strength", "6"]);
    let mut g = Gltf::new();
    let (pos, nrm, uv, idx) = grid(4);
    let other: Vec<[f32; 2]> = uv.iter().map(|t| [t[1] * 0.5, t[0] * 0.5 + 0.25]).collect();
    let p = g.floats(&pos, Some(34962));
    let n = g.floats(&nrm, Some(34962));
    let t0 = g.floats(&other, Some(34962));
    let t1 = g.floats(&uv, Some(34962));
    let i = g.indices(&idx);
    g.json["images"] = json!([{ "uri": "n.png" }]);
    g.json["textures"] = json!([{ "source": 0 }]);
    let m = g.material(json!({ "name": "Skin", "normalTexture": { "index": 0, "texCoord": 1 } }));
    g.mesh(json!({ "attributes": { "POSITION": p, "NORMAL": n, "TEXCOORD_0": t0, "TEXCOORD_1": t1 }, "indices": i, "material": m }));
    let input = g.write_gltf(&d, "uv1");
    let out = v.join("uv1.glb");
    let o = run_ok(&["bake", s(&input), "-o", s(&out), "--json"]);
    let rep: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let removed: Vec<&str> = rep["removed"].as_array().unwrap().iter().map(|r| r["what"].as_str().unwrap()).collect();
    assert!(
        removed.contains(&"mesh 0 primitive 0: TEXCOORD_0 (no texture reads it; TEXCOORD_1 becomes TEXCOORD_0)"),
        "{removed:#?}"
    );
    assert_validates(&out);
    let scene = load(&out);
    assert_nothing_unneeded(&scene);
    let attrs = scene.prim_json(P0)["attributes"].as_object().unwrap();
    assert!(attrs.contains_key("TEXCOORD_0") && !attrs.contains_key("TEXCOORD_1"), "{attrs:?}");
    assert_eq!(scene.normal_texcoord(P0), Some(0));
    let want: Vec<[f32; 2]> = idx.iter().map(|&k| uv[k as usize]).collect();
    assert_eq!(corner_attr::<2>(&scene, P0, "TEXCOORD_0"), want, "the set the map reads, moved to 0");
}

/// A 16-bit Gaussian bump (sigma 30 texels, heights 0..0.25) as a PNG.
fn gentle_bump(path: &Path) {
    let img = image::ImageBuffer::<image::Luma<u16>, _>::from_fn(200, 200, |x, y| {
        let r2 = (x as f64 - 100.0).powi(2) + (y as f64 - 100.0).powi(2);
        image::Luma([(0.25 * (-r2 / (2.0 * 30.0 * 30.0)).exp() * 65535.0).round() as u16])
    });
    img.save(path).unwrap();
}

/// A gentle height map at the default strength comes out flat: bake says so and names a strength
/// that shows the relief; at that strength the map is not flat.
#[test]
fn a_flat_result_is_warned_about_with_a_strength_that_shows_the_relief() {
    let d = scratch_dir("bake_flat_in");
    let v = validated_dir("bake_flat");
    let bump = d.join("bump.png");
    gentle_bump(&bump);
    let mesh = d.join("q.obj");
    std::fs::write(&mesh, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n")
        .unwrap();
    let out = v.join("flat.glb");
    let o = run_ok(&["bake", s(&mesh), "--height", s(&bump), "-o", s(&out)]);
    let err = String::from_utf8_lossy(&o.stderr);
    // Sobel's smoothing leaves every texel at the flat one: flat, not only nearly.
    assert!(err.contains("warning: bump.png: the normal map is flat: every texel rounds to (0, 0, 1)"), "{err}");
    let strength = err.split("--strength ").nth(1).and_then(|r| r.split_whitespace().next()).expect("a strength");
    assert_eq!(strength, "110", "tan 30° / steepest slope 0.25 e^-1/2 / 30: {err}");
    let out = v.join("relief.glb");
    let o = run_ok(&["bake", s(&mesh), "--height", s(&bump), "--strength", strength, "-o", s(&out)]);
    assert!(!String::from_utf8_lossy(&o.stderr).contains("warning"));
    assert_validates(&out);
}
