//! PLY in: the same mesh as OBJ and as PLY (ASCII, binary little and big endian, written here)
//! bakes the same map and gets the same tangents; damaged PLY files are clear errors.

mod common;
use common::*;
use std::path::{Path, PathBuf};

/// A bumpy 12x12 quad grid with exact normals and UVs.
struct Grid {
    pos: Vec<[f32; 3]>,
    nrm: Vec<[f32; 3]>,
    uv: Vec<[f32; 2]>,
    quads: Vec<[u32; 4]>,
}

fn grid(n: u32, bump: f32) -> Grid {
    let mut g = Grid { pos: vec![], nrm: vec![], uv: vec![], quads: vec![] };
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
            let z = bump * (x * 6.0).sin() * (y * 5.0).cos();
            let (hx, hy) =
                (bump * 6.0 * (x * 6.0).cos() * (y * 5.0).cos(), -bump * 5.0 * (x * 6.0).sin() * (y * 5.0).sin());
            let l = (hx * hx + hy * hy + 1.0).sqrt();
            g.pos.push([x, y, z]);
            g.nrm.push([-hx / l, -hy / l, 1.0 / l]);
            g.uv.push([x, y]);
        }
    }
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i;
            g.quads.push([a, a + 1, a + n + 2, a + n + 1]);
        }
    }
    g
}

fn obj(g: &Grid, name: &str) -> String {
    let mut s = format!("o {name}\n");
    for ((p, n), t) in g.pos.iter().zip(&g.nrm).zip(&g.uv) {
        s += &format!(
            "v {:?} {:?} {:?}\nvn {:?} {:?} {:?}\nvt {:?} {:?}\n",
            p[0], p[1], p[2], n[0], n[1], n[2], t[0], t[1]
        );
    }
    for q in &g.quads {
        let c: Vec<String> = q.iter().map(|i| format!("{0}/{0}/{0}", i + 1)).collect();
        s += &format!("f {}\n", c.join(" "));
    }
    s
}

fn ply(g: &Grid, enc: &str) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat {enc} 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\n\
         element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        g.pos.len(),
        g.quads.len()
    )
    .into_bytes();
    let be = enc == "binary_big_endian";
    let put = |out: &mut Vec<u8>, mut b: Vec<u8>| {
        if be {
            b.reverse();
        }
        out.extend(b);
    };
    for k in 0..g.pos.len() {
        let vals: Vec<f32> = g.pos[k].iter().chain(&g.nrm[k]).chain(&g.uv[k]).copied().collect();
        if enc == "ascii" {
            let t: Vec<String> = vals.iter().map(|v| format!("{v:?}")).collect();
            out.extend(format!("{}\n", t.join(" ")).bytes());
        } else {
            vals.iter().for_each(|v| put(&mut out, v.to_le_bytes().to_vec()));
        }
    }
    for q in &g.quads {
        if enc == "ascii" {
            out.extend(format!("4 {} {} {} {}\n", q[0], q[1], q[2], q[3]).bytes());
        } else {
            out.push(4);
            q.iter().for_each(|i| put(&mut out, i.to_le_bytes().to_vec()));
        }
    }
    out
}

const ENCODINGS: [&str; 3] = ["ascii", "binary_little_endian", "binary_big_endian"];

/// `high.obj` and `<enc>/high.ply` for every encoding, in `d`.
fn inputs(d: &Path, g: &Grid) -> Vec<PathBuf> {
    let mut files = vec![d.join("high.obj")];
    std::fs::write(&files[0], obj(g, "high")).unwrap();
    for enc in ENCODINGS {
        std::fs::create_dir_all(d.join(enc)).unwrap();
        let f = d.join(enc).join("high.ply");
        std::fs::write(&f, ply(g, enc)).unwrap();
        files.push(f);
    }
    files
}

#[test]
fn ply_and_obj_bake_the_same_map() {
    let d = scratch_dir("ply_bake");
    let highs = inputs(&d, &grid(12, 0.04));
    let low = d.join("low.obj");
    std::fs::write(&low, obj(&grid(3, 0.0), "low")).unwrap();
    let maps: Vec<Vec<u8>> = highs
        .iter()
        .enumerate()
        .map(|(k, h)| {
            let map = d.join(format!("map{k}.png"));
            let out = d.join(format!("out{k}.glb"));
            run_ok(&["bake", s(&low), "--from", s(h), "--size", "32", "--map-out", s(&map), "-o", s(&out), "-q"]);
            std::fs::read(&map).unwrap()
        })
        .collect();
    // The bumps show: the map is not flat.
    let img = image::load_from_memory(&maps[0]).unwrap().to_rgb8();
    assert!(img.pixels().any(|p| p[0].abs_diff(128) > 10), "the bake should show the bumps");
    for (k, m) in maps.iter().enumerate().skip(1) {
        assert!(m == &maps[0], "{} bakes a different map than the OBJ", highs[k].display());
    }
}

#[test]
fn ply_and_obj_get_the_same_tangents() {
    let d = scratch_dir("ply_tangents");
    let files = inputs(&d, &grid(6, 0.1));
    let outs: Vec<Vec<u8>> = files
        .iter()
        .enumerate()
        .map(|(k, f)| {
            let out = d.join(format!("t{k}.glb"));
            run_ok(&["tangents", s(f), "-o", s(&out), "-q"]);
            std::fs::read(&out).unwrap()
        })
        .collect();
    for (k, o) in outs.iter().enumerate().skip(1) {
        assert!(o == &outs[0], "{} gets different tangents than the OBJ", files[k].display());
    }
}

fn fails_cleanly(input: &Path, expect: &str) {
    let out = input.with_extension("glb");
    let o = run(&["tangents", s(input), "-o", s(&out)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{}: stderr: {err}", input.display());
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    assert!(err.contains(s(input)) && err.contains(expect), "{err}");
    assert!(!out.exists(), "no output after an error");
}

#[test]
fn damaged_ply_files_are_clear_errors() {
    let d = scratch_dir("ply_damaged");
    let g = grid(2, 0.0);
    for enc in ENCODINGS {
        let good = ply(&g, enc);
        let f = d.join(format!("{enc}-truncated.ply"));
        std::fs::write(&f, &good[..good.len() - 3]).unwrap();
        fails_cleanly(&f, "truncated");
        // The last face's last index points past the 9 vertices.
        let mut bad = good.clone();
        let n = bad.len();
        match enc {
            "ascii" => bad[n - 2] = b'9',
            "binary_big_endian" => bad[n - 1] = 9,
            _ => bad[n - 4] = 9,
        }
        let f = d.join(format!("{enc}-index.ply"));
        std::fs::write(&f, &bad).unwrap();
        fails_cleanly(&f, "names vertex 9, but there are 9 vertices");
    }
    let f = d.join("header.ply");
    let bad = String::from_utf8_lossy(&ply(&g, "ascii")).replace("property float y\n", "property float32 y z\n");
    std::fs::write(&f, bad.as_bytes()).unwrap();
    fails_cleanly(&f, "bad PLY header");
}
