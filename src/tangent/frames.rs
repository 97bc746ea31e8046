//! Per-corner frames, stored once per distinct value and found through the vertex.
//!
//! MikkTSpace gives every corner of a smooth vertex the same frame, so a frame per corner
//! (16 bytes, three corners a triangle) repeats each value about six times on a typical mesh.
//! [`Frames`] keeps each value once (per group of corners the engine summed together), a slot
//! per vertex, and a slot per corner only for the corners whose frame is not their vertex's
//! (tangent seams inside a vertex, corners without a frame beside corners with one). For a
//! million triangles that is about 10 MB instead of 48.

use crate::scene::weld::Fx;
use std::collections::HashMap;
use std::hash::BuildHasherDefault;

/// The slot of a corner the reference gives no frame.
const NO_FRAME: u32 = u32::MAX;
/// A vertex none of whose corners has been given a slot yet.
const UNSET: u32 = u32::MAX - 1;

type Overrides = HashMap<u32, u32, BuildHasherDefault<Fx>>;

/// Frames for the corners of an index list; read with the corner and its vertex.
#[derive(Debug, Clone)]
pub struct Frames {
    /// Per vertex: the slot of its corners, or [`NO_FRAME`].
    vertex: Vec<u32>,
    /// Corners whose slot is not their vertex's.
    corner: Overrides,
    /// `(t.x, t.y, t.z, sign)`.
    pub values: Vec<[f32; 4]>,
}

impl Frames {
    /// One value per corner, from flat per-corner frames (`w == 0` where there is none).
    pub fn from_flat(idx: &[u32], flat: Vec<[f32; 4]>) -> Frames {
        let mut b = Builder::new(idx);
        for (c, t) in flat.iter().enumerate() {
            if t[3] != 0.0 {
                b.put(c, c as u32);
            }
        }
        b.finish(flat)
    }

    /// No frame for any corner.
    pub fn none(idx: &[u32]) -> Frames {
        Builder::new(idx).finish(Vec::new())
    }

    /// The frame of corner `c` of vertex `v` (`idx[c]` of the index list the frames were made
    /// for), or `None`.
    #[inline]
    pub fn get(&self, c: usize, v: u32) -> Option<[f32; 4]> {
        let slot = if self.corner.is_empty() { None } else { self.corner.get(&(c as u32)).copied() };
        let slot = slot.unwrap_or_else(|| self.vertex[v as usize]);
        self.values.get(slot as usize).copied()
    }

    /// Flat per-corner frames, `[0.0; 4]` where there is none.
    pub fn to_flat(&self, idx: &[u32]) -> Vec<[f32; 4]> {
        idx.iter().enumerate().map(|(c, &v)| self.get(c, v).unwrap_or([0.0; 4])).collect()
    }

    /// Gives corner `c` a frame of its own.
    pub fn set(&mut self, c: usize, v: [f32; 4]) {
        self.corner.insert(c as u32, self.values.len() as u32);
        self.values.push(v);
    }
}

/// Builds [`Frames`] from slots given corner by corner.
pub(crate) struct Builder<'a> {
    idx: &'a [u32],
    vertex: Vec<u32>,
    corner: Overrides,
    /// One bit per corner that was given a slot.
    given: Vec<u64>,
}

impl<'a> Builder<'a> {
    pub(crate) fn new(idx: &'a [u32]) -> Builder<'a> {
        let n_vertices = idx.iter().map(|&v| v as usize + 1).max().unwrap_or(0);
        Builder {
            idx,
            vertex: vec![UNSET; n_vertices],
            corner: Overrides::default(),
            given: vec![0; idx.len().div_ceil(64)],
        }
    }

    /// Corner `c` gets value `slot`. Each corner at most once.
    #[inline]
    pub(crate) fn put(&mut self, c: usize, slot: u32) {
        self.given[c / 64] |= 1 << (c % 64);
        let v = &mut self.vertex[self.idx[c] as usize];
        if *v == UNSET {
            *v = slot;
        } else if *v != slot {
            self.corner.insert(c as u32, slot);
        }
    }

    /// The slot corner `c` was given, if any.
    #[inline]
    pub(crate) fn slot(&self, c: usize) -> Option<u32> {
        if self.given[c / 64] & (1 << (c % 64)) == 0 {
            return None;
        }
        Some(self.corner.get(&(c as u32)).copied().unwrap_or(self.vertex[self.idx[c] as usize]))
    }

    /// Corners never given a slot have no frame.
    pub(crate) fn finish(mut self, values: Vec<[f32; 4]>) -> Frames {
        for (c, &v) in self.idx.iter().enumerate() {
            if self.given[c / 64] & (1 << (c % 64)) == 0 && self.vertex[v as usize] != UNSET {
                self.corner.insert(c as u32, NO_FRAME);
            }
        }
        for v in &mut self.vertex {
            if *v == UNSET {
                *v = NO_FRAME;
            }
        }
        Frames { vertex: self.vertex, corner: self.corner, values }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_share_their_vertex_value_unless_they_differ() {
        // Vertex 0 has three corners: two share a frame, one has another, one has none.
        let idx = [0, 1, 0, 0, 2, 3];
        let flat = vec![
            [1.0, 0.0, 0.0, 1.0],
            [0.0, 1.0, 0.0, 1.0],
            [1.0, 0.0, 0.0, 1.0],
            [0.0; 4],
            [0.0; 4],
            [0.0, 0.0, 1.0, -1.0],
        ];
        let mut b = Builder::new(&idx);
        let values = vec![flat[0], flat[1], flat[5]];
        b.put(0, 0);
        b.put(1, 1);
        b.put(2, 0);
        b.put(5, 2);
        assert_eq!(b.slot(2), Some(0));
        assert_eq!(b.slot(3), None);
        let mut f = b.finish(values);
        assert_eq!(f.to_flat(&idx), flat);
        assert_eq!(f.corner.len(), 1, "only corner 3 differs from its vertex");
        assert_eq!(Frames::from_flat(&idx, flat.clone()).to_flat(&idx), flat);
        f.set(4, [0.0, 1.0, 0.0, -1.0]);
        assert_eq!(f.get(4, 2), Some([0.0, 1.0, 0.0, -1.0]));
        assert_eq!(f.get(3, 0), None);
        assert_eq!(Frames::none(&idx).to_flat(&idx), vec![[0.0; 4]; 6]);
    }
}
