//! Vertex welding with the reference's exact outcome.
//!
//! The legacy weld (`weld_vertices_legacy.rs` in `bevy_mikktspace`, `GenerateSharedVerticesIndexList`
//! in C) buckets corners along the longest bounding-box axis, then splits each bucket by
//! recursive midpoint partitioning (Hoare-style swaps) until a cell has no interior midpoint,
//! and in each such leaf welds every corner onto the *first* equal corner in the leaf's current
//! order. The swaps reorder corners, so the representative is not always the lowest index: to
//! get the same representatives (they decide the edge order, hence the adjacency of
//! non-manifold edges, and the signed zeros read back) the partitioning is replayed exactly.
//! Only the leaf, quadratic in the reference, is replaced: a hash map of the first corner per
//! key (bit-exact key with `-0` folded onto `+0`, NaN never equal) gives the same "first equal"
//! in linear time.

use super::math::{canon_bits, eq3, V3};
use super::Corners;
use rayon::prelude::*;
use std::collections::HashMap;

#[derive(Clone, Copy)]
struct Tmp {
    p: V3,
    /// Input corner id (`3 * face + corner`) of this list entry.
    id: u32,
    /// List position (`3 * internal triangle + corner`).
    k: u32,
    /// Input corner id of the representative.
    rep: u32,
}

const GROUPS: usize = 2048;
const CHUNK: usize = 1 << 15;

fn fold_bbox(acc: Option<(V3, V3)>, v: V3) -> Option<(V3, V3)> {
    let (mut mn, mut mx) = acc.unwrap_or((v, v));
    for c in 0..3 {
        mn[c] = mn[c].min(v[c]);
        mx[c] = mx[c].max(v[c]);
    }
    Some((mn, mx))
}

/// The reference's choice of the longest axis (ties and NaN resolve as in the reference).
fn longest_axis(d: V3) -> usize {
    if d[1] > d[0] && d[1] > d[2] {
        1
    } else if d[2] > d[0] {
        2
    } else {
        0
    }
}

/// Returns, for each list entry `k` (3 per internal triangle, good triangles first), the input
/// corner id of its welded representative.
pub(crate) fn weld(c: &Corners, order: &[u32]) -> Vec<u32> {
    let n = order.len() * 3;
    let id_of = |k: usize| 3 * order[k / 3] + (k % 3) as u32;
    // Bounding box in fixed chunks (same value as the reference's sequential fold; the chunking
    // does not depend on the thread count).
    let bbox = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|ch| {
            (ch * CHUNK..n.min((ch + 1) * CHUNK))
                .fold(None, |acc, k| fold_bbox(acc, c.pos(id_of(k) as usize)))
        })
        .collect::<Vec<_>>()
        .into_iter()
        .flatten()
        .fold(None, |acc: Option<(V3, V3)>, (mn, mx)| {
            let acc = fold_bbox(acc, mn);
            fold_bbox(acc, mx)
        });
    let mut welded: Vec<u32> = (0..n).map(id_of).collect();
    let Some((mn, mx)) = bbox else {
        return welded;
    };
    let d = [mx[0] - mn[0], mx[1] - mn[1], mx[2] - mn[2]];
    let cm = longest_axis(d);
    let buckets: Vec<u16> = (0..n)
        .into_par_iter()
        .map(|k| {
            let p = c.pos(id_of(k) as usize);
            let t = (p[cm] - mn[cm]) / d[cm];
            let g = (GROUPS as f32 * t.clamp(0.0, 1.0)) as u16;
            g.min(GROUPS as u16 - 1)
        })
        .collect();
    // Stable counting sort by bucket (the reference's `sort_by_key`).
    let mut start = vec![0usize; GROUPS + 1];
    for &b in &buckets {
        start[b as usize + 1] += 1;
    }
    for g in 0..GROUPS {
        start[g + 1] += start[g];
    }
    let mut cursor = start.clone();
    let mut buf = vec![Tmp { p: [0.0; 3], id: 0, k: 0, rep: 0 }; n];
    for (k, &b) in buckets.iter().enumerate() {
        let id = id_of(k);
        let slot = &mut cursor[b as usize];
        buf[*slot] = Tmp { p: c.pos(id as usize), id, k: k as u32, rep: id };
        *slot += 1;
    }
    drop(buckets);
    let mut slices = Vec::with_capacity(GROUPS);
    let mut rest = buf.as_mut_slice();
    for g in 0..GROUPS {
        let (head, tail) = rest.split_at_mut(start[g + 1] - start[g]);
        if head.len() >= 2 {
            slices.push(head);
        }
        rest = tail;
    }
    slices.into_par_iter().with_max_len(1).for_each(|s| merge(c, s));
    for t in &buf {
        welded[t.k as usize] = t.rep;
    }
    welded
}

/// `merge_verts_fast` of the reference with an explicit stack.
fn merge(c: &Corners, buf: &mut [Tmp]) {
    let mut stack = vec![(0usize, buf.len())];
    while let Some((lo, hi)) = stack.pop() {
        let b = &mut buf[lo..hi];
        if b.len() < 2 {
            continue;
        }
        let Some((mn, mx)) = b.iter().fold(None, |acc, t| fold_bbox(acc, t.p)) else {
            continue;
        };
        let d = [mx[0] - mn[0], mx[1] - mn[1], mx[2] - mn[2]];
        let ax = longest_axis(d);
        let sep = 0.5f32 * (mx[ax] + mn[ax]);
        if !sep.is_finite() {
            // The reference gives up on this cell: nothing in it is welded.
            continue;
        }
        if !(mn[ax] < sep && sep < mx[ax]) {
            leaf(c, b);
            continue;
        }
        let part = partition(b, ax, sep);
        stack.push((lo + part, hi));
        stack.push((lo, lo + part));
    }
}

/// The reference's pairwise-swap partition, step for step (NaN coordinates are neither
/// `>= sep` nor `< sep` and stay where the scans leave them).
fn partition(b: &mut [Tmp], ax: usize, sep: f32) -> usize {
    let (mut start, mut end) = (0usize, b.len());
    while end - start >= 2 {
        let mut a = None;
        while start < end {
            let i = start;
            start += 1;
            if b[i].p[ax] >= sep {
                a = Some(i);
                break;
            }
        }
        let mut z = None;
        while start < end {
            end -= 1;
            if b[end].p[ax] < sep {
                z = Some(end);
                break;
            }
        }
        match (a, z) {
            (Some(a), Some(z)) => {
                b.swap(a, z);
                start = a + 1;
                end = z;
            }
            (None, Some(z)) => end = z + 1,
            (Some(a), None) => {
                start = a;
                end = a + 1;
            }
            (None, None) => {}
        }
    }
    if start < end && b[start].p[ax] < sep {
        start + 1
    } else {
        start
    }
}

const SMALL_LEAF: usize = 24;

/// Welds every corner of a leaf onto the first equal corner in leaf order.
fn leaf(c: &Corners, b: &mut [Tmp]) {
    if b.len() <= SMALL_LEAF {
        for l in 1..b.len() {
            let (pa, na, ua) = (b[l].p, c.nrm(b[l].id as usize), c.uv(b[l].id as usize));
            for m in 0..l {
                let id = b[m].id as usize;
                if eq3(pa, b[m].p) && eq3(na, c.nrm(id)) && ua == c.uv(id) {
                    b[l].rep = b[m].rep;
                    break;
                }
            }
        }
        return;
    }
    let mut first: HashMap<[u32; 8], u32> = HashMap::with_capacity(b.len());
    for t in b.iter_mut() {
        let (n, u) = (c.nrm(t.id as usize), c.uv(t.id as usize));
        let all = [t.p[0], t.p[1], t.p[2], n[0], n[1], n[2], u[0], u[1]];
        if all.iter().any(|x| x.is_nan()) {
            continue; // never equal to anything, never a representative of another
        }
        let key = all.map(canon_bits);
        t.rep = *first.entry(key).or_insert(t.rep);
    }
}
