//! Turning per-corner attributes into indexed vertices: corners whose every attribute is equal,
//! byte for byte, become one vertex; all others stay apart. Vertices are numbered in the order
//! their first corner appears, so the result is deterministic.

use super::{Primitive, Stream};
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// FxHash (rustc's): the keys are attribute bytes we made ourselves, so a fast non-keyed hash is
/// safe, and SipHash would cost more than the rest of the weld.
#[derive(Default)]
pub(crate) struct Fx(u64);

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
        let next = order.len() as u32;
        let v = *first.entry(&keys[c * stride..(c + 1) * stride]).or_insert_with(|| {
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

/// Re-indexes an indexed primitive to which per-corner streams are being added (tangents, flat
/// normals). The result is exactly [`weld`] of the unwelded primitive plus those streams, without
/// unwelding: a corner is compared with the vertices its own vertex already produced by its
/// per-corner bytes alone, and only a corner unlike all of them is looked up by its full bytes.
/// `extra` holds `(position, name, stream)`: where the stream goes among the attributes
/// (`usize::MAX` appends).
pub fn split_corners(base: &Primitive, extra: Vec<(usize, String, Stream)>) -> Primitive {
    let corners = base.indices.len();
    let extra_stride: usize = extra.iter().map(|(_, _, s)| s.format.elem_size()).sum();
    let mut ekeys = Vec::with_capacity(corners * extra_stride);
    for c in 0..corners {
        for (_, _, s) in &extra {
            ekeys.extend_from_slice(s.elem(c));
        }
    }
    let ekey = |c: usize| &ekeys[c * extra_stride..(c + 1) * extra_stride];
    let vertex_streams: Vec<&Stream> = base.attributes.iter().map(|(_, s)| s).chain(base.targets.iter().flatten().map(|(_, s)| s)).collect();
    let full_key = |c: usize| -> Box<[u8]> {
        let v = base.indices[c] as usize;
        let mut k = Vec::with_capacity(64);
        for s in &vertex_streams {
            k.extend_from_slice(s.elem(v));
        }
        k.extend_from_slice(ekey(c));
        k.into_boxed_slice()
    };
    let n_vertices = base.vertex_count().max(base.indices.iter().map(|&v| v as usize + 1).max().unwrap_or(0));
    let mut made_first = vec![u32::MAX; n_vertices];
    let mut made_more: HashMap<u32, Vec<u32>, BuildHasherDefault<Fx>> = HashMap::default();
    let mut global: HashMap<Box<[u8]>, u32, BuildHasherDefault<Fx>> = HashMap::with_capacity_and_hasher(n_vertices, Default::default());
    let mut order: Vec<u32> = Vec::new();
    let mut indices = Vec::with_capacity(corners);
    for c in 0..corners {
        let v = base.indices[c];
        let first = made_first[v as usize];
        let local = (first != u32::MAX)
            .then(|| std::iter::once(first).chain(made_more.get(&v).into_iter().flatten().copied()).find(|&m| ekey(order[m as usize] as usize) == ekey(c)))
            .flatten();
        let m = match local {
            Some(m) => m,
            None => {
                let next = order.len() as u32;
                let m = *global.entry(full_key(c)).or_insert_with(|| {
                    order.push(c as u32);
                    next
                });
                if first == u32::MAX {
                    made_first[v as usize] = m;
                } else {
                    made_more.entry(v).or_default().push(m);
                }
                m
            }
        };
        indices.push(m);
    }
    let origins: Vec<u32> = order.iter().map(|&c| base.indices[c as usize]).collect();
    let mut attributes: Vec<(String, Stream)> = base.attributes.iter().map(|(n, s)| (n.clone(), s.gather(&origins))).collect();
    for (at, name, s) in extra {
        let s = s.gather(&order);
        if at < attributes.len() {
            attributes.insert(at, (name, s));
        } else {
            attributes.push((name, s));
        }
    }
    Primitive {
        attributes,
        targets: base.targets.iter().map(|t| t.iter().map(|(n, s)| (n.clone(), s.gather(&origins))).collect()).collect(),
        indices,
        mode: base.mode,
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

    #[test]
    fn split_corners_splits_by_the_new_streams_and_merges_equal_vertices() {
        // Vertices 1 and 2 are byte-identical; vertex 0's last corner gets another tangent.
        let uv = Stream::from_f32("VEC2", &[[0.0, 0.0], [1.0, 0.0], [1.0, 0.0]]);
        let p = Primitive { attributes: vec![("TEXCOORD_0".into(), uv)], targets: vec![], indices: vec![0, 1, 2, 0], mode: 4 };
        let t = Stream::from_f32("VEC4", &[[1.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, 1.0], [-1.0, 0.0, 0.0, -1.0]]);
        let out = split_corners(&p, vec![(usize::MAX, "TANGENT".into(), t)]);
        assert_eq!(out.indices, vec![0, 1, 1, 2]);
        assert_eq!(out.attr("TANGENT").unwrap().to_f32::<4>()[2], [-1.0, 0.0, 0.0, -1.0]);
        assert_eq!(out.attributes.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>(), ["TEXCOORD_0", "TANGENT"]);
    }
}
