//! What every level of the SAH build decides with: the bins, the cost model and the choice of a
//! boundary, shared by the builders of large ranges (`sah.rs`), of ranges of up to 256 triangles
//! (`range.rs`) and of up to 16 (`small.rs`).

use super::bounds::Aabb;
use glam::Vec3A;

pub(super) const BINS: usize = 16;
/// Ranges of at most this many triangles are leaves, larger ones are split (those whose centres
/// cannot be told apart end in leaves of up to twice this). The rays, cast in packets, test
/// four triangles for less than the node visit that would part them: at 10.24M triangles this
/// gave 36% fewer nodes than leaving leaves of three and four to the cost model (with a node
/// visit costed as two triangle tests), the build faster and the rays no slower
/// (`docs/transfer.md`, "The tree build").
pub(super) const MAX_LEAF: usize = 4;
/// Ranges of at most this many items are split exactly, without bins (`small.rs`).
pub(super) const SMALL: usize = 16;

/// Per bin: the items' bounds, their centres' bounds and their count (of triangles: an item
/// may be a pair, `pairs.rs`).
pub(super) type Bins = [(Aabb, Aabb, usize); BINS];

/// A binned split: the axis, the boundary (items in bins below `bin` go left), the left side's
/// count, and each side's bounds and centre bounds.
pub(super) struct Split {
    pub axis: usize,
    pub bin: usize,
    pub left_count: usize,
    pub left: (Aabb, Aabb),
    pub right: (Aabb, Aabb),
}

/// The best boundary between `bins` (of `n` triangles, binned along `axis`), or `None` when
/// one bin holds them all.
pub(super) fn choose(bins: &Bins, n: usize, axis: usize) -> Option<Split> {
    // Sweep from the right, then from the left: the cost of each boundary.
    let mut right_cost = [0.0f32; BINS];
    let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
    for k in (1..BINS).rev() {
        acc.join(&bins[k].0);
        cnt += bins[k].2;
        right_cost[k] = acc.area() * cnt as f32;
    }
    let mut best: Option<(f32, usize, usize)> = None;
    let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
    for k in 1..BINS {
        acc.join(&bins[k - 1].0);
        cnt += bins[k - 1].2;
        if cnt == 0 || cnt == n {
            continue;
        }
        let cost = acc.area() * cnt as f32 + right_cost[k];
        if best.map(|(bc, ..)| cost < bc).unwrap_or(true) {
            best = Some((cost, k, cnt));
        }
    }
    let (_, k, left_count) = best?;
    Some(Split { axis, bin: k, left_count, left: bins_bounds(bins, 0..k), right: bins_bounds(bins, k..BINS) })
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
