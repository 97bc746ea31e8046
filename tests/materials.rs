//! What materials need, read one way by every command: KHR_texture_transform (rotated normal
//! textures: tangents, validate and preview follow the transformed UVs), clearcoat normal
//! textures, KHR_materials_anisotropy and KHR_materials_variants all need tangents, and `bake`,
//! `validate` and `inspect` agree. Expected frames are in closed form.

mod common;
mod validate_support;

use common::*;
use serde_json::{json, Value};
use std::f32::consts::FRAC_PI_2;
use std::path::{Path, PathBuf};
use validate_support::{finding, findings, validate};

/// The unit quad as a 2 x 2 grid in the XY plane facing +Z; TEXCOORD_0 = (x, 1 - y), so +u runs
/// along +X and the image's up along +Y.
fn quad(g: &mut Gltf, uv1: bool, tangent: Option<[f32; 4]>) -> Value {
    let (p, n, uv, idx) = grid(2);
    let mut attrs = json!({
        "POSITION": g.floats(&p, Some(34962)),
        "NORMAL": g.floats(&n, Some(34962)),
        "TEXCOORD_0": g.floats(&uv, Some(34962)),
    });
    if uv1 {
        // Set 1 runs u along +Y and v along +X: T = +Y, and the image's up (-dP/dv) is -X.
        let uv1: Vec<[f32; 2]> = p.iter().map(|q| [q[1], q[0]]).collect();
        attrs["TEXCOORD_1"] = json!(g.floats(&uv1, Some(34962)));
    }
    if let Some(t) = tangent {
        attrs["TANGENT"] = json!(g.floats(&vec![t; p.len()], Some(34962)));
    }
    json!({ "attributes": attrs, "indices": g.indices(&idx) })
}

/// A normal map tilted towards +x of the image in its top half and flat in the bottom half, so
/// that both where the texture is sampled and the frame it is applied in show in the shading.
fn half_tilted_png() -> Vec<u8> {
    let img =
        image::RgbImage::from_fn(16, 16, |_, y| image::Rgb(if y < 8 { [204, 128, 230] } else { [128, 128, 255] }));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// A rotation by pi/2 with the offset that keeps the unit square in place: `(u, v) -> (v, 1 - u)`.
fn rotated() -> Value {
    json!({ "KHR_texture_transform": { "rotation": FRAC_PI_2, "offset": [0.0, 1.0] } })
}

/// Where `T` must point under [`rotated`]: +u' = +v of the stored UVs = -Y; the image's up is
/// `-dP/dv'` = +X = cross(N, T), so `w = +1`.
const ROTATED_T: [f32; 4] = [0.0, -1.0, 0.0, 1.0];
/// The untransformed UVs' frame: what a tool ignoring the transform writes.
const PLAIN_T: [f32; 4] = [1.0, 0.0, 0.0, 1.0];

fn one_quad(dir: &Path, name: &str, used: &[&str], material: Value, uv1: bool, t: Option<[f32; 4]>) -> PathBuf {
    let mut g = Gltf::new();
    let mut prim = quad(&mut g, uv1, t);
    prim["material"] = json!(g.material(material));
    g.mesh(prim);
    if !used.is_empty() {
        g.json["extensionsUsed"] = json!(used);
    }
    g.write_gltf(dir, name)
}

fn assert_tangents(path: &Path, want: [f32; 4]) {
    let scene = load(path);
    for (k, t) in corner_attr::<4>(&scene, P0, "TANGENT").into_iter().enumerate() {
        let close = t.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-5);
        assert!(close, "{}: corner {k} has {t:?}, want {want:?}", path.display());
    }
}

fn codes(report: &Value) -> Vec<String> {
    findings(report).into_iter().map(|(c, _)| c).collect()
}

// ---------- KHR_texture_transform ----------

#[test]
fn tangents_follow_a_rotated_normal_texture() {
    let (d, scratch) = (validated_dir("materials_rotated"), scratch_dir("materials_rotated"));
    // Mirrored in u by the transform, `(u, v) -> (1 - u, v)`: T = +u' = -X, and with the image's
    // up still +Y = cross(N, T) * w, w = -1.
    let mirrored = json!({ "KHR_texture_transform": { "scale": [-1.0, 1.0], "offset": [1.0, 0.0] } });
    for (name, transform, want) in [("rotated", rotated(), ROTATED_T), ("mirrored", mirrored, [-1.0, 0.0, 0.0, -1.0])] {
        let mut g = Gltf::new();
        let t = g.png_texture(&tiny_png());
        let mut prim = quad(&mut g, false, None);
        prim["material"] = json!(g.material(json!({ "normalTexture": { "index": t, "extensions": transform } })));
        g.mesh(prim);
        g.json["extensionsUsed"] = json!(["KHR_texture_transform"]);
        // Without the tangents its material needs, the input is not a valid glTF: it stays out of
        // the validated folder.
        let input = g.write_gltf(&scratch, name);
        let out = d.join(format!("{name}.glb"));
        run_ok(&["tangents", s(&input), "-o", s(&out)]);
        assert_tangents(&out, want);
        // The stored UVs stay as they were: only the frames follow the transform.
        let uv: Vec<[f32; 2]> = corner_attr::<2>(&load(&out), P0, "TEXCOORD_0");
        assert_eq!(uv, corner_attr::<2>(&load(&input), P0, "TEXCOORD_0"));
        // And validate agrees with what tangents made.
        let (_, r) = validate(&[s(&out)]);
        assert!(codes(&r).iter().all(|c| !c.starts_with("TANGENT")), "{name}: {r:#}");
    }
}

#[test]
fn validate_passes_the_rotated_frame_and_flags_the_plain_one() {
    let d = validated_dir("materials_rotated_validate");
    let make = |name: &str, t: [f32; 4]| {
        let mut g = Gltf::new();
        let tex = g.png_texture(&tiny_png());
        let mut prim = quad(&mut g, false, Some(t));
        prim["material"] = json!(g.material(json!({ "normalTexture": { "index": tex, "extensions": rotated() } })));
        g.mesh(prim);
        g.json["extensionsUsed"] = json!(["KHR_texture_transform"]);
        g.write_gltf(&d, name)
    };
    let right = make("right", ROTATED_T);
    let wrong = make("wrong", PLAIN_T);
    let (code, r) = validate(&[s(&right)]);
    assert!(codes(&r).iter().all(|c| !c.starts_with("TANGENT")), "{r:#}");
    assert_eq!(code, 0, "{r:#}");
    let (code, r) = validate(&[s(&wrong)]);
    assert_eq!(finding(&r, "TANGENT_MIKK_ANGLE")["severity"], "error", "{r:#}");
    assert_eq!(code, 1);
}

/// Mean absolute luma difference of two renders.
fn luma_diff(a: &Path, b: &Path) -> f64 {
    let (a, b) = (image::open(a).unwrap().to_luma8(), image::open(b).unwrap().to_luma8());
    assert_eq!(a.dimensions(), b.dimensions());
    a.pixels().zip(b.pixels()).map(|(x, y)| (x[0] as f64 - y[0] as f64).abs()).sum::<f64>() / a.len() as f64
}

#[test]
fn preview_samples_and_frames_through_the_transform() {
    // The inputs leave tangents to the renderer (a validator warning): scratch files.
    let d = scratch_dir("materials_rotated_preview");
    let png = half_tilted_png();
    // The reference: the transform applied to the stored UVs by hand, no extension.
    let make = |name: &str, transform: bool, pre_rotated: bool| {
        let mut g = Gltf::new();
        let tex = g.png_texture(&png);
        let mut prim = quad(&mut g, false, None);
        if pre_rotated {
            let (_, _, uv, _) = grid(2);
            let r: Vec<[f32; 2]> = uv.iter().map(|&[u, v]| [v, 1.0 - u]).collect();
            prim["attributes"]["TEXCOORD_0"] = json!(g.floats(&r, Some(34962)));
        }
        let mut info = json!({ "index": tex });
        if transform {
            info["extensions"] = rotated();
            g.json["extensionsUsed"] = json!(["KHR_texture_transform"]);
        }
        prim["material"] = json!(g.material(json!({ "normalTexture": info })));
        g.mesh(prim);
        let p = g.write_gltf(&d, name);
        let img = d.join(format!("{name}.png"));
        run_ok(&[
            "preview",
            s(&p),
            "-o",
            s(&img),
            "--size",
            "64x64",
            "--light",
            "dir:-1,0,-1",
            "--specular",
            "0",
            "-q",
        ]);
        img
    };
    let with_transform = make("transformed", true, false);
    let by_hand = make("by_hand", false, true);
    let ignored = make("ignored", false, false);
    let same = luma_diff(&with_transform, &by_hand);
    let differs = luma_diff(&ignored, &by_hand);
    assert!(same < 0.5, "transformed vs by hand: mean |diff| {same}");
    assert!(differs > 5.0, "ignoring the transform must show: mean |diff| {differs}");
}

// ---------- clearcoat, anisotropy, variants ----------

#[test]
fn a_clearcoat_normal_texture_alone_gets_tangents_from_its_uv_set() {
    let (d, scratch) = (validated_dir("materials_clearcoat"), scratch_dir("materials_clearcoat"));
    let mut g = Gltf::new();
    let tex = g.png_texture(&tiny_png());
    let mut prim = quad(&mut g, true, None);
    let cc = json!({ "clearcoatFactor": 1.0, "clearcoatNormalTexture": { "index": tex, "texCoord": 1 } });
    prim["material"] = json!(g.material(json!({ "extensions": { "KHR_materials_clearcoat": cc } })));
    g.mesh(prim);
    g.json["extensionsUsed"] = json!(["KHR_materials_clearcoat"]);
    let input = g.write_gltf(&scratch, "in");
    let out = d.join("out.glb");
    let o = run_ok(&["tangents", s(&input), "-o", s(&out), "--json"]);
    let report: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["primitives"][0]["action"], "generated", "{report:#}");
    assert_eq!(report["primitives"][0]["uv_set"], 1);
    assert_tangents(&out, [0.0, 1.0, 0.0, 1.0]);
    let (_, r) = validate(&[s(&out)]);
    assert!(!codes(&r).iter().any(|c| c.starts_with("TANGENT")), "{r:#}");
}

fn anisotropy(dir: &Path, name: &str, t: Option<[f32; 4]>) -> PathBuf {
    let m = json!({ "extensions": { "KHR_materials_anisotropy": { "anisotropyStrength": 0.6 } } });
    one_quad(dir, name, &["KHR_materials_anisotropy"], m, false, t)
}

#[test]
fn anisotropy_alone_keeps_and_gets_tangents() {
    let d = validated_dir("materials_anisotropy");
    // Made: from TEXCOORD_0, so T = +u = +X.
    let bare = anisotropy(&scratch_dir("materials_anisotropy"), "bare", None);
    let made = d.join("made.glb");
    run_ok(&["tangents", s(&bare), "-o", s(&made)]);
    assert_tangents(&made, PLAIN_T);
    let (_, r) = validate(&[s(&bare)]);
    assert!(codes(&r).contains(&"TANGENT_MISSING".to_string()), "{r:#}");

    // Kept: bake leaves them in, validate does not call them unused, inspect says who needs them.
    let with = anisotropy(&d, "with", Some(PLAIN_T));
    let baked = d.join("baked.glb");
    let o = run_ok(&["bake", s(&with), "-o", s(&baked), "--json"]);
    let report: Value = serde_json::from_slice(&o.stdout).unwrap();
    let removed = report["removed"].as_array().unwrap();
    assert!(!removed.iter().any(|r| r["what"].as_str().unwrap().contains("TANGENT")), "{report:#}");
    assert_tangents(&baked, PLAIN_T);
    let (code, r) = validate(&[s(&with), "--strict"]);
    assert!(!codes(&r).contains(&"TANGENT_UNUSED".to_string()), "{r:#}");
    assert_eq!(code, 0, "{r:#}");
    let o = run_ok(&["inspect", s(&with), "--json"]);
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["primitives"][0]["tangents_needed_from"], "TEXCOORD_0");
    assert_eq!(v["primitives"][0]["tangents_needed_by"], "KHR_materials_anisotropy needs tangents from TEXCOORD_0");
}

/// A quad whose default material has no normal texture, and a variant whose material has one
/// reading TEXCOORD_1.
fn variants(dir: &Path, name: &str, t: Option<[f32; 4]>) -> PathBuf {
    let mut g = Gltf::new();
    let tex = g.png_texture(&tiny_png());
    let mut prim = quad(&mut g, true, t);
    let plain = g.material(json!({ "name": "plain" }));
    let bumpy = g.material(json!({ "name": "bumpy", "normalTexture": { "index": tex, "texCoord": 1 } }));
    prim["material"] = json!(plain);
    prim["extensions"] = json!({ "KHR_materials_variants": { "mappings": [{ "material": bumpy, "variants": [1] }] } });
    g.mesh(prim);
    g.json["extensionsUsed"] = json!(["KHR_materials_variants"]);
    g.json["extensions"] =
        json!({ "KHR_materials_variants": { "variants": [{ "name": "plain" }, { "name": "bumpy" }] } });
    g.write_gltf(dir, name)
}

#[test]
fn a_variant_with_a_normal_texture_gets_tangents_and_keeps_them() {
    let d = validated_dir("materials_variants");
    let input = variants(&scratch_dir("materials_variants"), "in", None);
    let out = d.join("out.glb");
    let o = run_ok(&["tangents", s(&input), "-o", s(&out), "--json"]);
    let report: Value = serde_json::from_slice(&o.stdout).unwrap();
    let p = &report["primitives"][0];
    assert_eq!(p["action"], "generated", "{report:#}");
    assert_eq!(p["needed_by"], "normal texture of variant material 1 reads TEXCOORD_1");
    // From the variant's UV set 1: T = +Y.
    assert_tangents(&out, [0.0, 1.0, 0.0, 1.0]);

    let baked = d.join("baked.glb");
    run_ok(&["bake", s(&out), "-o", s(&baked)]);
    assert_tangents(&baked, [0.0, 1.0, 0.0, 1.0]);
    // The variant's material stays too; its UV set, the only one any material reads, is
    // renumbered to TEXCOORD_0 (glTF wants sets without gaps) and the texture follows it.
    let scene = load(&baked);
    let materials = scene.json["materials"].as_array().unwrap();
    assert_eq!(materials.len(), 2);
    let bumpy = materials.iter().find(|m| m["name"] == "bumpy").unwrap();
    assert_eq!(bumpy["normalTexture"].get("texCoord").and_then(|c| c.as_u64()).unwrap_or(0), 0, "{bumpy}");
    assert!(scene.prim_json(P0).pointer("/attributes/TEXCOORD_0").is_some());
    assert!(scene.prim_json(P0).pointer("/attributes/TEXCOORD_1").is_none());
    let (_, r) = validate(&[s(&baked)]);
    assert!(!codes(&r).iter().any(|c| c.starts_with("TANGENT")), "{r:#}");
}

/// preview draws the frames `tangents` would store, from the same UVs (the one rule of
/// `scene::view`): where the drawn material needs none but a variant's does, the frame views of
/// the input follow the variant's UV set, so they show what the output stores, pixel for pixel.
#[test]
fn preview_frames_follow_the_uvs_tangents_store() {
    let d = scratch_dir("materials_variants_preview");
    let input = variants(&d, "in", None);
    let out = d.join("out.glb");
    run_ok(&["tangents", s(&input), "-o", s(&out), "-q"]);
    assert_tangents(&out, [0.0, 1.0, 0.0, 1.0]);
    for view in ["tangent", "handedness"] {
        let picture = |mesh: &Path, name: &str| {
            let img = d.join(format!("{name}_{view}.png"));
            run_ok(&["preview", s(mesh), "-o", s(&img), "--size", "48x48", "--view", view, "-q"]);
            std::fs::read(img).unwrap()
        };
        assert!(picture(&input, "input") == picture(&out, "stored"), "--view {view}: input and output differ");
    }
}

// ---------- one reading ----------

/// The keys of material JSON: the list, a primitive's reference into it, and what a material
/// holds (any `...Texture` object and any `KHR_materials_*` extension included).
fn is_material_key(k: &str) -> bool {
    const KEYS: &[&str] = &[
        "materials",
        "material",
        "texCoord",
        "KHR_texture_transform",
        "pbrMetallicRoughness",
        "baseColorFactor",
        "metallicFactor",
        "roughnessFactor",
        "emissiveFactor",
        "alphaMode",
        "alphaCutoff",
        "doubleSided",
    ];
    KEYS.contains(&k) || k.ends_with("Texture") || k.starts_with("KHR_materials_")
}

/// The JSON keys a line of code names: words quoted (`get("materials")`, `["texCoord"]`,
/// `"doubleSided":`) or segments of a JSON pointer (`"/materials/{m}/name"`).
fn json_keys(line: &str) -> Vec<&str> {
    let b = line.as_bytes();
    let word = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if matches!(b[i], b'"' | b'/') {
            let mut j = i + 1;
            while j < b.len() && word(b[j]) {
                j += 1;
            }
            if j > i + 1 && j < b.len() && matches!(b[j], b'"' | b'/') {
                out.push(&line[i + 1..j]);
            }
            i = j.max(i + 1);
        } else {
            i += 1;
        }
    }
    out
}

/// Material JSON is read and changed only in the scene model (`src/scene/`: `Scene::materials`,
/// `Scene::leave_out` and the methods beside them) and by the readers and writers that build or
/// store it (`src/format/`). Every other file asks `MaterialInfo`, so no stage decides again what a
/// material reads.
#[test]
fn only_the_scene_model_reads_material_json() {
    let bad = stage_lines_where(|line| {
        // A texture's JSON and the raw material JSON of a primitive, too.
        let other = ["/textures/", "material_of("].iter().any(|l| line.contains(l));
        other || json_keys(line).into_iter().any(is_material_key)
    });
    // `error.rs` names the settings a message refers to ("material" is one), not JSON keys.
    let bad: Vec<String> = bad.into_iter().filter(|l| !l.contains("src/error.rs:")).collect();
    assert!(bad.is_empty(), "material JSON read outside src/scene/ (ask Scene::materials):\n{}", bad.join("\n"));
}

#[test]
fn the_material_key_finder_sees_quoted_keys_and_pointer_segments() {
    fn keys(l: &str) -> Vec<&str> {
        json_keys(l).into_iter().filter(|k| is_material_key(k)).collect()
    }
    assert_eq!(keys(r#"let m = json.get("materials");"#), ["materials"]);
    assert_eq!(
        keys(r#"j.pointer(&format!("/materials/{m}/normalTexture/texCoord"))"#),
        ["materials", "normalTexture", "texCoord"]
    );
    assert_eq!(
        keys(r#"pj["material"] = json!({ "doubleSided": true, "KHR_materials_sheen": {} });"#),
        ["material", "doubleSided", "KHR_materials_sheen"]
    );
    // Words in prose and other keys are not material JSON.
    assert!(keys(r#"format!("the texture's texCoord (set {n}) and the material's normalTexture")"#).is_empty());
    assert!(keys(r#"a.get("attributes"); "/meshes/0/primitives""#).is_empty());
}

/// `KHR_animation_pointer` names materials by index inside JSON pointers, which the reference
/// graph does not rewrite: leave-out keeps every material then, and drops unused ones otherwise.
#[test]
fn animation_pointers_keep_materials_in_place() {
    let d = validated_dir("materials_animation_pointer");
    let scratch = scratch_dir("materials_animation_pointer");
    for (name, used) in [("pointer", &["KHR_animation_pointer"][..]), ("plain", &[][..])] {
        let mut g = Gltf::new();
        let mut prim = quad(&mut g, false, None);
        g.material(json!({ "name": "unused" }));
        prim["material"] = json!(g.material(json!({ "name": "shown" })));
        g.mesh(prim);
        if !used.is_empty() {
            g.json["extensionsUsed"] = json!(used);
        }
        let input = g.write_gltf(&scratch, name);
        let out = d.join(format!("{name}.glb"));
        run_ok(&["bake", s(&input), "-o", s(&out)]);
        let names: Vec<String> = load(&out).json["materials"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| m["name"].as_str().unwrap().to_string())
            .collect();
        let want: &[&str] = if used.is_empty() { &["shown"] } else { &["unused", "shown"] };
        assert_eq!(names, want, "{name}");
    }
}
