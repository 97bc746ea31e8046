//! `bumpbake preview`: golden-image statistics, mirrored UVs, the handedness view, the pipeline
//! error of height field -> normal map -> tangents -> renderer, and bad input.

mod common;

use common::*;
use serde_json::{json, Value};
use std::cmp::Ordering::Greater;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

// ---------- helpers ----------

fn png_bytes(img: &image::RgbImage) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// Encodes a unit tangent-space normal as the conventions say: 8 bits, rounded.
fn encode(n: [f64; 3]) -> [u8; 3] {
    n.map(|c| ((c * 0.5 + 0.5) * 255.0).round().clamp(0.0, 255.0) as u8)
}

/// A normal map from a height field's exact gradient: `n = normalize(-S dh/dx, -S dh/dy_up, 1)`
/// per texel, x = column right, y_up = towards the top of the image; derivatives per texel.
/// `grad(x, y_up)` is the gradient in units of the unit square. `flip_green` negates y (DirectX).
fn normal_map(r: u32, s: f64, grad: impl Fn(f64, f64) -> (f64, f64), flip_green: bool) -> image::RgbImage {
    image::RgbImage::from_fn(r, r, |i, j| {
        let (x, y_up) = ((i as f64 + 0.5) / r as f64, 1.0 - (j as f64 + 0.5) / r as f64);
        let (gx, gy) = grad(x, y_up);
        let (dx, dy) = (gx / r as f64, gy / r as f64);
        let v = [-s * dx, -s * dy, 1.0];
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let mut n = [v[0] / l, v[1] / l, v[2] / l];
        if flip_green {
            n[1] = -n[1];
        }
        image::Rgb(encode(n))
    })
}

/// A grid of `n x n` quads over the unit square at height `z(x, y)` with normals `normal(x, y)`,
/// UVs (x, 1 - y) in glTF's v-down convention.
fn surface(n: usize, z: impl Fn(f64, f64) -> f64, normal: impl Fn(f64, f64) -> [f64; 3]) -> Mesh16 {
    let (p, _, uv, idx) = grid(n);
    let pos = p.iter().map(|q| [q[0], q[1], z(q[0] as f64, q[1] as f64) as f32]).collect();
    let nrm = p.iter().map(|q| normal(q[0] as f64, q[1] as f64).map(|c| c as f32)).collect();
    (pos, nrm, uv, idx)
}

/// Writes a one-primitive GLB; `normal_png` makes a material with that normal texture.
fn write_mesh(path: &Path, mesh: Mesh16, tangents: Option<Vec<[f32; 4]>>, normal_png: Option<&[u8]>) {
    let (p, n, uv, idx) = mesh;
    let mut g = Gltf::new();
    let a_p = g.floats(&p, Some(34962));
    let a_n = g.floats(&n, Some(34962));
    let a_uv = g.floats(&uv, Some(34962));
    let a_i = g.indices(&idx);
    let mut attrs = json!({ "POSITION": a_p, "NORMAL": a_n, "TEXCOORD_0": a_uv });
    if let Some(t) = tangents {
        attrs["TANGENT"] = json!(g.floats(&t, Some(34962)));
    }
    let mut prim = json!({ "attributes": attrs, "indices": a_i });
    let material = match normal_png {
        Some(png) => {
            let t = g.png_texture(png);
            json!({ "normalTexture": { "index": t }, "pbrMetallicRoughness": { "baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0 } })
        }
        None => json!({ "pbrMetallicRoughness": { "baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0 } }),
    };
    prim["material"] = json!(g.material(material));
    g.mesh(prim);
    g.write_glb(path);
}

/// Luma of an 8-bit RGB PNG, row-major.
fn luma(path: &Path) -> (u32, u32, Vec<f64>) {
    let img = image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgb8();
    let v = img.pixels().map(|p| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64).collect();
    (img.width(), img.height(), v)
}

fn preview(args: &[&str]) -> std::process::Output {
    run_ok(&[&["preview"], args].concat())
}

// ---------- golden images: a normal-mapped quad with one bump ----------

/// A Gaussian bump in the middle of the unit square: its gradient.
fn bump_grad(x: f64, y: f64) -> (f64, f64) {
    let (dx, dy) = (x - 0.5, y - 0.5);
    let s2 = 0.12f64 * 0.12;
    let h = (-(dx * dx + dy * dy) / (2.0 * s2)).exp();
    (-dx / s2 * h, -dy / s2 * h)
}

/// Renders the bump quad under a light from +X and one from +Y; returns
/// (right - left, top - bottom) mean-luma differences over the quad.
fn bump_sides(dir: &Path, name: &str, flip_green: bool, w: f32) -> (f64, f64) {
    let png = png_bytes(&normal_map(64, 0.25 * 64.0, bump_grad, flip_green));
    let glb = dir.join(format!("{name}.glb"));
    let quad = surface(1, |_, _| 0.0, |_, _| [0.0, 0.0, 1.0]);
    // Authored frame: T = +X (u grows with x), B = cross(N, T) * w = +Y where v-up points.
    let t = vec![[1.0, 0.0, 0.0, w]; 4];
    write_mesh(&glb, quad, Some(t), Some(&png));
    let mut out = [0.0; 2];
    for (k, light) in ["dir:-1,0,-1", "dir:0,-1,-1"].iter().enumerate() {
        let img = dir.join(format!("{name}_{k}.png"));
        preview(&[s(&glb), "-o", s(&img), "--size", "64x64", "--light", light, "--specular", "0", "-q"]);
        let (wd, ht, l) = luma(&img);
        let (mut a, mut na, mut b, mut nb) = (0.0, 0, 0.0, 0);
        for y in 0..ht {
            for x in 0..wd {
                let v = l[(y * wd + x) as usize];
                // The quad fills the middle of the frame; compare the halves through its centre.
                let first = if k == 0 { x >= wd / 2 } else { y < ht / 2 };
                if first {
                    a += v;
                    na += 1;
                } else {
                    b += v;
                    nb += 1;
                }
            }
        }
        out[k] = a / na as f64 - b / nb as f64;
    }
    (out[0], out[1])
}

#[test]
fn bump_is_lit_on_the_sides_facing_the_light() {
    let dir = scratch_dir("preview_bump_sides");
    let (rl, tb) = bump_sides(&dir, "ok", false, 1.0);
    // Light from +X lights the bump's right flank; light from +Y its top flank.
    assert!(rl > 2.0, "right - left = {rl}");
    assert!(tb > 2.0, "top - bottom = {tb}");

    // The same checks catch a flipped green channel and a flipped w: the vertical test fails.
    let (rl_g, tb_g) = bump_sides(&dir, "green", true, 1.0);
    assert!(rl_g > 2.0, "flipping green must not change x: {rl_g}");
    assert!(tb_g < -2.0, "a flipped green channel must light the bottom: {tb_g}");
    let (rl_w, tb_w) = bump_sides(&dir, "w", false, -1.0);
    assert!(rl_w > 2.0, "flipping w must not change x: {rl_w}");
    assert!(tb_w < -2.0, "a flipped w must light the bottom: {tb_w}");
    assert!(
        tb_g.partial_cmp(&2.0) != Some(Greater) && tb_w.partial_cmp(&2.0) != Some(Greater),
        "the golden check would have failed on both"
    );
}

// ---------- the mirrored-UV Khronos model ----------

/// Masks of the w = +1 and w = -1 pixels, from the handedness view.
fn handedness_masks(img: &Path) -> (Vec<bool>, Vec<bool>) {
    let i = image::open(img).unwrap().to_rgb8();
    let right = i.pixels().map(|p| p.0 == [38, 140, 242]).collect();
    let left = i.pixels().map(|p| p.0 == [242, 115, 26]).collect();
    (right, left)
}

/// How strongly the bumps in `mask` are lit on the side facing the light: the first moment of
/// the difference between opposite lights, normalised. Flat areas cancel (the lights are
/// symmetric about the surface normal and specular is off), so no bump centres are needed.
fn moment(a: &Path, b: &Path, mask: &[bool], vertical: bool) -> f64 {
    let (w, _, la) = luma(a);
    let (_, _, lb) = luma(b);
    let (mut m, mut total) = (0.0, 0.0);
    for (i, &on) in mask.iter().enumerate() {
        if !on {
            continue;
        }
        let d = la[i] - lb[i];
        let (x, y) = ((i as u32 % w) as f64, (i as u32 / w) as f64);
        m += d * if vertical { -y } else { x };
        total += d.abs();
    }
    m / total.max(1e-9)
}

fn mirror_moments(dir: &Path, model: &Path) -> [(f64, f64); 2] {
    let size = ["--size", "200x200", "-q"];
    let hand = dir.join("hand.png");
    preview(&[&[s(model), "-o", s(&hand), "--view", "handedness"], &size[..]].concat());
    let (right, left) = handedness_masks(&hand);
    let mut imgs = Vec::new();
    for (k, l) in ["dir:0,-1,-1", "dir:0,1,-1", "dir:-1,0,-1", "dir:1,0,-1"].iter().enumerate() {
        let p = dir.join(format!("light{k}.png"));
        preview(&[&[s(model), "-o", s(&p), "--light", l, "--specular", "0"], &size[..]].concat());
        imgs.push(p);
    }
    [&right, &left].map(|m| (moment(&imgs[2], &imgs[3], m, false), moment(&imgs[0], &imgs[1], m, true)))
}

#[test]
fn mirrored_halves_of_the_khronos_model_render_alike() {
    let dir = scratch_dir("preview_mirror");
    let model = fixture("khronos/NormalTangentMirrorTest.glb");
    let [(rx, ry), (lx, ly)] = mirror_moments(&dir, &model);
    // Both halves: lit from +X means brighter on the right, from +Y brighter on top, equally.
    for (what, v) in [("w=+1 x", rx), ("w=+1 y", ry), ("w=-1 x", lx), ("w=-1 y", ly)] {
        assert!(v > 0.5, "{what}: moment {v}");
    }
    assert!((rx / lx - 1.0).abs() < 0.25 && (ry / ly - 1.0).abs() < 0.25, "halves differ: {rx} {ry} vs {lx} {ly}");

    // A renderer (or a file) that ignores w lights the mirrored tiles from the wrong side (which
    // side depends on how each tile's UVs are mirrored and rotated): the same measure tells.
    let mut scene = load(&model);
    let mut p = scene.primitive(P0).unwrap();
    let t: Vec<[f32; 4]> =
        p.attr("TANGENT").unwrap().to_f32::<4>().into_iter().map(|t| [t[0], t[1], t[2], 1.0]).collect();
    p.set_attr("TANGENT", bumpbake::scene::Stream::from_f32("VEC4", &t));
    scene.set_primitive(P0, &p);
    let broken = dir.join("no_w.glb");
    let (outs, _) = bumpbake::format::write(&scene, &broken, &Default::default()).unwrap();
    outs.commit().unwrap();
    let bdir = dir.join("broken");
    std::fs::create_dir_all(&bdir).unwrap();
    let hand = bdir.join("hand.png");
    // The mask must come from the real handedness, so take it from the correct file.
    preview(&[s(&model), "-o", s(&hand), "--view", "handedness", "--size", "200x200", "-q"]);
    let (_, left) = handedness_masks(&hand);
    let mut imgs = Vec::new();
    for (k, l) in ["dir:0,-1,-1", "dir:0,1,-1", "dir:-1,0,-1", "dir:1,0,-1"].iter().enumerate() {
        let p = bdir.join(format!("light{k}.png"));
        preview(&[s(&broken), "-o", s(&p), "--light", l, "--specular", "0", "--size", "200x200", "-q"]);
        imgs.push(p);
    }
    let (bx, by) = (moment(&imgs[2], &imgs[3], &left, false), moment(&imgs[0], &imgs[1], &left, true));
    eprintln!("moments: w=+1 ({rx:.3}, {ry:.3}), w=-1 ({lx:.3}, {ly:.3}), w=-1 with w ignored ({bx:.3}, {by:.3})");
    assert!(bx < 0.5 * rx || by < 0.5 * ry, "ignoring w went unnoticed: ({bx}, {by}) vs ({rx}, {ry})");
}

#[test]
fn handedness_view_shows_both_colours_on_a_mirrored_mesh() {
    let dir = scratch_dir("preview_handedness");
    let img = dir.join("hand.png");
    preview(&[
        s(&fixture("khronos/NormalTangentMirrorTest.glb")),
        "-o",
        s(&img),
        "--view",
        "handedness",
        "--size",
        "128x128",
        "-q",
    ]);
    let (right, left) = handedness_masks(&img);
    let (r, l) = (right.iter().filter(|&&b| b).count(), left.iter().filter(|&&b| b).count());
    assert!(r > 500 && l > 500, "right-handed {r}, left-handed {l} pixels");

    // A mesh without mirrored UVs is one colour.
    let plain = dir.join("plain.png");
    preview(&[
        s(&fixture("khronos/NormalTangentTest.glb")),
        "-o",
        s(&plain),
        "--view",
        "handedness",
        "--size",
        "128x128",
        "-q",
    ]);
    let (right, left) = handedness_masks(&plain);
    let (r, l) = (right.iter().filter(|&&b| b).count(), left.iter().filter(|&&b| b).count());
    assert!(r.min(l) == 0 && r.max(l) > 1000, "right-handed {r}, left-handed {l} pixels");
}

// ---------- pipeline error: height field -> normal map -> tangents -> renderer ----------

const K: f64 = 2.0; // bumps per unit
const H: f64 = 0.03; // height range in scene units

fn height(x: f64, y: f64) -> f64 {
    0.5 + 0.5 * (2.0 * PI * K * x).sin() * (2.0 * PI * K * y).sin()
}

fn height_grad(x: f64, y: f64) -> (f64, f64) {
    let a = PI * K;
    (a * (2.0 * PI * K * x).cos() * (2.0 * PI * K * y).sin(), a * (2.0 * PI * K * x).sin() * (2.0 * PI * K * y).cos())
}

/// The true surface: a fine grid displaced by the height field, with its analytic normals.
fn reference_surface(dir: &Path) -> PathBuf {
    let hi = dir.join("high.glb");
    let mesh = surface(
        128,
        |x, y| H * height(x, y),
        |x, y| {
            let (gx, gy) = height_grad(x, y);
            let v = [-H * gx, -H * gy, 1.0];
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            v.map(|c| c / l)
        },
    );
    write_mesh(&hi, mesh, None, None);
    hi
}

/// The cheap asset: a coarse flat grid half-way up the relief with a normal map of the same
/// height field (S = height range / texel size), tangents from `bumpbake tangents`.
fn coarse_asset(scratch: &Path, dir: &Path, name: &str, flip_green: bool) -> PathBuf {
    let r = 256;
    let png = png_bytes(&normal_map(r, H * r as f64, height_grad, flip_green));
    let raw = scratch.join(format!("{name}_in.glb"));
    write_mesh(&raw, surface(4, |_, _| H * 0.5, |_, _| [0.0, 0.0, 1.0]), None, Some(&png));
    let out = dir.join(format!("{name}.glb"));
    run_ok(&["tangents", s(&raw), "-o", s(&out), "-q"]);
    out
}

fn pipeline_error(reference: &Path, candidate: &Path, out: &Path) -> Value {
    let o =
        preview(&["--reference", s(reference), "--compare", s(candidate), "-o", s(out), "--size", "160x160", "--json"]);
    let j: Value = serde_json::from_slice(&o.stdout).expect("JSON report");
    assert!(out.exists());
    j["comparison"].clone()
}

#[test]
fn pipeline_error_is_small_and_catches_flipped_green_and_w() {
    let scratch = scratch_dir("preview_pipeline");
    let valid = validated_dir("preview_pipeline");
    let hi = reference_surface(&scratch);
    let lo = coarse_asset(&scratch, &valid, "low", false);
    let c = pipeline_error(&hi, &lo, &scratch.join("diff.png"));
    let a = &c["normal_angle_deg"];
    let compared = c["pixels_compared"].as_u64().unwrap();
    assert!(compared > 8000, "too few pixels compared: {c}");
    assert!(a["mean"].as_f64().unwrap() < 2.0, "mean shading-normal error too large: {c}");
    assert!(a["p95"].as_f64().unwrap() < 4.0, "{c}");
    assert!(c["psnr_db"].as_f64().unwrap() > 30.0, "{c}");

    // Flipped green channel: the error is large.
    let green = coarse_asset(&scratch, &scratch, "green", true);
    let g = pipeline_error(&hi, &green, &scratch.join("diff_green.png"));
    assert!(g["normal_angle_deg"]["mean"].as_f64().unwrap() > 4.0, "flipped green not caught: {g}");

    // Flipped w: the same asset with every handedness negated.
    let mut scene = load(&lo);
    let mut p = scene.primitive(P0).unwrap();
    let t: Vec<[f32; 4]> =
        p.attr("TANGENT").unwrap().to_f32::<4>().into_iter().map(|t| [t[0], t[1], t[2], -t[3]]).collect();
    p.set_attr("TANGENT", bumpbake::scene::Stream::from_f32("VEC4", &t));
    scene.set_primitive(P0, &p);
    let flipped = scratch.join("w.glb");
    let (outs, _) = bumpbake::format::write(&scene, &flipped, &Default::default()).unwrap();
    outs.commit().unwrap();
    let w = pipeline_error(&hi, &flipped, &scratch.join("diff_w.png"));
    assert!(w["normal_angle_deg"]["mean"].as_f64().unwrap() > 4.0, "flipped w not caught: {w}");
}

// ---------- other behaviour ----------

#[test]
fn renders_obj_and_is_deterministic() {
    let dir = scratch_dir("preview_obj");
    let (a, b) = (dir.join("a.png"), dir.join("b.png"));
    let obj = fixture("spot/spot.obj");
    preview(&[s(&obj), "-o", s(&a), "--size", "96x96", "--ssaa", "2", "--yaw", "150", "-q"]);
    let out = bin()
        .args(["preview", s(&obj), "-o", s(&b), "--size", "96x96", "--ssaa", "2", "--yaw", "150", "-q"])
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .unwrap();
    assert!(out.status.success());
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap(), "output depends on threads");
    let (_, _, l) = luma(&a);
    let lit = l.iter().filter(|&&v| v > 60.0).count();
    assert!(lit > 96 * 96 / 10, "the cow should fill part of the frame: {lit} lit pixels");
}

#[test]
fn every_view_and_light_kind_renders() {
    let dir = scratch_dir("preview_views");
    let m = fixture("khronos/NormalTangentTest.glb");
    for v in ["shaded", "normal", "tangent", "bitangent", "handedness", "nomap"] {
        let p = dir.join(format!("{v}.png"));
        preview(&[s(&m), "-o", s(&p), "--view", v, "--size", "48x32", "-q"]);
        let img = image::open(&p).unwrap();
        assert_eq!((img.width(), img.height()), (48, 32));
    }
    let p = dir.join("lights.png");
    preview(&[
        s(&m),
        "-o",
        s(&p),
        "--size",
        "48x48",
        "--light",
        "point:0,0,3@0.5",
        "--light",
        "spot:0,0,3:0,0,-1:20",
        "--yaw",
        "-30",
        "--pitch",
        "-10",
        "-q",
    ]);
    // A camera inside the bounds exercises near-plane clipping.
    preview(&[s(&m), "-o", s(&p), "--size", "48x48", "--distance", "0.05", "-q"]);
}

#[test]
fn bad_input_exits_2_with_one_line_naming_the_file() {
    let dir = scratch_dir("preview_bad");
    let junk = dir.join("junk.glb");
    std::fs::write(&junk, b"glTF\x02\x00\x00\x00garbage").unwrap();
    let out_png = dir.join("o.png");
    for (args, needle) in [
        (vec!["preview", s(&junk), "-o", s(&out_png)], "junk.glb"),
        (vec!["preview", "does-not-exist.glb", "-o", s(&out_png)], "does-not-exist.glb"),
        (vec!["preview", s(&fixture("spot/spot.obj")), "-o", "x.jpg"], "x.jpg"),
        (vec!["preview", s(&fixture("spot/spot.obj")), "-o", s(&out_png), "--light", "dir:0,0"], "dir:0,0"),
        (vec!["preview", s(&fixture("spot/spot.obj")), "-o", s(&out_png), "--view", "diff"], "--compare"),
    ] {
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
        assert!(!out_png.exists(), "{args:?} wrote an output");
    }
    // A texture that is not an image.
    let mut g = Gltf::new();
    let (p, n, uv, idx) = grid(1);
    let (a_p, a_n, a_uv, a_i) =
        (g.floats(&p, Some(34962)), g.floats(&n, Some(34962)), g.floats(&uv, Some(34962)), g.indices(&idx));
    let t = g.png_texture(b"not a png");
    let m = g.material(json!({ "normalTexture": { "index": t } }));
    g.mesh(
        json!({ "attributes": { "POSITION": a_p, "NORMAL": a_n, "TEXCOORD_0": a_uv }, "indices": a_i, "material": m }),
    );
    let bad_tex = dir.join("badtex.glb");
    g.write_glb(&bad_tex);
    let o = run(&["preview", s(&bad_tex), "-o", s(&out_png)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("badtex.glb") && err.contains("image"), "{err}");
    assert!(!out_png.exists());
}

// ---------- strips and fans ----------

/// Strips and fans are drawn as the triangles they make, exactly as `tangents` processes them: the
/// same image as the triangle list with those triangles (odd strip triangles wound back, as glTF
/// says).
#[test]
fn strips_and_fans_draw_as_the_triangles_they_make() {
    let d = scratch_dir("preview_strip_fan");
    // A wavy band: strip vertices alternate bottom and top; a fan around its first vertex.
    let n = 8;
    let mut pos = Vec::new();
    let mut uv = Vec::new();
    for i in 0..=n {
        let x = i as f32 / n as f32;
        for y in [0.0f32, 1.0] {
            pos.push([x * 2.0 - 1.0, y * 2.0 - 1.0, 0.2 * (x * 6.0).sin()]);
            uv.push([x, 1.0 - y]);
        }
    }
    let count = pos.len() as u16;
    let strip: Vec<u16> = (0..count).collect();
    let fan: Vec<u16> = std::iter::once(0).chain((1..count).rev()).collect();
    let strip_list: Vec<u16> = (2..strip.len())
        .flat_map(|k| {
            if k % 2 == 0 {
                [strip[k - 2], strip[k - 1], strip[k]]
            } else {
                [strip[k - 1], strip[k - 2], strip[k]]
            }
        })
        .collect();
    let fan_list: Vec<u16> = (2..fan.len()).flat_map(|k| [fan[0], fan[k - 1], fan[k]]).collect();
    let write = |name: &str, idx: &[u16], mode: Option<u32>| {
        let mut g = Gltf::new();
        let p = g.floats(&pos, Some(34962));
        let t = g.floats(&uv, Some(34962));
        let i = g.indices(idx);
        let tex = g.texture();
        let m = g.material(json!({ "normalTexture": { "index": tex } }));
        let mut prim = json!({ "attributes": { "POSITION": p, "TEXCOORD_0": t }, "indices": i, "material": m });
        if let Some(mode) = mode {
            prim["mode"] = json!(mode);
        }
        g.mesh(prim);
        let f = d.join(format!("{name}.glb"));
        g.write_glb(&f);
        let png = d.join(format!("{name}.png"));
        preview(&[s(&f), "-o", s(&png), "--size", "96x96"]);
        std::fs::read(png).unwrap()
    };
    let strip_png = write("strip", &strip, Some(5));
    assert_eq!(strip_png, write("strip_list", &strip_list, None), "a strip draws as its triangle list");
    let fan_png = write("fan", &fan, Some(6));
    assert_eq!(fan_png, write("fan_list", &fan_list, None), "a fan draws as its triangle list");
    assert_ne!(strip_png, fan_png, "the two are different meshes (the strip is drawn at all)");
}

/// The most common test asset, a plane lying in XZ facing +Y, is drawn face-on by default (not
/// edge-on from the front), and the report says which view was chosen; angles the user gives
/// stand, and an object that is not flat keeps the front view.
#[test]
fn a_flat_plane_is_previewed_face_on_and_the_report_names_the_view() {
    let dir = scratch_dir("preview_flat");
    let (p, n, uv, idx) = grid(4);
    // The grid turned from XY (facing +Z) into XZ (facing +Y): (x, y, 0) -> (x, 0, -y).
    let p = p.iter().map(|q| [q[0], 0.0, -q[1]]).collect();
    let n = n.iter().map(|_| [0.0, 1.0, 0.0]).collect();
    let plane = dir.join("plane.glb");
    write_mesh(&plane, (p, n, uv, idx), None, None);
    let png = dir.join("plane.png");
    let out = preview(&[s(&plane), "-o", s(&png), "--size", "64x64", "--json"]);
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["camera"]["view"], "top", "{report}");
    assert_eq!(report["camera"]["pitch"], 90.0, "{report}");
    assert!(report["camera"]["flat"].as_str().unwrap().contains("XZ"), "{report}");
    let background = |path: &Path| {
        let img = image::open(path).unwrap().to_rgb8();
        let bg = [0.12f32, 0.12, 0.13].map(|c| (c * 255.0).round() as u8);
        img.pixels().filter(|p| p.0 == bg).count() as f64 / (img.width() * img.height()) as f64
    };
    let empty = background(&png);
    assert!(empty < 0.1, "the plane fills the image: {:.0}% background", empty * 100.0);
    // The human report says it too.
    let human = run_ok(&["preview", s(&plane), "-o", s(&png), "--size", "64x64"]);
    let err = String::from_utf8_lossy(&human.stderr);
    assert!(err.contains("camera: flat in XZ: top view, from +Y"), "{err}");
    // Angles the user gives are kept, even edge-on.
    let edge = dir.join("edge.png");
    let out = preview(&[s(&plane), "-o", s(&edge), "--size", "64x64", "--pitch", "0", "--json"]);
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["camera"]["view"], "given", "{report}");
    assert!(report["camera"].get("flat").is_none(), "{report}");
    assert!(background(&edge) > 0.9, "edge-on as asked");
    // Not flat: the front view, as before.
    let cow = dir.join("cow.png");
    let out = preview(&[s(&fixture("spot/spot.obj")), "-o", s(&cow), "--size", "32x32", "--json"]);
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["camera"], json!({ "yaw": 0.0, "pitch": 0.0, "view": "front" }), "{report}");
}

/// The library's check of the camera's numbers, worded in the command line's flags.
#[test]
fn a_bad_camera_number_names_its_flag() {
    let spot = fixture("spot/spot.obj").to_string_lossy().into_owned();
    for (flag, value, words) in [
        ("--fov", "0", "preview: --fov 0 is not a usable value: give degrees between 0 and 180"),
        ("--distance=-2", "", "preview: --distance -2 must be positive"),
    ] {
        let mut args = vec!["preview", &spot, "-o", "/nonexistent/p.png", flag];
        args.extend([value].into_iter().filter(|v| !v.is_empty()));
        let out = run(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert_eq!(err.trim_end(), format!("bumpbake: {words}"), "{err}");
    }
}
