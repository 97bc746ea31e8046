//! Leaving out what the scene does not need (`bake`'s last step before writing): tangents where no
//! material the primitive can show needs them (see [`super::material`]), UV sets no texture
//! reads, `_BITANGENT` unless asked for, materials, textures, images and samplers nothing
//! references, and images that are the same bytes. Accessors and buffer views that fall out of use
//! are dropped by the writer. Nothing a node, animation, skin, morph target or known extension
//! references is removed; with an unknown extension in use, only the attributes go.

use super::refs::{self, Walker};
use super::{texcoord, PrimRef, Scene};
use crate::error::{Result, Setting, Words};
use std::collections::HashMap;

/// One thing left out, and the bytes it took.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Removal {
    pub what: String,
    pub bytes: usize,
}

impl Scene {
    /// Leaves out what nothing needs; returns what went.
    pub fn leave_out(&mut self, keep_bitangents: bool) -> Result<Vec<Removal>> {
        let unknown = refs::unknown_object_refs(&self.json);
        // An unknown extension may read a UV set by its number: then no set is renumbered.
        let mut removed = if unknown { Vec::new() } else { self.renumber_uv_sets() };
        removed.extend(self.unneeded_attributes(keep_bitangents));
        if !unknown {
            removed.extend(self.unused_materials());
            let duplicates = self.dedupe_images();
            let unused = self.unused_textures_images_samplers(&duplicates);
            removed.extend(duplicates);
            removed.extend(unused);
        }
        Ok(removed)
    }

    /// UV sets no texture reads go even when a later one is read: the read sets are renumbered
    /// from 0, in primitives and in the materials that name them, where every primitive sharing
    /// those materials has every set they name.
    fn renumber_uv_sets(&mut self) -> Vec<Removal> {
        let refs = self.primitives();
        let mats = self.materials();
        let prims: Vec<texcoord::PrimSets> = refs
            .iter()
            .map(|&r| {
                let sets = self
                    .prim_json(r)
                    .get("attributes")
                    .and_then(|a| a.as_object())
                    .into_iter()
                    .flat_map(|a| a.keys())
                    .filter_map(|k| k.strip_prefix("TEXCOORD_")?.parse().ok())
                    .collect();
                texcoord::PrimSets { materials: mats.of_primitive(self, r), sets }
            })
            .collect();
        let named: Vec<_> = mats.list.iter().map(texcoord::named_sets).collect();
        let plan = texcoord::plan(&prims, &named);
        if plan.materials.iter().any(Option::is_some) {
            // The readings of the materials as they were, while their JSON changes.
            let infos = mats.list.clone();
            for (m, map) in plan.materials.iter().enumerate() {
                if let (Some(map), Some(mat)) = (map, self.json.pointer_mut(&format!("/materials/{m}"))) {
                    texcoord::renumber_material(mat, &infos[m], map);
                }
            }
            self.materials_changed();
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
            let Some(pj) = self.prim_json_mut(r) else { continue };
            for (name, idx) in texcoord::renumber_primitive(pj, map) {
                let bytes = self.accessor_bytes(idx);
                out.push(Removal { what: format!("mesh {} primitive {}: {name} ({why})", r.mesh, r.primitive), bytes });
            }
        }
        out
    }

    fn accessor_bytes(&self, idx: Option<u64>) -> usize {
        let Some(a) = idx.and_then(|i| self.json.pointer(&format!("/accessors/{i}"))) else { return 0 };
        let n = a.get("count").and_then(|c| c.as_u64()).unwrap_or(0) as usize;
        let f = super::Format {
            component_type: a.get("componentType").and_then(|c| c.as_u64()).unwrap_or(0) as u32,
            ty: a.get("type").and_then(|t| t.as_str()).unwrap_or("").to_string(),
            normalized: false,
        };
        n * f.elem_size()
    }

    fn unneeded_attributes(&mut self, keep_bitangents: bool) -> Vec<Removal> {
        // Decided for every primitive first: the materials do not change while attributes go.
        let mats = self.materials();
        let mut plan: Vec<(PrimRef, Vec<(String, Words)>)> = Vec::new();
        for r in self.primitives() {
            let needs_tangents = mats.tangent_need(self, r).is_some();
            let max_set = mats.uv_sets(self, r).into_iter().next_back();
            let names =
                self.prim_json(r).get("attributes").and_then(|a| a.as_object()).into_iter().flat_map(|a| a.keys());
            let mut drop = Vec::new();
            for name in names {
                let why = if name == "TANGENT" && !needs_tangents {
                    Some(Words::from("no normal texture, clearcoat normal texture or anisotropy reads it"))
                } else if name == "_BITANGENT" && !keep_bitangents {
                    Some(Words::from("not asked for (").name(Setting::Bitangents).text(")"))
                } else if let Some(k) = name.strip_prefix("TEXCOORD_").and_then(|k| k.parse::<u64>().ok()) {
                    // Only trailing sets go: glTF wants TEXCOORD_0..n without gaps.
                    (max_set.map(|m| k > m as u64).unwrap_or(true)).then(|| Words::from("no texture reads it"))
                } else {
                    None
                };
                if let Some(why) = why {
                    drop.push((name.clone(), why));
                }
            }
            plan.push((r, drop));
        }
        let mut out = Vec::new();
        for (r, drop) in plan {
            for (name, why) in drop {
                let Some(pj) = self.prim_json_mut(r) else { continue };
                let idx = pj
                    .get_mut("attributes")
                    .and_then(serde_json::Value::as_object_mut)
                    .and_then(|a| a.remove(&name))
                    .and_then(|v| v.as_u64());
                let mut target_idx = Vec::new();
                if name == "TANGENT" {
                    for t in pj.get_mut("targets").and_then(|t| t.as_array_mut()).into_iter().flatten() {
                        if let Some(i) = t.as_object_mut().and_then(|o| o.remove("TANGENT")).and_then(|v| v.as_u64()) {
                            target_idx.push(i);
                        }
                    }
                }
                let bytes =
                    self.accessor_bytes(idx) + target_idx.iter().map(|&i| self.accessor_bytes(Some(i))).sum::<usize>();
                out.push(Removal { what: format!("mesh {} primitive {}: {name} ({why})", r.mesh, r.primitive), bytes });
            }
        }
        out
    }

    /// Drops the entries of `json[key]` that `walk` finds no reference to and renumbers the rest;
    /// returns the indices that went. A list left empty goes too. Nothing changes when a
    /// reference dangles (the file is broken there; the writer names it).
    fn drop_unused(&mut self, key: &str, walk: Walker) -> Vec<usize> {
        let Ok(d) = refs::drop_unreferenced(&mut self.json, key, false, walk) else { return Vec::new() };
        if self.array(key).is_empty() {
            if let Some(o) = self.json.as_object_mut() {
                o.remove(key);
            }
        }
        if !d.gone.is_empty() {
            self.materials_changed();
        }
        d.gone
    }

    fn unused_materials(&mut self) -> Vec<Removal> {
        let names: Vec<String> = self.materials().list.iter().map(|m| quoted(m.name.as_deref())).collect();
        self.drop_unused("materials", refs::material_refs)
            .into_iter()
            .map(|i| Removal { what: format!("material {i} {} (no primitive uses it)", names[i]), bytes: 0 })
            .collect()
    }

    fn image_name(&self, i: usize) -> String {
        quoted(self.array("images").get(i).and_then(|img| img.get("name")).and_then(|n| n.as_str()))
    }

    /// Points every texture at the first image with the same bytes; the rest fall out of use.
    fn dedupe_images(&mut self) -> Vec<Removal> {
        let n = self.array("images").len();
        let mut first: HashMap<Vec<u8>, usize> = HashMap::new();
        let mut map: Vec<Option<usize>> = (0..n).map(Some).collect();
        let mut out = Vec::new();
        for (i, slot) in map.iter_mut().enumerate() {
            let Ok(bytes) = self.image_bytes(i) else { continue };
            match first.get(&bytes) {
                Some(&j) => {
                    *slot = Some(j);
                    out.push(Removal {
                        what: format!("image {i} {} (same bytes as image {j})", self.image_name(i)),
                        bytes: bytes.len(),
                    });
                }
                None => {
                    first.insert(bytes, i);
                }
            }
        }
        if !out.is_empty() {
            refs::image_refs(&mut self.json, &mut |i| *i = map.get(*i).copied().flatten().unwrap_or(*i));
            self.materials_changed();
        }
        out
    }

    /// `duplicates` are the images [`Self::dedupe_images`] already listed (with their bytes): each
    /// item is listed, and its bytes counted, once.
    fn unused_textures_images_samplers(&mut self, duplicates: &[Removal]) -> Vec<Removal> {
        // Textures: what materials read.
        let mut out: Vec<Removal> = self
            .drop_unused("textures", refs::texture_refs)
            .into_iter()
            .map(|i| Removal { what: format!("texture {i} (no material reads it)"), bytes: 0 })
            .collect();
        // Images: what textures show (those deduplicated above are already counted).
        let shown = refs::image_refs(&mut self.json, &mut |_| {});
        let unshown: HashMap<usize, (String, usize)> = (0..self.array("images").len())
            .filter(|i| !shown.contains(i))
            .map(|i| (i, (self.image_name(i), self.image_bytes(i).map(|b| b.len()).unwrap_or(0))))
            .collect();
        for i in self.drop_unused("images", refs::image_refs) {
            let listed = |r: &Removal| r.what.starts_with(&format!("image {i} "));
            if let Some((name, bytes)) = unshown.get(&i).filter(|_| !out.iter().chain(duplicates).any(listed)) {
                out.push(Removal { what: format!("image {i} {name} (no texture shows it)"), bytes: *bytes });
            }
        }
        // Samplers: what textures use.
        out.extend(
            self.drop_unused("samplers", refs::sampler_refs)
                .into_iter()
                .map(|i| Removal { what: format!("sampler {i} (no texture uses it)"), bytes: 0 }),
        );
        out
    }
}

/// A name as the removal list shows it: `'rock'`, or nothing.
fn quoted(name: Option<&str>) -> String {
    name.map(|n| format!("'{n}'")).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use crate::scene::{ReadOptions, Slot};
    use serde_json::json;
    use std::path::Path;

    #[test]
    fn the_materials_read_follow_every_change() {
        // One material reading set 1 only, under an override whose base set is 1 too; set 0 and
        // an unused material and sampler go.
        let doc = json!({
            "asset": { "version": "2.0" },
            "samplers": [{}, {}],
            "images": [{ "uri": "data:image/png;base64,AA==" }],
            "textures": [{ "source": 0, "sampler": 1 }],
            "materials": [
                { "name": "gone" },
                { "normalTexture": { "index": 0, "texCoord": 1,
                    "extensions": { "KHR_texture_transform": { "texCoord": 1, "rotation": 1.0 } } } },
            ],
            "meshes": [{ "primitives": [{ "attributes": { "TEXCOORD_0": 0, "TEXCOORD_1": 0 }, "material": 1 }] }],
            "accessors": [{ "count": 0, "componentType": 5126, "type": "VEC2" }],
        });
        let mut s =
            crate::format::read_bytes(Path::new("m.gltf"), &serde_json::to_vec(&doc).unwrap(), &ReadOptions::default())
                .unwrap();
        let before = s.materials() as *const _;
        assert_eq!(s.materials() as *const _, before, "read once");
        assert_eq!(s.materials().list[1].texture(Slot::Normal).unwrap().tex_coord, 1);
        let removed: Vec<String> = s.leave_out(false).unwrap().into_iter().map(|r| r.what).collect();
        assert_eq!(
            removed,
            [
                "mesh 0 primitive 0: TEXCOORD_0 (no texture reads it; TEXCOORD_1 becomes TEXCOORD_0)",
                "material 0 'gone' (no primitive uses it)",
                "sampler 0 (no texture uses it)",
            ]
        );
        let m = s.materials();
        assert_eq!(m.list.len(), 1);
        let t = m.list[0].texture(Slot::Normal).unwrap();
        assert_eq!((t.tex_coord, t.base_tex_coord, t.sampler), (0, 0, Some(0)));
        assert_eq!(
            s.json.pointer("/materials/0/normalTexture/extensions/KHR_texture_transform/texCoord"),
            Some(&json!(0))
        );
        assert!(s.json.pointer("/materials/0/normalTexture/texCoord").is_none());
    }

    /// An image with the same bytes as another is listed once, its bytes counted once, though it
    /// is both a duplicate and, after deduplication, shown by no texture.
    #[test]
    fn a_duplicate_image_is_listed_and_counted_once() {
        let png = "data:image/png;base64,iVBORw0KGgo=";
        let doc = json!({
            "asset": { "version": "2.0" },
            "images": [{ "uri": png }, { "uri": png }],
            "textures": [{ "source": 0 }, { "source": 1 }],
            "materials": [{ "normalTexture": { "index": 0 }, "occlusionTexture": { "index": 1 } }],
            "meshes": [{ "primitives": [{ "attributes": { "TEXCOORD_0": 0 }, "material": 0 }] }],
            "accessors": [{ "count": 0, "componentType": 5126, "type": "VEC2" }],
        });
        let mut s =
            crate::format::read_bytes(Path::new("m.gltf"), &serde_json::to_vec(&doc).unwrap(), &ReadOptions::default())
                .unwrap();
        let removed = s.leave_out(false).unwrap();
        let images: Vec<_> = removed.iter().filter(|r| r.what.starts_with("image ")).collect();
        assert_eq!(images.len(), 1, "{removed:?}");
        assert_eq!(images[0].bytes, 8);
        assert_eq!(removed.iter().map(|r| r.bytes).sum::<usize>(), 8);
        assert_eq!(s.array("images").len(), 1);
    }
}
