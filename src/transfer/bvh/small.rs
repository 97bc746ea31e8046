//! Ranges of at most [`SMALL`] triangles: the exact SAH split (each boundary between the centres
//! sorted along their longest axis) and no bins, whose fixed cost (16 bins, two sweeps) dwarfs
//! the work on so few items. A node sorts its items only when its longest axis is not its
//! parent's: a run of a sorted order is sorted, so the order is the one a sort at every node
//! gives. The items are one-byte indices into the range's boxes and centres (`range.rs`).

use super::bounds::Aabb;
use super::cost::{longest, MAX_LEAF, NODE_COST, SMALL};
use super::local::Local;
use super::node::Node;

/// Builds the subtree over the items `idx` of `l` (at most [`SMALL`], starting at `offset` in
/// leaf order, with bounds `b`) into `nodes`, and leaves `idx` in leaf order.
pub(super) fn build(l: &Local, idx: &mut [u8], offset: usize, nodes: &mut Vec<Node>, b: Aabb) {
    debug_assert!((1..=SMALL).contains(&idx.len()));
    node(l, idx, offset, nodes, b, None);
}

/// The node over `idx`, sorted along axis `sorted` if some, with bounds `b`.
fn node(l: &Local, idx: &mut [u8], offset: usize, nodes: &mut Vec<Node>, b: Aabb, sorted: Option<usize>) {
    let len = idx.len();
    if len == 1 {
        nodes.push(Node::leaf(&b, offset, 1));
        return;
    }
    let mut c = Aabb::EMPTY;
    idx.iter().for_each(|&i| c.grow(l.centre[i as usize]));
    let axis = longest(c.max - c.min);
    if sorted != Some(axis) {
        // Insertion sort: a handful of items; `id` breaks ties so the order is the input's.
        let key = |i: u8| (l.centre[i as usize][axis], l.was[i as usize].id);
        for i in 1..len {
            let mut j = i;
            while j > 0 && key(idx[j - 1]) > key(idx[j]) {
                idx.swap(j - 1, j);
                j -= 1;
            }
        }
    }
    let bounds = |k: usize| &l.bounds[idx[k] as usize];
    let mut right = [0.0f32; SMALL];
    let mut acc = Aabb::EMPTY;
    for k in (1..len).rev() {
        acc.join(bounds(k));
        right[k] = acc.area() * (len - k) as f32;
    }
    let (mut acc, mut best) = (Aabb::EMPTY, (f32::INFINITY, 0, Aabb::EMPTY));
    for (k, &r) in right.iter().enumerate().take(len).skip(1) {
        acc.join(bounds(k - 1));
        let cost = acc.area() * k as f32 + r;
        if cost < best.0 {
            best = (cost, k, acc);
        }
    }
    let (cost, k, lb) = best;
    // As in `sah::split`: a node visit costs two triangle tests.
    if len <= MAX_LEAF && cost + NODE_COST * b.area() >= b.area() * len as f32 {
        nodes.push(Node::leaf(&b, offset, len));
        return;
    }
    let join = |s: &[u8]| {
        let mut a = Aabb::EMPTY;
        s.iter().for_each(|&i| a.join(&l.bounds[i as usize]));
        a
    };
    // No finite cost (boxes too large for f32 areas): halves.
    let (k, lb) = if k == 0 { (len / 2, join(&idx[..len / 2])) } else { (k, lb) };
    let rb = join(&idx[k..]);
    let me = nodes.len();
    nodes.push(Node::inner(&b, 0));
    let (lo, hi) = idx.split_at_mut(k);
    node(l, lo, offset, nodes, lb, Some(axis));
    nodes[me].right_or_first = nodes.len() as u32;
    node(l, hi, offset + k, nodes, rb, Some(axis));
}
