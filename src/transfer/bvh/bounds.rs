//! Boxes, and the per-triangle records the builders sort.

use super::PARALLEL_MIN;
use glam::Vec3A;

/// An axis-aligned box; [`Aabb::EMPTY`] grows to the first point it meets.
#[derive(Clone, Copy)]
pub(super) struct Aabb {
    pub min: Vec3A,
    pub max: Vec3A,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb { min: Vec3A::splat(f32::INFINITY), max: Vec3A::splat(f32::NEG_INFINITY) };

    pub fn grow(&mut self, p: Vec3A) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    pub fn join(&mut self, o: &Aabb) {
        self.min = self.min.min(o.min);
        self.max = self.max.max(o.max);
    }

    /// Half the surface area: the surface area heuristic compares areas only with each other,
    /// so the factor of two is left out.
    pub fn area(&self) -> f32 {
        let d = self.max - self.min;
        if d.x < 0.0 {
            return 0.0;
        }
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

/// A triangle (or a quad's two halves, `pairs.rs`) as the build sorts it: 28 bytes, its box and
/// its index in the input (a pair's first triangle's). The centre
/// is recomputed from the box, in the same arithmetic every time, rather than stored, so that
/// the array the build moves around stays small.
#[derive(Clone, Copy)]
pub(super) struct Item {
    pub min: [f32; 3],
    pub max: [f32; 3],
    pub id: u32,
}

impl Item {
    /// Triangle `id`'s item, its corners `c`.
    pub fn of(c: &[[f32; 3]; 3], id: u32) -> Item {
        let mut b = Aabb::EMPTY;
        c.iter().for_each(|&p| b.grow(Vec3A::from(p)));
        Item { min: b.min.to_array(), max: b.max.to_array(), id }
    }

    pub fn bounds(&self) -> Aabb {
        Aabb { min: Vec3A::from(self.min), max: Vec3A::from(self.max) }
    }

    pub fn centre(&self) -> Vec3A {
        (Vec3A::from(self.min) + Vec3A::from(self.max)) * 0.5
    }
}

/// The items' bounds and their centres' bounds (on every core for a large range: min and max
/// give the same boxes in any grouping).
pub(super) fn bounds_of(items: &[Item]) -> (Aabb, Aabb) {
    bounds_by(items.len(), |i| items[i])
}

/// [`bounds_of`] the `n` items `item` gives.
fn bounds_by(n: usize, item: impl Fn(usize) -> Item + Sync) -> (Aabb, Aabb) {
    use rayon::prelude::*;
    let one = |r: std::ops::Range<usize>| {
        let (mut b, mut c) = (Aabb::EMPTY, Aabb::EMPTY);
        for it in r.map(&item) {
            b.join(&it.bounds());
            c.grow(it.centre());
        }
        (b, c)
    };
    if n < PARALLEL_MIN * 4 {
        return one(0..n);
    }
    (0..n.div_ceil(PARALLEL_MIN)).into_par_iter().map(|k| one(k * PARALLEL_MIN..n.min((k + 1) * PARALLEL_MIN))).reduce(
        || (Aabb::EMPTY, Aabb::EMPTY),
        |(mut b, mut c), (b2, c2)| {
            b.join(&b2);
            c.join(&c2);
            (b, c)
        },
    )
}
