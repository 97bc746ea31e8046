//! KHR_draco_mesh_compression, decoded right after parsing (after EXT_meshopt_compression, whose
//! views could hold a Draco stream): each compressed primitive's stream is decoded with
//! `draco-core` (pure Rust, `unsafe` forbidden; see docs/dependencies.md for the campaign that
//! chose it), its attributes and faces are written into a new buffer in the types the primitive's
//! accessors declare, the accessors are pointed at them, and the extension leaves the document.
//! Every later stage sees plain accessors, and the writer writes the file uncompressed.

use crate::error::{Error, Result};
use crate::scene::accessor::{component_count, component_size, FLOAT, UNSIGNED_INT, UNSIGNED_SHORT};
use crate::scene::as_index;
use draco_core::normal_compression_utils::OctahedronToolBox;
use draco_core::{
    DataType, DecodeLimits, DecoderBuffer, ErrorKind, GeometryAttributeType, Mesh, MeshDecoder, PointAttribute,
    PointIndex,
};
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::path::Path;

pub const EXT: &str = "KHR_draco_mesh_compression";

const TRIANGLES: u64 = 4;
const POINTS: u64 = 0;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// Float accessors decoded from a quantized Draco attribute -> the step of the grid the
/// quantization left their values on (see [`grid_step`]).
pub type Steps = BTreeMap<usize, f64>;

/// Decodes every Draco-compressed primitive of `json` into a new buffer appended to `buffers`,
/// and removes the extension. Returns the quantization steps of what it decoded, or `None` when
/// there was nothing to decode.
pub fn decode_all(path: &Path, json: &mut Value, buffers: &mut Vec<Vec<u8>>) -> Result<Option<Steps>> {
    let mut prims = Vec::new();
    for (m, mesh) in json.get("meshes").and_then(|m| m.as_array()).into_iter().flatten().enumerate() {
        for (p, prim) in mesh.get("primitives").and_then(|p| p.as_array()).into_iter().flatten().enumerate() {
            if prim.pointer("/extensions/KHR_draco_mesh_compression").is_some() {
                prims.push((m, p));
            }
        }
    }
    if prims.is_empty() {
        return Ok(None);
    }
    let mut out = Out { buffer: buffers.len(), bytes: Vec::new(), written: BTreeMap::new(), steps: Steps::new() };
    for (m, p) in prims {
        let bad = |msg: String| Error::input(path, format!("mesh {m} primitive {p}: {msg}"));
        let at = format!("/meshes/{m}/primitives/{p}");
        let prim = json.pointer(&at).cloned().unwrap_or_default();
        let ext = prim.pointer(&format!("/extensions/{EXT}")).unwrap_or(&Value::Null);
        let stream = stream_bytes(json, buffers, ext).map_err(|e| bad(format!("{EXT}: {e}")))?;
        let mesh = decode_stream(stream, limits(json, &prim))
            .map_err(|e| bad(format!("{EXT} stream could not be decoded ({e})")))?;
        let prim = out.place(json, &prim, &mesh).map_err(|e| bad(format!("{EXT}: {e}")))?;
        if let Some(slot) = json.pointer_mut(&at) {
            *slot = prim;
        }
    }
    if !out.bytes.is_empty() {
        crate::scene::array_mut(json, "buffers").push(json!({ "byteLength": out.bytes.len() }));
        buffers.push(out.bytes);
    }
    for key in ["extensionsUsed", "extensionsRequired"] {
        if let Some(list) = json.get_mut(key).and_then(|l| l.as_array_mut()) {
            list.retain(|e| e.as_str() != Some(EXT));
            if list.is_empty() {
                json.as_object_mut().map(|o| o.remove(key));
            }
        }
    }
    Ok(Some(out.steps))
}

/// Decodes one Draco stream, stopping at `limits`.
pub fn decode_stream(stream: &[u8], limits: DecodeLimits) -> crate::error::Faulty<Mesh> {
    let mut mesh = Mesh::new();
    MeshDecoder::new()
        .decode(&mut DecoderBuffer::new(stream).with_limits(limits), &mut mesh)
        .map_err(|e| match e.kind() {
            ErrorKind::LimitExceeded => format!("it holds more than the accessors declare: {}", e.message()),
            _ => e.to_string(),
        })
        .map_err(|e| e.replace(['\n', '\r'], " "))?;
    Ok(mesh)
}

/// Decodes a stream and reads every value of every attribute and every face as [`decode_all`]
/// does: what the fuzz target and the mutation campaign run. Returns the point and face counts.
pub fn decode_and_read(stream: &[u8]) -> crate::error::Faulty<(usize, usize)> {
    let mesh = decode_stream(stream, DecodeLimits::fuzzing())?;
    let n = mesh.num_points();
    for a in 0..mesh.num_attributes() {
        let attr = mesh.try_attribute(a).map_err(|e| e.to_string())?;
        let comps = attr.num_components() as usize;
        let mut sink = Vec::with_capacity(n * comps * 4);
        for_each_value(attr, n, comps, &mut |v| {
            sink.extend_from_slice(&(v as f32).to_le_bytes());
            Ok(())
        })?;
    }
    faces(&mesh)?;
    Ok((n, mesh.num_faces()))
}

/// The stream may not decode to more than its primitive's accessors declare: a stream that does is
/// refused anyway, and the ceilings let the decoder refuse it before allocating what it claims.
fn limits(json: &Value, prim: &Value) -> DecodeLimits {
    let count = |i: Option<&Value>| {
        i.and_then(as_index).and_then(|i| json.pointer(&format!("/accessors/{i}/count"))).and_then(|c| c.as_u64())
    };
    let attrs = prim.get("attributes").and_then(|a| a.as_object());
    let points = attrs.into_iter().flat_map(|a| a.values()).filter_map(|i| count(Some(i))).max();
    let mut l = DecodeLimits::default();
    if let Some(n) = points {
        l = l.with_max_points(n);
    }
    if let Some(n) = count(prim.get("indices")) {
        l = l.with_max_faces(n / 3);
    }
    l
}

/// The bytes of the stream's buffer view, checked against its buffer.
fn stream_bytes<'a>(json: &Value, buffers: &'a [Vec<u8>], ext: &Value) -> crate::error::Faulty<&'a [u8]> {
    let v = ext.get("bufferView").and_then(as_index).ok_or("no bufferView")?;
    let view = json.pointer(&format!("/bufferViews/{v}")).ok_or(format!("bufferView {v} does not exist"))?;
    let b = view.get("buffer").and_then(as_index).ok_or(format!("bufferView {v} has no buffer"))?;
    let off = view.get("byteOffset").and_then(|o| o.as_u64()).unwrap_or(0) as usize;
    let len = view.get("byteLength").and_then(|o| o.as_u64()).ok_or(format!("bufferView {v} has no byteLength"))?;
    buffers
        .get(b)
        .and_then(|buf| buf.get(off..off.checked_add(len as usize)?))
        .ok_or(format!("bufferView {v} runs past the end of buffer {b}").into())
}

/// The decoded data, accumulated into one new buffer.
struct Out {
    buffer: usize,
    bytes: Vec<u8>,
    /// Accessor already given data by a decoded primitive -> where in `bytes` that data lies.
    written: BTreeMap<usize, std::ops::Range<usize>>,
    steps: Steps,
}

impl Out {
    /// The primitive with its accessors pointed at the decoded data and without the extension.
    fn place(&mut self, json: &mut Value, prim: &Value, mesh: &Mesh) -> crate::error::Faulty<Value> {
        let mut prim = prim.clone();
        let ext = prim.pointer(&format!("/extensions/{EXT}")).cloned().unwrap_or_default();
        let ids = ext.get("attributes").and_then(|a| a.as_object()).ok_or("no attributes")?;
        let n = mesh.num_points();
        for (name, id) in ids {
            let Some(acc) = prim.get("attributes").and_then(|a| a.get(name)) else {
                continue;
            };
            let acc = as_index(acc).ok_or(format!("attribute {name} names no accessor"))?;
            let id = id.as_u64().and_then(|i| u32::try_from(i).ok()).ok_or(format!("attribute {name}: bad id"))?;
            let attr =
                mesh.attribute_by_unique_id(id).ok_or(format!("attribute {name}: the stream has no attribute {id}"))?;
            let (ct, comps, count) = layout(json, acc)?;
            if count != n {
                return Err(
                    format!("the stream decodes {n} points, but accessor {acc} ({name}) declares {count}").into()
                );
            }
            if attr.num_components() as usize != comps {
                return Err(format!(
                    "attribute {name}: the stream has {} components, accessor {acc} declares {comps}",
                    attr.num_components()
                )
                .into());
            }
            let size = component_size(ct).unwrap_or(4);
            // Each element of a vertex attribute starts on a 4-byte boundary (glTF 3.6.2.4).
            let stride = (comps * size).next_multiple_of(4);
            let pad = stride - comps * size;
            let mut data = Vec::with_capacity(n * stride);
            let float = !attr.data_type().is_integral();
            let mut bounds = Bounds::new(comps);
            let mut values = Vec::with_capacity(if float { n * comps } else { 0 });
            for_each_value(attr, n, comps, &mut |v| {
                if float {
                    values.push(v);
                }
                bounds.add(put(&mut data, ct, v, float)?);
                if bounds.at == 0 {
                    data.extend_from_slice(&[0; 3][..pad]);
                }
                Ok(())
            })
            .map_err(|e| format!("attribute {name} (accessor {acc}): {e}"))?;
            let acc = self.assign(json, acc, data, ARRAY_BUFFER, (pad != 0).then_some(stride));
            bounds.replace(json, acc, ct);
            let normal = attr.attribute_type() == GeometryAttributeType::Normal;
            if let Some(step) = grid_step(&values, comps, normal) {
                self.steps.insert(acc, step);
            }
            if let Some(attrs) = prim.get_mut("attributes") {
                crate::scene::set_key(attrs, name, json!(acc));
            }
        }
        let mode = prim.get("mode").and_then(|m| m.as_u64()).unwrap_or(TRIANGLES);
        let faces = faces(mesh)?;
        match mode {
            TRIANGLES => {
                let (acc, ct) = match prim.get("indices") {
                    Some(i) => {
                        let acc = as_index(i).ok_or("indices names no accessor")?;
                        let (ct, comps, count) = layout(json, acc)?;
                        if comps != 1 || !matches!(ct, 5121 | UNSIGNED_SHORT | UNSIGNED_INT) {
                            return Err(format!("indices accessor {acc} is not unsigned integer scalars").into());
                        }
                        if count != faces.len() {
                            return Err(format!(
                                "the stream decodes {} triangles, but indices accessor {acc} declares {count} indices",
                                faces.len() / 3
                            )
                            .into());
                        }
                        (Some(acc), ct)
                    }
                    None if n < 65535 => (None, UNSIGNED_SHORT),
                    None => (None, UNSIGNED_INT),
                };
                let mut data = Vec::with_capacity(faces.len() * component_size(ct).unwrap_or(4));
                let mut bounds = Bounds::new(1);
                for &i in &faces {
                    bounds.add(put(&mut data, ct, i as f64, false).map_err(|e| format!("indices: {e}"))?);
                }
                let acc = match acc {
                    Some(acc) => self.assign(json, acc, data, ELEMENT_ARRAY_BUFFER, None),
                    None => {
                        let accs = crate::scene::array_mut(json, "accessors");
                        accs.push(json!({ "componentType": ct, "count": faces.len(), "type": "SCALAR" }));
                        let acc = accs.len() - 1;
                        self.assign(json, acc, data, ELEMENT_ARRAY_BUFFER, None)
                    }
                };
                bounds.replace(json, acc, ct);
                crate::scene::set_key(&mut prim, "indices", json!(acc));
            }
            POINTS if faces.is_empty() && prim.get("indices").is_none() => {}
            _ => return Err(format!("mode {mode} with {} decoded triangles is not supported", faces.len() / 3).into()),
        }
        let exts = prim.get_mut("extensions").and_then(Value::as_object_mut).ok_or("extensions is not an object")?;
        exts.remove(EXT);
        if exts.is_empty() {
            prim.as_object_mut().map(|o| o.remove("extensions"));
        }
        Ok(prim)
    }

    /// Points accessor `acc` at `data` in a new buffer view, and returns the accessor to use: `acc`,
    /// or a copy of it when an earlier primitive gave `acc` different data (two primitives sharing
    /// an accessor, which only odd files do).
    fn assign(&mut self, json: &mut Value, acc: usize, data: Vec<u8>, target: u32, stride: Option<usize>) -> usize {
        let acc = match self.written.get(&acc) {
            Some(r) if self.bytes[r.clone()] == data[..] => return acc,
            Some(_) => {
                let copy = json.pointer(&format!("/accessors/{acc}")).cloned().unwrap_or_default();
                let accs = crate::scene::array_mut(json, "accessors");
                accs.push(copy);
                accs.len() - 1
            }
            None => acc,
        };
        self.bytes.resize(self.bytes.len().next_multiple_of(4), 0);
        let at = self.bytes.len();
        let mut view = json!({
            "buffer": self.buffer,
            "byteOffset": at,
            "byteLength": data.len(),
            "target": target,
        });
        if let Some(s) = stride {
            crate::scene::set_key(&mut view, "byteStride", json!(s));
        }
        self.bytes.extend_from_slice(&data);
        let views = crate::scene::array_mut(json, "bufferViews");
        views.push(view);
        let v = views.len() - 1;
        if let Some(a) = json.pointer_mut(&format!("/accessors/{acc}")).and_then(Value::as_object_mut) {
            a.insert("bufferView".into(), json!(v));
            a.remove("byteOffset");
        }
        self.written.insert(acc, at..at + data.len());
        acc
    }
}

/// An accessor's componentType, component count and count.
fn layout(json: &Value, acc: usize) -> crate::error::Faulty<(u32, usize, usize)> {
    let a = json.pointer(&format!("/accessors/{acc}")).ok_or(format!("accessor {acc} does not exist"))?;
    let ct = a.get("componentType").and_then(|c| c.as_u64()).unwrap_or(0) as u32;
    let ty = a.get("type").and_then(|t| t.as_str()).unwrap_or("");
    let comps = match component_count(ty) {
        Some(c) if component_size(ct).is_some() && !ty.starts_with("MAT") => c,
        _ => {
            return Err(
                format!("accessor {acc} (componentType {ct}, type '{ty}') cannot hold decoded Draco data").into()
            )
        }
    };
    let count = a.get("count").and_then(|c| c.as_u64()).ok_or(format!("accessor {acc} has no count"))?;
    Ok((ct, comps, count as usize))
}

/// Every component of every point of `attr`, in point order, as a number.
fn for_each_value(
    attr: &PointAttribute,
    points: usize,
    comps: usize,
    f: &mut dyn FnMut(f64) -> crate::error::Faulty<()>,
) -> crate::error::Faulty<()> {
    let dt = attr.data_type();
    let width = dt.byte_length();
    if width == 0 {
        return Err("the stream's attribute has no data type".into());
    }
    let stride = usize::try_from(attr.byte_stride()).map_err(|_| "the stream's attribute has a negative stride")?;
    let data = attr.buffer().data();
    for p in 0..points {
        let value = attr.mapped_index(PointIndex(p as u32)).0 as usize;
        let at = (value < attr.size())
            .then(|| value.checked_mul(stride))
            .flatten()
            .ok_or(format!("point {p} has no value"))?;
        for c in 0..comps {
            let bytes = at
                .checked_add(c * width)
                .and_then(|s| data.get(s..s + width))
                .ok_or(format!("point {p} lies outside the decoded data"))?;
            f(number(dt, bytes))?;
        }
    }
    Ok(())
}

fn number(dt: DataType, b: &[u8]) -> f64 {
    let a = |n: usize| -> [u8; 8] {
        let mut w = [0; 8];
        w[..n].copy_from_slice(&b[..n]);
        w
    };
    match dt {
        DataType::Int8 => b[0] as i8 as f64,
        DataType::Uint8 | DataType::Bool => b[0] as f64,
        DataType::Int16 => i16::from_le_bytes([b[0], b[1]]) as f64,
        DataType::Uint16 => u16::from_le_bytes([b[0], b[1]]) as f64,
        DataType::Int32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        DataType::Uint32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        DataType::Int64 => i64::from_le_bytes(a(8)) as f64,
        DataType::Uint64 => u64::from_le_bytes(a(8)) as f64,
        DataType::Float32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        DataType::Float64 => f64::from_le_bytes(a(8)),
        DataType::Invalid => 0.0,
    }
}

/// Appends `v` as component type `ct` and returns the value stored. Integers are copied only when
/// they fit; floats go only to float accessors (rounding them to integers would invent a
/// quantization the file did not ask for).
fn put(out: &mut Vec<u8>, ct: u32, v: f64, from_float: bool) -> crate::error::Faulty<f64> {
    if ct == FLOAT {
        out.extend_from_slice(&(v as f32).to_le_bytes());
        return Ok(v as f32 as f64);
    }
    if from_float {
        return Err(format!("the stream holds floats, the accessor declares componentType {ct}").into());
    }
    let (lo, hi) = match ct {
        5120 => (i8::MIN as f64, i8::MAX as f64),
        5121 => (0.0, u8::MAX as f64),
        5122 => (i16::MIN as f64, i16::MAX as f64),
        UNSIGNED_SHORT => (0.0, u16::MAX as f64),
        _ => (0.0, u32::MAX as f64),
    };
    if !(lo..=hi).contains(&v) {
        return Err(format!("value {v} does not fit componentType {ct}").into());
    }
    match ct {
        5120 => out.push(v as i8 as u8),
        5121 => out.push(v as u8),
        5122 => out.extend_from_slice(&(v as i16).to_le_bytes()),
        UNSIGNED_SHORT => out.extend_from_slice(&(v as u16).to_le_bytes()),
        _ => out.extend_from_slice(&(v as u32).to_le_bytes()),
    }
    Ok(v)
}

/// Fewer distinct values than this fit coarse grids by chance: such data is judged as floats.
const GRID_MIN_VALUES: usize = 16;

/// The step of the grid Draco's quantization put float values on, found from the values: the
/// decoder does not hand on the bits the stream declares, and the grid is what they imply.
///
/// Draco stores a quantized attribute as integers `q` in `0..=2^b - 1` and decodes
/// `v = min_c + q * range / (2^b - 1)`, with one `range` (the largest extent of any component)
/// and each component's own minimum; the step is the coarsest such grid all values lie on. A
/// normal is stored as a point of a `2^b - 1` grid on the octahedron instead; its step is the
/// per-component step whose angle ([`crate::validate::frames::Quant::vector_angle`]) bounds
/// that grid's: a point off by half a cell in each octahedral coordinate turns by at most
/// `sqrt(6) * 2 / (2^b - 2) * sqrt(3)/2`. `None` for data on no grid (Draco's lossless floats)
/// and for too few values to tell.
pub fn grid_step(values: &[f64], comps: usize, normal: bool) -> Option<f64> {
    let mut distinct: Vec<u64> = values.iter().map(|v| v.to_bits()).collect();
    distinct.sort_unstable();
    distinct.dedup();
    if comps == 0 || distinct.len() < GRID_MIN_VALUES || values.iter().any(|v| !v.is_finite()) {
        return None;
    }
    if normal && comps == 3 {
        return octahedral_bits(values).map(|b| 6f64.sqrt() * 2.0 / ((1u64 << b) - 2) as f64);
    }
    let mut lo = vec![f64::INFINITY; comps];
    let mut hi = vec![f64::NEG_INFINITY; comps];
    for (i, &v) in values.iter().enumerate() {
        lo[i % comps] = lo[i % comps].min(v);
        hi[i % comps] = hi[i % comps].max(v);
    }
    let range = lo.iter().zip(&hi).map(|(l, h)| h - l).fold(0.0, f64::max) as f32;
    // Past 24 bits a step is below a float's own rounding: every value fits, and says nothing.
    (1..=24).find_map(|b| {
        let step = (range / ((1u32 << b) - 1) as f32) as f64;
        let on_grid = |(i, &v): (usize, &f64)| {
            let q = (v - lo[i % comps]) / step;
            // The decoder adds in f32: a few of its ulps off the grid is on it.
            (q - q.round()).abs() * step <= 4.0 * f32::EPSILON as f64 * v.abs().max(lo[i % comps].abs()) + 0.01 * step
        };
        (step > 0.0 && values.iter().enumerate().all(on_grid)).then_some(step)
    })
}

/// The fewest octahedral bits whose grid every (unit) normal in `values` lies on.
fn octahedral_bits(values: &[f64]) -> Option<u32> {
    let normals: Vec<[f32; 3]> = values.chunks_exact(3).map(|n| [n[0] as f32, n[1] as f32, n[2] as f32]).collect();
    (2..=16).find(|&b| {
        let mut tools = OctahedronToolBox::new();
        tools.set_quantization_bits(b as i32);
        normals.iter().all(|n| {
            let (s, t) = tools.float_vector_to_quantized_octahedral_coords(n);
            let back = tools.quantized_octahedral_coords_to_unit_vector(s, t);
            back.iter().zip(n).all(|(a, b)| (a - b).abs() <= 1e-5)
        })
    })
}

/// Per-component bounds of the values written. An accessor's `min` and `max` were computed by the
/// encoder from the data before quantization, which the decoded data can exceed; glTF wants the
/// bounds of the data the file holds.
struct Bounds {
    lo: Vec<f64>,
    hi: Vec<f64>,
    at: usize,
}

impl Bounds {
    fn new(comps: usize) -> Bounds {
        Bounds { lo: vec![f64::INFINITY; comps], hi: vec![f64::NEG_INFINITY; comps], at: 0 }
    }

    fn add(&mut self, v: f64) {
        self.lo[self.at] = self.lo[self.at].min(v);
        self.hi[self.at] = self.hi[self.at].max(v);
        self.at = (self.at + 1) % self.lo.len();
    }

    /// Replaces the bounds accessor `acc` declares, if it declares any.
    fn replace(&self, json: &mut Value, acc: usize, ct: u32) {
        let Some(a) = json.pointer_mut(&format!("/accessors/{acc}")) else { return };
        if (a.get("min").is_none() && a.get("max").is_none()) || self.lo.iter().any(|v| !v.is_finite()) {
            return;
        }
        let list = |v: &[f64]| -> Value {
            if ct == FLOAT {
                json!(v)
            } else {
                json!(v.iter().map(|&x| x as i64).collect::<Vec<_>>())
            }
        };
        crate::scene::set_key(a, "min", list(&self.lo));
        crate::scene::set_key(a, "max", list(&self.hi));
    }
}

/// The faces as a flat index list, each index checked against the point count.
fn faces(mesh: &Mesh) -> crate::error::Faulty<Vec<u32>> {
    let n = mesh.num_points();
    let mut out = Vec::with_capacity(mesh.num_faces() * 3);
    for f in mesh.faces() {
        for p in f {
            if p.0 as usize >= n {
                return Err(format!("a face names point {}, past the {n} points", p.0).into());
            }
            out.push(p.0);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values as Draco's decoder makes them from quantized integers: `min + q * (range / (2^b - 1))` in f32.
    fn quantized(bits: u32, range: f32, min: [f32; 2], n: usize) -> Vec<f64> {
        let step = range / ((1u32 << bits) - 1) as f32;
        let top = (1u32 << bits) - 1;
        let q = |i: usize, k: u32| ((i as u32).wrapping_mul(2_654_435_761u32.wrapping_mul(k)) >> 7) % (top + 1);
        (0..n).flat_map(|i| [min[0] + q(i, 1) as f32 * step, min[1] + q(i, 3) as f32 * step]).map(f64::from).collect()
    }

    #[test]
    fn the_grid_of_quantized_values_is_found_from_the_values() {
        for bits in [8, 12, 14] {
            let mut v = quantized(bits, 2.5, [-1.25, 0.3], 400);
            // The full range is reached on one component, as the encoder's range is its extent.
            v.extend([-1.25, 0.3, 1.25, 0.3]);
            let step = grid_step(&v, 2, false).unwrap_or_else(|| panic!("{bits} bits: no grid"));
            let want = (2.5f32 / ((1u32 << bits) - 1) as f32) as f64;
            assert!((step - want).abs() < want * 1e-4, "{bits} bits: step {step}, want {want}");
        }
        // Floats on no grid, and too few values to tell, are floats.
        let noise: Vec<f64> = (0..300).map(|i| ((i as f64 * 0.754_877_666).fract() * 7.3).sin()).collect();
        let step = grid_step(&noise, 3, false);
        assert!(step.is_none_or(|s| s < 1e-5), "{step:?}");
        assert_eq!(grid_step(&[0.0, 1.0, 0.5, 0.25], 2, false), None);
    }

    #[test]
    fn normals_on_the_octahedral_grid_give_its_bits() {
        let mut tools = OctahedronToolBox::new();
        tools.set_quantization_bits(10);
        let mut v = Vec::new();
        for i in 0..200 {
            let (a, b) = (i as f32 * 0.37, i as f32 * 0.11);
            let n = [a.cos() * b.cos(), a.sin() * b.cos(), b.sin()];
            let (s, t) = tools.float_vector_to_quantized_octahedral_coords(&n);
            v.extend(tools.quantized_octahedral_coords_to_unit_vector(s, t).map(f64::from));
        }
        let step = grid_step(&v, 3, true).unwrap();
        assert!((step - 6f64.sqrt() * 2.0 / 1022.0).abs() < 1e-9, "{step}");
        // The bound covers the grid's real error: every normal within its angle of the input.
        let angle = crate::validate::frames::Quant::vector_angle(step).to_degrees();
        assert!(angle > 0.2 && angle < 0.3, "{angle}°");
    }
}
