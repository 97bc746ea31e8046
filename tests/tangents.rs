//! `bumpbake tangents` through the binary: reference tangents on real assets, seams, material
//! rules, degenerate input, round trips and determinism.

mod common;
use common::*;
use serde_json::json;

/// Corners of triangles with zero position or UV area have no reference frame.
fn degenerate(p: &[[f32; 3]], uv: &[[f32; 2]], tri: usize) -> bool {
    let v = |k: usize| glam::DVec3::from(p[tri * 3 + k].map(|x| x as f64));
    let t = |k: usize| glam::DVec2::from(uv[tri * 3 + k].map(|x| x as f64));
    let area = (v(1) - v(0)).cross(v(2) - v(0)).length();
    let uv_area = (t(1) - t(0)).perp_dot(t(2) - t(0)).abs();
    area < 1e-12 || uv_area < 1e-14
}

/// Compares every corner of primitive 0 of `out` with a reference file; returns the worst angle.
fn assert_matches_reference(out: &std::path::Path, reference_file: &str, tolerance_rad: f64) -> f64 {
    let scene = load(out);
    let t = corner_attr::<4>(&scene, P0, "TANGENT");
    let n = corner_attr::<3>(&scene, P0, "NORMAL");
    let p = corner_attr::<3>(&scene, P0, "POSITION");
    let uv = corner_attr::<2>(&scene, P0, "TEXCOORD_0");
    let r = reference(&fixture(reference_file));
    assert_eq!(t.len(), r.len(), "corner count");
    let mut worst = 0.0f64;
    let mut compared = 0;
    for c in 0..t.len() {
        assert_valid_frame(t[c], n[c], &format!("corner {c}"));
        if degenerate(&p, &uv, c / 3) {
            continue;
        }
        compared += 1;
        let a = angle(t[c], r[c]);
        assert!(a <= tolerance_rad, "corner {c}: {:?} vs reference {:?}: {a} rad", t[c], r[c]);
        assert_eq!(t[c][3], r[c][3], "corner {c}: w differs from the reference");
        worst = worst.max(a);
    }
    assert!(compared > t.len() * 9 / 10, "most corners are compared ({compared} of {})", t.len());
    worst
}

#[test]
fn normal_tangent_test_gains_reference_tangents() {
    let d = validated_dir("ntt");
    let out = d.join("NormalTangentTest.glb");
    let o = run_ok(&["tangents", s(&fixture("khronos/NormalTangentTest.glb")), "-o", s(&out), "--json"]);
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["generated"], 1);
    assert_matches_reference(&out, "khronos/NormalTangentTest.mesh0.prim0.tangents.txt", 1e-5);
}

#[test]
fn mirror_test_keeps_authored_tangents_and_overwrite_matches_reference() {
    let d = validated_dir("ntmt");
    let input = fixture("khronos/NormalTangentMirrorTest.glb");
    let kept = d.join("kept.glb");
    run_ok(&["tangents", s(&input), "-o", s(&kept), "-q"]);
    let authored = corner_attr::<4>(&load(&input), P0, "TANGENT");
    assert_eq!(corner_attr::<4>(&load(&kept), P0, "TANGENT"), authored, "valid authored tangents are kept");

    let redone = d.join("overwritten.gltf");
    run_ok(&["tangents", s(&input), "-o", s(&redone), "--overwrite", "-q"]);
    assert_matches_reference(&redone, "khronos/NormalTangentMirrorTest.mesh0.prim0.tangents.txt", 1e-5);
    // Blender's authored frames are MikkTSpace too: same signs, and close in direction.
    let r = reference(&fixture("khronos/NormalTangentMirrorTest.mesh0.prim0.tangents.txt"));
    let minus = authored.iter().filter(|t| t[3] < 0.0).count();
    assert!(minus > 0 && minus < authored.len(), "both signs are authored");
    for (c, (a, b)) in authored.iter().zip(&r).enumerate() {
        assert_eq!(a[3], b[3], "corner {c}: authored w vs reference");
        assert!(angle(*a, *b) < 0.02, "corner {c}: authored {a:?} vs reference {b:?}");
    }
}

#[test]
fn spot_obj_matches_reference() {
    let d = validated_dir("spot");
    let out = d.join("spot.glb");
    // Spot's material has no normal map, so --all asks for tangents anyway.
    run_ok(&["tangents", s(&fixture("spot/spot.obj")), "-o", s(&out), "--all", "-q"]);
    // The reader flips the UVs to glTF (v down); the reference was fed the same flipped UVs.
    assert_matches_reference(&out, "spot/spot.tangents.txt", 1e-5);
}

#[test]
fn blub_obj_matches_reference() {
    let d = validated_dir("blub");
    let out = d.join("blub.gltf");
    run_ok(&["tangents", s(&fixture("blub/blub_triangulated.obj")), "-o", s(&out), "--all", "-q"]);
    assert!(d.join("blub.bin").exists());
    assert_matches_reference(&out, "blub/blub.tangents.txt", 1e-5);
}

/// Two quads sharing an edge, the right one with mirrored UVs: the seam vertices must split.
#[test]
fn mirrored_uv_seam_splits_vertices_and_keeps_both_signs() {
    let d = scratch_dir("mirror_in");
    let v = validated_dir("mirror");
    let mut g = Gltf::new();
    let pos = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [2.0, 1.0, 0.0]];
    // u runs 0 -> 1 -> 0 across the seam at x = 1.
    let uv = [[0.0, 1.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.0], [1.0, 0.0], [0.0, 0.0]];
    let p = g.floats(&pos, Some(34962));
    let n = g.floats(&[[0.0, 0.0, 1.0]; 6], Some(34962));
    let t = g.floats(&uv, Some(34962));
    let i = g.indices(&[0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4]);
    let tex = g.texture();
    let m = g.material(json!({ "normalTexture": { "index": tex } }));
    g.mesh(json!({ "attributes": { "POSITION": p, "NORMAL": n, "TEXCOORD_0": t }, "indices": i, "material": m }));
    let input = d.join("mirror.glb");
    g.write_glb(&input);
    let out = v.join("mirror.glb");
    run_ok(&["tangents", s(&input), "-o", s(&out), "-q"]);
    let scene = load(&out);
    let prim = scene.primitive(P0).unwrap();
    assert_eq!(prim.vertex_count(), 8, "the two seam vertices are split, nothing else");
    let tc = corner_attr::<4>(&scene, P0, "TANGENT");
    // glTF UVs (v down) with u along +x: T = +x, and the frame is right-handed in glTF terms.
    for (c, t) in tc.iter().enumerate().take(6) {
        assert_eq!(*t, [1.0, 0.0, 0.0, 1.0], "left quad corner {c}");
    }
    for (c, t) in tc.iter().enumerate().take(12).skip(6) {
        assert_eq!(*t, [-1.0, 0.0, 0.0, -1.0], "mirrored quad corner {c}");
    }
}

#[test]
fn tangents_only_where_a_normal_texture_reads_them_from_its_uv_set() {
    let d = scratch_dir("mixed_in");
    let v = validated_dir("mixed");
    let mut g = Gltf::new();
    let (pos, nrm, uv0, idx) = grid(2);
    // UV set 1 runs u along +y: a normal texture reading it needs T = +y.
    let uv1: Vec<[f32; 2]> = pos.iter().map(|p| [p[1], p[0]]).collect();
    let tex = g.texture();
    let with_map = g.material(json!({ "name": "bumpy", "normalTexture": { "index": tex, "texCoord": 1 } }));
    let plain =
        g.material(json!({ "name": "plain", "pbrMetallicRoughness": { "baseColorTexture": { "index": tex } } }));
    for mat in [Some(with_map), Some(plain), None] {
        let p = g.floats(&pos, Some(34962));
        let n = g.floats(&nrm, Some(34962));
        let t0 = g.floats(&uv0, Some(34962));
        let t1 = g.floats(&uv1, Some(34962));
        let i = g.indices(&idx);
        let mut prim =
            json!({ "attributes": { "POSITION": p, "NORMAL": n, "TEXCOORD_0": t0, "TEXCOORD_1": t1 }, "indices": i });
        if let Some(m) = mat {
            prim["material"] = json!(m);
        }
        g.mesh(prim);
    }
    let input = g.write_gltf(&d, "mixed");
    let out = v.join("mixed.glb");
    let o = run_ok(&["tangents", s(&input), "-o", s(&out), "--json"]);
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["primitives"][0]["action"], "generated");
    assert_eq!(report["primitives"][0]["uv_set"], 1);
    assert_eq!(report["primitives"][1]["reason"], "material has no normal texture");
    assert_eq!(report["primitives"][2]["reason"], "no material");
    let scene = load(&out);
    for t in corner_attr::<4>(&scene, P0, "TANGENT") {
        assert!((t[1] - 1.0).abs() < 1e-6 && t[0].abs() < 1e-6, "T follows UV set 1: {t:?}");
    }
    for m in [1, 2] {
        let p = scene.primitive(bumpbake::scene::PrimRef { mesh: m, primitive: 0 }).unwrap();
        assert!(p.attr("TANGENT").is_none(), "mesh {m} gets no tangents");
    }
}

/// Zero-area, zero-UV-area, collinear-UV and repeated-index triangles, some with neighbours.
#[test]
fn degenerate_triangles_get_valid_fallback_frames() {
    let d = scratch_dir("degen_in");
    let v = validated_dir("degen");
    let mut g = Gltf::new();
    let pos = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0], // good
        [2.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [2.0, 0.0, 0.0], // zero area
        [3.0, 0.0, 0.0],
        [4.0, 0.0, 0.0],
        [3.0, 1.0, 0.0], // zero UV area
        [5.0, 0.0, 0.0],
        [6.0, 0.0, 0.0],
        [5.0, 1.0, 0.0], // collinear UVs
        [7.0, 0.0, 0.0],
        [8.0, 0.0, 0.0],
        [7.0, 1.0, 0.0], // repeated index
        [1.0, 1.0, 0.0], // shares an edge with the good triangle, zero UV area there
    ];
    let uv = [
        [0.0, 1.0],
        [1.0, 1.0],
        [0.0, 0.0],
        [0.0, 0.0],
        [1.0, 0.0],
        [0.0, 1.0],
        [0.5, 0.5],
        [0.5, 0.5],
        [0.5, 0.5],
        [0.0, 0.0],
        [0.5, 0.5],
        [1.0, 1.0],
        [0.0, 1.0],
        [1.0, 1.0],
        [0.0, 0.0],
        [1.0, 1.0],
    ];
    let nrm: Vec<[f32; 3]> = vec![[0.0, 0.0, 1.0]; pos.len()];
    let p = g.floats(&pos, Some(34962));
    let n = g.floats(&nrm, Some(34962));
    let t = g.floats(&uv, Some(34962));
    let i = g.indices(&[0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 12, 14, 1, 15, 2]);
    let tex = g.texture();
    let m = g.material(json!({ "normalTexture": { "index": tex } }));
    g.mesh(json!({ "attributes": { "POSITION": p, "NORMAL": n, "TEXCOORD_0": t }, "indices": i, "material": m }));
    let input = d.join("degen.glb");
    g.write_glb(&input);
    let out = v.join("degen.glb");
    let o = run_ok(&["tangents", s(&input), "-o", s(&out), "--json"]);
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(report["fallback_frames"].as_u64().unwrap() > 0, "substitutions are counted: {report}");
    let scene = load(&out);
    let tc = corner_attr::<4>(&scene, P0, "TANGENT");
    let nc = corner_attr::<3>(&scene, P0, "NORMAL");
    for c in 0..tc.len() {
        assert_valid_frame(tc[c], nc[c], &format!("corner {c}"));
    }
    assert_eq!(tc[0], [1.0, 0.0, 0.0, 1.0], "the good triangle keeps its exact frame");
}

#[test]
fn bitangents_only_on_request_and_equal_to_cross_n_t_times_w() {
    let v = validated_dir("bitangents");
    let input = fixture("khronos/NormalTangentTest.glb");
    let with = v.join("with.glb");
    let without = v.join("without.glb");
    run_ok(&["tangents", s(&input), "-o", s(&with), "--bitangents", "-q"]);
    run_ok(&["tangents", s(&input), "-o", s(&without), "-q"]);
    assert!(load(&without).primitive(P0).unwrap().attr("_BITANGENT").is_none());
    let scene = load(&with);
    let t = corner_attr::<4>(&scene, P0, "TANGENT");
    let n = corner_attr::<3>(&scene, P0, "NORMAL");
    let b = corner_attr::<3>(&scene, P0, "_BITANGENT");
    for c in 0..t.len() {
        let want = glam::Vec3::from(n[c]).normalize().cross(glam::Vec3::new(t[c][0], t[c][1], t[c][2])) * t[c][3];
        assert!((glam::Vec3::from(b[c]) - want).length() < 1e-6, "corner {c}");
    }
}

#[test]
fn output_is_byte_identical_across_runs_and_thread_counts() {
    let v = validated_dir("determinism");
    let input = fixture("khronos/NormalTangentTest.glb");
    let a = v.join("a.glb");
    let b = v.join("b.glb");
    run_ok(&["tangents", s(&input), "-o", s(&a), "-q"]);
    let o = bin().env("RAYON_NUM_THREADS", "1").args(["tangents", s(&input), "-o", s(&b), "-q"]).output().unwrap();
    assert!(o.status.success());
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    run_ok(&["tangents", s(&input), "-o", s(&b), "-q"]);
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

#[test]
fn indices_stay_16_bit_where_they_fit() {
    let v = validated_dir("u16");
    let out = v.join("ntt.glb");
    run_ok(&["tangents", s(&fixture("khronos/NormalTangentTest.glb")), "-o", s(&out), "-q"]);
    let scene = load(&out);
    let i = scene.prim_json(P0)["indices"].as_u64().unwrap() as usize;
    assert_eq!(scene.json["accessors"][i]["componentType"], 5123);
}
