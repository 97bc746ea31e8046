//! Outputs never less valid than their inputs (issue 22): a core texture that points at a KTX2
//! image without KHR_texture_basisu (engines accept it; the Khronos validator warns
//! IMAGE_UNRECOGNIZED_FORMAT) stays stored the way the input stored it, so the output gets no
//! TEXTURE_INVALID_IMAGE_MIME_TYPE error the input did not have. CI's `.ci/validate-gltf.js`
//! compares each output's Khronos codes with its input's (recorded by `record_input`).

mod common;
use common::*;

#[test]
fn a_core_ktx2_texture_stays_a_file_beside_every_kind_of_output() {
    let input = fixture("ktx2_core/quad.gltf");
    let d = validated_dir("ktx2_core");
    for (name, extra) in [("quad.glb", None), ("quad.gltf", None), ("embedded.gltf", Some("--embed"))] {
        let out = d.join(name);
        let mut args = vec!["tangents", s(&input), "-o", s(&out), "-q"];
        args.extend(extra);
        run_ok(&args);
        record_input(&out, &input, &[]);
        let scene = load(&out);
        let images = scene.json["images"].as_array().unwrap();
        let uris: Vec<&str> = images.iter().map(|i| i["uri"].as_str().unwrap_or("")).collect();
        assert_eq!(uris, ["color.ktx2", "normal.ktx2"], "{name}: {images:?}");
        assert!(images.iter().all(|i| i.get("mimeType").is_none() && i.get("bufferView").is_none()), "{name}");
        for f in ["color.ktx2", "normal.ktx2"] {
            assert_eq!(std::fs::read(d.join(f)).unwrap(), std::fs::read(fixture(&format!("ktx2_core/{f}"))).unwrap());
        }
        assert!(scene.primitive(P0).unwrap().attr("TANGENT").is_some(), "{name}");
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
