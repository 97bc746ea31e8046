//! Outputs never less valid than their inputs (issue 22), and an embedding output holds every
//! image it references (issue 41): a core texture that points at a KTX2 image without
//! KHR_texture_basisu (engines accept it; the Khronos validator warns IMAGE_UNRECOGNIZED_FORMAT)
//! is named through KHR_texture_basisu in a GLB or an embedded .gltf, its image inside with
//! `image/ktx2`, and stays a file beside a .gltf that keeps its images outside. Either way the
//! output gets no error its input did not have (no TEXTURE_INVALID_IMAGE_MIME_TYPE). CI's
//! `.ci/validate-gltf.js` compares each output's Khronos codes with its input's (recorded by
//! `record_input`).

mod common;
use common::*;
use std::path::Path;

const BASISU: &str = "KHR_texture_basisu";

/// A material's texture (JSON pointer into it) and the `ktx2_core` file it names.
type Named<'a> = &'a [(&'a str, &'a str)];

/// Checks that `out` holds every image inside, each texture naming its KTX2 through
/// KHR_texture_basisu (used and required, no core source), and that the KTX2 files of
/// `ktx2_core/quad.gltf` named in `kept` (material texture -> file) are inside byte for byte.
fn assert_ktx2_inside(out: &Path, what: &str, kept: Named) {
    let scene = load(out);
    let j = &scene.json;
    for key in ["extensionsUsed", "extensionsRequired"] {
        assert!(j[key].as_array().unwrap().iter().any(|e| e == BASISU), "{what}: {key}: {j}");
    }
    for t in j["textures"].as_array().unwrap() {
        assert!(t.get("source").is_none(), "{what}: no core source: {t}");
        let i = t["extensions"][BASISU]["source"].as_u64().unwrap_or_else(|| panic!("{what}: {t}")) as usize;
        let img = &j["images"][i];
        match img["uri"].as_str() {
            Some(u) => assert!(u.starts_with("data:image/ktx2;base64,"), "{what}: {img}"),
            None => assert!(img["mimeType"] == "image/ktx2" && img["bufferView"].is_u64(), "{what}: {img}"),
        }
    }
    for (pointer, f) in kept {
        let t = j["materials"][0].pointer(pointer).unwrap()["index"].as_u64().unwrap() as usize;
        let i = j["textures"][t]["extensions"][BASISU]["source"].as_u64().unwrap() as usize;
        let bytes = scene.image_bytes(i).unwrap();
        assert_eq!(bytes, std::fs::read(fixture(&format!("ktx2_core/{f}"))).unwrap(), "{what}: {f}");
    }
}

#[test]
fn a_core_ktx2_texture_goes_inside_an_embedding_output_through_khr_texture_basisu() {
    let input = fixture("ktx2_core/quad.gltf");
    let d = validated_dir("ktx2_core");
    let both: &[(&str, &str)] =
        &[("/pbrMetallicRoughness/baseColorTexture", "color.ktx2"), ("/normalTexture", "normal.ktx2")];
    // `textures` makes the normal map a KTX2 of its own; the colour one it carries.
    let colour = &both[..1];
    let commands: &[(&str, &[&str], Named)] = &[
        ("quad.glb", &["tangents"], both),
        ("embedded.gltf", &["tangents", "--embed"], both),
        ("bake.glb", &["bake"], both),
        ("textures.glb", &["textures"], colour),
    ];
    for (name, cmd, kept) in commands {
        let sub = d.join(name.replace('.', "_"));
        std::fs::create_dir_all(&sub).unwrap();
        let out = sub.join(name);
        let mut args = cmd.to_vec();
        args.extend([s(&input), "-o", s(&out), "-q"]);
        run_ok(&args);
        // The pinned Khronos validator does not know KHR_texture_basisu (tests/textures.rs).
        let why = "image/ktx2 is KHR_texture_basisu's mimeType; the core list has only PNG and JPEG";
        record_input(&out, &input, &[("VALUE_NOT_IN_LIST", why)]);
        assert_ktx2_inside(&out, &format!("{cmd:?}"), kept);
        // One file: nothing copied beside it.
        let beside: Vec<_> = std::fs::read_dir(&sub).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert!(beside.iter().all(|f| !f.to_string_lossy().ends_with(".ktx2")), "{cmd:?}: {beside:?}");
        if cmd[0] == "tangents" {
            assert!(load(&out).primitive(P0).unwrap().attr("TANGENT").is_some(), "{name}");
        }
    }
}

#[test]
fn a_core_ktx2_texture_stays_a_file_beside_a_gltf_that_keeps_images_outside() {
    let input = fixture("ktx2_core/quad.gltf");
    let d = validated_dir("ktx2_core_outside");
    let out = d.join("quad.gltf");
    run_ok(&["tangents", s(&input), "-o", s(&out), "-q"]);
    record_input(&out, &input, &[]);
    let scene = load(&out);
    let images = scene.json["images"].as_array().unwrap();
    let uris: Vec<&str> = images.iter().map(|i| i["uri"].as_str().unwrap_or("")).collect();
    assert_eq!(uris, ["color.ktx2", "normal.ktx2"], "{images:?}");
    assert!(images.iter().all(|i| i.get("mimeType").is_none() && i.get("bufferView").is_none()));
    assert!(scene.json.get("extensionsUsed").is_none(), "the input's naming is kept: {}", scene.json);
    for f in ["color.ktx2", "normal.ktx2"] {
        assert_eq!(std::fs::read(d.join(f)).unwrap(), std::fs::read(fixture(&format!("ktx2_core/{f}"))).unwrap());
    }
}

/// PNG and JPEG images of core textures still go inside a GLB (the writer's usual way).
#[test]
fn png_textures_are_still_embedded_in_a_glb() {
    let d = validated_dir("ktx2_core_png");
    let out = d.join("mirror.glb");
    run_ok(&["tangents", s(&fixture("khronos/NormalTangentMirrorTest.glb")), "-o", s(&out), "-q"]);
    let scene = load(&out);
    let images = scene.json["images"].as_array().unwrap();
    assert!(images.iter().all(|i| i["mimeType"] == "image/png" && i.get("bufferView").is_some()));
}
