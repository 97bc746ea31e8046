//! A range's items copied where its builders (`range.rs`, `small.rs`) address them by one-byte
//! index: each box and centre computed once, the centres also by axis.

use super::bounds::{Aabb, Item};
use glam::Vec3A;

/// The most items a range built here holds: an index fits a byte.
pub(super) const LOCAL: usize = 256;

/// The range's items as given, their boxes and their centres, by index.
pub(super) struct Local {
    pub was: [Item; LOCAL],
    pub bounds: [Aabb; LOCAL],
    pub centre: [Vec3A; LOCAL],
    /// The centres by axis, for the binning: one load an item, along the axis split.
    pub along: [[f32; LOCAL]; 3],
    /// Per axis, the order the small-range split sorts by as one integer: the centre's bits made
    /// to order as the floats do, above the item's id (which breaks ties as the input's order).
    pub key: [[u64; LOCAL]; 3],
    /// How many triangles each item holds (1, or 2 for a pair).
    pub weight: [u8; LOCAL],
}

thread_local! {
    /// One buffer a thread, filled anew for each range: 28 KB that a new one per range would
    /// zero first (tens of thousands of ranges at 10M triangles).
    static BUFFER: std::cell::RefCell<Box<Local>> = std::cell::RefCell::new(Box::new(Local {
        was: [Item { min: [0.0; 3], max: [0.0; 3], id: 0 }; LOCAL],
        bounds: [Aabb::EMPTY; LOCAL],
        centre: [Vec3A::ZERO; LOCAL],
        along: [[0.0; LOCAL]; 3],
        key: [[0; LOCAL]; 3],
        weight: [0; LOCAL],
    }));
}

impl Local {
    /// Calls `f` with this thread's buffer, to be filled by [`Local::set`].
    pub fn with<R>(f: impl FnOnce(&mut Local) -> R) -> R {
        BUFFER.with(|b| f(&mut b.borrow_mut()))
    }

    /// Copies `it` (of `weight` triangles) into place `i`, with its box, centre and sort keys.
    #[inline]
    pub fn set(&mut self, i: usize, it: Item, weight: u8) {
        self.was[i] = it;
        self.weight[i] = weight;
        self.bounds[i] = it.bounds();
        let c = it.centre();
        self.centre[i] = c;
        for a in 0..3 {
            self.along[a][i] = c[a];
            self.key[a][i] = u64::from(ordered(c[a])) << 32 | u64::from(it.id);
        }
    }
}

/// `x`'s bits as an integer that orders as the floats do (-0 as +0, so that they tie as floats).
fn ordered(x: f32) -> u32 {
    let b = (x + 0.0).to_bits();
    if b >> 31 == 1 {
        !b
    } else {
        b | 1 << 31
    }
}

#[cfg(test)]
mod tests {
    use super::ordered;

    #[test]
    fn ordered_as_the_floats() {
        let xs = [f32::NEG_INFINITY, -3.5e30, -1.0, -1e-40, -0.0, 0.0, 1e-40, 0.5, 1.0, 7e20, f32::INFINITY];
        for a in xs {
            for b in xs {
                assert_eq!(ordered(a).cmp(&ordered(b)), a.partial_cmp(&b).expect("no NaN"), "{a} {b}");
            }
        }
    }
}
