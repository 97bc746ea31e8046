//! A bounding-volume hierarchy over HIGH's triangles, four children to a node.
//!
//! Built in two steps: a binary tree by the surface area heuristic (`sah.rs`; ranges of up to
//! 256 items in `range.rs` on the copies `local.rs` makes, of up to 16 in `small.rs`; the bins,
//! the cost of a boundary and its choice, shared by the three, in `cost.rs`), its upper levels
//! split at Morton-code boundaries on a large HIGH (`morton.rs`, whose items are a triangle or a
//! quad's two halves: `pairs.rs`), then collapsed to the four-wide nodes the rays walk
//! (`collapse.rs`; both node layouts in `node.rs`).
//!
//! The tree depends on the triangles only, never on the thread count: every split is decided by
//! the same binned sweep, and subtrees built on other threads are spliced in a fixed order.
//! The tree holds its triangles' corners and corner indices (into normals that several trees can
//! share) permuted into leaf order, so that a leaf's triangles sit together; HIGH's positions
//! are needed only while it is built.

mod bounds;
mod collapse;
mod cost;
mod local;
mod morton;
mod node;
mod pairs;
mod range;
mod sah;
mod small;

use bounds::{bounds_of, Item};
use node::Nodes;
pub use node::WideNode;

/// Ranges smaller than this are built, bounded and binned on the current thread.
const PARALLEL_MIN: usize = 16 * 1024;

#[derive(Debug, Clone)]
pub struct Bvh {
    /// The four-wide nodes, root at 0 (on a large HIGH, among unused slots of zeros).
    pub nodes: Nodes,
    /// How many of `nodes` the tree uses.
    count: usize,
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
            return Bvh { nodes: Nodes::heap(Vec::new()), count: 0, ids: Vec::new(), tris: Vec::new() };
        }
        // Spelled out, not `t.map(..)`: the array's `map` was left out of line here, built the
        // corners on the stack and read them back whole before their stores had landed, and
        // cost the build a tenth of its time (`docs/transfer-history.md`).
        let at = |t: [u32; 3]| [positions[t[0] as usize], positions[t[1] as usize], positions[t[2] as usize]];
        let corners = |i: usize| at(triangles[i]);
        let item = |i: usize| Item::of(&corners(i), i as u32);
        let tri = |i: u32| {
            let t = triangles[i as usize];
            Tri { corners: at(t), index: index(i).unwrap_or(t) }
        };
        if morton::applies(n) {
            // Each range writes its triangles in leaf order as it ends, while they are cached:
            // no array of items, no pass of its own over HIGH in leaf order.
            // What `corners` of triangles `i..i + k` reads, asked for ahead: their records (the
            // first and the last, which may start another cache line), or with `deep` their
            // corners' positions. Hints: nothing read here changes what is built.
            let warm = |i: usize, k: usize, deep: bool| {
                use crate::pages::prefetch;
                let ts = triangles.get(i..i + k).unwrap_or(&[]);
                if !deep {
                    prefetch(ts.get(..1).unwrap_or(&[]));
                    prefetch(ts.get(k.saturating_sub(1)..).unwrap_or(&[]));
                    return;
                }
                for &c in ts.iter().flatten() {
                    prefetch(positions.get(c as usize..c as usize + 1).unwrap_or(&[]));
                }
            };
            let (nodes, count, ids, tris) = morton::build(n, &corners, &tri, &warm);
            drop(triangles);
            return Bvh { nodes, count, ids, tris };
        }
        let mut items: Vec<Item> = (0..n).into_par_iter().map(item).collect();
        let bc = bounds_of(&items);
        let wide = collapse::whole(&sah::build_par(&mut items, 0, bc));
        let ids: Vec<u32> = items.par_iter().map(|it| it.id).collect();
        // Each array is dropped as soon as the next is made from it: the build's peak is what
        // bounds memory on a large HIGH.
        drop(items);
        let tris = ids.par_iter().map(|&i| tri(i)).collect();
        Bvh { count: wide.len(), nodes: Nodes::heap(wide), ids, tris }
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

    /// Asks the CPU to start loading what a visit of child `child` (a leaf of `count`
    /// triangles, or a node when `count` is 0) reads, while the other children are tested: the
    /// triangles of a 10M-triangle HIGH are far out of cache, and the rays waited on their
    /// first loads (rays 871 -> 831 ms at 10.24M, `docs/transfer-history.md`). Nothing is read
    /// here and no result depends on it.
    #[inline(always)]
    pub fn prefetch(&self, child: u32, count: u32) {
        use crate::pages::prefetch;
        let at = child as usize;
        if count > 0 {
            prefetch(self.tris.get(at..at + count as usize).unwrap_or(&[]));
        } else {
            prefetch(self.nodes.get(at..at + 1).unwrap_or(&[]));
        }
    }

    /// How many four-wide nodes the tree has.
    pub fn node_count(&self) -> usize {
        self.count
    }

    /// Bytes held, for the memory figures (the nodes' unused slots are never made present).
    pub fn bytes(&self) -> usize {
        self.count * std::mem::size_of::<WideNode>()
            + self.tris.capacity() * std::mem::size_of::<Tri>()
            + self.ids.capacity() * 4
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::bounds::Aabb;
    use super::*;
    use glam::Vec3A;

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
            assert_eq!(tris.len() >= morton::MORTON_MIN, side == 200);
            covered_once_and_nested(&tris);
        }
    }

    fn covered_once_and_nested(tris: &[[Vec3A; 3]]) {
        let bvh = whole_and_nested(tris);
        // Four-wide: far fewer nodes than triangles.
        assert!(bvh.node_count() * 4 < tris.len(), "{} nodes", bvh.node_count());
    }

    /// The tree over `tris`: every triangle in one leaf, every node's box holding its children's,
    /// and every node counted in the tree (the unused slots are not).
    fn whole_and_nested(tris: &[[Vec3A; 3]]) -> Bvh {
        let (bvh, _) = soup(tris);
        let mut seen = vec![0u32; tris.len()];
        let mut visited = 0;
        // The box of what node `i`'s lanes hold, each checked against the lane's own box.
        fn walk(b: &Bvh, i: usize, seen: &mut [u32], visited: &mut usize) -> Aabb {
            *visited += 1;
            let n = b.nodes[i];
            let mut all = Aabb::EMPTY;
            for lane in (0..4).filter(|&k| n.has(k)) {
                let lo = Vec3A::new(n.min[0][lane], n.min[1][lane], n.min[2][lane]);
                let hi = Vec3A::new(n.max[0][lane], n.max[1][lane], n.max[2][lane]);
                let held = if n.is_leaf(lane) {
                    let mut a = Aabb::EMPTY;
                    let first = n.child[lane] as usize;
                    for k in first..first + n.count[lane] as usize {
                        seen[b.ids[k] as usize] += 1;
                        b.corners(k).iter().for_each(|&p| a.grow(p.into()));
                    }
                    a
                } else {
                    walk(b, n.child[lane] as usize, seen, visited)
                };
                assert!(
                    lo.cmple(held.min).all() && hi.cmpge(held.max).all(),
                    "node {i} lane {lane} does not hold its child"
                );
                all.join(&held);
            }
            all
        }
        walk(&bvh, 0, &mut seen, &mut visited);
        assert!(seen.iter().all(|&s| s == 1));
        assert_eq!(visited, bvh.node_count());
        bvh
    }

    /// On a large HIGH a quad's two halves are one item (`pairs.rs`): side by side in one leaf.
    #[test]
    fn a_quads_halves_share_a_leaf() {
        let tris = grid_tris(200);
        assert!(tris.len() >= morton::MORTON_MIN);
        let (bvh, _) = soup(&tris);
        let mut at = vec![0usize; tris.len()];
        bvh.ids.iter().enumerate().for_each(|(k, &id)| at[id as usize] = k);
        let starts: std::collections::HashSet<u32> =
            bvh.nodes.iter().flat_map(|n| (0..4).filter(|&k| n.has(k) && n.is_leaf(k)).map(|k| n.child[k])).collect();
        for q in 0..tris.len() / 2 {
            let (a, b) = (at[2 * q], at[2 * q + 1]);
            assert!(b == a + 1 && !starts.contains(&(b as u32)), "quad {q}: its halves at {a} and {b}");
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

    /// Identical triangles (no centre spread) still end in small leaves, on their own and as a
    /// pile among a large HIGH's others (more than a range of one Morton code holds); every
    /// triangle is in one leaf, with its own corners.
    #[test]
    fn duplicates_split_by_count() {
        let t = [Vec3A::ZERO, Vec3A::X, Vec3A::Y];
        let mut large = grid_tris(200);
        large.splice(5000..5000, vec![t.map(|p| p + Vec3A::new(3.5, 7.5, 9.0)); 1000]);
        for tris in [vec![t; 1000], large] {
            let (bvh, _) = soup(&tris);
            let counts = || bvh.nodes.iter().flat_map(|n| n.count);
            assert!(counts().all(|c| c as usize <= cost::MAX_LEAF * 2));
            assert_eq!(counts().map(|c| c as usize).sum::<usize>(), tris.len());
            for (k, &id) in bvh.ids.iter().enumerate() {
                assert_eq!(bvh.corners(k), &tris[id as usize].map(|p| p.to_array()), "leaf-order triangle {k}");
            }
            if tris.len() >= morton::MORTON_MIN {
                covered_once_and_nested(&tris);
            }
        }
    }

    /// A large HIGH whose items all have one Morton code is one range with no split above it:
    /// its root, placed among the slots, stands at 0 too, and the tree is whole (split by count:
    /// the centres cannot be told apart, so not four triangles a node).
    #[test]
    fn one_code_is_one_range_rooted_at_0() {
        let t = [Vec3A::ZERO, Vec3A::X, Vec3A::Y];
        let tris = vec![t; morton::MORTON_MIN];
        assert!(whole_and_nested(&tris).node_count() > 1);
    }
}
