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
}

/// No representative found (yet): the entry represents itself.
const SELF: u32 = u32::MAX;

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
    let mut buf = vec![Tmp { p: [0.0; 3], id: 0 }; n];
    for (k, &b) in buckets.iter().enumerate() {
        let id = id_of(k);
        let slot = &mut cursor[b as usize];
        buf[*slot] = Tmp { p: c.pos(id as usize), id };
        *slot += 1;
    }
    drop(buckets);
    // Representatives, aligned with the final (partitioned) buffer positions.
    let mut reps = vec![SELF; n];
    let mut slices = Vec::with_capacity(GROUPS);
    let (mut rest, mut rest_r) = (buf.as_mut_slice(), reps.as_mut_slice());
    for g in 0..GROUPS {
        let len = start[g + 1] - start[g];
        let (head, tail) = rest.split_at_mut(len);
        let (head_r, tail_r) = rest_r.split_at_mut(len);
        if len >= 2 {
            slices.push((head, head_r));
        }
        rest = tail;
        rest_r = tail_r;
    }
    slices.into_par_iter().with_max_len(1).for_each(|(s, r)| merge(c, s, r));
    // List position of an input corner id: the inverse of `id_of`.
    let mut pos_of_face = vec![0u32; order.len()];
    for (t, &f) in order.iter().enumerate() {
        pos_of_face[f as usize] = t as u32;
    }
    for (t, &r) in buf.iter().zip(&reps) {
        if r != SELF {
            let k = 3 * pos_of_face[(t.id / 3) as usize] as usize + (t.id % 3) as usize;
            welded[k] = r;
        }
    }
    welded
}

type BBox = Option<(V3, V3)>;

/// `merge_verts_fast` of the reference with an explicit stack. Each cell's bounding box is
/// gathered while its parent is partitioned (min/max ignore NaN and the order of folding; the
/// sign of a zero bound can differ but never changes a comparison the reference makes).
fn merge(c: &Corners, buf: &mut [Tmp], reps: &mut [u32]) {
    let bbox = buf.iter().fold(None, |acc, t| fold_bbox(acc, t.p));
    let mut stack = vec![(0usize, buf.len(), bbox)];
    let mut attrs: Vec<([f32; 3], [f32; 2])> = Vec::new();
    while let Some((lo, hi, bbox)) = stack.pop() {
        let b = &mut buf[lo..hi];
        if b.len() < 2 {
            continue;
        }
        let Some((mn, mx)) = bbox else {
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
            leaf(c, b, &mut reps[lo..hi], &mut attrs);
            continue;
        }
        let (part, left, right) = partition(b, ax, sep);
        stack.push((lo + part, hi, right));
        stack.push((lo, lo + part, left));
    }
}

/// The reference's pairwise-swap partition, step for step (NaN coordinates are neither
/// `>= sep` nor `< sep` and stay where the scans leave them). Returns the split point and the
/// bounding boxes of both sides: everything the forward scan passes ends up left, everything
/// the backward scan passes ends up right, and each swapped pair changes sides.
fn partition(b: &mut [Tmp], ax: usize, sep: f32) -> (usize, BBox, BBox) {
    let (mut left, mut right): (BBox, BBox) = (None, None);
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
            left = fold_bbox(left, b[i].p);
        }
        let mut z = None;
        while start < end {
            end -= 1;
            if b[end].p[ax] < sep {
                z = Some(end);
                break;
            }
            right = fold_bbox(right, b[end].p);
        }
        match (a, z) {
            (Some(a), Some(z)) => {
                b.swap(a, z);
                left = fold_bbox(left, b[a].p);
                right = fold_bbox(right, b[z].p);
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
    let part = if start < end && b[start].p[ax] < sep { start + 1 } else { start };
    // At most one element is left between the scans; it sits on the side `part` gives it.
    for i in start..end {
        if i < part {
            left = fold_bbox(left, b[i].p);
        } else {
            right = fold_bbox(right, b[i].p);
        }
    }
    (part, left, right)
}

const SMALL_LEAF: usize = 24;

/// Welds every corner of a leaf onto the first equal corner in leaf order.
fn leaf(c: &Corners, b: &[Tmp], reps: &mut [u32], attrs: &mut Vec<([f32; 3], [f32; 2])>) {
    attrs.clear();
    attrs.extend(b.iter().map(|t| (c.nrm(t.id as usize), c.uv(t.id as usize))));
    if b.len() <= SMALL_LEAF {
        for l in 1..b.len() {
            let (pa, (na, ua)) = (b[l].p, attrs[l]);
            for m in 0..l {
                if eq3(pa, b[m].p) && eq3(na, attrs[m].0) && ua == attrs[m].1 {
                    reps[l] = if reps[m] == SELF { b[m].id } else { reps[m] };
                    break;
                }
            }
        }
        return;
    }
    let mut first: HashMap<[u32; 8], u32> = HashMap::with_capacity(b.len());
    for (l, t) in b.iter().enumerate() {
        let (n, u) = attrs[l];
        let all = [t.p[0], t.p[1], t.p[2], n[0], n[1], n[2], u[0], u[1]];
        if all.iter().any(|x| x.is_nan()) {
            continue; // never equal to anything, never a representative of another
        }
        let r = *first.entry(all.map(canon_bits)).or_insert(t.id);
        if r != t.id {
            reps[l] = r;
        }
    }
}
