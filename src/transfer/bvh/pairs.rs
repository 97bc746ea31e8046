//! Neighbouring triangles built as one item: a triangle and the next in the input that shares an
//! edge with it (the two halves of a quad, as modellers, scanners and exporters write them) get
//! one box, one Morton key and one place in a range. The large build then sorts, bins and
//! collapses about half as many items, and a leaf holds the two together, as the tree over
//! single triangles mostly put them anyway (Embree builds over such pairs for the same reason).

use super::bounds::{Aabb, Item};
use glam::Vec3A;

/// Triangles are paired within fixed chunks of this many (a multiple of 64, so that a chunk's
/// bits are whole words): the pairs, and so the tree, are the same on any thread count.
const CHUNK: usize = 64 * 1024;

/// Which triangles are paired with the next: bit `t` set when triangles `t` and `t + 1` are one
/// item, whose id is `t`.
pub(super) struct Pairs {
    first: Vec<u64>,
}

/// What one pass over the triangles gives: the pairs, each item's id (its first triangle) in
/// input order, and the bounds of the items' centres.
pub(super) struct Found {
    pub pairs: Pairs,
    pub ids: Vec<u32>,
    pub centres: Aabb,
}

impl Pairs {
    /// How many triangles the item `t` holds (1 or 2); `t` must be an item's id.
    #[inline]
    pub fn size(&self, t: u32) -> u32 {
        1 + (self.first[t as usize / 64] >> (t % 64) & 1) as u32
    }

    /// The box of item `t`, from `item` of each triangle.
    #[inline]
    pub fn item(&self, t: u32, item: impl Fn(usize) -> Item) -> Item {
        let it = item(t as usize);
        if self.size(t) == 2 {
            return joined(it, &item(t as usize + 1));
        }
        it
    }
}

/// `it` grown to hold `o` too.
fn joined(mut it: Item, o: &Item) -> Item {
    it.min = Vec3A::from(it.min).min(Vec3A::from(o.min)).to_array();
    it.max = Vec3A::from(it.max).max(Vec3A::from(o.max)).to_array();
    it
}

/// Pairs each triangle with the next when they share an edge (two corners at the same position)
/// and the first is not already the second of a pair, greedily in input order within each
/// chunk; `corners(t)` gives triangle `t`'s corners.
pub(super) fn find(n: usize, corners: impl Fn(usize) -> [[f32; 3]; 3] + Sync) -> Found {
    use rayon::prelude::*;
    let chunks: Vec<(Vec<u64>, Vec<u32>, Aabb)> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let (start, end) = (c * CHUNK, n.min((c + 1) * CHUNK));
            let mut words = vec![0u64; (end - start).div_ceil(64)];
            let mut ids = Vec::with_capacity((end - start) / 2 + 1);
            let mut centres = Aabb::EMPTY;
            let mut t = start;
            let mut next = (t < end).then(|| corners(t));
            while let Some(a) = next {
                let after = (t + 1 < end).then(|| corners(t + 1));
                let mut it = Item::of(&a, t as u32);
                ids.push(t as u32);
                match after.filter(|o| shares_edge(&a, o)) {
                    Some(o) => {
                        words[(t - start) / 64] |= 1 << ((t - start) % 64);
                        it = joined(it, &Item::of(&o, t as u32));
                        t += 2;
                        next = (t < end).then(|| corners(t));
                    }
                    None => {
                        t += 1;
                        next = after;
                    }
                }
                centres.grow(it.centre());
            }
            (words, ids, centres)
        })
        .collect();
    let mut first = Vec::with_capacity(n.div_ceil(64));
    let mut ids = Vec::with_capacity(chunks.iter().map(|c| c.1.len()).sum());
    let mut centres = Aabb::EMPTY;
    for (w, i, c) in chunks {
        first.extend(w);
        ids.extend(i);
        centres.join(&c);
    }
    Found { pairs: Pairs { first }, ids, centres }
}

/// Whether two of `b`'s corners are at positions of `a`'s (bit for bit: the corners a mesh
/// shares, whether through one index or two).
fn shares_edge(a: &[[f32; 3]; 3], b: &[[f32; 3]; 3]) -> bool {
    // Spelled out rather than through arrays' `map`, which is left out of line here (see
    // `Bvh::build_indexed`).
    let bits = |p: &[f32; 3]| [p[0].to_bits(), p[1].to_bits(), p[2].to_bits()];
    let a = [bits(&a[0]), bits(&a[1]), bits(&a[2])];
    let shared = |p: &[f32; 3]| a.contains(&bits(p)) as u32;
    shared(&b[0]) + shared(&b[1]) + shared(&b[2]) >= 2
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri_item(c: &[[f32; 3]; 3], id: u32) -> Item {
        let mut b = Aabb::EMPTY;
        c.iter().for_each(|&p| b.grow(p.into()));
        Item { min: b.min.to_array(), max: b.max.to_array(), id }
    }

    /// Quads' halves pair; a triangle sharing one corner, or none, stays alone; a triangle is in
    /// one pair at most (the third of a fan goes alone), and pairs never cross a chunk.
    #[test]
    fn pairs_share_an_edge() {
        let q = |x: f32| {
            let p = |a: f32, b: f32| [x + a, b, 0.0];
            [[p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0)], [p(0.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)]]
        };
        let mut tris = Vec::new();
        tris.extend(q(0.0));
        // One shared corner only (with the quad's last), then a fan of three around it.
        tris.push([[1.0, 1.0, 0.0], [5.0, 5.0, 0.0], [6.0, 5.0, 0.0]]);
        tris.push([[9.0, 9.0, 0.0], [10.0, 9.0, 0.0], [9.0, 10.0, 0.0]]);
        tris.push([[9.0, 9.0, 0.0], [9.0, 10.0, 0.0], [8.0, 10.0, 0.0]]);
        tris.push([[9.0, 9.0, 0.0], [8.0, 10.0, 0.0], [8.0, 9.0, 0.0]]);
        let f = find(tris.len(), |t| tris[t]);
        assert_eq!(f.ids, vec![0, 2, 3, 5]);
        assert_eq!(f.ids.iter().map(|&t| f.pairs.size(t)).collect::<Vec<_>>(), vec![2, 1, 2, 1]);
        let pair = f.pairs.item(3, |t| tri_item(&tris[t], t as u32));
        assert_eq!((pair.min, pair.max, pair.id), ([8.0, 9.0, 0.0], [10.0, 10.0, 0.0], 3));
        assert_eq!((f.centres.min.to_array(), f.centres.max.to_array()), ([0.5, 0.5, 0.0], [9.0, 9.5, 0.0]));

        // A strip of quads across a chunk's end: the quad that straddles it is two items.
        let quads = CHUNK / 2 + 1;
        let mut tris: Vec<[[f32; 3]; 3]> = (0..quads).flat_map(|k| q(k as f32)).collect();
        tris.insert(0, [[-5.0, 0.0, 0.0], [-4.0, 0.0, 0.0], [-5.0, 1.0, 0.0]]);
        let f = find(tris.len(), |t| tris[t]);
        let sizes: u32 = f.ids.iter().map(|&t| f.pairs.size(t)).sum();
        assert_eq!(sizes as usize, tris.len(), "every triangle in one item");
        assert_eq!(f.pairs.size(CHUNK as u32 - 1), 1);
        assert_eq!(f.ids.len(), 1 + (quads - 1) + 2);
    }
}
