//! The scenes of the specular-antialiasing figures (README, `docs/preview.md`, "Mip levels and
//! specular antialiasing"): a unit plane carrying a 1024² normal map of fine bumps.
//!
//! `cargo run --release --example specular_aa_scene -- height DIR sine|noise` writes
//! `DIR/height.png`: crossed sine products (a regular pattern, the hard case for a single lobe) or
//! band-limited noise (random bumps, what most detail maps look like). `bumpbake normalmap` makes
//! `normal.png` from it; `... -- scene DIR` writes the plane and, per roughness, `png-R.gltf` with
//! that map. `bumpbake textures` then makes the KTX2 variants (docs/specular_aa_figures.sh).
use serde_json::json;
use std::f64::consts::PI;
use std::path::Path;

const SIZE: u32 = 1024;
const ROUGHNESS: [f32; 2] = [0.15, 0.5];

/// Fine regular bumps in [0, 1]: a crossed sine product and a slanted sine (periods of about 11
/// to 17 texels) that a mip level 3 to 4 averages away, so the normals' spread becomes the level's
/// lost length.
fn sine(x: f64, y: f64) -> f64 {
    let a = (2.0 * PI * 96.0 * x).sin() * (2.0 * PI * 80.0 * y).sin();
    let b = (2.0 * PI * (61.0 * x + 47.0 * y)).sin();
    0.5 + 0.3 * a + 0.2 * b
}

/// Random bumps: 256 waves of random direction and phase, wave vectors spread evenly over the
/// periods 6 to 128 texels (whole cycles across the map, so it tiles), each of height amplitude
/// proportional to its period (a 1/f spectrum: every scale tilts the surface alike). The sum of
/// many independent waves has nearly Gaussian slopes.
fn noise_waves() -> Vec<([f64; 2], f64, f64)> {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let (k_min, k_max) = (SIZE as f64 / 128.0, SIZE as f64 / 6.0);
    (0..256)
        .map(|_| {
            // Even over the annulus's area, as a white noise's modes are.
            let k = (k_min * k_min + rnd() * (k_max * k_max - k_min * k_min)).sqrt();
            let a = rnd() * 2.0 * PI;
            let kv = [(k * a.cos()).round(), (k * a.sin()).round()];
            let len = kv[0].hypot(kv[1]).max(1.0);
            (kv, 1.0 / len, rnd() * 2.0 * PI)
        })
        .collect()
}

fn write_height(dir: &Path, kind: &str) {
    let waves = noise_waves();
    let field: Vec<f64> = (0..SIZE * SIZE)
        .map(|t| {
            let (x, y) = (((t % SIZE) as f64 + 0.5) / SIZE as f64, ((t / SIZE) as f64 + 0.5) / SIZE as f64);
            match kind {
                "noise" => waves.iter().map(|&(k, a, p)| a * (2.0 * PI * (k[0] * x + k[1] * y) + p).sin()).sum(),
                _ => sine(x, y),
            }
        })
        .collect();
    // Noise is rescaled to [0, 1]; the sine field already spans it.
    let (lo, hi) = match kind {
        "noise" => field.iter().fold((f64::MAX, f64::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v))),
        _ => (0.0, 1.0),
    };
    let img = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(SIZE, SIZE, |i, j| {
        let v = (field[(j * SIZE + i) as usize] - lo) / (hi - lo);
        image::Luma([(v.clamp(0.0, 1.0) * 65535.0).round() as u16])
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

fn gltf(normal_png: &str, roughness: f32) -> serde_json::Value {
    let view = |offset: usize, len: usize| json!({ "buffer": 0, "byteOffset": offset, "byteLength": len });
    let acc =
        |view: usize, ty: &str, ct: u32| json!({ "bufferView": view, "componentType": ct, "count": 4, "type": ty });
    json!({
        "asset": { "version": "2.0", "generator": "bumpbake examples/specular_aa_scene.rs" },
        "scene": 0, "scenes": [{ "nodes": [0] }], "nodes": [{ "mesh": 0 }],
        "meshes": [{ "primitives": [{
            "attributes": { "POSITION": 0, "NORMAL": 1, "TANGENT": 2, "TEXCOORD_0": 3 }, "indices": 4, "material": 0 }] }],
        "materials": [{
            "pbrMetallicRoughness":
                { "baseColorFactor": [0.5, 0.5, 0.5, 1.0], "metallicFactor": 0.0, "roughnessFactor": roughness },
            "normalTexture": { "index": 0 } }],
        // Trilinear, repeat: what three.js and most engines use.
        "samplers": [{ "magFilter": 9729, "minFilter": 9987 }],
        "textures": [{ "sampler": 0, "source": 0 }],
        "images": [{ "uri": normal_png, "mimeType": "image/png" }],
        "buffers": [{ "uri": "plane.bin", "byteLength": 204 }],
        "bufferViews": [view(0, 48), view(48, 48), view(96, 64), view(160, 32), view(192, 12)],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
              "min": [-0.5, -0.5, 0.0], "max": [0.5, 0.5, 0.0] },
            acc(1, "VEC3", 5126), acc(2, "VEC4", 5126), acc(3, "VEC2", 5126),
            { "bufferView": 4, "componentType": 5123, "count": 6, "type": "SCALAR" }
        ]
    })
}

fn write_scene(dir: &Path) {
    std::fs::write(dir.join("plane.bin"), plane_bin()).expect("plane.bin");
    for r in ROUGHNESS {
        let text = serde_json::to_string_pretty(&gltf("normal.png", r)).expect("JSON");
        std::fs::write(dir.join(format!("png-{r}.gltf")), text).expect("glTF");
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let (what, dir) = (args.next().unwrap_or_default(), args.next().unwrap_or_else(|| "target/saa".into()));
    let dir = Path::new(&dir);
    std::fs::create_dir_all(dir).expect("output folder");
    match what.as_str() {
        "height" => write_height(dir, &args.next().unwrap_or_else(|| "sine".into())),
        "scene" => write_scene(dir),
        _ => eprintln!("usage: specular_aa_scene height DIR sine|noise, or scene DIR"),
    }
}
