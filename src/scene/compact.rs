//! Dropping accessors and buffer views nothing references, and packing the rest into one buffer.
//!
//! The writer does this on every output. [`Scene::compact`] does the same in memory, earlier: once
//! the primitives that get new data are decoded, the bytes they were read from need not stay
//! alive while tangents are made. Anything that cannot be proved unreferenced (data an unknown
//! extension might point at) is kept.

use super::refs::{accessor_refs, drop_unreferenced, primitive_accessor_refs, unknown_data_refs, view_refs};
use super::{as_index, PrimRef, Scene};
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::ops::Range;

/// What happened to the scene's buffers before writing. The writer's report counts as if nothing
/// had been freed early and every new stream had been appended to the last buffer (as the tool
/// once did), so the numbers a user sees do not depend on when memory was given back.
#[derive(Debug, Clone, Default)]
pub(crate) struct Ledger {
    pub accessors_dropped: usize,
    pub views_dropped: usize,
    /// Bytes the scene no longer holds but the report counts: what compaction freed, and the
    /// alignment padding one growing buffer would have needed between appended streams.
    pub bytes_unheld: usize,
    /// Length of that one growing buffer; set when the first stream is appended or compaction
    /// replaces the buffers, whichever comes first.
    tail: Option<usize>,
    /// Index accessors of detached primitives: their `name` and `extras` carry over to the new
    /// indices, and after compaction the old index no longer says which accessor it was.
    pub detached: BTreeMap<PrimRef, Value>,
}

impl Ledger {
    /// Counts a stream of `len` bytes appended; `last` is the length of the scene's last buffer.
    pub fn appended(&mut self, len: usize, last: usize) {
        let tail = self.tail.get_or_insert(last);
        let pad = (4 - *tail % 4) % 4;
        self.bytes_unheld += pad;
        *tail += pad + len;
    }
    /// A fresh, empty buffer now takes the appended streams.
    pub fn restart(&mut self) {
        self.tail = Some(0);
    }
}

impl Scene {
    /// Drops accessors and buffer views nothing references and packs the rest into one buffer,
    /// freeing the old bytes. Leaves the scene as it is when the document uses an extension this
    /// tool does not know or references something that does not exist (the writer decides then).
    pub fn compact(&mut self) {
        if unknown_data_refs(&self.json) {
            return;
        }
        let Ok(accessors) = drop_unreferenced(&mut self.json, "accessors", false, accessor_refs) else { return };
        self.ledger.accessors_dropped += accessors.gone.len();
        let Ok(views) = drop_unreferenced(&mut self.json, "bufferViews", false, view_refs) else { return };
        self.ledger.views_dropped += views.gone.len();
        if views.gone.is_empty() {
            return;
        }
        let last = self.buffers.last().map_or(0, |b| b.len());
        let Some(pieces) = pack_views(&mut self.json, &self.buffers) else { return };
        let mut bin = Vec::with_capacity(pieces.last().map_or(0, |p| p.at + p.range.len()));
        for p in &pieces {
            bin.resize(p.at, 0);
            bin.extend_from_slice(&self.buffers[p.buffer][p.range.clone()]);
        }
        let held: usize = self.buffers.iter().map(|b| b.len()).sum();
        self.ledger.tail.get_or_insert(last);
        self.ledger.bytes_unheld += held - bin.len();
        super::set_key(&mut self.json, "buffers", json!([{ "byteLength": bin.len() }]));
        self.buffers = vec![bin];
        self.absent_buffers.clear();
    }

    /// Takes the data of primitives that are about to get new data out of the document, then
    /// [`compact`](Self::compact)s it, so the bytes they were read from are freed. Until
    /// [`set_primitive`](Self::set_primitive) puts each back, its attributes, indices and morph
    /// targets name no accessor; every other part of its JSON stays.
    pub fn release_primitives(&mut self, refs: &[PrimRef]) {
        if refs.is_empty() || unknown_data_refs(&self.json) {
            return;
        }
        for &r in refs {
            let old = self.prim_json(r).get("indices").and_then(as_index);
            if let Some(template) = old.and_then(|i| self.array("accessors").get(i).cloned()) {
                self.ledger.detached.insert(r, template);
            }
            // Null keeps each key where it is, so the document reads the same once data is back.
            if let Some(pj) = self.prim_json_mut(r) {
                primitive_accessor_refs(pj, &mut |v| {
                    if as_index(v).is_some() {
                        *v = Value::Null;
                    }
                });
            }
        }
        self.compact();
    }
}

/// Where one buffer view's bytes come from, and where they land in the packed buffer.
pub(crate) struct Piece {
    pub buffer: usize,
    pub range: Range<usize>,
    pub at: usize,
}

/// Lays the buffer views out back to back in buffer 0, each at a multiple of 4, in order, and
/// points them there. None, and nothing changed, when a view runs past its buffer.
pub(crate) fn pack_views(json: &mut Value, buffers: &[Vec<u8>]) -> Option<Vec<Piece>> {
    let Some(views) = json.get_mut("bufferViews").and_then(|v| v.as_array_mut()) else { return Some(Vec::new()) };
    let mut pieces = Vec::with_capacity(views.len());
    let mut end = 0usize;
    for v in views.iter() {
        let buffer = v.get("buffer").and_then(as_index).unwrap_or(0);
        let off = v.get("byteOffset").and_then(|o| o.as_u64()).unwrap_or(0) as usize;
        let len = v.get("byteLength").and_then(|o| o.as_u64()).unwrap_or(0) as usize;
        buffers.get(buffer).and_then(|buf| buf.get(off..off + len))?;
        let at = end.next_multiple_of(4);
        end = at + len;
        pieces.push(Piece { buffer, range: off..off + len, at });
    }
    for (v, p) in views.iter_mut().zip(&pieces) {
        super::set_key(v, "buffer", json!(0));
        set_offset(v, p.at);
    }
    Some(pieces)
}

pub(crate) fn set_offset(v: &mut Value, at: usize) {
    if at == 0 {
        if let Some(o) = v.as_object_mut() {
            o.remove("byteOffset");
        }
    } else {
        super::set_key(v, "byteOffset", json!(at));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::{write, WriteOptions};
    use crate::scene::ReadOptions;
    use base64::Engine as _;
    use std::path::Path;

    /// Two buffers; accessor 1 and view 1 are unreferenced; the index view has an odd length, the
    /// normal accessor starts inside a strided view, and an image lives in buffer 1.
    fn scene(extensions: &[&str]) -> Scene {
        let mut b0 = Vec::new();
        for x in [0f32, 0., 0., 1., 0., 0., 0., 1., 0.] {
            b0.extend_from_slice(&x.to_le_bytes());
        }
        b0.extend_from_slice(&[7u8; 10]); // unreferenced view 1
        b0.extend_from_slice(&[0, 0, 1, 0, 2, 0]); // indices, 6 bytes
        let mut b1 = vec![9u8; 4]; // byteOffset of the strided view's accessor
        for n in [[0f32, 0., 1.], [0., 0., 1.], [0., 1., 0.]] {
            for x in n {
                b1.extend_from_slice(&x.to_le_bytes());
            }
            b1.extend_from_slice(&[0u8; 4]);
        }
        b1.extend_from_slice(b"\x89PNG fake");
        let uri = |b: &[u8]| {
            format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(b))
        };
        let json = json!({
            "asset": { "version": "2.0" },
            "extensionsUsed": extensions,
            "buffers": [{ "byteLength": b0.len(), "uri": uri(&b0) }, { "byteLength": b1.len(), "uri": uri(&b1) }],
            "bufferViews": [
                { "buffer": 0, "byteLength": 36 },
                { "buffer": 0, "byteOffset": 36, "byteLength": 10 },
                { "buffer": 0, "byteOffset": 46, "byteLength": 6 },
                { "buffer": 1, "byteLength": 52, "byteStride": 16 },
                { "buffer": 1, "byteOffset": 52, "byteLength": 9 },
            ],
            "accessors": [
                { "bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3" },
                { "bufferView": 1, "componentType": 5121, "count": 10, "type": "SCALAR" },
                { "bufferView": 2, "componentType": 5123, "count": 3, "type": "SCALAR", "name": "idx" },
                { "bufferView": 3, "byteOffset": 4, "componentType": 5126, "count": 3, "type": "VEC3" },
            ],
            "images": [{ "bufferView": 4, "mimeType": "image/png" }],
            "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0, "NORMAL": 3 }, "indices": 2, "material": 0, "extras": { "keep": true } }] }],
            "materials": [{ "normalTexture": { "index": 0 } }],
            "textures": [{ "source": 0 }],
        });
        crate::format::read_bytes(Path::new("t.gltf"), &serde_json::to_vec(&json).unwrap(), &ReadOptions::default())
            .unwrap()
    }

    const P: PrimRef = PrimRef { mesh: 0, primitive: 0 };

    #[test]
    fn drops_what_nothing_references_and_keeps_the_rest_readable() {
        let mut s = scene(&[]);
        let data = |p: super::super::Primitive| {
            (p.attributes.into_iter().map(|(n, s)| (n, s.format, s.data)).collect::<Vec<_>>(), p.indices)
        };
        let before = data(s.primitive(P).unwrap());
        let image = s.image_bytes(0).unwrap();
        s.compact();
        assert_eq!(s.array("accessors").len(), 3);
        assert_eq!(s.array("bufferViews").len(), 4);
        assert_eq!((s.ledger.accessors_dropped, s.ledger.views_dropped), (1, 1));
        assert_eq!(s.buffers.len(), 1);
        assert_eq!(s.json["buffers"], json!([{ "byteLength": s.buffers[0].len() }]));
        // Every remaining accessor and image reads as before, through the renumbered references.
        assert_eq!(data(s.primitive(P).unwrap()), before);
        assert_eq!(s.accessor(1).unwrap().template.unwrap()["name"], "idx");
        assert_eq!(s.image_bytes(0).unwrap(), image);
        for v in s.array("bufferViews") {
            assert_eq!(v["byteOffset"].as_u64().unwrap_or(0) % 4, 0);
        }
        // 36 + 6 (+2 padding) + 52 + 9.
        assert_eq!(s.buffers[0].len(), 105);
        assert_eq!(s.ledger.bytes_unheld, 52 + 61 - 105);
    }

    #[test]
    fn an_unknown_extension_leaves_the_scene_alone() {
        let mut s = scene(&["EXT_someone_elses"]);
        let (json, buffers) = (s.json.clone(), s.buffers.clone());
        s.compact();
        s.release_primitives(&[P]);
        assert_eq!((s.json, s.buffers), (json, buffers));
    }

    /// The whole point: releasing early must not change what is written.
    #[test]
    fn releasing_then_putting_back_writes_the_same_bytes() {
        let mut written = Vec::new();
        for release in [false, true] {
            let dir = tempfile::tempdir().unwrap();
            let mut s = scene(&[]);
            let p = s.primitive(P).unwrap();
            if release {
                s.release_primitives(&[P]);
                assert!(s.array("accessors").iter().all(|a| a.get("name").is_none()), "the index accessor is detached");
                assert_eq!(s.prim_json(P)["extras"], json!({ "keep": true }));
            }
            s.put_primitive(P, p);
            for ext in ["glb", "gltf"] {
                let out = dir.path().join(format!("o.{ext}"));
                let (files, stats) = write(&s, &out, &WriteOptions::default()).unwrap();
                files.commit().unwrap();
                let bin = std::fs::read(dir.path().join("o.bin")).unwrap_or_default();
                written.push((ext, std::fs::read(&out).unwrap(), bin, format!("{stats:?}")));
            }
        }
        assert_eq!(written[0], written[2]);
        assert_eq!(written[1], written[3]);
    }
}
