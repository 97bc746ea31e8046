//! The one in-memory model every stage shares.
//!
//! A [`Scene`] is a glTF 2.0 document: its JSON, kept as read so that everything the tool does not
//! touch (nodes, animations, skins, cameras, extensions, extras, names) leaves unchanged, plus the
//! bytes of its buffers. Stages read a mesh primitive into a [`Primitive`] (dense, typed streams),
//! change it, and put it back with [`Scene::set_primitive`]; the writer drops whatever data is no
//! longer referenced. OBJ input is converted into the same model on reading.

pub mod accessor;
pub mod basisu;
pub(crate) mod compact;
pub mod dequant;
pub mod leave_out;
pub mod material;
pub mod nodes;
pub mod normals;
pub mod refs;
pub mod shape;
pub mod texcoord;
pub mod texture_images;
pub mod uv_transform;
pub mod view;
pub mod weld;

pub use accessor::{Format, Stream};
pub use material::{Materials, PrimNeed, Slot, TangentNeed, UvTransform};
pub use normals::{flat_normals, smooth_normals, smooth_vertex_normals};
pub use view::{Geometry, Mode, PrimView, UvSource};

use crate::error::{Error, Result};
use accessor::*;
use serde_json::{json, Value};
use std::path::PathBuf;

/// Options that change how inputs are read.
#[derive(Debug, Clone, Default)]
pub struct ReadOptions {
    /// Permit URIs that reach outside the input's folder.
    pub allow_outside: bool,
    /// How to make normals for OBJ meshes that have none.
    pub obj_normals: NormalMode,
    /// Told how a slow read (a large OBJ) advances, in bytes parsed.
    pub progress: crate::progress::Reporter,
}

#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum NormalMode {
    Flat,
    #[default]
    Smooth,
}

/// The file format a [`Scene`] was read from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SourceFormat {
    Obj,
    Ply,
    Gltf,
    Glb,
}

impl SourceFormat {
    /// The name reports use: `obj`, `ply`, `gltf` or `glb`.
    pub fn name(self) -> &'static str {
        match self {
            SourceFormat::Obj => "obj",
            SourceFormat::Ply => "ply",
            SourceFormat::Gltf => "gltf",
            SourceFormat::Glb => "glb",
        }
    }

    /// Whether the format can store tangents (OBJ and PLY cannot: their renderers always make
    /// their own).
    pub fn stores_tangents(self) -> bool {
        !matches!(self, SourceFormat::Obj | SourceFormat::Ply)
    }
}

/// A glTF document in memory.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The glTF JSON root.
    pub json: Value,
    /// Bytes of `json.buffers`, index for index.
    pub buffers: Vec<Vec<u8>>,
    /// The file this scene was read from.
    pub source: PathBuf,
    /// The folder relative URIs resolve against.
    pub base_dir: PathBuf,
    /// Whether relative URIs may leave `base_dir`.
    pub allow_outside: bool,
    /// The file format the scene was read from, for reports only: every stage sees glTF's
    /// conventions whatever the source (the OBJ reader turns v-up UVs into glTF's v-down at load).
    pub source_format: SourceFormat,
    /// The images were gathered by bumpbake (from an MTL), not authored as glTF: the writer stores
    /// them in the buffer and drops PNG colour-space chunks glTF does not allow.
    pub own_images: bool,
    /// What the reader noticed and the user should hear (e.g. height maps left for `bake`).
    pub notes: Vec<String>,
    /// Files the reader opened besides `source` (external buffers, MTL files).
    pub deps: Vec<PathBuf>,
    /// Height maps named by OBJ `bump`/`map_Bump`, which only `bake` can turn into normal maps.
    pub height_maps: Vec<HeightMapRef>,
    /// What compaction and appending did, for the writer's report.
    pub(crate) ledger: compact::Ledger,
    /// Buffers whose bytes the file does not carry: no `uri`, and not a GLB's binary chunk. glTF
    /// allows them; reading a view into one is an error, only for the command that reads it.
    pub absent_buffers: std::collections::BTreeSet<usize>,
    /// [`Scene::materials`], once read.
    pub(crate) material_cache: std::sync::OnceLock<material::Materials>,
    /// Float accessors the reader decoded from quantized data (Draco) -> the step of the grid
    /// their values lie on, in the accessor's units: what quantization explains, as a normalized
    /// integer's step does.
    pub decoded_steps: std::collections::BTreeMap<usize, f64>,
}

/// A height map a material wants as its bump map.
#[derive(Debug, Clone, PartialEq)]
pub struct HeightMapRef {
    pub material: usize,
    pub path: PathBuf,
    /// The MTL `-bm` multiplier.
    pub multiplier: f32,
}

/// A mesh primitive, dense and decoded: the unit every tangent stage works on.
#[derive(Debug, Clone, PartialEq)]
pub struct Primitive {
    /// Attribute streams in the order the file lists them.
    pub attributes: Vec<(String, Stream)>,
    /// Morph targets, each a list of attribute streams.
    pub targets: Vec<Vec<(String, Stream)>>,
    /// Index list (made explicit for non-indexed primitives).
    pub indices: Vec<u32>,
    /// glTF primitive mode (4 = triangles).
    pub mode: u32,
}

impl Primitive {
    pub fn attr(&self, name: &str) -> Option<&Stream> {
        self.attributes.iter().find(|(n, _)| n == name).map(|(_, s)| s)
    }
    /// Replaces the stream called `name`, or appends it.
    pub fn set_attr(&mut self, name: &str, stream: Stream) {
        match self.attributes.iter_mut().find(|(n, _)| n == name) {
            Some(slot) => slot.1 = stream,
            None => self.attributes.push((name.to_string(), stream)),
        }
    }
    pub fn remove_attr(&mut self, name: &str) -> Option<Stream> {
        let i = self.attributes.iter().position(|(n, _)| n == name)?;
        Some(self.attributes.remove(i).1)
    }
    pub fn vertex_count(&self) -> usize {
        self.attributes.first().map(|(_, s)| s.len()).unwrap_or(0)
    }
    pub fn positions(&self) -> Vec<[f32; 3]> {
        self.attr("POSITION").map(|s| s.to_f32()).unwrap_or_default()
    }
}

/// Strips and fans become lists, so every later stage sees three indices per triangle.
pub fn to_triangle_list(mut p: Primitive) -> Primitive {
    let i = &p.indices;
    let list: Vec<u32> = match p.mode {
        5 => (2..i.len())
            .flat_map(|k| if k % 2 == 0 { [i[k - 2], i[k - 1], i[k]] } else { [i[k - 1], i[k - 2], i[k]] })
            .collect(),
        6 => (2..i.len()).flat_map(|k| [i[0], i[k - 1], i[k]]).collect(),
        _ => {
            let n = i.len() / 3 * 3;
            i[..n].to_vec()
        }
    };
    p.indices = list;
    p.mode = 4;
    p
}

/// Where a primitive sits in the document.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
pub struct PrimRef {
    pub mesh: usize,
    pub primitive: usize,
}

impl Scene {
    /// Adds encoded image bytes (kept in the buffer) as a new image; returns its index.
    pub fn push_image(&mut self, bytes: &[u8], mime: &str, name: Option<&str>) -> usize {
        let s = Stream {
            format: Format { component_type: accessor::UNSIGNED_BYTE, ty: "SCALAR".into(), normalized: false },
            data: bytes.to_vec(),
            template: None,
        };
        // Reuse the accessor path for the bytes, then keep only its buffer view.
        self.push_accessor(&s, None, false);
        let view = array_mut(&mut self.json, "accessors").pop().and_then(|a| a.get("bufferView").cloned());
        let mut img = json!({ "bufferView": view, "mimeType": mime });
        if let Some(n) = name {
            set_key(&mut img, "name", json!(n));
        }
        let images = array_mut(&mut self.json, "images");
        images.push(img);
        images.len() - 1
    }

    /// `len` bytes at `off` of buffer `b`, or why they cannot be read (said of the buffer view
    /// that names them).
    pub fn buffer_range(&self, b: usize, off: usize, len: usize) -> crate::error::Faulty<&[u8]> {
        if self.absent_buffers.contains(&b) {
            return Err(format!("reads buffer {b}, which has no data (no uri, and not a GLB's binary chunk)").into());
        }
        self.buffers
            .get(b)
            .and_then(|buf| buf.get(off..off.checked_add(len)?))
            .ok_or_else(|| format!("(bytes {off}..{}) runs past the end of buffer {b}", off.saturating_add(len)).into())
    }

    /// The image index a texture index shows, if any.
    pub fn texture_image(&self, texture: usize) -> Option<usize> {
        self.array("textures").get(texture)?.get("source").and_then(as_index)
    }

    /// An error about this scene's file.
    pub fn err(&self, msg: impl Into<crate::error::Words>) -> Error {
        Error::input(&self.source, msg)
    }

    pub(crate) fn array(&self, key: &str) -> &[Value] {
        self.json.get(key).and_then(|v| v.as_array()).map(|v| v.as_slice()).unwrap_or(&[])
    }

    /// Every mesh primitive, in document order.
    pub fn primitives(&self) -> Vec<PrimRef> {
        let mut out = Vec::new();
        for (m, mesh) in self.array("meshes").iter().enumerate() {
            let n = mesh.get("primitives").and_then(|p| p.as_array()).map(|p| p.len()).unwrap_or(0);
            out.extend((0..n).map(|p| PrimRef { mesh: m, primitive: p }));
        }
        out
    }

    /// The primitive's JSON (null for a primitive that does not exist).
    pub fn prim_json(&self, r: PrimRef) -> &Value {
        static NONE: Value = Value::Null;
        self.json.pointer(&prim_pointer(r)).unwrap_or(&NONE)
    }

    fn prim_json_mut(&mut self, r: PrimRef) -> Option<&mut Value> {
        self.json.pointer_mut(&prim_pointer(r))
    }

    /// The material JSON of a primitive, if it has one.
    pub fn material_of(&self, r: PrimRef) -> Option<&Value> {
        self.array("materials").get(self.material_index(r)?)
    }

    /// The UV set the primitive's own material's normal texture reads, if it has one: then the
    /// set its tangents follow ([`PrimView::tangent_uvs`]). See [`Scene::materials`] for
    /// everything else a material reads and needs.
    pub fn normal_texcoord(&self, r: PrimRef) -> Option<u32> {
        let view = PrimView::new(self, self.materials(), r);
        let need = view.tangent_need.as_ref().filter(|n| !n.variant && n.need.slot == Slot::Normal);
        need.map(|_| view.tangent_uvs().set)
    }

    /// The transform that the UVs deciding the primitive's tangents go through (the
    /// `KHR_texture_transform` of the texture that needs them), if any: [`PrimView::tangent_uvs`].
    pub fn normal_uv_transform(&self, r: PrimRef) -> Option<UvTransform> {
        PrimView::new(self, self.materials(), r).tangent_uvs().transform
    }

    /// Reads a primitive's streams, indices and morph targets: the data half of the one reading
    /// rule (docs/formats.md), so every command that reads a primitive refuses it with the same
    /// message: accessor and index bounds, equal counts, finite positions and UVs.
    pub fn primitive(&self, r: PrimRef) -> Result<Primitive> {
        let pj = self.prim_json(r);
        let where_ = format!("mesh {} primitive {}", r.mesh, r.primitive);
        let attrs = pj
            .get("attributes")
            .and_then(|a| a.as_object())
            .ok_or_else(|| self.err(format!("{where_}: no attributes")))?;
        let mut attributes = Vec::new();
        for (name, idx) in attrs {
            let idx = as_index(idx)
                .ok_or_else(|| self.err(format!("{where_}: attribute {name} is not an accessor index")))?;
            attributes.push((name.clone(), self.accessor(idx)?));
        }
        let mut targets = Vec::new();
        if let Some(ts) = pj.get("targets").and_then(|t| t.as_array()) {
            for t in ts {
                let mut streams = Vec::new();
                for (name, idx) in t.as_object().into_iter().flatten() {
                    let idx = as_index(idx)
                        .ok_or_else(|| self.err(format!("{where_}: morph target {name} is not an accessor index")))?;
                    streams.push((name.clone(), self.accessor(idx)?));
                }
                targets.push(streams);
            }
        }
        let (first, count) = attributes
            .iter()
            .find(|(n, _)| n == "POSITION")
            .or(attributes.first())
            .map_or(("POSITION", 0), |(n, s)| (n.as_str(), s.len()));
        // Attributes the tangent math reads must be finite: a NaN there would end up in the output.
        for (name, s) in &attributes {
            // Unusable normals are repaired on reading ([`normals::repair_normals`]).
            let used = name == "POSITION" || name.starts_with("TEXCOORD_");
            if used && s.format.component_type == FLOAT {
                let mut bad = None;
                s.for_each_element(|i, v| {
                    if bad.is_none() && !v.iter().all(|x| x.is_finite()) {
                        bad = Some(i);
                    }
                });
                if let Some(bad) = bad {
                    return Err(self.err(format!("{where_}: {name} {bad} is not finite (NaN or infinity)")));
                }
            }
        }
        let named = attributes.iter().map(|(n, s)| (format!("attribute {n}"), s));
        let in_targets = targets
            .iter()
            .enumerate()
            .flat_map(|(t, ss)| ss.iter().map(move |(n, s)| (format!("morph target {t}'s {n}"), s)));
        for (name, s) in named.chain(in_targets) {
            if s.len() != count {
                return Err(self.err(format!("{where_}: {name} has {} elements, {first} has {count}", s.len())));
            }
        }
        let indices = match pj.get("indices") {
            Some(i) => {
                let idx = as_index(i).ok_or_else(|| self.err(format!("{where_}: indices is not an accessor index")))?;
                let s = self.accessor(idx)?;
                if s.format.ty != "SCALAR"
                    || !matches!(s.format.component_type, UNSIGNED_BYTE | UNSIGNED_SHORT | UNSIGNED_INT)
                {
                    return Err(self.err(format!("{where_}: index accessor {idx} is not an unsigned integer scalar")));
                }
                let v = s.to_u32();
                if let Some((k, bad)) = v.iter().enumerate().find(|(_, &x)| x as usize >= count) {
                    return Err(self.err(format!(
                        "{where_}: index {bad} at position {k} is out of range (the primitive has {count} vertices)"
                    )));
                }
                v
            }
            None => (0..count as u32).collect(),
        };
        let mode = Mode::of(pj).0 as u32;
        Ok(Primitive { attributes, targets, indices, mode })
    }

    /// Reads an accessor into a dense stream (sparse substitution applied).
    pub fn accessor(&self, idx: usize) -> Result<Stream> {
        accessor::read_accessor(self, idx)
    }

    /// Puts a primitive back: its streams become new accessors, and the primitive's JSON points
    /// at them. Old accessors are left for the writer to drop.
    pub fn set_primitive(&mut self, r: PrimRef, p: &Primitive) {
        self.put_primitive(r, p.clone());
    }

    /// [`set_primitive`](Self::set_primitive) that moves the streams' bytes into the scene (each
    /// becomes a buffer of its own) instead of copying them.
    pub fn put_primitive(&mut self, r: PrimRef, p: Primitive) {
        let Primitive { attributes, targets, indices, mode } = p;
        let mut index_stream = index_stream(&indices, attributes.first().map(|(_, s)| s.len()).unwrap_or(0));
        drop(indices);
        let has_targets = !targets.is_empty();
        let mut attrs = serde_json::Map::new();
        for (name, s) in attributes {
            let i = self.push_stream(s, Some(34962), name == "POSITION");
            attrs.insert(name, json!(i));
        }
        let mut target_maps = Vec::new();
        for t in targets {
            let mut m = serde_json::Map::new();
            for (name, s) in t {
                let i = self.push_stream(s, Some(34962), name == "POSITION");
                m.insert(name, json!(i));
            }
            target_maps.push(Value::Object(m));
        }
        index_stream.template = match self.ledger.detached.remove(&r) {
            Some(template) => Some(template),
            None => self
                .prim_json(r)
                .get("indices")
                .and_then(as_index)
                .and_then(|i| self.array("accessors").get(i).cloned()),
        };
        let ii = self.push_stream(index_stream, Some(34963), false);
        if let Some(o) = self.prim_json_mut(r).and_then(Value::as_object_mut) {
            o.insert("attributes".into(), Value::Object(attrs));
            o.insert("indices".into(), json!(ii));
            if has_targets {
                o.insert("targets".into(), Value::Array(target_maps));
            }
            if mode == 4 {
                o.remove("mode");
            } else {
                o.insert("mode".into(), json!(mode));
            }
        }
    }

    /// Appends a stream as a new buffer view + accessor; returns the accessor index.
    pub fn push_accessor(&mut self, s: &Stream, target: Option<u32>, min_max: bool) -> usize {
        self.push_stream(s.clone(), target, min_max)
    }

    /// [`push_accessor`](Self::push_accessor) that moves the stream's bytes into a buffer of
    /// their own: no copy, and no growing buffer to reallocate. The writer packs all buffers
    /// into one anyway.
    pub fn push_stream(&mut self, mut s: Stream, target: Option<u32>, min_max: bool) -> usize {
        let count = s.len();
        let bounds = if min_max { s.bounds() } else { None };
        // Vertex attributes of 8- and 16-bit components (quantized data) need 4-byte strides.
        let mut stride = None;
        if target == Some(34962) {
            if let Some((bytes, st)) = s.padded_to_4() {
                stride = Some(st);
                s.data = bytes;
            }
        }
        if self.buffers.is_empty() || self.json.pointer("/buffers/0").is_none() {
            self.buffers.clear();
            set_key(&mut self.json, "buffers", json!([]));
            self.ledger.restart();
        }
        self.ledger.appended(s.data.len(), self.buffers.last().map_or(0, |b| b.len()));
        // byteOffset 0 rather than none: the writer edits the key in place, so the view's keys
        // keep the order they always had in the output.
        let mut view = json!({ "buffer": self.buffers.len(), "byteOffset": 0, "byteLength": s.data.len() });
        if let Some(st) = stride {
            set_key(&mut view, "byteStride", json!(st));
        }
        if let Some(t) = target {
            set_key(&mut view, "target", json!(t));
        }
        let views = array_mut(&mut self.json, "bufferViews");
        views.push(view);
        let vi = views.len() - 1;
        let mut acc = json!({
            "bufferView": vi,
            "componentType": s.format.component_type,
            "count": count,
            "type": s.format.ty,
        });
        if s.format.normalized {
            set_key(&mut acc, "normalized", json!(true));
        }
        if let Some(t) = &s.template {
            for key in ["name", "extras"] {
                if let Some(v) = t.get(key) {
                    set_key(&mut acc, key, v.clone());
                }
            }
        }
        if let Some((lo, hi)) = bounds {
            set_key(&mut acc, "min", lo);
            set_key(&mut acc, "max", hi);
        }
        array_mut(&mut self.json, "buffers").push(json!({ "byteLength": s.data.len() }));
        self.buffers.push(s.data);
        let accs = array_mut(&mut self.json, "accessors");
        accs.push(acc);
        accs.len() - 1
    }
}

/// The smallest index stream glTF allows for `vertex_count` vertices (never 8-bit; 16-bit only
/// below 65535, which is reserved as primitive restart).
fn index_stream(indices: &[u32], vertex_count: usize) -> Stream {
    if vertex_count < 65535 {
        let data = indices.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect();
        Stream {
            format: Format { component_type: UNSIGNED_SHORT, ty: "SCALAR".into(), normalized: false },
            data,
            template: None,
        }
    } else {
        let data = indices.iter().flat_map(|&i| i.to_le_bytes()).collect();
        Stream {
            format: Format { component_type: UNSIGNED_INT, ty: "SCALAR".into(), normalized: false },
            data,
            template: None,
        }
    }
}

pub(crate) fn as_index(v: &Value) -> Option<usize> {
    v.as_u64().map(|i| i as usize)
}

/// The JSON pointer of a primitive.
pub fn prim_pointer(r: PrimRef) -> String {
    format!("/meshes/{}/primitives/{}", r.mesh, r.primitive)
}

/// Sets `key` on a JSON object. The reading rule ([`shape`]) makes every value the writers set a
/// key on an object; anything else is left as it is rather than panicking.
pub fn set_key(v: &mut Value, key: &str, value: Value) {
    if let Some(o) = v.as_object_mut() {
        o.insert(key.to_string(), value);
    }
}

/// The array `root[key]`, made (empty) when it is missing or not an array. A scene's root is
/// always an object (the readers refuse anything else).
pub(crate) fn array_mut<'a>(root: &'a mut Value, key: &str) -> &'a mut Vec<Value> {
    if !root.get(key).is_some_and(Value::is_array) {
        if !root.is_object() {
            *root = json!({});
        }
        set_key(root, key, json!([]));
    }
    match root.get_mut(key) {
        Some(Value::Array(a)) => a,
        _ => unreachable!("an array was just put there"),
    }
}
