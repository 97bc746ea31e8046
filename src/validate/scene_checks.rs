//! Runs the checks over a whole scene: each primitive (presence, frames, handedness,
//! conformance, degenerate triangles), node transforms, and each normal-map image once.

use super::frames::{self, Explained, PrimData, Quant};
use super::{
    conformance, handedness, mip_levels, normal_image, roughness_levels, Code, Convention, Example, Finding, Options,
    Subject, Worst,
};
use crate::error::Result;
use crate::format::image;
use crate::scene::material::{MaterialInfo, Slot};
use crate::scene::nodes::instances;
use crate::scene::view::views;
use crate::scene::{Materials, PrimRef, Scene};
use rayon::prelude::*;
use serde_json::Value;
use std::borrow::Cow;
use std::collections::BTreeMap;

pub fn run(scene: &Scene, opts: &Options) -> Result<Vec<Subject>> {
    // Reading is cheap and may fail (exit 2); checking is the expensive part and runs in parallel.
    let mut subjects = Vec::new();
    let mats = scene.materials();
    for view in views(scene, mats) {
        let r = view.at;
        let mut s = Subject::new("primitive", prim_name(scene, r));
        s.mesh = Some(r.mesh);
        s.primitive = Some(r.primitive);
        check_texcoords(scene, mats, r, &mut s);
        let code = Code::PRIMITIVE_NOT_CHECKED;
        if !view.mode.has_triangles() {
            let why = format!("not checked: not triangles (mode {})", view.mode);
            s.check(code, Some(Finding::new(code, 1, 1, "primitives", why)));
            subjects.push((s, None));
            continue;
        }
        let g = match view.read(scene) {
            Ok(g) => g,
            Err(e) => {
                let why = match &e {
                    crate::Error::Input { msg, .. } => msg.to_string(),
                    other => other.to_string(),
                };
                let f = Finding::new(Code::PRIMITIVE_UNREADABLE, 1, 1, "primitives", format!("cannot be read: {why}"));
                s.check(Code::PRIMITIVE_UNREADABLE, Some(f));
                subjects.push((s, None));
                continue;
            }
        };
        let nr = g.normal_repair;
        let normal_finding = nr.any().then(|| {
            let n = g.primitive.vertex_count();
            let bad = nr.unusable + nr.renormalised;
            Finding::new(
                Code::NORMAL_NOT_UNIT,
                bad,
                n,
                "vertices",
                format!(
                    "{} normals are zero or not finite and {} are not unit length; checked with them repaired",
                    nr.unusable, nr.renormalised
                ),
            )
        });
        s.check(Code::NORMAL_NOT_UNIT, normal_finding);
        let p = &g.primitive;
        if p.attr("POSITION").map(|s| s.len()) != Some(p.vertex_count()) {
            let f = Finding::new(
                Code::PRIMITIVE_NOT_CHECKED,
                1,
                1,
                "primitives",
                "not checked: no usable POSITION attribute",
            );
            s.check(Code::PRIMITIVE_NOT_CHECKED, Some(f));
            subjects.push((s, None));
            continue;
        }
        // Compared as a renderer sees them (the view's values): quantized normals made unit, UVs
        // through the transform of the texture the tangents serve (the UVs the tangent must follow).
        let uvs = view.tangent_uvs();
        let step = |name: &str| {
            let decoded =
                scene.prim_json(r).get("attributes").and_then(|a| a.get(name)).and_then(crate::scene::as_index);
            let decoded = decoded.and_then(|a| scene.decoded_steps.get(&a)).copied().unwrap_or(0.0);
            p.attr(name).map_or(0.0, |s| s.step() as f64).max(decoded)
        };
        let quant = Quant {
            position: step("POSITION"),
            normal: step("NORMAL"),
            uv: step(&uvs.attribute()) * uvs.transform.as_ref().map_or(1.0, |t| t.max_stretch()),
            tangent: step("TANGENT"),
        };
        let positions = g.positions().into_owned();
        let normals = g.normals().map(Cow::into_owned);
        let tangent_uvs = g.tangent_uv_values().map(Cow::into_owned);
        let tangents = g.tangents();
        let d = PrimData { positions, normals, uvs: tangent_uvs, tangents, quant, indices: g.primitive.indices };
        let wanted_by = view.tangent_need.map(|n| n.describe());
        subjects.push((s, Some((d, wanted_by))));
    }
    let max_angle = opts.max_angle_deg;
    let stores_tangents = scene.source_format.stores_tangents();
    let mut done: Vec<Subject> = subjects
        .into_par_iter()
        .map(|(mut s, data)| {
            if let Some((d, wanted_by)) = data {
                check_primitive(&d, wanted_by.as_deref(), max_angle, stores_tangents, &mut s);
            }
            s
        })
        .collect();
    if let Some(s) = check_nodes(scene) {
        done.push(s);
    }
    done.extend(check_images(scene, mats));
    Ok(done)
}

/// Each texture of the primitive's materials (its own and its variants') must find the UV set it
/// reads.
fn check_texcoords(scene: &Scene, mats: &Materials, r: PrimRef, s: &mut Subject) {
    let textures = mats.textures_of(scene, r).len();
    if textures == 0 {
        return;
    }
    let missing = mats.missing_uv_sets(scene, r);
    let finding = (!missing.is_empty()).then(|| {
        let mut list: Vec<String> = Vec::new();
        for (m, t) in &missing {
            let line = format!("{} {} reads TEXCOORD_{}", m.label(), t.name(), t.tex_coord);
            if !list.contains(&line) {
                list.push(line);
            }
        }
        Finding::new(
            Code::TEXCOORD_MISSING,
            missing.len(),
            textures,
            "textures",
            format!("the primitive lacks the UV sets its materials' textures read: {}", list.join(", ")),
        )
    });
    s.check(Code::TEXCOORD_MISSING, finding);
}

fn prim_name(scene: &Scene, r: PrimRef) -> String {
    match scene.mesh_name(r.mesh) {
        Some(n) if !n.is_empty() => format!("mesh {} ('{n}') primitive {}", r.mesh, r.primitive),
        _ => format!("mesh {} primitive {}", r.mesh, r.primitive),
    }
}

/// Every check of one primitive, in the order that lets later checks skip what earlier ones
/// explained. `wanted_by` says what needs tangents (a normal, clearcoat normal or anisotropy
/// texture of a material the primitive can show), if anything does.
fn check_primitive(d: &PrimData, wanted_by: Option<&str>, max_angle_deg: f64, stores_tangents: bool, s: &mut Subject) {
    let uses_map = wanted_by.is_some();
    let has_t = d.tangents.is_some();
    let has_n = d.normals.is_some();
    // A format that cannot store tangents (OBJ) leaves them to the renderer that loads it.
    if uses_map && stores_tangents {
        s.check(
            Code::TANGENT_MISSING,
            (!has_t).then(|| {
                Finding::new(
                    Code::TANGENT_MISSING,
                    1,
                    1,
                    "primitives",
                    format!("tangents are needed ({}), but the primitive has no TANGENT", wanted_by.unwrap_or("")),
                )
            }),
        );
    }
    if has_t {
        s.check(
            Code::TANGENT_UNUSED,
            (!uses_map).then(|| {
                Finding::new(
                    Code::TANGENT_UNUSED,
                    1,
                    1,
                    "primitives",
                    "TANGENT is present but nothing reads it (no normal, clearcoat normal or anisotropy texture)",
                )
            }),
        );
        s.check(
            Code::TANGENT_WITHOUT_NORMAL,
            (!has_n).then(|| {
                Finding::new(
                    Code::TANGENT_WITHOUT_NORMAL,
                    1,
                    1,
                    "primitives",
                    "TANGENT without NORMAL: clients must compute flat normals and ignore the tangents",
                )
            }),
        );
    }
    if !(uses_map || has_t) {
        return;
    }
    let mut ex = Explained::new(d.positions.len(), d.indices.len());
    // Degenerate triangles are judged in the UV set that matters: the map's, if there is one.
    frames::check_degenerate(d, uses_map, &mut ex, s);
    if !has_t {
        return;
    }
    frames::check_vectors(d, &mut ex, s);
    // A shared mirror seam is the root cause of the mixed-w triangles around it: check it first.
    let expected = (uses_map && has_n && d.uvs.is_some()).then(|| {
        let e = handedness::expected_w(d, &ex);
        handedness::check_seams(d, &e, &mut ex, s);
        e
    });
    frames::check_w_mixed(d, &mut ex, s);
    let Some(expected) = expected else { return };
    handedness::check_w_vs_uv(d, &expected, &mut ex, s);
    conformance::check(d, max_angle_deg, &mut ex, s);
}

/// Nodes that show a mesh through a mirroring transform (negative determinant of the world
/// matrix), over the nodes the scene shows ([`instances`], the walk every stage places meshes with).
fn check_nodes(scene: &Scene) -> Option<Subject> {
    let mut shown: Vec<(usize, usize, bool)> =
        instances(scene).iter().filter_map(|i| Some((i.node?, i.mesh, i.mirrored()))).collect();
    shown.sort_by_key(|s| s.0);
    shown.dedup_by_key(|s| s.0);
    if shown.is_empty() {
        return None;
    }
    let name = |i: usize| scene.node_name(i);
    let mut s = Subject::new("file", "node transforms");
    let mut worst = Worst::default();
    let mirrored: Vec<&(usize, usize, bool)> = shown.iter().filter(|s| s.2).collect();
    for &&(i, mesh, _) in &mirrored {
        worst.push(1.0 / (1.0 + i as f64), || Example {
            kind: "node",
            index: i as u64,
            at: None,
            detail: format!(
                "node {i}{} shows mesh {mesh} mirrored",
                name(i).map(|x| format!(" ('{x}')")).unwrap_or_default()
            ),
        });
    }
    let (count, total) = (mirrored.len(), shown.len());
    s.check(
        Code::NODE_MIRRORED,
        (count > 0).then(|| {
            Finding::new(
                Code::NODE_MIRRORED,
                count,
                total,
                "nodes",
                format!("{count} of {total} mesh nodes have a negative-determinant (mirroring) world transform"),
            )
            .examples(worst.into_examples())
        }),
    );
    Some(s)
}

/// Each image some material's normal (or clearcoat normal) texture can show, its core source and
/// those of EXT_texture_webp and KHR_texture_basisu (different clients show different ones),
/// checked once.
fn check_images(scene: &Scene, mats: &Materials) -> Vec<Subject> {
    type Users<'a> = (Vec<String>, Option<&'static str>, Vec<&'a MaterialInfo>);
    let mut users: BTreeMap<usize, Users> = BTreeMap::new();
    for (m, t) in mats.normal_images().into_values().flatten() {
        for ti in scene.texture_images(t.texture) {
            let entry = users.entry(ti.image).or_default();
            if !entry.0.contains(&m.label()) {
                entry.0.push(m.label());
            }
            // Clearcoat normals pair with the clearcoat's roughness, not the base layer's.
            if t.slot == Slot::Normal && !entry.2.iter().any(|x| x.index == m.index) {
                entry.2.push(m);
            }
            entry.1 = entry.1.or(ti.extension);
        }
    }
    users
        .into_iter()
        .map(|(i, (mats, extension, base_layer))| {
            let img_json = scene.json.pointer(&format!("/images/{i}")).cloned().unwrap_or(Value::Null);
            let label = img_json
                .get("name")
                .and_then(|n| n.as_str())
                .or_else(|| img_json.get("uri").and_then(|u| u.as_str()).filter(|u| !u.starts_with("data:")))
                .map(|l| format!("image {i} ('{l}')"))
                .unwrap_or(format!("image {i}"));
            let mut s = Subject::new("image", label);
            s.image = Some(i);
            let via = extension.map(|e| format!(", through {e}")).unwrap_or_default();
            let wanted_by = format!("{} (as a normal map{via})", mats.join(", "));
            let bytes = scene.image_bytes(i).map_err(|e| e.to_string());
            if let Some(why) = bytes.as_deref().ok().and_then(image::not_decoded_why) {
                let f = Finding::new(Code::NORMALMAP_NOT_DECODED, 1, 1, "images", format!("not checked: {why}"));
                s.check(Code::NORMALMAP_NOT_DECODED, Some(f));
                return s;
            }
            let codec = bytes.as_deref().map(normal_image::Codec::sniff).unwrap_or(normal_image::Codec::Lossless);
            let unreadable = |e: String, what: &str| {
                let f = Finding::new(Code::NORMALMAP_UNREADABLE, 1, 1, "images", format!("{what} not checked: {e}"));
                Some(f)
            };
            let bytes = match bytes {
                Ok(b) => b,
                Err(e) => {
                    s.check(Code::NORMALMAP_UNREADABLE, unreadable(e, "normal texture"));
                    return s;
                }
            };
            // A KTX2 carries its own chain: every level is decoded (under the same limits), and
            // level 0 is checked as any other map.
            let chain = (image::Kind::sniff(&bytes) == image::Kind::Ktx2)
                .then(|| image::ktx2::decode_levels_within(&bytes, &image::Limits::TEXTURE));
            match chain {
                Some(Ok(imgs)) => {
                    normal_image::check(&imgs[0], codec, Convention::Opengl, &wanted_by, &mut s);
                    let levels = mip_levels::levels(&imgs);
                    drop(imgs);
                    mip_levels::check(&levels, codec, &mut s);
                    roughness_levels::check(scene, &base_layer, &levels, &mut s);
                }
                chain => match image::decode(&bytes) {
                    Ok(img) => {
                        normal_image::check(&img, codec, Convention::Opengl, &wanted_by, &mut s);
                        // Level 0 decodes and a level below it does not.
                        if let Some(Err(e)) = chain {
                            s.check(Code::NORMALMAP_UNREADABLE, unreadable(e.to_string(), "mip levels"));
                        }
                    }
                    Err(e) => s.check(Code::NORMALMAP_UNREADABLE, unreadable(e.to_string(), "normal texture")),
                },
            }
            s
        })
        .collect()
}
