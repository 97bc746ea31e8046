//! Accessor layouts and the raw, tightly packed vertex streams the model keeps, and how an
//! accessor's bytes (strided views, sparse substitution) become one.

use super::{as_index, Scene};
use crate::error::Result;
use serde_json::Value;

/// glTF component types.
pub const BYTE: u32 = 5120;
pub const UNSIGNED_BYTE: u32 = 5121;
pub const SHORT: u32 = 5122;
pub const UNSIGNED_SHORT: u32 = 5123;
pub const UNSIGNED_INT: u32 = 5125;
pub const FLOAT: u32 = 5126;

/// Size in bytes of one component.
pub fn component_size(component_type: u32) -> Option<usize> {
    match component_type {
        BYTE | UNSIGNED_BYTE => Some(1),
        SHORT | UNSIGNED_SHORT => Some(2),
        UNSIGNED_INT | FLOAT => Some(4),
        _ => None,
    }
}

/// Number of components of an accessor `type`.
pub fn component_count(ty: &str) -> Option<usize> {
    match ty {
        "SCALAR" => Some(1),
        "VEC2" => Some(2),
        "VEC3" => Some(3),
        "VEC4" | "MAT2" => Some(4),
        "MAT3" => Some(9),
        "MAT4" => Some(16),
        _ => None,
    }
}

/// How one element of a stream is stored.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Format {
    pub component_type: u32,
    pub ty: String,
    pub normalized: bool,
}

impl Format {
    pub fn f32(ty: &str) -> Self {
        Format { component_type: FLOAT, ty: ty.to_string(), normalized: false }
    }
    pub fn components(&self) -> usize {
        component_count(&self.ty).unwrap_or(0)
    }
    /// Bytes of one element, without the padding matrices need inside buffer views.
    pub fn elem_size(&self) -> usize {
        component_size(self.component_type).unwrap_or(0) * self.components()
    }
}

/// One vertex attribute, tightly packed (`elem_size` bytes per vertex), bytes as stored.
///
/// Keeping the bytes rather than floats means attributes the tool does not compute (colours,
/// joints, weights, quantised UVs) leave exactly as they came in.
#[derive(Debug, Clone, PartialEq)]
pub struct Stream {
    pub format: Format,
    pub data: Vec<u8>,
    /// The JSON of the accessor it was read from, for `name` and `extras` to survive.
    pub template: Option<serde_json::Value>,
}

impl Stream {
    pub fn len(&self) -> usize {
        self.data.len().checked_div(self.format.elem_size()).unwrap_or(0)
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// A float stream from `N`-component vectors.
    pub fn from_f32<const N: usize>(ty: &str, values: &[[f32; N]]) -> Self {
        let mut data = Vec::with_capacity(values.len() * N * 4);
        for v in values {
            for c in v {
                data.extend_from_slice(&c.to_le_bytes());
            }
        }
        Stream { format: Format::f32(ty), data, template: None }
    }

    /// Element `i`, component `c`, as a float (normalised integers are mapped as glTF says).
    pub fn get(&self, i: usize, c: usize) -> f32 {
        let f = &self.format;
        let cs = component_size(f.component_type).unwrap_or(4);
        let at = i * f.elem_size() + c * cs;
        let b = &self.data[at..at + cs];
        match (f.component_type, f.normalized) {
            (FLOAT, _) => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            (UNSIGNED_BYTE, true) => b[0] as f32 / 255.0,
            (UNSIGNED_BYTE, false) => b[0] as f32,
            (BYTE, true) => ((b[0] as i8) as f32 / 127.0).max(-1.0),
            (BYTE, false) => (b[0] as i8) as f32,
            (UNSIGNED_SHORT, true) => u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0,
            (UNSIGNED_SHORT, false) => u16::from_le_bytes([b[0], b[1]]) as f32,
            (SHORT, true) => (i16::from_le_bytes([b[0], b[1]]) as f32 / 32767.0).max(-1.0),
            (SHORT, false) => i16::from_le_bytes([b[0], b[1]]) as f32,
            (UNSIGNED_INT, _) => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
            _ => 0.0,
        }
    }

    /// The whole stream as `N`-component float vectors.
    pub fn to_f32<const N: usize>(&self) -> Vec<[f32; N]> {
        let mut out = vec![[0.0; N]; self.len()];
        self.for_each_element(|i, v| {
            for (x, &y) in out[i].iter_mut().zip(v) {
                *x = y;
            }
        });
        out
    }

    /// The stream as `N`-component float vectors, borrowed from its bytes when they are
    /// little-endian `f32`s with `N` components and suitably aligned (every float stream read from
    /// a file, in practice), else converted with [`Self::to_f32`].
    pub fn as_f32<const N: usize>(&self) -> std::borrow::Cow<'_, [[f32; N]]> {
        let n = self.len() * N * 4;
        if cfg!(target_endian = "little") && self.format.component_type == FLOAT && self.format.components() == N {
            if let Ok(v) = bytemuck::try_cast_slice::<u8, f32>(&self.data[..n]) {
                return std::borrow::Cow::Borrowed(v.as_chunks::<N>().0);
            }
        }
        std::borrow::Cow::Owned(self.to_f32())
    }

    /// An unsigned integer scalar stream (indices) as integers: a float would round them above
    /// 2^24. Other formats give their first component, truncated.
    pub fn to_u32(&self) -> Vec<u32> {
        match (self.format.component_type, self.format.components()) {
            (UNSIGNED_BYTE, 1) => self.data.iter().map(|&b| b as u32).collect(),
            (UNSIGNED_SHORT, 1) => self.data.chunks_exact(2).map(|b| u16::from_le_bytes([b[0], b[1]]) as u32).collect(),
            (UNSIGNED_INT, 1) => {
                self.data.chunks_exact(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect()
            }
            _ => (0..self.len()).map(|i| self.get(i, 0) as u32).collect(),
        }
    }

    /// Calls `f` with each element's index and components as floats (at most 16: a MAT4).
    /// Float streams are read straight from their bytes.
    pub fn for_each_element(&self, mut f: impl FnMut(usize, &[f32])) {
        let n = self.format.components().min(16);
        let mut v = [0.0f32; 16];
        if self.format.component_type == FLOAT && n > 0 {
            for (i, e) in self.data.chunks_exact(4 * n).enumerate() {
                for (x, b) in v.iter_mut().zip(e.chunks_exact(4)) {
                    *x = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                }
                f(i, &v[..n]);
            }
        } else {
            for i in 0..self.len() {
                for (c, x) in v.iter_mut().enumerate().take(n) {
                    *x = self.get(i, c);
                }
                f(i, &v[..n]);
            }
        }
    }

    /// The `min` and `max` glTF wants for this stream: per component, in the stream's own component
    /// type (integers stay integers, and `normalized` does not apply: glTF bounds are the stored
    /// values). `None` for an empty stream.
    pub fn bounds(&self) -> Option<(serde_json::Value, serde_json::Value)> {
        let n = self.format.components();
        if self.is_empty() || n == 0 {
            return None;
        }
        if self.format.component_type == FLOAT {
            let mut lo = vec![f32::INFINITY; n];
            let mut hi = vec![f32::NEG_INFINITY; n];
            self.for_each_element(|_, v| {
                for (c, &x) in v.iter().enumerate() {
                    lo[c] = lo[c].min(x);
                    hi[c] = hi[c].max(x);
                }
            });
            return Some((serde_json::json!(lo), serde_json::json!(hi)));
        }
        let mut lo = vec![i64::MAX; n];
        let mut hi = vec![i64::MIN; n];
        for i in 0..self.len() {
            for c in 0..n {
                let x = self.raw(i, c);
                lo[c] = lo[c].min(x);
                hi[c] = hi[c].max(x);
            }
        }
        Some((serde_json::json!(lo), serde_json::json!(hi)))
    }

    /// Element `i`, component `c` of an integer stream, as stored.
    pub fn raw(&self, i: usize, c: usize) -> i64 {
        let cs = component_size(self.format.component_type).unwrap_or(4);
        let at = i * self.format.elem_size() + c * cs;
        let b = &self.data[at..at + cs];
        match self.format.component_type {
            BYTE => b[0] as i8 as i64,
            UNSIGNED_BYTE => b[0] as i64,
            SHORT => i16::from_le_bytes([b[0], b[1]]) as i64,
            UNSIGNED_SHORT => u16::from_le_bytes([b[0], b[1]]) as i64,
            _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as i64,
        }
    }

    /// How finely the stream was quantized, in the units [`Self::get`] returns: each stored value
    /// is within half a step of the value that was quantized. Zero for floats, 1 for plain
    /// integers. Normalized integers are often quantized to fewer bits than they are stored in
    /// (glTF-Transform stores 12-bit UVs and 10-bit normals in 16 bits, as integer multiples of
    /// `65535 / 4095` and `32767 / 511`): the step is that of the fewest bits every stored value
    /// is consistent with, to within one stored unit (tools round twice: to their bits, then to
    /// the storage type). Streams with fewer than 16 distinct values say too little to tell and
    /// get their type's full precision.
    pub fn step(&self) -> f32 {
        let (bits, signed) = match (self.format.component_type, self.format.normalized) {
            (FLOAT, _) => return 0.0,
            (BYTE, true) => (8, true),
            (UNSIGNED_BYTE, true) => (8, false),
            (SHORT, true) => (16, true),
            (UNSIGNED_SHORT, true) => (16, false),
            _ => return 1.0,
        };
        let levels = |b: u32| if signed { ((1u32 << (b - 1)) - 1) as f64 } else { ((1u32 << b) - 1) as f64 };
        let full = levels(bits);
        let n = self.format.components();
        let mut values: Vec<i64> =
            (0..self.len()).flat_map(|i| (0..n).map(move |c| (i, c))).map(|(i, c)| self.raw(i, c)).collect();
        values.sort_unstable();
        values.dedup();
        if values.len() < 16 {
            return (1.0 / full) as f32;
        }
        let fits = |b: u32| {
            let k = full / levels(b);
            values.iter().all(|&r| (r as f64 - (r as f64 / k).round() * k).abs() <= 1.0 + 1e-6)
        };
        let b = (2..=bits).find(|&b| fits(b)).unwrap_or(bits);
        (1.0 / levels(b)) as f32
    }

    /// The stream laid out for a vertex buffer view: each element padded with zeros to a multiple
    /// of 4 bytes, as glTF requires of vertex attributes. Returns the bytes and the stride, or
    /// `None` when the elements are aligned already.
    pub fn padded_to_4(&self) -> Option<(Vec<u8>, usize)> {
        let es = self.format.elem_size();
        if es == 0 || es.is_multiple_of(4) {
            return None;
        }
        let stride = es.next_multiple_of(4);
        let mut out = vec![0u8; stride * self.len()];
        for (dst, src) in out.chunks_exact_mut(stride).zip(self.data.chunks_exact(es)) {
            dst[..es].copy_from_slice(src);
        }
        Some((out, stride))
    }

    /// Copies the elements named by `order` into a new stream (a gather).
    pub fn gather(&self, order: &[u32]) -> Stream {
        let s = self.format.elem_size();
        let mut data = Vec::with_capacity(order.len() * s);
        for &i in order {
            let i = i as usize;
            data.extend_from_slice(&self.data[i * s..(i + 1) * s]);
        }
        Stream { format: self.format.clone(), data, template: self.template.clone() }
    }

    /// Bytes of element `i`.
    pub fn elem(&self, i: usize) -> &[u8] {
        let s = self.format.elem_size();
        &self.data[i * s..(i + 1) * s]
    }
}

/// The bytes of a buffer view, already checked to be in range.
fn view_bytes(s: &Scene, view: usize) -> Result<(&[u8], Option<usize>)> {
    let v = s.array("bufferViews").get(view).ok_or_else(|| s.err(format!("bufferView {view} does not exist")))?;
    let b = v.get("buffer").and_then(as_index).unwrap_or(0);
    let off = v.get("byteOffset").and_then(|o| o.as_u64()).unwrap_or(0) as usize;
    let len = v.get("byteLength").and_then(|o| o.as_u64()).unwrap_or(0) as usize;
    let stride = v.get("byteStride").and_then(|o| o.as_u64()).map(|x| x as usize);
    let bytes = s.buffer_range(b, off, len).map_err(|why| s.err(format!("bufferView {view} {why}")))?;
    Ok((bytes, stride))
}

pub fn read_accessor(s: &Scene, idx: usize) -> Result<Stream> {
    let a = s.array("accessors").get(idx).ok_or_else(|| s.err(format!("accessor {idx} does not exist")))?;
    let ct = a.get("componentType").and_then(|c| c.as_u64()).unwrap_or(0) as u32;
    let ty = a.get("type").and_then(|t| t.as_str()).unwrap_or("");
    let count =
        a.get("count").and_then(|c| c.as_u64()).ok_or_else(|| s.err(format!("accessor {idx} has no count")))? as usize;
    let format = Format {
        component_type: ct,
        ty: ty.to_string(),
        normalized: a.get("normalized").and_then(|n| n.as_bool()).unwrap_or(false),
    };
    let (Some(_), Some(_)) = (component_size(ct), component_count(ty)) else {
        return Err(s.err(format!("accessor {idx} has an unknown componentType {ct} or type '{ty}'")));
    };
    let es = format.elem_size();
    let total = count
        .checked_mul(es)
        .filter(|&t| t <= 1 << 31)
        .ok_or_else(|| s.err(format!("accessor {idx}: count {count} is absurd")))?;
    let mut data = vec![0u8; 0];
    match a.get("bufferView").and_then(as_index) {
        Some(view) => {
            let (bytes, stride) = view_bytes(s, view)?;
            let off = a.get("byteOffset").and_then(|o| o.as_u64()).unwrap_or(0) as usize;
            let stride = stride.unwrap_or(es).max(es);
            // Matrices of 1- and 2-byte components pad each column to 4 bytes.
            let col_pad = matches!(ty, "MAT2" | "MAT3" | "MAT4") && component_size(ct).unwrap_or(4) < 4;
            if col_pad {
                return Err(s.err(format!("accessor {idx}: padded matrix layouts are not supported")));
            }
            let need = match count {
                0 => Some(0),
                _ => stride.checked_mul(count - 1).and_then(|x| x.checked_add(off)).and_then(|x| x.checked_add(es)),
            };
            let Some(need) = need.filter(|&n| n <= bytes.len()) else {
                return Err(s.err(format!(
                    "accessor {idx} (byteOffset {off}, {count} elements {stride} bytes apart) runs past bufferView {view}, which has {} bytes",
                    bytes.len()
                )));
            };
            if need > bytes.len() {
                return Err(s.err(format!(
                    "accessor {idx} needs {need} bytes of bufferView {view}, which has {}",
                    bytes.len()
                )));
            }
            data.reserve(total);
            for i in 0..count {
                let at = off + i * stride;
                data.extend_from_slice(&bytes[at..at + es]);
            }
        }
        None => data.resize(total, 0),
    }
    if let Some(sp) = a.get("sparse") {
        apply_sparse(s, idx, sp, es, count, &mut data)?;
    }
    Ok(Stream { format, data, template: Some(a.clone()) })
}

fn apply_sparse(s: &Scene, idx: usize, sp: &Value, es: usize, count: usize, data: &mut [u8]) -> Result<()> {
    let n = sp.get("count").and_then(|c| c.as_u64()).unwrap_or(0) as usize;
    let bad = |m: &str| s.err(format!("accessor {idx}: sparse {m}"));
    let iv = sp.pointer("/indices/bufferView").and_then(as_index).ok_or_else(|| bad("indices without bufferView"))?;
    let ioff = sp.pointer("/indices/byteOffset").and_then(|o| o.as_u64()).unwrap_or(0) as usize;
    let ict = sp.pointer("/indices/componentType").and_then(|o| o.as_u64()).unwrap_or(0) as u32;
    let ics = component_size(ict).ok_or_else(|| bad("indices have an unknown componentType"))?;
    let vv = sp.pointer("/values/bufferView").and_then(as_index).ok_or_else(|| bad("values without bufferView"))?;
    let voff = sp.pointer("/values/byteOffset").and_then(|o| o.as_u64()).unwrap_or(0) as usize;
    let (ib, _) = view_bytes(s, iv)?;
    let (vb, _) = view_bytes(s, vv)?;
    let end = |off: usize, size: usize| n.checked_mul(size).and_then(|x| x.checked_add(off));
    if end(ioff, ics).is_none_or(|e| e > ib.len()) || end(voff, es).is_none_or(|e| e > vb.len()) {
        return Err(bad("data runs past its bufferView"));
    }
    for k in 0..n {
        let at = ioff + k * ics;
        let i = match ics {
            1 => ib[at] as usize,
            2 => u16::from_le_bytes([ib[at], ib[at + 1]]) as usize,
            _ => u32::from_le_bytes([ib[at], ib[at + 1], ib[at + 2], ib[at + 3]]) as usize,
        };
        if i >= count {
            return Err(bad(&format!("index {i} is past the accessor's count {count}")));
        }
        data[i * es..(i + 1) * es].copy_from_slice(&vb[voff + k * es..voff + (k + 1) * es]);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integer_bounds_are_stored_values_and_vertex_layouts_are_padded() {
        let s = Stream {
            format: Format { component_type: SHORT, ty: "VEC3".into(), normalized: true },
            data: [-32767i16, 5, 0, 100, -2, 32767].iter().flat_map(|x| x.to_le_bytes()).collect(),
            template: None,
        };
        let (lo, hi) = s.bounds().unwrap();
        assert_eq!(lo.to_string(), "[-32767,-2,0]");
        assert_eq!(hi.to_string(), "[100,5,32767]");
        let (bytes, stride) = s.padded_to_4().unwrap();
        assert_eq!(stride, 8);
        assert_eq!(&bytes[..6], &s.data[..6]);
        assert_eq!(&bytes[6..8], &[0, 0]);
        assert_eq!(&bytes[8..14], &s.data[6..12]);
        assert!(Stream::from_f32("VEC3", &[[1.0, 2.0, 3.0]]).padded_to_4().is_none());
        assert_eq!(Stream::from_f32("VEC2", &[[1.0, -2.0]]).bounds().unwrap().0.to_string(), "[1.0,-2.0]");
    }

    #[test]
    fn the_step_is_that_of_the_bits_the_values_were_quantized_to() {
        // 12-bit UVs stored as normalized 16-bit integers, as glTF-Transform writes them.
        let raw: Vec<u16> = (0..4095u32).step_by(7).map(|q| (q as f64 * 65535.0 / 4095.0).round() as u16).collect();
        let s = Stream {
            format: Format { component_type: UNSIGNED_SHORT, ty: "VEC2".into(), normalized: true },
            data: raw.iter().flat_map(|x| x.to_le_bytes()).collect(),
            template: None,
        };
        assert_eq!(s.step(), 1.0 / 4095.0);
        let full: Vec<u16> = (0..100u16).map(|x| x * 601 + 3).collect();
        let s = Stream { data: full.iter().flat_map(|x| x.to_le_bytes()).collect(), ..s };
        // Within one stored unit, every integer is a multiple of the 15-bit step.
        assert!(s.step() <= 1.0 / 32767.0, "{}", s.step());
        assert_eq!(Stream::from_f32("VEC2", &[[0.5, 0.5]]).step(), 0.0);
    }

    #[test]
    fn indices_above_two_to_the_24_are_exact() {
        let big = [16_777_217u32, u32::MAX - 1, 7];
        let s = Stream {
            format: Format { component_type: UNSIGNED_INT, ty: "SCALAR".into(), normalized: false },
            data: big.iter().flat_map(|i| i.to_le_bytes()).collect(),
            template: None,
        };
        assert_eq!(s.to_u32(), big);
        let s = Stream {
            format: Format { component_type: UNSIGNED_SHORT, ty: "SCALAR".into(), normalized: false },
            data: vec![0xff, 0xff, 1, 0],
            template: None,
        };
        assert_eq!(s.to_u32(), [65535, 1]);
    }

    #[test]
    fn float_and_normalised_streams_read_the_same_through_both_paths() {
        let f = Stream::from_f32("VEC3", &[[1.5, -0.0, 3e38], [f32::MIN_POSITIVE, 2.0, -7.25]]);
        assert_eq!(f.to_f32::<3>(), [[1.5, -0.0, 3e38], [f32::MIN_POSITIVE, 2.0, -7.25]]);
        assert_eq!(f.to_f32::<2>(), [[1.5, -0.0], [f32::MIN_POSITIVE, 2.0]]);
        assert_eq!(f.to_f32::<4>(), [[1.5, -0.0, 3e38, 0.0], [f32::MIN_POSITIVE, 2.0, -7.25, 0.0]]);
        let n = Stream {
            format: Format { component_type: UNSIGNED_BYTE, ty: "VEC2".into(), normalized: true },
            data: vec![255, 0, 51, 102],
            template: None,
        };
        assert_eq!(n.to_f32::<2>(), [[1.0, 0.0], [0.2, 0.4]]);
        assert_eq!(&*n.as_f32::<2>(), [[1.0, 0.0], [0.2, 0.4]]);
        assert_eq!(&*f.as_f32::<3>(), &*f.to_f32::<3>());
        assert!(
            matches!(f.as_f32::<3>(), std::borrow::Cow::Borrowed(_)) || !(f.data.as_ptr() as usize).is_multiple_of(4)
        );
        // Misaligned bytes are converted, not misread.
        let mut shifted = vec![0u8];
        shifted.extend_from_slice(&f.data);
        let g = Stream { data: shifted[1..].to_vec(), ..f.clone() };
        assert_eq!(&*g.as_f32::<3>(), &*f.to_f32::<3>());
    }
}
