//! `bake LOW --from HIGH` on scenes as tools export them: node transforms (scale, rotation,
//! translation, parent chains, mirroring), parts matched by name, several materials, a LOW mesh
//! shown twice. Each transformed case keeps the world geometry of a plain pair and must bake the
//! plain pair's map (within one 8-bit level).

mod common;
use bumpbake::analytic::torus::{Mesh, Torus};
use common::*;
use glam::{Mat3, Mat4, Quat, Vec3};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

const SIZE: &str = "128";

/// One primitive of a scene under construction.
struct Prim<'a> {
    mesh: &'a Mesh,
    material: Option<usize>,
}

/// A GLB of `meshes` (each a name and its primitives), `nodes` as given (glTF JSON), every
/// parentless node a root, and `materials` by name.
fn scene_glb(meshes: &[(&str, Vec<Prim>)], nodes: Value, materials: &[&str]) -> Vec<u8> {
    let mut bin: Vec<u8> = Vec::new();
    let (mut views, mut accessors) = (Vec::new(), Vec::new());
    let mut push = |bytes: &[u8], count: usize, ty: &str, ct: u32, minmax: Option<([f32; 3], [f32; 3])>| {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        views.push(json!({ "buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len() }));
        bin.extend_from_slice(bytes);
        let mut a = json!({ "bufferView": views.len() - 1, "componentType": ct, "count": count, "type": ty });
        if let Some((lo, hi)) = minmax {
            a["min"] = json!(lo);
            a["max"] = json!(hi);
        }
        accessors.push(a);
        accessors.len() - 1
    };
    let mut mesh_json = Vec::new();
    for (name, prims) in meshes {
        let mut pj = Vec::new();
        for p in prims {
            let m = p.mesh;
            let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            for q in &m.positions {
                for c in 0..3 {
                    lo[c] = lo[c].min(q[c]);
                    hi[c] = hi[c].max(q[c]);
                }
            }
            let pos = push(bytemuck::cast_slice(&m.positions), m.positions.len(), "VEC3", 5126, Some((lo, hi)));
            let nrm = push(bytemuck::cast_slice(&m.normals), m.normals.len(), "VEC3", 5126, None);
            let mut attrs = json!({ "POSITION": pos, "NORMAL": nrm });
            if !m.uvs.is_empty() {
                attrs["TEXCOORD_0"] = json!(push(bytemuck::cast_slice(&m.uvs), m.uvs.len(), "VEC2", 5126, None));
            }
            let idx = push(bytemuck::cast_slice(&m.indices), m.indices.len(), "SCALAR", 5125, None);
            let mut prim = json!({ "attributes": attrs, "indices": idx });
            if let Some(k) = p.material {
                prim["material"] = json!(k);
            }
            pj.push(prim);
        }
        mesh_json.push(json!({ "name": name, "primitives": pj }));
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let n = nodes.as_array().unwrap();
    let children: Vec<u64> = n
        .iter()
        .flat_map(|x| x["children"].as_array().cloned().unwrap_or_default())
        .filter_map(|c| c.as_u64())
        .collect();
    let roots: Vec<usize> = (0..n.len()).filter(|i| !children.contains(&(*i as u64))).collect();
    let mut j = json!({
        "asset": { "version": "2.0", "generator": "bumpbake tests" },
        "scene": 0, "scenes": [{ "nodes": roots }], "nodes": nodes,
        "meshes": mesh_json, "bufferViews": views, "accessors": accessors,
        "buffers": [{ "byteLength": bin.len() }],
    });
    if !materials.is_empty() {
        j["materials"] = json!(materials
            .iter()
            .map(|m| json!({ "name": m, "pbrMetallicRoughness": { "metallicFactor": 0.0 } }))
            .collect::<Vec<_>>());
    }
    let mut js = serde_json::to_vec(&j).unwrap();
    while !js.len().is_multiple_of(4) {
        js.push(b' ');
    }
    common::glb_bytes(&js, &bin)
}

/// A one-mesh scene: `mesh` under one node `name` with transform `m`.
fn single(name: &str, mesh: &Mesh, m: Mat4, material: bool) -> Vec<u8> {
    let mat = material.then_some(0);
    scene_glb(
        &[(name, vec![Prim { mesh, material: mat }])],
        json!([{ "name": name, "mesh": 0, "matrix": m.to_cols_array() }]),
        if material { &["low"] } else { &[] },
    )
}

/// `mesh` with its vertices moved by `m` (normals by its normal matrix).
fn moved(mesh: &Mesh, m: Mat4) -> Mesh {
    let nm = Mat3::from_mat4(m).inverse().transpose();
    let mut out = mesh.clone();
    out.positions = mesh.positions.iter().map(|p| m.transform_point3(Vec3::from(*p)).to_array()).collect();
    out.normals = mesh.normals.iter().map(|n| (nm * Vec3::from(*n)).normalize().to_array()).collect();
    out
}

fn torus() -> (Mesh, Mesh) {
    let t = Torus::default();
    (t.low(48, 24), t.high(274, 68))
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// Bakes and returns the JSON report.
fn bake(low: &Path, highs: &[&Path], out: &Path, extra: &[&str]) -> Value {
    let mut args = vec!["bake", s(low), "-o", s(out), "--json", "--size", SIZE];
    for h in highs {
        args.extend(["--from", s(h)]);
    }
    args.extend_from_slice(extra);
    serde_json::from_slice(&run_ok(&args).stdout).unwrap()
}

/// The normal map of material `k` inside OUT.
fn map_of(out: &Path, k: usize) -> image::RgbImage {
    let sc = load(out);
    let t = sc.json.pointer(&format!("/materials/{k}/normalTexture/index")).unwrap().as_u64().unwrap();
    let img = sc.texture_image(t as usize).unwrap();
    image::load_from_memory(&sc.image_bytes(img).unwrap()).unwrap().to_rgb8()
}

/// Largest channel difference between two maps over the texels `keep` selects, and how many
/// texels differ at all.
fn diff(a: &image::RgbImage, b: &image::RgbImage, keep: &dyn Fn(u32, u32) -> bool) -> (u8, usize) {
    let (mut most, mut n) = (0u8, 0);
    for (x, y, p) in a.enumerate_pixels() {
        if !keep(x, y) {
            continue;
        }
        let q = b.get_pixel(x, y);
        let d = (0..3).map(|c| p.0[c].abs_diff(q.0[c])).max().unwrap();
        most = most.max(d);
        n += (d > 0) as usize;
    }
    (most, n)
}

/// The plain pair's map: both meshes at identity, one unnamed node each.
fn plain(dir: &Path) -> (PathBuf, PathBuf, image::RgbImage) {
    let (low, high) = torus();
    let lp = write(dir, "low.glb", &low.glb());
    let hp = write(dir, "high.glb", &high.glb());
    let out = dir.join("plain.glb");
    bake(&lp, &[&hp], &out, &[]);
    (lp, hp, map_of(&out, 0))
}

/// Writes the plain pair and bakes it with the map, height and miss files, so a build before and
/// after a change can be compared byte for byte (`BUMPBAKE_PAIR_DIR=dir cargo test -- --ignored`).
#[test]
#[ignore]
fn write_plain_pair_for_hashing() {
    let Ok(d) = std::env::var("BUMPBAKE_PAIR_DIR") else { return };
    let dir = PathBuf::from(d);
    std::fs::create_dir_all(&dir).unwrap();
    let (low, high) = torus();
    let lp = write(&dir, "low.glb", &low.glb());
    let hp = write(&dir, "high.glb", &high.glb());
    let out = dir.join("plain.glb");
    let (m, h, mm) = (dir.join("map.png"), dir.join("height.png"), dir.join("miss.png"));
    bake(&lp, &[&hp], &out, &["--map-out", s(&m), "--height-out", s(&h), "--miss-mask", s(&mm), "--samples", "2"]);
}

fn rot_trans() -> Mat4 {
    Mat4::from_rotation_translation(Quat::from_euler(glam::EulerRot::XYZ, 0.7, -0.4, 1.9), Vec3::new(3.0, -1.5, 0.8))
}

/// The three cases the issue measured, and a parent chain with non-uniform scale: each keeps the
/// plain pair's world geometry, so each bakes the plain pair's map.
#[test]
fn transformed_meshes_bake_the_plain_map() {
    let d = scratch_dir("scenes_transformed");
    let (_, hp, want) = plain(&d);
    let (low, high) = torus();
    let lp = write(&d, "low_plain.glb", &single("torus", &low, Mat4::IDENTITY, true));
    let m = rot_trans();
    let parent = Mat4::from_scale_rotation_translation(
        Vec3::new(2.0, 1.0, 0.5),
        Quat::from_rotation_z(0.3),
        Vec3::new(0.0, 0.0, -2.0),
    );
    let child = Mat4::from_rotation_translation(Quat::from_rotation_x(0.8), Vec3::new(0.5, 0.0, 0.0));
    let chain = scene_glb(
        &[("torus_detail", vec![Prim { mesh: &moved(&high, (parent * child).inverse()), material: None }])],
        json!([
            { "name": "rig", "children": [1], "scale": [2.0, 1.0, 0.5],
              "rotation": Quat::from_rotation_z(0.3).to_array(), "translation": [0.0, 0.0, -2.0] },
            { "name": "torus_detail", "mesh": 0, "matrix": child.to_cols_array() },
        ]),
        &[],
    );
    // A mirrored object as an exporter writes it: the mesh as modelled (its winding agreeing with
    // its normals), the mirror in the node. glTF then reads its faces clockwise.
    let mirror = Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0));
    let mut mirrored_low = moved(&low, mirror);
    mirrored_low.indices.chunks_exact_mut(3).for_each(|t| t.swap(1, 2));
    let cases: Vec<(&str, PathBuf, PathBuf)> = vec![
        (
            "HIGH halved under scale 2",
            lp.clone(),
            write(
                &d,
                "h_scaled.glb",
                &single(
                    "detail",
                    &moved(&high, Mat4::from_scale(Vec3::splat(0.5))),
                    Mat4::from_scale(Vec3::splat(2.0)),
                    false,
                ),
            ),
        ),
        (
            "HIGH under rotation + translation",
            lp.clone(),
            write(&d, "h_moved.glb", &single("detail", &moved(&high, m.inverse()), m, false)),
        ),
        (
            "LOW under rotation + translation",
            write(&d, "l_moved.glb", &single("torus", &moved(&low, m.inverse()), m, true)),
            hp.clone(),
        ),
        ("HIGH under a parent chain with non-uniform scale", lp.clone(), write(&d, "h_chain.glb", &chain)),
        (
            "LOW mirrored by its node",
            write(&d, "l_mirror.glb", &single("torus", &mirrored_low, mirror, true)),
            hp.clone(),
        ),
    ];
    for (what, l, h) in cases {
        let out = d.join("out.glb");
        let rep = bake(&l, &[&h], &out, &[]);
        assert_eq!(rep["transfer"]["counts"]["missed_rays"], 0, "{what}");
        let (most, n) = diff(&map_of(&out, 0), &want, &|_, _| true);
        assert!(most <= 1, "{what}: {n} texels differ from the plain pair's map, by up to {most} levels");
    }
}

/// LOW `ring_low` touching `cap_low`, HIGH `ring_high` and `cap_high`: matched by name, the ring
/// bakes as if the cap were not there; unmatched, the cap's HIGH bleeds into the ring's map.
#[test]
fn touching_parts_bake_apart() {
    let d = scratch_dir("scenes_parts");
    let t = Torus::default();
    let mut ring = t.low(48, 24);
    ring.uvs.iter_mut().for_each(|uv| uv[1] *= 0.5);
    let plate = |n: usize, uv: bool| {
        let mut m = Mesh::default();
        for j in 0..=n {
            for i in 0..=n {
                let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
                m.positions.push([3.0 * u - 1.5, 3.0 * v - 1.5, t.minor as f32]);
                m.normals.push([0.0, 0.0, 1.0]);
                if uv {
                    m.uvs.push([u, 1.0 - 0.5 * v]);
                }
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
    };
    let (cap_low, cap_high, ring_high) = (plate(4, true), plate(8, false), t.high(274, 68));
    let node = |name: &str, mesh: usize| json!({ "name": name, "mesh": mesh });
    let low = scene_glb(
        &[
            ("ring", vec![Prim { mesh: &ring, material: Some(0) }]),
            ("cap", vec![Prim { mesh: &cap_low, material: Some(0) }]),
        ],
        json!([node("ring_low", 0), node("Cap_LOW", 1)]),
        &["metal"],
    );
    let lp = write(&d, "low.glb", &low);
    let both = scene_glb(
        &[
            ("a", vec![Prim { mesh: &ring_high, material: None }]),
            ("b", vec![Prim { mesh: &cap_high, material: None }]),
        ],
        json!([node("ring_high", 0), node("cap_high.001", 1)]),
        &[],
    );
    let hp = write(&d, "high.glb", &both);
    let ring_only =
        scene_glb(&[("a", vec![Prim { mesh: &ring_high, material: None }])], json!([node("ring_high", 0)]), &[]);
    let rp = write(&d, "ring_high.glb", &ring_only);

    let rep = bake(&lp, &[&hp], &d.join("matched.glb"), &[]);
    let tr = &rep["transfer"];
    assert_eq!(
        tr["pairs"],
        json!([{ "low": ["ring_low"], "high": ["ring_high"] }, { "low": ["Cap_LOW"], "high": ["cap_high.001"] }])
    );
    assert_eq!((tr["unmatched_low"].clone(), tr["unmatched_high"].clone()), (json!([]), json!([])));
    let parts = tr["materials"][0]["parts"].as_array().unwrap();
    assert_eq!(parts.len(), 2);
    assert_eq!(parts[0]["name"], "ring_low");
    assert_eq!(parts[0]["triangles"], 2 * 48 * 24);
    // The ring's UVs fill the top half of the map, the cap's the bottom half.
    assert_eq!(parts[0]["texels"], 128 * 64);
    assert_eq!(parts[1]["texels"], 128 * 64);
    assert_eq!(parts[0]["missed_rays"], 0);
    let [lo, hi] = [0, 1].map(|k| parts[1]["distance_range"][k].as_f64().unwrap());
    assert!(lo.abs() < 1e-6 && hi.abs() < 1e-6, "the cap's HIGH lies on its LOW: {lo} {hi}");
    let matched = map_of(&d.join("matched.glb"), 0);

    bake(&lp, &[&rp], &d.join("alone.glb"), &["--match", "none"]);
    let alone = map_of(&d.join("alone.glb"), 0);
    let ring_rows = |_: u32, y: u32| y < 64;
    let (most, n) = diff(&matched, &alone, &ring_rows);
    assert!(most == 0, "the ring's map depends on the cap: {n} texels differ by up to {most}");

    // The same HIGH as an OBJ whose groups are the parts.
    let op = d.join("high.obj");
    std::fs::write(&op, obj(&[("ring_high", &ring_high), ("cap_high", &cap_high)])).unwrap();
    let rep = bake(&lp, &[&op], &d.join("obj.glb"), &[]);
    assert_eq!(rep["transfer"]["pairs"][0], json!({ "low": ["ring_low"], "high": ["ring_high"] }));
    let (most, n) = diff(&map_of(&d.join("obj.glb"), 0), &alone, &ring_rows);
    assert!(most == 0, "OBJ groups: {n} texels differ by up to {most}");

    bake(&lp, &[&hp], &d.join("bled.glb"), &["--match", "none"]);
    let (most, n) = diff(&map_of(&d.join("bled.glb"), 0), &alone, &ring_rows);
    assert!(most > 30 && n > 100, "without matching the cap should bleed into the ring ({n} texels, {most} levels)");
}

/// An OBJ with one group per named mesh (positions, normals; no UVs).
fn obj(parts: &[(&str, &Mesh)]) -> String {
    let mut o = String::new();
    let mut base = 1;
    for (name, m) in parts {
        o += &format!("g {name}\n");
        for p in &m.positions {
            o += &format!("v {} {} {}\n", p[0], p[1], p[2]);
        }
        for n in &m.normals {
            o += &format!("vn {} {} {}\n", n[0], n[1], n[2]);
        }
        for t in m.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize + base);
            o += &format!("f {a}//{a} {b}//{b} {c}//{c}\n");
        }
        base += m.positions.len();
    }
    o
}

/// Two materials on one LOW mesh: two maps, each the plain map where its triangles are, and the
/// extra files named after the materials.
#[test]
fn two_materials_share_one_low_mesh() {
    let d = scratch_dir("scenes_materials");
    let (_, hp, want) = plain(&d);
    let (low, _) = torus();
    // Tube rows 0..12 (the lower half of the map, v > 0.5) get Stone, the rest Metal/2.
    let half = low.indices.len() / 2;
    let mut a = low.clone();
    a.indices.truncate(half);
    let mut b = low.clone();
    b.indices = low.indices[half..].to_vec();
    let glb = scene_glb(
        &[("torus", vec![Prim { mesh: &a, material: Some(0) }, Prim { mesh: &b, material: Some(1) }])],
        json!([{ "name": "torus", "mesh": 0 }]),
        &["Stone", "Metal/2"],
    );
    let lp = write(&d, "low.glb", &glb);
    let out = d.join("out.glb");
    let (m, h) = (d.join("n.png"), d.join("h.png"));
    let rep = bake(&lp, &[&hp], &out, &["--map-out", s(&m), "--height-out", s(&h)]);
    for f in ["n_Stone.png", "n_Metal_2.png", "h_Stone.png", "h_Metal_2.png"] {
        assert!(d.join(f).is_file(), "{f} not written");
    }
    assert!(!m.exists() && !h.exists());
    let mats = rep["transfer"]["materials"].as_array().unwrap();
    assert_eq!(mats.len(), 2);
    assert_eq!((mats[0]["name"].clone(), mats[1]["name"].clone()), (json!("Stone"), json!("Metal/2")));
    assert_eq!(mats[0]["low_triangles"], 48 * 24);
    let rays: u64 = mats.iter().map(|m| m["counts"]["rays"].as_u64().unwrap()).sum();
    assert_eq!(rep["transfer"]["counts"]["rays"], rays);
    // Tangents are generated per primitive, so frames differ along the seam's triangle rows.
    let (stone, metal) = (map_of(&out, 0), map_of(&out, 1));
    let (most, _) = diff(&stone, &want, &|_, y| y >= 70);
    assert!(most <= 1, "Stone's map is off by {most}");
    let (most, _) = diff(&metal, &want, &|_, y| y < 58);
    assert!(most <= 1, "Metal's map is off by {most}");
    let disk = image::open(d.join("n_Stone.png")).unwrap().to_rgb8();
    assert_eq!(disk, stone);
    // --material still picks one, under the names given.
    let rep = bake(&lp, &[&hp], &d.join("one.glb"), &["--material", "Metal/2", "--map-out", s(&m)]);
    assert_eq!(rep["transfer"]["materials"].as_array().unwrap().len(), 1);
    assert!(m.is_file());
}

/// A LOW mesh two nodes show is one UV layout in two places: refused, naming both nodes, until
/// `--node` picks one.
#[test]
fn low_shown_twice_needs_a_node() {
    let d = scratch_dir("scenes_instanced");
    let (_, hp, want) = plain(&d);
    let (low, _) = torus();
    let glb = scene_glb(
        &[("torus", vec![Prim { mesh: &low, material: Some(0) }])],
        json!([
            { "name": "left", "mesh": 0, "translation": [-3.0, 0.0, 0.0] },
            { "name": "right", "mesh": 0 },
        ]),
        &["low"],
    );
    let lp = write(&d, "low.glb", &glb);
    let out = d.join("out.glb");
    let o = run(&["bake", s(&lp), "--from", s(&hp), "-o", s(&out), "--size", SIZE]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("'left' and 'right'") && err.contains("--node") && err.contains("low.glb"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(!out.exists());
    let o = run(&["bake", s(&lp), "--from", s(&hp), "-o", s(&out), "--node", "middle"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("left, right"));
    bake(&lp, &[&hp], &out, &["--node", "right"]);
    let (most, _) = diff(&map_of(&out, 0), &want, &|_, _| true);
    assert_eq!(most, 0);
}
