//! `inspect`: what a file holds that matters for bump mapping: primitives and their attributes,
//! materials and the textures they use, tangent presence and need, image sizes and bit depths.

use crate::error::Result;
use crate::scene::material::TextureUse;
use crate::scene::view::views;
use crate::scene::{Mode, ReadOptions, Scene, Slot};
use crate::tangent::apply::needs_tangents;
use serde::Serialize;
use serde_json::Value;
use std::path::{Path, PathBuf};

#[derive(Debug, Clone, Serialize)]
pub struct Inspection {
    pub file: PathBuf,
    pub format: &'static str,
    pub generator: Option<String>,
    pub nodes: usize,
    pub meshes: usize,
    pub animations: usize,
    pub skins: usize,
    pub extensions_used: Vec<String>,
    pub primitives: Vec<PrimInfo>,
    pub materials: Vec<MaterialInfo>,
    pub images: Vec<ImageInfo>,
}

#[derive(Debug, Clone, Serialize)]
pub struct PrimInfo {
    pub mesh: usize,
    pub primitive: usize,
    pub mode: u64,
    pub material: Option<usize>,
    pub vertices: usize,
    pub triangles: usize,
    pub attributes: Vec<AttrInfo>,
    pub morph_targets: usize,
    pub has_tangents: bool,
    /// The UV set tangents must come from, or why none are needed.
    pub tangents_needed_from: Option<String>,
    /// What needs them (`normal texture reads TEXCOORD_0`, ...).
    pub tangents_needed_by: Option<String>,
    /// Materials of the primitive (variants) whose textures read other UVs than the tangents follow.
    pub tangent_conflicts: Vec<String>,
    pub tangents_not_needed: Option<String>,
}

#[derive(Debug, Clone, Serialize)]
pub struct AttrInfo {
    pub name: String,
    pub r#type: String,
    pub component_type: u32,
    pub normalized: bool,
}

#[derive(Debug, Clone, Serialize)]
pub struct MaterialInfo {
    pub index: usize,
    pub name: Option<String>,
    pub base_color_image: Option<usize>,
    pub normal_image: Option<usize>,
    pub normal_tex_coord: Option<u32>,
    pub normal_scale: Option<f64>,
    pub height_map: Option<PathBuf>,
    /// What needs tangents in this material, most important first.
    pub tangents_needed_by: Vec<String>,
    /// Every texture the material reads.
    pub textures: Vec<TextureUse>,
}

#[derive(Debug, Clone, Serialize)]
pub struct ImageInfo {
    pub index: usize,
    pub stored: &'static str,
    pub bytes: usize,
    pub format: Option<String>,
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub color: Option<String>,
    pub bits_per_channel: Option<u16>,
    /// How the pixels are stored, for formats with variants (KTX2: `Basis Universal UASTC +
    /// Zstandard`); omitted otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub variant: Option<String>,
    pub error: Option<String>,
}

pub fn inspect(path: &Path, opts: &ReadOptions) -> Result<Inspection> {
    let scene = Scene::read(path, opts)?;
    let arr = |k: &str| scene.json.get(k).and_then(|v| v.as_array()).cloned().unwrap_or_default();
    let mats = scene.materials().clone();
    let mut primitives = Vec::new();
    for view in views(&scene, &mats) {
        let r = view.at;
        let p = scene.declared_primitive(r)?;
        let mode = view.mode;
        let need = needs_tangents(&view, false).map(|()| view.tangent_uvs());
        let by = need.as_ref().ok().and(view.tangent_need.as_ref());
        primitives.push(PrimInfo {
            mesh: r.mesh,
            primitive: r.primitive,
            mode: mode.0,
            material: scene.material_index(r),
            vertices: p.vertex_count(),
            triangles: if mode == Mode::TRIANGLES { p.indices.len() / 3 } else { p.indices.len().saturating_sub(2) },
            attributes: p
                .attributes
                .iter()
                .map(|(n, s)| AttrInfo {
                    name: n.clone(),
                    r#type: s.format.ty.clone(),
                    component_type: s.format.component_type,
                    normalized: s.format.normalized,
                })
                .collect(),
            morph_targets: p.targets.len(),
            has_tangents: p.attr("TANGENT").is_some(),
            tangents_needed_from: need.as_ref().ok().map(|u| u.attribute()),
            tangents_needed_by: by.map(|n| n.describe()),
            tangent_conflicts: by.map(|n| n.conflicts.clone()).unwrap_or_default(),
            tangents_not_needed: need.err(),
        });
    }
    let materials = mats
        .list
        .into_iter()
        .map(|m| {
            let nt = m.texture(Slot::Normal);
            MaterialInfo {
                index: m.index,
                base_color_image: m.texture(Slot::BaseColor).and_then(|t| t.image()),
                normal_image: nt.and_then(|t| t.image()),
                normal_tex_coord: nt.map(|t| t.tex_coord),
                normal_scale: nt.map(|t| t.scale.unwrap_or(1.0)),
                height_map: scene.height_maps.iter().find(|h| h.material == m.index).map(|h| h.path.clone()),
                tangents_needed_by: m
                    .tangent_needs
                    .iter()
                    .map(|n| format!("{} (TEXCOORD_{})", n.describe(), n.tex_coord))
                    .collect(),
                name: m.name,
                textures: m.textures,
            }
        })
        .collect();
    let images = arr("images").iter().enumerate().map(|(i, img)| image_info(&scene, i, img)).collect();
    Ok(Inspection {
        file: path.to_path_buf(),
        format: scene.source_format.name(),
        generator: scene.json.pointer("/asset/generator").and_then(|g| g.as_str()).map(String::from),
        nodes: arr("nodes").len(),
        meshes: arr("meshes").len(),
        animations: arr("animations").len(),
        skins: arr("skins").len(),
        extensions_used: arr("extensionsUsed").iter().filter_map(|e| e.as_str().map(String::from)).collect(),
        primitives,
        materials,
        images,
    })
}

fn image_info(scene: &Scene, i: usize, img: &Value) -> ImageInfo {
    let stored = match img.get("uri").and_then(|u| u.as_str()) {
        Some(u) if u.starts_with("data:") => "data-uri",
        Some(_) => "file",
        None => "buffer",
    };
    let mut info = ImageInfo {
        index: i,
        stored,
        bytes: 0,
        format: None,
        width: None,
        height: None,
        color: None,
        bits_per_channel: None,
        variant: None,
        error: None,
    };
    match scene.image_bytes(i) {
        Ok(bytes) => {
            info.bytes = bytes.len();
            // Only the header is read: a file claiming a huge size costs nothing here.
            let kind = crate::format::image::Kind::sniff(&bytes);
            if kind != crate::format::image::Kind::Unknown {
                info.format = Some(kind.name().to_ascii_lowercase());
            }
            match crate::format::image::header(&bytes) {
                Ok(h) => {
                    info.width = Some(h.width);
                    info.height = Some(h.height);
                    info.color = Some(h.colour.to_string());
                    info.bits_per_channel = Some(h.bits_per_channel);
                    info.variant = h.variant;
                }
                Err(e) => info.error = Some(e),
            }
        }
        Err(e) => info.error = Some(e.to_string()),
    }
    info
}
