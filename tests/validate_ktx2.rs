//! `validate` on KTX2 normal maps' mip chains (docs/validate.md, "Mip chains"): a chain made as
//! bumpbake makes it reports none of the chain codes; one filtered without renormalising, one
//! without mips, one with a level turned, and a material whose roughness ignores the map's
//! variance each report theirs. Every KTX2 written here goes to `ktx2_dir`, where CI has the
//! Basis Universal command-line tool read it (tests/ktx2_reference.rs).

mod common;
mod validate_support;
use bumpbake::format::image::ktx2::{self, Codec, Level};
use bumpbake::normalmap::{mips, specular_aa};
use common::*;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use validate_support::*;

const CHAIN_CODES: [&str; 4] =
    ["NORMALMAP_MIPS_MISSING", "NORMALMAP_MIPS_NOT_UNIT", "NORMALMAP_MIPS_DIRECTION", "ROUGHNESS_MIPS_NOT_WIDENED"];

/// A bumpy map: egg-crate relief of period ~30 texels with a diagonal ripple, tilts up to ~50°.
fn bumpy_map(n: u32) -> image::RgbImage {
    normal_map(n, n, 1.0, false, |x, y| 4.0 * (x / 5.0).sin() * (y / 4.0).cos() + 1.5 * ((x + y) / 3.0).sin())
}

/// The chain as bumpbake builds it: every level from the level-0 unit normals, renormalised.
fn good_chain(img: &image::RgbImage) -> Vec<mips::MipLevel> {
    let (w, h) = (img.width() as usize, img.height() as usize);
    mips::build_rgb(img.as_raw(), w, h)
}

fn encode_levels(levels: &[(usize, usize, Vec<u8>)], codec: Codec) -> Vec<u8> {
    let l: Vec<Level> =
        levels.iter().map(|(w, h, rgb)| Level { width: *w as u32, height: *h as u32, rgb: rgb.as_slice() }).collect();
    ktx2::encode(&l, codec, 1).unwrap()
}

fn uastc(chain: &[mips::MipLevel]) -> Vec<u8> {
    let l: Vec<_> = chain.iter().map(|l| (l.width, l.height, l.rgb.clone())).collect();
    encode_levels(&l, Codec::Uastc { level: 2, rdo: None })
}

/// Writes a KTX2 where CI's reference check reads it, and returns its bytes back.
fn keep(dir: &Path, name: &str, bytes: Vec<u8>) -> Vec<u8> {
    std::fs::write(dir.join(name), &bytes).unwrap();
    bytes
}

/// A grid with tangents whose material's normal texture is `normal` (KTX2 through
/// KHR_texture_basisu), roughness `roughness`, and its metallicRoughness texture `mr` if given.
fn material_gltf(dir: &Path, name: &str, normal: &[u8], roughness: f64, mr: Option<&[u8]>) -> PathBuf {
    let mut g = Gltf::new();
    let p = grid_prim();
    let attrs = attrs_of(&mut g, &p);
    let i = g.indices(&p.idx);
    let basisu = |bytes: &[u8]| json!({ "uri": data_uri("image/ktx2", bytes) });
    let mut images = vec![basisu(normal)];
    let mut textures = vec![json!({ "extensions": { "KHR_texture_basisu": { "source": 0 } } })];
    let mut pbr = json!({ "roughnessFactor": roughness, "metallicFactor": 0.0 });
    if let Some(mr) = mr {
        images.push(basisu(mr));
        textures.push(json!({ "extensions": { "KHR_texture_basisu": { "source": 1 } } }));
        pbr["metallicRoughnessTexture"] = json!({ "index": 1 });
    }
    g.json["images"] = Value::from(images);
    g.json["textures"] = Value::from(textures);
    g.json["extensionsUsed"] = json!(["KHR_texture_basisu"]);
    g.json["extensionsRequired"] = json!(["KHR_texture_basisu"]);
    let m = g.material(json!({ "name": "bumps", "normalTexture": { "index": 0 }, "pbrMetallicRoughness": pbr }));
    g.mesh(json!({ "attributes": attrs, "indices": i, "material": m }));
    g.write_gltf(dir, name)
}

/// The chain codes the report holds, and the image subject's checks.
fn chain_findings(r: &Value) -> (Vec<String>, Vec<String>) {
    let found = findings(r).into_iter().map(|(c, _)| c).filter(|c| CHAIN_CODES.contains(&c.as_str())).collect();
    let image = r["files"][0]["subjects"].as_array().unwrap().iter().find(|s| s["kind"] == "image").unwrap();
    let checks = image["checks"].as_array().unwrap().iter().map(|c| c.as_str().unwrap().to_string()).collect();
    (found, checks)
}

fn levels_named(f: &Value) -> Vec<u64> {
    f["examples"].as_array().unwrap().iter().map(|e| e["index"].as_u64().unwrap()).collect()
}

/// bumpbake's own chains, UASTC and ETC1S, at 256² and at the 128² of `normalmap`'s output:
/// nothing to report, and the chain checks ran.
#[test]
fn bumpbake_chains_report_none_of_the_chain_codes() {
    let d = scratch_dir("validate_ktx2_good");
    let k = ktx2_dir("validate_ktx2_good");
    let chain = good_chain(&bumpy_map(256));
    let etc1s = {
        let l: Vec<_> = chain.iter().map(|l| (l.width, l.height, l.rgb.clone())).collect();
        encode_levels(&l, Codec::Etc1s { quality: 128 })
    };
    let out = k.join("normalmap.ktx2");
    run_ok(&["normalmap", s(&fixture("bake/bumps.png")), "-o", s(&out), "--strength", "4", "-q"]);
    for (name, bytes) in [
        ("uastc", keep(&k, "good.uastc.ktx2", uastc(&chain))),
        ("etc1s", keep(&k, "good.etc1s.ktx2", etc1s)),
        ("normalmap", std::fs::read(&out).unwrap()),
    ] {
        let path = material_gltf(&d, name, &bytes, 1.0, None);
        let (code, r) = validate(&[s(&path)]);
        let (found, checks) = chain_findings(&r);
        assert!(found.is_empty(), "{name}: {found:?}\n{r:#}");
        for c in &CHAIN_CODES[..3] {
            assert!(checks.contains(&c.to_string()), "{name}: {c} did not run: {checks:?}");
        }
        assert_eq!(code, 0, "{name}: {r:#}");
    }
}

/// The Basis Universal tool's own chains (`-mipmap -normal_map -mip_renorm`, UASTC and ETC1S,
/// fixtures/ktx2/make.py): a second encoder's correct chains pass the direction check, and their
/// deepest levels (mean length 0.977 and 0.961, not renormalised) stay within the lossy tolerance.
#[test]
fn basisu_chains_report_none_of_the_chain_codes() {
    let d = scratch_dir("validate_ktx2_basisu");
    for codec in ["uastc", "etc1s"] {
        let bytes = std::fs::read(fixture(&format!("ktx2/bumps_normal.basisu_mips.{codec}.ktx2"))).unwrap();
        let path = material_gltf(&d, codec, &bytes, 1.0, None);
        let (_, r) = validate(&[s(&path)]);
        let (found, checks) = chain_findings(&r);
        assert!(found.is_empty(), "{codec}: {found:?}\n{r:#}");
        assert!(checks.contains(&"NORMALMAP_MIPS_DIRECTION".to_string()), "{codec}: {checks:?}");
    }
}

/// Box-averaging the 8-bit texels level by level without renormalising shortens the deeper
/// levels' texels: NORMALMAP_MIPS_NOT_UNIT, and their directions still follow the level above.
#[test]
fn a_chain_filtered_without_renormalising_is_not_unit() {
    let d = scratch_dir("validate_ktx2_no_renorm");
    let k = ktx2_dir("validate_ktx2_no_renorm");
    let base = bumpy_map(256);
    let mut levels = vec![(256usize, 256usize, base.into_raw())];
    while levels.last().unwrap().0 > 1 {
        let (w, _, rgb) = levels.last().unwrap();
        let (w, m) = (*w, w / 2);
        let v = |x: usize, y: usize, c: usize| rgb[(y * w + x) * 3 + c] as f64 / 127.5 - 1.0;
        let mut next = Vec::with_capacity(m * m * 3);
        for y in 0..m {
            for x in 0..m {
                let n = [0, 1, 2].map(|c| {
                    (v(2 * x, 2 * y, c) + v(2 * x + 1, 2 * y, c) + v(2 * x, 2 * y + 1, c) + v(2 * x + 1, 2 * y + 1, c))
                        / 4.0
                });
                next.extend(encode(n));
            }
        }
        levels.push((m, m, next));
    }
    let bytes = keep(&k, "no_renorm.uastc.ktx2", encode_levels(&levels, Codec::Uastc { level: 2, rdo: None }));
    let path = material_gltf(&d, "no_renorm", &bytes, 1.0, None);
    let (code, r) = validate(&[s(&path)]);
    let (found, _) = chain_findings(&r);
    assert_eq!(found, ["NORMALMAP_MIPS_NOT_UNIT"], "{r:#}");
    let f = finding(&r, "NORMALMAP_MIPS_NOT_UNIT");
    assert_eq!(f["severity"], "warning");
    assert_eq!(f["total"], 8, "levels 1-8 are checked: {f:#}");
    assert!(f["metrics"]["worst_mean_length"].as_f64().unwrap() < 0.9, "{f:#}");
    assert_eq!(code, 0);
    // The same file given bare on the command line: the same chain check.
    let (code, r) = validate(&[s(&k.join("no_renorm.uastc.ktx2"))]);
    assert_eq!(chain_findings(&r).0, ["NORMALMAP_MIPS_NOT_UNIT"], "{r:#}");
    assert_eq!(finding(&r, "NORMALMAP_MIPS_NOT_UNIT")["total"], 8);
    assert_eq!(code, 0);
}

/// One 1024² level and nothing below it: NORMALMAP_MIPS_MISSING, 10 of the 11 levels of a full
/// chain missing; the same map at 256² has nothing to report.
#[test]
fn a_large_map_without_mips_is_missing_them() {
    let d = scratch_dir("validate_ktx2_no_mips");
    let k = ktx2_dir("validate_ktx2_no_mips");
    for (n, want) in [(1024usize, Some(10)), (256, None)] {
        let img = normal_map(n as u32, n as u32, 0.5, false, |x, y| (x / 9.0).sin() * (y / 7.0).cos() * 6.0);
        let bytes = keep(
            &k,
            &format!("one_level_{n}.ktx2"),
            encode_levels(&[(n, n, img.into_raw())], Codec::Uastc { level: 0, rdo: None }),
        );
        let path = material_gltf(&d, &format!("one_level_{n}"), &bytes, 1.0, None);
        let (_, r) = validate(&[s(&path)]);
        let (found, checks) = chain_findings(&r);
        assert!(checks.contains(&"NORMALMAP_MIPS_MISSING".to_string()));
        // One level: no chain to judge for length, direction or roughness.
        assert!(!checks.contains(&"NORMALMAP_MIPS_NOT_UNIT".to_string()), "{checks:?}");
        match want {
            Some(missing) => {
                assert_eq!(found, ["NORMALMAP_MIPS_MISSING"], "{r:#}");
                let f = finding(&r, "NORMALMAP_MIPS_MISSING");
                assert_eq!((f["count"].as_u64(), f["total"].as_u64()), (Some(missing), Some(11)), "{f:#}");
                assert_eq!(f["severity"], "warning");
            }
            None => assert!(found.is_empty(), "{r:#}"),
        }
        // Bare on the command line: the same verdict.
        let (_, r) = validate(&[s(&k.join(format!("one_level_{n}.ktx2")))]);
        assert_eq!(chain_findings(&r).0, found, "{r:#}");
    }
}

/// Level 2 of a correct chain with its tilts turned by 90° (x, y) -> (-y, x): only level 2 is
/// reported (level 3 is judged against level 1, the last level that agreed).
#[test]
fn a_turned_level_departs_from_the_level_above() {
    let d = scratch_dir("validate_ktx2_turned");
    let k = ktx2_dir("validate_ktx2_turned");
    let mut chain = good_chain(&bumpy_map(256));
    for t in chain[2].rgb.chunks_exact_mut(3) {
        let (x, y) = (t[0], t[1]);
        t[0] = 255 - y;
        t[1] = x;
    }
    let bytes = keep(&k, "turned.uastc.ktx2", uastc(&chain));
    let path = material_gltf(&d, "turned", &bytes, 1.0, None);
    let (code, r) = validate(&[s(&path)]);
    let (found, _) = chain_findings(&r);
    assert_eq!(found, ["NORMALMAP_MIPS_DIRECTION"], "{r:#}");
    let f = finding(&r, "NORMALMAP_MIPS_DIRECTION");
    assert_eq!(levels_named(f), [2], "{f:#}");
    assert!(f["metrics"]["worst_correlation"].as_f64().unwrap() < 0.1, "{f:#}");
    assert_eq!(code, 0);
}

/// Roughness 0.15 from the factor alone on a bumpy chain: ROUGHNESS_MIPS_NOT_WIDENED (info).
/// With a metallicRoughness chain widened as specular antialiasing widens it, nothing; with
/// roughness 0.6, whose widening stays under the margin, nothing either.
#[test]
fn roughness_that_ignores_the_normal_variance_is_reported() {
    let d = scratch_dir("validate_ktx2_roughness");
    let k = ktx2_dir("validate_ktx2_roughness");
    let chain = good_chain(&bumpy_map(256));
    let normal = keep(&k, "bumpy.uastc.ktx2", uastc(&chain));

    let path = material_gltf(&d, "plain", &normal, 0.15, None);
    let (code, r) = validate(&[s(&path)]);
    let (found, _) = chain_findings(&r);
    assert_eq!(found, ["ROUGHNESS_MIPS_NOT_WIDENED"], "{r:#}");
    let f = finding(&r, "ROUGHNESS_MIPS_NOT_WIDENED");
    assert_eq!(f["severity"], "info");
    assert!(f["message"].as_str().unwrap().contains("material 0 ('bumps')"), "{f:#}");
    assert_eq!(code, 0);

    let widened = specular_aa::roughness_levels(&chain, &vec![0.15; 256 * 256], specular_aa::DEFAULT_THRESHOLD);
    let mr: Vec<_> = widened
        .iter()
        .map(|l| {
            let rgb = l.roughness.iter().flat_map(|&r| [255, (r * 255.0).round() as u8, 0]).collect();
            (l.width, l.height, rgb)
        })
        .collect();
    let mr = keep(&k, "widened_roughness.uastc.ktx2", encode_levels(&mr, Codec::Uastc { level: 2, rdo: None }));
    for (name, roughness, mr) in [("widened", 1.0, Some(mr.as_slice())), ("rough", 0.6, None)] {
        let path = material_gltf(&d, name, &normal, roughness, mr);
        let (_, r) = validate(&[s(&path)]);
        let (found, checks) = chain_findings(&r);
        assert!(found.is_empty(), "{name}: {r:#}");
        assert!(checks.contains(&"ROUGHNESS_MIPS_NOT_WIDENED".to_string()), "{name}: {checks:?}");
    }
}
