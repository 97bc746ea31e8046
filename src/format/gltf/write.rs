//! Writing a [`Scene`] as `.gltf` (+ `.bin`) or `.glb`.
//!
//! The writer keeps only the accessors and buffer views something still references, repacks them
//! into one buffer, and renumbers the references. Anything it cannot prove unreferenced (data an
//! unknown extension might point at) is kept.

use super::uri;
use crate::error::{Error, Result};
use crate::output::Outputs;
use crate::scene::compact::{pack_views, set_offset};
use crate::scene::refs::{accessor_refs, drop_unreferenced, unknown_data_refs, view_refs, Dangling};
use crate::scene::{set_key, Scene};
use base64::Engine as _;
use serde_json::{json, Value};
use std::borrow::Cow;
use std::collections::BTreeSet;
use std::path::Path;

#[derive(Debug, Clone, Default)]
pub struct WriteOptions {
    /// For `.gltf`: put buffers and images inside the JSON as data URIs.
    pub embed: bool,
    /// For `.gltf`: write images held in buffers or data URIs as files beside the output.
    pub images_external: bool,
}

/// Where an image ends up in the output.
enum Place {
    /// As it is (a data URI in a `.gltf`).
    Keep,
    /// In the output's buffer.
    Buffer,
    /// As a data URI.
    DataUri,
    /// Its file copied beside the output under the same relative name.
    CopyBeside,
    /// Written beside the output under a new name.
    NewFile,
}

/// What the writer did, for the report.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct WriteStats {
    pub accessors_dropped: usize,
    pub buffer_views_dropped: usize,
    pub buffer_bytes_in: usize,
    pub buffer_bytes_out: usize,
}

/// Builds every file the output consists of; the caller commits them (atomically, together).
/// The binary data is not copied: the files borrow it from `scene`.
pub fn write<'a>(scene: &'a Scene, out: &Path, opts: &WriteOptions) -> Result<(Outputs<'a>, WriteStats)> {
    let ext = out.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    let glb = match ext.as_str() {
        "glb" => true,
        "gltf" => false,
        _ => return Err(Error::usage(format!("{}: output must end in .gltf or .glb", out.display()))),
    };
    let mut json = scene.json.clone();
    add_position_bounds(scene, &mut json)?;
    let held: usize = scene.buffers.iter().map(|b| b.len()).sum();
    let mut stats = WriteStats { buffer_bytes_in: held + scene.ledger.bytes_unheld, ..Default::default() };
    let keep_all = unknown_data_refs(&json);
    let mut bin = Bin::default();
    let mut files = Outputs::new();
    let out_dir = out.parent().map(|p| p.to_path_buf()).unwrap_or_default();
    let dangling = |what: &str, Dangling(i, n)| {
        scene.err(format!("{what} {i} is referenced but does not exist ({n} in the file)"))
    };

    // Accessors.
    let dropped =
        drop_unreferenced(&mut json, "accessors", keep_all, accessor_refs).map_err(|d| dangling("accessor", d))?;
    stats.accessors_dropped = dropped.gone.len() + scene.ledger.accessors_dropped;

    // Images: embedded, copied or written out, before buffer views are renumbered.
    let images = json.get("images").and_then(|i| i.as_array()).cloned().unwrap_or_default();
    let mut new_images = Vec::with_capacity(images.len());
    let mut pending_views: Vec<(Vec<u8>, usize)> = Vec::new();
    let stem = out.file_stem().and_then(|s| s.to_str()).unwrap_or("scene").to_string();
    // Embedded, a core texture's KTX2 image is named the one way glTF allows a KTX2 to be: its
    // texture reads it through KHR_texture_basisu, and the image says `image/ktx2`.
    let ktx2: BTreeSet<usize> = match glb || opts.embed {
        true => core_sources(&json).into_iter().filter(|&i| is_ktx2(scene, i)).collect(),
        false => BTreeSet::new(),
    };
    crate::scene::basisu::core_ktx2_to_basisu(&mut json, &ktx2);
    let core = core_sources(&json);
    for (i, img) in images.iter().enumerate() {
        let mut img = img.clone();
        let u = img.get("uri").and_then(|u| u.as_str()).map(|s| s.to_string());
        let plain_file = u.as_deref().map(|u| !u.starts_with("data:")).unwrap_or(false) && !scene.own_images;
        // A core texture may only name PNG or JPEG by mimeType; an image in another format there
        // (KTX2 without KHR_texture_basisu, as some engines accept) has no mimeType the output
        // could give it, so it stays stored the way the input stored it.
        let as_stored = core.contains(&i) && !scene.own_images && !core_mime(scene, i);
        let place = if as_stored {
            // A GLB holds every embedded image in its binary chunk (data URIs are not allowed
            // there).
            if plain_file {
                Place::CopyBeside
            } else if u.is_some() && !glb {
                Place::Keep
            } else {
                Place::Buffer
            }
        } else if glb {
            Place::Buffer
        } else if opts.embed {
            Place::DataUri
        } else if plain_file {
            Place::CopyBeside
        } else if opts.images_external {
            Place::NewFile
        } else if u.is_some() && !scene.own_images {
            Place::Keep
        } else {
            Place::Buffer
        };
        let in_buffer = img.get("bufferView").is_some();
        match place {
            Place::Keep => {}
            Place::Buffer if in_buffer => {}
            Place::CopyBeside => copy_beside(&mut img, u.as_deref().unwrap_or(""), scene, &out_dir, &mut files)?,
            Place::Buffer | Place::DataUri | Place::NewFile => {
                let mut bytes = scene.image_bytes(i)?;
                if scene.own_images {
                    bytes = strip_png_colour_chunks(bytes);
                }
                let mime = img
                    .get("mimeType")
                    .and_then(|m| m.as_str())
                    .filter(|_| !ktx2.contains(&i))
                    .map(|s| s.to_string())
                    .unwrap_or_else(|| sniff_mime(&bytes, u.as_deref().unwrap_or("")));
                let o = img.as_object_mut().ok_or_else(|| scene.err(format!("image {i} is not an object")))?;
                o.remove("uri");
                o.remove("bufferView");
                match place {
                    Place::Buffer => {
                        o.insert("mimeType".into(), json!(mime));
                        pending_views.push((bytes, i));
                    }
                    Place::DataUri => {
                        o.insert(
                            "uri".into(),
                            json!(format!(
                                "data:{mime};base64,{}",
                                base64::engine::general_purpose::STANDARD.encode(&bytes)
                            )),
                        );
                    }
                    _ => {
                        let ext = mime.rsplit('/').next().unwrap_or("png").replace("jpeg", "jpg");
                        let name = format!("{stem}_image{i}.{ext}");
                        o.insert("uri".into(), json!(name));
                        files.add(out_dir.join(&name), bytes);
                    }
                }
            }
        }
        new_images.push(img);
    }
    if !images.is_empty() {
        set_key(&mut json, "images", Value::Array(new_images));
    }

    // Buffer views: keep what kept accessors, images and compressed primitives use; repack.
    let dropped =
        drop_unreferenced(&mut json, "bufferViews", keep_all, view_refs).map_err(|d| dangling("bufferView", d))?;
    stats.buffer_views_dropped = dropped.gone.len() + scene.ledger.views_dropped;
    for (i, v) in json.get("bufferViews").and_then(Value::as_array).into_iter().flatten().enumerate() {
        let b = v.get("buffer").and_then(Value::as_u64).unwrap_or(0) as usize;
        if scene.absent_buffers.contains(&b) {
            return Err(scene.err(format!(
                "bufferView {i} is kept in the output but reads buffer {b}, which has no data (no uri, and not a GLB's binary chunk)"
            )));
        }
    }
    for p in pack_views(&mut json, &scene.buffers).ok_or_else(|| scene.err("bufferView runs past its buffer"))? {
        bin.pad4();
        debug_assert_eq!(bin.len, p.at);
        bin.push(Cow::Borrowed(&scene.buffers[p.buffer][p.range]));
    }
    for (bytes, img) in pending_views {
        bin.pad4();
        let at = bin.len;
        let mut v = json!({ "buffer": 0, "byteLength": bytes.len() });
        set_offset(&mut v, at);
        bin.push(Cow::Owned(bytes));
        let views = crate::scene::array_mut(&mut json, "bufferViews");
        views.push(v);
        let view = views.len() - 1;
        if let Some(image) = json.pointer_mut(&format!("/images/{img}")) {
            set_key(image, "bufferView", json!(view));
        }
    }
    stats.buffer_bytes_out = bin.len;

    // One buffer, or none.
    let root = json.as_object_mut().ok_or_else(|| scene.err("glTF JSON is not an object"))?;
    // glTF wants a buffer's byteLength to be 1 or more: with no bytes left, no buffer.
    let no_views = root.get("bufferViews").and_then(Value::as_array).is_none_or(Vec::is_empty);
    if bin.len == 0 && no_views {
        root.remove("buffers");
    } else {
        let mut b = json!({ "byteLength": bin.len });
        if !glb {
            if opts.embed {
                set_key(
                    &mut b,
                    "uri",
                    json!(format!(
                        "data:application/octet-stream;base64,{}",
                        base64::engine::general_purpose::STANDARD.encode(bin.parts.concat())
                    )),
                );
            } else {
                let name = format!("{}.bin", out.file_stem().and_then(|s| s.to_str()).unwrap_or("scene"));
                set_key(&mut b, "uri", json!(name));
                files.add_parts(out_dir.join(&name), std::mem::take(&mut bin).parts);
            }
        }
        root.insert("buffers".into(), json!([b]));
    }
    for key in ["accessors", "bufferViews", "images"] {
        if root.get(key).and_then(|a| a.as_array()).map(|a| a.is_empty()).unwrap_or(false) {
            root.remove(key);
        }
    }

    if glb {
        files.add_parts(out, glb_parts(&json, bin));
    } else {
        let mut text = serde_json::to_vec_pretty(&json).map_err(|e| Error::output(out, e))?;
        text.push(b'\n');
        files.add(out, text);
    }
    Ok((files, stats))
}

/// glTF requires `min` and `max` on every POSITION accessor (morph targets' too); inputs that lack
/// them get them from their data, in the accessor's own component type.
fn add_position_bounds(scene: &Scene, json: &mut Value) -> Result<()> {
    let mut missing = BTreeSet::new();
    for mesh in json.get("meshes").and_then(|m| m.as_array()).into_iter().flatten() {
        for p in mesh.get("primitives").and_then(|p| p.as_array()).into_iter().flatten() {
            let targets = p.get("targets").and_then(|t| t.as_array()).into_iter().flatten();
            for set in std::iter::once(p.get("attributes")).chain(targets.map(Some)) {
                if let Some(i) = set.and_then(|a| a.get("POSITION")).and_then(|i| i.as_u64()) {
                    missing.insert(i as usize);
                }
            }
        }
    }
    for i in missing {
        let Some(acc) = json.pointer(&format!("/accessors/{i}")) else { continue };
        // An accessor without a bufferView is all zeros (or sparse): its bounds are for the file to give.
        if (acc.get("min").is_some() && acc.get("max").is_some()) || acc.get("bufferView").is_none() {
            continue;
        }
        if let (Some((lo, hi)), Some(acc)) = (scene.accessor(i)?.bounds(), json.pointer_mut(&format!("/accessors/{i}")))
        {
            set_key(acc, "min", lo);
            set_key(acc, "max", hi);
        }
    }
    Ok(())
}

/// The output buffer as the pieces it is made of, most of them borrowed from the scene: the
/// scene's bytes need not exist twice while the file is written.
#[derive(Default)]
struct Bin<'a> {
    parts: Vec<Cow<'a, [u8]>>,
    len: usize,
}

impl<'a> Bin<'a> {
    fn push(&mut self, bytes: Cow<'a, [u8]>) {
        self.len += bytes.len();
        self.parts.push(bytes);
    }
    /// Zeros up to the next multiple of 4.
    fn pad4(&mut self) {
        let n = self.len.next_multiple_of(4) - self.len;
        if n > 0 {
            self.push(Cow::Borrowed(&[0u8; 3][..n]));
        }
    }
}

/// The GLB container: header and JSON chunk, then the binary chunk (`b`'s parts, not copied).
fn glb_parts<'a>(json: &Value, mut b: Bin<'a>) -> Vec<Cow<'a, [u8]>> {
    let mut j = serde_json::to_vec(json).expect("a Value always serialises");
    j.resize(j.len().next_multiple_of(4), b' ');
    b.pad4();
    let has_bin = b.len != 0 || json.get("buffers").is_some();
    let total = 12 + 8 + j.len() + if has_bin { 8 + b.len } else { 0 };
    let mut out = Vec::with_capacity(12 + 8 + j.len() + 8);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(&0x4E4F534Au32.to_le_bytes());
    out.extend_from_slice(&j);
    if !has_bin {
        return vec![Cow::Owned(out)];
    }
    out.extend_from_slice(&(b.len as u32).to_le_bytes());
    out.extend_from_slice(&0x004E4942u32.to_le_bytes());
    let mut parts = Vec::with_capacity(1 + b.parts.len());
    parts.push(Cow::Owned(out));
    parts.extend(b.parts);
    parts
}

/// Copies an external image next to the output (unless it is already there).
fn copy_beside(img: &mut Value, u: &str, scene: &Scene, out_dir: &Path, files: &mut Outputs<'_>) -> Result<()> {
    let src = match uri::resolve(u, &scene.base_dir, &scene.source, scene.allow_outside)? {
        uri::Target::File(p) => p,
        uri::Target::Data { .. } => return Ok(()),
    };
    // A URI that climbs out of the folder (allowed by the user) lands beside the output by name.
    let rel = if u.contains("..") || u.starts_with('/') {
        let name = src.file_name().and_then(|n| n.to_str()).unwrap_or("image").to_string();
        set_key(img, "uri", json!(name.clone()));
        name
    } else {
        u.to_string()
    };
    let dst = out_dir.join(super::uri::decoded_path(&rel));
    let same = match (std::fs::canonicalize(&src), std::fs::canonicalize(&dst)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    };
    if !same {
        let bytes = std::fs::read(&src).map_err(|e| scene.err(format!("cannot read image '{u}': {e}")))?;
        files.add(dst, bytes);
    }
    Ok(())
}

/// Drops the PNG chunks that make the Khronos validator warn (colour profiles, gamma,
/// chromaticities, pixel aspect): glTF defines the colour space itself. Non-PNG bytes pass through.
fn strip_png_colour_chunks(bytes: Vec<u8>) -> Vec<u8> {
    if !bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        return bytes;
    }
    let mut out = bytes[..8].to_vec();
    let mut at = 8;
    while at + 12 <= bytes.len() {
        let len = u32::from_be_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]) as usize;
        let end = match at.checked_add(12 + len) {
            Some(e) if e <= bytes.len() => e,
            _ => return bytes,
        };
        let kind = &bytes[at + 4..at + 8];
        if !matches!(kind, b"iCCP" | b"cHRM" | b"gAMA" | b"sRGB" | b"pHYs" | b"sBIT") {
            out.extend_from_slice(&bytes[at..end]);
        }
        at = end;
    }
    out
}

/// Images some texture names as its core `source` (not only through an extension).
fn core_sources(json: &Value) -> BTreeSet<usize> {
    let textures = json.get("textures").and_then(|t| t.as_array());
    textures.into_iter().flatten().filter_map(|t| t.get("source")?.as_u64()).map(|i| i as usize).collect()
}

/// Whether image `i` is PNG or JPEG (by its bytes), the formats a core texture may carry. An
/// image that cannot be read is left to the path that reads it, which says why.
fn core_mime(scene: &Scene, i: usize) -> bool {
    match scene.image_bytes(i) {
        Ok(b) => b.starts_with(b"\x89PNG") || b.starts_with(&[0xFF, 0xD8]),
        Err(_) => true,
    }
}

/// Whether image `i` is a KTX2 (by its bytes; one that cannot be read is not).
fn is_ktx2(scene: &Scene, i: usize) -> bool {
    scene.image_bytes(i).is_ok_and(|b| b.starts_with(&[0xAB, b'K', b'T', b'X', b' ', b'2', b'0', 0xBB]))
}

fn sniff_mime(bytes: &[u8], uri: &str) -> String {
    if bytes.starts_with(b"\x89PNG") {
        "image/png".into()
    } else if bytes.starts_with(&[0xFF, 0xD8]) {
        "image/jpeg".into()
    } else if bytes.len() > 12 && &bytes[8..12] == b"WEBP" {
        "image/webp".into()
    } else if bytes.starts_with(&[0xAB, b'K', b'T', b'X']) {
        "image/ktx2".into()
    } else if uri.to_ascii_lowercase().ends_with(".jpg") || uri.to_ascii_lowercase().ends_with(".jpeg") {
        "image/jpeg".into()
    } else {
        "image/png".into()
    }
}
