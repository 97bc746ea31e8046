//! The tree as the rays walk it: four children to a node, their boxes side by side, so one
//! node's four slab tests are four-lane vector operations and a ray fetches about half as many
//! nodes as in the binary tree it is collapsed from.

use super::bvh::Node;
use glam::Vec4;
use rayon::prelude::*;

/// One node: 128 bytes, two cache lines.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
pub struct Wide {
    /// The children's boxes by axis: `min[0]` holds the four children's smallest x.
    pub min: [Vec4; 3],
    pub max: [Vec4; 3],
    /// Per child: an inner child's node index, or a leaf's first triangle (in leaf order).
    pub child: [u32; 4],
    /// Per child: 0 for an inner node, else the leaf's triangle count.
    pub count: [u8; 4],
    /// Bit `k` set when child `k` exists.
    pub lanes: u32,
}

impl Wide {
    fn empty() -> Wide {
        Wide { min: [Vec4::ZERO; 3], max: [Vec4::ZERO; 3], child: [0; 4], count: [0; 4], lanes: 0 }
    }

    fn set(&mut self, k: usize, n: &Node) {
        for a in 0..3 {
            self.min[a][k] = n.min[a];
            self.max[a][k] = n.max[a];
        }
        self.lanes |= 1 << k;
    }
}

/// Collapses the binary tree `bin` (root at 0, left child next, as [`super::bvh`] builds it)
/// into four-wide nodes, root at 0, each node before its children (depth first).
fn collapse(bin: &[Node]) -> Vec<Wide> {
    if bin[0].n > 0 {
        return lone_leaf(&bin[0]);
    }
    let mut out = Vec::with_capacity(bin.len() / 3 + 1);
    node(bin, 0, &mut out);
    out
}

/// A tree that is one leaf: a root with that leaf as its only child.
fn lone_leaf(leaf: &Node) -> Vec<Wide> {
    let mut w = Wide::empty();
    w.set(0, leaf);
    w.child[0] = leaf.a;
    w.count[0] = leaf_count(leaf);
    vec![w]
}

fn leaf_count(n: &Node) -> u8 {
    u8::try_from(n.n).expect("leaves hold at most 255 triangles")
}

/// The children a wide node takes from a binary node whose children are `l` and `r`: the
/// largest (by area) inner child opened into its own two children, in place, until four (or
/// only leaves) remain. `inner` gives an inner child's area and children, `None` for a leaf.
fn open<T: Copy>(l: T, r: T, inner: impl Fn(T) -> Option<(f32, T, T)>) -> ([T; 4], usize) {
    let mut kids = [l, r, r, r];
    let mut len = 2;
    while len < 4 {
        let mut pick: Option<(usize, f32, T, T)> = None;
        for (i, &k) in kids[..len].iter().enumerate() {
            if let Some((area, a, b)) = inner(k) {
                if pick.is_none_or(|p| area > p.1) {
                    pick = Some((i, area, a, b));
                }
            }
        }
        let Some((i, _, a, b)) = pick else { break };
        // The opened child's two children take its place, in order, so the lanes stay in the
        // binary tree's left-to-right order.
        kids.copy_within(i + 1..len, i + 2);
        kids[i] = a;
        kids[i + 1] = b;
        len += 1;
    }
    (kids, len)
}

/// The wide node for binary inner node `b`: its two children opened, then the largest inner
/// child among them opened until four (or only leaves) remain; returns its index.
fn node(bin: &[Node], b: usize, out: &mut Vec<Wide>) -> u32 {
    let inner = |k: usize| (bin[k].n == 0).then(|| (bin[k].area(), k + 1, bin[k].a as usize));
    let (kids, len) = open(b + 1, bin[b].a as usize, inner);
    let me = out.len();
    out.push(Wide::empty());
    let mut w = Wide::empty();
    for (lane, &k) in kids[..len].iter().enumerate() {
        w.set(lane, &bin[k]);
        if bin[k].n > 0 {
            w.child[lane] = bin[k].a;
            w.count[lane] = leaf_count(&bin[k]);
        } else {
            w.child[lane] = node(bin, k, out);
        }
    }
    out[me] = w;
    me as u32
}

/// The tree as the Morton build leaves it: binary splits over ranges, each range collapsed to
/// its own four-wide tree on the core that built it, while its nodes are still in cache. A
/// split carries its box in a [`Node`].
pub enum Upper {
    /// A range's binary root (its box, or the leaf it is) and its four-wide tree (empty when
    /// the root is a leaf).
    Range(Node, Vec<Wide>),
    Split(Node, Box<Upper>, Box<Upper>),
}

impl Upper {
    /// A range over the binary tree `bin` (root at 0).
    pub fn range(bin: Vec<Node>) -> Upper {
        let wide = if bin[0].n > 0 { Vec::new() } else { collapse(&bin) };
        Upper::Range(bin[0], wide)
    }

    /// Its binary root's box.
    pub fn node(&self) -> &Node {
        match self {
            Upper::Range(n, _) | Upper::Split(n, ..) => n,
        }
    }

    /// The four-wide tree, root at 0: the splits collapsed as a binary tree is (a range's
    /// root is not opened into the node above it), then every range's tree appended in the
    /// order the splits meet them, its inner children shifted as it is copied.
    pub fn collapse(self) -> Vec<Wide> {
        match self {
            Upper::Range(root, _) if root.n > 0 => return lone_leaf(&root),
            Upper::Range(_, wide) => return wide,
            Upper::Split(..) => {}
        }
        let (mut out, mut later) = (Vec::new(), Vec::new());
        split_node(&self, &mut out, &mut later);
        // Each range's tree goes after the upper nodes, in the order the splits met them; the
        // copies (tens of MB at 10M triangles, every page of them new) run on every core.
        let base = out.len();
        let mut starts = Vec::with_capacity(later.len() + 1);
        starts.push(0);
        for &(me, lane, wide) in &later {
            let start = *starts.last().expect("starts at 0");
            out[me].child[lane] = (base + start) as u32;
            starts.push(start + wide.len());
        }
        let total = *starts.last().expect("starts at 0");
        out.reserve_exact(total);
        out.par_extend((0..total).into_par_iter().map(|i| {
            let r = starts.partition_point(|&s| s <= i) - 1;
            let mut n = later[r].2[i - starts[r]];
            let at = (base + starts[r]) as u32;
            for k in (0..4).filter(|&k| n.lanes & (1 << k) != 0 && n.count[k] == 0) {
                n.child[k] += at;
            }
            n
        }));
        out
    }
}

/// The wide node for split `s`, as [`node`] builds one; lanes whose child is a range's root
/// (not a leaf) are listed in `later` as (node, lane, the range's tree) to be pointed at it
/// once placed.
fn split_node<'a>(s: &'a Upper, out: &mut Vec<Wide>, later: &mut Vec<(usize, usize, &'a [Wide])>) -> u32 {
    let Upper::Split(_, l, r) = s else { unreachable!("split_node is given splits") };
    let inner = |k: &'a Upper| match k {
        Upper::Split(n, a, b) => Some((n.area(), &**a, &**b)),
        Upper::Range(..) => None,
    };
    let (kids, len) = open(&**l, &**r, inner);
    let me = out.len();
    out.push(Wide::empty());
    let mut w = Wide::empty();
    for (lane, k) in kids[..len].iter().enumerate() {
        w.set(lane, k.node());
        match k {
            Upper::Split(..) => w.child[lane] = split_node(k, out, later),
            Upper::Range(root, _) if root.n > 0 => {
                w.child[lane] = root.a;
                w.count[lane] = leaf_count(root);
            }
            Upper::Range(_, wide) => later.push((me, lane, wide)),
        }
    }
    out[me] = w;
    me as u32
}
