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
    /// Triangles drawn (strips and fans counted as the triangles they make); 0 for points and
    /// lines.
    pub triangles: usize,
    /// What the mode draws, counted: `elements` of `element` (`points`, `lines`, `triangles`).
    pub elements: usize,
    pub element: &'static str,
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
    /// Why the primitive's data cannot be read, when it cannot: every command that reads it
    /// refuses the file with this message.
    pub error: Option<String>,
}

/// A primitive as its JSON declares it: counts and formats, without reading any data.
struct Declared {
    vertices: usize,
    index_count: Option<usize>,
    attributes: Vec<AttrInfo>,
    morph_targets: usize,
}

fn declared(scene: &Scene, r: crate::scene::PrimRef) -> Declared {
    let pj = scene.prim_json(r);
    let accessor = |v: &Value| v.as_u64().and_then(|i| scene.array("accessors").get(i as usize));
    let count = |a: &Value| a.get("count").and_then(Value::as_u64).unwrap_or(0) as usize;
    let mut attributes = Vec::new();
    let mut vertices = 0;
    for (name, idx) in pj.get("attributes").and_then(Value::as_object).into_iter().flatten() {
        let Some(a) = accessor(idx) else { continue };
        if name == "POSITION" || attributes.is_empty() {
            vertices = count(a);
        }
        attributes.push(AttrInfo {
            name: name.clone(),
            r#type: a.get("type").and_then(Value::as_str).unwrap_or("").to_string(),
            component_type: a.get("componentType").and_then(Value::as_u64).unwrap_or(0) as u32,
            normalized: a.get("normalized").and_then(Value::as_bool).unwrap_or(false),
        });
    }
    Declared {
        vertices,
        index_count: pj.get("indices").and_then(accessor).map(count),
        attributes,
        morph_targets: pj.get("targets").and_then(Value::as_array).map_or(0, Vec::len),
    }
}

/// How many of what a primitive of `mode` with `n` indices (or vertices) draws.
fn elements(mode: Mode, n: usize) -> (usize, &'static str) {
    match mode.0 {
        0 => (n, "points"),
        1 => (n / 2, "lines"),
        2 if n >= 2 => (n, "lines"),
        2 => (0, "lines"),
        3 => (n.saturating_sub(1), "lines"),
        4 => (n / 3, "triangles"),
        _ => (n.saturating_sub(2), "triangles"),
    }
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
    let scene = crate::format::read(path, opts)?;
    let arr = |k: &str| scene.json.get(k).and_then(|v| v.as_array()).cloned().unwrap_or_default();
    let mats = scene.materials().clone();
    let mut primitives = Vec::new();
    for view in views(&scene, &mats) {
        let r = view.at;
        let d = declared(&scene, r);
        let mode = view.mode;
        let need = needs_tangents(&view, false).map(|()| view.tangent_uvs());
        let by = need.as_ref().ok().and(view.tangent_need.as_ref());
        // Listing reads the JSON; whether the data can be read is the reading rule's answer,
        // the same every other command gets.
        let error = scene.primitive(r).err().map(|e| match e {
            crate::Error::Input { msg, .. } => msg.to_string(),
            other => other.to_string(),
        });
        let (elements, element) = elements(mode, d.index_count.unwrap_or(d.vertices));
        primitives.push(PrimInfo {
            mesh: r.mesh,
            primitive: r.primitive,
            mode: mode.0,
            material: scene.material_index(r),
            vertices: d.vertices,
            triangles: if mode.has_triangles() { elements } else { 0 },
            elements,
            element,
            attributes: d.attributes,
            morph_targets: d.morph_targets,
            has_tangents: view.has("TANGENT"),
            tangents_needed_from: need.as_ref().ok().map(|u| u.attribute()),
            tangents_needed_by: by.map(|n| n.describe()),
            tangent_conflicts: by.map(|n| n.conflicts.clone()).unwrap_or_default(),
            tangents_not_needed: need.err(),
            error,
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
                Err(e) => info.error = Some(e.to_string()),
            }
        }
        Err(e) => info.error = Some(e.to_string()),
    }
    info
}
