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

impl Inspection {
    pub fn text(&self) -> String {
        let mut s = format!(
            "{} ({}): {} nodes, {} meshes, {} animations, {} skins\n",
            self.file.display(),
            self.format,
            self.nodes,
            self.meshes,
            self.animations,
            self.skins
        );
        if !self.extensions_used.is_empty() {
            s += &format!("  extensions: {}\n", self.extensions_used.join(", "));
        }
        for p in &self.primitives {
            let attrs: Vec<String> = p.attributes.iter().map(|a| format!("{} {}", a.name, a.r#type)).collect();
            s += &format!(
                "  mesh {} primitive {}: {} vertices, {} triangles, material {}\n    attributes: {}\n",
                p.mesh,
                p.primitive,
                p.vertices,
                p.triangles,
                p.material.map(|m| m.to_string()).unwrap_or("-".into()),
                attrs.join(", ")
            );
            let by = |uv: &str| p.tangents_needed_by.clone().unwrap_or_else(|| format!("--all reads {uv}"));
            let t = match (&p.tangents_needed_from, p.has_tangents) {
                (Some(uv), true) => format!("present; needed ({})", by(uv)),
                (Some(uv), false) => format!("MISSING; needed ({})", by(uv)),
                (None, true) => format!("present but unused ({})", p.tangents_not_needed.as_deref().unwrap_or("")),
                (None, false) => format!("none; not needed ({})", p.tangents_not_needed.as_deref().unwrap_or("")),
            };
            s += &format!("    tangents: {t}\n");
            for c in &p.tangent_conflicts {
                s += &format!("    note: {c}\n");
            }
        }
        for m in &self.materials {
            s += &format!("  material {} {}: ", m.index, m.name.as_deref().unwrap_or(""));
            let mut parts = Vec::new();
            if let Some(i) = m.base_color_image {
                parts.push(format!("base colour image {i}"));
            }
            if let Some(i) = m.normal_image {
                parts.push(format!(
                    "normal image {i} (TEXCOORD_{}, scale {})",
                    m.normal_tex_coord.unwrap_or(0),
                    m.normal_scale.unwrap_or(1.0)
                ));
            }
            if let Some(h) = &m.height_map {
                parts.push(format!("height map {}", h.display()));
            }
            for t in m.textures.iter().filter(|t| !matches!(t.slot, Slot::BaseColor | Slot::Normal)) {
                let img = t.image().map(|i| format!("image {i}")).unwrap_or_else(|| "no image".into());
                parts.push(format!("{:?} {img} (TEXCOORD_{})", t.slot, t.tex_coord));
            }
            if !m.tangents_needed_by.is_empty() {
                parts.push(format!("needs tangents: {}", m.tangents_needed_by.join(", ")));
            }
            s += &(if parts.is_empty() { "no textures".to_string() } else { parts.join(", ") } + "\n");
        }
        for i in &self.images {
            match (&i.error, i.width) {
                (None, Some(w)) => {
                    s += &format!(
                        "  image {}: {}x{} {}{} {}-bit {} ({} bytes, {})\n",
                        i.index,
                        w,
                        i.height.unwrap_or(0),
                        i.format.as_deref().unwrap_or("?"),
                        i.variant.as_ref().map(|v| format!(" ({v})")).unwrap_or_default(),
                        i.bits_per_channel.unwrap_or(0),
                        i.color.as_deref().unwrap_or(""),
                        i.bytes,
                        i.stored
                    )
                }
                (Some(e), _) => s += &format!("  image {}: unreadable: {e}\n", i.index),
                _ => s += &format!("  image {}: {} bytes\n", i.index, i.bytes),
            }
        }
        s
    }
}
