//! A range of at most `LOCAL` (256) items (every Morton range, and the bottom of every SAH
//! subtree), built on copies of its items' boxes and centres held by the builder: the splits move
//! one-byte indices instead of 28-byte items, each centre is computed once instead of at every
//! level, an item's bin is kept from the binning for the partition, and the partition moves its
//! indices without branches. The items are put in leaf order once, at the end. The splits are
//! those of `sah.rs` exactly, and the partition leaves the same order as its swaps.

use super::bounds::{Aabb, Item};
use super::cost::{self, Bins, BINS, MAX_LEAF, SMALL};
use super::local::{Local, LOCAL};
use super::node::Node;
use super::small;

/// Builds the subtree over `items` (at most [`LOCAL`], starting at `offset` in leaf order, with
/// bounds and centre bounds `bc`) into `nodes`, and leaves `items` in leaf order.
pub(super) fn build(items: &mut [Item], offset: usize, nodes: &mut Vec<Node>, bc: (Aabb, Aabb)) {
    debug_assert!((1..=LOCAL).contains(&items.len()));
    Local::with(|l| {
        items.iter().enumerate().for_each(|(i, &it)| l.set(i, it, 1));
        let idx = l.run(items.len(), offset, nodes, bc);
        for (it, &i) in items.iter_mut().zip(&idx) {
            *it = l.was[i as usize];
        }
    });
}

/// [`build`] over the items `item(k)` for each `k` in `ids` (at most [`LOCAL`]), each with the
/// count of triangles it holds, made where they are rather than gathered first; `offset` and
/// the leaves count triangles. Leaves `ids` holding the items' ids in leaf order.
pub(super) fn build_by_index(
    item: impl Fn(usize) -> (Item, u8),
    ids: &mut [u64],
    offset: usize,
    nodes: &mut Vec<Node>,
) {
    debug_assert!((1..=LOCAL).contains(&ids.len()));
    Local::with(|l| {
        let (mut b, mut c) = (Aabb::EMPTY, Aabb::EMPTY);
        for (i, &k) in ids.iter().enumerate() {
            let (it, weight) = item(k as usize);
            l.set(i, it, weight);
            b.join(&l.bounds[i]);
            c.grow(l.centre[i]);
        }
        let idx = l.run(ids.len(), offset, nodes, (b, c));
        for (x, &i) in ids.iter_mut().zip(&idx) {
            *x = u64::from(l.was[i as usize].id);
        }
    });
}

impl Local {
    /// Builds the subtree over the first `n` places; returns them in leaf order.
    fn run(&self, n: usize, offset: usize, nodes: &mut Vec<Node>, bc: (Aabb, Aabb)) -> [u8; LOCAL] {
        let mut idx = [0u8; LOCAL];
        idx.iter_mut().take(n).enumerate().for_each(|(i, x)| *x = i as u8);
        let weight = self.weight[..n].iter().map(|&w| w as usize).sum();
        self.serial(&mut idx[..n], offset, nodes, bc, weight);
        idx
    }

    /// As `sah::build_serial`, over the items `idx` (holding `weight` triangles), which it
    /// leaves in leaf order.
    fn serial(&self, idx: &mut [u8], offset: usize, nodes: &mut Vec<Node>, (b, c): (Aabb, Aabb), weight: usize) {
        if idx.len() <= SMALL {
            small::build(self, idx, offset, nodes, b);
            return;
        }
        let me = nodes.len();
        let (mid, left, lb, rb) = match self.split(idx, &c, weight) {
            Some((sp, which)) => (partition(idx, &which, sp.bin), sp.left_count, sp.left, sp.right),
            None if weight <= MAX_LEAF * 2 => {
                nodes.push(Node::leaf(&b, offset, weight));
                return;
            }
            None => self.halves(idx),
        };
        nodes.push(Node::inner(&b, 0));
        let (l, r) = idx.split_at_mut(mid);
        self.serial(l, offset, nodes, lb, left);
        nodes[me].right_or_first = nodes.len() as u32;
        self.serial(r, offset + left, nodes, rb, weight - left);
    }

    /// As `sah::split`, with each item's bin (by its place in `idx`) for the partition.
    fn split(&self, idx: &[u8], c: &Aabb, weight: usize) -> Option<(cost::Split, [u8; LOCAL])> {
        let extent = c.max - c.min;
        let axis = cost::longest(extent);
        let e = extent[axis];
        if e.is_nan() || e <= 0.0 {
            return None;
        }
        let (lo, scale) = (c.min[axis], BINS as f32 / (c.max[axis] - c.min[axis]));
        let along = &self.along[axis];
        let mut bins: Bins = [(Aabb::EMPTY, Aabb::EMPTY, 0usize); BINS];
        let mut which = [0u8; LOCAL];
        for (w, &i) in which.iter_mut().zip(idx) {
            let i = i as usize;
            // `as u32` floors and saturates as `sah::bin`'s `as usize` does for any value here
            // (at least 0, or NaN), in fewer instructions.
            let k = (((along[i] - lo) * scale) as u32).min(BINS as u32 - 1) as usize;
            bins[k].0.join(&self.bounds[i]);
            bins[k].1.grow(self.centre[i]);
            bins[k].2 += self.weight[i] as usize;
            *w = k as u8;
        }
        cost::choose(&bins, weight, axis).map(|sp| (sp, which))
    }

    /// As `sah::halves`: two halves of equal count (centres that cannot be told apart), and the
    /// triangles the first holds.
    fn halves(&self, idx: &[u8]) -> (usize, usize, (Aabb, Aabb), (Aabb, Aabb)) {
        let mid = idx.len() / 2;
        let left = idx[..mid].iter().map(|&i| self.weight[i as usize] as usize).sum();
        let bounds = |s: &[u8]| {
            let (mut b, mut c) = (Aabb::EMPTY, Aabb::EMPTY);
            for &i in s {
                b.join(&self.bounds[i as usize]);
                c.grow(self.centre[i as usize]);
            }
            (b, c)
        };
        (mid, left, bounds(&idx[..mid]), bounds(&idx[mid..]))
    }
}

/// Moves the items whose bin (`which`, by place) is below `k` to the front, in the order
/// `sah::partition`'s swaps leave; returns how many there are. Each step writes both places
/// whichever side the item is on, so the loop has no branch to mispredict (half of them would
/// be: an item's side is a coin toss).
fn partition(idx: &mut [u8], which: &[u8; LOCAL], k: usize) -> usize {
    let mut i = 0;
    for (j, &w) in which.iter().enumerate().take(idx.len()) {
        let left = (w as usize) < k;
        let (a, b) = (idx[i], idx[j]);
        idx[i] = if left { b } else { a };
        idx[j] = if left { a } else { b };
        i += left as usize;
    }
    i
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The branch-free partition leaves the order of the swaps it stands for.
    #[test]
    fn partition_as_the_swaps_leave() {
        let mut x = crate::test_rng::XorShift32(0x2545_f491);
        for n in [1, 2, 17, 100, 256] {
            for k in 0..=BINS {
                let mut which = [0u8; LOCAL];
                which.iter_mut().take(n).for_each(|w| *w = (x.next() % BINS as u32) as u8);
                let mut want: Vec<u8> = (0..n).map(|i| i as u8).collect();
                let mut i = 0;
                for (j, &w) in which.iter().enumerate().take(n) {
                    if (w as usize) < k {
                        want.swap(i, j);
                        i += 1;
                    }
                }
                let mut got: Vec<u8> = (0..n).map(|i| i as u8).collect();
                assert_eq!(partition(&mut got, &which, k), i);
                assert_eq!(got, want, "{n} items, boundary {k}");
            }
        }
    }
}
