//! The hostile-input campaign that admitted `draco-core` (docs/dependencies.md): every Draco stream
//! at hand (`fuzz/seeds/draco_decode/`: glTF-Transform's and Blender's), truncated and bit-flipped
//! in a fixed sequence, must be decoded or refused: never a panic, never a hang. The same mutations
//! then go through the whole glTF reader inside each file the streams came from, so the glue that
//! checks the decoded data against the accessors is held to the same rule.

mod common;
use common::{run_ok, s, validated_dir};
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// Per stream; `BUMPBAKE_DRACO_MUTANTS` asks for a longer run.
fn mutants() -> usize {
    std::env::var("BUMPBAKE_DRACO_MUTANTS").ok().and_then(|v| v.parse().ok()).unwrap_or(400)
}
/// Far above the slowest mutant measured (a few ms in a debug build): only a hang reaches it.
const HANG: Duration = Duration::from_secs(20);

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn seeds() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join("fuzz/seeds/draco_decode"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "drc"))
        .collect();
    v.sort();
    assert!(v.len() >= 5, "{v:?}");
    v
}

/// The i-th mutant of `src`: even ones truncated (lengths spread over the whole stream, the first
/// bytes more densely), odd ones with 1 to 8 bits flipped, from a seeded xorshift.
fn mutant(src: &[u8], i: usize, rng: &mut u64) -> Vec<u8> {
    let mut next = || {
        *rng ^= *rng << 13;
        *rng ^= *rng >> 7;
        *rng ^= *rng << 17;
        *rng as usize
    };
    let mut b = src.to_vec();
    if i.is_multiple_of(2) {
        let k = i / 2;
        let len = if k < 40 { k } else { next() % b.len() };
        b.truncate(len);
    } else {
        for _ in 0..1 + next() % 8 {
            let at = next() % b.len();
            b[at] ^= 1 << (next() % 8);
        }
    }
    b
}

#[derive(Default, Debug)]
struct Tally {
    ok: usize,
    error: usize,
    panic: usize,
    slowest: Duration,
}

/// Runs `f` on every mutant of `src` on a worker thread, counting outcomes; a mutant that takes
/// longer than [`HANG`] fails the test naming it.
fn campaign(
    name: &str,
    src: Vec<u8>,
    f: impl Fn(&[u8]) -> Result<(), String> + Send + 'static,
) -> (Tally, Vec<String>) {
    let n = mutants();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let mut rng = 0x9E37_79B9_7F4A_7C15u64 ^ src.len() as u64;
        for i in 0..n {
            let b = mutant(&src, i, &mut rng);
            let t = Instant::now();
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| f(&b)));
            if tx.send((i, r.map_err(|_| ()), t.elapsed())).is_err() {
                return;
            }
        }
    });
    let mut tally = Tally::default();
    let mut panics = Vec::new();
    for _ in 0..n {
        let (i, r, took) =
            rx.recv_timeout(HANG).unwrap_or_else(|_| panic!("{name}: a mutant ran longer than {HANG:?} (a hang)"));
        tally.slowest = tally.slowest.max(took);
        match r {
            Ok(Ok(())) => tally.ok += 1,
            Ok(Err(e)) => {
                assert!(!e.is_empty() && !e.contains('\n'), "{name} mutant {i}: {e:?}");
                tally.error += 1;
            }
            Err(()) => {
                tally.panic += 1;
                panics.push(format!("{name} mutant {i}"));
            }
        }
    }
    (tally, panics)
}

#[test]
fn mutated_draco_streams_are_decoded_or_refused() {
    let mut all_panics = Vec::new();
    for f in seeds() {
        let name = f.file_name().unwrap().to_str().unwrap().to_string();
        let src = std::fs::read(&f).unwrap();
        let t = Instant::now();
        let (points, faces) = bumpbake::format::gltf::draco::decode_and_read(&src).unwrap();
        let whole = t.elapsed();
        let (tally, panics) = campaign(&name, src, |b| {
            bumpbake::format::gltf::draco::decode_and_read(b).map(|_| ()).map_err(|e| e.to_string())
        });
        eprintln!("{name}: {points} points, {faces} faces, decoded in {whole:?}; {} mutants: {tally:?}", mutants());
        assert_eq!(tally.ok + tally.error + tally.panic, mutants());
        assert!(tally.error > mutants() / 4, "{name}: most truncations must be refused: {tally:?}");
        all_panics.extend(panics);
    }
    assert!(all_panics.is_empty(), "draco-core panicked on: {all_panics:?}");
}

/// A GLB with the bytes of its first Draco stream's buffer view replaced by `stream`.
struct Glb {
    json: serde_json::Value,
    bin: Vec<u8>,
    view: usize,
}

impl Glb {
    fn read(path: &Path) -> Glb {
        let b = std::fs::read(path).unwrap();
        let n = u32::from_le_bytes(b[12..16].try_into().unwrap()) as usize;
        let json: serde_json::Value = serde_json::from_slice(&b[20..20 + n]).unwrap();
        let m = u32::from_le_bytes(b[20 + n..24 + n].try_into().unwrap()) as usize;
        let bin = b[28 + n..28 + n + m].to_vec();
        let view = json
            .pointer("/meshes/0/primitives/0/extensions/KHR_draco_mesh_compression/bufferView")
            .and_then(|v| v.as_u64())
            .unwrap() as usize;
        Glb { json, bin, view }
    }

    fn stream(&self) -> Vec<u8> {
        let v = &self.json["bufferViews"][self.view];
        let off = v["byteOffset"].as_u64().unwrap_or(0) as usize;
        self.bin[off..off + v["byteLength"].as_u64().unwrap() as usize].to_vec()
    }

    /// The file with `stream` appended to the binary chunk and the view pointed at it.
    fn with(&self, stream: &[u8]) -> Vec<u8> {
        let mut json = self.json.clone();
        let mut bin = self.bin.clone();
        bin.resize(bin.len().next_multiple_of(4), 0);
        json["bufferViews"][self.view]["byteOffset"] = bin.len().into();
        json["bufferViews"][self.view]["byteLength"] = stream.len().into();
        bin.extend_from_slice(stream);
        bin.resize(bin.len().next_multiple_of(4), 0);
        json["buffers"][0]["byteLength"] = bin.len().into();
        let mut j = serde_json::to_vec(&json).unwrap();
        j.resize(j.len().next_multiple_of(4), b' ');
        common::glb_bytes(&j, &bin)
    }
}

#[test]
fn mutated_draco_streams_inside_their_files_are_read_or_refused_in_one_line() {
    let files = [
        "fixtures/real/mirror_small.draco.glb",
        "fixtures/blender/sphere_draco.glb",
        "fixtures/blender_scene/plain/torus_low_draco.glb",
    ];
    let mut all_panics = Vec::new();
    for f in files {
        let glb = std::sync::Arc::new(Glb::read(&root().join(f)));
        // The file rebuilt around its own stream reads as the original does.
        let opts = bumpbake::scene::ReadOptions::default();
        let path = Path::new("/nonexistent-bumpbake/in.glb");
        bumpbake::format::read_bytes(path, &glb.with(&glb.stream()), &opts).unwrap();
        let g = glb.clone();
        let (tally, panics) = campaign(f, glb.stream(), move |b| {
            let path = Path::new("/nonexistent-bumpbake/in.glb");
            let scene =
                bumpbake::format::read_bytes(path, &g.with(b), &Default::default()).map_err(|e| e.to_string())?;
            for r in scene.primitives() {
                scene.primitive(r).map_err(|e| e.to_string())?;
            }
            Ok(())
        });
        eprintln!("{f}: {} mutants through the reader: {tally:?}", mutants());
        assert!(tally.error > mutants() / 4, "{f}: {tally:?}");
        all_panics.extend(panics);
    }
    assert!(all_panics.is_empty(), "the reader panicked on: {all_panics:?}");
}

#[test]
fn a_broken_stream_is_one_line_naming_the_file_and_the_primitive() {
    let glb = Glb::read(&root().join("fixtures/real/mirror_small.draco.glb"));
    let stream = glb.stream();
    let path = Path::new("/nonexistent-bumpbake/broken.glb");
    let e = bumpbake::format::read_bytes(path, &glb.with(&stream[..stream.len() / 2]), &Default::default())
        .err()
        .unwrap()
        .to_string();
    assert!(e.starts_with("/nonexistent-bumpbake/broken.glb: mesh 0 primitive 0: "), "{e}");
    assert!(e.contains("KHR_draco_mesh_compression stream could not be decoded ("), "{e}");
    assert!(!e.contains('\n') && !e.contains("Some(") && !e.contains("{ "), "{e}");
}

/// `mirror_small.draco.glb` with its JSON changed by `f`, read.
fn read_changed(f: impl FnOnce(&mut serde_json::Value)) -> Result<bumpbake::scene::Scene, String> {
    let mut glb = Glb::read(&root().join("fixtures/real/mirror_small.draco.glb"));
    f(&mut glb.json);
    let stream = glb.stream();
    let path = Path::new("/nonexistent-bumpbake/changed.glb");
    bumpbake::format::read_bytes(path, &glb.with(&stream), &Default::default()).map_err(|e| e.to_string())
}

fn positions(scene: &bumpbake::scene::Scene, primitive: usize) -> Vec<[f32; 3]> {
    scene.primitive(bumpbake::scene::PrimRef { mesh: 0, primitive }).unwrap().positions()
}

#[test]
fn decoded_counts_and_types_must_match_the_accessors() {
    let e = read_changed(|j| {
        let pos = j["meshes"][0]["primitives"][0]["attributes"]["POSITION"].as_u64().unwrap() as usize;
        j["accessors"][pos]["count"] = 300.into();
    })
    .err()
    .unwrap();
    assert!(e.contains("mesh 0 primitive 0: KHR_draco_mesh_compression: the stream decodes 310 points"), "{e}");
    let e = read_changed(|j| {
        let uv = j["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"].as_u64().unwrap() as usize;
        j["accessors"][uv]["componentType"] = 5123.into();
        j["accessors"][uv]["normalized"] = true.into();
    })
    .err()
    .unwrap();
    assert!(e.contains("TEXCOORD_0") && e.contains("holds floats"), "{e}");
    let e = read_changed(|j| {
        let i = j["meshes"][0]["primitives"][0]["indices"].as_u64().unwrap() as usize;
        j["accessors"][i]["count"] = 3.into();
    })
    .err()
    .unwrap();
    assert!(e.contains("could not be decoded") || e.contains("triangles"), "{e}");
}

#[test]
fn primitives_sharing_accessors_or_without_indices_read_as_the_original() {
    let plain = read_changed(|_| {}).unwrap();
    let want = positions(&plain, 0);
    let triangles = plain.primitive(bumpbake::scene::PrimRef { mesh: 0, primitive: 0 }).unwrap().indices.len();
    // A second primitive with the same stream and accessors: the accessors are shared, not doubled.
    let twice = read_changed(|j| {
        let p = j["meshes"][0]["primitives"][0].clone();
        j["meshes"][0]["primitives"].as_array_mut().unwrap().push(p);
    })
    .unwrap();
    assert_eq!(positions(&twice, 0), want);
    assert_eq!(positions(&twice, 1), want);
    assert_eq!(twice.json["accessors"].as_array().unwrap().len(), plain.json["accessors"].as_array().unwrap().len());
    // No indices accessor: one is made from the decoded faces.
    let unindexed = read_changed(|j| {
        j["meshes"][0]["primitives"][0].as_object_mut().unwrap().remove("indices");
    })
    .unwrap();
    let p = unindexed.primitive(bumpbake::scene::PrimRef { mesh: 0, primitive: 0 }).unwrap();
    assert_eq!((p.positions(), p.indices.len()), (want, triangles));
    assert!(!unindexed.json.to_string().contains("KHR_draco_mesh_compression"));
}

#[test]
fn bake_from_reads_a_draco_low_and_high_and_writes_the_same_counts_as_the_plain_pair() {
    let d = validated_dir("draco_bake_from");
    let plain = root().join("fixtures/blender_scene/plain");
    let mut verts = Vec::new();
    for (low, high, out) in
        [("torus_low_draco.glb", "torus_high_draco.glb", "draco.glb"), ("torus_low.glb", "torus_high.glb", "plain.glb")]
    {
        let out = d.join(out);
        let (low, high) = (plain.join(low), plain.join(high));
        run_ok(&["bake", s(&low), "--from", s(&high), "-o", s(&out), "--size", "64", "-q"]);
        let scene = bumpbake::format::read(&out, &Default::default()).unwrap();
        assert!(!scene.json.to_string().contains("KHR_draco_mesh_compression"));
        let p = scene.primitive(bumpbake::scene::PrimRef { mesh: 0, primitive: 0 }).unwrap();
        assert!(p.attr("TANGENT").is_some(), "{}", out.display());
        verts.push(p.indices.len());
    }
    assert_eq!(verts[0], verts[1], "the Draco LOW decodes to the plain LOW's triangles");
}
