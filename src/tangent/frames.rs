//! Per-corner frames, stored once per distinct value.
//!
//! MikkTSpace gives every corner of a smooth vertex the same frame, so a frame per corner
//! (16 bytes, three corners a triangle) repeats each value about six times on a typical mesh.
//! [`Frames`] keeps a 4-byte slot per corner and each value once (per group of corners the
//! engine summed together); a corner without an answer has no slot. For a million triangles
//! that is about 20 MB instead of 48.

/// The slot of a corner the reference gives no frame.
pub const NO_FRAME: u32 = u32::MAX;

#[derive(Debug, Clone, Default, PartialEq)]
pub struct Frames {
    /// Per corner: an index into `values`, or [`NO_FRAME`].
    pub slot: Vec<u32>,
    /// `(t.x, t.y, t.z, sign)`.
    pub values: Vec<[f32; 4]>,
}

impl Frames {
    /// One slot per corner, from flat per-corner frames (`w == 0` where there is none).
    pub fn from_flat(flat: Vec<[f32; 4]>) -> Frames {
        let slot = flat.iter().enumerate().map(|(i, t)| if t[3] == 0.0 { NO_FRAME } else { i as u32 }).collect();
        Frames { slot, values: flat }
    }

    /// Number of corners.
    pub fn len(&self) -> usize {
        self.slot.len()
    }

    pub fn is_empty(&self) -> bool {
        self.slot.is_empty()
    }

    /// Corner `c`'s frame, or `None`.
    #[inline]
    pub fn get(&self, c: usize) -> Option<[f32; 4]> {
        self.values.get(self.slot[c] as usize).copied()
    }

    /// Flat per-corner frames, `[0.0; 4]` where there is none.
    pub fn to_flat(&self) -> Vec<[f32; 4]> {
        (0..self.len()).map(|c| self.get(c).unwrap_or([0.0; 4])).collect()
    }

    /// Gives corner `c` a frame of its own.
    pub fn set(&mut self, c: usize, v: [f32; 4]) {
        self.slot[c] = self.values.len() as u32;
        self.values.push(v);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_round_trip_and_own_values() {
        let flat = vec![[1.0, 0.0, 0.0, 1.0], [0.0; 4], [0.0, 1.0, 0.0, -1.0]];
        let mut f = Frames::from_flat(flat.clone());
        assert_eq!(f.get(1), None);
        assert_eq!(f.to_flat(), flat);
        f.slot[2] = f.slot[0];
        f.set(1, [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(f.to_flat(), vec![[1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 1.0], [1.0, 0.0, 0.0, 1.0]]);
    }
}
