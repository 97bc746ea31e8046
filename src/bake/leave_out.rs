//! Leaving out what the scene does not need: tangents where no normal texture reads them, UV sets
//! no texture reads, `_BITANGENT` unless asked for, materials, textures, images and samplers
//! nothing references, and images that are the same bytes. Accessors and buffer views that fall
//! out of use are dropped by the writer. Nothing a node, animation, skin, morph target or known
//! extension references is removed; with an unknown extension in use, only the attributes go.

use crate::error::Result;
use crate::scene::{PrimRef, Scene};
use serde_json::{json, Value};
use std::collections::{BTreeSet, HashMap};

/// One thing left out, and the bytes it took.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Removal {
    pub what: String,
    pub bytes: usize,
}

/// Extensions whose texture and image references [`texture_refs`] and [`image_refs`] follow.
const KNOWN: &[&str] = &[
    "KHR_texture_transform",
    "KHR_lights_punctual",
    "KHR_materials_clearcoat",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_iridescence",
    "KHR_materials_sheen",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_materials_unlit",
    "KHR_materials_variants",
    "KHR_materials_volume",
    "KHR_materials_anisotropy",
    "KHR_materials_dispersion",
    "KHR_mesh_quantization",
    "KHR_texture_basisu",
    "EXT_texture_webp",
    "EXT_mesh_gpu_instancing",
];

pub fn leave_out(scene: &mut Scene, keep_bitangents: bool) -> Result<Vec<Removal>> {
    let unknown = scene
        .json
        .get("extensionsUsed")
        .and_then(|e| e.as_array())
        .map(|l| l.iter().any(|e| !KNOWN.contains(&e.as_str().unwrap_or(""))))
        .unwrap_or(false);
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
    let prims: Vec<texcoord::PrimSets> = refs
        .iter()
        .map(|&r| {
            let pj = scene.prim_json(r);
            let mut materials: Vec<usize> =
                pj.get("material").and_then(|m| m.as_u64()).map(|m| m as usize).into_iter().collect();
            for mapping in pj
                .pointer("/extensions/KHR_materials_variants/mappings")
                .and_then(|m| m.as_array())
                .into_iter()
                .flatten()
            {
                materials.extend(mapping.get("material").and_then(|m| m.as_u64()).map(|m| m as usize));
            }
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

fn texture_infos(v: &mut Value, f: &mut dyn FnMut(&mut Value)) {
    crate::scene::texcoord::texture_infos_mut(v, f)
}

/// The UV sets a material's textures read.
fn used_sets(material: Option<&Value>) -> BTreeSet<u64> {
    let mut sets = BTreeSet::new();
    if let Some(m) = material {
        let mut m = m.clone();
        texture_infos(&mut m, &mut |t| {
            let over = t.pointer("/extensions/KHR_texture_transform/texCoord").and_then(|c| c.as_u64());
            sets.insert(over.or_else(|| t.get("texCoord").and_then(|c| c.as_u64())).unwrap_or(0));
        });
    }
    sets
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
    for r in scene.primitives() {
        let has_normal_tex = scene.normal_texcoord(r).is_some();
        let sets = used_sets(scene.material_of(r));
        let max_set = sets.iter().next_back().copied();
        let names: Vec<String> = scene
            .prim_json(r)
            .get("attributes")
            .and_then(|a| a.as_object())
            .map(|a| a.keys().cloned().collect())
            .unwrap_or_default();
        let mut drop = Vec::new();
        for name in names {
            let why = if name == "TANGENT" && !has_normal_tex {
                Some("no normal texture reads it")
            } else if name == "_BITANGENT" && !keep_bitangents {
                Some("not asked for (--bitangents)")
            } else if let Some(k) = name.strip_prefix("TEXCOORD_").and_then(|k| k.parse::<u64>().ok()) {
                // Only trailing sets go: glTF wants TEXCOORD_0..n without gaps.
                (max_set.map(|m| k > m).unwrap_or(true)).then_some("no texture reads it")
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

/// Keeps `keep` of `json[key]`, returns old -> new index.
fn compact(scene: &mut Scene, key: &str, keep: &BTreeSet<usize>) -> Vec<Option<usize>> {
    let list = scene.json.get(key).and_then(|a| a.as_array()).cloned().unwrap_or_default();
    let mut map = vec![None; list.len()];
    let mut kept = Vec::new();
    for (i, item) in list.into_iter().enumerate() {
        if keep.contains(&i) {
            map[i] = Some(kept.len());
            kept.push(item);
        }
    }
    if kept.is_empty() {
        if let Some(o) = scene.json.as_object_mut() {
            o.remove(key);
        }
    } else {
        scene.json[key] = Value::Array(kept);
    }
    map
}

fn remap(v: &mut Value, map: &[Option<usize>]) {
    if let Some(i) = v.as_u64().and_then(|i| map.get(i as usize).copied().flatten()) {
        *v = json!(i);
    }
}

fn materials(scene: &mut Scene) -> Vec<Removal> {
    let n = len(scene, "materials");
    let mut keep = BTreeSet::new();
    for r in scene.primitives() {
        let pj = scene.prim_json(r);
        if let Some(m) = pj.get("material").and_then(|m| m.as_u64()) {
            keep.insert(m as usize);
        }
        for mapping in
            pj.pointer("/extensions/KHR_materials_variants/mappings").and_then(|m| m.as_array()).into_iter().flatten()
        {
            if let Some(m) = mapping.get("material").and_then(|m| m.as_u64()) {
                keep.insert(m as usize);
            }
        }
    }
    keep.retain(|&m| m < n);
    let removed: Vec<Removal> = (0..n)
        .filter(|i| !keep.contains(i))
        .map(|i| Removal {
            what: format!("material {i} {} (no primitive uses it)", name_of(scene, "materials", i)),
            bytes: 0,
        })
        .collect();
    if removed.is_empty() {
        return removed;
    }
    let map = compact(scene, "materials", &keep);
    for r in scene.primitives() {
        let pj = prim_mut(scene, r);
        if let Some(m) = pj.get_mut("material") {
            remap(m, &map);
        }
        if let Some(list) = pj.pointer_mut("/extensions/KHR_materials_variants/mappings").and_then(|m| m.as_array_mut())
        {
            for mapping in list {
                if let Some(m) = mapping.get_mut("material") {
                    remap(m, &map);
                }
            }
        }
    }
    removed
}

fn name_of(scene: &Scene, key: &str, i: usize) -> String {
    scene
        .json
        .pointer(&format!("/{key}/{i}/name"))
        .and_then(|n| n.as_str())
        .map(|n| format!("'{n}'"))
        .unwrap_or_default()
}

/// Image sources of a texture, including those of texture extensions.
fn texture_sources(t: &mut Value, f: &mut dyn FnMut(&mut Value)) {
    if let Some(s) = t.get_mut("source") {
        f(s);
    }
    for ext in ["KHR_texture_basisu", "EXT_texture_webp", "MSFT_texture_dds"] {
        if let Some(s) = t.pointer_mut(&format!("/extensions/{ext}/source")) {
            f(s);
        }
    }
}

/// Points every texture at the first image with the same bytes; the rest fall out of use.
fn dedupe_images(scene: &mut Scene) -> Result<Vec<Removal>> {
    let n = len(scene, "images");
    let mut first: HashMap<Vec<u8>, usize> = HashMap::new();
    let mut map: Vec<Option<usize>> = (0..n).map(Some).collect();
    let mut out = Vec::new();
    for i in 0..n {
        let Ok(bytes) = scene.image_bytes(i) else { continue };
        match first.get(&bytes) {
            Some(&j) => {
                map[i] = Some(j);
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
        for t in scene.json.get_mut("textures").and_then(|t| t.as_array_mut()).into_iter().flatten() {
            texture_sources(t, &mut |s| remap(s, &map));
        }
    }
    Ok(out)
}

fn textures_images_samplers(scene: &mut Scene) -> Result<Vec<Removal>> {
    let mut out = Vec::new();
    // Textures: what materials read.
    let n = len(scene, "textures");
    let mut keep = BTreeSet::new();
    for m in scene.json.get_mut("materials").and_then(|m| m.as_array_mut()).into_iter().flatten() {
        texture_infos(m, &mut |t| {
            if let Some(i) = t.get("index").and_then(|i| i.as_u64()) {
                keep.insert(i as usize);
            }
        });
    }
    keep.retain(|&t| t < n);
    out.extend(
        (0..n)
            .filter(|i| !keep.contains(i))
            .map(|i| Removal { what: format!("texture {i} (no material reads it)"), bytes: 0 }),
    );
    let map = compact(scene, "textures", &keep);
    for m in scene.json.get_mut("materials").and_then(|m| m.as_array_mut()).into_iter().flatten() {
        texture_infos(m, &mut |t| remap(&mut t["index"], &map));
    }
    // Images: what textures show.
    let n = len(scene, "images");
    let mut keep = BTreeSet::new();
    for t in scene.json.get_mut("textures").and_then(|t| t.as_array_mut()).into_iter().flatten() {
        texture_sources(t, &mut |s| {
            if let Some(i) = s.as_u64() {
                keep.insert(i as usize);
            }
        });
    }
    keep.retain(|&i| i < n);
    for i in (0..n).filter(|i| !keep.contains(i)) {
        if !out.iter().any(|r| r.what.starts_with(&format!("image {i} "))) {
            let bytes = scene.image_bytes(i).map(|b| b.len()).unwrap_or(0);
            out.push(Removal {
                what: format!("image {i} {} (no texture shows it)", name_of(scene, "images", i)),
                bytes,
            });
        }
    }
    let map = compact(scene, "images", &keep);
    for t in scene.json.get_mut("textures").and_then(|t| t.as_array_mut()).into_iter().flatten() {
        texture_sources(t, &mut |s| remap(s, &map));
    }
    // Samplers: what textures use.
    let n = len(scene, "samplers");
    let mut keep = BTreeSet::new();
    for t in scene.json.get("textures").and_then(|t| t.as_array()).into_iter().flatten() {
        if let Some(s) = t.get("sampler").and_then(|s| s.as_u64()) {
            keep.insert(s as usize);
        }
    }
    keep.retain(|&s| s < n);
    out.extend(
        (0..n)
            .filter(|i| !keep.contains(i))
            .map(|i| Removal { what: format!("sampler {i} (no texture uses it)"), bytes: 0 }),
    );
    let map = compact(scene, "samplers", &keep);
    for t in scene.json.get_mut("textures").and_then(|t| t.as_array_mut()).into_iter().flatten() {
        if let Some(s) = t.get_mut("sampler") {
            remap(s, &map);
        }
    }
    Ok(out)
}
