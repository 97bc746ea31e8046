//! `bake --from` options against analytic cases: `--ignore-backfaces` on a thin shell, `--dither`
//! on a gentle ramp, and `--height-out` held to the normal map one trace writes with it.

mod common;
use common::*;
use serde_json::Value;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// An OBJ of `(position, normal)` corners, three to a triangle, counter-clockwise.
fn obj(path: &Path, tris: &[[([f64; 3], [f64; 3]); 3]]) -> PathBuf {
    let mut s = String::new();
    for (k, t) in tris.iter().enumerate() {
        for (p, n) in t {
            writeln!(s, "v {} {} {}\nvn {} {} {}", p[0], p[1], p[2], n[0], n[1], n[2]).unwrap();
        }
        let i = 3 * k + 1;
        writeln!(s, "f {i}//{i} {}//{} {}//{}", i + 1, i + 1, i + 2, i + 2).unwrap();
    }
    std::fs::write(path, s).unwrap();
    path.to_path_buf()
}

/// LOW: the unit square at z = 0 facing +z, its UVs its x and y (so the map's top row is y = 1).
fn flat_low(dir: &Path) -> PathBuf {
    let s = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n\
             f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n";
    let p = dir.join("low.obj");
    std::fs::write(&p, s).unwrap();
    p
}

fn bake(low: &Path, high: &Path, out: &Path, extra: &[&str]) -> Value {
    let mut args = vec!["bake", s(low), "--from", s(high), "-o", s(out), "--json"];
    args.extend_from_slice(extra);
    serde_json::from_slice(&run_ok(&args).stdout).unwrap()
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|x| x / l)
}

/// The six faces of the box `lo..hi`, wound to face out (or in, for a cavity), each with one
/// shading normal for all its corners, as `normal(axis, sign)` gives it.
fn box_faces(
    lo: [f64; 3],
    hi: [f64; 3],
    out: bool,
    normal: &dyn Fn(usize, f64) -> [f64; 3],
) -> Vec<[([f64; 3], [f64; 3]); 3]> {
    let mut tris = Vec::new();
    for a in 0..3 {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        for sign in [-1.0, 1.0] {
            let at = |u: f64, v: f64| {
                let mut p = [0.0; 3];
                p[a] = if sign > 0.0 { hi[a] } else { lo[a] };
                (p[b], p[c]) = (u, v);
                p
            };
            // Counter-clockwise seen from +a for (b, c) in this order: flipped for -a, and for a
            // cavity's walls, which face in.
            let mut q = [at(lo[b], lo[c]), at(hi[b], lo[c]), at(hi[b], hi[c]), at(lo[b], hi[c])];
            if (sign < 0.0) == out {
                q.reverse();
            }
            let n = normal(a, sign);
            tris.push([(q[0], n), (q[1], n), (q[2], n)]);
            tris.push([(q[0], n), (q[2], n), (q[3], n)]);
        }
    }
    tris
}

/// A thin shell around LOW: a box whose walls are 0.01 thick, the cavity's top wall at z = 0.01
/// facing LOW, the outside's at z = 0.02 facing away. Rays leave LOW along +z. Every face is
/// shaded with its own normal, except the outer top, tilted so that the map tells it apart.
/// Without the option the nearest wall, the inner one, is hit; with it, that wall faces away
/// from where the rays come from (beyond their outer end) and the outer one is hit.
#[test]
fn ignore_backfaces_sees_a_thin_shell_from_outside() {
    let d = scratch_dir("transfer_backfaces");
    let low = flat_low(&d);
    let tilt = unit([0.3, 0.0, 1.0]);
    let face = |a: usize, s: f64| {
        let mut n = [0.0; 3];
        n[a] = s;
        n
    };
    let mut shell = box_faces([-0.2, -0.2, -0.2], [1.2, 1.2, 0.02], true, &|a, s| {
        if a == 2 && s > 0.0 {
            tilt
        } else {
            face(a, s)
        }
    });
    shell.extend(box_faces([-0.1, -0.1, -0.1], [1.1, 1.1, 0.01], false, &|a, s| face(a, -s)));
    let high = obj(&d.join("shell.obj"), &shell);
    let size = ["--size", "32", "--ray-front", "0.05", "--ray-back", "0.05"];
    let (plain_map, culled_map) = (d.join("plain.png"), d.join("culled.png"));
    let plain = bake(&low, &high, &d.join("plain.glb"), &[&size[..], &["--map-out", s(&plain_map)]].concat());
    let culled = bake(
        &low,
        &high,
        &d.join("culled.glb"),
        &[&size[..], &["--map-out", s(&culled_map), "--ignore-backfaces"]].concat(),
    );
    let range = |r: &Value| -> [f64; 2] {
        let h = &r["transfer"]["height_range"];
        [h[0].as_f64().unwrap(), h[1].as_f64().unwrap()]
    };
    let near = |r: [f64; 2], z: f64| (r[0] - z).abs() < 1e-6 && (r[1] - z).abs() < 1e-6;
    assert!(near(range(&plain), 0.01), "without the option: {:?}", range(&plain));
    assert!(near(range(&culled), 0.02), "with the option: {:?}", range(&culled));
    for r in [&plain, &culled] {
        assert_eq!(r["transfer"]["counts"]["missed_rays"], 0);
    }
    // The inner wall faces LOW: its normal points below LOW's surface and is clamped (flat).
    assert_eq!(plain["transfer"]["counts"]["clamped_below"], 32 * 32);
    let px = |p: &Path| image::open(p).unwrap().to_rgb8();
    assert!(px(&plain_map).pixels().all(|p| p.0 == [128, 128, 255]));
    let want = tilt.map(|v| (v * 127.5 + 128.0) as u8);
    assert!(px(&culled_map).pixels().all(|p| p.0 == want), "the outer wall's tilt is {want:?}");
}

/// Lengths of the runs of equal values along a row.
fn runs(row: &[u8]) -> Vec<usize> {
    let mut out = vec![1];
    for w in row.windows(2) {
        if w[0] == w[1] {
            *out.last_mut().unwrap() += 1;
        } else {
            out.push(1);
        }
    }
    out
}

/// A gentle ramp: HIGH is LOW's square 0.001 above it, its shading normal turning about y from
/// +z at x = 0 to where the map's red rises four levels at x = 1, over 256 texels: rounding
/// alone makes bands one level's run wide (64 texels). Dithered, no run of equal values along a
/// row is half that long, and the mean over 16 texels of a column band follows the ramp within
/// a seventh of a level, which the bands miss by up to half a level.
#[test]
fn dither_breaks_the_bands_of_a_gentle_ramp() {
    let d = scratch_dir("transfer_dither");
    let low = flat_low(&d);
    let slope = 4.0 / 127.5;
    let n0 = [0.0, 0.0, 1.0];
    let n1 = unit([slope, 0.0, 1.0]);
    let p = |x: f64, y: f64| [x, y, 0.001];
    let high = obj(
        &d.join("ramp.obj"),
        &[
            [(p(0.0, 0.0), n0), (p(1.0, 0.0), n1), (p(1.0, 1.0), n1)],
            [(p(0.0, 0.0), n0), (p(1.0, 1.0), n1), (p(0.0, 1.0), n0)],
        ],
    );
    let (w, h) = (256usize, 16usize);
    let red = |dither: bool| -> Vec<u8> {
        let map = d.join(format!("ramp_{dither}.png"));
        let mut extra = vec!["--size", "256x16", "--padding", "0", "--map-out", s(&map)];
        if dither {
            extra.push("--dither");
        }
        bake(&low, &high, &d.join(format!("ramp_{dither}.glb")), &extra);
        image::open(&map).unwrap().to_rgb8().pixels().map(|p| p.0[0]).collect()
    };
    // The red level the ramp has at column x's centre: HIGH's normal there, normalised.
    let exact = |x: usize| {
        let t = (x as f64 + 0.5) / w as f64;
        let n = unit([n1[0] * t, 0.0, (1.0 - t) + n1[2] * t]);
        n[0] * 127.5 + 127.5
    };
    let (plain, dithered) = (red(false), red(true));
    let run = 64;
    let longest = |v: &[u8]| v.chunks(w).flat_map(runs).max().unwrap();
    let worst_mean = |v: &[u8]| {
        (0..w / 16)
            .map(|b| {
                let sum: f64 = (0..h)
                    .flat_map(|y| (16 * b..16 * b + 16).map(move |x| (x, y)))
                    .map(|(x, y)| v[y * w + x] as f64)
                    .sum();
                let want: f64 = (16 * b..16 * b + 16).map(exact).sum::<f64>() * h as f64;
                (sum - want).abs() / (16 * h) as f64
            })
            .fold(0.0, f64::max)
    };
    // The test's premise: rounding bands the ramp.
    assert!(longest(&plain) >= run - 1, "undithered runs up to {}", longest(&plain));
    assert!(worst_mean(&plain) > 0.3, "undithered mean off by {}", worst_mean(&plain));
    assert!(longest(&dithered) < run / 2, "a dithered band {} texels wide", longest(&dithered));
    assert!(worst_mean(&dithered) < 1.0 / 7.0, "dithered mean off by {} levels", worst_mean(&dithered));
    // Deterministic: the same bytes on one thread.
    let map = d.join("ramp_one_thread.png");
    let o = bin()
        .env("RAYON_NUM_THREADS", "1")
        .args(["bake", s(&low), "--from", s(&high), "-o", s(&d.join("one.glb")), "--size", "256x16"])
        .args(["--padding", "0", "--dither", "--map-out", s(&map)])
        .output()
        .unwrap();
    assert!(o.status.success());
    assert_eq!(std::fs::read(&map).unwrap(), std::fs::read(d.join("ramp_true.png")).unwrap());
}

/// Angle in degrees between two 16-bit RGB normals.
fn angle16(a: &[u16], b: &[u16]) -> f64 {
    let v = |p: &[u16]| unit([0, 1, 2].map(|k| p[k] as f64 / 65535.0 * 2.0 - 1.0));
    let (a, b) = (v(a), v(b));
    (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]).clamp(-1.0, 1.0).acos().to_degrees()
}

/// A height field HIGH over a flat LOW: the height map one trace writes, made into a normal map
/// by `normalmap` with the height range the report gives, is the normal map it writes, within
/// 0.5° mean (a 2-texel border, where the height map's differences are one-sided, left out).
#[test]
fn height_out_and_the_map_agree() {
    let d = scratch_dir("transfer_height_vs_map");
    let low = flat_low(&d);
    let (a, k, l) = (0.012, 9.0, 7.0);
    let field = |x: f64, y: f64| {
        let z = a * (k * x).cos() * (l * y).sin();
        let (hx, hy) = (-a * k * (k * x).sin() * (l * y).sin(), a * l * (k * x).cos() * (l * y).cos());
        ([x, y, z], unit([-hx, -hy, 1.0]))
    };
    let n = 200;
    let at = |i: usize, j: usize| field(i as f64 / n as f64, j as f64 / n as f64);
    let mut tris = Vec::new();
    for j in 0..n {
        for i in 0..n {
            tris.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            tris.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    let high = obj(&d.join("field.obj"), &tris);
    let (map, height, back) = (d.join("map.png"), d.join("height.png"), d.join("from_height.png"));
    let size = 256;
    let rep = bake(
        &low,
        &high,
        &d.join("field.glb"),
        &["--size", "256", "--bits16", "--map-out", s(&map), "--height-out", s(&height)],
    );
    let r = &rep["transfer"]["height_range"];
    let span = r[1].as_f64().unwrap() - r[0].as_f64().unwrap();
    assert!((span - 2.0 * a).abs() < 0.1 * a, "height range {r}");
    let texel = (1.0 / size as f64).to_string();
    run_ok(&[
        "normalmap",
        s(&height),
        "-o",
        s(&back),
        "--bits",
        "16",
        "--height-range",
        &span.to_string(),
        "--texel-size",
        &texel,
    ]);
    let (m, b) = (image::open(&map).unwrap().to_rgb16(), image::open(&back).unwrap().to_rgb16());
    let inner = 2..size as u32 - 2;
    let errs: Vec<f64> = inner
        .clone()
        .flat_map(|y| inner.clone().map(move |x| (x, y)))
        .map(|(x, y)| angle16(&m.get_pixel(x, y).0, &b.get_pixel(x, y).0))
        .collect();
    let mean = errs.iter().sum::<f64>() / errs.len() as f64;
    let max = errs.iter().copied().fold(0.0, f64::max);
    // The map is not flat (slopes up to 6°): agreeing means something.
    let tilt = inner.clone().map(|x| angle16(&m.get_pixel(x, 100).0, &[32768, 32768, 65535])).fold(0.0, f64::max);
    assert!(tilt > 4.0, "the map tilts only {tilt}°");
    assert!(mean < 0.5, "height map and normal map differ by {mean}° mean ({max}° max)");
}

/// The options belong to `--from`.
#[test]
fn the_options_need_from() {
    for flag in ["--dither", "--ignore-backfaces"] {
        let o = run(&["bake", s(&fixture("bake/torus.obj")), "-o", "/dev/null", flag]);
        assert_eq!(o.status.code(), Some(2), "{flag}");
    }
}
