//! One typed reading of the document's materials: which textures each reads (from which UV set,
//! through which `KHR_texture_transform`, showing which image, in which colour space) and whether
//! it needs tangents. Every stage asks this instead of reading material JSON, so `tangents`,
//! `bake`, `validate`, `inspect` and `preview` agree on what a material needs.
//!
//! Tangents are needed by `normalTexture`, `KHR_materials_clearcoat`'s `clearcoatNormalTexture`
//! and `KHR_materials_anisotropy` (whose spec requires them even without a texture: the
//! anisotropy direction is given relative to the tangent). A primitive whose
//! `KHR_materials_variants` mappings can switch it to another material needs tangents if any of
//! its possible materials does.

use super::{as_index, PrimRef, Scene};
use serde::Serialize;
use serde_json::{json, Value};

pub use super::uv_transform::UvTransform;

/// How a texture's texels are to be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ColourSpace {
    /// Colour data (base colour, emissive, sheen and specular colour): decode sRGB.
    Srgb,
    /// Data (normals, roughness, occlusion, factors): use as stored.
    Linear,
}

/// Where in a material a texture is read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum Slot {
    BaseColor,
    MetallicRoughness,
    Normal,
    Occlusion,
    Emissive,
    Clearcoat,
    ClearcoatRoughness,
    ClearcoatNormal,
    Sheen,
    SheenRoughness,
    Specular,
    SpecularColor,
    Transmission,
    Thickness,
    Iridescence,
    IridescenceThickness,
    Anisotropy,
    DiffuseTransmission,
    DiffuseTransmissionColor,
    Diffuse,
    SpecularGlossiness,
    /// A `...Texture` object of an extension this table does not list.
    Other,
}

use ColourSpace::{Linear, Srgb};

/// Every texture slot of the core spec and the ratified `KHR_materials_*` extensions (and the
/// archived specular-glossiness one, still common in older files), with the colour space its
/// spec reads it in.
const SLOTS: &[(Slot, &str, ColourSpace)] = &[
    (Slot::BaseColor, "/pbrMetallicRoughness/baseColorTexture", Srgb),
    (Slot::MetallicRoughness, "/pbrMetallicRoughness/metallicRoughnessTexture", Linear),
    (Slot::Normal, "/normalTexture", Linear),
    (Slot::Occlusion, "/occlusionTexture", Linear),
    (Slot::Emissive, "/emissiveTexture", Srgb),
    (Slot::Clearcoat, "/extensions/KHR_materials_clearcoat/clearcoatTexture", Linear),
    (Slot::ClearcoatRoughness, "/extensions/KHR_materials_clearcoat/clearcoatRoughnessTexture", Linear),
    (Slot::ClearcoatNormal, "/extensions/KHR_materials_clearcoat/clearcoatNormalTexture", Linear),
    (Slot::Sheen, "/extensions/KHR_materials_sheen/sheenColorTexture", Srgb),
    (Slot::SheenRoughness, "/extensions/KHR_materials_sheen/sheenRoughnessTexture", Linear),
    (Slot::Specular, "/extensions/KHR_materials_specular/specularTexture", Linear),
    (Slot::SpecularColor, "/extensions/KHR_materials_specular/specularColorTexture", Srgb),
    (Slot::Transmission, "/extensions/KHR_materials_transmission/transmissionTexture", Linear),
    (Slot::Thickness, "/extensions/KHR_materials_volume/thicknessTexture", Linear),
    (Slot::Iridescence, "/extensions/KHR_materials_iridescence/iridescenceTexture", Linear),
    (Slot::IridescenceThickness, "/extensions/KHR_materials_iridescence/iridescenceThicknessTexture", Linear),
    (Slot::Anisotropy, "/extensions/KHR_materials_anisotropy/anisotropyTexture", Linear),
    (Slot::DiffuseTransmission, "/extensions/KHR_materials_diffuse_transmission/diffuseTransmissionTexture", Linear),
    (
        Slot::DiffuseTransmissionColor,
        "/extensions/KHR_materials_diffuse_transmission/diffuseTransmissionColorTexture",
        Srgb,
    ),
    (Slot::Diffuse, "/extensions/KHR_materials_pbrSpecularGlossiness/diffuseTexture", Srgb),
    (Slot::SpecularGlossiness, "/extensions/KHR_materials_pbrSpecularGlossiness/specularGlossinessTexture", Srgb),
];

impl Slot {
    /// The slot's name in words, for reports.
    pub fn describe(self) -> &'static str {
        match self {
            Slot::Normal => "normal texture",
            Slot::ClearcoatNormal => "clearcoat normal texture",
            Slot::Anisotropy => "anisotropy texture",
            Slot::BaseColor => "base colour texture",
            _ => "texture",
        }
    }
}

/// An image a texture shows, and the texture property that names it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct ImageSource {
    pub image: usize,
    /// `source`, or the extension (`KHR_texture_basisu`, `EXT_texture_webp`, `EXT_texture_avif`).
    pub via: &'static str,
}

/// One texture as a material reads it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TextureUse {
    pub slot: Slot,
    /// Where the texture-info object sits in the material, as a JSON pointer.
    pub pointer: String,
    pub texture: usize,
    /// The UV set read: `KHR_texture_transform`'s `texCoord` where given, else `texCoord`, else 0.
    pub tex_coord: u32,
    /// The texture-info's own `texCoord` (else 0): what a client without `KHR_texture_transform`
    /// reads, so leave-out keeps it too. Not in `inspect`'s JSON, whose schema stays as it was.
    #[serde(skip)]
    pub base_tex_coord: u32,
    /// `KHR_texture_transform`, unless it changes nothing.
    pub transform: Option<UvTransform>,
    pub sampler: Option<usize>,
    /// The images the texture names: its plain `source` first (the core formats, PNG or JPEG),
    /// then those of image-format extensions (what a client supporting them shows instead).
    pub images: Vec<ImageSource>,
    pub colour: ColourSpace,
    /// `scale` of a normal texture, `strength` of an occlusion texture.
    pub scale: Option<f64>,
}

impl TextureUse {
    /// The texture's property name in the material (`normalTexture`, `baseColorTexture`, ...).
    pub fn name(&self) -> &str {
        self.pointer.rsplit('/').next().unwrap_or(&self.pointer)
    }

    /// The image to read for this texture: the plain `source`, else the first extension's.
    pub fn image(&self) -> Option<usize> {
        self.images.first().map(|i| i.image)
    }
}

/// Why a material needs tangents, and the UVs they must follow.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TangentNeed {
    /// The slot that needs them (`Normal`, `ClearcoatNormal` or `Anisotropy`).
    pub slot: Slot,
    pub tex_coord: u32,
    /// The transform the renderer applies to those UVs before sampling: tangents follow +u of
    /// the transformed UVs.
    pub transform: Option<UvTransform>,
}

impl TangentNeed {
    pub fn describe(&self) -> &'static str {
        match self.slot {
            Slot::Anisotropy => "KHR_materials_anisotropy",
            s => s.describe(),
        }
    }
    fn same_uvs(&self, o: &TangentNeed) -> bool {
        self.tex_coord == o.tex_coord && self.transform == o.transform
    }
}

/// What one material reads and needs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MaterialInfo {
    pub index: usize,
    pub name: Option<String>,
    /// Every texture it reads, in `SLOTS` order, then any other `...Texture` objects.
    pub textures: Vec<TextureUse>,
    /// Everything that needs tangents, most important first: normal, clearcoat normal, anisotropy.
    pub tangent_needs: Vec<TangentNeed>,
    /// `pbrMetallicRoughness.baseColorFactor`, when it is four numbers.
    pub base_color_factor: Option<[f32; 4]>,
    /// `pbrMetallicRoughness.metallicFactor` and `roughnessFactor`, when they are numbers.
    pub metallic_factor: Option<f32>,
    pub roughness_factor: Option<f32>,
    pub double_sided: bool,
}

impl MaterialInfo {
    pub fn texture(&self, slot: Slot) -> Option<&TextureUse> {
        self.textures.iter().find(|t| t.slot == slot)
    }
    /// The need tangents are made for when the material is drawn alone.
    pub fn tangents(&self) -> Option<&TangentNeed> {
        self.tangent_needs.first()
    }
    /// The material as messages name it: `material 2 ('rock')`, or `material 2` without a name.
    pub fn label(&self) -> String {
        match &self.name {
            Some(n) => format!("material {} ('{n}')", self.index),
            None => format!("material {}", self.index),
        }
    }
}

/// The tangents a primitive needs, over every material it can show.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PrimNeed {
    /// The material whose need decided: the primitive's own, else the lowest-numbered variant's.
    pub material: usize,
    /// True when that material is reached only through a `KHR_materials_variants` mapping.
    pub variant: bool,
    pub need: TangentNeed,
    /// Other needs of its materials that read other UVs (another set or transform): the tangents
    /// cannot follow both, and the report says which lost.
    pub conflicts: Vec<String>,
}

impl PrimNeed {
    /// `normal texture reads TEXCOORD_0`, `clearcoat normal texture of variant material 2 reads ...`.
    pub fn describe(&self) -> String {
        let of = if self.variant { format!(" of variant material {}", self.material) } else { String::new() };
        let tr = if self.need.transform.is_some() { " through KHR_texture_transform" } else { "" };
        let verb = if self.need.slot == Slot::Anisotropy { "needs tangents from" } else { "reads" };
        format!("{}{of} {verb} TEXCOORD_{}{tr}", self.need.describe(), self.need.tex_coord)
    }
}

/// Every material of a scene, read once.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Materials {
    pub list: Vec<MaterialInfo>,
}

impl Materials {
    pub fn get(&self, m: usize) -> Option<&MaterialInfo> {
        self.list.get(m)
    }

    /// The material a primitive shows by default.
    pub fn default_of(&self, scene: &Scene, r: PrimRef) -> Option<&MaterialInfo> {
        scene.material_index(r).and_then(|m| self.get(m))
    }

    /// Every material the primitive can show: its own first, then its variants' in ascending
    /// order (each once). Indices that name no material are left out.
    pub fn of_primitive(&self, scene: &Scene, r: PrimRef) -> Vec<usize> {
        let pj = scene.prim_json(r);
        let own = scene.material_index(r).filter(|&m| m < self.list.len());
        let mut variants: Vec<usize> = pj
            .pointer("/extensions/KHR_materials_variants/mappings")
            .and_then(|m| m.as_array())
            .into_iter()
            .flatten()
            .filter_map(|m| m.get("material").and_then(as_index))
            .filter(|&m| m < self.list.len() && Some(m) != own)
            .collect();
        variants.sort_unstable();
        variants.dedup();
        own.into_iter().chain(variants).collect()
    }

    /// The tangents a primitive needs: from its own material's first need, else from its
    /// lowest-numbered variant material that has one. None when no material it can show needs them.
    pub fn tangent_need(&self, scene: &Scene, r: PrimRef) -> Option<PrimNeed> {
        let own = scene.material_index(r);
        let all = self.of_primitive(scene, r);
        let mut needs = all.iter().flat_map(|&m| self.list[m].tangent_needs.iter().map(move |n| (m, n)));
        let (material, need) = needs.next()?;
        let conflicts = needs
            .filter(|(_, n)| !n.same_uvs(need))
            .map(|(m, n)| {
                format!(
                    "{}'s {} reads {}; the tangents follow {}'s {} ({})",
                    self.list[m].label(),
                    n.describe(),
                    uv_words(n),
                    self.list[material].label(),
                    need.describe(),
                    uv_words(need)
                )
            })
            .collect();
        Some(PrimNeed { material, variant: own != Some(material), need: need.clone(), conflicts })
    }

    /// Every UV set a texture of any material the primitive can show reads.
    pub fn uv_sets(&self, scene: &Scene, r: PrimRef) -> std::collections::BTreeSet<u32> {
        let mut sets = std::collections::BTreeSet::new();
        for m in self.of_primitive(scene, r) {
            sets.extend(self.list[m].textures.iter().map(|t| t.tex_coord));
            sets.extend(self.list[m].tangent_needs.iter().map(|n| n.tex_coord));
        }
        sets
    }

    /// Every texture of the materials the primitive can show, with its material.
    pub fn textures_of(&self, scene: &Scene, r: PrimRef) -> Vec<(&MaterialInfo, &TextureUse)> {
        let mut out = Vec::new();
        for m in self.of_primitive(scene, r) {
            out.extend(self.list[m].textures.iter().map(|t| (&self.list[m], t)));
        }
        out
    }

    /// The textures of [`Self::textures_of`] that read a UV set the primitive does not have:
    /// nothing can place them.
    pub fn missing_uv_sets(&self, scene: &Scene, r: PrimRef) -> Vec<(&MaterialInfo, &TextureUse)> {
        let attrs = scene.prim_json(r).get("attributes").and_then(|a| a.as_object());
        let has = |k: u32| attrs.is_some_and(|a| a.contains_key(&format!("TEXCOORD_{k}")));
        self.textures_of(scene, r).into_iter().filter(|(_, t)| !has(t.tex_coord)).collect()
    }

    /// Each image read as a normal map (normal or clearcoat normal texture), with the materials
    /// and slots reading it, in image order.
    pub fn normal_images(&self) -> std::collections::BTreeMap<usize, Vec<(&MaterialInfo, &TextureUse)>> {
        let mut out: std::collections::BTreeMap<usize, Vec<_>> = Default::default();
        for m in &self.list {
            for t in m.textures.iter().filter(|t| matches!(t.slot, Slot::Normal | Slot::ClearcoatNormal)) {
                if let Some(i) = t.image() {
                    out.entry(i).or_default().push((m, t));
                }
            }
        }
        out
    }
}

fn uv_words(n: &TangentNeed) -> String {
    match n.transform {
        Some(_) => format!("TEXCOORD_{} through KHR_texture_transform", n.tex_coord),
        None => format!("TEXCOORD_{}", n.tex_coord),
    }
}

impl Scene {
    /// Every material, read once and kept until the materials change: the one reading of material
    /// JSON that every stage asks. The methods that change the JSON of materials or textures
    /// (here and in `leave_out.rs`) drop it with `materials_changed`; code outside `scene/`
    /// changes them only through those methods (`tests/materials.rs` holds that). Images are not
    /// part of it: a texture names its images by index, and adding or replacing an image leaves
    /// every index in place.
    pub fn materials(&self) -> &Materials {
        self.material_cache.get_or_init(|| {
            let list = self.array("materials").iter().enumerate().map(|(i, m)| self.material_info(i, m)).collect();
            Materials { list }
        })
    }

    /// The material a primitive names (its `material`), whether or not the document has it.
    pub fn material_index(&self, r: PrimRef) -> Option<usize> {
        self.prim_json(r).get("material").and_then(as_index)
    }

    /// Forgets the materials read, after a change to the JSON of materials or textures.
    pub(crate) fn materials_changed(&mut self) {
        self.material_cache.take();
    }

    fn material_info(&self, index: usize, m: &Value) -> MaterialInfo {
        let infos = super::refs::texture_info_pointers(m);
        let mut textures = Vec::new();
        // The slots of the table in its order, then texture-info objects of extensions it does
        // not list.
        for &(slot, pointer, colour) in SLOTS {
            if infos.iter().any(|p| p == pointer) {
                textures.extend(m.pointer(pointer).and_then(|info| self.texture_use(slot, pointer, colour, info)));
            }
        }
        for pointer in infos.iter().filter(|p| !SLOTS.iter().any(|(_, s, _)| s == p)) {
            textures.extend(m.pointer(pointer).and_then(|info| self.texture_use(Slot::Other, pointer, Linear, info)));
        }
        let mut tangent_needs = Vec::new();
        for slot in [Slot::Normal, Slot::ClearcoatNormal] {
            if let Some(t) = textures.iter().find(|t| t.slot == slot) {
                tangent_needs.push(TangentNeed { slot, tex_coord: t.tex_coord, transform: t.transform });
            }
        }
        if m.pointer("/extensions/KHR_materials_anisotropy").is_some() {
            // Without a texture the direction is still relative to the tangent; set 0 is what a
            // renderer's tangents come from then.
            let (tex_coord, transform) = textures
                .iter()
                .find(|t| t.slot == Slot::Anisotropy)
                .map(|t| (t.tex_coord, t.transform))
                .unwrap_or((0, None));
            tangent_needs.push(TangentNeed { slot: Slot::Anisotropy, tex_coord, transform });
        }
        let base_color_factor = m
            .pointer("/pbrMetallicRoughness/baseColorFactor")
            .and_then(|f| f.as_array())
            .filter(|f| f.len() == 4)
            .map(|f| std::array::from_fn(|k| f[k].as_f64().unwrap_or(1.0) as f32));
        let factor =
            |k: &str| m.pointer(&format!("/pbrMetallicRoughness/{k}")).and_then(|f| f.as_f64()).map(|f| f as f32);
        MaterialInfo {
            index,
            name: m.get("name").and_then(|n| n.as_str()).map(String::from),
            textures,
            tangent_needs,
            base_color_factor,
            metallic_factor: factor("metallicFactor"),
            roughness_factor: factor("roughnessFactor"),
            double_sided: m.get("doubleSided").and_then(|d| d.as_bool()).unwrap_or(false),
        }
    }

    fn texture_use(&self, slot: Slot, pointer: &str, colour: ColourSpace, info: &Value) -> Option<TextureUse> {
        let texture = info.get("index").and_then(as_index)?;
        let base_tex_coord = info.get("texCoord").and_then(|c| c.as_u64()).unwrap_or(0) as u32;
        let over = info.pointer("/extensions/KHR_texture_transform/texCoord").and_then(|c| c.as_u64());
        let tex_coord = over.map_or(base_tex_coord, |c| c as u32);
        let tj = self.array("textures").get(texture);
        // The plain source first (the core formats), then the extensions' in the order a client
        // prefers them.
        let mut images: Vec<ImageSource> = self
            .texture_images(texture)
            .into_iter()
            .map(|t| ImageSource { image: t.image, via: t.extension.unwrap_or("source") })
            .collect();
        images.sort_by_key(|i| i.via != "source");
        let scale_key = if slot == Slot::Occlusion { "strength" } else { "scale" };
        Some(TextureUse {
            slot,
            pointer: pointer.to_string(),
            texture,
            tex_coord,
            base_tex_coord,
            transform: UvTransform::from_texture_info(info),
            sampler: tj.and_then(|t| t.get("sampler")).and_then(as_index),
            images,
            colour,
            scale: info.get(scale_key).and_then(|s| s.as_f64()).filter(|s| s.is_finite()),
        })
    }

    /// A scene without materials gets a plain one (untextured, not metallic, unnamed: the file
    /// never had it), shown by every primitive without a material, so that a map has somewhere
    /// to go. Returns its index, when one was made: a scene without primitives gets none.
    pub fn ensure_material(&mut self) -> Option<usize> {
        let rs = self.primitives();
        if !self.array("materials").is_empty() || rs.is_empty() {
            return None;
        }
        let m = push_plain_material(&mut self.json, None);
        for r in rs {
            if let Some(pj) = self.prim_json_mut(r).and_then(Value::as_object_mut) {
                pj.entry("material").or_insert(json!(m));
            }
        }
        self.materials_changed();
        Some(m)
    }

    /// Gives material `m` texture `texture` as its normal texture (UV set 0), keeping the scale
    /// of the one it replaces.
    pub fn set_normal_texture(&mut self, m: usize, texture: usize) {
        let Some(mat) = self.json.pointer_mut(&format!("/materials/{m}")) else { return };
        let scale = mat.pointer("/normalTexture/scale").cloned();
        let mut info = json!({ "index": texture });
        if let Some(Value::Number(n)) = scale {
            super::set_key(&mut info, "scale", Value::Number(n));
        }
        super::set_key(mat, "normalTexture", info);
        self.materials_changed();
    }

    /// Adds a texture showing `image` through `sampler`; returns its index.
    pub fn push_texture(&mut self, image: usize, sampler: Option<usize>) -> usize {
        let mut tex = json!({ "source": image });
        if let Some(s) = sampler {
            super::set_key(&mut tex, "sampler", json!(s));
        }
        let textures = super::array_mut(&mut self.json, "textures");
        textures.push(tex);
        let t = textures.len() - 1;
        self.materials_changed();
        t
    }

    /// Puts the PNG `png` in place of image `img`, keeping its index and name.
    pub fn replace_image(&mut self, img: usize, png: &[u8]) {
        let name = self.array("images").get(img).and_then(|i| i.get("name")).and_then(|n| n.as_str()).map(String::from);
        let new = self.push_image(png, "image/png", name.as_deref());
        let images = super::array_mut(&mut self.json, "images");
        images.swap(img, new);
        images.pop();
    }

    /// The `wrapS` mode of a sampler (glTF's default, repeat, when there is none).
    pub fn sampler_wrap_s(&self, sampler: Option<usize>) -> u64 {
        sampler
            .and_then(|s| self.array("samplers").get(s))
            .and_then(|s| s.get("wrapS"))
            .and_then(|w| w.as_u64())
            .unwrap_or(10497)
    }

    /// Whether texture `t` exists.
    pub fn has_texture(&self, t: usize) -> bool {
        t < self.array("textures").len()
    }

    /// The sampler JSON of a sampler index.
    pub fn sampler_json(&self, sampler: Option<usize>) -> Option<&Value> {
        sampler.and_then(|s| self.array("samplers").get(s))
    }
}

/// Appends a plain material named `name` to the glTF document `doc` and returns its index:
/// untextured and not metallic (glTF's default metallic factor of 1 looks black without an
/// environment to reflect), for meshes that come without one.
fn push_plain_material(doc: &mut Value, name: Option<&str>) -> usize {
    let mut m = json!({ "pbrMetallicRoughness": { "metallicFactor": 0.0 } });
    if let Some(n) = name {
        super::set_key(&mut m, "name", json!(n));
    }
    let materials = super::array_mut(doc, "materials");
    materials.push(m);
    materials.len() - 1
}

/// Gives `prim`, a primitive's JSON about to join the document `doc`, a new plain material named
/// `name` (for documents built by hand, as `bench transfer`'s LOW).
pub fn give_plain_material(doc: &mut Value, prim: &mut Value, name: &str) {
    let m = push_plain_material(doc, Some(name));
    super::set_key(prim, "material", json!(m));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::ReadOptions;
    use std::path::Path;

    fn scene(mut j: Value) -> Scene {
        crate::scene::shape::pad_references(&mut j);
        crate::format::read_bytes(Path::new("m.gltf"), &serde_json::to_vec(&j).unwrap(), &ReadOptions::default())
            .unwrap()
    }

    #[test]
    fn reads_every_slot_with_overrides_sources_and_colour_spaces() {
        let s = scene(json!({
            "asset": { "version": "2.0" },
            "textures": [
                { "source": 0, "sampler": 0 },
                { "extensions": { "KHR_texture_basisu": { "source": 1 } } },
                { "source": 0, "extensions": { "EXT_texture_webp": { "source": 2 } } },
            ],
            "materials": [
                {
                    "name": "coat",
                    "pbrMetallicRoughness": { "baseColorTexture": { "index": 2 } },
                    "normalTexture": { "index": 0, "texCoord": 1, "scale": 0.5,
                        "extensions": { "KHR_texture_transform": { "texCoord": 2, "rotation": 1.0 } } },
                    "extensions": {
                        "KHR_materials_clearcoat": { "clearcoatNormalTexture": { "index": 1, "texCoord": 1 } },
                        "KHR_materials_sheen": { "sheenColorTexture": { "index": 2 } },
                        "EXT_future": { "futureTexture": { "index": 0 } },
                    },
                },
                { "extensions": { "KHR_materials_anisotropy": { "anisotropyStrength": 0.5 } } },
                { "extensions": { "KHR_materials_clearcoat": { "clearcoatNormalTexture": { "index": 1 } } } },
                { "pbrMetallicRoughness": { "baseColorTexture": { "index": 0 } } },
            ],
        }));
        let m = s.materials();
        let coat = &m.list[0];
        let n = coat.texture(Slot::Normal).unwrap();
        assert_eq!((n.tex_coord, n.scale, n.sampler, n.colour), (2, Some(0.5), Some(0), Linear));
        assert_eq!(n.transform.unwrap().rotation, 1.0);
        let cc = coat.texture(Slot::ClearcoatNormal).unwrap();
        assert_eq!(cc.images, vec![ImageSource { image: 1, via: "KHR_texture_basisu" }]);
        let base = coat.texture(Slot::BaseColor).unwrap();
        assert_eq!(base.colour, Srgb);
        assert_eq!(
            base.images.iter().map(|i| (i.image, i.via)).collect::<Vec<_>>(),
            [(0, "source"), (2, "EXT_texture_webp")]
        );
        assert_eq!(coat.texture(Slot::Sheen).unwrap().colour, Srgb);
        assert_eq!(coat.texture(Slot::Other).unwrap().pointer, "/extensions/EXT_future/futureTexture");
        let slots: Vec<(Slot, u32)> = coat.tangent_needs.iter().map(|n| (n.slot, n.tex_coord)).collect();
        assert_eq!(slots, [(Slot::Normal, 2), (Slot::ClearcoatNormal, 1)]);
        assert_eq!(m.list[1].tangents().map(|n| (n.slot, n.tex_coord)), Some((Slot::Anisotropy, 0)));
        assert_eq!(m.list[2].tangents().map(|n| n.slot), Some(Slot::ClearcoatNormal));
        assert_eq!(m.list[3].tangents(), None);
    }

    #[test]
    fn variants_decide_the_need_deterministically() {
        let s = scene(json!({
            "asset": { "version": "2.0" },
            "textures": [{ "source": 0 }],
            "materials": [
                { "name": "plain" },
                { "normalTexture": { "index": 0, "texCoord": 1 } },
                { "normalTexture": { "index": 0 } },
            ],
            "meshes": [{ "primitives": [
                { "attributes": {}, "material": 0, "extensions": { "KHR_materials_variants": { "mappings": [
                    { "material": 2, "variants": [0] }, { "material": 1, "variants": [1] }, { "material": 2, "variants": [2] }] } } },
                { "attributes": {}, "material": 0 },
            ] }],
        }));
        let m = s.materials();
        let r = PrimRef { mesh: 0, primitive: 0 };
        assert_eq!(m.of_primitive(&s, r), [0, 1, 2]);
        let need = m.tangent_need(&s, r).unwrap();
        assert_eq!((need.material, need.variant, need.need.tex_coord), (1, true, 1));
        assert_eq!(need.conflicts.len(), 1);
        assert!(need.conflicts[0].starts_with("material 2's normal texture reads TEXCOORD_0"), "{:?}", need.conflicts);
        assert_eq!(m.uv_sets(&s, r).into_iter().collect::<Vec<_>>(), [0, 1]);
        assert_eq!(m.tangent_need(&s, PrimRef { mesh: 0, primitive: 1 }), None);
    }
}
