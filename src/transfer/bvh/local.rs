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
}

impl Local {
    /// The copies of `items` (1 to [`LOCAL`] of them).
    pub fn of(items: &[Item]) -> Local {
        let n = items.len();
        let mut l = Local {
            was: [items[0]; LOCAL],
            bounds: [Aabb::EMPTY; LOCAL],
            centre: [Vec3A::ZERO; LOCAL],
            along: [[0.0; LOCAL]; 3],
        };
        l.was[..n].copy_from_slice(items);
        for (i, it) in items.iter().enumerate() {
            l.bounds[i] = it.bounds();
            let c = it.centre();
            l.centre[i] = c;
            (0..3).for_each(|a| l.along[a][i] = c[a]);
        }
        l
    }
}
