//! Every file format bumpbake reads or writes, in a room of its own below the stages.
//!
//! Each reader hands over the same [`Scene`] (glTF JSON + buffers; OBJ and PLY converted on
//! reading, from the [`mesh::StoredMesh`] both parsers fill) and the image reader the same
//! decoded image, so no stage learns where a mesh or a texture came from. Compression (meshopt,
//! Draco) is decoded right after parsing, as gltfpack's `parsegltf.cpp` does for meshopt.

pub mod gltf;
pub mod image;
pub mod mesh;
pub mod obj;
pub mod ply;

pub use gltf::{write, WriteOptions, WriteStats};

use crate::error::{Error, Result};
use crate::scene::{as_index, ReadOptions, Scene};
use std::path::{Path, PathBuf};

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
        return gltf::read::read_glb_owned(path, bytes, opts);
    }
    read_bytes(path, &bytes, opts)
}

/// Reads a scene from bytes already in memory. `path` names the file in messages, decides the
/// format by its extension (GLB is recognised by its magic) and is the folder relative URIs
/// resolve against.
pub fn read_bytes(path: &Path, bytes: &[u8], opts: &ReadOptions) -> Result<Scene> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    if ext == "obj" {
        obj::read(path, bytes, opts)
    } else if ext == "ply" || ply::is_ply(bytes) {
        ply::scene(path, ply::parse(path, bytes)?, opts)
    } else if bytes.starts_with(b"glTF") || ext == "glb" {
        gltf::read::read_glb(path, bytes, opts)
    } else if ext == "gltf" || bytes.first().map(|b| *b == b'{').unwrap_or(false) {
        gltf::read::read_gltf(path, bytes, opts)
    } else {
        Err(Error::input(path, "unknown mesh format (expected .obj, .ply, .gltf or .glb)"))
    }
}

impl Scene {
    /// Every file the output depends on: the source, external buffers, MTL files, images and
    /// height maps, for Make/Ninja depfiles.
    pub fn dependencies(&self) -> Vec<PathBuf> {
        let mut out = vec![self.source.clone()];
        out.extend(self.deps.iter().cloned());
        for img in self.array("images") {
            if let Some(u) = img.get("uri").and_then(|u| u.as_str()) {
                if let Ok(gltf::uri::Target::File(p)) =
                    gltf::uri::resolve(u, &self.base_dir, &self.source, self.allow_outside)
                {
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
            return gltf::uri::read(u, &self.base_dir, &self.source, self.allow_outside);
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
