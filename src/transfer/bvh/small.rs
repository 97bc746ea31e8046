//! Ranges of at most [`SMALL`] items: the exact SAH split (each boundary between the centres
//! sorted along their longest axis) and no bins, whose fixed cost (16 bins, two sweeps) dwarfs
//! the work on so few items. A node sorts its items only when its longest axis is not its
//! parent's: a run of a sorted order is sorted, so the order is the one a sort at every node
//! gives. The items are one-byte indices into the range's boxes and centres (`range.rs`).

use super::bounds::Aabb;
use super::cost::{longest, MAX_LEAF, SMALL};
use super::local::Local;
use super::node::Node;

/// Builds the subtree over the items `idx` of `l` (at most [`SMALL`], their triangles starting
/// at `offset` in leaf order, with bounds `b`) into `nodes`, and leaves `idx` in leaf order.
pub(super) fn build(l: &Local, idx: &mut [u8], offset: usize, nodes: &mut Vec<Node>, b: Aabb) {
    debug_assert!((1..=SMALL).contains(&idx.len()));
    node(l, idx, offset, nodes, b, None);
}

/// The node over `idx`, sorted along axis `sorted` if some, with bounds `b`.
fn node(l: &Local, idx: &mut [u8], offset: usize, nodes: &mut Vec<Node>, b: Aabb, sorted: Option<usize>) {
    let len = idx.len();
    let weight: usize = idx.iter().map(|&i| l.weight[i as usize] as usize).sum();
    if weight <= MAX_LEAF {
        nodes.push(Node::leaf(&b, offset, weight));
        return;
    }
    let mut c = Aabb::EMPTY;
    idx.iter().for_each(|&i| c.grow(l.centre[i as usize]));
    let axis = longest(c.max - c.min);
    if sorted != Some(axis) {
        // Insertion sort: a handful of items; the key's id breaks ties as the input's order.
        let key = &l.key[axis];
        for i in 1..len {
            let (x, kx) = (idx[i], key[idx[i] as usize]);
            let mut j = i;
            while j > 0 && key[idx[j - 1] as usize] > kx {
                idx[j] = idx[j - 1];
                j -= 1;
            }
            idx[j] = x;
        }
    }
    // Triangles before each place (an item may be a pair, `pairs.rs`).
    let mut before = [0usize; SMALL + 1];
    for t in 0..len {
        before[t + 1] = before[t] + l.weight[idx[t] as usize] as usize;
    }
    // Both sweeps in one loop, for two chains of joins the core runs side by side: `left[k]` and
    // `right[k]` are the boxes of the items before and from place `k`.
    let bounds = |k: usize| &l.bounds[idx[k] as usize];
    let (mut left, mut right) = ([Aabb::EMPTY; SMALL], [Aabb::EMPTY; SMALL]);
    let (mut la, mut ra) = ([0.0f32; SMALL], [0.0f32; SMALL]);
    let (mut accl, mut accr) = (Aabb::EMPTY, Aabb::EMPTY);
    for t in 1..len {
        accl.join(bounds(t - 1));
        left[t] = accl;
        la[t] = accl.area() * before[t] as f32;
        accr.join(bounds(len - t));
        right[len - t] = accr;
        ra[len - t] = accr.area() * (weight - before[len - t]) as f32;
    }
    let mut best = (f32::INFINITY, 0);
    for k in 1..len {
        let cost = la[k] + ra[k];
        if cost < best.0 {
            best = (cost, k);
        }
    }
    let (_, k) = best;
    // No finite cost (boxes too large for f32 areas): halves.
    let k = if k == 0 { len / 2 } else { k };
    let (lb, rb) = (left[k], right[k]);
    let me = nodes.len();
    nodes.push(Node::inner(&b, 0));
    let (lo, hi) = idx.split_at_mut(k);
    node(l, lo, offset, nodes, lb, Some(axis));
    nodes[me].right_or_first = nodes.len() as u32;
    node(l, hi, offset + before[k], nodes, rb, Some(axis));
}
