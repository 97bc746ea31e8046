//! Bad input ends with exit 2, one line naming the file and the problem, no output, no panic.

mod common;
use bumpbake::scene::PrimRef;
use common::*;
use serde_json::json;
use std::path::{Path, PathBuf};

/// Runs `tangents` on `input` and checks the failure contract; returns the message.
fn fails_cleanly(input: &Path, expect: &str) -> String {
    let dir = input.parent().unwrap().join("out");
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("o.glb");
    let o = run(&["tangents", s(input), "-o", s(&out)]);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(2), "{}: exit code; stderr: {err}", input.display());
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    assert!(err.contains(&*input.to_string_lossy()), "names the file: {err}");
    assert!(err.to_lowercase().contains(&expect.to_lowercase()), "says '{expect}': {err}");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "nothing written for {}", input.display());
    err
}

fn good_glb() -> Vec<u8> {
    std::fs::read(fixture("khronos/NormalTangentTest.glb")).unwrap()
}

fn case(name: &str) -> PathBuf {
    scratch_dir(&format!("bad_{name}"))
}

fn simple(g: &mut Gltf) {
    let (pos, nrm, uv, idx) = grid(1);
    let p = g.floats(&pos, Some(34962));
    let n = g.floats(&nrm, Some(34962));
    let t = g.floats(&uv, Some(34962));
    let i = g.indices(&idx);
    let tex = g.texture();
    let m = g.material(json!({ "normalTexture": { "index": tex } }));
    g.mesh(json!({ "attributes": { "POSITION": p, "NORMAL": n, "TEXCOORD_0": t }, "indices": i, "material": m }));
}

#[test]
fn truncated_empty_and_wrong_magic_glb() {
    let d = case("glb");
    let b = good_glb();
    let f = d.join("truncated.glb");
    std::fs::write(&f, &b[..b.len() / 2]).unwrap();
    fails_cleanly(&f, "truncated");
    let f = d.join("empty.glb");
    std::fs::write(&f, b"").unwrap();
    fails_cleanly(&f, "truncated");
    let f = d.join("magic.glb");
    let mut m = b.clone();
    m[0..4].copy_from_slice(b"gLTF");
    std::fs::write(&f, &m).unwrap();
    fails_cleanly(&f, "magic");
}

#[test]
fn broken_json_and_gltf_1() {
    let d = case("json");
    let f = d.join("broken.gltf");
    std::fs::write(&f, b"{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [").unwrap();
    fails_cleanly(&f, "invalid JSON");
    let f = d.join("v1.gltf");
    std::fs::write(&f, br#"{"asset": {"version": "1.0"}}"#).unwrap();
    fails_cleanly(&f, "version 1.0");
}

#[test]
fn index_out_of_range() {
    let d = case("index");
    let mut g = Gltf::new();
    simple(&mut g);
    // Point the last index past the four vertices.
    let n = g.bin.len();
    g.bin[n - 2..].copy_from_slice(&9u16.to_le_bytes());
    let f = d.join("index.glb");
    g.write_glb(&f);
    fails_cleanly(&f, "out of range");
}

#[test]
fn missing_buffer_file_and_escaping_uri() {
    let d = case("missing");
    let mut g = Gltf::new();
    simple(&mut g);
    let f = g.write_gltf(&d, "m");
    std::fs::remove_file(d.join("m.bin")).unwrap();
    fails_cleanly(&f, "m.bin");
    let mut g = Gltf::new();
    simple(&mut g);
    g.json["buffers"] = json!([{ "byteLength": g.bin.len(), "uri": "../secret.bin" }]);
    let f = d.join("escape.gltf");
    std::fs::write(&f, serde_json::to_vec(&g.json).unwrap()).unwrap();
    fails_cleanly(&f, "outside");
    g.json["buffers"] = json!([{ "byteLength": g.bin.len(), "uri": "data:application/octet-stream;base64,@@@" }]);
    let f = d.join("b64.gltf");
    std::fs::write(&f, serde_json::to_vec(&g.json).unwrap()).unwrap();
    fails_cleanly(&f, "base64");
}

#[test]
fn accessor_past_its_buffer() {
    let d = case("accessor");
    let mut g = Gltf::new();
    simple(&mut g);
    g.json["accessors"][0]["count"] = json!(1000);
    let f = d.join("acc.glb");
    g.write_glb(&f);
    fails_cleanly(&f, "accessor 0");
}

#[test]
fn nan_position() {
    let d = case("nan");
    let mut g = Gltf::new();
    simple(&mut g);
    g.bin[0..4].copy_from_slice(&f32::NAN.to_le_bytes());
    let f = d.join("nan.glb");
    g.write_glb(&f);
    fails_cleanly(&f, "not finite");
    let f = d.join("nan.obj");
    std::fs::write(&f, "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    fails_cleanly(&f, "non-finite");
}

#[test]
fn obj_garbage_and_out_of_range_faces() {
    let d = case("obj");
    let f = d.join("range.obj");
    std::fs::write(&f, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n").unwrap();
    fails_cleanly(&f, "OBJ");
    let f = d.join("garbage.obj");
    std::fs::write(&f, "v 0 zero 0\nf 1 2 3\n").unwrap();
    fails_cleanly(&f, "OBJ");
    let f = d.join("nomtl.obj");
    std::fs::write(&f, "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    fails_cleanly(&f, "gone.mtl");
}

#[test]
fn failed_run_in_place_leaves_the_input_untouched() {
    let d = case("inplace");
    let f = d.join("same.glb");
    let b = good_glb();
    let cut = &b[..b.len() - 100];
    std::fs::write(&f, cut).unwrap();
    let o = run(&["tangents", s(&f), "-o", s(&f)]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(std::fs::read(&f).unwrap(), cut);
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1, "no temporary left behind");
}

#[test]
fn unknown_output_extension_is_a_usage_error() {
    let d = case("ext");
    let o = run(&["tangents", s(&fixture("khronos/NormalTangentTest.glb")), "-o", s(&d.join("x.fbx"))]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains(".gltf or .glb"));
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 0);
}

/// CRC-32 (IEEE) for hand-made PNG chunks.
fn crc32(data: &[u8]) -> u32 {
    let mut c = 0xFFFF_FFFFu32;
    for &b in data {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 { 0xEDB8_8320 ^ (c >> 1) } else { c >> 1 };
        }
    }
    !c
}

/// A PNG whose header claims `w x h` RGB pixels, followed by a few bytes of pixel data.
fn png_claiming(w: u32, h: u32) -> Vec<u8> {
    let chunk = |kind: &[u8], data: &[u8]| {
        let mut c = (data.len() as u32).to_be_bytes().to_vec();
        let mut body = kind.to_vec();
        body.extend_from_slice(data);
        c.extend_from_slice(&body);
        c.extend_from_slice(&crc32(&body).to_be_bytes());
        c
    };
    let mut ihdr = w.to_be_bytes().to_vec();
    ihdr.extend_from_slice(&h.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    out.extend(chunk(b"IHDR", &ihdr));
    out.extend(chunk(b"IDAT", &[0x78, 0x9c, 0x63, 0x00, 0x00]));
    out.extend(chunk(b"IEND", &[]));
    out
}

fn truncated_png() -> Vec<u8> {
    let big = {
        let img = image::RgbImage::from_fn(64, 64, |x, y| image::Rgb([x as u8 * 4, y as u8 * 4, 255]));
        let mut c = std::io::Cursor::new(Vec::new());
        img.write_to(&mut c, image::ImageFormat::Png).unwrap();
        c.into_inner()
    };
    big[..big.len() / 2].to_vec()
}

#[test]
fn hostile_png_headers_parse_without_allocating() {
    assert_eq!(crc32(b"IEND"), 0xAE42_6082, "the CRC helper is right");
    let e = bumpbake::format::image::dimensions(&png_claiming(200_000, 200_000)).unwrap_err();
    assert!(e.to_string().contains("200000x200000"), "{e}");
    assert!(bumpbake::format::image::decode(&png_claiming(200_000, 200_000)).is_err());
    assert!(bumpbake::format::image::decode(&truncated_png()).is_err());
    assert_eq!(bumpbake::format::image::dimensions(&tiny_png()).unwrap(), (1, 1));
}

/// `tangents` carries images along byte for byte and never decodes them: a truncated PNG and
/// one claiming 200000 x 200000 pixels go through untouched, in bounded time.
#[test]
fn gltf_images_are_carried_not_decoded() {
    let d = case("images");
    for (name, bytes) in [("huge.png", png_claiming(200_000, 200_000)), ("cut.png", truncated_png())] {
        std::fs::write(d.join(name), &bytes).unwrap();
        let mut g = Gltf::new();
        simple(&mut g);
        g.json["images"][0] = json!({ "uri": name });
        let f = g.write_gltf(&d, name.trim_end_matches(".png"));
        let out = d.join("carried").join(format!("{name}.glb"));
        std::fs::create_dir_all(out.parent().unwrap()).unwrap();
        let t0 = std::time::Instant::now();
        let o = run(&["tangents", s(&f), "-o", s(&out), "-q"]);
        assert!(o.status.success(), "{name}: {}", String::from_utf8_lossy(&o.stderr));
        assert!(t0.elapsed() < std::time::Duration::from_secs(30));
        let scene = load(&out);
        let v = scene.json["images"][0]["bufferView"].as_u64().unwrap() as usize;
        let view = &scene.json["bufferViews"][v];
        let off = view["byteOffset"].as_u64().unwrap_or(0) as usize;
        let len = view["byteLength"].as_u64().unwrap() as usize;
        assert_eq!(&scene.buffers[0][off..off + len], &bytes[..], "{name} carried byte for byte");
    }
    // A missing image is an error naming it.
    let mut g = Gltf::new();
    simple(&mut g);
    g.json["images"][0] = json!({ "uri": "gone.png" });
    let f = g.write_gltf(&d, "gone");
    fails_cleanly(&f, "gone.png");
}

/// OBJ `bump` maps are decoded to tell normal maps from height maps: a header claiming 200000 x
/// 200000 pixels is refused before anything is allocated, a truncated file is reported, and the
/// mesh still gets its tangents.
#[test]
fn obj_bump_images_are_decoded_under_limits() {
    let d = case("obj_bump");
    std::fs::write(d.join("huge.png"), png_claiming(200_000, 200_000)).unwrap();
    std::fs::write(d.join("cut.png"), truncated_png()).unwrap();
    for (img, says) in [("huge.png", "200000x200000"), ("cut.png", "cut.png")] {
        let stem = img.trim_end_matches(".png");
        std::fs::write(d.join(format!("{stem}.mtl")), format!("newmtl m\nbump {img}\n")).unwrap();
        let obj = d.join(format!("{stem}.obj"));
        std::fs::write(
            &obj,
            format!("mtllib {stem}.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n"),
        )
        .unwrap();
        let out = d.join(format!("{stem}.gltf"));
        let t0 = std::time::Instant::now();
        let o = run(&["tangents", s(&obj), "-o", s(&out), "--all", "--json"]);
        assert!(o.status.success(), "{img}: {}", String::from_utf8_lossy(&o.stderr));
        assert!(t0.elapsed() < std::time::Duration::from_secs(30));
        let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let notes = report["notes"].to_string();
        assert!(notes.contains(says), "{img}: {notes}");
        assert_eq!(report["generated"], 1);
    }
}

#[test]
fn absolute_and_parent_uris_need_allow_outside() {
    let d = case("outside");
    let sub = d.join("asset");
    std::fs::create_dir_all(&sub).unwrap();
    let mut g = Gltf::new();
    simple(&mut g);
    std::fs::write(d.join("shared.bin"), &g.bin).unwrap();
    let abs = d.join("shared.bin");
    for (name, uri) in [("parent", "../shared.bin".to_string()), ("absolute", abs.to_string_lossy().into_owned())] {
        g.json["buffers"] = json!([{ "byteLength": g.bin.len(), "uri": uri }]);
        let f = sub.join(format!("{name}.gltf"));
        std::fs::write(&f, serde_json::to_vec(&g.json).unwrap()).unwrap();
        fails_cleanly(&f, "--allow-outside");
        let out = d.join(format!("{name}.glb"));
        let o = run(&["tangents", s(&f), "-o", s(&out), "--allow-outside", "-q"]);
        assert!(o.status.success(), "{name}: {}", String::from_utf8_lossy(&o.stderr));
        assert_eq!(load(&out).primitives().len(), 1);
    }
}

#[test]
fn more_obj_garbage() {
    let d = case("obj_more");
    let cases: &[(&str, &[u8], &str)] = &[
        ("uv_range.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/5 3/1\n", "OBJ"),
        ("n_range.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//9\n", "OBJ"),
        ("negative.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -7\n", "OBJ"),
        ("empty.obj", b"", "no faces"),
        ("only_vertices.obj", b"v 0 0 0\nv 1 0 0\n", "no faces"),
        ("binary.obj", b"\x00\xff\xfe\x89PNG\r\n\x1a\nf 1 2 3\x00\x00", "OBJ"),
    ];
    for (name, bytes, says) in cases {
        let f = d.join(name);
        std::fs::write(&f, bytes).unwrap();
        fails_cleanly(&f, says);
    }
}

#[test]
fn nan_uv_is_refused_and_a_nan_normal_repaired() {
    let d = case("nan_attr");
    let with_infinity = |acc: usize, name: &str| {
        let mut g = Gltf::new();
        simple(&mut g);
        let off = g.json["bufferViews"][acc]["byteOffset"].as_u64().unwrap() as usize;
        g.bin[off + 4..off + 8].copy_from_slice(&f32::INFINITY.to_le_bytes());
        let f = d.join(format!("{name}.glb"));
        g.write_glb(&f);
        f
    };
    fails_cleanly(&with_infinity(2, "TEXCOORD_0"), "TEXCOORD_0 0 is not finite");
    // A normal without a direction is one the file did not give: made again from the faces
    // (docs/validate.md, NORMAL_NOT_UNIT), and said.
    let f = with_infinity(1, "NORMAL");
    let out = d.join("out").join("normal.glb");
    let o = run_ok(&["tangents", s(&f), "-o", s(&out)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("1 normals were zero or not finite"), "{err}");
    let scene = load(&out);
    let r = PrimRef { mesh: 0, primitive: 0 };
    for n in corner_attr::<3>(&scene, r, "NORMAL") {
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((len - 1.0).abs() < 1e-5, "{n:?}");
    }
    let v = run(&["validate", s(&f)]);
    assert_eq!(v.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&v.stderr).contains("NORMAL_NOT_UNIT"));
}

/// A failure while writing (the folder is missing, a file or folder is in the way, the folder is
/// read-only) is exit 2 naming the output, and leaves nothing behind.
#[test]
fn failures_during_the_write_leave_nothing() {
    let d = case("write_fail");
    let input = fixture("khronos/NormalTangentTest.glb");
    let check = |out: &Path, says: &str| {
        let o = run(&["tangents", s(&input), "-o", s(out), "-q"]);
        let err = String::from_utf8_lossy(&o.stderr).to_string();
        assert_eq!(o.status.code(), Some(2), "{}: {err}", out.display());
        assert!(!err.contains("panicked"), "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
        assert!(err.contains(&*out.to_string_lossy()) && err.contains(says), "{err}");
    };
    check(&d.join("missing").join("o.glb"), "cannot write");
    assert!(!d.join("missing").exists());
    std::fs::write(d.join("file"), b"x").unwrap();
    check(&d.join("file").join("o.glb"), "cannot write");
    // The .gltf name is taken by a folder: the .bin must not be left behind either.
    std::fs::create_dir_all(d.join("taken.gltf")).unwrap();
    check(&d.join("taken.gltf"), "directory");
    let listing = |dir: &Path| {
        let mut v: Vec<String> =
            std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        v.sort();
        v
    };
    assert_eq!(listing(&d), vec!["file", "taken.gltf"], "no .bin, no temporary");
    // Read-only folder (skipped where permissions do not apply, e.g. as root).
    use std::os::unix::fs::PermissionsExt as _;
    let ro = d.join("ro");
    std::fs::create_dir_all(&ro).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    if std::fs::write(ro.join("probe"), b"").is_err() {
        check(&ro.join("o.gltf"), "cannot write");
        assert!(listing(&ro).is_empty());
    }
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
}

/// Fuzzing found this (gltf_read, `crash-ff0f4ba0…`): a primitive whose attributes have no
/// POSITION (here misspelt `POSITIOn`) made the tangent stage index an empty position list and
/// panic. glTF allows such primitives (clients skip them): they are skipped with a reason.
#[test]
fn primitive_without_position_is_skipped() {
    let d = case("no_position");
    let mut g = Gltf::new();
    simple(&mut g);
    let attrs = g.json["meshes"][0]["primitives"][0]["attributes"].as_object_mut().unwrap();
    let p = attrs.remove("POSITION").unwrap();
    attrs.insert("POSITIOn".into(), p);
    let f = d.join("nopos.glb");
    g.write_glb(&f);
    let out = d.join("out.glb");
    let o = run(&["tangents", s(&f), "-o", s(&out), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["skipped"], 1, "{report}");
    assert!(report["primitives"][0]["reason"].as_str().unwrap().contains("POSITION"));
}

/// A PNG whose last IDAT stops before the compressed stream's checksum, with no IEND: an
/// unfinished copy. Every command that reads height or normal maps refuses it, as validate does.
#[test]
fn truncated_png_is_refused_everywhere() {
    let d = case("truncated_png");
    // Big enough that the rows are all there without the stream's last bytes.
    let img =
        image::ImageBuffer::<image::Luma<u16>, _>::from_fn(256, 256, |x, y| image::Luma([(x * 200 + y * 37) as u16]));
    let full = d.join("full.png");
    img.save(&full).unwrap();
    let bytes = std::fs::read(&full).unwrap();
    // The IEND chunk is the last 12 bytes; before it, the last IDAT's CRC (4) and the end of its
    // zlib stream, whose last 4 bytes are the Adler-32 checksum.
    let cut = bytes.len() - 12 - 4 - 4;
    assert_eq!(&bytes[bytes.len() - 8..bytes.len() - 4], b"IEND");
    let png = d.join("cut.png");
    std::fs::write(&png, &bytes[..cut]).unwrap();
    let out = d.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let mesh = fixture("bake/torus.obj");
    let runs: [Vec<&str>; 4] = [
        vec!["normalmap", s(&png), "-o", "N"],
        vec!["bake", s(&mesh), "--height", s(&png), "-o", "N.glb"],
        vec!["bake", s(&mesh), "--normal", s(&png), "-o", "N.glb"],
        vec!["validate", s(&png)],
    ];
    for args in runs {
        let target = out.join("n.png");
        let target_glb = out.join("n.glb");
        let args: Vec<&str> = args
            .iter()
            .map(|a| match *a {
                "N" => s(&target),
                "N.glb" => s(&target_glb),
                a => a,
            })
            .collect();
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(
            err.contains("cut.png") && (err.contains("truncated") || err.contains("end of file")),
            "{args:?}: {err}"
        );
        assert_eq!(std::fs::read_dir(&out).unwrap().count(), 0, "{args:?}: nothing written");
    }
}

/// Error lines are plain words: no Rust debug text such as `Some(Jpeg)`.
#[test]
fn unsupported_image_formats_are_named_in_words() {
    let d = case("gif_height");
    // A GIF's header: enough for its format to be recognised; bumpbake reads no GIF.
    let gif = d.join("h.gif");
    std::fs::write(&gif, b"GIF89a\x01\x00\x01\x00\x00\x00\x00;").unwrap();
    // A JPEG's start (SOI, a JFIF APP0 segment) and its end, with no image between.
    let jpg = d.join("h.jpg");
    let mut bytes = vec![0xFF, 0xD8, 0xFF, 0xE0, 0x00, 0x10];
    bytes.extend_from_slice(b"JFIF\0\x01\x01\0\0\x01\0\x01\0\0");
    bytes.extend_from_slice(&[0xFF, 0xD9]);
    std::fs::write(&jpg, &bytes).unwrap();
    let out = d.join("n.png");
    for (img, words) in [(&gif, "a GIF image, which bumpbake does not decode"), (&jpg, "cannot decode as JPEG")] {
        for args in [vec!["normalmap", s(img), "-o", s(&out)], vec!["validate", s(img)]] {
            let o = run(&args);
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
            assert!(err.contains(words), "{args:?}: {err}");
            assert!(
                !err.contains("Some(") && !err.contains("Jpeg") && !err.contains('"'),
                "{args:?}: debug text in {err}"
            );
            assert!(!out.exists());
        }
    }
}
