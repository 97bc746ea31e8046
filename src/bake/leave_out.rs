//! Leaving out what the scene does not need: tangents where no material the primitive can show
//! needs them (see [`crate::scene::material`]), UV sets no texture reads, `_BITANGENT` unless asked for, materials, textures, images and samplers
//! nothing references, and images that are the same bytes. Accessors and buffer views that fall
//! out of use are dropped by the writer. Nothing a node, animation, skin, morph target or known
//! extension references is removed; with an unknown extension in use, only the attributes go.

use crate::error::Result;
use crate::scene::refs::{self, Walker};
use crate::scene::{PrimRef, Scene};
use serde_json::Value;
use std::collections::HashMap;

/// One thing left out, and the bytes it took.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Removal {
    pub what: String,
    pub bytes: usize,
}

pub fn leave_out(scene: &mut Scene, keep_bitangents: bool) -> Result<Vec<Removal>> {
    let unknown = refs::unknown_object_refs(&scene.json);
    // An unknown extension may read a UV set by its number: then no set is renumbered.
    let mut removed = if unknown { Vec::new() } else { renumber_uv_sets(scene) };
    removed.extend(attributes(scene, keep_bitangents)?);
    if !unknown {
        removed.extend(materials(scene));
        removed.extend(dedupe_images(scene)?);
        removed.extend(textures_images_samplers(scene)?);
    }
    Ok(removed)
}

/// UV sets no texture reads go even when a later one is read: the read sets are renumbered from
/// 0, in primitives and in the materials that name them, where every primitive sharing those
/// materials has every set they name.
fn renumber_uv_sets(scene: &mut Scene) -> Vec<Removal> {
    use crate::scene::texcoord;
    let refs = scene.primitives();
    let mats = scene.materials();
    let prims: Vec<texcoord::PrimSets> = refs
        .iter()
        .map(|&r| {
            let pj = scene.prim_json(r);
            let materials = mats.of_primitive(scene, r);
            let sets = pj
                .get("attributes")
                .and_then(|a| a.as_object())
                .into_iter()
                .flat_map(|a| a.keys())
                .filter_map(|k| k.strip_prefix("TEXCOORD_")?.parse().ok())
                .collect();
            texcoord::PrimSets { materials, sets }
        })
        .collect();
    let named: Vec<_> = scene
        .json
        .get("materials")
        .and_then(|m| m.as_array())
        .into_iter()
        .flatten()
        .map(texcoord::material_named_sets)
        .collect();
    let plan = texcoord::plan(&prims, &named);
    for (m, map) in plan.materials.iter().enumerate() {
        if let Some(map) = map {
            texcoord::renumber_material(&mut scene.json["materials"][m], map);
        }
    }
    let mut out = Vec::new();
    for (r, map) in refs.into_iter().zip(&plan.primitives) {
        let Some(map) = map else { continue };
        let moved: Vec<String> =
            map.iter().filter(|(o, n)| o != n).map(|(o, n)| format!("TEXCOORD_{o} becomes TEXCOORD_{n}")).collect();
        let why = if moved.is_empty() {
            "no texture reads it".to_string()
        } else {
            format!("no texture reads it; {}", moved.join(", "))
        };
        for (name, idx) in texcoord::renumber_primitive(prim_mut(scene, r), map) {
            let bytes = accessor_bytes(scene, idx);
            out.push(Removal { what: format!("mesh {} primitive {}: {name} ({why})", r.mesh, r.primitive), bytes });
        }
    }
    out
}

fn accessor_bytes(scene: &Scene, idx: Option<u64>) -> usize {
    let Some(a) = idx.and_then(|i| scene.json.pointer(&format!("/accessors/{i}"))) else { return 0 };
    let n = a.get("count").and_then(|c| c.as_u64()).unwrap_or(0) as usize;
    let f = crate::scene::Format {
        component_type: a.get("componentType").and_then(|c| c.as_u64()).unwrap_or(0) as u32,
        ty: a.get("type").and_then(|t| t.as_str()).unwrap_or("").to_string(),
        normalized: false,
    };
    n * f.elem_size()
}

fn attributes(scene: &mut Scene, keep_bitangents: bool) -> Result<Vec<Removal>> {
    let mut out = Vec::new();
    let mats = scene.materials();
    for r in scene.primitives() {
        let needs_tangents = mats.tangent_need(scene, r).is_some();
        let max_set = mats.uv_sets(scene, r).into_iter().next_back();
        let names: Vec<String> = scene
            .prim_json(r)
            .get("attributes")
            .and_then(|a| a.as_object())
            .map(|a| a.keys().cloned().collect())
            .unwrap_or_default();
        let mut drop = Vec::new();
        for name in names {
            let why = if name == "TANGENT" && !needs_tangents {
                Some("no normal texture, clearcoat normal texture or anisotropy reads it")
            } else if name == "_BITANGENT" && !keep_bitangents {
                Some("not asked for (--bitangents)")
            } else if let Some(k) = name.strip_prefix("TEXCOORD_").and_then(|k| k.parse::<u64>().ok()) {
                // Only trailing sets go: glTF wants TEXCOORD_0..n without gaps.
                (max_set.map(|m| k > m as u64).unwrap_or(true)).then_some("no texture reads it")
            } else {
                None
            };
            if let Some(why) = why {
                drop.push((name, why));
            }
        }
        for (name, why) in drop {
            let pj = prim_mut(scene, r);
            let idx = pj["attributes"].as_object_mut().and_then(|a| a.remove(&name)).and_then(|v| v.as_u64());
            let mut target_idx = Vec::new();
            if name == "TANGENT" {
                for t in pj.get_mut("targets").and_then(|t| t.as_array_mut()).into_iter().flatten() {
                    if let Some(i) = t.as_object_mut().and_then(|o| o.remove("TANGENT")).and_then(|v| v.as_u64()) {
                        target_idx.push(i);
                    }
                }
            }
            let bytes =
                accessor_bytes(scene, idx) + target_idx.iter().map(|&i| accessor_bytes(scene, Some(i))).sum::<usize>();
            out.push(Removal { what: format!("mesh {} primitive {}: {name} ({why})", r.mesh, r.primitive), bytes });
        }
    }
    Ok(out)
}

fn prim_mut(scene: &mut Scene, r: PrimRef) -> &mut Value {
    &mut scene.json["meshes"][r.mesh]["primitives"][r.primitive]
}

fn len(scene: &Scene, key: &str) -> usize {
    scene.json.get(key).and_then(|a| a.as_array()).map(|a| a.len()).unwrap_or(0)
}

/// Drops the entries of `json[key]` that `walk` finds no reference to and renumbers the rest;
/// returns the indices that went. A list left empty goes too. Nothing changes when a reference
/// dangles (the file is broken there; the writer names it).
fn drop_unused(scene: &mut Scene, key: &str, walk: Walker) -> Vec<usize> {
    let Ok(d) = refs::drop_unreferenced(&mut scene.json, key, false, walk) else { return Vec::new() };
    if len(scene, key) == 0 {
        if let Some(o) = scene.json.as_object_mut() {
            o.remove(key);
        }
    }
    d.gone
}

fn materials(scene: &mut Scene) -> Vec<Removal> {
    let names: Vec<String> = (0..len(scene, "materials")).map(|i| name_of(scene, "materials", i)).collect();
    drop_unused(scene, "materials", refs::material_refs)
        .into_iter()
        .map(|i| Removal { what: format!("material {i} {} (no primitive uses it)", names[i]), bytes: 0 })
        .collect()
}

fn name_of(scene: &Scene, key: &str, i: usize) -> String {
    scene
        .json
        .pointer(&format!("/{key}/{i}/name"))
        .and_then(|n| n.as_str())
        .map(|n| format!("'{n}'"))
        .unwrap_or_default()
}

/// Points every texture at the first image with the same bytes; the rest fall out of use.
fn dedupe_images(scene: &mut Scene) -> Result<Vec<Removal>> {
    let n = len(scene, "images");
    let mut first: HashMap<Vec<u8>, usize> = HashMap::new();
    let mut map: Vec<Option<usize>> = (0..n).map(Some).collect();
    let mut out = Vec::new();
    for (i, slot) in map.iter_mut().enumerate() {
        let Ok(bytes) = scene.image_bytes(i) else { continue };
        match first.get(&bytes) {
            Some(&j) => {
                *slot = Some(j);
                out.push(Removal {
                    what: format!("image {i} {} (same bytes as image {j})", name_of(scene, "images", i)),
                    bytes: bytes.len(),
                });
            }
            None => {
                first.insert(bytes, i);
            }
        }
    }
    if !out.is_empty() {
        refs::image_refs(&mut scene.json, &mut |i| *i = map.get(*i).copied().flatten().unwrap_or(*i));
    }
    Ok(out)
}

fn textures_images_samplers(scene: &mut Scene) -> Result<Vec<Removal>> {
    // Textures: what materials read.
    let mut out: Vec<Removal> = drop_unused(scene, "textures", refs::texture_refs)
        .into_iter()
        .map(|i| Removal { what: format!("texture {i} (no material reads it)"), bytes: 0 })
        .collect();
    // Images: what textures show (those deduplicated above are already counted).
    let shown = refs::image_refs(&mut scene.json, &mut |_| {});
    let unshown: HashMap<usize, (String, usize)> = (0..len(scene, "images"))
        .filter(|i| !shown.contains(i))
        .map(|i| (i, (name_of(scene, "images", i), scene.image_bytes(i).map(|b| b.len()).unwrap_or(0))))
        .collect();
    for i in drop_unused(scene, "images", refs::image_refs) {
        if let Some((name, bytes)) =
            unshown.get(&i).filter(|_| !out.iter().any(|r| r.what.starts_with(&format!("image {i} "))))
        {
            out.push(Removal { what: format!("image {i} {name} (no texture shows it)"), bytes: *bytes });
        }
    }
    // Samplers: what textures use.
    out.extend(
        drop_unused(scene, "samplers", refs::sampler_refs)
            .into_iter()
            .map(|i| Removal { what: format!("sampler {i} (no texture uses it)"), bytes: 0 }),
    );
    Ok(out)
}
