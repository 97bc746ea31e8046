//! Helpers shared by the integration tests: running the binary, building small glTF files, and
//! reading outputs back through the library.
#![allow(dead_code)]

use bumpbake::scene::{PrimRef, ReadOptions, Scene};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_bumpbake"));
    c.env_remove("RAYON_NUM_THREADS");
    c
}

pub fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("bumpbake runs")
}

/// Runs and insists on exit 0, showing stderr otherwise.
pub fn run_ok(args: &[&str]) -> Output {
    let out = run(args);
    assert!(out.status.success(), "bumpbake {:?} failed: {}", args, String::from_utf8_lossy(&out.stderr));
    out
}

pub fn fixture(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures").join(rel)
}

/// A fresh folder for a test's outputs. Files under `validated/` are run through the Khronos
/// glTF-Validator by CI, so only outputs that must pass it go there.
pub fn validated_dir(test: &str) -> PathBuf {
    fresh(Path::new(env!("CARGO_TARGET_TMPDIR")).join("validated").join(test))
}

/// A fresh folder for KTX2 files a test writes that are not inside a validated glTF: CI has a
/// reference decoder (the Basis Universal command-line tool, tests/ktx2_reference.rs) read every
/// KTX2 here and under `validated/`.
pub fn ktx2_dir(test: &str) -> PathBuf {
    fresh(Path::new(env!("CARGO_TARGET_TMPDIR")).join("ktx2").join(test))
}

/// Records beside `out` (in `OUT.input.json`) the input it was written from, so that CI's
/// Khronos check (`.ci/validate-gltf.js`) holds `out` to "no issue its input does not have"
/// instead of "no issue at all". `explained` lists codes bumpbake's report says it could not
/// avoid, with why.
pub fn record_input(out: &Path, input: &Path, explained: &[(&str, &str)]) {
    let input = std::fs::canonicalize(input).unwrap_or_else(|e| panic!("{}: {e}", input.display()));
    let explained: serde_json::Map<String, Value> =
        explained.iter().map(|(c, why)| (c.to_string(), Value::from(*why))).collect();
    let mut name = out.as_os_str().to_owned();
    name.push(".input.json");
    std::fs::write(name, serde_json::to_vec_pretty(&json!({ "input": input, "explained": explained })).unwrap())
        .unwrap();
}

/// A fresh folder for scratch files (inputs the tests build, outputs not meant to validate).
pub fn scratch_dir(test: &str) -> PathBuf {
    fresh(Path::new(env!("CARGO_TARGET_TMPDIR")).join("scratch").join(test))
}

fn fresh(d: PathBuf) -> PathBuf {
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

pub fn load(path: &Path) -> Scene {
    bumpbake::format::read(path, &ReadOptions::default()).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()))
}

pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Per-corner values of a float attribute of a primitive.
pub fn corner_attr<const N: usize>(scene: &Scene, r: PrimRef, name: &str) -> Vec<[f32; N]> {
    let p = scene.primitive(r).unwrap();
    let v: Vec<[f32; N]> = p.attr(name).unwrap_or_else(|| panic!("no {name}")).to_f32();
    p.indices.iter().map(|&i| v[i as usize]).collect()
}

pub const P0: PrimRef = PrimRef { mesh: 0, primitive: 0 };

/// Reference tangents: `face corner tx ty tz w` per line.
pub fn reference(path: &Path) -> Vec<[f32; 4]> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let f: Vec<f32> = l.split_whitespace().skip(2).map(|x| x.parse().unwrap()).collect();
            [f[0], f[1], f[2], f[3]]
        })
        .collect()
}

pub fn angle(a: [f32; 4], b: [f32; 4]) -> f64 {
    let (a, b) = (
        glam::DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64),
        glam::DVec3::new(b[0] as f64, b[1] as f64, b[2] as f64),
    );
    let c = a.normalize().dot(b.normalize()).clamp(-1.0, 1.0);
    // acos loses precision near 1; atan2 of cross and dot does not.
    a.normalize().cross(b.normalize()).length().atan2(c)
}

/// Asserts a frame obeys the conventions: finite, unit, orthogonal to the normal, w = +-1.
pub fn assert_valid_frame(t: [f32; 4], n: [f32; 3], what: &str) {
    let v = glam::Vec3::new(t[0], t[1], t[2]);
    let n = glam::Vec3::from(n);
    assert!(v.is_finite(), "{what}: tangent not finite {t:?}");
    assert!((v.length() - 1.0).abs() < 1e-4, "{what}: tangent not unit {t:?}");
    assert!(t[3] == 1.0 || t[3] == -1.0, "{what}: w is {}", t[3]);
    assert!((n.length() - 1.0).abs() < 1e-3, "{what}: normal not unit {n:?}");
    assert!(v.dot(n).abs() < 1e-3, "{what}: tangent {t:?} not orthogonal to normal {n:?}");
}

/// A minimal glTF assembled in memory.
pub struct Gltf {
    pub json: Value,
    pub bin: Vec<u8>,
}

impl Gltf {
    pub fn new() -> Self {
        Gltf {
            json: json!({ "asset": { "version": "2.0" }, "scene": 0, "scenes": [{ "nodes": [] }], "nodes": [], "meshes": [], "accessors": [], "bufferViews": [], "buffers": [] }),
            bin: Vec::new(),
        }
    }

    fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut v = json!({ "buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len() });
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.bin.extend_from_slice(bytes);
        let views = self.json["bufferViews"].as_array_mut().unwrap();
        views.push(v);
        views.len() - 1
    }

    pub fn floats<const N: usize>(&mut self, data: &[[f32; N]], target: Option<u32>) -> usize {
        let bytes: Vec<u8> = data.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
        let v = self.view(&bytes, target);
        let ty = match N {
            1 => "SCALAR",
            2 => "VEC2",
            3 => "VEC3",
            4 => "VEC4",
            16 => "MAT4",
            _ => panic!("size"),
        };
        let mut acc = json!({ "bufferView": v, "componentType": 5126, "count": data.len(), "type": ty });
        if N == 3 && target == Some(34962) {
            let mut lo = [f32::INFINITY; N];
            let mut hi = [f32::NEG_INFINITY; N];
            for d in data {
                for c in 0..N {
                    lo[c] = lo[c].min(d[c]);
                    hi[c] = hi[c].max(d[c]);
                }
            }
            acc["min"] = json!(lo.to_vec());
            acc["max"] = json!(hi.to_vec());
        }
        self.push_accessor(acc)
    }

    /// A vertex accessor of raw bytes with the given component type.
    pub fn bytes(&mut self, bytes: &[u8], component_type: u32, ty: &str, count: usize) -> usize {
        let v = self.view(bytes, Some(34962));
        self.push_accessor(json!({ "bufferView": v, "componentType": component_type, "count": count, "type": ty }))
    }

    pub fn indices(&mut self, idx: &[u16]) -> usize {
        let bytes: Vec<u8> = idx.iter().flat_map(|i| i.to_le_bytes()).collect();
        let v = self.view(&bytes, Some(34963));
        self.push_accessor(json!({ "bufferView": v, "componentType": 5123, "count": idx.len(), "type": "SCALAR" }))
    }

    /// Animation inputs need min and max.
    pub fn accessor_min_max(&mut self, acc: usize) {
        let a = self.json["accessors"][acc].clone();
        let view = &self.json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
        let off = view["byteOffset"].as_u64().unwrap() as usize;
        let n = a["count"].as_u64().unwrap() as usize;
        let vals: Vec<f32> =
            (0..n).map(|k| f32::from_le_bytes(self.bin[off + 4 * k..off + 4 * k + 4].try_into().unwrap())).collect();
        let lo = vals.iter().cloned().fold(f32::INFINITY, f32::min);
        let hi = vals.iter().cloned().fold(f32::NEG_INFINITY, f32::max);
        self.json["accessors"][acc]["min"] = json!([lo]);
        self.json["accessors"][acc]["max"] = json!([hi]);
    }

    pub fn push_accessor(&mut self, acc: Value) -> usize {
        let a = self.json["accessors"].as_array_mut().unwrap();
        a.push(acc);
        a.len() - 1
    }

    /// Adds a mesh with one primitive and a node showing it; returns the mesh index.
    pub fn mesh(&mut self, prim: Value) -> usize {
        let meshes = self.json["meshes"].as_array_mut().unwrap();
        meshes.push(json!({ "primitives": [prim] }));
        let m = meshes.len() - 1;
        let nodes = self.json["nodes"].as_array_mut().unwrap();
        nodes.push(json!({ "mesh": m }));
        let n = nodes.len() - 1;
        self.json["scenes"][0]["nodes"].as_array_mut().unwrap().push(json!(n));
        m
    }

    /// A 1x1 PNG as a data URI image + texture; returns the texture index.
    pub fn texture(&mut self) -> usize {
        self.png_texture(&tiny_png())
    }

    /// `png` as a data URI image + texture (default sampler); returns the texture index.
    pub fn png_texture(&mut self, png: &[u8]) -> usize {
        use base64::Engine as _;
        let uri = format!("data:image/png;base64,{}", base64::engine::general_purpose::STANDARD.encode(png));
        let images = self.json.as_object_mut().unwrap().entry("images").or_insert(json!([]));
        images.as_array_mut().unwrap().push(json!({ "uri": uri }));
        let img = images.as_array().unwrap().len() - 1;
        let textures = self.json.as_object_mut().unwrap().entry("textures").or_insert(json!([]));
        textures.as_array_mut().unwrap().push(json!({ "source": img }));
        textures.as_array().unwrap().len() - 1
    }

    pub fn material(&mut self, m: Value) -> usize {
        let mats = self.json.as_object_mut().unwrap().entry("materials").or_insert(json!([]));
        mats.as_array_mut().unwrap().push(m);
        mats.as_array().unwrap().len() - 1
    }

    pub fn write_glb(&mut self, path: &Path) {
        self.json["buffers"] = json!([{ "byteLength": self.bin.len() }]);
        let mut j = serde_json::to_vec(&self.json).unwrap();
        while !j.len().is_multiple_of(4) {
            j.push(b' ');
        }
        let mut b = self.bin.clone();
        while !b.len().is_multiple_of(4) {
            b.push(0);
        }
        std::fs::write(path, glb_bytes(&j, &b)).unwrap();
    }

    /// Writes `name.gltf` + `name.bin` into `dir`; returns the .gltf path.
    pub fn write_gltf(&mut self, dir: &Path, name: &str) -> PathBuf {
        let bin = format!("{name}.bin");
        self.json["buffers"] = json!([{ "byteLength": self.bin.len(), "uri": bin }]);
        std::fs::write(dir.join(&bin), &self.bin).unwrap();
        let p = dir.join(format!("{name}.gltf"));
        std::fs::write(&p, serde_json::to_vec_pretty(&self.json).unwrap()).unwrap();
        p
    }
}

/// A valid 1x1 RGB PNG (flat normal colour), made with the image crate.
pub fn tiny_png() -> Vec<u8> {
    let img = image::RgbImage::from_pixel(1, 1, image::Rgb([128, 128, 255]));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// A grid of `n x n` quads in the XY plane facing +Z, UV = position (v down, as glTF stores it).
/// Positions, normals, UVs and 16-bit indices of a test mesh.
pub type Mesh16 = (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<[f32; 2]>, Vec<u16>);

pub fn grid(n: usize) -> Mesh16 {
    let mut p = Vec::new();
    let mut uv = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
            p.push([x, y, 0.0]);
            uv.push([x, 1.0 - y]);
        }
    }
    let mut idx = Vec::new();
    let w = (n + 1) as u16;
    for j in 0..n as u16 {
        for i in 0..n as u16 {
            let a = j * w + i;
            idx.extend([a, a + 1, a + w + 1, a, a + w + 1, a + w]);
        }
    }
    (p.clone(), vec![[0.0, 0.0, 1.0]; p.len()], uv, idx)
}

/// One quad whose material's normal texture is `texture` (its images are the caller's).
pub fn normal_mapped_quad(g: &mut Gltf, texture: Value) {
    let (pos, nrm, uv, idx) = grid(1);
    let attrs = json!({
        "POSITION": g.floats(&pos, Some(34962)),
        "NORMAL": g.floats(&nrm, Some(34962)),
        "TEXCOORD_0": g.floats(&uv, Some(34962)),
    });
    let i = g.indices(&idx);
    g.json["textures"] = json!([texture]);
    let m = g.material(json!({ "normalTexture": { "index": 0 } }));
    g.mesh(json!({ "attributes": attrs, "indices": i, "material": m }));
}

pub fn data_uri(mime: &str, bytes: &[u8]) -> String {
    use base64::Engine as _;
    format!("data:{mime};base64,{}", base64::engine::general_purpose::STANDARD.encode(bytes))
}

/// Every line of code (comments left out) of the crate's sources outside `src/scene/` (the
/// model) and `src/format/` (the readers that build it) for which `found` holds, as
/// `path:line: text`: what guard tests use to keep a decision in the model.
pub fn stage_lines_where(found: impl Fn(&str) -> bool) -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut out = Vec::new();
    let mut stack = vec![root.clone()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                if p != root.join("scene") && p != root.join("format") {
                    stack.push(p);
                }
            } else if p.extension().is_some_and(|x| x == "rs") {
                let text = std::fs::read_to_string(&p).unwrap();
                for (n, line) in text.lines().enumerate().filter(|(_, l)| !l.trim_start().starts_with("//")) {
                    if found(line) {
                        out.push(format!("{}:{}: {}", p.display(), n + 1, line.trim()));
                    }
                }
            }
        }
    }
    out
}

/// A GLB of JSON and binary chunks whose lengths are already multiples of 4.
pub fn glb_bytes(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(28 + json.len() + bin.len());
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&((28 + json.len() + bin.len()) as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(bin);
    out
}
