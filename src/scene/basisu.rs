//! What shipping textures as KTX2 changes in the document (`textures::encode_ktx2`): a texture's
//! `KHR_texture_basisu` source, the extension's place in `extensionsUsed`/`extensionsRequired`, a
//! material's metallic-roughness texture and factors, and the textures and images that fall out
//! of use. Material and texture JSON is changed here, in the model, so the stage never names a key.

use super::leave_out::Removal;
use super::refs::{self, Walker};
use super::{as_index, set_key, Scene};
use serde_json::{json, Value};
use std::collections::BTreeSet;

/// The extension that carries KTX2 images.
pub const BASISU: &str = "KHR_texture_basisu";

/// A material's metallic-roughness factors (glTF's defaults, 1 and 1, where absent).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PbrFactors {
    pub metallic: f32,
    pub roughness: f32,
}

impl Scene {
    /// `pbrMetallicRoughness`'s factors of material `m`.
    pub fn pbr_factors(&self, m: usize) -> PbrFactors {
        let f = |k: &str| {
            self.json
                .pointer(&format!("/materials/{m}/pbrMetallicRoughness/{k}"))
                .and_then(Value::as_f64)
                .filter(|v| v.is_finite())
                .map_or(1.0, |v| v as f32)
        };
        PbrFactors { metallic: f("metallicFactor"), roughness: f("roughnessFactor") }
    }

    /// Whether material `m` is a specular-glossiness one: its clients read no metallic-roughness.
    pub fn is_specular_glossiness(&self, m: usize) -> bool {
        self.json.pointer(&format!("/materials/{m}/extensions/KHR_materials_pbrSpecularGlossiness")).is_some()
    }

    /// Whether texture `t` is read by any texture-info other than `except` (material, JSON
    /// pointer into it).
    pub fn texture_read_elsewhere(&self, t: usize, except: &[(usize, String)]) -> bool {
        self.array("materials").iter().enumerate().any(|(m, mat)| {
            refs::texture_info_pointers(mat).into_iter().any(|p| {
                let index = mat.pointer(&p).and_then(|i| i.get("index")).and_then(as_index);
                index == Some(t) && !except.iter().any(|(em, ep)| *em == m && *ep == p)
            })
        })
    }

    /// Adds a texture whose image is the KTX2 `ktx2` (through `KHR_texture_basisu`), with
    /// `fallback` as its core `source` when given; returns its index.
    pub fn push_basisu_texture(&mut self, ktx2: usize, fallback: Option<usize>, sampler: Option<usize>) -> usize {
        let mut tex = json!({ "extensions": { BASISU: { "source": ktx2 } } });
        if let Some(f) = fallback {
            set_key(&mut tex, "source", json!(f));
        }
        if let Some(s) = sampler {
            set_key(&mut tex, "sampler", json!(s));
        }
        let textures = super::array_mut(&mut self.json, "textures");
        textures.push(tex);
        let t = textures.len() - 1;
        self.materials_changed();
        t
    }

    /// A copy of texture `t` (its sampler, name and extensions), for a slot that is to change
    /// while the other readers of `t` keep it; returns its index.
    pub fn copy_texture(&mut self, t: usize) -> usize {
        let tex = self.array("textures").get(t).cloned().unwrap_or_else(|| json!({}));
        let textures = super::array_mut(&mut self.json, "textures");
        textures.push(tex);
        let n = textures.len() - 1;
        self.materials_changed();
        n
    }

    /// Makes texture `t` show the KTX2 image `ktx2` through `KHR_texture_basisu`. Other
    /// image-format extensions go (they show the map the KTX2 replaces); the core `source` stays
    /// as the fallback when `keep_source`, else it goes too.
    pub fn set_basisu_source(&mut self, t: usize, ktx2: usize, keep_source: bool) {
        let Some(tex) = self.json.pointer_mut(&format!("/textures/{t}")) else { return };
        if let Some(o) = tex.as_object_mut() {
            if !keep_source {
                o.remove("source");
            }
            let exts = o.entry("extensions").or_insert_with(|| json!({}));
            if let Some(e) = exts.as_object_mut() {
                for other in refs::IMAGE_SOURCE_EXTENSIONS.iter().filter(|&&x| x != BASISU) {
                    e.remove(*other);
                }
            }
            set_key(exts, BASISU, json!({ "source": ktx2 }));
        }
        self.materials_changed();
    }

    /// Points the texture-info at `pointer` in material `m` at texture `t`.
    pub fn set_texture_index(&mut self, m: usize, pointer: &str, t: usize) {
        if let Some(info) = self.json.pointer_mut(&format!("/materials/{m}{pointer}")) {
            set_key(info, "index", json!(t));
            self.materials_changed();
        }
    }

    /// Gives material `m` texture `t` as its metallic-roughness texture, read as the texture-info
    /// at `like` reads (its UV set and `KHR_texture_transform`: the texels correspond), and sets
    /// `roughnessFactor` to 1: the roughness is in the texture now.
    pub fn set_metallic_roughness(&mut self, m: usize, t: usize, like: &str) {
        let Some(mat) = self.json.pointer_mut(&format!("/materials/{m}")) else { return };
        let mut info = json!({ "index": t });
        let read = mat.pointer(like);
        if let Some(c) = read.and_then(|i| i.get("texCoord")).cloned() {
            set_key(&mut info, "texCoord", c);
        }
        if let Some(tt) = read.and_then(|i| i.pointer("/extensions/KHR_texture_transform")).cloned() {
            set_key(&mut info, "extensions", json!({ "KHR_texture_transform": tt }));
        }
        if !mat.get("pbrMetallicRoughness").is_some_and(Value::is_object) {
            set_key(mat, "pbrMetallicRoughness", json!({}));
        }
        if let Some(pbr) = mat.get_mut("pbrMetallicRoughness") {
            set_key(pbr, "metallicRoughnessTexture", info);
            set_key(pbr, "roughnessFactor", json!(1.0));
        }
        self.materials_changed();
    }

    /// Lists `KHR_texture_basisu` in `extensionsUsed`, and in `extensionsRequired` when
    /// `required` (no texture keeps a core fallback).
    pub fn use_basisu(&mut self, required: bool) {
        list_basisu(&mut self.json, required);
    }

    /// Image-format extensions no texture uses any more leave `extensionsUsed` and
    /// `extensionsRequired`.
    pub fn forget_unused_image_extensions(&mut self) {
        let used: BTreeSet<&str> = refs::IMAGE_SOURCE_EXTENSIONS
            .iter()
            .copied()
            .filter(|ext| self.array("textures").iter().any(|t| t.pointer(&format!("/extensions/{ext}")).is_some()))
            .collect();
        for key in ["extensionsUsed", "extensionsRequired"] {
            let Some(list) = self.json.get_mut(key).and_then(Value::as_array_mut) else { continue };
            list.retain(|e| e.as_str().is_none_or(|e| !refs::IMAGE_SOURCE_EXTENSIONS.contains(&e) || used.contains(e)));
            if list.is_empty() {
                if let Some(o) = self.json.as_object_mut() {
                    o.remove(key);
                }
            }
        }
    }

    /// Drops those of `textures`, then of `images`, that nothing references any more (the ones a
    /// change replaced), renumbering the rest; returns what went. Entries the input already
    /// left unused stay, and nothing goes while an extension that may name them in ways the
    /// walkers do not follow is in use.
    pub fn drop_replaced(&mut self, textures: &[usize], images: &[usize]) -> Vec<Removal> {
        if refs::unknown_object_refs(&self.json) {
            return Vec::new();
        }
        let mut out: Vec<Removal> = self
            .drop_if_unreferenced("textures", textures, refs::texture_refs)
            .into_iter()
            .map(|i| Removal { what: format!("texture {i} (replaced by its KTX2)"), bytes: 0 })
            .collect();
        let bytes: Vec<(usize, usize)> =
            images.iter().map(|&i| (i, self.image_bytes(i).map(|b| b.len()).unwrap_or(0))).collect();
        for i in self.drop_if_unreferenced("images", images, refs::image_refs) {
            let b = bytes.iter().find(|(j, _)| *j == i).map_or(0, |(_, b)| *b);
            out.push(Removal { what: format!("image {i} (replaced by its KTX2)"), bytes: b });
        }
        out
    }

    fn drop_if_unreferenced(&mut self, key: &str, candidates: &[usize], walk: Walker) -> Vec<usize> {
        let n = self.array(key).len();
        let seen = walk(&mut self.json, &mut |_| {});
        let gone: BTreeSet<usize> = candidates.iter().copied().filter(|i| *i < n && !seen.contains(i)).collect();
        if gone.is_empty() {
            return Vec::new();
        }
        let keep: BTreeSet<usize> = (0..n).filter(|i| !gone.contains(i)).collect();
        let map = refs::renumber(&mut self.json, key, &keep);
        walk(&mut self.json, &mut |i| *i = map.get(*i).copied().flatten().unwrap_or(*i));
        self.materials_changed();
        gone.into_iter().collect()
    }
}

impl Scene {
    /// Image `i`'s `name`, if it has one.
    pub fn image_label(&self, i: usize) -> Option<String> {
        self.array("images").get(i).and_then(|img| img.get("name")).and_then(Value::as_str).map(String::from)
    }
}

/// [`Scene::use_basisu`] on a document.
fn list_basisu(json: &mut Value, required: bool) {
    let lists: &[&str] = if required { &["extensionsUsed", "extensionsRequired"] } else { &["extensionsUsed"] };
    for key in lists {
        let list = super::array_mut(json, key);
        if !list.iter().any(|e| e.as_str() == Some(BASISU)) {
            list.push(json!(BASISU));
        }
    }
}

/// Every texture whose core `source` is one of the KTX2 images `ktx2` names it through
/// `KHR_texture_basisu` instead, the one place glTF lets a KTX2 image be named; the extension
/// is then used and required (such a texture has no PNG or JPEG source to fall back on).
/// Textures that already carry the extension are left as they are. Returns whether any changed.
pub fn core_ktx2_to_basisu(json: &mut Value, ktx2: &BTreeSet<usize>) -> bool {
    let mut changed = false;
    for t in json.get_mut("textures").and_then(Value::as_array_mut).into_iter().flatten() {
        let Some(src) = t.get("source").and_then(as_index).filter(|i| ktx2.contains(i)) else { continue };
        if t.pointer(&format!("/extensions/{BASISU}")).is_some() {
            continue;
        }
        let Some(o) = t.as_object_mut() else { continue };
        o.remove("source");
        let exts = o.entry("extensions").or_insert_with(|| json!({}));
        set_key(exts, BASISU, json!({ "source": src }));
        changed = true;
    }
    if changed {
        list_basisu(json, true);
    }
    changed
}
