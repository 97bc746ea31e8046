//! Every file format bumpbake reads or writes, in a room of its own below the stages.
//!
//! Each reader hands over the same [`Scene`] (glTF JSON + buffers, OBJ converted on reading) and
//! the image reader the same decoded image, so no stage learns where a mesh or a texture came
//! from. Compression (meshopt, Draco) is decoded right after parsing, as gltfpack's `parsegltf.cpp`
//! does for meshopt.

pub mod dequant;
pub mod draco;
mod gltf_read;
mod gltf_write;
pub mod image;
pub mod ktx2;
mod meshopt;
mod obj;
mod obj_block;
mod obj_fast;
pub mod obj_parse;
pub mod ply;
mod ply_ascii;
mod ply_binary;
pub mod raw;
pub mod uri;

pub use gltf_write::{write, WriteOptions, WriteStats};

use crate::error::{Error, Result};
use crate::scene::{as_index, ReadOptions, Scene};
use std::path::{Path, PathBuf};

impl Scene {
    /// Reads an `.obj`, `.ply`, `.gltf` or `.glb` file (GLB and PLY are also recognised by their
    /// magic, not only their name).
    pub fn read(path: &Path, opts: &ReadOptions) -> Result<Scene> {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
        if ext == "obj" {
            // Streamed: the text is never held whole next to what is parsed from it.
            return obj::read_file(path, opts);
        }
        let bytes = std::fs::read(path).map_err(|e| Error::input(path, format!("cannot read: {e}")))?;
        if ext != "obj" && bytes.starts_with(b"glTF") {
            return gltf_read::read_glb_owned(path, bytes, opts);
        }
        Scene::read_bytes(path, &bytes, opts)
    }

    /// Reads a scene from bytes already in memory. `path` names the file in messages, decides the
    /// format by its extension (GLB is recognised by its magic) and is the folder relative URIs
    /// resolve against.
    pub fn read_bytes(path: &Path, bytes: &[u8], opts: &ReadOptions) -> Result<Scene> {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
        if ext == "obj" {
            obj::read(path, bytes, opts)
        } else if ext == "ply" || ply::is_ply(bytes) {
            obj::ply_scene(path, ply::parse(path, bytes)?, opts)
        } else if bytes.starts_with(b"glTF") || ext == "glb" {
            gltf_read::read_glb(path, bytes, opts)
        } else if ext == "gltf" || bytes.first().map(|b| *b == b'{').unwrap_or(false) {
            gltf_read::read_gltf(path, bytes, opts)
        } else {
            Err(Error::input(path, "unknown mesh format (expected .obj, .ply, .gltf or .glb)"))
        }
    }

    /// Every file the output depends on: the source, external buffers, MTL files, images and
    /// height maps, for Make/Ninja depfiles.
    pub fn dependencies(&self) -> Vec<PathBuf> {
        let mut out = vec![self.source.clone()];
        out.extend(self.deps.iter().cloned());
        for img in self.array("images") {
            if let Some(u) = img.get("uri").and_then(|u| u.as_str()) {
                if let Ok(uri::Target::File(p)) = uri::resolve(u, &self.base_dir, &self.source, self.allow_outside) {
                    out.push(p);
                }
            }
        }
        out.extend(self.height_maps.iter().map(|h| h.path.clone()));
        let mut seen = std::collections::HashSet::new();
        out.retain(|p| seen.insert(p.clone()));
        out
    }

    /// The encoded bytes of image `i` (from its URI, data URI or buffer view).
    pub fn image_bytes(&self, i: usize) -> Result<Vec<u8>> {
        let img = self.array("images").get(i).ok_or_else(|| self.err(format!("image {i} does not exist")))?;
        if let Some(u) = img.get("uri").and_then(|u| u.as_str()) {
            return uri::read(u, &self.base_dir, &self.source, self.allow_outside);
        }
        let v = img
            .get("bufferView")
            .and_then(as_index)
            .ok_or_else(|| self.err(format!("image {i} has neither uri nor bufferView")))?;
        let view = self
            .array("bufferViews")
            .get(v)
            .ok_or_else(|| self.err(format!("image {i}: bufferView {v} does not exist")))?;
        let b = view.get("buffer").and_then(as_index).unwrap_or(0);
        let off = view.get("byteOffset").and_then(|o| o.as_u64()).unwrap_or(0) as usize;
        let len = view.get("byteLength").and_then(|o| o.as_u64()).unwrap_or(0) as usize;
        self.buffer_range(b, off, len)
            .map(<[u8]>::to_vec)
            .map_err(|why| self.err(format!("image {i}: bufferView {v} {why}")))
    }
}

/// The first vertex with a coordinate that is not finite, as an error naming `path` (every
/// reader's words for it); on every core.
fn check_finite(path: &Path, p: &[[f32; 3]]) -> Result<()> {
    use rayon::prelude::*;
    match p.par_iter().position_first(|q| !q.iter().all(|c| c.is_finite())) {
        Some(i) => Err(Error::input(path, format!("vertex {} has a non-finite coordinate", i + 1))),
        None => Ok(()),
    }
}

/// A sign, then 1 to 18 decimal digits (so it never overflows), as `str::parse::<i64>` reads it
/// without its UTF-8 check; `None` for anything else, a longer number included. The OBJ and ASCII
/// PLY readers' one integer parser.
#[inline]
fn short_int(t: &[u8]) -> Option<i64> {
    let (neg, digits) = match t.first()? {
        b'-' => (true, &t[1..]),
        b'+' => (false, &t[1..]),
        _ => (false, t),
    };
    if digits.is_empty() || digits.len() > 18 {
        return None;
    }
    let mut v = 0i64;
    for &c in digits {
        let d = c.wrapping_sub(b'0');
        if d > 9 {
            return None;
        }
        v = v * 10 + d as i64;
    }
    Some(if neg { -v } else { v })
}
