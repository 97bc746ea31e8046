//! The binary tree collapsed to four-wide nodes, as the rays walk it: a ray fetches about half
//! as many nodes as in the binary tree, and tests a node's four boxes at once.

use super::node::{Node, WideNode};
use rayon::prelude::*;

/// A tree that is one leaf: a root with that leaf as its only child.
fn lone_leaf(leaf: &Node) -> Vec<WideNode> {
    let mut w = WideNode::empty();
    w.set_box(0, leaf);
    w.child[0] = leaf.right_or_first;
    w.count[0] = leaf_count(leaf);
    vec![w]
}

fn leaf_count(n: &Node) -> u8 {
    u8::try_from(n.count).expect("leaves hold at most 255 triangles")
}

/// The children a wide node takes from a binary node whose children are `l` and `r`: the
/// largest (by area) inner child opened into its own two children, in place, until four (or
/// only leaves) remain. `inner` gives an inner child's area and children, `None` for a leaf.
/// Opening the largest first keeps the children the rays are likeliest to enter in one node.
fn open<T: Copy>(l: T, r: T, inner: impl Fn(T) -> Option<(f32, T, T)>) -> ([T; 4], usize) {
    let mut kids = [l, r, r, r];
    // Each child's `inner`, asked once: a child stays in the node until it is opened.
    let mut info = [inner(l), inner(r), None, None];
    let mut len = 2;
    while len < 4 {
        let mut pick: Option<(usize, f32)> = None;
        for (i, k) in info[..len].iter().enumerate() {
            if let Some((area, ..)) = *k {
                if pick.is_none_or(|p| area > p.1) {
                    pick = Some((i, area));
                }
            }
        }
        let Some((i, _)) = pick else { break };
        let Some((_, a, b)) = info[i] else { break };
        // The opened child's two children take its place, in order, so the lanes stay in the
        // binary tree's left-to-right order.
        kids.copy_within(i + 1..len, i + 2);
        info.copy_within(i + 1..len, i + 2);
        kids[i] = a;
        kids[i + 1] = b;
        info[i] = inner(a);
        info[i + 1] = inner(b);
        len += 1;
    }
    (kids, len)
}

/// The wide node for binary inner node `b`: its two children opened, then the largest inner
/// child among them opened until four (or only leaves) remain; returns its index.
fn collapse_inner(bin: &[Node], b: usize, out: &mut Vec<WideNode>) -> u32 {
    let inner = |k: usize| (!bin[k].is_leaf()).then(|| (bin[k].area(), k + 1, bin[k].right_or_first as usize));
    let (kids, len) = open(b + 1, bin[b].right_or_first as usize, inner);
    let me = out.len();
    out.push(WideNode::empty());
    let mut w = WideNode::empty();
    for (lane, &k) in kids[..len].iter().enumerate() {
        w.set_box(lane, &bin[k]);
        if bin[k].is_leaf() {
            w.child[lane] = bin[k].right_or_first;
            w.count[lane] = leaf_count(&bin[k]);
        } else {
            w.child[lane] = collapse_inner(bin, k, out);
        }
    }
    out[me] = w;
    me as u32
}

/// The most nodes a thread's collapse buffer keeps between ranges (a range's tree has fewer).
const SCRATCH_KEPT: usize = 4096;

thread_local! {
    static SCRATCH: std::cell::RefCell<Vec<WideNode>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// The tree as the Morton build leaves it: binary splits over ranges, each range collapsed to
/// its own four-wide tree on the core that built it, while its nodes are still in cache. A
/// split carries its box in a [`Node`].
pub(super) enum Upper {
    /// A range's binary root (its box, or the leaf it is) and its four-wide tree (empty when
    /// the root is a leaf).
    Range(Node, Vec<WideNode>),
    Split(Node, Box<Upper>, Box<Upper>),
}

impl Upper {
    /// A range over the binary tree `bin` (root at 0). Collapsed in a buffer each thread
    /// reuses, then copied out at its size: tens of thousands of ranges at 10M triangles, and a
    /// vector each grown to fit cost their allocations and copies.
    pub fn range(bin: &[Node]) -> Upper {
        if bin[0].is_leaf() {
            return Upper::Range(bin[0], Vec::new());
        }
        let wide = SCRATCH.with(|s| {
            let mut s = s.borrow_mut();
            s.clear();
            collapse_inner(bin, 0, &mut s);
            let wide = s.to_vec();
            // A whole tree built without ranges (a small HIGH) is not held on to.
            if s.capacity() > SCRATCH_KEPT {
                *s = Vec::new();
            }
            wide
        });
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
    pub fn collapse(self) -> Vec<WideNode> {
        match self {
            Upper::Range(root, _) if root.is_leaf() => return lone_leaf(&root),
            Upper::Range(_, wide) => return wide,
            Upper::Split(..) => {}
        }
        let (mut out, mut later) = (Vec::new(), Vec::new());
        collapse_split(&self, &mut out, &mut later);
        // Each range's tree goes after the upper nodes, in the order the splits met them; the
        // copies (tens of MB at 10M triangles, into new pages) run on every core.
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
        crate::pages::prefault(out.spare_capacity_mut());
        // Each task walks its indices upwards, so the range holding index `i` is found by one
        // search per task and then by stepping on.
        out.par_extend((0..total).into_par_iter().map_init(
            || usize::MAX,
            |r, i| {
                if *r == usize::MAX || i < starts[*r] {
                    *r = starts.partition_point(|&s| s <= i) - 1;
                }
                while i >= starts[*r + 1] {
                    *r += 1;
                }
                let mut n = later[*r].2[i - starts[*r]];
                let at = (base + starts[*r]) as u32;
                for k in 0..4 {
                    if n.has(k) && !n.is_leaf(k) {
                        n.child[k] += at;
                    }
                }
                n
            },
        ));
        out
    }
}

/// The wide node for split `s`, as [`collapse_inner`] builds one; lanes whose child is a
/// range's root (not a leaf) are listed in `later` as (node, lane, the range's tree) to be
/// pointed at it once placed.
fn collapse_split<'a>(s: &'a Upper, out: &mut Vec<WideNode>, later: &mut Vec<(usize, usize, &'a [WideNode])>) -> u32 {
    let Upper::Split(_, l, r) = s else { unreachable!("collapse_split is given splits") };
    let inner = |k: &'a Upper| match k {
        Upper::Split(n, a, b) => Some((n.area(), &**a, &**b)),
        Upper::Range(..) => None,
    };
    let (kids, len) = open(&**l, &**r, inner);
    let me = out.len();
    out.push(WideNode::empty());
    let mut w = WideNode::empty();
    for (lane, k) in kids[..len].iter().enumerate() {
        w.set_box(lane, k.node());
        match k {
            Upper::Split(..) => w.child[lane] = collapse_split(k, out, later),
            Upper::Range(root, _) if root.is_leaf() => {
                w.child[lane] = root.right_or_first;
                w.count[lane] = leaf_count(root);
            }
            Upper::Range(_, wide) => later.push((me, lane, wide)),
        }
    }
    out[me] = w;
    me as u32
}
