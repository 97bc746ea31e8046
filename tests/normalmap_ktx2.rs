//! `bumpbake normalmap … -o N.ktx2`: the file is read back with bumpbake's KTX2 reader, level by
//! level, and every level is held to the average of the full-resolution normals, worked out here
//! from the PNG of the same map (level 0 of the KTX2 is that PNG through the codec).

mod common;

use bumpbake::format::image::ktx2::decode_levels_within;
use bumpbake::format::image::Limits;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BUMPS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/bake/bumps.png");

fn run(args: &[&str], threads: Option<&str>) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_bumpbake"));
    c.env_remove("RAYON_NUM_THREADS");
    if let Some(t) = threads {
        c.env("RAYON_NUM_THREADS", t);
    }
    c.args(args).output().expect("the binary runs")
}

fn ok(args: &[&str]) -> Output {
    let out = run(args, None);
    assert!(out.status.success(), "{args:?} failed: {}", String::from_utf8_lossy(&out.stderr));
    out
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

fn tmp(d: &Path, name: &str) -> PathBuf {
    d.join(name)
}

fn unit(c: &[u8]) -> [f64; 3] {
    let v = [c[0] as f64 / 127.5 - 1.0, c[1] as f64 / 127.5 - 1.0, c[2] as f64 / 127.5 - 1.0];
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / l, v[1] / l, v[2] / l]
}

fn deg(a: [f64; 3], b: [f64; 3]) -> f64 {
    (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]).clamp(-1.0, 1.0).acos().to_degrees()
}

/// The renormalised box average of level-0 normals over each 2^k x 2^k footprint (a square
/// power-of-two map).
fn ideal(level0: &[[f64; 3]], n: usize, k: usize) -> Vec<[f64; 3]> {
    let (m, s) = (n >> k, 1 << k);
    let mut out = Vec::with_capacity(m * m);
    for y in 0..m {
        for x in 0..m {
            let mut a = [0.0; 3];
            for yy in y * s..(y + 1) * s {
                for xx in x * s..(x + 1) * s {
                    let v = level0[yy * n + xx];
                    (0..3).for_each(|i| a[i] += v[i]);
                }
            }
            let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            out.push(if l > 1e-12 { [a[0] / l, a[1] / l, a[2] / l] } else { [0.0, 0.0, 1.0] });
        }
    }
    out
}

/// Per level: (mean angle, largest angle, largest |length - 1| of the decoded texel).
fn levels_against_png(ktx2: &Path, png: &Path) -> Vec<(usize, usize, f64, f64, f64)> {
    let base = image::open(png).unwrap().to_rgb8();
    let n = base.width() as usize;
    let level0: Vec<[f64; 3]> = base.as_raw().chunks_exact(3).map(unit).collect();
    let levels = decode_levels_within(&std::fs::read(ktx2).unwrap(), &Limits::TEXTURE).unwrap();
    levels
        .iter()
        .enumerate()
        .map(|(k, img)| {
            let rgb = img.to_rgb8();
            let want = ideal(&level0, n, k);
            let (mut sum, mut max, mut len_err) = (0.0, 0.0f64, 0.0f64);
            for (t, w) in rgb.as_raw().chunks_exact(3).zip(&want) {
                let v = [t[0] as f64 / 127.5 - 1.0, t[1] as f64 / 127.5 - 1.0, t[2] as f64 / 127.5 - 1.0];
                len_err = len_err.max(((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt() - 1.0).abs());
                let a = deg(unit(t), *w);
                sum += a;
                max = max.max(a);
            }
            (rgb.width() as usize, rgb.height() as usize, sum / want.len() as f64, max, len_err)
        })
        .collect()
}

#[test]
fn uastc_levels_read_back_as_the_averaged_full_resolution_normals() {
    let d = common::ktx2_dir("normalmap_uastc_levels_read_back_as_the_averaged_full_resolution_normals");
    let (k, png) = (tmp(&d, "n.ktx2"), tmp(&d, "n.png"));
    ok(&["normalmap", BUMPS, "-o", p(&k), "--strength", "4"]);
    ok(&["normalmap", BUMPS, "-o", p(&png), "--strength", "4"]);
    let levels = levels_against_png(&k, &png);
    // 128 x 128: log2(128) + 1 levels, each half the one before.
    assert_eq!(levels.len(), 8);
    for (i, &(w, h, mean, max, len_err)) in levels.iter().enumerate() {
        assert_eq!((w, h), (128 >> i, 128 >> i));
        // 8-bit texels are within 1/127.5 of the unit sphere per channel; UASTC adds a few codes.
        assert!(len_err < 0.06, "level {i}: a texel {len_err:.3} off unit length");
        // Measured: at most 2.3° mean (level 2, where neighbouring texels differ most), 5.3° max.
        assert!(mean < 3.0 && max < 8.0, "level {i}: mean {mean:.2}°, max {max:.2}°");
    }
}

#[test]
fn etc1s_levels_read_back_within_its_coarser_error() {
    let d = common::ktx2_dir("normalmap_etc1s_levels_read_back_within_its_coarser_error");
    let (k, png) = (tmp(&d, "n.ktx2"), tmp(&d, "n.png"));
    ok(&["normalmap", BUMPS, "-o", p(&k), "--strength", "4", "--ktx2", "etc1s"]);
    ok(&["normalmap", BUMPS, "-o", p(&png), "--strength", "4"]);
    let levels = levels_against_png(&k, &png);
    assert_eq!(levels.len(), 8);
    for (i, &(w, h, mean, _, _)) in levels.iter().enumerate() {
        assert_eq!((w, h), (128 >> i, 128 >> i));
        assert!(mean < 10.0, "level {i}: mean {mean:.2}°");
    }
}

#[test]
fn odd_sizes_follow_ktx2_level_sizes() {
    let d = common::ktx2_dir("normalmap_odd_sizes_follow_ktx2_level_sizes");
    let (h, k) = (tmp(&d, "h.png"), tmp(&d, "n.ktx2"));
    image::ImageBuffer::from_fn(37, 10, |x, y| image::Luma([((x * 7 + y * 3) % 64) as u8])).save(&h).unwrap();
    ok(&["normalmap", p(&h), "-o", p(&k)]);
    let levels = decode_levels_within(&std::fs::read(&k).unwrap(), &Limits::TEXTURE).unwrap();
    let sizes: Vec<(u32, u32)> = levels.iter().map(|l| (l.width(), l.height())).collect();
    assert_eq!(sizes, [(37, 10), (18, 5), (9, 2), (4, 1), (2, 1), (1, 1)]);
}

#[test]
fn reruns_and_thread_counts_give_the_same_bytes() {
    let d = common::ktx2_dir("normalmap_reruns_and_thread_counts_give_the_same_bytes");
    for codec in ["uastc", "etc1s"] {
        let outs: Vec<Vec<u8>> = [None, None, Some("1")]
            .iter()
            .enumerate()
            .map(|(i, threads)| {
                let k = tmp(&d, &format!("{codec}{i}.ktx2"));
                let out = run(&["normalmap", BUMPS, "-o", p(&k), "--strength", "4", "--ktx2", codec], *threads);
                assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
                std::fs::read(&k).unwrap()
            })
            .collect();
        assert_eq!(outs[0], outs[1], "{codec}: a rerun differs");
        assert_eq!(outs[0], outs[2], "{codec}: one thread differs");
    }
    // A batch, one file at a time and all at once.
    let a = tmp(&d, "a");
    let b = tmp(&d, "b");
    let copy = tmp(&d, "bumps2.png");
    std::fs::copy(BUMPS, &copy).unwrap();
    for (dir, j) in [(&a, "1"), (&b, "0")] {
        ok(&["normalmap", BUMPS, p(&copy), "--out-dir", p(dir), "--out-ext", "ktx2", "-j", j, "--quiet"]);
    }
    for name in ["bumps.ktx2", "bumps2.ktx2"] {
        assert_eq!(std::fs::read(a.join(name)).unwrap(), std::fs::read(b.join(name)).unwrap(), "{name}");
    }
}

#[test]
fn the_report_names_each_level_in_text_and_json() {
    let d = common::ktx2_dir("normalmap_the_report_names_each_level_in_text_and_json");
    let k = tmp(&d, "n.ktx2");
    let out = ok(&["normalmap", BUMPS, "-o", p(&k), "--strength", "4", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let levels = v["levels"].as_array().expect("levels");
    assert_eq!(levels.len(), 8);
    for (i, l) in levels.iter().enumerate() {
        assert_eq!(l["level"], i);
        assert_eq!(l["width"], 128 >> i);
        let (mean, p99) = (l["mean_deg"].as_f64().unwrap(), l["p99_deg"].as_f64().unwrap());
        assert!(mean >= 0.0 && mean <= p99 && p99 < 8.0, "{l}");
        let len = l["mean_length"].as_f64().unwrap();
        assert!(len > 0.0 && len <= 1.0);
    }
    // The text report goes to stderr, as every command's does.
    let text = String::from_utf8(ok(&["normalmap", BUMPS, "-o", p(&k), "--strength", "4"]).stderr).unwrap();
    assert!(text.contains("8 mip levels") && text.contains("level  7"), "{text}");
    // PNG output says nothing of levels.
    let out = ok(&["normalmap", BUMPS, "-o", p(&tmp(&d, "n.png")), "--json"]);
    assert!(!String::from_utf8_lossy(&out.stdout).contains("levels"));
}

#[test]
fn bad_ktx2_options_are_one_line_and_exit_2() {
    let d = common::ktx2_dir("normalmap_bad_ktx2_options_are_one_line_and_exit_2");
    let k = tmp(&d, "n.ktx2");
    for args in [
        vec!["--ktx2-quality", "5"],
        vec!["--ktx2", "etc1s", "--ktx2-quality", "0"],
        vec!["--bits", "16"],
        vec!["--alpha", "height"],
    ] {
        let mut all = vec!["normalmap", BUMPS, "-o", p(&k)];
        all.extend(args.iter().copied());
        let out = run(&all, None);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(!k.exists(), "{args:?} left a file");
    }
    // Wider than the Basis Universal encoder takes.
    let wide = tmp(&d, "wide.png");
    image::ImageBuffer::from_pixel(16385, 1, image::Luma([9u8])).save(&wide).unwrap();
    let out = run(&["normalmap", p(&wide), "-o", p(&k)], None);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("16384") && err.trim_end().lines().count() == 1, "{err}");
    assert!(!k.exists());
}
