//! The binary tree by the surface area heuristic: a ray that meets a node's box meets a child's
//! with a chance of about the ratio of their areas, so a split costs each side's box area times
//! its triangle count. Large ranges split at the best of 16 bin boundaries, ranges of at most
//! [`SMALL`] at the best boundary between their sorted centres; from [`PARALLEL_MIN`] triangles
//! on, the two sides are built on separate cores. Nodes are stored depth first, so an inner
//! node's first child is the node after it.

use super::bounds::{bounds_of, Aabb, Item};
use super::node::Node;
use super::range::{self, LOCAL};
use super::PARALLEL_MIN;
use glam::Vec3A;

pub(super) const BINS: usize = 16;
/// The most triangles a leaf is made of by choice; ranges whose centres cannot be told apart
/// end in leaves of up to twice this.
pub(super) const MAX_LEAF: usize = 4;
/// A node visit costed in triangle tests, for the leaf-or-split choice.
pub(super) const NODE_COST: f32 = 2.0;
/// Ranges of at most this many triangles are split exactly, without bins (`small.rs`).
pub(super) const SMALL: usize = 16;

/// Builds the subtree over `items` (which start at `offset` in leaf order, with bounds and
/// centre bounds `bc`); its root is node 0.
pub(super) fn build_par(items: &mut [Item], offset: usize, bc: (Aabb, Aabb)) -> Vec<Node> {
    if items.len() < PARALLEL_MIN {
        let mut nodes = Vec::with_capacity(items.len() / 2 + 1);
        build_serial(items, offset, &mut nodes, bc);
        return nodes;
    }
    let (b, c) = bc;
    let (mid, lb, rb) = divide(items, &b, &c);
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
    let (mid, lb, rb) = match split(items, &b, &c) {
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

/// Per bin: the items' bounds, their centres' bounds and their count.
pub(super) type Bins = [(Aabb, Aabb, usize); BINS];

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

/// The bounds and centre bounds of bins `r`: a child's, with no pass over its items.
fn bins_bounds(bins: &Bins, r: std::ops::Range<usize>) -> (Aabb, Aabb) {
    let (mut b, mut c) = (Aabb::EMPTY, Aabb::EMPTY);
    for x in &bins[r] {
        b.join(&x.0);
        c.join(&x.1);
    }
    (b, c)
}

/// A binned split: the axis, the boundary (items in bins below `bin` go left), and each side's
/// bounds and centre bounds.
pub(super) struct Split {
    pub axis: usize,
    pub bin: usize,
    pub left: (Aabb, Aabb),
    pub right: (Aabb, Aabb),
}

/// The best binned-SAH split of `items` along the centres' longest axis, or `None` when a leaf
/// is cheaper or the centres cannot be told apart.
fn split(items: &[Item], b: &Aabb, c: &Aabb) -> Option<Split> {
    let extent = c.max - c.min;
    // One axis only: a third of the binning work of trying all three; on the benchmark's HIGH
    // the whole bake took less CPU time this way (build cheaper, tracing no slower).
    let axis = longest(extent);
    let e = extent[axis];
    if e.is_nan() || e <= 0.0 {
        return None;
    }
    choose(&bin(items, c, axis), items.len(), b, axis)
}

/// The best boundary between `bins` (of `n` items with bounds `b`, binned along `axis`), or
/// `None` when a leaf is cheaper.
pub(super) fn choose(bins: &Bins, n: usize, b: &Aabb, axis: usize) -> Option<Split> {
    // Sweep from the right, then from the left: the cost of each boundary.
    let mut right_cost = [0.0f32; BINS];
    let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
    for k in (1..BINS).rev() {
        acc.join(&bins[k].0);
        cnt += bins[k].2;
        right_cost[k] = acc.area() * cnt as f32;
    }
    let mut best: Option<(f32, usize)> = None;
    let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
    for k in 1..BINS {
        acc.join(&bins[k - 1].0);
        cnt += bins[k - 1].2;
        if cnt == 0 || cnt == n {
            continue;
        }
        let cost = acc.area() * cnt as f32 + right_cost[k];
        if best.map(|(bc, _)| cost < bc).unwrap_or(true) {
            best = Some((cost, k));
        }
    }
    let (cost, k) = best?;
    // A node visit is costed as two triangle tests: on the benchmark's HIGH that gives 36% fewer
    // nodes and took about 6% less CPU than costing it as one (same map, bit for bit).
    let leaf_cost = b.area() * n as f32;
    if n <= MAX_LEAF && cost + NODE_COST * b.area() >= leaf_cost {
        return None;
    }
    Some(Split { axis, bin: k, left: bins_bounds(bins, 0..k), right: bins_bounds(bins, k..BINS) })
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
fn divide(items: &mut [Item], b: &Aabb, c: &Aabb) -> (usize, (Aabb, Aabb), (Aabb, Aabb)) {
    match split(items, b, c) {
        Some(sp) => (partition(items, c, sp.axis, sp.bin), sp.left, sp.right),
        None => halves(items),
    }
}

fn halves(items: &[Item]) -> (usize, (Aabb, Aabb), (Aabb, Aabb)) {
    let mid = items.len() / 2;
    (mid, bounds_of(&items[..mid]), bounds_of(&items[mid..]))
}

/// The axis along which `e` is longest (x before y before z on ties).
pub(super) fn longest(e: Vec3A) -> usize {
    if e.x >= e.y && e.x >= e.z {
        0
    } else if e.y >= e.z {
        1
    } else {
        2
    }
}
