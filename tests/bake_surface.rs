//! `bake --height-range` without `--texel-size`: the height map is made through the mesh, each
//! texel as large as the mesh lays it out ([`bumpbake::bake::surface`]). On a plane stretched
//! 3:1 the map equals the analytic normal of the height field in world units along both axes,
//! where one texel size for the whole map is wrong along one of them.

mod common;
use common::*;
use std::f64::consts::PI;
use std::path::Path;

const W: usize = 256;
const H: usize = 256;

/// `h(x, row)` in 0..1: one period across the image each way.
fn height(x: f64, row: f64) -> f64 {
    0.5 + 0.25 * (2.0 * PI * x / W as f64).sin() * (2.0 * PI * row / H as f64).cos()
}

/// The plane `[0, sx] x [0, sy]` (z = 0, normal +z) with its UV square mapped whole, and a
/// 16-bit height PNG; returns the OBJ.
fn stretched_plane(dir: &Path, sx: f64, sy: f64) -> std::path::PathBuf {
    let obj = format!(
        "mtllib plane.mtl\nv 0 0 0\nv {sx} 0 0\nv {sx} {sy} 0\nv 0 {sy} 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nusemtl plane\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n"
    );
    std::fs::write(dir.join("plane.obj"), obj).unwrap();
    std::fs::write(dir.join("plane.mtl"), "newmtl plane\nKd 0.8 0.8 0.8\n").unwrap();
    let img = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(W as u32, H as u32, |x, y| {
        image::Luma([(height(x as f64, y as f64) * 65535.0).round() as u16])
    });
    img.save(dir.join("height.png")).unwrap();
    dir.join("plane.obj")
}

/// The normal map in the baked GLB, decoded (16-bit).
fn baked_normals(glb: &Path) -> Vec<[f64; 3]> {
    let scene = load(glb);
    let bytes = scene.image_bytes(0).unwrap();
    let img = image::load_from_memory(&bytes).unwrap().to_rgb16();
    assert_eq!((img.width() as usize, img.height() as usize), (W, H));
    img.pixels().map(|p| p.0.map(|c| c as f64 / 65535.0 * 2.0 - 1.0)).collect()
}

/// The analytic tangent-space normal at texel `(x, row)`: `T = +X`, `B = +Y`, the height's
/// slope per world unit (a row runs down the image, towards -Y).
fn analytic(x: usize, row: usize, d: f64, sx: f64, sy: f64) -> [f64; 3] {
    let (x, r) = (x as f64, row as f64);
    let k = 2.0 * PI;
    let dhdx = 0.25 * k / W as f64 * (k * x / W as f64).cos() * (k * r / H as f64).cos();
    let dhdrow = -0.25 * k / H as f64 * (k * x / W as f64).sin() * (k * r / H as f64).sin();
    let (gx, gy) = (dhdx * W as f64 / sx, -dhdrow * H as f64 / sy);
    let n = [-d * gx, -d * gy, 1.0];
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    n.map(|c| c / l)
}

fn angle_deg(a: [f64; 3], b: [f64; 3]) -> f64 {
    let l = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let dot = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (l(a) * l(b));
    dot.clamp(-1.0, 1.0).acos().to_degrees()
}

/// Mean and largest angle between the map and the analytic normals.
fn errors(map: &[[f64; 3]], d: f64, sx: f64, sy: f64) -> (f64, f64) {
    let mut sum = 0.0f64;
    let mut max = 0.0f64;
    for row in 0..H {
        for x in 0..W {
            let e = angle_deg(map[row * W + x], analytic(x, row, d, sx, sy));
            sum += e;
            max = max.max(e);
        }
    }
    (sum / (W * H) as f64, max)
}

/// `bake OBJ --height HEIGHT --height-range RANGE -o OUT` with `extra` flags; it must succeed.
fn bake_height(obj: &Path, height: &Path, range: &str, out: &Path, extra: &[&str]) -> std::process::Output {
    let args = [&["bake", s(obj), "--height", s(height), "--height-range", range, "-o", s(out)][..], extra].concat();
    run_ok(&args)
}

#[test]
fn a_stretched_plane_is_bumped_in_world_units_along_both_axes() {
    let dir = scratch_dir("bake_surface_stretched");
    let (sx, sy, d) = (3.0, 1.0, 0.05);
    let obj = stretched_plane(&dir, sx, sy);
    let out = dir.join("plane.glb");
    let height = dir.join("height.png");
    let o = bake_height(&obj, &height, "0.05", &out, &["--bits16", "--json"]);
    let rep: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(rep["maps"][0]["source"], "height");
    assert!(rep["warnings"].as_array().unwrap().is_empty(), "{}", rep["warnings"]);
    let (mean, max) = errors(&baked_normals(&out), d, sx, sy);
    // The filter's own error (Sobel on one period per 256 texels) and 16-bit rounding.
    assert!(mean < 0.01 && max < 0.05, "through the mesh: mean {mean:.4}°, max {max:.4}°");
    assert_eq!(run(&["validate", "--strict", s(&out)]).status.code(), Some(0));

    // One texel size for the whole map (the U extent's) is right along U and 3x too steep along V.
    let uniform = dir.join("uniform.glb");
    let texel = format!("{}", sx / W as f64);
    bake_height(&obj, &height, "0.05", &uniform, &["--texel-size", &texel, "--bits16"]);
    let (mean_u, _) = errors(&baked_normals(&uniform), d, sx, sy);
    assert!(mean_u > 20.0 * mean, "one texel size: mean {mean_u:.4}° against {mean:.4}° through the mesh");
}

#[test]
fn invert_turns_the_relief_over_and_a_flat_result_is_named() {
    let dir = scratch_dir("bake_surface_invert");
    let (sx, sy, d) = (1.0, 1.0, 0.01);
    let obj = stretched_plane(&dir, sx, sy);
    let height = dir.join("height.png");
    let out = dir.join("inverted.glb");
    bake_height(&obj, &height, "0.01", &out, &["--invert", "--bits16"]);
    let (mean, _) = errors(&baked_normals(&out), -d, sx, sy);
    assert!(mean < 0.01, "inverted: mean {mean:.4}°");

    let tiny = dir.join("tiny.glb");
    let o = bake_height(&obj, &height, "1e-7", &tiny, &["--json"]);
    let rep: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let w = rep["warnings"][0].as_str().unwrap_or_default();
    assert!(w.contains("flat") && w.contains("--height-range"), "{w}");

    let bad = run(&["bake", s(&obj), "--height", s(&height), "--height-range", "nan", "-o", s(&tiny)]);
    assert_eq!(bad.status.code(), Some(2));
}
