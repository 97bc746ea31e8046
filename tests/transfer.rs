//! `bake LOW --from HIGH`: maps measured against surfaces whose normals are known in closed form,
//! decoded through the frames written into OUT; misses, overlaps, degenerate input, far-away
//! meshes, grazing rays, mirrored UVs and thread counts.

mod common;
use bumpbake::analytic::torus::{evaluate, Evaluation, Mesh, Torus};
use common::*;
use glam::DVec3;
use std::path::{Path, PathBuf};

fn write(path: &Path, m: &Mesh) -> PathBuf {
    std::fs::write(path, m.glb()).unwrap();
    path.to_path_buf()
}

fn bake(low: &Path, high: &Path, out: &Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["bake", s(low), "--from", s(high), "-o", s(out), "--json"];
    args.extend_from_slice(extra);
    let o = run_ok(&args);
    serde_json::from_slice(&o.stdout).unwrap()
}

fn counts(rep: &serde_json::Value) -> &serde_json::Value {
    &rep["transfer"]["counts"]
}

/// A height field `z = h(x, y)` with its gradient.
type Field = dyn Fn(f64, f64) -> (f64, f64, f64) + Sync;

/// HIGH: `n x n` quads of `h` over `[x0, x1] x [0, 1]`, exact normals, vertices offset by `off`.
fn field_high(h: &Field, n: usize, x0: f64, x1: f64, off: DVec3) -> Mesh {
    let mut m = Mesh::default();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (x0 + (x1 - x0) * i as f64 / n as f64, j as f64 / n as f64);
            let (z, hx, hy) = h(x, y);
            m.positions.push((DVec3::new(x, y, z) + off).as_vec3().to_array());
            m.normals.push(DVec3::new(-hx, -hy, 1.0).normalize().as_vec3().to_array());
        }
    }
    let w = (n + 1) as u32;
    for j in 0..n as u32 {
        for i in 0..n as u32 {
            let a = j * w + i;
            m.indices.extend([a, a + 1, a + w + 1, a, a + w + 1, a + w]);
        }
    }
    m
}

/// LOW: the flat `n x n` grid over `[x0, x1] x [0, 1]` at z = 0 with UVs `uv(x, y)`.
fn flat_low(n: usize, x0: f64, x1: f64, off: DVec3, uv: &dyn Fn(f64, f64) -> [f32; 2]) -> Mesh {
    let mut m = field_high(&|_, _| (0.0, 0.0, 0.0), n, x0, x1, off);
    m.uvs = m
        .positions
        .iter()
        .map(|p| {
            let q = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) - off;
            uv(q.x, q.y)
        })
        .collect();
    m
}

/// The true normal where the ray from `p` along `d` meets `z = h(x, y)` (+ `off`).
fn field_truth(h: &Field, off: DVec3) -> impl Fn(DVec3, DVec3) -> Option<DVec3> + Sync + '_ {
    move |p, d| {
        let p = p - off;
        let mut s = 0.0;
        for _ in 0..50 {
            let q = p + d * s;
            let (z, hx, hy) = h(q.x, q.y);
            // Newton on f(s) = q.z - h(q.x, q.y).
            let f = q.z - z;
            let df = d.z - hx * d.x - hy * d.y;
            s -= f / df;
        }
        let q = p + d * s;
        let (z, hx, hy) = h(q.x, q.y);
        ((q.z - z).abs() < 1e-9).then(|| DVec3::new(-hx, -hy, 1.0).normalize())
    }
}

fn bumps(x: f64, y: f64) -> (f64, f64, f64) {
    // Even in x, so that a mirrored UV layout over x = 0 sees the same map on both sides.
    let (a, k, l) = (0.012, 9.0, 7.0);
    let z = a * (k * x).cos() * (l * y).sin();
    (z, -a * k * (k * x).sin() * (l * y).sin(), a * l * (k * x).cos() * (l * y).cos())
}

fn assert_within(e: &Evaluation, mean: f64, p99: f64, what: &str) {
    assert!(e.synced.texels > 1000, "{what}: only {} texels measured", e.synced.texels);
    assert_eq!(e.no_truth, 0, "{what}: rays that met no surface");
    assert!(
        e.synced.mean <= mean && e.synced.p99 <= p99,
        "{what}: mean {:.3}° (<= {mean}), p99 {:.3}° (<= {p99}), max {:.3}°",
        e.synced.mean,
        e.synced.p99,
        e.synced.max
    );
}

/// The target: a displaced torus, 1024x1024, 8-bit, decoded through OUT's frames (seams
/// included): mean <= 0.3°, p99 <= 0.65°. The reference renderer agrees.
#[test]
fn analytic_torus_within_targets() {
    let v = validated_dir("transfer_torus");
    let t = Torus::default();
    let high = write(&v.join("high.glb"), &t.high(1096, 274));
    let low = write(&v.join("low.glb"), &t.low(48, 24));
    let out = v.join("baked.glb");
    let rep = bake(&low, &high, &out, &["--size", "1024"]);
    let c = counts(&rep);
    assert_eq!(c["missed_rays"], 0);
    assert_eq!(c["overlapping_samples"], 0);
    assert_eq!(c["uncovered"], 0);
    assert_eq!(c["covered"], 1024 * 1024);
    let e = evaluate(&out, &|p, d| t.truth(p, d, 0.2), &|_| true).unwrap();
    assert_within(&e, 0.3, 0.65, "torus");

    let o = run_ok(&["preview", "--reference", s(&high), "--compare", s(&out), "-o", s(&v.join("diff.png")), "--json"]);
    let cmp: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let mean = cmp["comparison"]["normal_angle_deg"]["mean"].as_f64().unwrap();
    let flat = {
        let o = run_ok(&[
            "preview",
            "--reference",
            s(&high),
            "--compare",
            s(&low),
            "-o",
            s(&v.join("diff0.png")),
            "--json",
        ]);
        let c: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        c["comparison"]["normal_angle_deg"]["mean"].as_f64().unwrap()
    };
    // The renders differ by parallax too: the same pixel sees HIGH up to 0.035 off LOW.
    assert!(mean < 2.0 && mean < flat / 5.0, "preview: baked {mean:.2}° from HIGH, unbaked LOW {flat:.2}°");
}

/// Mirrored UV islands: the left half of LOW reuses the right half's UVs flipped. HIGH is even in
/// x, so one map is right on both sides, read through frames of opposite handedness.
#[test]
fn mirrored_uv_islands_are_right_on_both_sides() {
    let v = validated_dir("transfer_mirror");
    let high = write(&v.join("high.glb"), &field_high(&bumps, 250, -1.0, 1.0, DVec3::ZERO));
    let low = write(
        &v.join("low.glb"),
        &flat_low(16, -1.0, 1.0, DVec3::ZERO, &|x, y| [(0.5 + 0.45 * x.abs()) as f32, (0.05 + 0.9 * (1.0 - y)) as f32]),
    );
    let out = v.join("baked.glb");
    let rep = bake(&low, &high, &out, &["--size", "512"]);
    let c = counts(&rep);
    assert!(c["overlapping_samples"].as_u64().unwrap() > 0, "the mirrored halves overlap in UV");
    // Half the square has no island: the borders are extended, 16 rings padded, the rest flat.
    assert!(c["extended"].as_u64().unwrap() > 0 && c["padded"].as_u64().unwrap() > 0);
    assert!(c["uncovered"].as_u64().unwrap() > 100 * 512);
    let truth = field_truth(&bumps, DVec3::ZERO);
    let right = evaluate(&out, &truth, &|p| p.x > 0.0).unwrap();
    let left = evaluate(&out, &truth, &|p| p.x < 0.0).unwrap();
    assert_within(&right, 0.35, 0.8, "right half");
    assert_within(&left, 0.35, 0.8, "left (mirrored) half");
}

/// A model a thousand units from the origin bakes as well as at the origin.
#[test]
fn far_from_the_origin() {
    let v = validated_dir("transfer_far");
    let mut errs = Vec::new();
    for off in [DVec3::ZERO, DVec3::new(1000.0, -1500.0, 800.0)] {
        let high = write(&v.join("high.glb"), &field_high(&bumps, 300, 0.0, 1.0, off));
        let low = write(&v.join("low.glb"), &flat_low(8, 0.0, 1.0, off, &|x, y| [x as f32, (1.0 - y) as f32]));
        let out = v.join(format!("baked_{}.glb", errs.len()));
        let rep = bake(&low, &high, &out, &["--size", "256"]);
        assert_eq!(counts(&rep)["missed_rays"], 0);
        let e = evaluate(&out, &field_truth(&bumps, off), &|_| true).unwrap();
        assert_within(&e, 0.4, 0.9, &format!("offset {off}"));
        errs.push(e.synced.mean);
    }
    assert!(errs[1] < errs[0] + 0.05, "far away {:.3}° against {:.3}° at the origin", errs[1], errs[0]);
}

/// Duplicate and zero-area triangles in HIGH change nothing; rays exactly through HIGH's
/// vertices, and rays in the plane of a vertical wall, find the surface under them.
#[test]
fn degenerate_duplicate_and_grazing() {
    let v = validated_dir("transfer_degenerate");
    let n = 64;
    let tilt = |i: usize, j: usize| {
        let t = DVec3::new((i as f64 * 0.7).sin() * 0.4, (j as f64 * 0.9).cos() * 0.4, 1.0).normalize();
        t.as_vec3().to_array()
    };
    // HIGH's vertices sit exactly under texel centres (and one ring beyond LOW's edges): every
    // ray passes through a vertex.
    let mut clean = Mesh::default();
    let m = n + 2;
    for j in 0..m {
        for i in 0..m {
            let (x, y) = ((i as f32 - 0.5) / n as f32, (j as f32 - 0.5) / n as f32);
            clean.positions.push([x, y, 0.0]);
            clean.normals.push(tilt(i, j));
        }
    }
    let w = m as u32;
    for j in 0..w - 1 {
        for i in 0..w - 1 {
            let a = j * w + i;
            clean.indices.extend([a, a + 1, a + w + 1, a, a + w + 1, a + w]);
        }
    }
    // A vertical wall in the plane of the rays of texel column 10.
    let x = 10.5 / n as f32;
    let base = clean.positions.len() as u32;
    clean.positions.extend([[x, 0.0, -0.5], [x, 1.0, -0.5], [x, 1.0, 0.5], [x, 0.0, 0.5]]);
    clean.normals.extend([[1.0, 0.0, 0.0]; 4]);
    clean.indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    let mut dirty = clean.clone();
    let tris = clean.indices.len() / 3;
    for k in (0..tris).step_by(3) {
        let t = clean.indices[3 * k..3 * k + 3].to_vec();
        dirty.indices.extend(&t);
        dirty.indices.extend([t[0], t[0], t[1]]);
    }
    let mut low = flat_low(4, 0.0, 1.0, DVec3::new(0.0, 0.0, 0.01), &|x, y| [x as f32, (1.0 - y) as f32]);
    // One more triangle whose UVs have no area: counted, baked nowhere.
    let k = low.positions.len() as u32;
    low.positions.extend([[0.2, 0.2, 0.01], [0.3, 0.2, 0.01], [0.2, 0.3, 0.01]]);
    low.normals.extend([[0.0, 0.0, 1.0]; 3]);
    low.uvs.extend([[0.5, 0.5]; 3]);
    low.indices.extend([k, k + 1, k + 2]);
    let low = write(&v.join("low.glb"), &low);
    let a = v.join("clean.glb");
    let b = v.join("dirty.glb");
    let args = ["--size", "64", "--padding", "0"];
    let ra = bake(&low, &write(&v.join("high_clean.glb"), &clean), &a, &args);
    let rb = bake(&low, &write(&v.join("high_dirty.glb"), &dirty), &b, &args);
    assert_eq!(counts(&ra)["missed_rays"], 0, "rays through HIGH's vertices slipped through");
    assert_eq!(counts(&ra)["zero_uv_triangles"], 1);
    assert_eq!(counts(&ra), counts(&rb));
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap(), "duplicates and degenerates changed the map");
    // LOW's frame is the world's (u along x, v up along y): each texel holds its vertex's normal.
    let map = image_of(&a);
    for (k, p) in map.pixels().enumerate() {
        let (i, j) = (k % n, n - 1 - k / n);
        let want = tilt(i + 1, j + 1).map(|c| ((c as f64 * 0.5 + 0.5) * 255.0).round() as i32);
        let got = p.0.map(|c| c as i32);
        assert!((0..3).all(|c| (got[c] - want[c]).abs() <= 1), "texel {i},{j}: {got:?}, HIGH's normal is {want:?}");
    }
}

/// The normal map inside OUT (material 0).
fn image_of(out: &Path) -> image::RgbImage {
    let sc = load(out);
    let t = sc.json.pointer("/materials/0/normalTexture/index").unwrap().as_u64().unwrap();
    let img = sc.texture_image(t as usize).unwrap();
    image::load_from_memory(&sc.image_bytes(img).unwrap()).unwrap().to_rgb8()
}

/// A hole in HIGH: the rays there miss, are counted and shown in the mask, and the texels are
/// flat; elsewhere the map is right.
#[test]
fn hole_in_high_gives_flat_texels_and_a_miss_mask() {
    let v = validated_dir("transfer_hole");
    let mut high = field_high(&bumps, 200, 0.0, 1.0, DVec3::ZERO);
    // Drop every triangle whose corners all lie within 0.2 of the centre.
    let near = |i: u32| {
        let p = high.positions[i as usize];
        (p[0] - 0.5).hypot(p[1] - 0.5) < 0.2
    };
    let kept: Vec<u32> =
        high.indices.chunks_exact(3).filter(|t| !t.iter().all(|&i| near(i))).flatten().copied().collect();
    high.indices = kept;
    let high = write(&v.join("high.glb"), &high);
    let low = write(&v.join("low.glb"), &flat_low(8, 0.0, 1.0, DVec3::ZERO, &|x, y| [x as f32, (1.0 - y) as f32]));
    let out = v.join("baked.glb");
    let mask = scratch_dir("transfer_hole").join("miss.png");
    let rep = bake(
        &low,
        &high,
        &out,
        &["--size", "128", "--ray-front", "0.05", "--ray-back", "0.05", "--miss-mask", s(&mask)],
    );
    let missed = counts(&rep)["missed_rays"].as_u64().unwrap();
    // The hole covers about pi * 0.19^2 of the square.
    assert!((missed as f64 - 0.113 * 128.0 * 128.0).abs() < 0.02 * 128.0 * 128.0, "{missed} rays missed");
    assert_eq!(counts(&rep)["texels_with_misses"], missed);
    let m = image::open(&mask).unwrap().to_luma8();
    let map = image_of(&out);
    for y in 0..128u32 {
        for x in 0..128u32 {
            let (px, py) = ((x as f64 + 0.5) / 128.0, 1.0 - (y as f64 + 0.5) / 128.0);
            let r = (px - 0.5).hypot(py - 0.5);
            if r < 0.17 {
                assert_eq!(m.get_pixel(x, y).0, [255], "texel {x},{y} in the hole is not in the mask");
                assert_eq!(map.get_pixel(x, y).0, [128, 128, 255], "texel {x},{y} in the hole is not flat");
            } else if r > 0.22 {
                assert_eq!(m.get_pixel(x, y).0, [0]);
            }
        }
    }
    let e = evaluate(&out, &field_truth(&bumps, DVec3::ZERO), &|p| (p.x - 0.5).hypot(p.y - 0.5) > 0.22).unwrap();
    assert_within(&e, 0.4, 0.9, "around the hole");
}

/// Same bytes (OUT, height map, miss mask) with one thread or two, and with a cage.
#[test]
fn deterministic_across_thread_counts() {
    let v = validated_dir("transfer_det");
    let t = Torus::default();
    let high = write(&v.join("high.glb"), &t.high(300, 80));
    let low = write(&v.join("low.glb"), &t.low(48, 24));
    let sd = scratch_dir("transfer_det");
    let mut outs = Vec::new();
    for threads in ["1", "2", "3"] {
        let out = v.join(format!("baked_{threads}.glb"));
        let hmap = sd.join(format!("h_{threads}.png"));
        let o = bin()
            .env("RAYON_NUM_THREADS", threads)
            .args(["bake", s(&low), "--from", s(&high), "-o", s(&out), "--size", "200x160", "--samples", "2"])
            .args(["--height-out", s(&hmap)])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        outs.push((std::fs::read(&out).unwrap(), std::fs::read(&hmap).unwrap()));
    }
    assert!(outs.windows(2).all(|w| w[0] == w[1]), "bytes differ between thread counts");
}

/// A cage (LOW pushed out along its normals) gives the same quality as the default reach.
#[test]
fn cage_bakes_like_the_default_reach() {
    let v = validated_dir("transfer_cage");
    let t = Torus::default();
    let high = write(&v.join("high.glb"), &t.high(600, 150));
    let low_mesh = t.low(48, 24);
    let low = write(&v.join("low.glb"), &low_mesh);
    let mut cage = low_mesh.clone();
    for (p, n) in cage.positions.iter_mut().zip(&low_mesh.normals) {
        (0..3).for_each(|c| p[c] += 0.08 * n[c]);
    }
    let cage = write(&v.join("cage.glb"), &cage);
    let a = v.join("plain.glb");
    let b = v.join("caged.glb");
    bake(&low, &high, &a, &["--size", "256"]);
    let rep = bake(&low, &high, &b, &["--size", "256", "--cage", s(&cage), "--ray-back", "0.08"]);
    assert_eq!(counts(&rep)["missed_rays"], 0);
    let ea = evaluate(&a, &|p, d| t.truth(p, d, 0.2), &|_| true).unwrap();
    let eb = evaluate(&b, &|p, d| t.truth(p, d, 0.2), &|_| true).unwrap();
    assert!(eb.synced.mean < ea.synced.mean + 0.1, "cage {:.3}° against {:.3}°", eb.synced.mean, ea.synced.mean);
}

/// Inputs `--from` cannot use are refused in one line, exit 2, nothing written.
#[test]
fn bad_inputs_are_refused() {
    let v = scratch_dir("transfer_bad");
    let t = Torus::default();
    let high = write(&v.join("high.glb"), &t.high(40, 10));
    let low = write(&v.join("low.glb"), &t.low(8, 4));
    let no_uv = write(&v.join("nouv.glb"), &t.high(8, 4));
    let wrong_cage = write(&v.join("cage.glb"), &t.low(8, 5));
    let out = v.join("out.glb");
    let missing = v.join("missing.glb");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["bake", s(&low), "--from", s(&missing), "-o", s(&out)], "missing.glb"),
        (vec!["bake", s(&no_uv), "--from", s(&high), "-o", s(&out)], "TEXCOORD_0"),
        (vec!["bake", s(&low), "--from", s(&high), "--cage", s(&wrong_cage), "-o", s(&out)], "cage"),
        (vec!["bake", s(&low), "--from", s(&high), "--size", "0", "-o", s(&out)], "--size"),
        (vec!["bake", s(&low), "--from", s(&high), "--samples", "9", "-o", s(&out)], "--samples"),
        (vec!["bake", s(&low), "--from", s(&high), "--ray-front=-1", "-o", s(&out)], "--ray-front"),
    ];
    for (args, says) in cases {
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?} should name {says}: {err}");
        assert!(!err.contains("{") && err.trim().lines().count() == 1, "{args:?}: one plain line: {err}");
        assert!(!out.exists(), "{args:?} wrote output");
    }
}

/// An OBJ LOW (UVs stored v up) bakes the same map as the same LOW in glTF (v down).
#[test]
fn obj_low_bakes_like_gltf_low() {
    let v = validated_dir("transfer_obj");
    let high = write(&v.join("high.glb"), &field_high(&bumps, 200, 0.0, 1.0, DVec3::ZERO));
    let low = flat_low(6, 0.0, 1.0, DVec3::ZERO, &|x, y| [(0.1 + 0.8 * x) as f32, (0.1 + 0.8 * (1.0 - y)) as f32]);
    let glb = write(&v.join("low.glb"), &low);
    let mut obj = String::new();
    for (p, (n, t)) in low.positions.iter().zip(low.normals.iter().zip(&low.uvs)) {
        obj += &format!("v {} {} {}\nvn {} {} {}\nvt {} {}\n", p[0], p[1], p[2], n[0], n[1], n[2], t[0], 1.0 - t[1]);
    }
    for t in low.indices.chunks_exact(3) {
        let [a, b, c] = [t[0] + 1, t[1] + 1, t[2] + 1];
        obj += &format!("f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}\n");
    }
    let obj_path = scratch_dir("transfer_obj").join("low.obj");
    std::fs::write(&obj_path, obj).unwrap();
    let (a, b) = (v.join("from_glb.glb"), v.join("from_obj.glb"));
    bake(&glb, &high, &a, &["--size", "128"]);
    bake(&obj_path, &high, &b, &["--size", "128"]);
    let (ia, ib) = (image_of(&a), image_of(&b));
    let worst = ia
        .pixels()
        .zip(ib.pixels())
        .flat_map(|(p, q)| (0..3).map(move |c| (p.0[c] as i32 - q.0[c] as i32).abs()))
        .max();
    assert!(worst.unwrap() <= 1, "maps differ by up to {worst:?}");
    let e = evaluate(&b, &field_truth(&bumps, DVec3::ZERO), &|_| true).unwrap();
    assert_within(&e, 0.4, 0.9, "OBJ LOW");
}

/// HIGH split over two files (`--from` twice) bakes the same map as HIGH in one file.
#[test]
fn several_high_files_bake_as_one() {
    let v = validated_dir("transfer_two_highs");
    let whole = field_high(&bumps, 120, 0.0, 1.0, DVec3::ZERO);
    let half = whole.indices.len() / 6 * 3;
    let (mut first, mut second) = (whole.clone(), whole.clone());
    first.indices.truncate(half);
    second.indices.drain(..half);
    let h = write(&v.join("high.glb"), &whole);
    let h1 = write(&v.join("high1.glb"), &first);
    let h2 = write(&v.join("high2.glb"), &second);
    let low = write(&v.join("low.glb"), &flat_low(4, 0.0, 1.0, DVec3::ZERO, &|x, y| [x as f32, (1.0 - y) as f32]));
    let (a, b) = (v.join("one.glb"), v.join("two.glb"));
    bake(&low, &h, &a, &["--size", "96"]);
    let rep = bake(&low, &h1, &b, &["--size", "96", "--from", s(&h2)]);
    assert_eq!(rep["transfer"]["high"].as_array().unwrap().len(), 2);
    assert_eq!(image_of(&a), image_of(&b));
}
