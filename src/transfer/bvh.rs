//! A bounding-volume hierarchy over HIGH's triangles: binned SAH, built in parallel.
//!
//! The tree depends on the triangles only, never on the thread count: every split is decided by
//! the same binned sweep, and subtrees built on other threads are spliced in a fixed order.
//! The tree holds its triangles' corners and corner indices (into normals that several trees can
//! share) permuted into leaf order, so that a leaf's triangles sit together; HIGH's positions
//! are needed only while it is built.

use super::wide::{Upper, Wide};
use glam::Vec3A;

/// One node: 32 bytes. An inner node's left child is the next node and `a` is its right child;
/// a leaf holds `n > 0` triangles from `a` on (in leaf order).
#[derive(Debug, Clone, Copy)]
pub struct Node {
    pub min: [f32; 3],
    pub a: u32,
    pub max: [f32; 3],
    pub n: u32,
}

impl Node {
    /// Half its box's surface area, as the build's cost model counts it.
    pub fn area(&self) -> f32 {
        Aabb { min: Vec3A::from(self.min), max: Vec3A::from(self.max) }.area()
    }
}

#[derive(Debug, Clone)]
pub struct Bvh {
    /// The binary tree collapsed to four children a node, as the rays walk it.
    pub nodes: Vec<Wide>,
    /// Each leaf-order triangle's index in the input.
    pub ids: Vec<u32>,
    /// The triangles in leaf order: a leaf's triangles are read from one place, not through
    /// their indices from positions scattered over the whole mesh.
    tris: Vec<Tri>,
}

/// A triangle as the rays read it: its corners, and beside them (in the cache line the test
/// has just loaded) the corner indices its hit is shaded with.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Tri {
    corners: [[f32; 3]; 3],
    /// Into the positions the tree was built from, or as [`Bvh::build_indexed`] was told.
    index: [u32; 3],
}

const BINS: usize = 16;
const MAX_LEAF: usize = 4;
/// A node visit costed in triangle tests, for the leaf-or-split choice.
const NODE_COST: f32 = 2.0;
/// Ranges of at most this many triangles are split exactly, without bins ([`build_small`]).
const SMALL: usize = 16;
/// Ranges smaller than this are built on the current thread.
const PARALLEL_MIN: usize = 16 * 1024;
/// From this many triangles on, the upper levels split at Morton-code boundaries (one sort, no
/// pass over every item per level) and binned SAH builds only ranges of [`SAH_RANGE`] or fewer,
/// whose items fit in a core's cache.
const MORTON_MIN: usize = 64 * 1024;
const SAH_RANGE: usize = 256;
/// A Morton key holds the code above a triangle's index, so keys are unique and sort alike on
/// any thread count: 12 bits an axis over 28 bits of index (HIGHs up to 268M triangles).
const INDEX_BITS: u32 = 28;
const INDEX_MASK: u64 = (1 << INDEX_BITS) - 1;
const AXIS_BITS: u32 = 12;

#[derive(Clone, Copy)]
struct Aabb {
    min: Vec3A,
    max: Vec3A,
}

impl Aabb {
    const EMPTY: Aabb = Aabb { min: Vec3A::splat(f32::INFINITY), max: Vec3A::splat(f32::NEG_INFINITY) };
    fn grow(&mut self, p: Vec3A) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }
    fn join(&mut self, o: &Aabb) {
        self.min = self.min.min(o.min);
        self.max = self.max.max(o.max);
    }
    fn area(&self) -> f32 {
        let d = self.max - self.min;
        if d.x < 0.0 {
            return 0.0;
        }
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

/// Per-triangle data the build sorts: 28 bytes (the centre is recomputed from the bounds, in the
/// same arithmetic, rather than stored).
#[derive(Clone, Copy)]
struct Item {
    min: [f32; 3],
    max: [f32; 3],
    id: u32,
}

impl Item {
    fn bounds(&self) -> Aabb {
        Aabb { min: Vec3A::from(self.min), max: Vec3A::from(self.max) }
    }
    fn centre(&self) -> Vec3A {
        (Vec3A::from(self.min) + Vec3A::from(self.max)) * 0.5
    }
}

impl Bvh {
    /// Builds the tree over `triangles` (corner indices into `positions`, which must be in
    /// range). Every triangle is kept, degenerate ones too: the intersection test rejects them,
    /// and their ids stay aligned with the input.
    pub fn build(positions: &[[f32; 3]], triangles: Vec<[u32; 3]>) -> Bvh {
        Bvh::build_indexed(positions, triangles, |_| None)
    }

    /// [`Bvh::build`], with each triangle's shading corners given by `index(id)` where it
    /// gives some (a mesh whose normals have indices of their own, as an OBJ's `vn`), else its
    /// position indices: they are read in leaf order, beside the corners.
    pub fn build_indexed(
        positions: &[[f32; 3]],
        triangles: Vec<[u32; 3]>,
        index: impl Fn(u32) -> Option<[u32; 3]> + Sync,
    ) -> Bvh {
        use rayon::prelude::*;
        let n = triangles.len();
        if n == 0 {
            return Bvh { nodes: Vec::new(), ids: Vec::new(), tris: Vec::new() };
        }
        let mut items: Vec<Item> = (0..n)
            .into_par_iter()
            .map(|i| {
                let mut b = Aabb::EMPTY;
                triangles[i].iter().for_each(|&k| b.grow(Vec3A::from(positions[k as usize])));
                Item { min: b.min.to_array(), max: b.max.to_array(), id: i as u32 }
            })
            .collect();
        let bc = bounds_of(&items);
        let upper = if (MORTON_MIN..1 << INDEX_BITS).contains(&n) {
            let mut keys = morton_keys(&items, &bc.1);
            items = keys.par_iter().map(|k| items[(k & INDEX_MASK) as usize]).collect();
            keys.iter_mut().for_each(|k| *k >>= INDEX_BITS);
            build_morton(&mut items, &keys, 0)
        } else {
            Upper::range(build_par(&mut items, 0, bc))
        };
        // Each array is dropped as soon as the next is made from it: the build's peak is what
        // bounds memory on a large HIGH.
        let ids: Vec<u32> = items.par_iter().map(|it| it.id).collect();
        drop(items);
        let wide = upper.collapse();
        let tris = ids
            .par_iter()
            .map(|&i| {
                let t = triangles[i as usize];
                Tri { corners: t.map(|k| positions[k as usize]), index: index(i).unwrap_or(t) }
            })
            .collect();
        Bvh { nodes: wide, ids, tris }
    }

    /// An empty tree has no nodes.
    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// The corners of leaf-order triangle `k`.
    #[inline]
    pub fn corners(&self, k: usize) -> &[[f32; 3]; 3] {
        &self.tris[k].corners
    }

    /// The corner indices of leaf-order triangle `k` (see [`Bvh::build_indexed`]).
    #[inline]
    pub fn index(&self, k: usize) -> [u32; 3] {
        self.tris[k].index
    }

    /// Bytes held, for the memory figures.
    pub fn bytes(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<Wide>()
            + self.tris.capacity() * std::mem::size_of::<Tri>()
            + self.ids.capacity() * 4
    }
}

/// The items' bounds and their centres' bounds (on every core for a large range: min and max
/// give the same boxes in any grouping).
fn bounds_of(items: &[Item]) -> (Aabb, Aabb) {
    use rayon::prelude::*;
    let one = |items: &[Item]| {
        let (mut b, mut c) = (Aabb::EMPTY, Aabb::EMPTY);
        for it in items {
            b.join(&it.bounds());
            c.grow(it.centre());
        }
        (b, c)
    };
    if items.len() < PARALLEL_MIN * 4 {
        return one(items);
    }
    items.par_chunks(PARALLEL_MIN).map(one).reduce(
        || (Aabb::EMPTY, Aabb::EMPTY),
        |(mut b, mut c), (b2, c2)| {
            b.join(&b2);
            c.join(&c2);
            (b, c)
        },
    )
}

/// Per bin: the items' bounds, their centres' bounds and their count.
type Bins = [(Aabb, Aabb, usize); BINS];

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

/// A split: the axis, the bin boundary, and each side's bounds and centre bounds.
struct Split {
    axis: usize,
    k: usize,
    left: (Aabb, Aabb),
    right: (Aabb, Aabb),
}

fn leaf(b: &Aabb, first: usize, n: usize) -> Node {
    Node { min: b.min.to_array(), a: first as u32, max: b.max.to_array(), n: n as u32 }
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
    let bins = bin(items, c, axis);
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
        if cnt == 0 || cnt == items.len() {
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
    let leaf_cost = b.area() * items.len() as f32;
    if items.len() <= MAX_LEAF && cost + NODE_COST * b.area() >= leaf_cost {
        return None;
    }
    Some(Split { axis, k, left: bins_bounds(&bins, 0..k), right: bins_bounds(&bins, k..BINS) })
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
        Some(sp) => (partition(items, c, sp.axis, sp.k), sp.left, sp.right),
        None => halves(items),
    }
}

fn halves(items: &[Item]) -> (usize, (Aabb, Aabb), (Aabb, Aabb)) {
    let mid = items.len() / 2;
    (mid, bounds_of(&items[..mid]), bounds_of(&items[mid..]))
}

/// Each item's key (Morton code of its box's centre over the centres' bounds `c`, then its
/// index), sorted.
fn morton_keys(items: &[Item], c: &Aabb) -> Vec<u64> {
    use rayon::prelude::*;
    let n = items.len();
    let cells = (1u32 << AXIS_BITS) as f32;
    let extent = c.max - c.min;
    let scale = Vec3A::select(extent.cmpgt(Vec3A::ZERO), Vec3A::splat(cells) / extent, Vec3A::ZERO);
    let keys: Vec<u64> = items
        .par_iter()
        .enumerate()
        .map(|(i, it)| {
            let q = ((it.centre() - c.min) * scale).min(Vec3A::splat(cells - 1.0));
            let code = spread(q.x as u64) | spread(q.y as u64) << 1 | spread(q.z as u64) << 2;
            code << INDEX_BITS | i as u64
        })
        .collect();
    // One pass on the code's top 12 bits into buckets, then each bucket sorted on its own, on
    // every core: the keys are unique, so any sort gives the one order.
    let top = |k: u64| (k >> (INDEX_BITS + 2 * AXIS_BITS)) as usize;
    let mut start = vec![0usize; (1 << AXIS_BITS) + 1];
    keys.iter().for_each(|&k| start[top(k) + 1] += 1);
    for d in 1..start.len() {
        start[d] += start[d - 1];
    }
    let mut sorted = vec![0u64; n];
    let mut next = start.clone();
    for &k in &keys {
        let d = top(k);
        sorted[next[d]] = k;
        next[d] += 1;
    }
    drop(keys);
    let mut buckets: Vec<&mut [u64]> = Vec::with_capacity(1 << AXIS_BITS);
    let mut rest = sorted.as_mut_slice();
    for d in 0..1 << AXIS_BITS {
        let (b, r) = rest.split_at_mut(start[d + 1] - start[d]);
        buckets.push(b);
        rest = r;
    }
    buckets.into_par_iter().for_each(|b| b.sort_unstable());
    sorted
}

/// The low 12 bits of `x`, two zero bits after each.
fn spread(x: u64) -> u64 {
    let mut x = x & 0xfff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

fn upper_bounds(u: &Upper) -> Aabb {
    let n = u.node();
    Aabb { min: Vec3A::from(n.min), max: Vec3A::from(n.max) }
}

/// The upper levels over Morton-sorted items: each split where the codes' highest differing
/// bit flips; ranges of [`SAH_RANGE`] or fewer (or of one code) are built by binned SAH.
fn build_morton(items: &mut [Item], codes: &[u64], offset: usize) -> Upper {
    let last = codes.len() - 1;
    if items.len() <= SAH_RANGE || codes[0] == codes[last] {
        let bc = bounds_of(items);
        return Upper::range(build_par(items, offset, bc));
    }
    let bit = 63 - (codes[0] ^ codes[last]).leading_zeros();
    let mid = codes.partition_point(|c| c >> bit & 1 == 0);
    let (l, r) = items.split_at_mut(mid);
    let (cl, cr) = codes.split_at(mid);
    let (left, right) = rayon::join(|| build_morton(l, cl, offset), || build_morton(r, cr, offset + mid));
    let mut b = upper_bounds(&left);
    b.join(&upper_bounds(&right));
    let node = Node { min: b.min.to_array(), a: 0, max: b.max.to_array(), n: 0 };
    Upper::Split(node, Box::new(left), Box::new(right))
}

/// Builds the subtree over `items` (which start at `offset` in leaf order, with bounds and
/// centre bounds `bc`); its root is node 0.
fn build_par(items: &mut [Item], offset: usize, bc: (Aabb, Aabb)) -> Vec<Node> {
    if items.len() < PARALLEL_MIN {
        let mut nodes = Vec::with_capacity(items.len() / 2 + 1);
        build_serial(items, offset, &mut nodes, bc);
        return nodes;
    }
    let (b, c) = bc;
    let (mid, lb, rb) = divide(items, &b, &c);
    let (l, r) = items.split_at_mut(mid);
    let (mut left, mut right) = rayon::join(|| build_par(l, offset, lb), || build_par(r, offset + mid, rb));
    let shift = |nodes: &mut [Node], by: u32| {
        for n in nodes.iter_mut().filter(|n| n.n == 0) {
            n.a += by;
        }
    };
    shift(&mut left, 1);
    shift(&mut right, 1 + left.len() as u32);
    let mut nodes = Vec::with_capacity(1 + left.len() + right.len());
    nodes.push(Node { min: b.min.to_array(), a: 1 + left.len() as u32, max: b.max.to_array(), n: 0 });
    nodes.append(&mut left);
    nodes.append(&mut right);
    nodes
}

fn build_serial(items: &mut [Item], offset: usize, nodes: &mut Vec<Node>, (b, c): (Aabb, Aabb)) {
    if items.len() <= SMALL {
        build_small(items, offset, nodes, b);
        return;
    }
    let me = nodes.len();
    let (mid, lb, rb) = match split(items, &b, &c) {
        Some(sp) => (partition(items, &c, sp.axis, sp.k), sp.left, sp.right),
        None if items.len() <= MAX_LEAF * 2 => {
            nodes.push(leaf(&b, offset, items.len()));
            return;
        }
        None => halves(items),
    };
    nodes.push(Node { min: b.min.to_array(), a: 0, max: b.max.to_array(), n: 0 });
    let (l, r) = items.split_at_mut(mid);
    build_serial(l, offset, nodes, lb);
    nodes[me].a = nodes.len() as u32;
    build_serial(r, offset + mid, nodes, rb);
}

/// A range of at most [`SMALL`] triangles: the exact SAH split (each boundary between the
/// centres sorted along their longest axis) and no bins, whose fixed cost (16 bins, two sweeps)
/// dwarfed the work on so few items: 70% of the build's instructions went there.
fn build_small(items: &mut [Item], offset: usize, nodes: &mut Vec<Node>, b: Aabb) {
    let n = items.len();
    if n == 1 {
        nodes.push(leaf(&b, offset, 1));
        return;
    }
    let mut c = Aabb::EMPTY;
    items.iter().for_each(|it| c.grow(it.centre()));
    let axis = longest(c.max - c.min);
    // Insertion sort of the keys, each computed once (a handful of items; `id` breaks ties so
    // the order is the input's), then the items moved once.
    let mut keys = [((0.0f32, 0u32), 0usize); SMALL];
    for (i, (k, it)) in keys.iter_mut().zip(items.iter()).enumerate() {
        *k = ((it.centre()[axis], it.id), i);
    }
    for i in 1..n {
        let mut j = i;
        while j > 0 && keys[j - 1].0 > keys[j].0 {
            keys.swap(j - 1, j);
            j -= 1;
        }
    }
    let mut was = [items[0]; SMALL];
    was[..n].copy_from_slice(items);
    items.iter_mut().zip(&keys).for_each(|(it, &(_, i))| *it = was[i]);
    let mut right = [(Aabb::EMPTY, 0.0f32); SMALL];
    let mut acc = Aabb::EMPTY;
    for k in (1..n).rev() {
        acc.join(&items[k].bounds());
        right[k] = (acc, acc.area() * (n - k) as f32);
    }
    let (mut acc, mut best) = (Aabb::EMPTY, (f32::INFINITY, 0, Aabb::EMPTY));
    for k in 1..n {
        acc.join(&items[k - 1].bounds());
        let cost = acc.area() * k as f32 + right[k].1;
        if cost < best.0 {
            best = (cost, k, acc);
        }
    }
    let (cost, k, lb) = best;
    // As in `split`: a node visit costs two triangle tests.
    if n <= MAX_LEAF && cost + NODE_COST * b.area() >= b.area() * n as f32 {
        nodes.push(leaf(&b, offset, n));
        return;
    }
    let me = nodes.len();
    nodes.push(Node { min: b.min.to_array(), a: 0, max: b.max.to_array(), n: 0 });
    let (l, r) = items.split_at_mut(k);
    build_small(l, offset, nodes, lb);
    nodes[me].a = nodes.len() as u32;
    build_small(r, offset + k, nodes, right[k].0);
}

/// The axis along which `e` is longest (x before y before z on ties).
fn longest(e: Vec3A) -> usize {
    if e.x >= e.y && e.x >= e.z {
        0
    } else if e.y >= e.z {
        1
    } else {
        2
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A tree over unshared corners, as a triangle soup, and its positions.
    pub(crate) fn soup(tris: &[[Vec3A; 3]]) -> (Bvh, Vec<[f32; 3]>) {
        let positions: Vec<[f32; 3]> = tris.iter().flat_map(|t| t.map(|p| p.to_array())).collect();
        let k = tris.len() as u32;
        (Bvh::build(&positions, (0..k).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect()), positions)
    }

    fn grid_tris(n: usize) -> Vec<[Vec3A; 3]> {
        let mut t = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let p = |a: usize, b: usize| Vec3A::new(a as f32, b as f32, ((a * 7 + b * 3) % 5) as f32 * 0.1);
                t.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
                t.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
            }
        }
        t
    }

    /// Every triangle is in exactly one leaf, and every node's box holds its children's: built
    /// by binned SAH alone, and with Morton-split upper levels.
    #[test]
    fn leaves_cover_every_triangle_once_and_boxes_nest() {
        for side in [150, 200] {
            let tris = grid_tris(side);
            assert_eq!(tris.len() >= MORTON_MIN, side == 200);
            covered_once_and_nested(&tris);
        }
    }

    fn covered_once_and_nested(tris: &[[Vec3A; 3]]) {
        let (bvh, _) = soup(tris);
        let mut seen = vec![0u32; tris.len()];
        // The box of what node `i`'s lanes hold, each checked against the lane's own box.
        fn walk(b: &Bvh, i: usize, seen: &mut [u32]) -> Aabb {
            let n = b.nodes[i];
            let mut all = Aabb::EMPTY;
            for lane in (0..4).filter(|&k| n.lanes & (1 << k) != 0) {
                let lo = Vec3A::new(n.min[0][lane], n.min[1][lane], n.min[2][lane]);
                let hi = Vec3A::new(n.max[0][lane], n.max[1][lane], n.max[2][lane]);
                let held = if n.count[lane] > 0 {
                    let mut a = Aabb::EMPTY;
                    let first = n.child[lane] as usize;
                    for k in first..first + n.count[lane] as usize {
                        seen[b.ids[k] as usize] += 1;
                        b.corners(k).iter().for_each(|&p| a.grow(p.into()));
                    }
                    a
                } else {
                    walk(b, n.child[lane] as usize, seen)
                };
                assert!(
                    lo.cmple(held.min).all() && hi.cmpge(held.max).all(),
                    "node {i} lane {lane} does not hold its child"
                );
                all.join(&held);
            }
            all
        }
        walk(&bvh, 0, &mut seen);
        assert!(seen.iter().all(|&s| s == 1));
        // Four-wide: far fewer nodes than triangles.
        assert!(bvh.nodes.len() * 4 < tris.len(), "{} nodes", bvh.nodes.len());
    }

    #[test]
    fn spread_leaves_two_zero_bits_after_each() {
        for x in [0u64, 1, 0b101, 0xfff, 0xabc] {
            let mut want = 0;
            (0..12).for_each(|b| want |= (x >> b & 1) << (3 * b));
            assert_eq!(spread(x), want, "{x:#x}");
        }
    }

    /// The same tree, node for node, whatever the thread count (large enough for the parallel
    /// binning and the parallel subtrees).
    #[test]
    fn same_tree_on_any_thread_count() {
        let tris = grid_tris(260);
        let build = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
            let (b, _) = pool.install(|| soup(&tris));
            let bits = |v: [glam::Vec4; 3]| v.map(|a| a.to_array().map(f32::to_bits));
            let nodes: Vec<_> = b.nodes.iter().map(|n| (bits(n.min), bits(n.max), n.child, n.count, n.lanes)).collect();
            (nodes, b.tris, b.ids)
        };
        assert!(tris.len() > PARALLEL_MIN * 8);
        let one = build(1);
        assert_eq!(one, build(2));
        assert_eq!(one, build(3));
    }

    /// Identical triangles (no centre spread) still end in small leaves.
    #[test]
    fn duplicates_split_by_count() {
        let t = [Vec3A::ZERO, Vec3A::X, Vec3A::Y];
        let (bvh, _) = soup(&vec![t; 1000]);
        let counts = || bvh.nodes.iter().flat_map(|n| n.count);
        assert!(counts().all(|c| c as usize <= MAX_LEAF * 2));
        assert_eq!(counts().map(|c| c as usize).sum::<usize>(), 1000);
    }
}
