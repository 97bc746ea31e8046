//! Accessor layouts and the raw, tightly packed vertex streams the model keeps.

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

#[cfg(test)]
mod tests {
    use super::*;

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
