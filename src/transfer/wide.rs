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

/// An [`Upper`] whose ranges are set aside, numbered in depth-first order.
enum Shape {
    Range(usize, Node),
    Split(Node, Box<Shape>, Box<Shape>),
}

impl Shape {
    fn node(&self) -> &Node {
        match self {
            Shape::Range(_, n) | Shape::Split(n, ..) => n,
        }
    }
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

    fn shape(self, ranges: &mut Vec<Vec<Wide>>) -> Shape {
        match self {
            Upper::Range(root, wide) => {
                ranges.push(wide);
                Shape::Range(ranges.len() - 1, root)
            }
            Upper::Split(n, l, r) => {
                let l = l.shape(ranges);
                Shape::Split(n, Box::new(l), Box::new(r.shape(ranges)))
            }
        }
    }

    /// The four-wide tree, root at 0: the splits collapsed as a binary tree is (a range's
    /// root is not opened into the node above it), then every range's tree appended in order.
    pub fn collapse(self) -> Vec<Wide> {
        let mut ranges = Vec::new();
        let shape = match self {
            Upper::Range(root, _) if root.n > 0 => return lone_leaf(&root),
            Upper::Range(_, wide) => return wide,
            split => split.shape(&mut ranges),
        };
        let (mut out, mut later) = (Vec::new(), Vec::new());
        split_node(&shape, &mut out, &mut later);
        let mut at = out.len();
        let offsets: Vec<u32> = ranges
            .iter()
            .map(|w| {
                let o = at as u32;
                at += w.len();
                o
            })
            .collect();
        for (me, lane, range) in later {
            out[me].child[lane] = offsets[range];
        }
        ranges.par_iter_mut().zip(&offsets).for_each(|(w, &o)| {
            for n in w.iter_mut() {
                for lane in (0..4).filter(|&k| n.lanes & (1 << k) != 0 && n.count[k] == 0) {
                    n.child[lane] += o;
                }
            }
        });
        out.reserve_exact(at - out.len());
        ranges.iter().for_each(|w| out.extend_from_slice(w));
        out
    }
}

/// The wide node for split `s`, as [`node`] builds one; lanes whose child is a range's root
/// (not a leaf) are listed in `later` as (node, lane, range) to be pointed at it once placed.
fn split_node<'a>(s: &'a Shape, out: &mut Vec<Wide>, later: &mut Vec<(usize, usize, usize)>) -> u32 {
    let Shape::Split(_, l, r) = s else { unreachable!("split_node is given splits") };
    let inner = |k: &'a Shape| match k {
        Shape::Split(n, a, b) => Some((n.area(), &**a, &**b)),
        Shape::Range(..) => None,
    };
    let (kids, len) = open(&**l, &**r, inner);
    let me = out.len();
    out.push(Wide::empty());
    let mut w = Wide::empty();
    for (lane, k) in kids[..len].iter().enumerate() {
        w.set(lane, k.node());
        match k {
            Shape::Split(..) => w.child[lane] = split_node(k, out, later),
            Shape::Range(_, root) if root.n > 0 => {
                w.child[lane] = root.a;
                w.count[lane] = leaf_count(root);
            }
            Shape::Range(range, _) => later.push((me, lane, *range)),
        }
    }
    out[me] = w;
    me as u32
}
