//! Reading `.gltf` and `.glb` into a [`Scene`], checking every reference before it is followed.

use super::{draco, meshopt, uri};
use crate::error::{Error, Result};
use crate::scene::{as_index, ReadOptions, Scene, SourceFormat};
use serde_json::Value;
use std::path::Path;

const GLB_JSON: u32 = 0x4E4F534A;
const GLB_BIN: u32 = 0x004E4942;

pub fn read_glb(path: &Path, bytes: &[u8], opts: &ReadOptions) -> Result<Scene> {
    let (json, bin) = parse_glb(path, bytes)?;
    build(path, json, bin.map(|r| bytes[r].to_vec()), SourceFormat::Glb, opts)
}

/// [`read_glb`] on bytes it may keep: the binary chunk becomes the buffer in place, without a
/// second copy of the file in memory.
pub fn read_glb_owned(path: &Path, mut bytes: Vec<u8>, opts: &ReadOptions) -> Result<Scene> {
    let (json, bin) = parse_glb(path, &bytes)?;
    let bin = bin.map(|r| {
        bytes.truncate(r.end);
        bytes.drain(..r.start);
        bytes.shrink_to_fit();
        bytes
    });
    build(path, json, bin, SourceFormat::Glb, opts)
}

/// The JSON and where the binary chunk lies.
fn parse_glb(path: &Path, bytes: &[u8]) -> Result<(Value, Option<std::ops::Range<usize>>)> {
    let bad = |m: String| Error::input(path, m);
    if bytes.len() < 12 {
        return Err(bad(format!("truncated GLB: {} bytes, the header alone needs 12", bytes.len())));
    }
    if &bytes[0..4] != b"glTF" {
        return Err(bad("not a GLB file (wrong magic)".into()));
    }
    let word = |at: usize| u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let version = word(4);
    if version != 2 {
        return Err(bad(format!("GLB container version {version} is not supported (only glTF 2.0)")));
    }
    let total = word(8) as usize;
    if total > bytes.len() {
        return Err(bad(format!("truncated GLB: header says {total} bytes, file has {}", bytes.len())));
    }
    let mut at = 12;
    let mut json_chunk: Option<&[u8]> = None;
    let mut bin: Option<std::ops::Range<usize>> = None;
    while at + 8 <= total {
        let len = word(at) as usize;
        let kind = word(at + 4);
        let start = at + 8;
        let end = start.checked_add(len).filter(|&e| e <= total).ok_or_else(|| {
            bad(format!("truncated GLB: chunk at byte {at} claims {len} bytes past the end of the file"))
        })?;
        match kind {
            GLB_JSON if json_chunk.is_none() => json_chunk = Some(&bytes[start..end]),
            GLB_BIN if bin.is_none() && json_chunk.is_some() => bin = Some(start..end),
            _ => {}
        }
        at = end + (4 - end % 4) % 4;
    }
    let json_bytes = json_chunk.ok_or_else(|| bad("GLB has no JSON chunk".into()))?;
    Ok((parse_json(path, json_bytes)?, bin))
}

pub fn read_gltf(path: &Path, bytes: &[u8], opts: &ReadOptions) -> Result<Scene> {
    let json = parse_json(path, bytes)?;
    build(path, json, None, SourceFormat::Gltf, opts)
}

fn parse_json(path: &Path, bytes: &[u8]) -> Result<Value> {
    let v: Value = serde_json::from_slice(bytes).map_err(|e| Error::input(path, format!("invalid JSON: {e}")))?;
    if !v.is_object() {
        return Err(Error::input(path, "glTF JSON is not an object"));
    }
    let version = v.pointer("/asset/version").and_then(|v| v.as_str());
    match version {
        Some(s) if s.starts_with("2.") => Ok(v),
        Some(s) => Err(Error::input(path, format!("glTF version {s} is not supported (only 2.x)"))),
        None => Err(Error::input(path, "missing asset.version (is this glTF 1.0?)")),
    }
}

fn build(
    path: &Path,
    mut json: Value,
    bin: Option<Vec<u8>>,
    source_format: SourceFormat,
    opts: &ReadOptions,
) -> Result<Scene> {
    crate::scene::shape::check_and_settle(&mut json).map_err(|e| Error::input(path, e.0))?;
    let base_dir = path.parent().map(|p| p.to_path_buf()).unwrap_or_default();
    let mut buffers = Vec::new();
    let mut deps = Vec::new();
    let mut bin = bin;
    let mut absent = std::collections::BTreeSet::new();
    let list = json.get("buffers").and_then(|b| b.as_array()).cloned().unwrap_or_default();
    for (i, b) in list.iter().enumerate() {
        let declared =
            b.get("byteLength")
                .and_then(|l| l.as_u64())
                .ok_or_else(|| Error::input(path, format!("buffer {i} has no byteLength")))? as usize;
        let data = match b.get("uri").and_then(|u| u.as_str()) {
            Some(u) => {
                if let uri::Target::File(p) = uri::resolve(u, &base_dir, path, opts.allow_outside)? {
                    deps.push(p);
                }
                uri::read(u, &base_dir, path, opts.allow_outside)?
            }
            None if i == 0 && bin.is_some() => bin.take().unwrap_or_default(),
            // Room for what EXT_meshopt_compression decodes into it.
            None if meshopt::is_fallback(b) && declared <= 1 << 31 => vec![0; declared],
            None if meshopt::is_fallback(b) => {
                return Err(Error::input(path, format!("buffer {i}: {declared} bytes is absurd for a fallback buffer")))
            }
            None => {
                absent.insert(i);
                Vec::new()
            }
        };
        if absent.contains(&i) {
            buffers.push(data);
            continue;
        }
        if data.len() < declared {
            return Err(Error::input(
                path,
                format!("buffer {i} holds {} bytes, byteLength says {declared}", data.len()),
            ));
        }
        buffers.push(data);
    }
    let mut notes = Vec::new();
    if meshopt::decode_all(path, &mut json, &mut buffers)? {
        notes.push(format!("{}: decoded; the output is written without it (uncompressed)", meshopt::EXT));
    }
    let decoded_steps = draco::decode_all(path, &mut json, &mut buffers)?;
    if decoded_steps.is_some() {
        notes.push(format!("{}: decoded; the output is written without it (uncompressed)", draco::EXT));
    }
    let scene = Scene {
        json,
        buffers,
        source: path.to_path_buf(),
        base_dir,
        allow_outside: opts.allow_outside,
        source_format,
        notes,
        deps,
        height_maps: Vec::new(),
        ledger: Default::default(),
        material_cache: Default::default(),
        absent_buffers: absent,
        own_images: false,
        decoded_steps: decoded_steps.unwrap_or_default(),
    };
    check_views(&scene)?;
    Ok(scene)
}

/// Every buffer view must lie inside its buffer; checked once so accessor reads can trust them.
fn check_views(s: &Scene) -> Result<()> {
    for (i, v) in s.array("bufferViews").iter().enumerate() {
        let b = v.get("buffer").and_then(as_index).ok_or_else(|| s.err(format!("bufferView {i} has no buffer")))?;
        let buf =
            s.buffers.get(b).ok_or_else(|| s.err(format!("bufferView {i} names buffer {b}, which does not exist")))?;
        if s.absent_buffers.contains(&b) {
            continue;
        }
        let off = v.get("byteOffset").and_then(|o| o.as_u64()).unwrap_or(0);
        let len = v
            .get("byteLength")
            .and_then(|o| o.as_u64())
            .ok_or_else(|| s.err(format!("bufferView {i} has no byteLength")))?;
        if off.checked_add(len).map(|e| e > buf.len() as u64).unwrap_or(true) {
            return Err(s.err(format!(
                "bufferView {i} (bytes {off}..{}) runs past the end of buffer {b} ({} bytes)",
                off.saturating_add(len),
                buf.len()
            )));
        }
    }
    Ok(())
}
