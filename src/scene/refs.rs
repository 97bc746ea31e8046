//! The document's reference graph: every place one glTF object names another by index, the
//! extensions whose references are known, and renumbering a list after some entries go.
//!
//! Compaction (dropping accessors and buffer views), the writer and `bake`'s leave-out all walk
//! the same graph through these functions, so what one of them counts as referenced the others do
//! too. A walker visits each reference (and may rewrite it) and returns the set of indices seen.

use serde_json::{json, Value};
use std::collections::BTreeSet;

/// How far the walkers see into an extension's references.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Reach {
    /// Everything it references is followed (or it references nothing).
    All,
    /// Its accessor and buffer-view references are followed, but it may name materials, textures,
    /// images or samplers in ways the walkers do not read (`KHR_animation_pointer`'s JSON
    /// pointers): those lists must keep their order.
    DataOnly,
}

/// The extensions whose references the walkers know; any other extension in `extensionsUsed`
/// might point at anything, so nothing is dropped or renumbered then.
const KNOWN_EXTENSIONS: &[(&str, Reach)] = &[
    ("KHR_texture_transform", Reach::All),
    ("KHR_lights_punctual", Reach::All),
    ("KHR_materials_anisotropy", Reach::All),
    ("KHR_materials_clearcoat", Reach::All),
    ("KHR_materials_diffuse_transmission", Reach::All),
    ("KHR_materials_dispersion", Reach::All),
    ("KHR_materials_emissive_strength", Reach::All),
    ("KHR_materials_ior", Reach::All),
    ("KHR_materials_iridescence", Reach::All),
    ("KHR_materials_pbrSpecularGlossiness", Reach::All),
    ("KHR_materials_sheen", Reach::All),
    ("KHR_materials_specular", Reach::All),
    ("KHR_materials_transmission", Reach::All),
    ("KHR_materials_unlit", Reach::All),
    ("KHR_materials_variants", Reach::All),
    ("KHR_materials_volume", Reach::All),
    ("KHR_mesh_quantization", Reach::All),
    ("KHR_texture_basisu", Reach::All),
    ("EXT_texture_webp", Reach::All),
    ("EXT_texture_avif", Reach::All),
    ("EXT_mesh_gpu_instancing", Reach::All),
    ("KHR_xmp_json_ld", Reach::All),
    ("KHR_animation_pointer", Reach::DataOnly),
];

/// Texture extensions that name an image as `source`, besides the texture's own `source`.
pub const IMAGE_SOURCE_EXTENSIONS: &[&str] = &["KHR_texture_basisu", "EXT_texture_webp", "EXT_texture_avif"];

fn extensions_used(json: &Value) -> impl Iterator<Item = &str> {
    json.get("extensionsUsed").and_then(|e| e.as_array()).into_iter().flatten().map(|e| e.as_str().unwrap_or(""))
}

/// An extension is in use whose accessor or buffer-view references the walkers do not know.
pub fn unknown_data_refs(json: &Value) -> bool {
    extensions_used(json).any(|e| !KNOWN_EXTENSIONS.iter().any(|(k, _)| *k == e))
}

/// An extension is in use that may name materials, textures, images or samplers in ways the
/// walkers do not follow.
pub fn unknown_object_refs(json: &Value) -> bool {
    extensions_used(json).any(|e| !KNOWN_EXTENSIONS.iter().any(|(k, r)| *k == e && *r == Reach::All))
}

/// A walker: visits every reference of one kind, returns the indices seen.
pub type Walker = fn(&mut Value, &mut dyn FnMut(&mut usize)) -> BTreeSet<usize>;

/// Every accessor reference.
pub fn accessor_refs(json: &mut Value, f: &mut dyn FnMut(&mut usize)) -> BTreeSet<usize> {
    let mut seen = BTreeSet::new();
    let mut visit = |v: &mut Value| visit_index(v, &mut seen, f);
    for mesh in arr_mut(json, "meshes") {
        for p in arr_mut(mesh, "primitives") {
            primitive_accessor_refs(p, &mut visit);
        }
    }
    for skin in arr_mut(json, "skins") {
        if let Some(i) = skin.get_mut("inverseBindMatrices") {
            visit(i);
        }
    }
    for anim in arr_mut(json, "animations") {
        for s in arr_mut(anim, "samplers") {
            for key in ["input", "output"] {
                if let Some(i) = s.get_mut(key) {
                    visit(i);
                }
            }
        }
    }
    for node in arr_mut(json, "nodes") {
        let inst = node.pointer_mut("/extensions/EXT_mesh_gpu_instancing/attributes");
        for a in obj_values_mut(inst) {
            visit(a);
        }
    }
    seen
}

/// The accessor references of one primitive: attributes, indices, morph targets.
pub fn primitive_accessor_refs(p: &mut Value, visit: &mut dyn FnMut(&mut Value)) {
    for a in obj_values_mut(p.get_mut("attributes")) {
        visit(a);
    }
    if let Some(i) = p.get_mut("indices") {
        visit(i);
    }
    for t in arr_mut(p, "targets") {
        for a in obj_values_mut(Some(t)) {
            visit(a);
        }
    }
}

/// Every buffer-view reference.
pub fn view_refs(json: &mut Value, f: &mut dyn FnMut(&mut usize)) -> BTreeSet<usize> {
    let mut seen = BTreeSet::new();
    let mut visit = |v: &mut Value| visit_index(v, &mut seen, f);
    for a in arr_mut(json, "accessors") {
        if let Some(v) = a.get_mut("bufferView") {
            visit(v);
        }
        for p in ["/sparse/indices/bufferView", "/sparse/values/bufferView"] {
            if let Some(v) = a.pointer_mut(p) {
                visit(v);
            }
        }
    }
    for img in arr_mut(json, "images") {
        if let Some(v) = img.get_mut("bufferView") {
            visit(v);
        }
    }
    for mesh in arr_mut(json, "meshes") {
        for p in arr_mut(mesh, "primitives") {
            if let Some(v) = p.pointer_mut("/extensions/KHR_draco_mesh_compression/bufferView") {
                visit(v);
            }
        }
    }
    seen
}

/// Every material reference: each primitive's `material` and its `KHR_materials_variants`
/// mappings.
pub fn material_refs(json: &mut Value, f: &mut dyn FnMut(&mut usize)) -> BTreeSet<usize> {
    let mut seen = BTreeSet::new();
    for mesh in arr_mut(json, "meshes") {
        for p in arr_mut(mesh, "primitives") {
            if let Some(m) = p.get_mut("material") {
                visit_index(m, &mut seen, f);
            }
            let mappings = p.pointer_mut("/extensions/KHR_materials_variants/mappings");
            for mapping in mappings.and_then(|m| m.as_array_mut()).into_iter().flatten() {
                if let Some(m) = mapping.get_mut("material") {
                    visit_index(m, &mut seen, f);
                }
            }
        }
    }
    seen
}

/// Every texture reference: the `index` of every texture-info object of every material (see
/// [`texture_info_pointers`]).
pub fn texture_refs(json: &mut Value, f: &mut dyn FnMut(&mut usize)) -> BTreeSet<usize> {
    let mut seen = BTreeSet::new();
    for m in arr_mut(json, "materials") {
        for p in texture_info_pointers(m) {
            if let Some(i) = m.pointer_mut(&p).and_then(|t| t.get_mut("index")) {
                visit_index(i, &mut seen, f);
            }
        }
    }
    seen
}

/// Where a material's texture-info objects sit, as JSON pointers into the material, in document
/// order: every object under a key ending in `Texture` that has an `index` (`baseColorTexture`,
/// `normalTexture`, and those of material extensions, known or not, at any depth). The one walk
/// over a material's textures: [`crate::scene::Materials`] reads them through it, and
/// [`texture_refs`] follows their references.
pub fn texture_info_pointers(material: &Value) -> Vec<String> {
    fn walk(v: &Value, at: &str, out: &mut Vec<String>) {
        for (k, child) in v.as_object().into_iter().flatten() {
            // RFC 6901 escapes, so that the pointer finds the key again.
            let p = format!("{at}/{}", k.replace('~', "~0").replace('/', "~1"));
            if k.ends_with("Texture") && child.get("index").is_some() {
                out.push(p.clone());
            }
            walk(child, &p, out);
        }
    }
    let mut out = Vec::new();
    walk(material, "", &mut out);
    out
}

/// Every image reference: each texture's `source` and the sources of image-format extensions.
pub fn image_refs(json: &mut Value, f: &mut dyn FnMut(&mut usize)) -> BTreeSet<usize> {
    let mut seen = BTreeSet::new();
    for t in arr_mut(json, "textures") {
        if let Some(s) = t.get_mut("source") {
            visit_index(s, &mut seen, f);
        }
        for ext in IMAGE_SOURCE_EXTENSIONS.iter().chain(&["MSFT_texture_dds"]) {
            if let Some(s) = t.pointer_mut(&format!("/extensions/{ext}/source")) {
                visit_index(s, &mut seen, f);
            }
        }
    }
    seen
}

/// Every sampler reference.
pub fn sampler_refs(json: &mut Value, f: &mut dyn FnMut(&mut usize)) -> BTreeSet<usize> {
    let mut seen = BTreeSet::new();
    for t in arr_mut(json, "textures") {
        if let Some(s) = t.get_mut("sampler") {
            visit_index(s, &mut seen, f);
        }
    }
    seen
}

fn visit_index(v: &mut Value, seen: &mut BTreeSet<usize>, f: &mut dyn FnMut(&mut usize)) {
    if let Some(mut i) = v.as_u64().map(|i| i as usize) {
        seen.insert(i);
        f(&mut i);
        *v = json!(i);
    }
}

/// Keeps the listed entries of `json[key]`; returns old index -> new index.
pub fn renumber(json: &mut Value, key: &str, keep: &BTreeSet<usize>) -> Vec<Option<usize>> {
    let list = json.get(key).and_then(|a| a.as_array()).cloned().unwrap_or_default();
    let mut map = vec![None; list.len().max(keep.iter().next_back().map(|m| m + 1).unwrap_or(0))];
    let mut kept = Vec::new();
    for (i, item) in list.into_iter().enumerate() {
        if keep.contains(&i) {
            map[i] = Some(kept.len());
            kept.push(item);
        }
    }
    if json.get(key).is_some() {
        json[key] = Value::Array(kept);
    }
    map
}

/// A reference to an entry past the end of its list: (index, length of the list).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Dangling(pub usize, pub usize);

/// What [`drop_unreferenced`] did.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Dropped {
    /// The indices (before renumbering) that went.
    pub gone: Vec<usize>,
}

/// Drops the entries of `json[key]` that `refs` does not find (none with `keep_all`) and
/// renumbers the references. Changes nothing when a reference dangles.
pub fn drop_unreferenced(json: &mut Value, key: &str, keep_all: bool, refs: Walker) -> Result<Dropped, Dangling> {
    let n = json.get(key).and_then(|a| a.as_array()).map(|a| a.len()).unwrap_or(0);
    let keep: BTreeSet<usize> = if keep_all { (0..n).collect() } else { refs(json, &mut |_| {}) };
    if let Some(&i) = keep.iter().next_back().filter(|&&i| i >= n) {
        return Err(Dangling(i, n));
    }
    let gone: Vec<usize> = (0..n).filter(|i| !keep.contains(i)).collect();
    if gone.is_empty() {
        return Ok(Dropped { gone });
    }
    let map = renumber(json, key, &keep);
    refs(json, &mut |i| *i = map[*i].expect("kept entry"));
    Ok(Dropped { gone })
}

fn arr_mut<'a>(v: &'a mut Value, key: &str) -> std::slice::IterMut<'a, Value> {
    match v.get_mut(key).and_then(|a| a.as_array_mut()) {
        Some(a) => a.iter_mut(),
        None => [].iter_mut(),
    }
}

fn obj_values_mut(v: Option<&mut Value>) -> Vec<&mut Value> {
    match v.and_then(|v| v.as_object_mut()) {
        Some(o) => o.values_mut().collect(),
        None => Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_table_decides_both_questions() {
        let used = |e: &[&str]| json!({ "extensionsUsed": e });
        assert!(!unknown_data_refs(&used(&["KHR_materials_anisotropy", "EXT_texture_avif"])));
        assert!(!unknown_object_refs(&used(&["KHR_materials_anisotropy", "EXT_texture_avif"])));
        // Animation pointers name materials by JSON pointer: data may go, materials may not move.
        assert!(!unknown_data_refs(&used(&["KHR_animation_pointer"])));
        assert!(unknown_object_refs(&used(&["KHR_animation_pointer"])));
        assert!(unknown_data_refs(&used(&["EXT_someone_elses"])));
        assert!(unknown_object_refs(&used(&["EXT_someone_elses"])));
    }

    #[test]
    fn dropping_materials_renumbers_primitives_and_variant_mappings() {
        let mut j = json!({
            "materials": [{ "name": "a" }, { "name": "unused" }, { "name": "b" }, { "name": "c" }],
            "meshes": [{ "primitives": [{ "material": 2, "extensions": { "KHR_materials_variants": {
                "mappings": [{ "material": 3, "variants": [0] }, { "material": 0, "variants": [1] }] } } }] }],
        });
        let d = drop_unreferenced(&mut j, "materials", false, material_refs).unwrap();
        assert_eq!(d.gone, vec![1]);
        assert_eq!(j["materials"], json!([{ "name": "a" }, { "name": "b" }, { "name": "c" }]));
        let p = &j["meshes"][0]["primitives"][0];
        assert_eq!(p["material"], 1);
        assert_eq!(p.pointer("/extensions/KHR_materials_variants/mappings/0/material").unwrap(), 2);
        assert_eq!(p.pointer("/extensions/KHR_materials_variants/mappings/1/material").unwrap(), 0);
    }

    #[test]
    fn textures_of_every_material_extension_and_image_sources_of_every_format() {
        let mut j = json!({
            "materials": [{ "extensions": {
                "KHR_materials_anisotropy": { "anisotropyTexture": { "index": 3 } },
                "KHR_materials_clearcoat": { "clearcoatNormalTexture": { "index": 1 } } } }],
            "textures": [
                { "source": 0 },
                { "extensions": { "KHR_texture_basisu": { "source": 2 } } },
                { "sampler": 1 },
                { "source": 0, "extensions": { "EXT_texture_webp": { "source": 1 }, "EXT_texture_avif": { "source": 3 } } },
            ],
        });
        assert_eq!(texture_refs(&mut j, &mut |_| {}), BTreeSet::from([1, 3]));
        assert_eq!(image_refs(&mut j, &mut |_| {}), BTreeSet::from([0, 1, 2, 3]));
        assert_eq!(sampler_refs(&mut j, &mut |_| {}), BTreeSet::from([1]));
    }

    #[test]
    fn texture_infos_are_found_at_any_depth_in_document_order() {
        let m = json!({
            "normalTexture": { "index": 0 },
            "occlusionTexture": { "texCoord": 1 },
            "extensions": {
                "EXT_odd/name": { "oddTexture": { "index": 1 }, "nested": { "deepTexture": { "index": 2 } } },
            },
            "pbrMetallicRoughness": { "baseColorTexture": { "index": 3 } },
        });
        let p = texture_info_pointers(&m);
        assert_eq!(
            p,
            [
                "/normalTexture",
                "/extensions/EXT_odd~1name/oddTexture",
                "/extensions/EXT_odd~1name/nested/deepTexture",
                "/pbrMetallicRoughness/baseColorTexture",
            ]
        );
        assert!(p.iter().all(|p| m.pointer(p).is_some()));
    }

    #[test]
    fn a_dangling_reference_changes_nothing() {
        let mut j = json!({ "materials": [{}], "meshes": [{ "primitives": [{ "material": 4 }] }] });
        let before = j.clone();
        assert_eq!(drop_unreferenced(&mut j, "materials", false, material_refs), Err(Dangling(4, 1)));
        assert_eq!(j, before);
    }
}
