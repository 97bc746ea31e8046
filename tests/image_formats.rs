//! Every command that reads an image reads PNG, JPEG and WebP alike (one reader in
//! `format::image`), names formats it does not decode, and refuses broken files in plain words.

mod common;
use common::*;
use image::{ImageFormat, RgbImage};
use serde_json::{json, Value};
use std::path::Path;

fn encoded(img: &image::DynamicImage, format: ImageFormat) -> Vec<u8> {
    let mut c = std::io::Cursor::new(Vec::new());
    match format {
        // Quality 90, as exporters commonly write normal maps.
        ImageFormat::Jpeg => {
            img.write_with_encoder(image::codecs::jpeg::JpegEncoder::new_with_quality(&mut c, 90)).unwrap()
        }
        f => img.write_to(&mut c, f).unwrap(),
    }
    c.into_inner()
}

/// A saddle `h = x * y_up` baked to an 8-bit tangent-space normal map (OpenGL, or DirectX with
/// green flipped): a map with twist, whose convention the detector can tell.
fn saddle(n: u32, directx: bool) -> image::DynamicImage {
    image::DynamicImage::ImageRgb8(RgbImage::from_fn(n, n, |x, row| {
        let y = (n - 1 - row) as f64;
        let (hx, hy) = (y / n as f64, x as f64 / n as f64);
        let l = (hx * hx + hy * hy + 1.0).sqrt();
        let ny = if directx { hy / l } else { -hy / l };
        let c = |v: f64| ((v * 0.5 + 0.5) * 255.0).round() as u8;
        image::Rgb([c(-hx / l), c(ny), c(1.0 / l)])
    }))
}

fn normal(p: image::Rgb<u8>) -> glam::DVec3 {
    glam::DVec3::new(p[0] as f64 / 127.5 - 1.0, p[1] as f64 / 127.5 - 1.0, p[2] as f64 / 127.5 - 1.0)
}

/// A ramp height map (h = 20/255 a texel along x) as PNG, lossless WebP and JPEG: the PNG and WebP
/// maps are the same bytes, and the JPEG one gives the exact slope's normal within JPEG's error.
#[test]
fn normalmap_reads_jpeg_and_webp_heights() {
    let d = scratch_dir("formats_normalmap");
    let ramp = image::DynamicImage::ImageLuma8(image::GrayImage::from_fn(24, 16, |x, _| image::Luma([(x * 10) as u8])));
    let mut outs = Vec::new();
    for (name, f) in [("png", ImageFormat::Png), ("webp", ImageFormat::WebP), ("jpg", ImageFormat::Jpeg)] {
        let input = d.join(format!("ramp.{name}"));
        std::fs::write(&input, encoded(&ramp, f)).unwrap();
        let out = d.join(format!("n_{name}.png"));
        run_ok(&["normalmap", s(&input), "-o", s(&out), "--strength", "3"]);
        outs.push(out);
    }
    assert_eq!(std::fs::read(&outs[0]).unwrap(), std::fs::read(&outs[1]).unwrap(), "lossless WebP is the PNG");
    // Central differences of h = 10/255 x: the slope is 10/255 a texel, away from the edges.
    let (gx, s3) = (10.0 / 255.0, 3.0);
    let want = glam::DVec3::new(-s3 * gx, 0.0, 1.0).normalize();
    let jpg = image::open(&outs[2]).unwrap().to_rgb8();
    let mut worst = 0.0f64;
    for y in 0..16 {
        for x in 2..22 {
            worst = worst.max(normal(*jpg.get_pixel(x, y)).normalize().angle_between(want).to_degrees());
        }
    }
    // Measured: 0.36 degrees with the quality-90 JPEG (8-bit output rounding included); twice that
    // is allowed.
    assert!(worst < 0.72, "JPEG ramp normals off by {worst} degrees");
}

/// `bake --normal` embeds a JPEG as JPEG (a core glTF format) and turns WebP into PNG; `bake
/// --height` reads both. Every output is a valid glTF.
#[test]
fn bake_takes_jpeg_and_webp_maps() {
    let d = scratch_dir("formats_bake_in");
    let v = validated_dir("formats_bake");
    let map = saddle(32, false);
    for (name, f, mime) in [("jpg", ImageFormat::Jpeg, "image/jpeg"), ("webp", ImageFormat::WebP, "image/png")] {
        let input = d.join(format!("n.{name}"));
        std::fs::write(&input, encoded(&map, f)).unwrap();
        let out = v.join(format!("normal_{name}.glb"));
        run_ok(&["bake", s(&fixture("bake/torus.obj")), "--normal", s(&input), "-o", s(&out), "-q"]);
        let scene = load(&out);
        let img = scene.texture_image(0).unwrap();
        assert_eq!(scene.json["images"][img]["mimeType"], mime);
        let bytes = scene.image_bytes(img).unwrap();
        if f == ImageFormat::Jpeg {
            assert_eq!(bytes, std::fs::read(&input).unwrap(), "the JPEG is embedded as given");
        } else {
            assert_eq!(image::load_from_memory(&bytes).unwrap().to_rgb8(), map.to_rgb8(), "lossless WebP -> PNG");
        }
        let gray = image::DynamicImage::ImageLuma8(map.to_luma8());
        let h = d.join(format!("h.{name}"));
        std::fs::write(&h, encoded(&gray, f)).unwrap();
        run_ok(&[
            "bake",
            s(&fixture("bake/torus.obj")),
            "--height",
            s(&h),
            "-o",
            s(&v.join(format!("height_{name}.glb"))),
            "-q",
        ]);
    }
}

fn validate_json(path: &Path) -> Value {
    let o = run(&["validate", s(path), "--format", "json"]);
    serde_json::from_slice(&o.stdout).unwrap_or_else(|_| panic!("{}", String::from_utf8_lossy(&o.stderr)))
}

fn image_codes(r: &Value) -> Vec<String> {
    r["files"][0]["subjects"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|s| s["kind"] == "image")
        .flat_map(|s| s["findings"].as_array().unwrap().iter().map(|f| f["code"].as_str().unwrap().to_string()))
        .collect()
}

/// A KTX2 file in a block format bumpbake does not decode (BC7), which it names.
fn block_compressed_ktx2() -> Vec<u8> {
    std::fs::read(fixture("ktx2/bc7.ktx2")).unwrap()
}

/// A DirectX map is caught whether it is a JPEG, a WebP behind EXT_texture_webp (with a PNG
/// fallback, both checked), and a KTX2 image in a format not decoded is named, not dropped.
#[test]
fn validate_checks_jpeg_and_webp_maps_and_names_ktx2() {
    let d = scratch_dir("formats_validate");
    let dx = saddle(32, true);
    let cases: [(&str, Vec<Value>, Value, &[&str]); 3] = [
        (
            "jpeg",
            vec![json!({ "uri": data_uri("image/jpeg", &encoded(&dx, ImageFormat::Jpeg)) })],
            json!({ "source": 0 }),
            &["NORMALMAP_GREEN_FLIPPED"],
        ),
        (
            "webp",
            vec![
                json!({ "uri": data_uri("image/png", &encoded(&saddle(32, false), ImageFormat::Png)) }),
                json!({ "uri": data_uri("image/webp", &encoded(&dx, ImageFormat::WebP)) }),
            ],
            json!({ "source": 0, "extensions": { "EXT_texture_webp": { "source": 1 } } }),
            &["NORMALMAP_GREEN_FLIPPED"],
        ),
        (
            "ktx2",
            vec![json!({ "uri": data_uri("image/ktx2", &block_compressed_ktx2()) })],
            json!({ "extensions": { "KHR_texture_basisu": { "source": 0 } } }),
            &["NORMALMAP_NOT_DECODED"],
        ),
    ];
    for (name, images, texture, want) in cases {
        let mut g = Gltf::new();
        normal_mapped_quad(&mut g, texture);
        g.json["images"] = json!(images);
        let path = d.join(format!("{name}.glb"));
        g.write_glb(&path);
        let r = validate_json(&path);
        assert_eq!(image_codes(&r), want, "{name}: {r}");
        if name == "ktx2" {
            let f = &r["files"][0]["subjects"].as_array().unwrap().iter().find(|s| s["kind"] == "image").unwrap()
                ["findings"][0];
            assert_eq!(f["severity"], "info");
            let m = f["message"].as_str().unwrap();
            assert!(m.starts_with("not checked: a KTX2 image in a BC1-BC7 block format"), "{f}");
        }
        if name == "webp" {
            let subjects = r["files"][0]["subjects"].as_array().unwrap();
            assert_eq!(subjects.iter().filter(|s| s["kind"] == "image").count(), 2, "fallback and WebP both checked");
        }
    }
}

/// Broken images are refused in one line that names the format in words, never Rust's names.
#[test]
fn truncated_jpeg_and_webp_are_refused_in_words() {
    let d = scratch_dir("formats_truncated");
    let map = saddle(32, false);
    for (name, f, word) in [("jpg", ImageFormat::Jpeg, "JPEG"), ("webp", ImageFormat::WebP, "WebP")] {
        let bytes = encoded(&map, f);
        let cut = d.join(format!("cut.{name}"));
        std::fs::write(&cut, &bytes[..bytes.len() * 2 / 3]).unwrap();
        let out = d.join("out.png");
        for args in [
            vec!["normalmap", s(&cut), "-o", s(&out)],
            vec!["bake", s(&fixture("bake/torus.obj")), "--normal", s(&cut), "-o", s(&d.join("o.glb"))],
        ] {
            let o = run(&args);
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
            assert_eq!(err.lines().count(), 1, "{err}");
            assert!(err.contains(&format!("cannot decode as {word}")), "{err}");
            assert!(!err.contains("Some(") && !err.contains("Jpeg") && !err.contains("WebP)"), "{err}");
        }
        assert!(!out.exists());
    }
}

/// preview draws a KTX2 texture's PNG fallback and says so; a KTX2-only texture is drawn without,
/// with a note naming the image; a WebP-only texture is drawn with its map.
#[test]
fn preview_names_ktx2_and_draws_what_it_can() {
    let d = scratch_dir("formats_preview");
    let ktx2 = json!({ "uri": data_uri("image/ktx2", &block_compressed_ktx2()) });
    let png = json!({ "uri": data_uri("image/png", &encoded(&saddle(16, false), ImageFormat::Png)) });
    let webp = json!({ "uri": data_uri("image/webp", &encoded(&saddle(16, false), ImageFormat::WebP)) });
    let basisu = |source: Option<u64>| {
        let mut t = json!({ "extensions": { "KHR_texture_basisu": { "source": 0 } } });
        if let Some(s) = source {
            t["source"] = json!(s);
        }
        t
    };
    let cases = [
        ("fallback", vec![ktx2.clone(), png], basisu(Some(1)), Some("image 1 is used instead")),
        ("ktx2_only", vec![ktx2], basisu(None), Some("the texture is left out")),
        ("webp_only", vec![webp], json!({ "extensions": { "EXT_texture_webp": { "source": 0 } } }), None),
    ];
    let mut shaded = Vec::new();
    for (name, images, texture, note) in cases {
        let mut g = Gltf::new();
        normal_mapped_quad(&mut g, texture);
        g.json["images"] = json!(images);
        let path = d.join(format!("{name}.glb"));
        g.write_glb(&path);
        let img = d.join(format!("{name}.png"));
        let o = run_ok(&["preview", s(&path), "-o", s(&img), "--size", "32x32", "--light", "dir:-1,-1,-1"]);
        let err = String::from_utf8_lossy(&o.stderr);
        match note {
            Some(n) => {
                assert!(err.contains("image 0 (KTX2, KHR_texture_basisu) not decoded") && err.contains(n), "{err}")
            }
            None => assert!(!err.contains("not decoded") && !err.contains("without"), "{err}"),
        }
        shaded.push(std::fs::read(&img).unwrap());
    }
    // The PNG fallback and the lossless WebP are the same map: the same picture.
    assert_eq!(shaded[0], shaded[2]);
    assert_ne!(shaded[0], shaded[1], "without the map the quad is shaded flat");
}
