//! Issue 32: no shape of glTF JSON makes a command panic. Every fixture's JSON is mutated (each
//! value replaced by `[]`, `{}`, `"x"`, `1` and `null`, each array emptied, each index set to
//! -1, its target array's length and 2^32) and every command runs on every mutant: it must end
//! with exit 0 or 2 (validate also 1) and one line of plain words per bad file, never exit 101.
//!
//! The full set is over ten thousand files; a debug build on 2 cores cannot run seven commands
//! over all of them within CI's budget, so by default each document gives a seeded sample that
//! holds every kind of change at every depth, and then as many places in the schema as the budget
//! allows (`sample`). `BUMPBAKE_MUTANTS=all` runs the full set, `BUMPBAKE_MUTANTS=N` samples N per
//! document, and `BUMPBAKE_MUTATION_SEED=S` draws another sample (soak runs).

mod common;
use common::*;

use serde_json::{json, Value};
use std::collections::{BTreeMap, BTreeSet};
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Small fixtures that between them hold every part of glTF bumpbake reads, and what each brings.
/// The two Khronos models are left out: `real/mirror_small.glb` is one of them cut down, and at
/// 2 MB each their thousands of mutants would cost more than everything else here together.
/// `ktx2/mirror_etc1s.glb` is left out for its 512x512 ETC1S map (180 ms a file for validate in a
/// debug build): `quad.gltf` through KHR_texture_basisu reaches the same code on 16x16 images.
const FIXTURES: &[(&str, &str)] = &[
    ("real/mirror_small.glb", "meshes, materials, textures, images, samplers"),
    ("real/mirror_small.quantize.glb", "KHR_mesh_quantization"),
    ("real/mirror_small.meshopt.glb", "EXT_meshopt_compression, fallback buffers"),
    ("real/mirror_small.gltfpack-c.glb", "KHR_texture_transform with meshopt"),
    ("blender/sphere.glb", "node hierarchy, skin, joints, morph targets, JPEG"),
    ("blender/sphere_webp.glb", "EXT_texture_webp"),
    ("blender/sphere_draco.glb", "KHR_draco_mesh_compression"),
    ("ktx2_core/quad.gltf", ".gltf with an external buffer and KTX2 image files"),
];

/// Documents made from the fixtures (or from nothing) for what no fixture holds.
fn derived(dir: &Path) -> Vec<(String, &'static str, Source)> {
    let mut bare = Source::read(&fixture("real/mirror_small.glb"));
    // Without materials bake makes one (`Scene::ensure_material`), a path no fixture reaches.
    for k in ["materials", "textures", "images", "samplers"] {
        bare.json.as_object_mut().unwrap().remove(k);
    }
    for m in bare.json["meshes"].as_array_mut().unwrap() {
        for p in m["primitives"].as_array_mut().unwrap() {
            p.as_object_mut().unwrap().remove("material");
        }
    }
    let mut basisu = Source::read(&fixture("ktx2_core/quad.gltf"));
    for t in basisu.json["textures"].as_array_mut().unwrap() {
        let source = t.as_object_mut().unwrap().remove("source").unwrap();
        t["extensions"] = json!({ "KHR_texture_basisu": { "source": source } });
    }
    basisu.json["extensionsUsed"] = json!(["KHR_texture_basisu"]);
    basisu.json["extensionsRequired"] = json!(["KHR_texture_basisu"]);
    vec![
        ("mirror_small.glb without materials".into(), "a scene bake gives a material", bare),
        ("quad.gltf through KHR_texture_basisu".into(), "KHR_texture_basisu", basisu),
        ("synthetic scene".into(), "animations, camera, sparse accessor, variants, anisotropy", synthetic(dir)),
    ]
}

/// A quad with what no fixture has: an animation (node and morph weights), a camera under a
/// child node, a sparse morph target, KHR_materials_variants and KHR_materials_anisotropy.
fn synthetic(dir: &Path) -> Source {
    let mut g = Gltf::new();
    let (pos, nrm, uv, idx) = grid(1);
    let attributes = json!({
        "POSITION": g.floats(&pos, Some(34962)),
        "NORMAL": g.floats(&nrm, Some(34962)),
        "TEXCOORD_0": g.floats(&uv, Some(34962)),
    });
    let indices = g.indices(&idx);
    let tex = g.texture();
    let plain = g.material(json!({ "normalTexture": { "index": tex, "texCoord": 0 } }));
    let aniso = g.material(json!({
        "normalTexture": { "index": tex },
        "extensions": { "KHR_materials_anisotropy": { "anisotropyStrength": 0.5, "anisotropyTexture": { "index": tex } } }
    }));
    let sparse_at = raw_view(&mut g, &2u16.to_le_bytes());
    let sparse_values = raw_view(&mut g, &[0.0f32, 0.0, 0.25].map(f32::to_le_bytes).concat());
    let target = g.push_accessor(json!({
        "componentType": 5126, "count": pos.len(), "type": "VEC3",
        "sparse": { "count": 1, "indices": { "bufferView": sparse_at, "componentType": 5123 }, "values": { "bufferView": sparse_values } }
    }));
    let mesh = g.mesh(json!({
        "attributes": attributes, "indices": indices, "material": plain, "targets": [{ "POSITION": target }],
        "extensions": { "KHR_materials_variants": { "mappings": [{ "material": aniso, "variants": [0] }] } }
    }));
    g.json["meshes"][mesh]["weights"] = json!([0.0]);
    g.json["cameras"] = json!([{ "type": "perspective", "perspective": { "yfov": 0.8, "znear": 0.1 } }]);
    g.json["nodes"].as_array_mut().unwrap().push(json!({ "camera": 0, "translation": [0.0, 0.0, 2.0] }));
    g.json["nodes"][0]["children"] = json!([1]);
    let times = g.floats(&[[0.0], [1.0]], None);
    g.accessor_min_max(times);
    let moves = g.floats(&[[0.0, 0.0, 2.0], [0.0, 0.0, 3.0]], None);
    let weights = g.floats(&[[0.0], [1.0]], None);
    g.json["animations"] = json!([{
        "samplers": [{ "input": times, "output": moves, "interpolation": "LINEAR" }, { "input": times, "output": weights }],
        "channels": [{ "sampler": 0, "target": { "node": 1, "path": "translation" } }, { "sampler": 1, "target": { "node": 0, "path": "weights" } }]
    }]);
    g.json["extensions"] = json!({ "KHR_materials_variants": { "variants": [{ "name": "brushed" }] } });
    g.json["extensionsUsed"] = json!(["KHR_materials_variants", "KHR_materials_anisotropy"]);
    let path = dir.join("synthetic.glb");
    g.write_glb(&path);
    Source::read(&path)
}

/// A buffer view over `bytes` with no target, as sparse accessors want.
fn raw_view(g: &mut Gltf, bytes: &[u8]) -> usize {
    while !g.bin.len().is_multiple_of(4) {
        g.bin.push(0);
    }
    let view = json!({ "buffer": 0, "byteOffset": g.bin.len(), "byteLength": bytes.len() });
    g.bin.extend_from_slice(bytes);
    let views = g.json["bufferViews"].as_array_mut().unwrap();
    views.push(view);
    views.len() - 1
}

/// The mutants per fixture when `BUMPBAKE_MUTANTS` is unset. A budget under the strata of a
/// fixture never drops a stratum: each keeps one mutant whatever the budget.
const DEFAULT_BUDGET: usize = 150;
/// preview takes one input, so a process per mutant: in a sample it sees every stratum's first
/// mutant and one in this many of the others.
const PREVIEW_STRIDE: usize = 3;
/// The normal map `bake --normal` attaches: a scene without a map of its own still gets baked.
const FLAT_PNG: &str = "flat.png";
const DEFAULT_SEED: u64 = 0x6a73_6f6e_2d6d_7574;

/// A process that has not ended after this long is reported as hung (a mutant that loops).
const TIMEOUT: Duration = Duration::from_secs(300);

/// Text that only Rust's `Debug` formatting writes: an error message must never show it.
const DEBUG_TEXT: &[&str] =
    &["Error {", "Some(", "Ok(", "Err(", "Object {", "Array [", "String(\"", "Number(", "Bool(", "panicked"];

#[test]
fn no_json_shape_makes_a_command_panic() {
    let started = Instant::now();
    let (budget, seed) = sampling();
    let root = scratch_dir("json_mutation");
    let mut problems = Vec::new();
    let mut total = 0;
    let mut bases: Vec<(String, &str, Source)> =
        FIXTURES.iter().map(|(rel, covers)| (rel.to_string(), *covers, Source::read(&fixture(rel)))).collect();
    bases.extend(derived(&root));
    for (name, covers, src) in &bases {
        let all = mutants(&src.json);
        let all_count = all.len();
        let strata = all.iter().map(Mutant::stratum).collect::<BTreeSet<_>>().len();
        let chosen = match budget {
            Some(b) => sample(all, b, seed ^ fnv(name)),
            None => all.into_iter().map(|m| Mutant { previewed: true, ..m }).collect(),
        };
        total += chosen.len();
        let previewed = chosen.iter().filter(|m| m.previewed).count();
        println!(
            "{name} ({covers}): {} of {all_count} mutants ({strata} kind x depth strata), {previewed} previewed",
            chosen.len()
        );
        let dir = root.join(name.replace(['/', '.', ' '], "_"));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join(FLAT_PNG), tiny_png()).unwrap();
        let files = src.write_mutants(&dir, &chosen);
        for cmd in Cmd::ALL {
            let t = Instant::now();
            problems.extend(check(cmd, &dir, &files, &chosen, name));
            println!("  {:<15} {:>6.1} s", cmd.name(), t.elapsed().as_secs_f64());
        }
    }
    println!("{total} mutants, {:.1} s", started.elapsed().as_secs_f64());
    assert!(problems.is_empty(), "{} problem(s) over {total} mutants:\n{}", problems.len(), problems.join("\n"));
}

/// The budget per fixture (`None`: every mutant) and the seed.
fn sampling() -> (Option<usize>, u64) {
    let seed = std::env::var("BUMPBAKE_MUTATION_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(DEFAULT_SEED);
    match std::env::var("BUMPBAKE_MUTANTS").as_deref() {
        Ok("all") => (None, seed),
        Ok(n) => (Some(n.parse().expect("BUMPBAKE_MUTANTS is `all` or a number")), seed),
        Err(_) => (Some(DEFAULT_BUDGET), seed),
    }
}

// ---------------------------------------------------------------------------------------------
// Fixtures in and mutants out.

/// A fixture's JSON and what a mutant needs around it to be read the same way: the GLB's binary
/// chunk, or the files a `.gltf` names by relative URI.
struct Source {
    json: Value,
    bin: Option<Vec<u8>>,
    ext: &'static str,
    companions: Vec<PathBuf>,
}

impl Source {
    fn read(path: &Path) -> Source {
        let bytes = std::fs::read(path).unwrap();
        if bytes.starts_with(b"glTF") {
            let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
            let (mut json, mut bin) = (None, None);
            let mut at = 12;
            while at + 8 <= bytes.len() {
                let (len, kind) = (word(at), &bytes[at + 4..at + 8]);
                let chunk = &bytes[at + 8..at + 8 + len];
                match kind {
                    b"JSON" => json = Some(serde_json::from_slice(chunk).unwrap()),
                    b"BIN\0" => bin = Some(chunk.to_vec()),
                    _ => {}
                }
                at += 8 + len;
            }
            Source { json: json.expect("GLB has JSON"), bin, ext: "glb", companions: Vec::new() }
        } else {
            let json: Value = serde_json::from_slice(&bytes).unwrap();
            let dir = path.parent().unwrap();
            let companions = ["buffers", "images"]
                .iter()
                .flat_map(|k| json[*k].as_array().cloned().unwrap_or_default())
                .filter_map(|v| v["uri"].as_str().map(str::to_owned))
                .filter(|u| !u.starts_with("data:"))
                .map(|u| dir.join(u))
                .collect();
            Source { json, bin: None, ext: "gltf", companions }
        }
    }

    /// Writes each mutant as `mNNNN.EXT` in `dir` (a `.gltf`'s companions copied beside them once)
    /// and returns the file names, relative to `dir` to keep the command lines short.
    fn write_mutants(&self, dir: &Path, ms: &[Mutant]) -> Vec<String> {
        for c in &self.companions {
            std::fs::copy(c, dir.join(c.file_name().unwrap())).unwrap();
        }
        ms.iter()
            .enumerate()
            .map(|(i, m)| {
                let name = format!("m{i:04}.{}", self.ext);
                let json = serde_json::to_vec(&m.apply(&self.json)).unwrap();
                let bytes = match &self.bin {
                    Some(bin) => glb(json, bin),
                    None if self.ext == "glb" => glb(json, &[]),
                    None => json,
                };
                std::fs::write(dir.join(&name), bytes).unwrap();
                name
            })
            .collect()
    }
}

fn glb(mut json: Vec<u8>, bin: &[u8]) -> Vec<u8> {
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut bin = bin.to_vec();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    if !bin.is_empty() {
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
    }
    out
}

/// One change to a document: the value at `pointer` becomes `value`.
#[derive(Clone, Debug)]
struct Mutant {
    pointer: String,
    value: Value,
    /// What the change is (`[]`, `emptied`, `index -1`, ...), for sampling and reports.
    kind: &'static str,
    /// The place in the schema, indices generalised: `/meshes/*/primitives/*/material`.
    place: String,
    depth: usize,
    /// Whether preview runs on it (it runs on every mutant of a full run).
    previewed: bool,
}

impl Mutant {
    /// A sample keeps one mutant of each kind of change at each depth.
    fn stratum(&self) -> (&'static str, usize) {
        (self.kind, self.depth)
    }

    fn apply(&self, doc: &Value) -> Value {
        let mut doc = doc.clone();
        *doc.pointer_mut(&self.pointer).expect("pointer found while walking") = self.value.clone();
        doc
    }

    fn describe(&self) -> String {
        let at = if self.pointer.is_empty() { "(the root)" } else { &self.pointer };
        let what = if self.kind == "emptied" { "emptied".to_owned() } else { format!("= {}", self.value) };
        format!("{at} {what}")
    }
}

/// Every mutant of `doc`, in document order.
fn mutants(doc: &Value) -> Vec<Mutant> {
    let mut out = Vec::new();
    walk(doc, doc, &mut Vec::new(), &mut out);
    out
}

/// The shapes every value is replaced by in turn.
fn shapes() -> [(&'static str, Value); 5] {
    [("[]", json!([])), ("{}", json!({})), ("\"x\"", json!("x")), ("1", json!(1)), ("null", Value::Null)]
}

fn walk(root: &Value, v: &Value, path: &mut Vec<String>, out: &mut Vec<Mutant>) {
    let pointer: String = path.iter().map(|s| format!("/{}", s.replace('~', "~0").replace('/', "~1"))).collect();
    let place: String =
        path.iter().map(|s| if s.parse::<usize>().is_ok() { "/*".to_owned() } else { format!("/{s}") }).collect();
    let mut push = |kind: &'static str, value: Value| {
        let (pointer, place, depth) = (pointer.clone(), place.clone(), path.len());
        out.push(Mutant { pointer, value, kind, place, depth, previewed: false });
    };
    for (kind, shape) in shapes() {
        if shape != *v {
            push(kind, shape);
        }
    }
    if v.as_array().is_some_and(|a| !a.is_empty()) {
        push("emptied", json!([]));
    }
    if let Some(count) = v.as_u64().and(index_target(root, path)) {
        push("index -1", json!(-1));
        push("index = count", json!(count));
        push("index 2^32", json!(1u64 << 32));
    }
    match v {
        Value::Object(o) => {
            for (k, c) in o {
                path.push(k.clone());
                walk(root, c, path, out);
                path.pop();
            }
        }
        Value::Array(a) => {
            for (i, c) in a.iter().enumerate() {
                path.push(i.to_string());
                walk(root, c, path, out);
                path.pop();
            }
        }
        _ => {}
    }
}

/// The length of the array an integer at `path` indexes, or `None` when it is not an index.
fn index_target(root: &Value, path: &[String]) -> Option<usize> {
    let len = |v: Option<&Value>| v.and_then(Value::as_array).map_or(0, Vec::len);
    let top = |k: &str| len(root.get(k));
    let key = path.last()?.as_str();
    let up = |n: usize| path.len().checked_sub(n + 1).map(|i| path[i].as_str());
    Some(match key {
        "bufferView" => top("bufferViews"),
        "buffer" => top("buffers"),
        "accessor" | "indices" | "input" | "output" | "inverseBindMatrices" => top("accessors"),
        "source" => top("images"),
        // An animation channel's sampler is one of its animation's own.
        "sampler" if path[0] == "animations" => len(root.pointer(&format!("/animations/{}/samplers", path[1]))),
        "sampler" => top("samplers"),
        "index" => top("textures"),
        "material" => top("materials"),
        "mesh" => top("meshes"),
        "node" | "skeleton" => top("nodes"),
        "skin" => top("skins"),
        "camera" => top("cameras"),
        "scene" => top("scenes"),
        "texCoord" => texcoord_sets(root),
        _ if up(1) == Some("attributes") || up(2) == Some("targets") => top("accessors"),
        _ if matches!(up(1), Some("nodes" | "children" | "joints")) => top("nodes"),
        _ if up(1) == Some("variants") => len(root.pointer("/extensions/KHR_materials_variants/variants")),
        _ => return None,
    })
}

/// The most `TEXCOORD_n` sets any primitive has: the first `texCoord` no primitive can serve.
fn texcoord_sets(root: &Value) -> usize {
    let prims = root["meshes"].as_array().into_iter().flatten().flat_map(|m| m["primitives"].as_array()).flatten();
    prims
        .filter_map(|p| p["attributes"].as_object())
        .map(|a| a.keys().filter(|k| k.starts_with("TEXCOORD_")).count())
        .max()
        .unwrap_or(0)
}

/// A seeded sample of `budget` mutants (more when there are more strata), in document order:
/// first one of every kind at every depth, then one of every kind at every place in the schema
/// while the budget lasts, then any. preview gets the first tier and a stride of the rest.
fn sample(all: Vec<Mutant>, budget: usize, seed: u64) -> Vec<Mutant> {
    let mut rng = SplitMix(seed);
    let mut order: Vec<usize> = (0..all.len()).collect();
    for i in (1..order.len()).rev() {
        order.swap(i, (rng.next() % (i as u64 + 1)) as usize);
    }
    let (mut strata, mut spots) = (BTreeSet::new(), BTreeSet::new());
    let mut tiers = [Vec::new(), Vec::new(), Vec::new()];
    for i in order {
        let m = &all[i];
        let new_spot = spots.insert((m.kind, &m.place));
        let tier = if strata.insert(m.stratum()) {
            0
        } else if new_spot {
            1
        } else {
            2
        };
        tiers[tier].push(i);
    }
    let first = tiers[0].len();
    let mut chosen: Vec<(usize, bool)> = tiers.concat().into_iter().enumerate().map(|(n, i)| (i, n < first)).collect();
    chosen.truncate(budget.max(first));
    chosen.sort_unstable();
    chosen
        .into_iter()
        .enumerate()
        .map(|(n, (i, core))| Mutant { previewed: core || n % PREVIEW_STRIDE == 0, ..all[i].clone() })
        .collect()
}

/// A small seeded generator, so that a sample is the same on every machine and run.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
}

/// Gives each fixture its own sample from one seed.
fn fnv(s: &str) -> u64 {
    s.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3))
}

// ---------------------------------------------------------------------------------------------
// Running the commands and judging what they did.

#[derive(Clone, Copy, Debug, PartialEq)]
enum Cmd {
    Inspect,
    Validate,
    Tangents,
    TangentsAll,
    Bake,
    BakeNormal,
    Preview,
}

impl Cmd {
    const ALL: [Cmd; 7] =
        [Cmd::Inspect, Cmd::Validate, Cmd::Tangents, Cmd::TangentsAll, Cmd::Bake, Cmd::BakeNormal, Cmd::Preview];

    fn name(self) -> &'static str {
        match self {
            Cmd::Inspect => "inspect",
            Cmd::Validate => "validate",
            Cmd::Tangents => "tangents",
            Cmd::TangentsAll => "tangents --all",
            Cmd::Bake => "bake",
            Cmd::BakeNormal => "bake --normal",
            Cmd::Preview => "preview",
        }
    }

    /// The command line over `files`; `preview` takes one input, so it is given one at a time.
    fn args(self, files: &[String], out: &str) -> Vec<String> {
        let mut a: Vec<String> = match self {
            Cmd::Inspect => vec!["inspect".into(), "--json".into()],
            Cmd::Validate => ["validate", "--format", "json", "-q", "-j", "2"].map(String::from).to_vec(),
            Cmd::Tangents => ["tangents", "--json", "-j", "2", "--out-dir", out].map(String::from).to_vec(),
            Cmd::TangentsAll => ["tangents", "--all", "--json", "-j", "2", "--out-dir", out].map(String::from).to_vec(),
            Cmd::Bake => ["bake", "--json", "-j", "2", "--out-dir", out].map(String::from).to_vec(),
            Cmd::BakeNormal => {
                ["bake", "--normal", FLAT_PNG, "--json", "-j", "2", "--out-dir", out].map(String::from).to_vec()
            }
            Cmd::Preview => {
                assert_eq!(files.len(), 1, "preview takes one input");
                let png = format!("{out}/{}.png", files[0]);
                ["preview", "--size", "12x12", "--json", "-q", "-o", &png].map(String::from).to_vec()
            }
        };
        a.extend(files.iter().cloned());
        a
    }

    fn allowed(self, code: i32) -> bool {
        code == 0 || code == 2 || (self == Cmd::Validate && code == 1)
    }

    fn out_dir(self) -> String {
        format!("out-{}", self.name().replace(" --", "-"))
    }
}

/// Runs `cmd` over the mutants in `dir` and returns what is wrong, each problem naming the
/// fixture, the command and, for a crash, the mutant that caused it.
fn check(cmd: Cmd, dir: &Path, files: &[String], ms: &[Mutant], rel: &str) -> Vec<String> {
    let out = cmd.out_dir();
    std::fs::create_dir_all(dir.join(&out)).unwrap();
    let mut problems = Vec::new();
    if cmd == Cmd::Preview {
        // One process per mutant, two at a time (the batch commands run with -j 2 too).
        let next = std::sync::atomic::AtomicUsize::new(0);
        let found = std::sync::Mutex::new(Vec::new());
        std::thread::scope(|s| {
            for _ in 0..2 {
                s.spawn(|| loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some(f) = files.get(i) else { break };
                    if !ms[i].previewed {
                        continue;
                    }
                    let run = run_in(dir, &cmd.args(std::slice::from_ref(f), &out), false);
                    if let Some(crash) = crash(cmd, &run) {
                        let site = panic_site(&run_in(dir, &cmd.args(std::slice::from_ref(f), &out), true));
                        found.lock().unwrap().push(culprit(rel, cmd, &ms[i], &crash, &site));
                    } else if let Some(p) = judge_preview(&run) {
                        found.lock().unwrap().push(format!("{rel}: preview: {}: {p}", ms[i].describe()));
                    }
                });
            }
        });
        let mut found = found.into_inner().unwrap();
        found.sort();
        return found;
    }
    let mut files: Vec<String> = files.to_vec();
    let mut run = run_in(dir, &cmd.args(&files, &out), false);
    if crash(cmd, &run).is_some() {
        let mut idx: Vec<usize> = (0..files.len()).collect();
        let found = culprits(cmd, dir, &files, &mut idx, &out);
        if found.is_empty() {
            return vec![format!("{rel}: {}: the batch crashed but no single mutant does", cmd.name())];
        }
        let crashed: BTreeSet<usize> = found.iter().map(|(i, ..)| *i).collect();
        problems.extend(found.iter().map(|(i, crash, site)| culprit(rel, cmd, &ms[*i], crash, site)));
        // The others still owe their records: the batch runs again without the crashing ones.
        files = files.into_iter().enumerate().filter(|(i, _)| !crashed.contains(i)).map(|(_, f)| f).collect();
        run = run_in(dir, &cmd.args(&files, &out), false);
        if let Some(c) = crash(cmd, &run) {
            problems.push(format!("{rel}: {}: the batch crashed again without its crashing mutants: {c}", cmd.name()));
            return problems;
        }
    }
    let judged = match cmd {
        Cmd::Validate => judge_validate(&run, &files),
        _ => judge_records(cmd, &run, &files),
    };
    problems.extend(judged.into_iter().map(|p| format!("{rel}: {}: {p}", cmd.name())));
    problems
}

fn culprit(rel: &str, cmd: Cmd, m: &Mutant, crash: &str, site: &str) -> String {
    format!("{rel}: {}: {}: {crash}; {site}", cmd.name(), m.describe())
}

/// The mutants among `idx` on which `cmd` crashes, found by halving: a crash in a batch stops
/// it, so one run cannot tell which file did it, and per-file runs only happen on failure.
fn culprits(cmd: Cmd, dir: &Path, files: &[String], idx: &mut [usize], out: &str) -> Vec<(usize, String, String)> {
    let names: Vec<String> = idx.iter().map(|&i| files[i].clone()).collect();
    let run = run_in(dir, &cmd.args(&names, out), idx.len() == 1);
    let Some(crash) = crash(cmd, &run) else { return Vec::new() };
    if idx.len() == 1 {
        return vec![(idx[0], crash, panic_site(&run))];
    }
    let (a, b) = idx.split_at_mut(idx.len() / 2);
    let mut found = culprits(cmd, dir, files, a, out);
    found.extend(culprits(cmd, dir, files, b, out));
    found
}

/// Why a run counts as a crash (a panic, a signal, a hang, an exit code outside the contract).
fn crash(cmd: Cmd, run: &Run) -> Option<String> {
    let stderr = String::from_utf8_lossy(&run.out.stderr);
    if run.hung {
        return Some(format!("still running after {} s", TIMEOUT.as_secs()));
    }
    match run.out.status.code() {
        None => Some(format!("killed by a signal ({})", run.out.status)),
        Some(c) if !cmd.allowed(c) || stderr.contains("panicked") => {
            let msg = stderr.lines().skip_while(|l| !l.contains("panicked at")).take(2).collect::<Vec<_>>().join(" ");
            Some(if msg.is_empty() { format!("exit {c}: {}", last_line(&stderr)) } else { format!("exit {c}: {msg}") })
        }
        Some(_) => None,
    }
}

/// The first frame of this crate in a panic's backtrace: where a fix goes, when the panic itself
/// is raised inside a dependency (serde_json's `Index`, slice indexing).
fn panic_site(run: &Run) -> String {
    let stderr = String::from_utf8_lossy(&run.out.stderr);
    let mut function = "";
    for l in stderr.lines().map(str::trim) {
        if let Some(at) = l.strip_prefix("at ") {
            let here = at.strip_prefix(env!("CARGO_MANIFEST_DIR")).unwrap_or(at).trim_start_matches(['.', '/']);
            if here.starts_with("src/") && !function.is_empty() {
                return format!("first bumpbake frame {function} at {here}");
            }
        } else if let Some((n, f)) = l.split_once(": ") {
            if n.chars().all(|c| c.is_ascii_digit()) {
                function = f;
            }
        }
    }
    "no bumpbake frame in the backtrace".into()
}

/// The JSON Lines contract of a batch: one record per input in input order, errors as one line
/// of plain words, and the exit code saying whether any failed.
fn judge_records(cmd: Cmd, run: &Run, files: &[String]) -> Vec<String> {
    let stdout = String::from_utf8_lossy(&run.out.stdout);
    let lines: Vec<&str> = stdout.lines().collect();
    if lines.len() != files.len() {
        return vec![format!("{} records for {} inputs", lines.len(), files.len())];
    }
    let mut problems = Vec::new();
    let mut errors = 0;
    // inspect names its input `file`, the others `input` (docs/json.md).
    let input_key = if cmd == Cmd::Inspect { "file" } else { "input" };
    for (line, file) in lines.iter().zip(files) {
        let Ok(r) = serde_json::from_str::<Value>(line) else {
            problems.push(format!("{file}: record is not JSON: {line}"));
            continue;
        };
        if r[input_key].as_str() != Some(file.as_str()) {
            problems.push(format!("{file}: record for {} out of order", r[input_key]));
        }
        if r["status"] == "error" {
            errors += 1;
            match r["error"].as_str() {
                Some(e) => problems.extend(words(e).map(|p| format!("{file}: error record {p}"))),
                None => problems.push(format!("{file}: error record without an error: {line}")),
            }
            if r["exit_code"] != 2 {
                problems.push(format!("{file}: error record with exit_code {}", r["exit_code"]));
            }
        }
    }
    let expected = if errors > 0 { 2 } else { 0 };
    if run.out.status.code() != Some(expected) {
        problems.push(format!("exit {:?} with {errors} error record(s)", run.out.status.code()));
    }
    problems
}

/// validate prints one document for the files it could check and a `bumpbake: ` line on stderr
/// for each it could not; between them every input is accounted for.
fn judge_validate(run: &Run, files: &[String]) -> Vec<String> {
    let doc: Value = match serde_json::from_slice(&run.out.stdout) {
        Ok(d) => d,
        Err(e) => return vec![format!("stdout is not one JSON document: {e}")],
    };
    let stderr = String::from_utf8_lossy(&run.out.stderr);
    let unusable: Vec<&str> = stderr.lines().collect();
    let checked = doc["files"].as_array().map_or(0, Vec::len);
    let mut problems = Vec::new();
    if checked + unusable.len() != files.len() {
        problems.push(format!("{checked} files checked and {} unusable of {} inputs", unusable.len(), files.len()));
    }
    for l in &unusable {
        match l.strip_prefix("bumpbake: ") {
            Some(e) => problems.extend(words(e).map(|p| format!("unusable-file line {p}"))),
            None => problems.push(format!("stderr line not of the form `bumpbake: FILE: problem`: {l}")),
        }
    }
    let code = run.out.status.code();
    if !unusable.is_empty() && code != Some(2) {
        problems.push(format!("exit {code:?} with {} unusable file(s)", unusable.len()));
    }
    problems
}

/// preview's one document, or one error line on stderr.
fn judge_preview(run: &Run) -> Option<String> {
    let stderr = String::from_utf8_lossy(&run.out.stderr);
    match run.out.status.code() {
        Some(0) => serde_json::from_slice::<Value>(&run.out.stdout).err().map(|e| format!("report is not JSON: {e}")),
        _ => match stderr.trim_end().strip_prefix("bumpbake: ") {
            Some(e) => words(e).next(),
            None => Some(format!("stderr is not one `bumpbake: ` line: {stderr:?}")),
        },
    }
}

/// What is wrong with an error message as a person reads it: several lines, or Debug output.
fn words(e: &str) -> impl Iterator<Item = String> + '_ {
    let lines = e.contains('\n').then(|| format!("spans lines: {e:?}"));
    let debug = DEBUG_TEXT.iter().find(|d| e.contains(*d)).map(|d| format!("shows Rust debug text `{d}`: {e}"));
    lines.into_iter().chain(debug)
}

fn last_line(s: &str) -> &str {
    s.lines().last().unwrap_or("")
}

struct Run {
    out: Output,
    hung: bool,
}

/// Runs the binary in `dir`, killing it after [`TIMEOUT`]; with a backtrace when `backtrace`.
fn run_in(dir: &Path, args: &[String], backtrace: bool) -> Run {
    let mut c: Command = bin();
    c.current_dir(dir).args(args).env("RUST_BACKTRACE", if backtrace { "1" } else { "0" }).env_remove("CI");
    c.stdin(Stdio::null()).stdout(Stdio::piped()).stderr(Stdio::piped());
    let mut child = c.spawn().expect("bumpbake runs");
    // Pipes are drained on threads so a chatty child never blocks on a full pipe while we wait.
    let mut so = child.stdout.take().unwrap();
    let mut se = child.stderr.take().unwrap();
    let so = std::thread::spawn(move || {
        let mut b = Vec::new();
        so.read_to_end(&mut b).ok();
        b
    });
    let se = std::thread::spawn(move || {
        let mut b = Vec::new();
        se.read_to_end(&mut b).ok();
        b
    });
    let start = Instant::now();
    let mut hung = false;
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > TIMEOUT {
            hung = true;
            child.kill().ok();
            break child.wait().unwrap();
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    Run { out: Output { status, stdout: so.join().unwrap(), stderr: se.join().unwrap() }, hung }
}

/// Keeps the per-kind totals honest: every kind of change exists in the full set of some
/// fixture, so no kind silently stops being generated.
#[test]
fn every_kind_of_change_is_generated() {
    let mut kinds: BTreeMap<&str, usize> = BTreeMap::new();
    for (rel, _) in FIXTURES {
        for m in mutants(&Source::read(&fixture(rel)).json) {
            *kinds.entry(m.kind).or_default() += 1;
        }
    }
    let expected = ["\"x\"", "1", "[]", "emptied", "index -1", "index 2^32", "index = count", "null", "{}"];
    assert_eq!(kinds.keys().copied().collect::<Vec<_>>(), expected, "{kinds:?}");
}

/// A sample keeps one mutant of every stratum and is the same from one run to the next.
#[test]
fn sampling_is_seeded_and_keeps_every_stratum() {
    let doc = Source::read(&fixture("blender/sphere.glb")).json;
    let all = mutants(&doc);
    let strata: BTreeSet<_> = all.iter().map(Mutant::stratum).collect();
    let spots: BTreeSet<_> = all.iter().map(|m| (m.kind, m.place.clone())).collect();
    let a = sample(all.clone(), 10, 7);
    let b = sample(all.clone(), 10, 7);
    assert_eq!(a.iter().map(Mutant::describe).collect::<Vec<_>>(), b.iter().map(Mutant::describe).collect::<Vec<_>>());
    assert_eq!(a.iter().map(Mutant::stratum).collect::<BTreeSet<_>>(), strata);
    assert_eq!(a.len(), strata.len(), "a budget under the strata count takes one per stratum");
    assert!(a.iter().all(|m| m.previewed), "preview sees every stratum");
    // A budget as large as the places gets to every place before it repeats one.
    let wide = sample(all.clone(), spots.len(), 7);
    let reached: BTreeSet<_> = wide.iter().map(|m| (m.kind, m.place.clone())).collect();
    assert_eq!(reached.len(), spots.len(), "{:?}", spots.difference(&reached).collect::<Vec<_>>());
    assert_eq!(sample(all.clone(), all.len() + 5, 7).len(), all.len());
    // The index changes know their targets: the sphere's skin has 2 joints among 4 nodes.
    let joint = all.iter().find(|m| m.pointer == "/skins/0/joints/0" && m.kind == "index = count").unwrap();
    assert_eq!(joint.value, json!(doc["nodes"].as_array().unwrap().len()));
    assert_eq!(joint.value, 4);
}
