//! The scene of the specular-antialiasing figures (README, `docs/preview.md`, "Mip levels and
//! specular antialiasing"): a unit plane carrying a 1024² normal map of fine bumps.
//!
//! `cargo run --release --example specular_aa_scene -- height DIR` writes `DIR/height.png`;
//! `bumpbake normalmap` makes `normal.png` and `normal.ktx2` from it; then
//! `cargo run --release --example specular_aa_scene -- scene DIR` writes the plane and, per
//! roughness, three glTF files: `png-R.gltf` (the PNG map: the renderer's own box mips),
//! `ktx2-R.gltf` (bumpbake's KTX2 map and mips) and `saa-R.gltf` (the same with a KTX2
//! metallicRoughness texture whose roughness levels carry what each normal level lost,
//! `bumpbake::normalmap::specular_aa::roughness_levels`). Until `bake --textures ktx2
//! --specular-aa` lands, this is that step done by hand with the same library functions.
use bumpbake::format::image::ktx2::{encode, Codec, Level};
use bumpbake::normalmap::mips;
use bumpbake::normalmap::specular_aa::{roughness_levels, DEFAULT_THRESHOLD};
use serde_json::json;
use std::f64::consts::PI;
use std::path::Path;

const SIZE: u32 = 1024;
const ROUGHNESS: [f32; 2] = [0.15, 0.5];

/// Fine bumps in [0, 1]: a crossed sine product and a slanted sine (periods of about 11 to 17
/// texels) that a mip level
/// 3 to 4 averages away, so the normals' spread becomes the level's lost length.
fn height(x: f64, y: f64) -> f64 {
    let a = (2.0 * PI * 96.0 * x).sin() * (2.0 * PI * 80.0 * y).sin();
    let b = (2.0 * PI * (61.0 * x + 47.0 * y)).sin();
    0.5 + 0.3 * a + 0.2 * b
}

fn write_height(dir: &Path) {
    let img = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(SIZE, SIZE, |i, j| {
        let (x, y) = ((i as f64 + 0.5) / SIZE as f64, (j as f64 + 0.5) / SIZE as f64);
        image::Luma([(height(x, y).clamp(0.0, 1.0) * 65535.0).round() as u16])
    });
    img.save(dir.join("height.png")).expect("height.png");
}

/// A unit plane in z = 0 facing +Z, UVs v-down, tangent +X (u grows with x, v-up with y).
fn plane_bin() -> Vec<u8> {
    let p = [[-0.5f32, -0.5, 0.0], [0.5, -0.5, 0.0], [0.5, 0.5, 0.0], [-0.5, 0.5, 0.0]];
    let mut b = Vec::new();
    let mut put = |v: &[f32]| v.iter().for_each(|x| b.extend_from_slice(&x.to_le_bytes()));
    p.iter().for_each(|q| put(q));
    p.iter().for_each(|_| put(&[0.0, 0.0, 1.0]));
    p.iter().for_each(|_| put(&[1.0, 0.0, 0.0, 1.0]));
    p.iter().for_each(|q| put(&[q[0] + 0.5, 0.5 - q[1]]));
    for i in [0u16, 1, 2, 0, 2, 3] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b
}

fn gltf(normal: &str, metal_rough: Option<&str>, roughness: f32) -> serde_json::Value {
    let view = |offset: usize, len: usize| json!({ "buffer": 0, "byteOffset": offset, "byteLength": len });
    let acc =
        |view: usize, ty: &str, ct: u32| json!({ "bufferView": view, "componentType": ct, "count": 4, "type": ty });
    let ktx2 = |uri: &str| uri.ends_with(".ktx2");
    let image = |uri: &str| json!({ "uri": uri, "mimeType": if ktx2(uri) { "image/ktx2" } else { "image/png" } });
    let texture = |i: usize, uri: &str| {
        if ktx2(uri) {
            json!({ "sampler": 0, "extensions": { "KHR_texture_basisu": { "source": i } } })
        } else {
            json!({ "sampler": 0, "source": i })
        }
    };
    let mut images = vec![image(normal)];
    let mut textures = vec![texture(0, normal)];
    let mut pbr =
        json!({ "baseColorFactor": [0.5, 0.5, 0.5, 1.0], "metallicFactor": 0.0, "roughnessFactor": roughness });
    if let Some(mr) = metal_rough {
        images.push(image(mr));
        textures.push(texture(1, mr));
        pbr["metallicRoughnessTexture"] = json!({ "index": 1 });
        pbr["roughnessFactor"] = json!(1.0);
        pbr["metallicFactor"] = json!(1.0);
    }
    let mut g = json!({
        "asset": { "version": "2.0", "generator": "bumpbake examples/specular_aa_scene.rs" },
        "scene": 0, "scenes": [{ "nodes": [0] }], "nodes": [{ "mesh": 0 }],
        "meshes": [{ "primitives": [{
            "attributes": { "POSITION": 0, "NORMAL": 1, "TANGENT": 2, "TEXCOORD_0": 3 }, "indices": 4, "material": 0 }] }],
        "materials": [{ "pbrMetallicRoughness": pbr, "normalTexture": { "index": 0 } }],
        // Trilinear, repeat: what three.js and most engines use.
        "samplers": [{ "magFilter": 9729, "minFilter": 9987 }],
        "textures": textures, "images": images,
        "buffers": [{ "uri": "plane.bin", "byteLength": 204 }],
        "bufferViews": [view(0, 48), view(48, 48), view(96, 64), view(160, 32), view(192, 12)],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
              "min": [-0.5, -0.5, 0.0], "max": [0.5, 0.5, 0.0] },
            acc(1, "VEC3", 5126), acc(2, "VEC4", 5126), acc(3, "VEC2", 5126),
            { "bufferView": 4, "componentType": 5123, "count": 6, "type": "SCALAR" }
        ]
    });
    if ktx2(normal) {
        g["extensionsUsed"] = json!(["KHR_texture_basisu"]);
        g["extensionsRequired"] = json!(["KHR_texture_basisu"]);
    }
    g
}

/// `threshold`: the widening cap ([`DEFAULT_THRESHOLD`] unless a third argument gives another, to
/// measure what the cap costs).
fn write_scene(dir: &Path, threshold: f32) {
    std::fs::write(dir.join("plane.bin"), plane_bin()).expect("plane.bin");
    let png = image::open(dir.join("normal.png")).expect("normal.png (bumpbake normalmap)").to_rgb8();
    let (w, h) = (png.width() as usize, png.height() as usize);
    let levels = mips::build(&mips::unit_normals(png.as_raw()), w, h);
    for r in ROUGHNESS {
        let name = |kind: &str| format!("{kind}-{r}.gltf");
        let mr_name = format!("roughness-{r}.ktx2");
        let rough = roughness_levels(&levels, &vec![r; w * h], threshold);
        // glTF's channels: occlusion in R (unused), roughness in G, metalness in B (0).
        let rgb: Vec<Vec<u8>> = rough
            .iter()
            .map(|l| l.roughness.iter().flat_map(|&g| [255, (g * 255.0).round() as u8, 0]).collect())
            .collect();
        let input: Vec<Level> = rough
            .iter()
            .zip(&rgb)
            .map(|(l, rgb)| Level { width: l.width as u32, height: l.height as u32, rgb })
            .collect();
        let bytes = encode(&input, Codec::Uastc { level: 2, rdo: None }, 2).expect("KTX2 encode");
        std::fs::write(dir.join(&mr_name), bytes).expect("roughness KTX2");
        for (kind, normal, mr) in
            [("png", "normal.png", None), ("ktx2", "normal.ktx2", None), ("saa", "normal.ktx2", Some(mr_name.as_str()))]
        {
            let text = serde_json::to_string_pretty(&gltf(normal, mr, r)).expect("JSON");
            std::fs::write(dir.join(name(kind)), text).expect("glTF");
        }
        for (k, l) in rough.iter().enumerate() {
            let mean = l.roughness.iter().map(|&v| v as f64).sum::<f64>() / l.roughness.len() as f64;
            println!("roughness {r}: level {k} ({}x{}) mean roughness {mean:.3}", l.width, l.height);
        }
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let (what, dir) = (args.next().unwrap_or_default(), args.next().unwrap_or_else(|| "target/saa".into()));
    let dir = Path::new(&dir);
    std::fs::create_dir_all(dir).expect("output folder");
    match what.as_str() {
        "height" => write_height(dir),
        "scene" => write_scene(dir, args.next().and_then(|t| t.parse().ok()).unwrap_or(DEFAULT_THRESHOLD)),
        _ => eprintln!("usage: specular_aa_scene height|scene DIR"),
    }
}
