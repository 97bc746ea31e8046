//! EXT_meshopt_compression, decoded right after parsing (as gltfpack's `parsegltf.cpp` does): each
//! compressed buffer view is decoded into the place its fallback buffer reserves for it, and the
//! extension leaves the document, so every later stage sees plain buffer views and the writer
//! writes the file uncompressed.
//!
//! The decoders are meshoptimizer's own (through the `meshopt` crate), which its author documents
//! as safe on untrusted input; everything they are handed is bounds-checked here first.

use crate::error::{Error, Result};
use crate::scene::as_index;
use serde_json::Value;
use std::path::Path;

pub const EXT: &str = "EXT_meshopt_compression";

/// True for a buffer whose bytes the extension supplies (`fallback`): it may have no `uri`.
pub fn is_fallback(buffer: &Value) -> bool {
    buffer.pointer("/extensions/EXT_meshopt_compression").is_some()
}

/// Decodes every compressed buffer view of `json` into `buffers` and removes the extension.
/// Returns whether there was anything to decode.
pub fn decode_all(path: &Path, json: &mut Value, buffers: &mut [Vec<u8>]) -> Result<bool> {
    let bad = |m: String| Error::input(path, format!("{EXT}: {m}"));
    let mut any = false;
    let n_views = json.get("bufferViews").and_then(|v| v.as_array()).map_or(0, |v| v.len());
    for i in 0..n_views {
        let Some(view) = json.pointer(&format!("/bufferViews/{i}")) else { continue };
        let Some(ext) = view.pointer("/extensions/EXT_meshopt_compression").cloned() else {
            continue;
        };
        any = true;
        let job = Job::read(&ext, view).map_err(|m| bad(format!("bufferView {i}: {m}")))?;
        let src = buffers
            .get(job.src_buffer)
            .and_then(|b| b.get(job.src_offset..job.src_offset.checked_add(job.src_len)?))
            .ok_or_else(|| bad(format!("bufferView {i}: the compressed bytes lie outside buffer {}", job.src_buffer)))?
            .to_vec();
        let dst = buffers
            .get_mut(job.dst_buffer)
            .and_then(|b| b.get_mut(job.dst_offset..job.dst_offset.checked_add(job.dst_len)?))
            .ok_or_else(|| bad(format!("bufferView {i} runs past the end of buffer {}", job.dst_buffer)))?;
        job.decode(&src, dst).map_err(|m| bad(format!("bufferView {i}: {m}")))?;
        if let Some(view) = json.pointer_mut(&format!("/bufferViews/{i}")).and_then(Value::as_object_mut) {
            if let Some(exts) = view.get_mut("extensions").and_then(Value::as_object_mut) {
                exts.remove(EXT);
                if exts.is_empty() {
                    view.remove("extensions");
                }
            }
        }
    }
    for b in json.get_mut("buffers").and_then(|b| b.as_array_mut()).into_iter().flatten() {
        if let Some(exts) = b.get_mut("extensions").and_then(|e| e.as_object_mut()) {
            exts.remove(EXT);
            if exts.is_empty() {
                b.as_object_mut().map(|o| o.remove("extensions"));
            }
        }
    }
    for key in ["extensionsUsed", "extensionsRequired"] {
        if let Some(list) = json.get_mut(key).and_then(|l| l.as_array_mut()) {
            list.retain(|e| e.as_str() != Some(EXT));
            if list.is_empty() {
                json.as_object_mut().map(|o| o.remove(key));
            }
        }
    }
    Ok(any)
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    Attributes,
    Triangles,
    Indices,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Filter {
    None,
    Octahedral,
    Quaternion,
    Exponential,
}

/// One compressed view, checked against the rules of the extension.
struct Job {
    src_buffer: usize,
    src_offset: usize,
    src_len: usize,
    dst_buffer: usize,
    dst_offset: usize,
    dst_len: usize,
    stride: usize,
    count: usize,
    mode: Mode,
    filter: Filter,
}

impl Job {
    fn read(ext: &Value, view: &Value) -> crate::error::Faulty<Job> {
        let num = |v: &Value, key: &str| v.get(key).and_then(|x| x.as_u64()).map(|x| x as usize);
        let need = |key: &str| num(ext, key).ok_or_else(|| format!("no {key}"));
        let mode = match ext.get("mode").and_then(|m| m.as_str()) {
            Some("ATTRIBUTES") => Mode::Attributes,
            Some("TRIANGLES") => Mode::Triangles,
            Some("INDICES") => Mode::Indices,
            other => return Err(format!("unknown mode {}", other.unwrap_or("(none)")).into()),
        };
        let filter = match ext.get("filter").and_then(|m| m.as_str()).unwrap_or("NONE") {
            "NONE" => Filter::None,
            "OCTAHEDRAL" => Filter::Octahedral,
            "QUATERNION" => Filter::Quaternion,
            "EXPONENTIAL" => Filter::Exponential,
            other => return Err(format!("unknown filter {other}").into()),
        };
        let job = Job {
            src_buffer: ext.get("buffer").and_then(as_index).ok_or("no buffer")?,
            src_offset: num(ext, "byteOffset").unwrap_or(0),
            src_len: need("byteLength")?,
            dst_buffer: view.get("buffer").and_then(as_index).ok_or("no buffer")?,
            dst_offset: num(view, "byteOffset").unwrap_or(0),
            dst_len: num(view, "byteLength").ok_or("no byteLength")?,
            stride: need("byteStride")?,
            count: need("count")?,
            mode,
            filter,
        };
        let stride_ok = match (job.mode, job.filter) {
            (Mode::Attributes, Filter::None | Filter::Exponential) => job.stride.is_multiple_of(4) && job.stride <= 256,
            (Mode::Attributes, Filter::Octahedral) => job.stride == 4 || job.stride == 8,
            (Mode::Attributes, Filter::Quaternion) => job.stride == 8,
            (_, Filter::None) => job.stride == 2 || job.stride == 4,
            _ => return Err("filters apply only to ATTRIBUTES".into()),
        };
        if !stride_ok || job.stride == 0 {
            return Err(format!("byteStride {} is not allowed here", job.stride).into());
        }
        if job.mode == Mode::Triangles && !job.count.is_multiple_of(3) {
            return Err(format!("TRIANGLES count {} is not a multiple of 3", job.count).into());
        }
        match job.count.checked_mul(job.stride) {
            Some(n) if n <= job.dst_len => Ok(job),
            _ => {
                Err(format!("{} elements of {} bytes do not fit its {} bytes", job.count, job.stride, job.dst_len)
                    .into())
            }
        }
    }

    fn decode(&self, src: &[u8], dst: &mut [u8]) -> crate::error::Faulty<()> {
        let out = &mut dst[..self.count * self.stride];
        // SAFETY: `out` holds exactly count * stride bytes (checked in `read`), which is what each
        // decoder writes; the decoders read at most `src.len()` bytes of `src`.
        let rc = unsafe {
            let (d, s) = (out.as_mut_ptr().cast(), src.as_ptr());
            match self.mode {
                Mode::Attributes => {
                    ::meshopt::ffi::meshopt_decodeVertexBuffer(d, self.count, self.stride, s, src.len())
                }
                Mode::Triangles => ::meshopt::ffi::meshopt_decodeIndexBuffer(d, self.count, self.stride, s, src.len()),
                Mode::Indices => ::meshopt::ffi::meshopt_decodeIndexSequence(d, self.count, self.stride, s, src.len()),
            }
        };
        if rc != 0 {
            return Err(format!("the compressed data is damaged (decoder error {rc})").into());
        }
        // SAFETY: each filter rewrites count elements of `stride` bytes in place, within `out`;
        // the strides were checked against what each filter accepts.
        unsafe {
            let d = out.as_mut_ptr().cast();
            match self.filter {
                Filter::None => {}
                Filter::Octahedral => ::meshopt::ffi::meshopt_decodeFilterOct(d, self.count, self.stride),
                Filter::Quaternion => ::meshopt::ffi::meshopt_decodeFilterQuat(d, self.count, self.stride),
                Filter::Exponential => ::meshopt::ffi::meshopt_decodeFilterExp(d, self.count, self.stride),
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    /// Encodes with meshoptimizer's encoder and checks the round trip through the glTF layer.
    #[test]
    fn attributes_and_triangles_round_trip_into_the_fallback_buffer() {
        let verts: Vec<[u16; 4]> = (0..50u16).map(|i| [i, i * 3, 65535 - i, 7]).collect();
        let idx: Vec<u32> = (0..48u32).map(|i| (i * 7) % 50).collect();
        let venc = ::meshopt::encode_vertex_buffer(&verts).unwrap();
        let ienc = ::meshopt::encode_index_buffer(&idx, 50).unwrap();
        let mut src = venc.clone();
        src.resize(src.len().next_multiple_of(4), 0);
        let ioff = src.len();
        src.extend_from_slice(&ienc);
        let mut json = json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": ["EXT_meshopt_compression"],
            "extensionsRequired": ["EXT_meshopt_compression"],
            "buffers": [{"byteLength": src.len()},
                        {"byteLength": 400 + 192, "extensions": {"EXT_meshopt_compression": {"fallback": true}}}],
            "bufferViews": [
                {"buffer": 1, "byteOffset": 0, "byteLength": 400, "byteStride": 8, "extensions": {"EXT_meshopt_compression":
                    {"buffer": 0, "byteLength": venc.len(), "byteStride": 8, "count": 50, "mode": "ATTRIBUTES"}}},
                {"buffer": 1, "byteOffset": 400, "byteLength": 192, "extensions": {"EXT_meshopt_compression":
                    {"buffer": 0, "byteOffset": ioff, "byteLength": ienc.len(), "byteStride": 4, "count": 48, "mode": "TRIANGLES"}}}
            ]
        });
        let mut buffers = vec![src, vec![0u8; 592]];
        assert!(decode_all(Path::new("t.glb"), &mut json, &mut buffers).unwrap());
        let got_v: Vec<u8> = verts.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        assert_eq!(&buffers[1][..400], &got_v[..]);
        let got_i: Vec<u32> =
            buffers[1][400..].chunks_exact(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
        // The index codec may rotate a triangle's corners; the triangles themselves are kept.
        for (a, b) in got_i.chunks(3).zip(idx.chunks(3)) {
            let rot = |t: &[u32], k: usize| [t[k % 3], t[(k + 1) % 3], t[(k + 2) % 3]];
            assert!((0..3).any(|k| rot(a, k) == [b[0], b[1], b[2]]), "{a:?} vs {b:?}");
        }
        assert!(json.get("extensionsUsed").is_none() && json.get("extensionsRequired").is_none());
        assert!(json["bufferViews"][0].get("extensions").is_none());
        assert!(json["buffers"][1].get("extensions").is_none());
    }

    /// Decodes one compressed view of `count` elements of `stride` bytes through the glTF layer.
    fn decode_one(encoded: &[u8], stride: usize, count: usize, mode: &str, filter: &str) -> Vec<u8> {
        let mut json = json!({
            "buffers": [{"byteLength": encoded.len()}, {"byteLength": stride * count}],
            "bufferViews": [{"buffer": 1, "byteLength": stride * count, "extensions": {"EXT_meshopt_compression":
                {"buffer": 0, "byteLength": encoded.len(), "byteStride": stride, "count": count,
                 "mode": mode, "filter": filter}}}]
        });
        let mut buffers = vec![encoded.to_vec(), vec![0u8; stride * count]];
        decode_all(Path::new("t.glb"), &mut json, &mut buffers).unwrap();
        buffers.pop().unwrap()
    }

    fn encode_vertices(filtered: &[u8], stride: usize) -> Vec<u8> {
        let count = filtered.len() / stride;
        let mut out = vec![0u8; unsafe { ::meshopt::ffi::meshopt_encodeVertexBufferBound(count, stride) }];
        // SAFETY: `out` is the bound meshoptimizer asks for; `filtered` holds count * stride bytes.
        let n = unsafe {
            ::meshopt::ffi::meshopt_encodeVertexBuffer(
                out.as_mut_ptr(),
                out.len(),
                filtered.as_ptr().cast(),
                count,
                stride,
            )
        };
        out.truncate(n);
        out
    }

    #[test]
    fn octahedral_quaternion_and_exponential_filters_decode_to_the_encoded_values() {
        let count = 64;
        let unit: Vec<[f32; 4]> = (0..count)
            .map(|i| {
                let (a, b) = (i as f32 * 0.37, i as f32 * 0.11);
                [a.cos() * b.cos(), a.sin() * b.cos(), b.sin(), if i % 2 == 0 { 1.0 } else { -1.0 }]
            })
            .collect();
        let flat: Vec<f32> = unit.iter().flatten().copied().collect();
        // Octahedral, 16-bit components (stride 8): unit vectors with w carried.
        let mut filtered = vec![0u8; count * 8];
        // SAFETY: `filtered` holds count * 8 bytes, `flat` count * 4 floats.
        unsafe { ::meshopt::ffi::meshopt_encodeFilterOct(filtered.as_mut_ptr().cast(), count, 8, 16, flat.as_ptr()) };
        let out = decode_one(&encode_vertices(&filtered, 8), 8, count, "ATTRIBUTES", "OCTAHEDRAL");
        for (v, e) in unit.iter().zip(out.chunks_exact(8)) {
            let c = |k: usize| i16::from_le_bytes([e[2 * k], e[2 * k + 1]]) as f32 / 32767.0;
            assert!((0..3).all(|k| (c(k) - v[k]).abs() < 1e-3), "{v:?}");
            assert_eq!(c(3), v[3]);
        }
        // Quaternion (stride 8): unit quaternions up to sign.
        let q: Vec<f32> =
            unit.iter().flat_map(|v| glam::Quat::from_xyzw(v[0], v[1], v[2], 0.5).normalize().to_array()).collect();
        unsafe { ::meshopt::ffi::meshopt_encodeFilterQuat(filtered.as_mut_ptr().cast(), count, 8, 12, q.as_ptr()) };
        let out = decode_one(&encode_vertices(&filtered, 8), 8, count, "ATTRIBUTES", "QUATERNION");
        for (v, e) in q.chunks_exact(4).zip(out.chunks_exact(8)) {
            let c = |k: usize| i16::from_le_bytes([e[2 * k], e[2 * k + 1]]) as f32 / 32767.0;
            let dot: f32 = (0..4).map(|k| c(k) * v[k]).sum();
            assert!(dot.abs() > 0.9999, "{v:?}: {dot}");
        }
        // Exponential (stride 16): floats to about 2^-15 relative.
        let big: Vec<f32> = flat.iter().enumerate().map(|(i, x)| x * (i as f32 + 1.0) * 1000.0).collect();
        let mut filtered = vec![0u8; count * 16];
        unsafe {
            ::meshopt::ffi::meshopt_encodeFilterExp(filtered.as_mut_ptr().cast(), count, 16, 16, big.as_ptr(), 0)
        };
        let out = decode_one(&encode_vertices(&filtered, 16), 16, count, "ATTRIBUTES", "EXPONENTIAL");
        for (x, e) in big.iter().zip(out.chunks_exact(4)) {
            let y = f32::from_le_bytes([e[0], e[1], e[2], e[3]]);
            assert!((x - y).abs() <= x.abs() * 1e-4 + 1e-6, "{x} vs {y}");
        }
    }

    #[test]
    fn index_sequences_decode_exactly() {
        let idx: Vec<u32> = (0..90u32).map(|i| (i * 13) % 40).collect();
        // SAFETY: the buffer is the bound meshoptimizer asks for.
        let mut out = vec![0u8; unsafe { ::meshopt::ffi::meshopt_encodeIndexSequenceBound(idx.len(), 40) }];
        let n = unsafe {
            ::meshopt::ffi::meshopt_encodeIndexSequence(out.as_mut_ptr(), out.len(), idx.as_ptr(), idx.len())
        };
        out.truncate(n);
        let got = decode_one(&out, 2, idx.len(), "INDICES", "NONE");
        let got: Vec<u32> = got.chunks_exact(2).map(|b| u16::from_le_bytes([b[0], b[1]]) as u32).collect();
        assert_eq!(got, idx);
    }

    #[test]
    fn damaged_or_oversized_views_are_errors_naming_the_extension() {
        let mut json = json!({
            "buffers": [{"byteLength": 8}, {"byteLength": 16}],
            "bufferViews": [{"buffer": 1, "byteLength": 16, "extensions": {"EXT_meshopt_compression":
                {"buffer": 0, "byteLength": 8, "byteStride": 4, "count": 4, "mode": "ATTRIBUTES"}}}]
        });
        let mut buffers = vec![vec![0xa0, 1, 2, 3, 4, 5, 6, 7], vec![0u8; 16]];
        let e = decode_all(Path::new("t.glb"), &mut json.clone(), &mut buffers).unwrap_err().to_string();
        assert!(e.contains("EXT_meshopt_compression") && e.contains("damaged"), "{e}");
        json["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["count"] = json!(5);
        let e = decode_all(Path::new("t.glb"), &mut json, &mut buffers).unwrap_err().to_string();
        assert!(e.contains("do not fit"), "{e}");
    }
}
