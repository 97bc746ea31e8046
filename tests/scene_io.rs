//! Reading and writing: glTF round trips, OBJ conversion, and bad input.

mod common;
use common::*;
use serde_json::{json, Value};

/// Everything but the data layout (accessors, views, buffers, primitive attribute indices).
fn layout_free(mut j: Value) -> Value {
    for key in ["accessors", "bufferViews", "buffers"] {
        j.as_object_mut().unwrap().remove(key);
    }
    for m in j["meshes"].as_array_mut().unwrap() {
        for p in m["primitives"].as_array_mut().unwrap() {
            for key in ["attributes", "indices", "targets"] {
                p.as_object_mut().unwrap().remove(key);
            }
        }
    }
    // Accessor numbers move when the layout does; what they hold is compared separately.
    for ptr in ["/skins/0/inverseBindMatrices", "/animations/0/samplers/0/input", "/animations/0/samplers/0/output"] {
        if let Some(v) = j.pointer_mut(ptr) {
            *v = json!("accessor");
        }
    }
    j
}

#[test]
fn untouched_parts_of_a_gltf_survive_unchanged() {
    let d = scratch_dir("roundtrip_in");
    let v = validated_dir("roundtrip");
    let mut g = Gltf::new();
    let (pos, nrm, uv, idx) = grid(2);
    let p = g.floats(&pos, Some(34962));
    let n = g.floats(&nrm, Some(34962));
    let t = g.floats(&uv, Some(34962));
    let joints: Vec<[f32; 4]> = vec![[0.0; 4]; pos.len()];
    let weights: Vec<[f32; 4]> = vec![[1.0, 0.0, 0.0, 0.0]; pos.len()];
    let jb: Vec<u8> = joints.iter().flat_map(|j| j.iter().map(|&x| x as u8)).collect();
    // JOINTS_0 as unsigned bytes, to show integer streams pass through untouched.
    let jv = g.bytes(&jb, 5121, "VEC4", pos.len());
    let w = g.floats(&weights, Some(34962));
    let morph = g.floats(&vec![[0.0, 0.0, 0.5]; pos.len()], Some(34962));
    let i = g.indices(&idx);
    let ibm = g.floats(&[[1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]], None);
    let times = g.floats(&[[0.0], [1.0]], None);
    let rots = g.floats(
        &[[0.0, 0.0, 0.0, 1.0], [0.0, std::f32::consts::FRAC_1_SQRT_2, 0.0, std::f32::consts::FRAC_1_SQRT_2]],
        None,
    );
    let tex = g.texture();
    let m = g.material(json!({
        "name": "bumpy",
        "normalTexture": { "index": tex, "scale": 0.5, "extensions": { "KHR_texture_transform": { "scale": [2.0, 2.0] } } },
        "emissiveFactor": [1.0, 0.5, 0.0],
        "extensions": { "KHR_materials_emissive_strength": { "emissiveStrength": 2.0 } },
        "extras": { "author": "test", "nested": { "n": [1, 2, 3] } }
    }));
    g.mesh(json!({
        "attributes": { "POSITION": p, "NORMAL": n, "TEXCOORD_0": t, "JOINTS_0": jv, "WEIGHTS_0": w },
        "targets": [{ "POSITION": morph }],
        "indices": i, "material": m, "extras": { "prim": true }
    }));
    g.json["meshes"][0]["weights"] = json!([0.25]);
    g.json["meshes"][0]["name"] = json!("Sheet");
    g.json["nodes"] = json!([
        { "name": "root", "children": [2], "extras": { "tag": 7 }, "extensions": { "KHR_lights_punctual": { "light": 0 } } },
        { "name": "skinned", "mesh": 0, "skin": 0 },
        { "name": "joint", "translation": [0.0, 1.0, 0.0] },
        { "name": "cam", "camera": 0, "rotation": [0.0, 0.0, 0.0, 1.0] }
    ]);
    g.json["scenes"] = json!([{ "name": "main", "nodes": [0, 1, 3] }]);
    g.json["skins"] = json!([{ "joints": [2], "inverseBindMatrices": ibm }]);
    g.json["animations"] = json!([{ "name": "spin", "channels": [{ "sampler": 0, "target": { "node": 2, "path": "rotation" } }], "samplers": [{ "input": times, "output": rots }] }]);
    g.accessor_min_max(times);
    g.json["cameras"] = json!([{ "type": "perspective", "perspective": { "yfov": 0.8, "znear": 0.1 } }]);
    g.json["samplers"] = json!([{ "magFilter": 9729, "wrapS": 33648 }]);
    g.json["textures"][0]["sampler"] = json!(0);
    g.json["extensionsUsed"] =
        json!(["KHR_texture_transform", "KHR_materials_emissive_strength", "KHR_lights_punctual"]);
    g.json["extensions"] =
        json!({ "KHR_lights_punctual": { "lights": [{ "type": "directional", "intensity": 3.0 }] } });
    g.json["extras"] = json!({ "pipeline": "bumpbake test" });
    g.json["asset"]["copyright"] = json!("test");
    let input = g.write_gltf(&d, "rig");
    let before = load(&input);
    let out = v.join("rig.gltf");
    run_ok(&["tangents", s(&input), "-o", s(&out), "-q"]);
    let after = load(&out);

    assert_eq!(layout_free(after.json.clone()), layout_free(before.json.clone()), "only the data layout changed");
    let pa = after.primitive(P0).unwrap();
    let pb = before.primitive(P0).unwrap();
    let names: Vec<&str> = pa.attributes.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["POSITION", "NORMAL", "TEXCOORD_0", "JOINTS_0", "WEIGHTS_0", "TANGENT"]);
    assert_eq!(pa.attr("JOINTS_0").unwrap().format.component_type, 5121, "byte joints stay bytes");
    assert_eq!(pa.targets.len(), 1);
    // Per corner, every attribute and the morph target is what it was.
    for name in ["POSITION", "NORMAL", "TEXCOORD_0", "JOINTS_0", "WEIGHTS_0"] {
        let a = pa.attr(name).unwrap();
        let b = pb.attr(name).unwrap();
        for (ca, cb) in pa.indices.iter().zip(&pb.indices) {
            assert_eq!(a.elem(*ca as usize), b.elem(*cb as usize), "{name}");
        }
    }
    // Animation and skin data are the same accessors' contents.
    let acc = |sc: &bumpbake::scene::Scene, ptr: &str| {
        sc.accessor(sc.json.pointer(ptr).unwrap().as_u64().unwrap() as usize).unwrap().data
    };
    for ptr in ["/animations/0/samplers/0/input", "/animations/0/samplers/0/output", "/skins/0/inverseBindMatrices"] {
        assert_eq!(acc(&after, ptr), acc(&before, ptr), "{ptr}");
    }
}

#[test]
fn obj_without_normals_with_quads_and_normal_map() {
    let d = scratch_dir("obj_quads_in");
    let v = validated_dir("obj_quads");
    std::fs::write(d.join("n.png"), tiny_png()).unwrap();
    std::fs::write(d.join("m.mtl"), "newmtl bumpy\nKd 0.5 0.5 0.5\nnorm -bm 0.8 n.png\n").unwrap();
    // A unit cube's top face as one quad plus a side quad, no vn.
    std::fs::write(
        d.join("q.obj"),
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 1 0 -1\nv 1 1 -1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl bumpy\nf 1/1 2/2 3/3 4/4\nf 2/1 5/2 6/3 3/4\n",
    )
    .unwrap();
    for mode in ["smooth", "flat"] {
        let out = v.join(format!("q_{mode}.glb"));
        run_ok(&["tangents", s(&d.join("q.obj")), "-o", s(&out), "--normals", mode, "-q"]);
        let scene = load(&out);
        assert_eq!(scene.json["materials"][0]["normalTexture"]["scale"], json!(0.8f32));
        let p = scene.primitive(P0).unwrap();
        assert_eq!(p.indices.len(), 12, "two quads -> four triangles");
        let n = corner_attr::<3>(&scene, P0, "NORMAL");
        let t = corner_attr::<4>(&scene, P0, "TANGENT");
        for c in 0..12 {
            assert_valid_frame(t[c], n[c], &format!("{mode} corner {c}"));
        }
        if mode == "flat" {
            assert_eq!(n[0], [0.0, 0.0, 1.0]);
            assert_eq!(n[6], [1.0, 0.0, 0.0]);
        } else {
            // Vertex 2 (index 1) is shared by both faces at right angles: the average.
            let s2 = std::f32::consts::FRAC_1_SQRT_2;
            assert!((glam::Vec3::from(n[1]) - glam::Vec3::new(s2, 0.0, s2)).length() < 1e-6, "{:?}", n[1]);
        }
        // v is flipped to glTF's convention on the way out.
        let uv = corner_attr::<2>(&scene, P0, "TEXCOORD_0");
        assert_eq!(uv[0], [0.0, 1.0]);
        assert_eq!(uv[2], [1.0, 0.0]);
    }
}

/// Smoothing groups in a file without `vn`: the two quads at right angles share vertex 2's
/// normal only when they are in one group; in two groups, or with `s off`, each keeps its own
/// face normal there, and the tangents follow.
#[test]
fn obj_smoothing_groups_make_hard_edges() {
    let d = scratch_dir("obj_groups_in");
    let v = validated_dir("obj_groups");
    let body = |first: &str, second: &str| {
        format!(
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 1 0 -1\nv 1 1 -1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n{first}\nf 1/1 2/2 3/3 4/4\n{second}\nf 2/1 5/2 6/3 3/4\n"
        )
    };
    let s2 = std::f32::consts::FRAC_1_SQRT_2;
    for (name, first, second, shared) in
        [("one", "s 1", "s 1", true), ("two", "s 1", "s 2", false), ("off", "s off", "", false)]
    {
        std::fs::write(d.join(format!("{name}.obj")), body(first, second)).unwrap();
        let out = v.join(format!("{name}.glb"));
        run_ok(&["tangents", s(&d.join(format!("{name}.obj"))), "-o", s(&out), "--all", "-q"]);
        let scene = load(&out);
        let n = corner_attr::<3>(&scene, P0, "NORMAL");
        let t = corner_attr::<4>(&scene, P0, "TANGENT");
        for c in 0..12 {
            assert_valid_frame(t[c], n[c], &format!("{name} corner {c}"));
        }
        // Corner 1 is vertex 2 in the top quad; corner 6 is vertex 2 in the side quad.
        if shared {
            for c in [1, 6] {
                assert!((glam::Vec3::from(n[c]) - glam::Vec3::new(s2, 0.0, s2)).length() < 1e-6, "{name}: {:?}", n[c]);
            }
        } else {
            assert_eq!((n[1], n[6]), ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]), "{name}");
        }
        // `--normals flat` is flat whatever the groups say.
        let flat = v.join(format!("{name}_flat.glb"));
        run_ok(&["tangents", s(&d.join(format!("{name}.obj"))), "-o", s(&flat), "--all", "--normals", "flat", "-q"]);
        let n = corner_attr::<3>(&load(&flat), P0, "NORMAL");
        assert_eq!((n[1], n[6]), ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]), "{name} flat");
    }
}

/// Files Blender 5.0.1 wrote without normals, with its smoothing groups (plain and bit-flag),
/// read with the normals Blender itself exports for the same mesh (`fixtures/blender_obj/`: a
/// cylinder with hard cap edges and two hard side edges, and a flat cube), corner for corner,
/// as a Scene and as HIGH for `bake --from`.
#[test]
fn obj_smoothing_groups_give_blenders_own_normals() {
    let want = load(&fixture("blender_obj/normals.obj"));
    let want_high =
        bumpbake::transfer::high::read_high(&fixture("blender_obj/normals.obj"), &Default::default()).unwrap();
    // Blender writes `vn` with four decimals.
    let close = |a: [f32; 3], b: [f32; 3]| (glam::Vec3::from(a) - glam::Vec3::from(b)).length() < 1e-4;
    for name in ["groups", "bitflags"] {
        let path = fixture(&format!("blender_obj/{name}.obj"));
        let got = load(&path);
        for mesh in 0..2 {
            let r = bumpbake::scene::PrimRef { mesh, primitive: 0 };
            let (g, w) = (corner_attr::<3>(&got, r, "NORMAL"), corner_attr::<3>(&want, r, "NORMAL"));
            assert_eq!(g.len(), w.len());
            let off = g.iter().zip(&w).filter(|(a, b)| !close(**a, **b)).count();
            assert_eq!(off, 0, "{name}, mesh {mesh}: {off} of {} corners differ from Blender's", g.len());
        }
        let high = bumpbake::transfer::high::read_high(&path, &Default::default()).unwrap();
        let corner =
            |h: &bumpbake::transfer::high::HighMesh, t: usize, k: usize| h.normals[h.normal_triangles[t][k] as usize];
        for t in 0..high.triangles.len() {
            for k in 0..3 {
                assert!(
                    close(corner(&high, t, k), corner(&want_high, t, k)),
                    "{name} as HIGH: triangle {t} corner {k}"
                );
            }
        }
    }
}

#[test]
fn obj_height_bump_is_reported_for_bake() {
    let d = scratch_dir("obj_height_in");
    let v = validated_dir("obj_height");
    let grey = image::GrayImage::from_fn(4, 4, |x, _| image::Luma([(x * 60) as u8]));
    grey.save(d.join("h.png")).unwrap();
    std::fs::write(d.join("m.mtl"), "newmtl m\nmap_Bump -bm 0.3 h.png\n").unwrap();
    std::fs::write(
        d.join("t.obj"),
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nusemtl m\nf 1/1/1 2/2/1 3/3/1\n",
    )
    .unwrap();
    let out = v.join("t.glb");
    let o = run_ok(&["tangents", s(&d.join("t.obj")), "-o", s(&out)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("h.png") && err.contains("height map"), "{err}");
    let scene = load(&out);
    assert!(scene.json["materials"][0].get("normalTexture").is_none());
    assert!(scene.primitive(P0).unwrap().attr("TANGENT").is_none());
}

#[test]
fn gltf_without_normals_gets_flat_normals_and_tangents() {
    let d = scratch_dir("nonormal_in");
    let v = validated_dir("nonormal");
    let mut g = Gltf::new();
    let (pos, _, uv, idx) = grid(1);
    let p = g.floats(&pos, Some(34962));
    let t = g.floats(&uv, Some(34962));
    let i = g.indices(&idx);
    let tex = g.texture();
    let m = g.material(json!({ "normalTexture": { "index": tex } }));
    g.mesh(json!({ "attributes": { "POSITION": p, "TEXCOORD_0": t }, "indices": i, "material": m }));
    let input = d.join("nn.glb");
    g.write_glb(&input);
    let out = v.join("nn.glb");
    run_ok(&["tangents", s(&input), "-o", s(&out), "-q"]);
    let scene = load(&out);
    for n in corner_attr::<3>(&scene, P0, "NORMAL") {
        assert_eq!(n, [0.0, 0.0, 1.0]);
    }
    for t in corner_attr::<4>(&scene, P0, "TANGENT") {
        assert_eq!(t, [1.0, 0.0, 0.0, 1.0]);
    }
}
