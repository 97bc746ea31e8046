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
        let s = self.format.elem_size();
        if s == 0 {
            0
        } else {
            self.data.len() / s
        }
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
        (0..self.len())
            .map(|i| {
                let mut v = [0.0; N];
                for (c, x) in v.iter_mut().enumerate().take(self.format.components()) {
                    *x = self.get(i, c);
                }
                v
            })
            .collect()
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
