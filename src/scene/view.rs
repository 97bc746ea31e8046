//! A renderer's view of a mesh primitive: what every stage reads of one primitive, decided here
//! once so that `tangents`, `validate`, `preview`, `inspect` and `bake --from` cannot disagree.
//!
//! - **Mode**: glTF's `mode`, triangles (4) when absent ([`Mode`]).
//! - **The UVs the tangents follow**, the one rule ([`PrimView::tangent_uvs`]): the UV set a
//!   renderer samples the normal texture with (`normalTexture.texCoord`, overridden by its
//!   `KHR_texture_transform`'s `texCoord`), through that extension's transform. Without a normal
//!   texture, the clearcoat normal texture's, then `KHR_materials_anisotropy`'s; a primitive whose
//!   own material needs no tangents takes its lowest-numbered `KHR_materials_variants` material's
//!   ([`Materials::tangent_need`]); with no need at all, set 0 as stored. docs/conventions.md,
//!   "Tangent frames", is the contract.
//! - **Values as a renderer decodes them** ([`Geometry`]): float positions and UVs, unit float
//!   normals, UVs through the transform of the texture in question. Quantized data
//!   (`KHR_mesh_quantization`) is made float here and nowhere else.
//! - **The w-sign rule** ([`gltf_w`]) and **where the primitive is shown**
//!   ([`PrimView::instances`], from the one node walker [`instances`](super::nodes::instances), whose
//!   [`Instance`] carries the normal matrix and `w` on a mirroring node).
//!
//! The file format a scene came from is not part of the view: every reader hands over glTF's
//! conventions, and `Scene.source_format` exists for reports only.

use super::dequant;
use super::material::{Materials, PrimNeed, TextureUse, UvTransform};
use super::nodes::Instance;
use super::{to_triangle_list, PrimRef, Primitive, Scene, Stream};
use crate::error::Result;
use serde_json::Value;
use std::borrow::Cow;

/// The `w` glTF stores for MikkTSpace's reference sign: its negation. The reference calls a
/// triangle orientation-preserving when its UVs wind counter-clockwise with v up; glTF's UVs run
/// v down, which turns every winding over (docs/conventions.md). The one place this rule lives.
pub fn gltf_w(reference_w: f32) -> f32 {
    -reference_w
}

/// glTF's primitive `mode`, read in one place: absent means 4 (triangles).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Mode(pub u64);

impl Mode {
    pub const TRIANGLES: Mode = Mode(4);

    /// The mode a primitive's JSON declares.
    pub fn of(prim_json: &Value) -> Mode {
        Mode(prim_json.get("mode").and_then(|m| m.as_u64()).unwrap_or(4))
    }

    /// Triangles, a triangle strip or a fan: a surface ([`to_triangle_list`] makes any of them a
    /// list). Points and lines are not.
    pub fn has_triangles(self) -> bool {
        (4..=6).contains(&self.0)
    }
}

impl std::fmt::Display for Mode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

/// A UV set and the `KHR_texture_transform` a renderer puts it through before sampling.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct UvSource {
    pub set: u32,
    pub transform: Option<UvTransform>,
}

impl UvSource {
    /// The UVs a texture is sampled with.
    pub fn of(texture: &TextureUse) -> UvSource {
        UvSource { set: texture.tex_coord, transform: texture.transform }
    }

    /// The attribute holding the set: `TEXCOORD_n`.
    pub fn attribute(&self) -> String {
        format!("TEXCOORD_{}", self.set)
    }
}

/// What a renderer decides about one primitive before reading its bytes.
#[derive(Debug, Clone)]
pub struct PrimView {
    pub at: PrimRef,
    pub mode: Mode,
    /// The material it shows by default: its `material`, when that names one.
    pub material: Option<usize>,
    /// What needs tangents, over every material the primitive can show; `None` when nothing does.
    pub tangent_need: Option<PrimNeed>,
    /// Whether it has POSITION (glTF lets a primitive leave it out; clients draw nothing then).
    pub has_position: bool,
    /// Attribute names it declares.
    attributes: Vec<String>,
}

impl PrimView {
    /// The view of primitive `at`, with `mats` the scene's materials.
    pub fn new(scene: &Scene, mats: &Materials, at: PrimRef) -> PrimView {
        let pj = scene.prim_json(at);
        let attributes: Vec<String> =
            pj.get("attributes").and_then(|a| a.as_object()).map(|a| a.keys().cloned().collect()).unwrap_or_default();
        PrimView {
            at,
            mode: Mode::of(pj),
            material: mats.default_of(scene, at).map(|m| m.index),
            tangent_need: mats.tangent_need(scene, at),
            has_position: attributes.iter().any(|a| a == "POSITION"),
            attributes,
        }
    }

    /// Whether the primitive is a surface something can be drawn or baked from: triangles, a
    /// strip or a fan, with POSITION. The one answer every stage asks for ([`is_surface`]).
    pub fn is_surface(&self) -> bool {
        self.mode.has_triangles() && self.has_position
    }

    /// Whether the primitive declares attribute `name`.
    pub fn has(&self, name: &str) -> bool {
        self.attributes.iter().any(|a| a == name)
    }

    /// The UVs the primitive's tangents follow: those of what needs them, else set 0 as stored
    /// (what `tangents --all` and the preview's frame views use where nothing needs tangents).
    pub fn tangent_uvs(&self) -> UvSource {
        self.tangent_need
            .as_ref()
            .map(|n| UvSource { set: n.need.tex_coord, transform: n.need.transform })
            .unwrap_or_default()
    }

    /// Whether the material the primitive shows by default needs tangents (it decided
    /// [`Self::tangent_need`], not one of its variants).
    pub fn own_material_needs_tangents(&self) -> bool {
        self.tangent_need.as_ref().is_some_and(|n| !n.variant)
    }

    /// The places `all` (from [`instances`](super::nodes::instances)) shows this primitive's mesh, in walk order.
    pub fn instances<'a>(&self, all: &'a [Instance]) -> impl Iterator<Item = &'a Instance> + 'a {
        let mesh = self.at.mesh;
        all.iter().filter(move |i| i.mesh == mesh)
    }

    /// Reads the primitive's data (a triangle list when its mode is a surface), fails on what
    /// cannot be read (the reading rule of [`Scene::primitive`]).
    pub fn read(&self, scene: &Scene) -> Result<Geometry> {
        let p = scene.primitive(self.at)?;
        let mut primitive = if self.mode.has_triangles() { to_triangle_list(p) } else { p };
        let normal_repair = super::normals::repair_normals(&mut primitive);
        Ok(Geometry { primitive, tangent_uvs: self.tangent_uvs(), normal_repair })
    }
}

/// [`PrimView::is_surface`] without the materials a view reads.
pub fn is_surface(scene: &Scene, r: PrimRef) -> bool {
    let pj = scene.prim_json(r);
    Mode::of(pj).has_triangles() && pj.pointer("/attributes/POSITION").is_some()
}

/// The view of every primitive of `scene`, in document order.
pub fn views(scene: &Scene, mats: &Materials) -> Vec<PrimView> {
    scene.primitives().into_iter().map(|r| PrimView::new(scene, mats, r)).collect()
}

/// A primitive's data with the values a renderer decodes from it. Streams stay as stored in
/// [`Geometry::primitive`] (so what the tool does not compute leaves unchanged); the methods give
/// floats.
#[derive(Debug, Clone)]
pub struct Geometry {
    pub primitive: Primitive,
    /// The UVs its tangents follow ([`PrimView::tangent_uvs`]).
    pub tangent_uvs: UvSource,
    /// What reading did to unusable normals ([`super::normals::repair_normals`]).
    pub normal_repair: super::normals::NormalRepair,
}

impl Geometry {
    /// A primitive whose tangents follow `tangent_uvs`.
    pub fn new(primitive: Primitive, tangent_uvs: UvSource) -> Geometry {
        Geometry { primitive, tangent_uvs, normal_repair: Default::default() }
    }

    /// POSITION, borrowed when stored as floats; a point at the origin per vertex without one.
    pub fn positions(&self) -> Cow<'_, [[f32; 3]]> {
        match self.primitive.attr("POSITION") {
            Some(s) => s.as_f32(),
            None => vec![[0.0; 3]; self.primitive.vertex_count()].into(),
        }
    }

    /// NORMAL as a renderer uses it: float normals as stored (the reference MikkTSpace sees them
    /// so), quantized ones brought back to unit length.
    pub fn normals(&self) -> Option<Cow<'_, [[f32; 3]]>> {
        self.primitive.attr("NORMAL").map(dequant::unit_normals)
    }

    /// UV set `uvs.set` as floats, through `uvs.transform`; `None` when the set is missing.
    pub fn uvs(&self, uvs: UvSource) -> Option<Cow<'_, [[f32; 2]]>> {
        let s = self.primitive.attr(&uvs.attribute())?;
        Some(dequant::transformed_uvs(s.as_f32(), uvs.transform.as_ref()))
    }

    /// The UVs `texture` is sampled at.
    pub fn texture_uvs(&self, texture: &TextureUse) -> Option<Cow<'_, [[f32; 2]]>> {
        self.uvs(UvSource::of(texture))
    }

    /// The UVs the tangents follow ([`Self::tangent_uvs`] applied).
    pub fn tangent_uv_values(&self) -> Option<Cow<'_, [[f32; 2]]>> {
        self.uvs(self.tangent_uvs)
    }

    /// The UVs the tangents follow on a morph target's mesh at weight 1: the stored set plus the
    /// target's `delta` of it (none: the stored set), through the transform, as a renderer
    /// morphs and then samples them. Zeros without the set.
    pub fn morphed_tangent_uvs(&self, delta: Option<&Stream>) -> Vec<[f32; 2]> {
        let n = self.primitive.vertex_count();
        let mut uv: Vec<[f32; 2]> =
            self.primitive.attr(&self.tangent_uvs.attribute()).map(|s| s.to_f32()).unwrap_or_else(|| vec![[0.0; 2]; n]);
        if let Some(d) = delta {
            uv.iter_mut().zip(d.to_f32::<2>()).for_each(|(a, b)| *a = [a[0] + b[0], a[1] + b[1]]);
        }
        dequant::transformed_uvs(uv.into(), self.tangent_uvs.transform.as_ref()).into_owned()
    }

    /// TANGENT as floats, as stored (quantized ones decoded, not made unit: whether they are unit
    /// is for `validate` to judge), `w` included.
    pub fn tangents(&self) -> Option<Vec<[f32; 4]>> {
        self.primitive.attr("TANGENT").map(|s| s.to_f32::<4>())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::accessor::{Format, BYTE, UNSIGNED_SHORT};
    use crate::scene::ReadOptions;
    use serde_json::json;
    use std::path::Path;

    fn scene(mut j: Value) -> Scene {
        crate::scene::shape::pad_references(&mut j);
        crate::format::read_bytes(Path::new("m.gltf"), &serde_json::to_vec(&j).unwrap(), &ReadOptions::default())
            .unwrap()
    }

    #[test]
    fn one_rule_picks_the_normal_texture_s_uvs_with_the_transform_override() {
        let s = scene(json!({
            "asset": { "version": "2.0" },
            "accessors": [{ "componentType": 5126, "count": 3, "type": "VEC3" }],
            "textures": [{ "source": 0 }],
            "materials": [
                { "normalTexture": { "index": 0, "texCoord": 0,
                    "extensions": { "KHR_texture_transform": { "texCoord": 1, "scale": [2.0, 2.0] } } },
                  "pbrMetallicRoughness": { "baseColorTexture": { "index": 0 } } },
                { "name": "plain" },
                { "extensions": { "KHR_materials_clearcoat": { "clearcoatNormalTexture": { "index": 0, "texCoord": 1 } } } },
            ],
            "meshes": [{ "primitives": [
                { "attributes": { "POSITION": 0 }, "material": 0, "mode": 5 },
                { "attributes": {}, "material": 1, "mode": 1 },
                { "attributes": {}, "material": 1, "extensions": { "KHR_materials_variants": { "mappings": [
                    { "material": 2, "variants": [0] }] } } },
            ] }],
        }));
        let mats = s.materials();
        let v = views(&s, mats);
        assert_eq!(v[0].tangent_uvs().set, 1);
        assert_eq!(v[0].tangent_uvs().transform.map(|t| t.scale), Some([2.0, 2.0]));
        assert!(v[0].own_material_needs_tangents() && v[0].has_position && v[0].mode.has_triangles());
        let base = mats.get(0).unwrap().texture(crate::scene::Slot::BaseColor).unwrap();
        assert_eq!(UvSource::of(base), UvSource::default());
        // No need: set 0 as stored; a mode other than a surface says so.
        assert_eq!((v[1].tangent_uvs(), v[1].mode, v[1].mode.has_triangles()), (UvSource::default(), Mode(1), false));
        // A variant's clearcoat normal texture decides, but the drawn material needs nothing.
        assert_eq!(v[2].tangent_uvs().set, 1);
        assert!(!v[2].own_material_needs_tangents() && !v[2].has_position);
        assert_eq!(Mode::of(&json!({})), Mode::TRIANGLES);
    }

    #[test]
    fn geometry_decodes_quantized_normals_and_uvs_once() {
        let normals = Stream {
            format: Format { component_type: BYTE, ty: "VEC3".into(), normalized: true },
            data: vec![90, 90, 0, 0, 0, 127],
            template: None,
        };
        let uvs = Stream {
            format: Format { component_type: UNSIGNED_SHORT, ty: "VEC2".into(), normalized: true },
            data: [65535u16, 0, 0, 65535].iter().flat_map(|x| x.to_le_bytes()).collect(),
            template: None,
        };
        let p = Primitive {
            attributes: vec![
                ("POSITION".into(), Stream::from_f32("VEC3", &[[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]])),
                ("NORMAL".into(), normals),
                ("TEXCOORD_0".into(), uvs),
            ],
            targets: Vec::new(),
            indices: vec![0, 1, 0],
            mode: 4,
        };
        let t = UvTransform { offset: [0.5, 0.0], rotation: 0.0, scale: [2.0, 1.0] };
        let g = Geometry::new(p, UvSource { set: 0, transform: Some(t) });
        let n = g.normals().unwrap();
        assert!(((n[0][0] as f64).hypot(n[0][1] as f64) - 1.0).abs() < 1e-6);
        assert_eq!(n[1], [0.0, 0.0, 1.0]);
        assert_eq!(&*g.tangent_uv_values().unwrap(), [[2.5, 0.0], [0.5, 1.0]]);
        assert_eq!(&*g.uvs(UvSource::default()).unwrap(), [[1.0, 0.0], [0.0, 1.0]]);
        assert!(g.uvs(UvSource { set: 1, transform: None }).is_none());
        assert!(matches!(g.positions(), Cow::Borrowed(_)) || g.positions()[1] == [4.0, 5.0, 6.0]);
        assert_eq!(g.tangents(), None);
    }
}
