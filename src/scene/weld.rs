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
    weld_from(attributes, targets, mode, None)
}

/// [`weld`], told which vertex each corner was unwelded from. Corners of one original vertex are
/// usually equal, so each is first compared with the vertices its origin already produced (a
/// byte compare, no hashing); only a corner unlike all of them is looked up among all vertices.
/// The result is the same as without `origin`.
pub fn weld_from(attributes: Vec<(String, Stream)>, targets: Vec<Vec<(String, Stream)>>, mode: u32, origin: Option<&[u32]>) -> Primitive {
    let all: Vec<&Stream> = attributes.iter().map(|(_, s)| s).chain(targets.iter().flatten().map(|(_, s)| s)).collect();
    let corners = all.first().map(|s| s.len()).unwrap_or(0);
    let stride: usize = all.iter().map(|s| s.format.elem_size()).sum();
    let mut keys = Vec::with_capacity(corners * stride);
    for c in 0..corners {
        for s in &all {
            keys.extend_from_slice(s.elem(c));
        }
    }
    let key = |c: usize| &keys[c * stride..(c + 1) * stride];
    let origin = origin.filter(|o| o.len() == corners);
    let n_origins = origin.map(|o| o.iter().map(|&v| v as usize + 1).max().unwrap_or(0)).unwrap_or(0);
    // Vertices made from each origin: the first inline, any further ones in a side table.
    let mut made_first = vec![u32::MAX; n_origins];
    let mut made_more: HashMap<u32, Vec<u32>, BuildHasherDefault<Fx>> = HashMap::default();
    let mut first: HashMap<&[u8], u32, BuildHasherDefault<Fx>> = HashMap::with_capacity_and_hasher(if origin.is_some() { corners / 4 } else { corners }, Default::default());
    let mut order: Vec<u32> = Vec::new();
    let mut indices = Vec::with_capacity(corners);
    for c in 0..corners {
        let k = key(c);
        let local = origin.and_then(|o| {
            let v = o[c];
            let f = made_first[v as usize];
            if f == u32::MAX {
                return None;
            }
            std::iter::once(f).chain(made_more.get(&v).into_iter().flatten().copied()).find(|&m| key(order[m as usize] as usize) == k)
        });
        let vertex = match local {
            Some(m) => m,
            None => {
                let next = order.len() as u32;
                let m = *first.entry(k).or_insert_with(|| {
                    order.push(c as u32);
                    next
                });
                if let Some(o) = origin {
                    let v = o[c];
                    if made_first[v as usize] == u32::MAX {
                        made_first[v as usize] = m;
                    } else {
                        made_more.entry(v).or_default().push(m);
                    }
                }
                m
            }
        };
        indices.push(vertex);
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

    #[test]
    fn origin_shortcut_gives_the_same_result() {
        // Corner origins: 0,1,0,0,2 where origin 0's third corner differs, and origin 2 equals
        // origin 1's bytes (so it merges across origins).
        let uv = Stream::from_f32("VEC2", &[[0.0, 0.0], [1.0, 0.0], [0.0, 0.0], [0.5, 0.0], [1.0, 0.0]]);
        let plain = weld(vec![("TEXCOORD_0".into(), uv.clone())], vec![], 4);
        let fast = weld_from(vec![("TEXCOORD_0".into(), uv)], vec![], 4, Some(&[0, 1, 0, 0, 2]));
        assert_eq!(plain, fast);
        assert_eq!(fast.indices, vec![0, 1, 0, 2, 1]);
    }
}
