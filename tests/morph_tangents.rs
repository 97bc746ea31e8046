//! Morph targets that move a normal-mapped surface get TANGENT deltas: MikkTSpace on the morphed
//! mesh minus the base frame, per output vertex.

mod common;
use common::*;
use serde_json::json;

/// A target's stream, one value per corner of primitive 0.
fn target_corners<const N: usize>(scene: &bumpbake::scene::Scene, target: usize, name: &str) -> Vec<[f32; N]> {
    let p = scene.primitive(P0).unwrap();
    let s = p.targets[target].iter().find(|(n, _)| n == name).unwrap_or_else(|| panic!("target {target}: no {name}"));
    let v: Vec<[f32; N]> = s.1.to_f32();
    p.indices.iter().map(|&i| v[i as usize]).collect()
}

fn close(a: [f32; 3], b: [f32; 3], tol: f32) -> bool {
    a.iter().zip(&b).all(|(x, y)| (x - y).abs() <= tol)
}

/// A 4x4 grid in the XY plane (UV = position, v down) with three targets whose morphed tangent is
/// known in closed form: a turn about Z by 0.5 rad (positions only: T = (cos, sin, 0)), a turn
/// about Y by 0.3 rad (positions and normals: T = (cos, 0, -sin)), and a UV swap (u = y, v = x,
/// stored v down: T = +Y, same handedness).
#[test]
fn targets_that_turn_the_surface_or_its_uvs_get_the_closed_form_deltas() {
    let d = scratch_dir("morph_in");
    let v = validated_dir("morph");
    let (pos, nrm, uv, idx) = grid(4);
    let (a, b) = (0.5f32, 0.3f32);
    let rot_z: Vec<[f32; 3]> = pos
        .iter()
        .map(|p| [p[0] * a.cos() - p[1] * a.sin() - p[0], p[0] * a.sin() + p[1] * a.cos() - p[1], 0.0])
        .collect();
    let rot_y: Vec<[f32; 3]> = pos.iter().map(|p| [p[0] * b.cos() - p[0], 0.0, -p[0] * b.sin()]).collect();
    let rot_y_n = vec![[b.sin(), 0.0, b.cos() - 1.0]; pos.len()];
    let swap: Vec<[f32; 2]> = pos.iter().zip(&uv).map(|(p, t)| [p[1] - t[0], p[0] - t[1]]).collect();
    let mut g = Gltf::new();
    let attrs = json!({
        "POSITION": g.floats(&pos, Some(34962)),
        "NORMAL": g.floats(&nrm, Some(34962)),
        "TEXCOORD_0": g.floats(&uv, Some(34962)),
    });
    let targets = json!([
        { "POSITION": g.floats(&rot_z, Some(34962)) },
        { "POSITION": g.floats(&rot_y, Some(34962)), "NORMAL": g.floats(&rot_y_n, Some(34962)) },
        { "TEXCOORD_0": g.floats(&swap, Some(34962)) },
    ]);
    let i = g.indices(&idx);
    let tex = g.texture();
    let m = g.material(json!({ "normalTexture": { "index": tex } }));
    g.mesh(json!({ "attributes": attrs, "indices": i, "material": m, "targets": targets }));
    g.json["meshes"][0]["weights"] = json!([0.0, 0.0, 0.0]);
    let input = d.join("morph.glb");
    g.write_glb(&input);
    let out = v.join("morph.glb");
    run_ok(&["tangents", s(&input), "-o", s(&out), "-q"]);

    let scene = load(&out);
    let base = corner_attr::<4>(&scene, P0, "TANGENT");
    let want = [[a.cos() - 1.0, a.sin(), 0.0], [b.cos() - 1.0, 0.0, -b.sin()], [-1.0, 1.0, 0.0]];
    for (c, t) in base.iter().enumerate() {
        assert!(close([t[0], t[1], t[2]], [1.0, 0.0, 0.0], 1e-6) && t[3] == 1.0, "base corner {c}: {t:?}");
    }
    for (k, w) in want.iter().enumerate() {
        let got = target_corners::<3>(&scene, k, "TANGENT");
        assert_eq!(got.len(), base.len());
        for (c, t) in got.iter().enumerate() {
            assert!(close(*t, *w, 2e-6), "target {k} corner {c}: {t:?}, expected {w:?}");
        }
    }
    // Nothing split: every delta is the same at every corner of a vertex.
    assert_eq!(scene.primitive(P0).unwrap().vertex_count(), pos.len());
    // validate reads the targets' TANGENT without complaint.
    let rep = run(&["validate", s(&out), "--format", "json"]);
    assert_eq!(rep.status.code(), Some(0), "{}", String::from_utf8_lossy(&rep.stdout));
}

/// A target that moves only part of the mesh splits nothing by itself, and a vertex on a UV seam
/// keeps one delta per side: deltas are made per output vertex.
#[test]
fn deltas_follow_the_seam_split() {
    let d = scratch_dir("morph_seam_in");
    let v = validated_dir("morph_seam");
    let pos = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [2.0, 1.0, 0.0f32]];
    // u runs 0 -> 1 -> 0 across the seam at x = 1: the seam vertices split into two.
    let uv = [[0.0, 1.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.0], [1.0, 0.0], [0.0, 0.0f32]];
    // Turn the whole strip about Z by 0.25 rad: both sides' tangents turn with it.
    let a = 0.25f32;
    let dp: Vec<[f32; 3]> = pos
        .iter()
        .map(|p| [p[0] * a.cos() - p[1] * a.sin() - p[0], p[0] * a.sin() + p[1] * a.cos() - p[1], 0.0])
        .collect();
    let mut g = Gltf::new();
    let attrs = json!({
        "POSITION": g.floats(&pos, Some(34962)),
        "NORMAL": g.floats(&[[0.0, 0.0, 1.0f32]; 6], Some(34962)),
        "TEXCOORD_0": g.floats(&uv, Some(34962)),
    });
    let targets = json!([{ "POSITION": g.floats(&dp, Some(34962)) }]);
    let i = g.indices(&[0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4]);
    let tex = g.texture();
    let m = g.material(json!({ "normalTexture": { "index": tex } }));
    g.mesh(json!({ "attributes": attrs, "indices": i, "material": m, "targets": targets }));
    let input = d.join("seam.glb");
    g.write_glb(&input);
    let out = v.join("seam.glb");
    run_ok(&["tangents", s(&input), "-o", s(&out), "-q"]);
    let scene = load(&out);
    assert_eq!(scene.primitive(P0).unwrap().vertex_count(), 8);
    let base = corner_attr::<4>(&scene, P0, "TANGENT");
    let delta = target_corners::<3>(&scene, 0, "TANGENT");
    for c in 0..12 {
        let side = if c < 6 { 1.0 } else { -1.0 };
        assert_eq!(base[c][0], side, "corner {c}");
        // The turned tangent is side * (cos a, sin a, 0).
        let want = [side * a.cos() - side, side * a.sin(), 0.0];
        assert!(close(delta[c], want, 2e-6), "corner {c}: {:?}, expected {want:?}", delta[c]);
    }
}

/// Without NORMAL, bumpbake writes the flat normals a client would make; the morphed frames use
/// those same normals (the file gives no NORMAL delta), so a turn about Z still gives the closed form.
#[test]
fn targets_of_a_primitive_without_normals() {
    let d = scratch_dir("morph_flat_in");
    let v = validated_dir("morph_flat");
    let (pos, _, uv, idx) = grid(2);
    let a = 1.0f32;
    let rot_z: Vec<[f32; 3]> = pos
        .iter()
        .map(|p| [p[0] * a.cos() - p[1] * a.sin() - p[0], p[0] * a.sin() + p[1] * a.cos() - p[1], 0.0])
        .collect();
    let mut g = Gltf::new();
    let attrs = json!({ "POSITION": g.floats(&pos, Some(34962)), "TEXCOORD_0": g.floats(&uv, Some(34962)) });
    let targets = json!([{ "POSITION": g.floats(&rot_z, Some(34962)) }]);
    let i = g.indices(&idx);
    let tex = g.texture();
    let m = g.material(json!({ "normalTexture": { "index": tex } }));
    g.mesh(json!({ "attributes": attrs, "indices": i, "material": m, "targets": targets }));
    let input = d.join("flat.glb");
    g.write_glb(&input);
    let out = v.join("flat.glb");
    run_ok(&["tangents", s(&input), "-o", s(&out), "-q"]);
    let scene = load(&out);
    let want = [a.cos() - 1.0, a.sin(), 0.0];
    for (c, t) in target_corners::<3>(&scene, 0, "TANGENT").iter().enumerate() {
        assert!(close(*t, want, 2e-6), "corner {c}: {t:?}, expected {want:?}");
    }
}

/// A normal texture read through KHR_texture_transform: the base frames follow the transformed
/// UVs, and so do the morphed ones. A target that only lifts the surface (no turn, no UV change)
/// leaves every frame as it was: zero deltas. The rotation by pi/2 turns the tangent from +u to
/// -v of the stored UVs (docs/conventions.md).
#[test]
fn morphed_frames_follow_the_texture_transform_too() {
    let d = scratch_dir("morph_transform_in");
    let v = validated_dir("morph_transform");
    let (pos, nrm, uv, idx) = grid(3);
    let lift = vec![[0.0, 0.0, 0.5f32]; pos.len()];
    let mut g = Gltf::new();
    let attrs = json!({
        "POSITION": g.floats(&pos, Some(34962)),
        "NORMAL": g.floats(&nrm, Some(34962)),
        "TEXCOORD_0": g.floats(&uv, Some(34962)),
    });
    let targets = json!([{ "POSITION": g.floats(&lift, Some(34962)) }]);
    let i = g.indices(&idx);
    let tex = g.texture();
    let transform = json!({ "KHR_texture_transform": { "rotation": std::f64::consts::FRAC_PI_2 } });
    let m = g.material(json!({ "normalTexture": { "index": tex, "extensions": transform } }));
    g.mesh(json!({ "attributes": attrs, "indices": i, "material": m, "targets": targets }));
    g.json["extensionsUsed"] = json!(["KHR_texture_transform"]);
    let input = d.join("transform.glb");
    g.write_glb(&input);
    let out = v.join("transform.glb");
    run_ok(&["tangents", s(&input), "-o", s(&out), "-q"]);
    let scene = load(&out);
    let base = corner_attr::<4>(&scene, P0, "TANGENT");
    let delta = target_corners::<3>(&scene, 0, "TANGENT");
    for (c, (t, dt)) in base.iter().zip(&delta).enumerate() {
        assert!(close([t[0], t[1], t[2]], [0.0, -1.0, 0.0], 1e-6), "base corner {c}: {t:?}");
        assert!(close(*dt, [0.0; 3], 1e-6), "corner {c}: delta {dt:?} for a target that turns nothing");
    }
}
