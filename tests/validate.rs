//! `bumpbake validate` through the binary: one small fixture per check, built to trigger that
//! check and no other; the Khronos models; the green-channel detector on analytic height fields;
//! exit codes and report formats.

mod common;
mod validate_support;
use common::*;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use validate_support::*;

// ---------------------------------------------------------------------------------------------
// Clean files

#[test]
fn bumpbake_tangents_output_is_clean() {
    let d = scratch_dir("validate_clean_in");
    let v = validated_dir("validate_clean");
    let mut p = grid_prim();
    p.tan = None;
    let input = write_prim(&d, "grid", &p, true);
    let out = v.join("grid.glb");
    run_ok(&["tangents", s(&input), "-o", s(&out), "-q"]);
    let (code, r) = validate(&[s(&out)]);
    assert_eq!(code, 0, "{r:#}");
    assert_eq!(findings(&r), vec![], "a clean file has nothing to report: {r:#}");
    assert_eq!(r["summary"]["warnings"], 0);
    // Strict changes nothing on a clean file.
    assert_eq!(validate(&[s(&out), "--strict"]).0, 0);
}

#[test]
fn mirrored_uvs_after_tangents_are_clean() {
    let d = scratch_dir("validate_mirror_clean_in");
    let v = validated_dir("validate_mirror_clean");
    let p = mirror_prim(None);
    let input = write_prim(&d, "mirror", &p, true);
    let out = v.join("mirror.gltf");
    run_ok(&["tangents", s(&input), "-o", s(&out), "-q"]);
    let (code, r) = validate(&[s(&out), "--strict"]);
    assert_eq!((code, findings(&r)), (0, vec![]), "{r:#}");
}

#[test]
fn hand_built_correct_grid_is_clean() {
    let (code, r) = broken("correct", &grid_prim(), true, &["--strict"]);
    assert_eq!((code, findings(&r)), (0, vec![]), "{r:#}");
    let c = &r["files"][0]["subjects"][0]["conformance"];
    assert!(c["compared"].as_u64().unwrap() == 24 && c["max_angle_deg"].as_f64().unwrap() < 1e-3, "{c}");
}

// ---------------------------------------------------------------------------------------------
// Presence

#[test]
fn missing_tangents_are_a_warning_that_strict_fails() {
    let mut p = grid_prim();
    p.tan = None;
    let (code, r) = broken("missing", &p, true, &[]);
    assert_only(&r, "TANGENT_MISSING", "warning");
    assert_eq!(code, 0);
    assert_eq!(broken("missing_strict", &p, true, &["--strict"]).0, 1);
}

#[test]
fn unused_tangents_are_info() {
    let (code, r) = broken("unused", &grid_prim(), false, &["--strict"]);
    assert_only(&r, "TANGENT_UNUSED", "info");
    assert_eq!(code, 0);
}

#[test]
fn tangents_without_normals_are_ignored_by_spec() {
    let mut p = grid_prim();
    p.nrm = None;
    let (code, r) = broken("no_normal", &p, true, &[]);
    assert_only(&r, "TANGENT_WITHOUT_NORMAL", "warning");
    assert_eq!(code, 0);
}

// ---------------------------------------------------------------------------------------------
// Frames

fn with_tangent(v: usize, t: [f32; 4]) -> Prim {
    let mut p = grid_prim();
    p.tan.as_mut().unwrap()[v] = t;
    p
}

#[test]
fn nan_tangent() {
    let (code, r) = broken("nan", &with_tangent(4, [f32::NAN, 0.0, 0.0, 1.0]), true, &[]);
    assert_only(&r, "TANGENT_NOT_FINITE", "error");
    assert_eq!(code, 1);
    assert_eq!(finding(&r, "TANGENT_NOT_FINITE")["examples"][0]["index"], 4);
}

#[test]
fn non_unit_tangent() {
    let (code, r) = broken("nonunit", &with_tangent(2, [1.1, 0.0, 0.0, 1.0]), true, &[]);
    assert_only(&r, "TANGENT_NOT_UNIT", "error");
    assert_eq!(code, 1);
    // Within the Khronos tolerance is fine.
    let (code, r) = broken("nearly_unit", &with_tangent(2, [1.005, 0.0, 0.0, 1.0]), true, &[]);
    assert_eq!((code, findings(&r)), (0, vec![]), "{r:#}");
}

#[test]
fn w_not_plus_minus_one() {
    let (code, r) = broken("w_half", &with_tangent(0, [1.0, 0.0, 0.0, 0.5]), true, &[]);
    assert_only(&r, "TANGENT_W_INVALID", "error");
    assert_eq!(code, 1);
}

#[test]
fn w_differs_between_corners_of_a_triangle() {
    let (code, r) = broken("w_mixed", &with_tangent(4, [1.0, 0.0, 0.0, -1.0]), true, &[]);
    assert_only(&r, "TANGENT_W_MIXED", "error");
    assert_eq!(code, 1);
    let f = finding(&r, "TANGENT_W_MIXED");
    assert_eq!(
        (f["count"].as_u64(), f["total"].as_u64()),
        (Some(6), Some(8)),
        "the centre vertex touches six triangles"
    );
}

#[test]
fn tangent_not_orthogonal_to_normal() {
    let a = 5f32.to_radians();
    let (code, r) = broken("skew", &with_tangent(4, [a.cos(), 0.0, a.sin(), 1.0]), true, &[]);
    assert_only(&r, "TANGENT_NOT_ORTHOGONAL", "warning");
    assert_eq!(code, 0);
    let m = finding(&r, "TANGENT_NOT_ORTHOGONAL")["metrics"]["max_angle_deg"].as_f64().unwrap();
    assert!((m - 5.0).abs() < 0.01, "{m}");
}

#[test]
fn tangent_parallel_to_normal() {
    let (code, r) = broken("parallel", &with_tangent(4, [0.0, 0.0, 1.0, 1.0]), true, &[]);
    assert_only(&r, "TANGENT_PARALLEL_NORMAL", "error");
    assert_eq!(code, 1);
}

// ---------------------------------------------------------------------------------------------
// Handedness

#[test]
fn flipped_w_disagrees_with_uv_orientation() {
    let mut p = grid_prim();
    p.tan = Some(vec![[1.0, 0.0, 0.0, -1.0]; p.pos.len()]);
    let (code, r) = broken("w_flipped", &p, true, &[]);
    assert_only(&r, "TANGENT_W_MISMATCH_UV", "error");
    assert_eq!(code, 1);
    let f = finding(&r, "TANGENT_W_MISMATCH_UV");
    assert_eq!((f["count"].as_u64(), f["total"].as_u64()), (Some(24), Some(24)));
}

/// Two quads sharing the edge x = 1, the right one with mirrored UVs. `seam_w` gives the two
/// shared vertices one tangent (`None`: no tangents at all).
fn mirror_prim(seam_w: Option<f32>) -> Prim {
    let pos =
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [2.0, 1.0, 0.0]];
    let uv = vec![[0.0, 1.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.0], [1.0, 0.0], [0.0, 0.0]];
    let left = [1.0, 0.0, 0.0, 1.0];
    let right = [-1.0, 0.0, 0.0, -1.0];
    let tan = seam_w.map(|w| {
        let seam = if w > 0.0 { left } else { right };
        vec![left, seam, right, left, seam, right]
    });
    Prim { nrm: Some(vec![[0.0, 0.0, 1.0]; 6]), pos, uv: Some(uv), tan, idx: vec![0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4] }
}

#[test]
fn shared_mirror_seam() {
    let (code, r) = broken("seam", &mirror_prim(Some(1.0)), true, &[]);
    assert_only(&r, "TANGENT_SEAM_SHARED", "error");
    assert_eq!(code, 1);
    let f = finding(&r, "TANGENT_SEAM_SHARED");
    assert_eq!(f["count"], 2);
    let mut seam: Vec<u64> = f["examples"].as_array().unwrap().iter().map(|e| e["index"].as_u64().unwrap()).collect();
    seam.sort();
    assert_eq!(seam, vec![1, 4]);
}

// ---------------------------------------------------------------------------------------------
// Conformance

fn rotated(deg: f32) -> Prim {
    let a = deg.to_radians();
    let mut p = grid_prim();
    p.tan = Some(vec![[a.cos(), a.sin(), 0.0, 1.0]; p.pos.len()]);
    p
}

#[test]
fn tangents_rotated_90_degrees_do_not_conform() {
    let (code, r) = broken("rot90", &rotated(90.0), true, &[]);
    assert_only(&r, "TANGENT_MIKK_ANGLE", "error");
    assert_eq!(code, 1);
    let f = finding(&r, "TANGENT_MIKK_ANGLE");
    assert!((f["metrics"]["max_angle_deg"].as_f64().unwrap() - 90.0).abs() < 1e-3);
    assert!((f["metrics"]["p99_angle_deg"].as_f64().unwrap() - 90.0).abs() < 1e-3);
}

#[test]
fn conformance_threshold_is_max_angle_deg() {
    let (code, r) = broken("rot_half", &rotated(0.5), true, &[]);
    assert_eq!((code, findings(&r)), (0, vec![]), "0.5° is within the default 1°: {r:#}");
    let (code, r) = broken("rot_half_tight", &rotated(0.5), true, &["--max-angle-deg", "0.25"]);
    assert_only(&r, "TANGENT_MIKK_ANGLE", "error");
    assert_eq!(code, 1);
}

#[test]
fn sign_against_mikktspace_on_triangles_wound_against_their_normals() {
    // Normals face -Z while the triangles wind counter-clockwise around +Z: the conventions' sign
    // (from the normal) and MikkTSpace's (from the winding) part; w follows the conventions.
    let mut p = grid_prim();
    p.nrm = Some(vec![[0.0, 0.0, -1.0]; p.pos.len()]);
    p.tan = Some(vec![[1.0, 0.0, 0.0, -1.0]; p.pos.len()]);
    let (code, r) = broken("mikk_sign", &p, true, &[]);
    assert_only(&r, "TANGENT_MIKK_SIGN", "error");
    assert_eq!(code, 1);
}

// ---------------------------------------------------------------------------------------------
// Degenerate geometry and nodes

fn with_extra_triangle(pos: [[f32; 3]; 3], uv: [[f32; 2]; 3]) -> Prim {
    let mut p = grid_prim();
    let base = p.pos.len() as u16;
    for k in 0..3 {
        p.pos.push(pos[k]);
        p.uv.as_mut().unwrap().push(uv[k]);
        p.nrm.as_mut().unwrap().push([0.0, 0.0, 1.0]);
        p.tan.as_mut().unwrap().push([1.0, 0.0, 0.0, 1.0]);
    }
    p.idx.extend([base, base + 1, base + 2]);
    p
}

#[test]
fn zero_area_triangle_is_info() {
    let mut p = grid_prim();
    p.idx.extend([0, 0, 1]);
    let (code, r) = broken("zero_area", &p, true, &["--strict"]);
    assert_only(&r, "TRIANGLE_DEGENERATE", "info");
    assert_eq!(code, 0);
    assert_eq!(finding(&r, "TRIANGLE_DEGENERATE")["examples"][0]["index"], 8);
}

#[test]
fn zero_uv_area_triangle_is_info() {
    let p = with_extra_triangle([[2.0, 0.0, 0.0], [3.0, 0.0, 0.0], [2.0, 1.0, 0.0]], [[0.5, 0.5]; 3]);
    let (code, r) = broken("zero_uv", &p, true, &["--strict"]);
    assert_only(&r, "TRIANGLE_UV_DEGENERATE", "info");
    assert_eq!(code, 0);
}

#[test]
fn sliver_triangle_is_info() {
    let p = with_extra_triangle(
        [[2.0, 0.0, 0.0], [3.0, 0.0, 0.0], [2.5, 1e-4, 0.0]],
        [[0.0, 1.0], [1.0, 1.0], [0.5, 1.0 - 1e-4]],
    );
    let (code, r) = broken("sliver", &p, true, &["--strict"]);
    assert_only(&r, "TRIANGLE_SLIVER", "info");
    assert_eq!(code, 0);
}

/// The primitive JSON of a grid whose material reads a bumpy normal map, its data added to `g`.
fn mapped_grid(g: &mut Gltf) -> Value {
    let p = grid_prim();
    let attrs = attrs_of(g, &p);
    let i = g.indices(&p.idx);
    let tex = texture_of(g, &bumpy(false));
    let m = g.material(json!({ "normalTexture": { "index": tex } }));
    json!({ "attributes": attrs, "indices": i, "material": m })
}

#[test]
fn mirrored_instance_is_info() {
    let d = scratch_dir("validate_node_mirror");
    // The mesh's node sits under a parent with a negative scale.
    let mut g = Gltf::new();
    let mesh = mapped_grid(&mut g);
    g.mesh(mesh);
    g.json["nodes"]
        .as_array_mut()
        .unwrap()
        .push(json!({ "name": "mirror", "scale": [-1.0, 1.0, 1.0], "children": [0] }));
    g.json["scenes"][0]["nodes"] = json!([1]);
    let path = d.join("mirrored.glb");
    g.write_glb(&path);
    let (code, r) = validate(&[s(&path), "--strict"]);
    assert_only(&r, "NODE_MIRRORED", "info");
    assert_eq!(code, 0);
    assert_eq!(finding(&r, "NODE_MIRRORED")["examples"][0]["index"], 0);
}

/// The mirror check walks the nodes the default scene shows, as preview and `bake --from` place
/// meshes (`scene::nodes`): a mirroring node that only another scene shows is not drawn, so not
/// counted; a mirroring node in the default scene is, with its parent chain.
#[test]
fn mirror_check_walks_the_default_scene() {
    let d = scratch_dir("validate_node_mirror_scenes");
    let mut g = Gltf::new();
    let mut mesh = mapped_grid(&mut g);
    mesh["name"] = json!("quad");
    g.mesh(mesh);
    let nodes = g.json["nodes"].as_array_mut().unwrap();
    nodes.push(json!({ "name": "mirror", "scale": [-1.0, 1.0, 1.0], "children": [0] }));
    nodes.push(json!({ "name": "other scene", "scale": [1.0, 1.0, -1.0], "mesh": 0 }));
    nodes.push(json!({ "name": "plain", "mesh": 0, "translation": [3.0, 0.0, 0.0] }));
    g.json["scenes"] = json!([{ "nodes": [1, 3] }, { "nodes": [2] }]);
    let path = d.join("scenes.glb");
    g.write_glb(&path);
    let (code, r) = validate(&[s(&path), "--strict"]);
    assert_only(&r, "NODE_MIRRORED", "info");
    assert_eq!(code, 0);
    let f = finding(&r, "NODE_MIRRORED");
    assert_eq!((f["count"].as_u64(), f["total"].as_u64()), (Some(1), Some(2)), "{f:#}");
    assert_eq!(f["examples"][0]["index"], 0);
}

#[test]
fn non_triangle_primitive_is_not_checked_info() {
    let d = scratch_dir("validate_lines");
    let mut g = Gltf::new();
    let pos = g.floats(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], Some(34962));
    let tan = g.floats(&[[1.0, 0.0, 0.0, 1.0]; 2], Some(34962));
    g.mesh(json!({ "attributes": { "POSITION": pos, "TANGENT": tan }, "mode": 1 }));
    let path = d.join("lines.glb");
    g.write_glb(&path);
    let (code, r) = validate(&[s(&path)]);
    assert_only(&r, "PRIMITIVE_NOT_CHECKED", "info");
    assert_eq!(code, 0);
}

// ---------------------------------------------------------------------------------------------
// Normal-map images

fn write_png(dir: &Path, name: &str, img: &image::RgbImage) -> PathBuf {
    let p = dir.join(name);
    img.save(&p).unwrap();
    p
}

#[test]
fn texels_with_negative_z() {
    let d = scratch_dir("validate_img_zneg");
    let mut img = bumpy(false);
    img.put_pixel(3, 5, image::Rgb([128, 128, 60]));
    let path = write_png(&d, "zneg.png", &img);
    let (code, r) = validate(&[s(&path)]);
    assert_only(&r, "NORMALMAP_Z_NEGATIVE", "error");
    assert_eq!(code, 1);
    assert_eq!(finding(&r, "NORMALMAP_Z_NEGATIVE")["examples"][0]["at"], json!([3, 5]));
}

#[test]
fn texels_far_from_unit_length() {
    let d = scratch_dir("validate_img_nonunit");
    let mut img = bumpy(false);
    img.put_pixel(7, 2, image::Rgb([128, 128, 180]));
    let path = write_png(&d, "short.png", &img);
    let (code, r) = validate(&[s(&path)]);
    assert_only(&r, "NORMALMAP_NOT_UNIT", "warning");
    assert_eq!(code, 0);
}

#[test]
fn flat_map() {
    let d = scratch_dir("validate_img_flat");
    let path = write_png(&d, "flat.png", &image::RgbImage::from_pixel(16, 16, image::Rgb([128, 128, 255])));
    let (code, r) = validate(&[s(&path)]);
    assert_only(&r, "NORMALMAP_FLAT", "warning");
    assert_eq!(code, 0);
}

#[test]
fn directx_map_given_directly() {
    let d = scratch_dir("validate_img_dx");
    let path = write_png(&d, "dx.png", &bumpy(true));
    let (code, r) = validate(&[s(&path)]);
    assert_only(&r, "NORMALMAP_GREEN_FLIPPED", "error");
    assert_eq!(code, 1);
    let f = finding(&r, "NORMALMAP_GREEN_FLIPPED");
    assert!(f["message"].as_str().unwrap().contains("looks like DirectX (-Y)"), "{f}");
    assert!(f["metrics"]["confidence"].as_f64().unwrap() > 0.8);
    // Expected to be DirectX, it passes; an OpenGL map then fails.
    let (code, r) = validate(&[s(&path), "--image-convention", "directx"]);
    assert_eq!((code, findings(&r)), (0, vec![]), "{r:#}");
    let gl = write_png(&d, "gl.png", &bumpy(false));
    let (code, r) = validate(&[s(&gl), "--image-convention", "directx"]);
    assert_only(&r, "NORMALMAP_GREEN_FLIPPED", "error");
    assert_eq!(code, 1);
}

#[test]
fn directx_map_in_a_gltf_material() {
    let d = scratch_dir("validate_gltf_dx");
    let mut g = Gltf::new();
    let p = grid_prim();
    let attrs = attrs_of(&mut g, &p);
    let i = g.indices(&p.idx);
    let tex = texture_of(&mut g, &bumpy(true));
    let m = g.material(json!({ "name": "bricks", "normalTexture": { "index": tex } }));
    g.mesh(json!({ "attributes": attrs, "indices": i, "material": m }));
    let path = g.write_gltf(&d, "dx");
    let (code, r) = validate(&[s(&path)]);
    assert_only(&r, "NORMALMAP_GREEN_FLIPPED", "error");
    assert_eq!(code, 1);
    assert!(finding(&r, "NORMALMAP_GREEN_FLIPPED")["message"].as_str().unwrap().contains("'bricks'"));
}

#[test]
fn undecodable_normal_texture_is_a_warning() {
    let d = scratch_dir("validate_gltf_badimg");
    let mut g = Gltf::new();
    let p = grid_prim();
    let attrs = attrs_of(&mut g, &p);
    let i = g.indices(&p.idx);
    let tex = g.texture();
    g.json["images"][0]["uri"] = json!("data:image/png;base64,AAAAAAAA");
    let m = g.material(json!({ "normalTexture": { "index": tex } }));
    g.mesh(json!({ "attributes": attrs, "indices": i, "material": m }));
    let path = d.join("badimg.glb");
    g.write_glb(&path);
    let (code, r) = validate(&[s(&path)]);
    assert_only(&r, "NORMALMAP_UNREADABLE", "warning");
    assert_eq!(code, 0);
}

/// The detector on five different analytic height fields, as they are and with green flipped.
#[test]
fn green_channel_convention_on_height_fields() {
    use bumpbake::normalmap::Convention;
    use bumpbake::validate::detect_convention;
    type Field = Box<dyn Fn(f64, f64) -> f64>;
    let fields: Vec<(&str, Field)> = vec![
        ("sine product", Box::new(|x, y| 6.0 * (x / 7.0).sin() * (y / 5.0).cos())),
        ("gaussian bump", Box::new(|x, y| 20.0 * (-((x - 40.0).powi(2) + (y - 25.0).powi(2)) / 200.0).exp())),
        ("ripple", Box::new(|x, y| 3.0 * (((x - 32.0).powi(2) + (y - 32.0).powi(2)).sqrt() / 3.0).sin())),
        ("saddle", Box::new(|x, y| (x - 32.0) * (y - 32.0) / 40.0)),
        ("egg crate with slope", Box::new(|x, y| 2.0 * (x / 3.0).sin() * (y / 4.0).sin() + 0.3 * x + 0.1 * y)),
        (
            "two bumps and a dent",
            Box::new(|x, y| {
                let g = |cx: f64, cy: f64, r: f64| (-((x - cx).powi(2) + (y - cy).powi(2)) / (r * r)).exp();
                10.0 * g(20.0, 20.0, 8.0) + 6.0 * g(45.0, 40.0, 5.0) - 8.0 * g(30.0, 50.0, 10.0)
            }),
        ),
    ];
    for (name, h) in &fields {
        for strength in [0.5, 2.0] {
            let (c, conf) = detect_convention(&normal_map(64, 64, strength, false, h));
            assert_eq!(c, Some(Convention::Opengl), "{name} (S {strength}), confidence {conf}");
            assert!(conf > 0.8, "{name} (S {strength}): OpenGL confidence {conf}");
            let (c, conf) = detect_convention(&normal_map(64, 64, strength, true, h));
            assert_eq!(c, Some(Convention::Directx), "{name} (S {strength}), confidence {conf}");
            assert!(conf > 0.8, "{name} (S {strength}): DirectX confidence {conf}");
        }
    }
    // A map that cannot tell (relief that is a sum f(x) + g(y) has no twist) is not accused.
    let (_, conf) =
        detect_convention(&normal_map(64, 64, 1.0, true, |x, y| 3.0 * (x / 5.0).sin() + 2.0 * (y / 4.0).cos()));
    assert!(conf < 0.5, "separable relief gives no evidence: {conf}");
}

/// The maps `bumpbake normalmap` makes from six height fields: OpenGL as made, DirectX with
/// `--convention directx`, as `bumpbake validate` reads them from the files.
#[test]
fn normalmap_output_is_recognised_in_both_conventions() {
    type Field = Box<dyn Fn(f64, f64) -> f64>;
    let fields: Vec<(&str, Field)> = vec![
        ("sine product", Box::new(|x, y| 0.5 + 0.4 * (x / 7.0).sin() * (y / 5.0).cos())),
        ("gaussian bump", Box::new(|x, y| 0.1 + 0.8 * (-((x - 40.0).powi(2) + (y - 25.0).powi(2)) / 200.0).exp())),
        ("ripple", Box::new(|x, y| 0.5 + 0.3 * (((x - 32.0).powi(2) + (y - 32.0).powi(2)).sqrt() / 3.0).sin())),
        ("saddle", Box::new(|x, y| 0.5 + (x - 32.0) * (y - 32.0) / 2500.0)),
        (
            "egg crate with slope",
            Box::new(|x, y| 0.3 + 0.1 * (x / 3.0).sin() * (y / 4.0).sin() + 0.004 * x + 0.002 * y),
        ),
        (
            "two bumps and a dent",
            Box::new(|x, y| {
                let g = |cx: f64, cy: f64, r: f64| (-((x - cx).powi(2) + (y - cy).powi(2)) / (r * r)).exp();
                0.4 + 0.4 * g(20.0, 20.0, 8.0) + 0.2 * g(45.0, 40.0, 5.0) - 0.3 * g(30.0, 50.0, 10.0)
            }),
        ),
    ];
    let d = scratch_dir("validate_nm_conventions");
    for (k, (name, h)) in fields.iter().enumerate() {
        let height = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(64, 64, |x, y| {
            image::Luma([(h(x as f64, y as f64).clamp(0.0, 1.0) * 65535.0).round() as u16])
        });
        let hp = d.join(format!("h{k}.png"));
        height.save(&hp).unwrap();
        for (conv, want) in [("opengl", "opengl"), ("directx", "directx")] {
            let np = d.join(format!("n{k}_{conv}.png"));
            let o = run(&["normalmap", s(&hp), "-o", s(&np), "--strength", "40", "--convention", conv]);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            let (_, r) = validate(&[s(&np), "--image-convention", conv]);
            let c = &r["files"][0]["subjects"][0]["convention"];
            assert_eq!(c["convention"], want, "{name} made {conv}: {c}");
            assert!(c["confidence"].as_f64().unwrap() > 0.8, "{name} {conv}: {c}");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Khronos sample models

#[test]
fn khronos_mirror_test_passes() {
    let (code, r) = validate(&[s(&fixture("khronos/NormalTangentMirrorTest.glb")), "--strict"]);
    assert_eq!((code, findings(&r)), (0, vec![]), "{r:#}");
    let c = &r["files"][0]["subjects"][0]["conformance"];
    assert!(c["compared"].as_u64().unwrap() > 10000, "{c}");
}

#[test]
fn khronos_tangent_test_needs_tangents_then_passes() {
    let input = fixture("khronos/NormalTangentTest.glb");
    let (code, r) = validate(&[s(&input)]);
    assert_only(&r, "TANGENT_MISSING", "warning");
    assert_eq!(code, 0);
    let v = validated_dir("validate_ntt");
    let out = v.join("NormalTangentTest.glb");
    run_ok(&["tangents", s(&input), "-o", s(&out), "-q"]);
    let (code, r) = validate(&[s(&out), "--strict"]);
    assert_eq!((code, findings(&r)), (0, vec![]), "{r:#}");
}

// ---------------------------------------------------------------------------------------------
// Command line, exit codes, formats

#[test]
fn deny_and_allow_move_single_checks() {
    let d = scratch_dir("validate_policy");
    let unused = write_prim(&d, "unused", &grid_prim(), false);
    let (code, r) = validate(&[s(&unused), "--deny", "TANGENT_UNUSED"]);
    assert_only(&r, "TANGENT_UNUSED", "error");
    assert_eq!(code, 1);
    let mut p = grid_prim();
    p.tan = Some(vec![[1.0, 0.0, 0.0, -1.0]; p.pos.len()]);
    let flipped = write_prim(&d, "flipped", &p, true);
    let (code, r) = validate(&[s(&flipped), "--allow", "tangent_w_mismatch_uv,TANGENT_UNUSED"]);
    assert_only(&r, "TANGENT_W_MISMATCH_UV", "info");
    assert_eq!(code, 0);
}

#[test]
fn unusable_input_and_bad_command_lines_exit_2() {
    let d = scratch_dir("validate_bad");
    let garbage = d.join("garbage.glb");
    std::fs::write(&garbage, b"glTF\x02\0\0\0").unwrap();
    let notimg = d.join("notes.txt");
    std::fs::write(&notimg, b"hello").unwrap();
    for args in [
        vec!["validate", s(&garbage)],
        vec!["validate", s(&notimg)],
        vec!["validate", s(&d.join("missing.gltf"))],
        vec!["validate", s(&fixture("khronos/NormalTangentTest.glb")), "--deny", "NO_SUCH_CHECK"],
        vec!["validate", s(&fixture("khronos/NormalTangentTest.glb")), "--max-angle-deg", "-1"],
        vec!["validate", s(&fixture("khronos/NormalTangentTest.glb")), "--format", "xml"],
        vec!["validate"],
    ] {
        let out = run(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
        assert!(out.stdout.is_empty(), "{args:?} prints no report");
    }
    let out = run(&["validate", s(&garbage)]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "one line: {err}");
    assert!(err.contains("garbage.glb"), "names the file: {err}");
}

#[test]
fn json_schema_is_stable() {
    let mut p = grid_prim();
    p.tan = Some(vec![[1.0, 0.0, 0.0, -1.0]; p.pos.len()]);
    let (_, r) = broken("schema", &p, true, &[]);
    assert_eq!(r["schema"], "bumpbake-validate/1");
    assert_eq!(r["exit_code"], 1);
    assert_eq!(r["summary"]["errors"], 1);
    let file = &r["files"][0];
    assert_eq!(file["kind"], "mesh");
    let sub = &file["subjects"][0];
    assert_eq!(
        (sub["kind"].as_str(), sub["mesh"].as_u64(), sub["primitive"].as_u64()),
        (Some("primitive"), Some(0), Some(0))
    );
    assert!(sub["checks"].as_array().unwrap().iter().any(|c| c == "TANGENT_MIKK_ANGLE"));
    let f = finding(&r, "TANGENT_W_MISMATCH_UV");
    for key in ["code", "severity", "count", "total", "unit", "message", "hint", "examples", "metrics"] {
        assert!(f.get(key).is_some(), "finding has {key}: {f}");
    }
    let e = &f["examples"][0];
    assert_eq!((e["kind"].as_str(), e["index"].as_u64()), (Some("corner"), Some(0)));
}

#[test]
fn junit_has_a_testcase_per_primitive_and_check() {
    let d = scratch_dir("validate_junit");
    let mut p = grid_prim();
    p.tan = Some(vec![[1.0, 0.0, 0.0, -1.0]; p.pos.len()]);
    let path = write_prim(&d, "flipped", &p, true);
    let out = run(&["validate", s(&path), "--format", "junit", "-q"]);
    assert_eq!(out.status.code(), Some(1));
    let x = String::from_utf8(out.stdout).unwrap();
    assert!(x.starts_with("<?xml"), "{x}");
    let cases = x.matches("<testcase ").count();
    let (_, r) = validate(&[s(&path)]);
    let expected: usize =
        r["files"][0]["subjects"].as_array().unwrap().iter().map(|s| s["checks"].as_array().unwrap().len()).sum();
    assert_eq!(cases, expected);
    assert_eq!(x.matches("<failure ").count(), 1);
    assert!(x.contains("type=\"TANGENT_W_MISMATCH_UV\""));
    assert!(x.contains(&format!("tests=\"{expected}\" failures=\"1\"")));
}

#[test]
fn github_annotations() {
    let d = scratch_dir("validate_github");
    let mut p = grid_prim();
    p.tan = Some(vec![[1.0, 0.0, 0.0, -1.0]; p.pos.len()]);
    let path = write_prim(&d, "flipped", &p, true);
    let out = run(&["validate", s(&path), "--format", "github", "-q"]);
    assert_eq!(out.status.code(), Some(1));
    let t = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = t.lines().collect();
    assert_eq!(lines.len(), 1, "{t}");
    assert!(lines[0].starts_with("::error file="), "{t}");
    assert!(lines[0].contains("title=TANGENT_W_MISMATCH_UV::mesh 0 primitive 0: "), "{t}");
    assert!(lines[0].contains("%0Afix: "), "newlines are escaped: {t}");
}

#[test]
fn human_summary_on_stderr_and_help_examples() {
    let out = run(&["validate", s(&fixture("khronos/NormalTangentTest.glb"))]);
    assert_eq!(out.status.code(), Some(0));
    assert!(out.stdout.is_empty());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("TANGENT_MISSING") && e.contains("fix: ") && e.contains("PASS"), "{e}");
    let h = run_ok(&["validate", "--help"]);
    let h = String::from_utf8_lossy(&h.stdout);
    assert!(h.trim_end().lines().last().unwrap().trim_start().starts_with("bumpbake validate "), "{h}");
    let codes = run_ok(&["validate", "--list-codes"]);
    assert!(String::from_utf8_lossy(&codes.stdout).lines().count() >= 20);
}

#[test]
fn obj_input_and_multiple_files() {
    let (code, r) = validate(&[s(&fixture("spot/spot.obj")), s(&fixture("khronos/NormalTangentMirrorTest.glb"))]);
    assert_eq!(code, 0, "{r:#}");
    assert_eq!(r["files"].as_array().unwrap().len(), 2);
}

/// A 1M-triangle grid for the timing in docs/validate.md (no timing here):
/// `cargo test --release --test validate -- --ignored big_grid`, then time both commands on it.
#[test]
#[ignore]
fn big_grid() {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("bench");
    std::fs::create_dir_all(&d).unwrap();
    let path = d.join("grid1m.glb");
    write_big_grid(&path, 708); // 708 * 708 * 2 = 1,002,528 triangles
    eprintln!("wrote {}", path.display());
}

/// A normal texture reading a UV set the primitive lacks is an error (the Khronos validator's
/// MESH_PRIMITIVE_TOO_FEW_TEXCOORDS): nothing can place the map.
#[test]
fn texture_reading_a_missing_uv_set_is_an_error() {
    let mut p = grid_prim();
    p.uv = None;
    let (code, r) = broken("texcoord_missing", &p, true, &[]);
    let f = finding(&r, "TEXCOORD_MISSING");
    assert_eq!(f["severity"], "error", "{f:#}");
    assert!(f["message"].as_str().unwrap().contains("normalTexture reads TEXCOORD_0"), "{f:#}");
    assert_eq!(code, 1);
}
