//! The binary tree by the surface area heuristic: a ray that meets a node's box meets a child's
//! with a chance of about the ratio of their areas, so a split costs each side's box area times
//! its triangle count. Large ranges split at the best of 16 bin boundaries, ranges of at most
//! [`SMALL`] at the best boundary between their sorted centres; from [`PARALLEL_MIN`] triangles
//! on, the two sides are built on separate cores. Nodes are stored depth first, so an inner
//! node's first child is the node after it.

use super::bounds::{bounds_of, Aabb, Item};
use super::cost::{choose, longest, Bins, Split, BINS, MAX_LEAF};
use super::local::LOCAL;
use super::node::Node;
use super::range;
use super::PARALLEL_MIN;

/// Builds the subtree over `items` (which start at `offset` in leaf order, with bounds and
/// centre bounds `bc`); its root is node 0.
pub(super) fn build_par(items: &mut [Item], offset: usize, bc: (Aabb, Aabb)) -> Vec<Node> {
    if items.len() < PARALLEL_MIN {
        let mut nodes = Vec::with_capacity(items.len() / 2 + 1);
        build_serial(items, offset, &mut nodes, bc);
        return nodes;
    }
    let (b, c) = bc;
    let (mid, lb, rb) = divide(items, &c);
    let (l, r) = items.split_at_mut(mid);
    let (mut left, mut right) = rayon::join(|| build_par(l, offset, lb), || build_par(r, offset + mid, rb));
    // Each side was built with its root at 0; here they follow their parent and each other.
    let shift = |nodes: &mut [Node], by: u32| {
        for n in nodes.iter_mut().filter(|n| !n.is_leaf()) {
            n.right_or_first += by;
        }
    };
    shift(&mut left, 1);
    shift(&mut right, 1 + left.len() as u32);
    let mut nodes = Vec::with_capacity(1 + left.len() + right.len());
    nodes.push(Node::inner(&b, 1 + left.len() as u32));
    nodes.append(&mut left);
    nodes.append(&mut right);
    nodes
}

fn build_serial(items: &mut [Item], offset: usize, nodes: &mut Vec<Node>, (b, c): (Aabb, Aabb)) {
    if items.len() <= LOCAL {
        range::build(items, offset, nodes, (b, c));
        return;
    }
    let me = nodes.len();
    let (mid, lb, rb) = match split(items, &c) {
        Some(sp) => (partition(items, &c, sp.axis, sp.bin), sp.left, sp.right),
        None if items.len() <= MAX_LEAF * 2 => {
            nodes.push(Node::leaf(&b, offset, items.len()));
            return;
        }
        None => halves(items),
    };
    nodes.push(Node::inner(&b, 0));
    let (l, r) = items.split_at_mut(mid);
    build_serial(l, offset, nodes, lb);
    nodes[me].right_or_first = nodes.len() as u32;
    build_serial(r, offset + mid, nodes, rb);
}

/// The items binned by centre along `axis` (in parallel for a large range; the same bins in any
/// grouping).
fn bin(items: &[Item], c: &Aabb, axis: usize) -> Bins {
    use rayon::prelude::*;
    let scale = BINS as f32 / (c.max[axis] - c.min[axis]);
    let one = |items: &[Item]| {
        let mut bins = [(Aabb::EMPTY, Aabb::EMPTY, 0usize); BINS];
        for it in items {
            let m = it.centre();
            let k = (((m[axis] - c.min[axis]) * scale) as usize).min(BINS - 1);
            bins[k].0.join(&it.bounds());
            bins[k].1.grow(m);
            bins[k].2 += 1;
        }
        bins
    };
    if items.len() < PARALLEL_MIN * 4 {
        return one(items);
    }
    items.par_chunks(PARALLEL_MIN).map(one).reduce(
        || [(Aabb::EMPTY, Aabb::EMPTY, 0usize); BINS],
        |mut a, b| {
            for (x, y) in a.iter_mut().zip(&b) {
                x.0.join(&y.0);
                x.1.join(&y.1);
                x.2 += y.2;
            }
            a
        },
    )
}

/// The best binned-SAH split of `items` along the centres' longest axis, or `None` when the
/// centres cannot be told apart.
fn split(items: &[Item], c: &Aabb) -> Option<Split> {
    let extent = c.max - c.min;
    // One axis only: a third of the binning work of trying all three; on the benchmark's HIGH
    // the whole bake took less CPU time this way (build cheaper, tracing no slower).
    let axis = longest(extent);
    let e = extent[axis];
    if e.is_nan() || e <= 0.0 {
        return None;
    }
    choose(&bin(items, c, axis), items.len(), axis)
}

/// Moves the items left of bin boundary `k` on `axis` to the front; returns how many there are.
fn partition(items: &mut [Item], c: &Aabb, axis: usize, k: usize) -> usize {
    let scale = BINS as f32 / (c.max[axis] - c.min[axis]);
    let side = |it: &Item| (((it.centre()[axis] - c.min[axis]) * scale) as usize).min(BINS - 1) < k;
    let mut i = 0;
    for j in 0..items.len() {
        if side(&items[j]) {
            items.swap(i, j);
            i += 1;
        }
    }
    i
}

/// Where `items` split and each side's bounds: by the best binned split, else in two halves of
/// equal count (identical centres).
fn divide(items: &mut [Item], c: &Aabb) -> (usize, (Aabb, Aabb), (Aabb, Aabb)) {
    match split(items, c) {
        Some(sp) => (partition(items, c, sp.axis, sp.bin), sp.left, sp.right),
        None => halves(items),
    }
}

fn halves(items: &[Item]) -> (usize, (Aabb, Aabb), (Aabb, Aabb)) {
    let mid = items.len() / 2;
    (mid, bounds_of(&items[..mid]), bounds_of(&items[mid..]))
}
