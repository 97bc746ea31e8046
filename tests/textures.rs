//! Textures that ship as KTX2: `bake --textures ktx2` and `bumpbake textures`. Outputs are read
//! back with bumpbake's own KTX2 reader, level by level, and held to the mip chain and the
//! widened roughness worked out from the PNG output of the same bake.

mod common;
use bumpbake::format::image::ktx2::decode_levels_within;
use bumpbake::format::image::Limits;
use bumpbake::normalmap::mips;
use bumpbake::normalmap::specular_aa::{roughness_levels, DEFAULT_THRESHOLD};
use bumpbake::scene::Scene;
use common::*;
use serde_json::{json, Value};
use std::path::Path;

const BASISU: &str = "KHR_texture_basisu";

fn torus() -> std::path::PathBuf {
    fixture("bake/torus.obj")
}

/// The pinned Khronos glTF-Validator (2.0.0-dev.3.10) does not know KHR_texture_basisu: it holds
/// `image/ktx2` to the core mimeType list and cannot read KTX2 bytes. `reference` is the same
/// asset before shipping (the input, or the PNG bake), which the output must be no less valid than.
fn record(out: &Path, reference: &Path) {
    record_input(
        out,
        reference,
        &[
            ("VALUE_NOT_IN_LIST", "image/ktx2 is KHR_texture_basisu's mimeType; the core list has only PNG and JPEG"),
            ("IMAGE_UNRECOGNIZED_FORMAT", "the validator does not read KTX2 (KHR_texture_basisu)"),
        ],
    );
}

fn report(out: &std::process::Output) -> Value {
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The image a texture shows through KHR_texture_basisu, decoded level by level (RGB8).
fn ktx2_levels(scene: &Scene, texture: u64) -> Vec<image::RgbImage> {
    let i = scene.json["textures"][texture as usize]["extensions"][BASISU]["source"].as_u64().expect("a KTX2 source");
    assert_eq!(scene.json["images"][i as usize]["mimeType"], "image/ktx2");
    let bytes = scene.image_bytes(i as usize).unwrap();
    decode_levels_within(&bytes, &Limits::TEXTURE).unwrap().iter().map(|l| l.to_rgb8()).collect()
}

fn used(scene: &Scene, key: &str) -> Vec<String> {
    scene.json[key].as_array().into_iter().flatten().map(|e| e.as_str().unwrap().to_string()).collect()
}

fn deg(a: [f32; 3], b: [f32; 3]) -> f64 {
    ((a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) as f64).clamp(-1.0, 1.0).acos().to_degrees()
}

/// The same bake as PNG and as KTX2: every level decodes, with the full chain's sizes, close to
/// the average of the PNG's full-resolution normals; the roughness texture holds the widened
/// levels; roughnessFactor moved into it.
#[test]
fn bake_ktx2_holds_the_chain_and_the_widened_roughness() {
    let d = validated_dir("textures_bake");
    let (png_out, ktx_out) = (d.join("torus_png.glb"), d.join("torus_ktx2.glb"));
    run_ok(&["bake", s(&torus()), "-o", s(&png_out)]);
    let o = run_ok(&["bake", s(&torus()), "-o", s(&ktx_out), "--textures", "ktx2", "--json"]);
    record(&ktx_out, &png_out);
    let rep = report(&o);
    assert_eq!(rep["textures"]["normal_maps"], 1, "{rep:#}");
    let (png, ktx) = (load(&png_out), load(&ktx_out));

    // The normal map: the PNG's chain, through the codec.
    let tex = ktx.json["materials"][0]["normalTexture"]["index"].as_u64().unwrap();
    assert!(ktx.json["textures"][tex as usize].get("source").is_none(), "no fallback without --ktx2-fallback");
    assert!(used(&ktx, "extensionsUsed").contains(&BASISU.to_string()));
    assert!(used(&ktx, "extensionsRequired").contains(&BASISU.to_string()));
    let png_img = png.json["textures"][png.json["materials"][0]["normalTexture"]["index"].as_u64().unwrap() as usize]
        ["source"]
        .as_u64()
        .unwrap();
    let base = image::load_from_memory(&png.image_bytes(png_img as usize).unwrap()).unwrap().to_rgb8();
    let (w, h) = (base.width() as usize, base.height() as usize);
    let chain = mips::build_rgb(base.as_raw(), w, h);
    let levels = ktx2_levels(&ktx, tex);
    assert_eq!(levels.len(), mips::level_count(w, h));
    for (k, (got, want)) in levels.iter().zip(&chain).enumerate() {
        assert_eq!((got.width() as usize, got.height() as usize), (want.width, want.height), "level {k}");
        let n = mips::unit_normals(got.as_raw());
        let mean = n.iter().zip(&want.ideal).map(|(a, b)| deg(*a, *b)).sum::<f64>() / n.len() as f64;
        // UASTC level 2 on bumps.png: 0.4-2.3° per level (docs/normalmap.md).
        assert!(mean < 4.0, "level {k}: mean {mean:.2}° from the averaged full-resolution normals");
        let reported = rep["textures"]["materials"][0]["levels"][k]["mean_deg"].as_f64().unwrap();
        assert!((reported - mean).abs() < 0.01, "level {k}: reported {reported:.3}°, measured here {mean:.3}°");
    }
    assert_eq!(rep["textures"]["materials"][0]["levels"].as_array().unwrap().len(), levels.len());

    // The roughness: roughnessFactor x 1 at level 0, widened above, within rounding and UASTC's error.
    let old = png.pbr_factors(0);
    let now = ktx.pbr_factors(0);
    assert_eq!((now.roughness, now.metallic), (1.0, old.metallic));
    let mr = ktx.json["materials"][0]["pbrMetallicRoughness"]["metallicRoughnessTexture"]["index"].as_u64().unwrap();
    let want = roughness_levels(&chain, &vec![old.roughness; w * h], DEFAULT_THRESHOLD);
    let got = ktx2_levels(&ktx, mr);
    assert_eq!(got.len(), want.len());
    let mut widened = false;
    for (k, (g, wl)) in got.iter().zip(&want).enumerate() {
        let d: Vec<f32> = g.pixels().zip(&wl.roughness).map(|(p, r)| (p[1] as f32 / 255.0 - r).abs()).collect();
        let mean = d.iter().sum::<f32>() / d.len() as f32;
        let max = d.iter().copied().fold(0.0f32, f32::max);
        // Rounding to 8 bits and the codec (UASTC pack level 0 for a chain of factors alone).
        assert!(
            mean < 1.0 / 255.0 && max < 2.0 / 255.0,
            "level {k}: roughness off by {mean} on average, {max} at most"
        );
        assert!(g.pixels().all(|p| p[2] == 255), "level {k}: metalness kept (factors only: B = 255)");
        widened |= wl.roughness.iter().any(|&r| r > old.roughness + 0.02);
    }
    assert!(widened, "the bumps widen some level's roughness");
    let added = rep["textures"]["materials"][0]["roughness"]["added"].as_array().unwrap();
    assert_eq!(added.len(), want.len());
    assert!(added[0]["max"].as_f64().unwrap() < 1e-4, "level 0 is the material as it was: {added:?}");
}

/// `--ktx2-fallback` keeps the PNGs as `source`: the extension is used, not required, and the
/// roughness fallback renders level 0 as before (roughnessFactor x G within 1/255).
#[test]
fn fallback_keeps_the_pngs_and_does_not_require_the_extension() {
    let d = validated_dir("textures_fallback");
    let out = d.join("torus.gltf");
    run_ok(&["bake", s(&torus()), "-o", s(&out), "--textures", "ktx2", "--ktx2-fallback", "--images", "external"]);
    let scene = load(&out);
    assert!(used(&scene, "extensionsUsed").contains(&BASISU.to_string()));
    assert!(!used(&scene, "extensionsRequired").contains(&BASISU.to_string()));
    let m = &scene.json["materials"][0];
    let normal = &scene.json["textures"][m["normalTexture"]["index"].as_u64().unwrap() as usize];
    let mr = &scene.json["textures"]
        [m["pbrMetallicRoughness"]["metallicRoughnessTexture"]["index"].as_u64().unwrap() as usize];
    for t in [normal, mr] {
        let src = t["source"].as_u64().expect("a core fallback") as usize;
        assert_eq!(scene.json["images"][src]["mimeType"], "image/png", "{t}");
        assert!(t["extensions"][BASISU]["source"].is_u64());
    }
    let png = d.join("torus_png.glb");
    run_ok(&["bake", s(&torus()), "-o", s(&png)]);
    record(&out, &png);
    let old = load(&png).pbr_factors(0).roughness;
    let src = mr["source"].as_u64().unwrap() as usize;
    let level0 = image::load_from_memory(&scene.image_bytes(src).unwrap()).unwrap().to_rgb8();
    assert!(level0.pixels().all(|p| (p[1] as f32 / 255.0 - old).abs() <= 1.0 / 255.0), "level 0 renders as before");
    // The KTX2 files sit beside the .gltf.
    assert!(std::fs::read_dir(&d).unwrap().any(|e| e.unwrap().path().extension().is_some_and(|x| x == "ktx2")));
}

/// The default is PNG, byte for byte what `--textures png` writes.
#[test]
fn png_is_the_default_byte_for_byte() {
    let d = scratch_dir("textures_default");
    let (a, b) = (d.join("a.glb"), d.join("b.glb"));
    run_ok(&["bake", s(&torus()), "-o", s(&a)]);
    run_ok(&["bake", s(&torus()), "-o", s(&b), "--textures", "png"]);
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let o = run_ok(&["bake", s(&torus()), "-o", s(&b), "--json"]);
    assert!(report(&o).get("textures").is_none(), "no textures record without --textures ktx2");
}

/// The same bytes whatever the thread count.
#[test]
fn ktx2_output_is_deterministic() {
    let d = scratch_dir("textures_threads");
    let mut outs = Vec::new();
    for threads in ["1", "2"] {
        let out = d.join(format!("t{threads}.glb"));
        let o = bin()
            .env("RAYON_NUM_THREADS", threads)
            .args(["bake", s(&torus()), "-o", s(&out), "--textures", "ktx2", "-q"])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        outs.push(std::fs::read(out).unwrap());
    }
    assert!(outs[0] == outs[1], "thread count changed the bytes");
}

fn image_of(scene: &Scene, texture: &Value) -> Vec<u8> {
    scene.image_bytes(texture["source"].as_u64().unwrap() as usize).unwrap()
}

/// On a file another tool wrote (an ORM texture shared by metallicRoughness and occlusion): the
/// normal map becomes KTX2, the base colour and the occlusion texture keep their bytes, and the
/// material gets its own roughness texture; with --no-specular-aa the ORM stays its
/// metallicRoughness too.
#[test]
fn textures_leaves_every_other_texture_as_it_was() {
    let d = validated_dir("textures_command");
    let input = fixture("real/mirror_small.glb");
    let before = load(&input);
    let tex = |s: &Scene, p: &str| {
        s.json["textures"][s.json["materials"][0].pointer(p).unwrap().as_u64().unwrap() as usize].clone()
    };
    let (base, occl, mr) = (
        "/pbrMetallicRoughness/baseColorTexture/index",
        "/occlusionTexture/index",
        "/pbrMetallicRoughness/metallicRoughnessTexture/index",
    );
    for (name, extra) in [("aa", &[][..]), ("no_aa", &["--no-specular-aa"][..])] {
        let out = d.join(format!("mirror_{name}.glb"));
        let mut args = vec!["textures", s(&input), "-o", s(&out), "--json"];
        args.extend_from_slice(extra);
        let rep = report(&run_ok(&args));
        record(&out, &input);
        let after = load(&out);
        assert_eq!(image_of(&after, &tex(&after, base)), image_of(&before, &tex(&before, base)), "{name}: base colour");
        assert_eq!(image_of(&after, &tex(&after, occl)), image_of(&before, &tex(&before, occl)), "{name}: occlusion");
        let normal = tex(&after, "/normalTexture/index");
        assert!(normal.get("source").is_none() && normal["extensions"][BASISU]["source"].is_u64(), "{name}: {normal}");
        if extra.is_empty() {
            let t = tex(&after, mr);
            assert!(t.get("source").is_none() && t["extensions"][BASISU]["source"].is_u64(), "{name}: {t}");
            assert!(rep["materials"][0]["roughness"]["from_texture"].as_bool().unwrap(), "{rep:#}");
        } else {
            assert_eq!(image_of(&after, &tex(&after, mr)), image_of(&before, &tex(&before, mr)), "{name}: ORM");
        }
        let r = run(&["validate", "--strict", s(&out)]);
        assert_eq!(r.status.code(), Some(0), "{name}: {}", String::from_utf8_lossy(&r.stderr));
    }
}

/// Files from gltfpack (texture transforms) and Blender (a WebP-only normal texture).
#[test]
fn textures_on_other_tools_files() {
    let d = validated_dir("textures_tools");
    for f in ["real/mirror_small.gltfpack.glb", "blender/sphere_webp.glb", "blender/sphere.glb"] {
        let input = fixture(f);
        let out = d.join(Path::new(f).file_name().unwrap());
        let rep = report(&run_ok(&["textures", s(&input), "-o", s(&out), "--json"]));
        record(&out, &input);
        assert_eq!(rep["status"], "ok");
        let after = load(&out);
        assert!(used(&after, "extensionsRequired").contains(&BASISU.to_string()), "{f}");
        assert!(
            !used(&after, "extensionsUsed").contains(&"EXT_texture_webp".to_string()),
            "{f}: no texture uses WebP now"
        );
        let n = after.json["materials"][0]["normalTexture"]["index"].as_u64().unwrap();
        assert!(ktx2_levels(&after, n).len() > 1, "{f}: a mip chain");
    }
}

/// A metallicRoughness texture read through another UV set than the normal texture: its texels
/// do not correspond, so that material keeps its roughness, with a note; a normal image two
/// materials share is encoded once.
#[test]
fn roughness_through_other_uvs_is_left_with_a_note() {
    let scratch = scratch_dir("textures_uvs");
    let d = validated_dir("textures_uvs");
    let mut g = Gltf::new();
    let (pos, nrm, uv, idx) = grid(1);
    let attrs = json!({
        "POSITION": g.floats(&pos, Some(34962)),
        "NORMAL": g.floats(&nrm, Some(34962)),
        "TEXCOORD_0": g.floats(&uv, Some(34962)),
        "TEXCOORD_1": g.floats(&uv, Some(34962)),
    });
    let i = g.indices(&idx);
    let bumps = image::RgbImage::from_fn(16, 16, |x, y| {
        image::Rgb(if (x / 2 + y / 2) % 2 == 0 { [180, 128, 236] } else { [76, 128, 236] })
    });
    let mut png = std::io::Cursor::new(Vec::new());
    bumps.write_to(&mut png, image::ImageFormat::Png).unwrap();
    let normal = g.png_texture(png.get_ref());
    let mr = g.texture();
    let a = g.material(json!({ "normalTexture": { "index": normal },
        "pbrMetallicRoughness": { "metallicRoughnessTexture": { "index": mr, "texCoord": 1 }, "roughnessFactor": 0.3 } }));
    let b =
        g.material(json!({ "normalTexture": { "index": normal }, "pbrMetallicRoughness": { "roughnessFactor": 0.2 } }));
    g.mesh(json!({ "attributes": attrs.clone(), "indices": i, "material": a }));
    g.mesh(json!({ "attributes": attrs, "indices": i, "material": b }));
    let input = g.write_gltf(&scratch, "in");
    let out = d.join("out.glb");
    let rep = report(&run_ok(&["textures", s(&input), "-o", s(&out), "--json"]));
    record(&out, &input);
    assert_eq!(rep["normal_maps"], 1, "one image, encoded once: {rep:#}");
    let notes = rep["notes"].as_array().unwrap();
    assert!(notes.iter().any(|n| n.as_str().unwrap().contains("TEXCOORD_1")), "{rep:#}");
    let after = load(&out);
    assert_eq!(after.pbr_factors(0).roughness, 0.3, "material 0 left as it was");
    assert_eq!(after.pbr_factors(1).roughness, 1.0, "material 1's factor moved into its texture");
    let m0 = &after.json["materials"][0]["pbrMetallicRoughness"]["metallicRoughnessTexture"];
    assert_eq!(m0["texCoord"], 1);
    assert!(after.json["textures"][m0["index"].as_u64().unwrap() as usize]["source"].is_u64());
}

/// Bad input and contradicting options: exit 2, one line, nothing written.
#[test]
fn bad_inputs_and_options_exit_2() {
    let d = scratch_dir("textures_bad");
    let junk = d.join("junk.glb");
    std::fs::write(&junk, b"glTF not really").unwrap();
    let out = d.join("out.glb");
    let bumps = fixture("bake/bumps.png");
    let png_out = d.join("n.png");
    let ktx_out = d.join("n.ktx2");
    for args in [
        vec!["textures", s(&junk), "-o", s(&out)],
        vec!["textures", s(&torus()), "-o", s(&out), "--specular-aa-threshold", "3"],
        vec!["textures", s(&torus()), "-o", s(&out), "--ktx2-quality", "9"],
        vec!["bake", s(&torus()), "-o", s(&out), "--ktx2-fallback"],
        vec!["bake", s(&torus()), "-o", s(&out), "--textures", "png", "--no-specular-aa"],
        vec!["normalmap", s(&bumps), "-o", s(&png_out), "--textures", "ktx2"],
        vec!["normalmap", s(&bumps), "-o", s(&ktx_out), "--textures", "png"],
    ] {
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: one line: {err}");
        assert!(!out.exists() && !png_out.exists() && !ktx_out.exists(), "{args:?}: nothing written");
    }
    run_ok(&["normalmap", s(&bumps), "-o", s(&ktx_out), "--textures", "ktx2"]);
    assert!(std::fs::read(&ktx_out).unwrap().starts_with(&[0xAB, b'K', b'T', b'X']));
}

/// `bake --from` ships the map it baked: the KTX2's level 0 is the PNG bake's map within UASTC's
/// error, and the chain is full (64² has 7 levels).
#[test]
fn bake_from_ships_the_baked_map() {
    let d = validated_dir("textures_bake_from");
    let low = fixture("blender_scene/plain/torus_low.glb");
    let high = fixture("blender_scene/plain/torus_high.glb");
    let (png, ktx) = (d.join("png.glb"), d.join("ktx2.glb"));
    run_ok(&["bake", s(&low), "--from", s(&high), "-o", s(&png), "--size", "64", "-q"]);
    record_input(&png, &low, &[]);
    let o =
        run_ok(&["bake", s(&low), "--from", s(&high), "-o", s(&ktx), "--size", "64", "--textures", "ktx2", "--json"]);
    record(&ktx, &png);
    assert!(report(&o).get("textures").is_some(), "a textures record");
    let (a, b) = (load(&png), load(&ktx));
    let t = b.json.pointer("/materials/0/normalTexture/index").and_then(Value::as_u64).unwrap();
    let levels = ktx2_levels(&b, t);
    assert_eq!(levels.iter().map(|l| l.width()).collect::<Vec<_>>(), [64, 32, 16, 8, 4, 2, 1]);
    let ta = a.json.pointer("/materials/0/normalTexture/index").and_then(Value::as_u64).unwrap();
    let baked =
        image::load_from_memory(&a.image_bytes(a.texture_image(ta as usize).unwrap()).unwrap()).unwrap().to_rgb8();
    let n = |p: &image::Rgb<u8>| {
        let v = p.0.map(|c| c as f32 / 127.5 - 1.0);
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        [v[0] / l, v[1] / l, v[2] / l]
    };
    let angles: Vec<f64> = baked.pixels().zip(levels[0].pixels()).map(|(p, q)| deg(n(p), n(q))).collect();
    let mean = angles.iter().sum::<f64>() / angles.len() as f64;
    assert!(mean < 3.0, "level 0 is the baked map within the codec's error: mean {mean:.2}°");
    assert!(baked.pixels().any(|p| p.0[0].abs_diff(128) > 20), "the baked map is not flat");
}

/// What the encoder would clamp without a word is refused by the library, whichever front end
/// calls it, with the setting and the value given as data and worded by the caller: the command
/// line's flags here, the Python package's keywords in `python/tests/test_files.py`.
#[test]
fn codec_settings_are_refused_by_the_library_as_data() {
    use bumpbake::error::{Neutral, Setting};
    use bumpbake::format::image::ktx2::Codec;
    use bumpbake::textures::{encode_ktx2, EncodeOptions};
    let with = |codec| EncodeOptions { codec, ..Default::default() };
    let refused = [
        (
            with(Codec::Uastc { level: 5, rdo: None }),
            Setting::Ktx2Quality,
            "5",
            "ktx2_quality=5: UASTC levels are 0 to 4",
        ),
        (with(Codec::Etc1s { quality: 0 }), Setting::Ktx2Quality, "0", "ktx2_quality=0: ETC1S quality is 1 to 255"),
        (
            with(Codec::Etc1s { quality: 256 }),
            Setting::Ktx2Quality,
            "256",
            "ktx2_quality=256: ETC1S quality is 1 to 255",
        ),
        (
            EncodeOptions { threshold: 1.5, ..Default::default() },
            Setting::SpecularAaThreshold,
            "1.5",
            "specular_aa_threshold=1.5: give a number from 0 to 1",
        ),
        (
            EncodeOptions { threshold: f32::NAN, ..Default::default() },
            Setting::SpecularAaThreshold,
            "NaN",
            "specular_aa_threshold=NaN: give a number from 0 to 1",
        ),
    ];
    let scene = bumpbake::format::read(&torus(), &Default::default()).unwrap();
    for (o, setting, value, words) in refused {
        let e = o.check().unwrap_err();
        match &e {
            bumpbake::Error::Usage { setting: s, value: v, .. } => {
                assert_eq!((*s, v.as_deref()), (Some(setting), Some(value)), "{words}")
            }
            other => panic!("{words}: {other:?}"),
        }
        assert_eq!(e.worded(&Neutral), words);
        // The library's own entry refuses it before touching the scene.
        let mut s = scene.clone();
        assert!(encode_ktx2(&mut s, &o).is_err(), "{words}");
        assert_eq!(s.json, scene.json, "{words}: the scene was changed");
    }
    for codec in (0..=4)
        .map(|level| Codec::Uastc { level, rdo: None })
        .chain([1, 128, 255].map(|quality| Codec::Etc1s { quality }))
    {
        with(codec).check().unwrap();
    }
    for lambda in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        assert!(with(Codec::Uastc { level: 2, rdo: Some(lambda) }).check().is_err(), "rdo {lambda}");
    }
    with(Codec::Uastc { level: 2, rdo: Some(1.0) }).check().unwrap();
    for threshold in [0.0, 0.2, 1.0] {
        EncodeOptions { threshold, ..Default::default() }.check().unwrap();
    }
    // On the command line, in its flags.
    let out = run(&["textures", &torus().to_string_lossy(), "-o", "/nonexistent/o.glb", "--ktx2-quality", "9"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--ktx2-quality 9: UASTC levels are 0 to 4"), "{err}");
}
