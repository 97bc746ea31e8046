//! The tree as the rays walk it: four children to a node, their boxes side by side, so one
//! node's four slab tests are four-lane vector operations and a ray fetches about half as many
//! nodes as in the binary tree it is collapsed from.

use super::bvh::Node;
use glam::Vec4;

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
pub fn collapse(bin: &[Node]) -> Vec<Wide> {
    let mut out = Vec::with_capacity(bin.len() / 3 + 1);
    if bin[0].n > 0 {
        // A tree that is one leaf: a root with that leaf as its only child.
        let mut w = Wide::empty();
        w.set(0, &bin[0]);
        w.child[0] = bin[0].a;
        w.count[0] = leaf_count(&bin[0]);
        out.push(w);
    } else {
        node(bin, 0, &mut out);
    }
    out
}

fn leaf_count(n: &Node) -> u8 {
    u8::try_from(n.n).expect("leaves hold at most 255 triangles")
}

fn area(n: &Node) -> f32 {
    let d = [n.max[0] - n.min[0], n.max[1] - n.min[1], n.max[2] - n.min[2]];
    d[0] * d[1] + d[1] * d[2] + d[2] * d[0]
}

/// The wide node for binary inner node `b`: its two children opened, then the largest inner
/// child among them opened until four (or only leaves) remain; returns its index.
fn node(bin: &[Node], b: usize, out: &mut Vec<Wide>) -> u32 {
    let mut kids = [0usize; 4];
    kids[..2].copy_from_slice(&[b + 1, bin[b].a as usize]);
    let mut len = 2;
    while len < 4 {
        let mut pick: Option<(usize, f32)> = None;
        for (i, &k) in kids[..len].iter().enumerate() {
            if bin[k].n == 0 && pick.is_none_or(|(_, a)| area(&bin[k]) > a) {
                pick = Some((i, area(&bin[k])));
            }
        }
        let Some((i, _)) = pick else { break };
        let k = kids[i];
        // The opened child's two children take its place, in order, so the lanes stay in the
        // binary tree's left-to-right order.
        kids.copy_within(i + 1..len, i + 2);
        kids[i] = k + 1;
        kids[i + 1] = bin[k].a as usize;
        len += 1;
    }
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
