//! Files other tools write: KHR_mesh_quantization, EXT_meshopt_compression and
//! KHR_draco_mesh_compression from glTF-Transform and gltfpack.
//!
//! The small files in `fixtures/real/` (made by `fixtures/real/make.sh`) run with every `cargo
//! test`. The full corpus (`.ci/corpus.sh`, variants of the Khronos fixtures) is found through
//! `BUMPBAKE_CORPUS`, which `.ci/run` sets; under `CI=true` a missing corpus fails the test.

mod common;
use bumpbake::scene::dequant::{transformed_uvs, unit_normals};
use bumpbake::tangent::mikk::{generate, Engine};
use bumpbake::tangent::TriMesh;
use common::*;
use std::path::{Path, PathBuf};

/// Every corner of every primitive whose material has a normal texture carries the MikkTSpace frame
/// of the geometry a renderer decodes (quantized normals made unit, UVs through the normal
/// texture's transform). Returns the number of corners compared.
fn assert_mikktspace(out: &Path) -> usize {
    let scene = load(out);
    let mut compared = 0;
    for r in scene.primitives() {
        let Some(set) = scene.normal_texcoord(r) else { continue };
        let p = bumpbake::scene::to_triangle_list(scene.primitive(r).unwrap());
        let t = p.attr("TANGENT").unwrap_or_else(|| panic!("{}: {r:?} has a normal texture and no TANGENT", s(out)));
        assert_eq!(t.format.component_type, bumpbake::scene::accessor::FLOAT, "tangents written as floats");
        let t = t.to_f32::<4>();
        let positions = p.positions();
        let normals = unit_normals(p.attr("NORMAL").unwrap()).into_owned();
        let uvs = p.attr(&format!("TEXCOORD_{set}")).unwrap().as_f32();
        let uvs = transformed_uvs(uvs, scene.normal_uv_transform(r).as_ref()).into_owned();
        let mesh = TriMesh { positions: &positions, normals: &normals, uvs: &uvs, indices: &p.indices };
        // The C reference when it is built in; otherwise our engine, held bit for bit to it by
        // tests/mikktspace_differential.rs.
        let engine = if cfg!(feature = "reference") { Engine::Bevy } else { Engine::Fast };
        let reference = generate(&mesh, engine);
        let mut bad = 0;
        for (c, rf) in reference.iter().enumerate() {
            let Some(rf) = rf else { continue };
            let stored = t[p.indices[c] as usize];
            compared += 1;
            // glTF UVs run v down: the stored w is the reference sign negated (the conventions).
            if angle(stored, *rf) > 1e-4 || stored[3] != -rf[3] {
                bad += 1;
            }
        }
        assert!(bad * 1000 <= reference.len(), "{}: {bad} corners differ from MikkTSpace", s(out));
    }
    compared
}

/// An exit 2 is one plain line naming the file and what to do, never Rust debug text.
fn assert_plain_refusal(o: &std::process::Output, input: &Path, must_name: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{}: {err}", s(input));
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    assert!(err.contains(input.file_name().unwrap().to_str().unwrap()), "names the file: {err}");
    assert!(err.contains(must_name), "names {must_name}: {err}");
    assert!(!err.contains("Some(") && !err.contains("{ "), "no debug text: {err}");
}

fn real(name: &str) -> PathBuf {
    fixture(&format!("real/{name}"))
}

#[test]
fn quantized_and_meshopt_files_get_mikktspace_tangents_on_their_decoded_geometry() {
    let d = validated_dir("real_tangents");
    for name in [
        "mirror_small.quantize.glb",
        "mirror_small.meshopt.glb",
        "mirror_small.gltfpack.glb",
        "mirror_small.gltfpack-c.glb",
    ] {
        let out = d.join(name);
        let o = run_ok(&["tangents", s(&real(name)), "-o", s(&out), "--overwrite", "--json"]);
        let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(report["generated"], 1, "{name}: {report}");
        assert!(assert_mikktspace(&out) > 500, "{name}: most corners compared");
        let json = load(&out).json;
        let used = json["extensionsUsed"].to_string();
        assert!(!used.contains("EXT_meshopt_compression"), "{name}: written uncompressed: {used}");
        if name.contains("meshopt") || name.contains("-c") {
            assert!(report.to_string().contains("EXT_meshopt_compression"), "the report says it was decoded");
        }
        // Quantized attributes keep their types; POSITION keeps integer bounds.
        let pos = json["meshes"][0]["primitives"][0]["attributes"]["POSITION"].as_u64().unwrap() as usize;
        let acc = &json["accessors"][pos];
        assert_ne!(acc["componentType"], 5126, "{name}: POSITION stays quantized");
        assert!(acc["min"].as_array().unwrap().iter().all(|x| x.is_i64() || x.is_u64()), "{name}: {acc}");
    }
}

#[test]
fn authored_tangents_carried_through_quantization_pass_strict_validation() {
    // Draco decodes to floats; its grid is found from the decoded values (docs/validate.md).
    for name in [
        "mirror_small.glb",
        "mirror_small.quantize.glb",
        "mirror_small.gltfpack.glb",
        "mirror_small.gltfpack-c.glb",
        "mirror_small.draco.glb",
    ] {
        let o = run(&["validate", "--strict", "--format", "json", s(&real(name))]);
        assert_eq!(o.status.code(), Some(0), "{name}: {}", String::from_utf8_lossy(&o.stdout));
    }
}

/// `input` with every stored tangent turned by `turn_deg` about its normal and `w` multiplied by
/// `flip`, written to `out`.
fn spoil_tangents(input: &Path, out: &Path, turn_deg: f32, flip: f32) {
    let mut scene = load(input);
    for r in scene.primitives() {
        let mut p = scene.primitive(r).unwrap();
        let (Some(n), Some(t)) = (p.attr("NORMAL"), p.attr("TANGENT")) else { continue };
        let n = unit_normals(n).into_owned();
        let changed: Vec<[f32; 4]> = t
            .to_f32::<4>()
            .iter()
            .zip(&n)
            .map(|(t, n)| {
                let q = glam::Quat::from_axis_angle(glam::Vec3::from(*n), turn_deg.to_radians());
                let v = q * glam::Vec3::new(t[0], t[1], t[2]).normalize();
                [v.x, v.y, v.z, t[3] * flip]
            })
            .collect();
        p.set_attr("TANGENT", bumpbake::scene::Stream::from_f32("VEC4", &changed));
        scene.set_primitive(r, &p);
    }
    let (files, _) = bumpbake::format::write(&scene, out, &Default::default()).unwrap();
    files.commit().unwrap();
}

/// Validating a spoilt copy of `input` fails with `code`.
fn assert_spoilt_frames_fail(input: &Path, d: &Path) {
    let stem = input.file_stem().unwrap().to_str().unwrap();
    for (name, turn, flip, code) in
        [("rotated", 20f32, 1.0, "TANGENT_MIKK_ANGLE"), ("flipped", 0.0, -1.0, "TANGENT_W_MISMATCH_UV")]
    {
        let f = d.join(format!("{stem}.{name}.glb"));
        spoil_tangents(input, &f, turn, flip);
        let o = run(&["validate", "--format", "json", s(&f)]);
        let out = String::from_utf8_lossy(&o.stdout);
        assert_eq!(o.status.code(), Some(1), "{stem} {name}: {out}");
        assert!(out.contains(code), "{stem} {name}: {code} expected in {out}");
    }
}

#[test]
fn a_rotated_or_flipped_frame_in_a_quantized_file_is_still_an_error() {
    // Quantization explains well under a degree on most triangles of this mesh, and no sign.
    assert_spoilt_frames_fail(&real("mirror_small.gltfpack.glb"), &scratch_dir("real_rotated"));
}

/// A Draco file, decoded on reading: `tangents --overwrite` writes it uncompressed with the
/// MikkTSpace frames of the decoded geometry, `preview` draws it, `validate` checks its frames and
/// reads its normal map. Returns the validate report.
fn assert_draco_decoded(input: &Path, out_dir: &Path, scratch: &Path) -> serde_json::Value {
    let stem = input.file_stem().unwrap().to_str().unwrap();
    let out = out_dir.join(format!("{stem}.decoded.glb"));
    let o = run_ok(&["tangents", s(input), "-o", s(&out), "--overwrite", "--json"]);
    record_input(&out, input, &[]);
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["generated"], 1, "{stem}: {report}");
    assert!(report["notes"].to_string().contains("KHR_draco_mesh_compression: decoded"), "{stem}: {report}");
    assert!(assert_mikktspace(&out) > 500, "{stem}: most corners compared");
    let json = load(&out).json;
    assert!(!json.to_string().contains("KHR_draco_mesh_compression"), "{stem}: written uncompressed");
    let png = scratch.join(format!("{stem}.png"));
    run_ok(&["preview", s(input), "-o", s(&png)]);
    assert!(image::open(&png).unwrap().width() > 0);
    let o = run(&["validate", "--format", "json", s(input)]);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{stem}: {}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let subjects = v["files"][0]["subjects"].as_array().unwrap();
    let checked =
        |kind: &str| subjects.iter().any(|x| x["kind"] == kind && !x["checks"].as_array().unwrap().is_empty());
    assert!(checked("primitive") && checked("image"), "{stem}: frames and map checked: {v}");
    assert!(!v.to_string().contains("PRIMITIVE_NOT_CHECKED\""), "{stem}: {v}");
    v
}

#[test]
fn draco_files_are_decoded_for_every_command() {
    let input = real("mirror_small.draco.glb");
    assert_draco_decoded(&input, &validated_dir("real_draco"), &scratch_dir("real_draco"));
    // Without --overwrite the decoded tangents are kept, and the file still leaves uncompressed.
    let d = validated_dir("real_draco_kept");
    let out = d.join("kept.gltf");
    run_ok(&["tangents", s(&input), "-o", s(&out)]);
    record_input(&out, &input, &[]);
    assert!(!load(&out).json.to_string().contains("KHR_draco_mesh_compression"));
    let d = scratch_dir("real_draco_bake");
    run_ok(&["bake", s(&input), "-o", s(&d.join("b.glb"))]);
    run_ok(&["inspect", s(&input)]);
}

/// The files `.ci/corpus.sh` made, or `None` (with a note) outside CI when there are none.
fn corpus() -> Option<Vec<PathBuf>> {
    let ci = std::env::var("CI").map(|v| v == "true").unwrap_or(false);
    let Some(dir) = std::env::var_os("BUMPBAKE_CORPUS") else {
        assert!(!ci, "CI=true but BUMPBAKE_CORPUS is not set: .ci/run makes the corpus with .ci/corpus.sh");
        eprintln!("BUMPBAKE_CORPUS is not set: the corpus test has nothing to run (bash .ci/corpus.sh DIR)");
        return None;
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("BUMPBAKE_CORPUS={}: {e}", PathBuf::from(&dir).display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "glb" || e == "gltf"))
        .collect();
    files.sort();
    assert!(files.len() >= 14, "the corpus has {} files; .ci/corpus.sh makes 14", files.len());
    Some(files)
}

#[test]
fn every_command_on_every_corpus_file_succeeds_or_says_why() {
    let Some(files) = corpus() else { return };
    let d = validated_dir("corpus");
    let scratch = scratch_dir("corpus");
    for f in &files {
        let stem = f.file_stem().unwrap().to_str().unwrap();
        let draco = stem.contains("draco");
        for (tag, extra) in [("kept", None), ("overwrite", Some("--overwrite"))] {
            let out = d.join(format!("{stem}.tangents-{tag}.glb"));
            let mut args = vec!["tangents", s(f), "-o", s(&out), "-q"];
            args.extend(extra);
            let o = run(&args);
            assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
            // CI holds the output to its input's Khronos issues (.ci/validate-gltf.js).
            record_input(&out, f, &[]);
            if extra.is_some() {
                assert!(assert_mikktspace(&out) > 0, "{stem}");
            }
        }
        let out = d.join(format!("{stem}.bake.glb"));
        let o = run(&["bake", s(f), "-o", s(&out), "-q"]);
        match o.status.code() {
            Some(0) => record_input(&out, f, &[]),
            // Images another helper's decoder may not read yet: a plain refusal naming the format.
            _ => assert_plain_refusal(&o, f, ""),
        }
        let png = scratch.join(format!("{stem}.png"));
        let o = run(&["preview", s(f), "-o", s(&png)]);
        match o.status.code() {
            Some(0) => assert!(png.exists()),
            _ => assert_plain_refusal(&o, f, ""),
        }
        let o = run(&["validate", "--format", "json", s(f)]);
        assert!(matches!(o.status.code(), Some(0 | 1)), "{stem}: {}", String::from_utf8_lossy(&o.stderr));
        serde_json::from_slice::<serde_json::Value>(&o.stdout).unwrap();
        if draco {
            assert_draco_decoded(f, &d, &scratch);
        }
        run_ok(&["inspect", s(f)]);
        // A correct map after glTF-Transform's JPEG or WebP coding passes strictly (issue 22);
        // mirror_small's 8x8 normal map is flat (NORMALMAP_FLAT), so only the full-size one.
        if stem.starts_with("NormalTangentMirrorTest") && (stem.ends_with(".jpeg") || stem.ends_with(".webp")) {
            let o = run(&["validate", "--strict", s(f)]);
            assert_eq!(o.status.code(), Some(0), "{stem}: {}", String::from_utf8_lossy(&o.stderr));
        }
        // Quantized authored frames pass strictly (Draco's like its meshopt twin's); turned or
        // flipped ones still fail.
        if ["quantize", "gltfpack", "meshopt", "draco"].iter().any(|k| stem.contains(k)) {
            let o = run(&["validate", "--strict", s(f)]);
            assert_eq!(o.status.code(), Some(0), "{stem}: {}", String::from_utf8_lossy(&o.stderr));
            assert_spoilt_frames_fail(f, &scratch);
        }
    }
}

#[test]
fn preview_draws_quantized_files_as_their_float_original() {
    // gltfpack's UVs only land on the textures through the KHR_texture_transform it adds; the
    // quantized file must render like the float one it was made from.
    let d = scratch_dir("real_preview");
    let render = |name: &str| {
        let out = d.join(format!("{name}.png"));
        run_ok(&["preview", s(&real(name)), "-o", s(&out), "--size", "128x128"]);
        image::open(&out).unwrap().to_rgb8()
    };
    let float = render("mirror_small.glb");
    for name in ["mirror_small.gltfpack.glb", "mirror_small.quantize.glb", "mirror_small.gltfpack-c.glb"] {
        let q = render(name);
        let diff: u64 = float.as_raw().iter().zip(q.as_raw()).map(|(a, b)| a.abs_diff(*b) as u64).sum();
        let mean = diff as f64 / float.as_raw().len() as f64;
        assert!(mean < 2.0, "{name}: mean difference {mean:.2} of 255 from the float original");
    }
}

#[test]
fn position_accessors_leave_with_bounds_even_when_the_input_had_none() {
    let mut g = Gltf::new();
    let p = g.floats(&[[0.0, 0.0, 0.0], [2.0, 0.0, -1.0], [0.0, 3.0, 0.5]], Some(34962));
    let n = g.floats(&[[0.0, 0.0, 1.0]; 3], Some(34962));
    g.mesh(serde_json::json!({ "attributes": { "POSITION": p, "NORMAL": n } }));
    for key in ["min", "max"] {
        g.json["accessors"][p].as_object_mut().unwrap().remove(key);
    }
    let input = scratch_dir("real_bounds").join("no_bounds.glb");
    g.write_glb(&input);
    assert!(load(&input).json["accessors"][p].get("min").is_none());
    let out = validated_dir("real_bounds").join("bounds.glb");
    run_ok(&["tangents", s(&input), "-o", s(&out), "-q"]);
    let acc = &load(&out).json["accessors"][0];
    assert_eq!(acc["min"], serde_json::json!([0.0, 0.0, -1.0]));
    assert_eq!(acc["max"], serde_json::json!([2.0, 3.0, 0.5]));
}

#[test]
fn a_rotated_texture_transform_turns_the_tangent_with_it() {
    // A flat quad with u along +x and v along +y. The normal texture turns its UVs by 90°
    // (u' = v, v' = -u), so the map's +x runs along +y on the surface: that is the tangent.
    for (rotation, expected) in [(0.0, [1.0, 0.0, 0.0]), (std::f64::consts::FRAC_PI_2, [0.0, 1.0, 0.0])] {
        let mut g = Gltf::new();
        let p = g.floats(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]], Some(34962));
        let n = g.floats(&[[0.0, 0.0, 1.0]; 4], Some(34962));
        let t = g.floats(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], Some(34962));
        let i = g.indices(&[0, 1, 2, 0, 2, 3]);
        let tex = g.texture();
        let m = g.material(serde_json::json!({
            "normalTexture": { "index": tex, "extensions": { "KHR_texture_transform": { "rotation": rotation } } }
        }));
        g.json["extensionsUsed"] = serde_json::json!(["KHR_texture_transform"]);
        g.mesh(serde_json::json!({ "attributes": { "POSITION": p, "NORMAL": n, "TEXCOORD_0": t }, "indices": i, "material": m }));
        let input = scratch_dir("real_rotated_uv").join("quad.glb");
        g.write_glb(&input);
        let out = validated_dir(&format!("real_rotated_uv_{}", rotation != 0.0)).join("quad.glb");
        run_ok(&["tangents", s(&input), "-o", s(&out), "-q"]);
        for tan in corner_attr::<4>(&load(&out), P0, "TANGENT") {
            let d: f32 = (0..3).map(|k| tan[k] * expected[k]).sum();
            assert!(d > 0.9999, "rotation {rotation}: tangent {tan:?}, expected {expected:?}");
            assert_eq!(tan[3], -1.0);
        }
    }
}

#[test]
fn valid_quantized_tangents_are_kept_as_they_are() {
    let d = validated_dir("real_kept");
    for name in ["mirror_small.gltfpack.glb", "mirror_small.quantize.glb"] {
        let out = d.join(name);
        let o = run_ok(&["tangents", s(&real(name)), "-o", s(&out), "--json"]);
        let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(report["kept"], 1, "{name}: {report}");
        let (a, b) = (load(&real(name)), load(&out));
        let tangent = |sc: &bumpbake::scene::Scene| sc.primitive(P0).unwrap().attr("TANGENT").unwrap().clone();
        let (ta, tb) = (tangent(&a), tangent(&b));
        assert_eq!(
            (ta.format, ta.data),
            (tb.format, tb.data),
            "{name}: the authored quantized tangents, byte for byte"
        );
    }
}

/// The JSON and binary chunks of a GLB.
fn glb_chunks(bytes: &[u8]) -> (serde_json::Value, Vec<u8>) {
    let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().unwrap()) as usize;
    let json_len = u32_at(12);
    let json = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let at = 20 + json_len;
    let bin = if at + 8 <= bytes.len() { bytes[at + 8..at + 8 + u32_at(at)].to_vec() } else { Vec::new() };
    (json, bin)
}

/// `v` with every number as a float: two documents that differ only in how they spell whole
/// numbers compare equal.
fn numbers_as_floats(v: &serde_json::Value) -> serde_json::Value {
    use serde_json::Value;
    match v {
        Value::Number(n) => Value::from(n.as_f64().unwrap()),
        Value::Array(a) => Value::Array(a.iter().map(numbers_as_floats).collect()),
        Value::Object(o) => Value::Object(o.iter().map(|(k, x)| (k.clone(), numbers_as_floats(x))).collect()),
        other => other.clone(),
    }
}

fn integers_written_as_fractions(v: &mut serde_json::Value) {
    use serde_json::Value;
    match v {
        Value::Number(n) if n.is_u64() => *v = Value::from(n.as_u64().unwrap() as f64),
        Value::Array(a) => a.iter_mut().for_each(integers_written_as_fractions),
        Value::Object(o) => o.values_mut().for_each(integers_written_as_fractions),
        _ => {}
    }
}

/// JSON has one number type: `1.0` is the integer 1 wherever glTF wants an integer (the Khronos
/// validator reads it so). Every command reads a file whose integers are all written `N.0` as
/// it reads the same file written with integers, writes the same outputs, and writes the
/// integers it re-emits as integers.
#[test]
fn integers_written_with_a_zero_fraction_read_as_integers_in_every_command() {
    let d = scratch_dir("real_whole_fractions");
    let (json, data) = glb_chunks(&std::fs::read(real("mirror_small.glb")).unwrap());
    let mut fractions = json.clone();
    integers_written_as_fractions(&mut fractions);
    let text = serde_json::to_string(&fractions).unwrap();
    assert!(text.contains("\"count\":310.0") && text.contains("\"componentType\":5126.0"), "{text}");
    let mut outputs = Vec::new();
    for (name, doc) in [("integers", &json), ("fractions", &fractions)] {
        let dir = d.join(name);
        std::fs::create_dir_all(&dir).unwrap();
        let mut j = serde_json::to_vec(doc).unwrap();
        j.resize(j.len().next_multiple_of(4), b' ');
        std::fs::write(dir.join("in.glb"), glb_bytes(&j, &data)).unwrap();
        let commands: &[&[&str]] = &[
            &["tangents", "in.glb", "-o", "tangents.glb", "--overwrite", "-q"],
            &["bake", "in.glb", "-o", "bake.glb", "-q"],
            &["bake", "in.glb", "--from", "in.glb", "--size", "32", "-o", "from.glb", "-q"],
            &["textures", "in.glb", "-o", "textures.glb", "-q"],
            &["preview", "in.glb", "-o", "preview.png", "--size", "48x32", "-q"],
            &["validate", "--format", "json", "in.glb"],
            &["inspect", "--json", "in.glb"],
        ];
        let mut seen = Vec::new();
        for args in commands {
            let o = bin().args(*args).current_dir(&dir).output().unwrap();
            let err = String::from_utf8_lossy(&o.stderr);
            assert!(matches!(o.status.code(), Some(0 | 1)) && !err.contains("whole number"), "{name} {args:?}: {err}");
            seen.push((args.join(" "), o.status.code(), o.stdout));
        }
        for f in ["tangents.glb", "bake.glb", "from.glb", "textures.glb"] {
            let (j, b) = glb_chunks(&std::fs::read(dir.join(f)).unwrap());
            // What the writer re-emits is an integer, however the input spelt it.
            for a in j["accessors"].as_array().unwrap() {
                assert!(a["count"].is_u64() && a["componentType"].is_u64(), "{name} {f}: {a}");
            }
            seen.push((f.to_string(), None, serde_json::to_vec(&numbers_as_floats(&j)).unwrap()));
            seen.push((format!("{f} bin"), None, b));
        }
        seen.push(("preview.png".into(), None, std::fs::read(dir.join("preview.png")).unwrap()));
        outputs.push(seen);
    }
    for (a, b) in outputs[0].iter().zip(&outputs[1]) {
        assert!(a == b, "{}: differs between integers and fractions", a.0);
    }
}
