//! One definition of "flat" for `bake`, `normalmap` and `validate` (issue 22): the largest tilt
//! of the texels as written. A gentle bump (red and green within 125..130, about 1.5°) is named
//! by `bake` and `normalmap` with a strength that shows it, and `validate` calls it nearly flat,
//! never flat.

mod common;
use common::*;
use serde_json::Value;
use std::path::Path;

/// A 16-bit Gaussian bump, sigma 10 texels, heights 0..0.35: at strength 1 its steepest slope
/// is 0.35 e^-1/2 / 10 = 0.021 per texel, a tilt of 1.2°.
fn gentle_bump(path: &Path) {
    let img = image::ImageBuffer::<image::Luma<u16>, _>::from_fn(128, 128, |x, y| {
        let r2 = (x as f64 - 64.0).powi(2) + (y as f64 - 64.0).powi(2);
        image::Luma([(0.35 * (-r2 / (2.0 * 10.0 * 10.0)).exp() * 65535.0).round() as u16])
    });
    img.save(path).unwrap();
}

/// The validate findings on a file's images: (code, max_tilt_deg).
fn image_findings(file: &Path) -> Vec<(String, f64)> {
    let o = run(&["validate", "--format", "json", s(file)]);
    let r: Value = serde_json::from_slice(&o.stdout).unwrap();
    let mut out = Vec::new();
    for subj in r["files"][0]["subjects"].as_array().unwrap() {
        if subj["kind"] == "image" {
            for f in subj["findings"].as_array().unwrap() {
                out.push((
                    f["code"].as_str().unwrap().to_string(),
                    f["metrics"]["max_tilt_deg"].as_f64().unwrap_or(-1.0),
                ));
            }
        }
    }
    out
}

#[test]
fn a_gentle_bump_is_named_by_bake_and_called_nearly_flat_not_flat_by_validate() {
    let d = scratch_dir("flat_gentle_in");
    let v = validated_dir("flat_gentle");
    let bump = d.join("bump.png");
    gentle_bump(&bump);
    let mesh = d.join("q.obj");
    std::fs::write(&mesh, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n")
        .unwrap();
    let out = v.join("gentle.glb");
    let o = run_ok(&["bake", s(&mesh), "--height", s(&bump), "--filter", "central", "-o", s(&out)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("warning: bump.png: the normal map is nearly flat: its largest tilt is 1."), "{err}");
    let strength = err.split("--strength ").nth(1).and_then(|r| r.split_whitespace().next()).expect("a strength");
    // tan 30° / (0.35 e^-1/2 / 10) = 27.2.
    assert_eq!(strength, "27", "{err}");

    // The map as written: red and green within 125..130, as in the issue.
    let scene = load(&out);
    let png = image::load_from_memory(&scene.image_bytes(0).unwrap()).unwrap().to_rgb8();
    let (lo, hi) = png.pixels().flat_map(|p| [p.0[0], p.0[1]]).fold((255, 0), |(l, h), c| (c.min(l), c.max(h)));
    assert!(lo >= 125 && hi <= 130 && (lo, hi) != (127, 128), "{lo}..{hi}");

    let found = image_findings(&out);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].0, "NORMALMAP_NEARLY_FLAT", "{found:?}");
    assert!(found[0].1 > 0.33 && found[0].1 < 2.0, "{found:?}");
    // The same largest tilt in both reports.
    assert!(err.contains(&format!("{:.2}°", found[0].1)), "{err} vs {found:?}");

    // At the strength bake named, the relief shows: no warning, no flat finding.
    let shown = v.join("shown.glb");
    let o = run_ok(&[
        "bake",
        s(&mesh),
        "--height",
        s(&bump),
        "--filter",
        "central",
        "--strength",
        strength,
        "-o",
        s(&shown),
    ]);
    assert!(!String::from_utf8_lossy(&o.stderr).contains("warning"));
    assert_eq!(image_findings(&shown), vec![]);
    assert_eq!(run(&["validate", "--strict", s(&shown)]).status.code(), Some(0));
}

#[test]
fn normalmap_warns_on_the_same_condition_validate_reports() {
    let d = scratch_dir("flat_normalmap");
    let bump = d.join("bump.png");
    gentle_bump(&bump);
    let out = d.join("n.png");
    let o = run_ok(&["normalmap", s(&bump), "-o", s(&out), "--filter", "central"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("nearly flat: its largest tilt is") && err.contains("--strength 27"), "{err}");
    let found = image_findings(&out);
    assert_eq!(found.iter().map(|f| f.0.as_str()).collect::<Vec<_>>(), ["NORMALMAP_NEARLY_FLAT"], "{found:?}");
    // An exactly flat map is NORMALMAP_FLAT.
    let flat = d.join("flat.png");
    image::RgbImage::from_pixel(16, 16, image::Rgb([128, 128, 255])).save(&flat).unwrap();
    let found = image_findings(&flat);
    assert_eq!(found.iter().map(|f| f.0.as_str()).collect::<Vec<_>>(), ["NORMALMAP_FLAT"], "{found:?}");
}
