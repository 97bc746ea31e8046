//! The binary tree collapsed to four-wide nodes, as the rays walk it: a ray fetches about half
//! as many nodes as in the binary tree, and tests a node's four boxes at once.

use super::node::{Node, WideNode};

/// The root of a tree that is one leaf: that leaf as its only child.
fn lone_leaf(leaf: &Node) -> WideNode {
    let mut w = WideNode::empty();
    w.set_box(0, leaf);
    w.child[0] = leaf.right_or_first;
    w.count[0] = leaf_count(leaf);
    w
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

/// The four-wide tree over the binary tree `bin` (root at 0), root at 0: a tree built without
/// Morton ranges (a small HIGH).
pub(super) fn whole(bin: &[Node]) -> Vec<WideNode> {
    if bin[0].is_leaf() {
        return vec![lone_leaf(&bin[0])];
    }
    let mut out = Vec::new();
    collapse_inner(bin, 0, &mut out);
    out
}

/// Where the ranges of a part of the Morton build put their four-wide nodes: the part of the
/// tree's node array that its triangles' places address (a tree over `t` triangles has at most
/// `t - 1` four-wide nodes, each on two binary inner nodes or more, so parts never overlap).
/// The ranges of a part built on one thread append one after the other, so its nodes stay
/// together and the rest of its slots are never written: in a mapping that makes them pages
/// never made present (`node.rs`).
pub(super) struct Slots<'a> {
    nodes: &'a mut [WideNode],
    /// The index in the whole array of `nodes[0]`.
    at: usize,
    used: usize,
}

impl<'a> Slots<'a> {
    pub fn new(nodes: &'a mut [WideNode], at: usize) -> Slots<'a> {
        Slots { nodes, at, used: 0 }
    }

    /// The first `k` slots and the rest, for two parts built apart; none may be used yet.
    pub fn split_at(&mut self, k: usize) -> (Slots<'_>, Slots<'_>) {
        debug_assert_eq!(self.used, 0, "a part built on one thread is not split again");
        let (a, b) = self.nodes.split_at_mut(k);
        (Slots::new(a, self.at), Slots::new(b, self.at + k))
    }

    /// A range over the binary tree `bin` (root at 0), its four-wide tree collapsed in a buffer
    /// each thread reuses (while the range's nodes are still in cache) and copied into the next
    /// free slots, its inner children pointed at their places there.
    pub fn range(&mut self, bin: &[Node]) -> Upper {
        if bin[0].is_leaf() {
            return Upper::Range(bin[0], 0, 0);
        }
        SCRATCH.with(|s| {
            let mut s = s.borrow_mut();
            s.clear();
            collapse_inner(bin, 0, &mut s);
            let at = self.at + self.used;
            let shift = u32::try_from(at).expect("node indices fit 32 bits");
            let to =
                self.nodes.get_mut(self.used..self.used + s.len()).expect("a range has fewer nodes than triangles");
            for (slot, n) in to.iter_mut().zip(s.iter()) {
                let mut n = *n;
                for k in 0..4 {
                    if n.has(k) && !n.is_leaf(k) {
                        n.child[k] += shift;
                    }
                }
                *slot = n;
            }
            self.used += s.len();
            let len = s.len() as u32;
            // A pile of duplicates built as one range can be large: not held on to.
            if s.capacity() > SCRATCH_KEPT {
                *s = Vec::new();
            }
            Upper::Range(bin[0], shift, len)
        })
    }
}

/// The tree as the Morton build leaves it: binary splits over ranges, each range's four-wide
/// tree already in its slots of the node array. A split carries its box in a [`Node`].
pub(super) enum Upper {
    /// A range's binary root (its box, or the leaf it is), the index of its four-wide root in
    /// the node array and its count of four-wide nodes (0 when the root is a leaf).
    Range(Node, u32, u32),
    Split(Node, Box<Upper>, Box<Upper>),
}

impl Upper {
    /// Its binary root's box.
    pub fn node(&self) -> &Node {
        match self {
            Upper::Range(n, ..) | Upper::Split(n, ..) => n,
        }
    }

    /// The four-wide nodes over the splits, written from `nodes[0]` (the root), collapsed as a
    /// binary tree is (a range's root is not opened into the node above it), their lanes
    /// pointed at the ranges' roots in their slots; returns how many nodes the whole tree has.
    /// The nodes above the ranges go in the first `front` slots.
    pub fn collapse(self, nodes: &mut [WideNode], front: usize) -> usize {
        match self {
            Upper::Range(root, ..) if root.is_leaf() => {
                nodes[0] = lone_leaf(&root);
                return 1;
            }
            // One range: its root, whose children are placed already, copied to the front.
            Upper::Range(_, at, len) => {
                nodes[0] = nodes[at as usize];
                return len as usize;
            }
            Upper::Split(..) => {}
        }
        let mut out = Vec::new();
        let ranges = collapse_split(&self, &mut out);
        assert!(out.len() <= front, "room for the nodes above the ranges");
        nodes[..out.len()].copy_from_slice(&out);
        out.len() + ranges
    }
}

/// The wide node for split `s`, as [`collapse_inner`] builds one, pushed to `out` (whose
/// indices are the node array's); lanes whose child is a range's root point at its slot.
/// Returns the four-wide nodes of the ranges below.
fn collapse_split<'a>(s: &'a Upper, out: &mut Vec<WideNode>) -> usize {
    let Upper::Split(_, l, r) = s else { unreachable!("collapse_split is given splits") };
    let inner = |k: &'a Upper| match k {
        Upper::Split(n, a, b) => Some((n.area(), &**a, &**b)),
        Upper::Range(..) => None,
    };
    let (kids, len) = open(&**l, &**r, inner);
    let me = out.len();
    out.push(WideNode::empty());
    let mut w = WideNode::empty();
    let mut ranges = 0;
    for (lane, k) in kids[..len].iter().enumerate() {
        w.set_box(lane, k.node());
        match k {
            Upper::Split(..) => {
                w.child[lane] = out.len() as u32;
                ranges += collapse_split(k, out);
            }
            Upper::Range(root, ..) if root.is_leaf() => {
                w.child[lane] = root.right_or_first;
                w.count[lane] = leaf_count(root);
            }
            Upper::Range(_, at, n) => {
                w.child[lane] = *at;
                ranges += *n as usize;
            }
        }
    }
    out[me] = w;
    ranges
}
