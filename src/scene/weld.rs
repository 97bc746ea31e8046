//! Turning per-corner attributes into indexed vertices: corners whose every attribute is equal,
//! byte for byte, become one vertex; all others stay apart. Vertices are numbered in the order
//! their first corner appears, so the result is deterministic.

use super::{Primitive, Stream};
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// FxHash (rustc's): the keys are attribute bytes we made ourselves, so a fast non-keyed hash is
/// safe, and SipHash would cost more than the rest of the weld.
#[derive(Default)]
struct Fx(u64);

impl Hasher for Fx {
    fn write(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            self.add(u64::from_le_bytes(c.try_into().expect("8 bytes")));
        }
        for &b in chunks.remainder() {
            self.add(b as u64);
        }
    }
    fn write_usize(&mut self, n: usize) {
        self.add(n as u64);
    }
    fn finish(&self) -> u64 {
        self.0
    }
}

impl Fx {
    fn add(&mut self, w: u64) {
        self.0 = (self.0.rotate_left(5) ^ w).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

/// Builds an indexed primitive from streams that hold one element per corner.
pub fn weld(attributes: Vec<(String, Stream)>, targets: Vec<Vec<(String, Stream)>>, mode: u32) -> Primitive {
    let all: Vec<&Stream> = attributes.iter().map(|(_, s)| s).chain(targets.iter().flatten().map(|(_, s)| s)).collect();
    let corners = all.first().map(|s| s.len()).unwrap_or(0);
    let stride: usize = all.iter().map(|s| s.format.elem_size()).sum();
    let mut keys = Vec::with_capacity(corners * stride);
    for c in 0..corners {
        for s in &all {
            keys.extend_from_slice(s.elem(c));
        }
    }
    let mut first: HashMap<&[u8], u32, BuildHasherDefault<Fx>> = HashMap::with_capacity_and_hasher(corners, Default::default());
    let mut order: Vec<u32> = Vec::new();
    let mut indices = Vec::with_capacity(corners);
    for c in 0..corners {
        let key = &keys[c * stride..(c + 1) * stride];
        let next = order.len() as u32;
        let v = *first.entry(key).or_insert_with(|| {
            order.push(c as u32);
            next
        });
        indices.push(v);
    }
    let gather = |list: Vec<(String, Stream)>| list.into_iter().map(|(n, s)| (n, s.gather(&order))).collect::<Vec<_>>();
    Primitive {
        attributes: gather(attributes),
        targets: targets.into_iter().map(gather).collect(),
        indices,
        mode,
    }
}

/// Expands an indexed primitive to one element per corner (the inverse of [`weld`]).
pub fn unweld(p: &Primitive) -> (Vec<(String, Stream)>, Vec<Vec<(String, Stream)>>) {
    let per_corner = |list: &Vec<(String, Stream)>| list.iter().map(|(n, s)| (n.clone(), s.gather(&p.indices))).collect::<Vec<_>>();
    (per_corner(&p.attributes), p.targets.iter().map(per_corner).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_corners_merge_and_different_ones_split() {
        let pos = Stream::from_f32("VEC3", &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]);
        let uv = Stream::from_f32("VEC2", &[[0.0, 0.0], [1.0, 0.0], [0.0, 0.0], [0.5, 0.0]]);
        let p = weld(vec![("POSITION".into(), pos), ("TEXCOORD_0".into(), uv)], vec![], 4);
        assert_eq!(p.indices, vec![0, 1, 0, 2]);
        assert_eq!(p.vertex_count(), 3);
        assert_eq!(p.attr("TEXCOORD_0").unwrap().to_f32::<2>()[2], [0.5, 0.0]);
        let (attrs, _) = unweld(&p);
        assert_eq!(attrs[1].1.to_f32::<2>(), vec![[0.0, 0.0], [1.0, 0.0], [0.0, 0.0], [0.5, 0.0]]);
    }
}
