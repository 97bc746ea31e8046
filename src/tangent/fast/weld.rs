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
use super::triangles::Order;
use super::Corners;
use rayon::prelude::*;
use std::collections::HashMap;

#[derive(Clone, Copy)]
struct Tmp {
    p: V3,
    /// List position (`3 * internal triangle + corner`) of this entry.
    k: u32,
}

/// No representative found (yet): the entry represents itself.
const SELF: u32 = u32::MAX;

const GROUPS: usize = 2048;
const CHUNK: usize = 1 << 15;

/// A bounding box that ignores NaN like the reference's `f32::min`/`max` fold, with one
/// compare-and-select per bound. Empty components (no non-NaN value) read back as NaN, as in the
/// reference. (The sign of a zero bound may differ; no comparison the reference makes can see
/// it.)
#[derive(Clone, Copy)]
struct BBox {
    mn: V3,
    mx: V3,
}

const EMPTY: BBox = BBox { mn: [f32::INFINITY; 3], mx: [f32::NEG_INFINITY; 3] };

impl BBox {
    #[inline]
    fn grow(&mut self, p: V3) {
        #[allow(clippy::needless_range_loop)] // one axis of three arrays at a time
        for c in 0..3 {
            self.mn[c] = if p[c] < self.mn[c] { p[c] } else { self.mn[c] };
            self.mx[c] = if p[c] > self.mx[c] { p[c] } else { self.mx[c] };
        }
    }
    #[inline]
    fn union(mut self, o: BBox) -> BBox {
        for c in 0..3 {
            self.mn[c] = if o.mn[c] < self.mn[c] { o.mn[c] } else { self.mn[c] };
            self.mx[c] = if o.mx[c] > self.mx[c] { o.mx[c] } else { self.mx[c] };
        }
        self
    }
    fn bounds(self) -> (V3, V3) {
        let (mut mn, mut mx) = (self.mn, self.mx);
        for c in 0..3 {
            if mn[c] > mx[c] {
                mn[c] = f32::NAN;
                mx[c] = f32::NAN;
            }
        }
        (mn, mx)
    }
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

/// The first split of the legacy weld: the bounding box of all corners, its longest axis, and
/// which of the [`GROUPS`] buckets along it each position falls in.
struct Buckets {
    mn: V3,
    d: V3,
    cm: usize,
}

impl Buckets {
    /// The split for the `n` list entries whose positions `pos_of` gives; `None` for an empty
    /// list. The bounding box is folded in fixed chunks (same value as the reference's
    /// sequential fold; the chunking does not depend on the thread count).
    fn new(n: usize, pos_of: impl Fn(usize) -> V3 + Sync) -> Option<Buckets> {
        let bbox = (0..n.div_ceil(CHUNK))
            .into_par_iter()
            .map(|ch| {
                let mut b = EMPTY;
                (ch * CHUNK..n.min((ch + 1) * CHUNK)).for_each(|k| b.grow(pos_of(k)));
                b
            })
            .collect::<Vec<_>>()
            .into_iter()
            .fold(EMPTY, BBox::union);
        Self::from_bbox(bbox, n)
    }
    /// The split for a list of `n` entries with bounding box `bbox`.
    fn from_bbox(bbox: BBox, n: usize) -> Option<Buckets> {
        if n == 0 {
            return None;
        }
        let (mn, mx) = bbox.bounds();
        let d = [mx[0] - mn[0], mx[1] - mn[1], mx[2] - mn[2]];
        Some(Buckets { mn, d, cm: longest_axis(d) })
    }
    #[inline]
    fn of(&self, p: &V3) -> usize {
        let cm = self.cm;
        let t = (p[cm] - self.mn[cm]) / self.d[cm];
        let g = (GROUPS as f32 * t.clamp(0.0, 1.0)) as u16;
        g.min(GROUPS as u16 - 1) as usize
    }
}

/// Positions in list order, gathered once.
fn list_positions(c: &Corners, order: &Order) -> Vec<V3> {
    (0..order.len() * 3)
        .into_par_iter()
        .with_min_len(1 << 12)
        .map(|k| c.pos(3 * order.at(k / 3) as usize + k % 3))
        .collect()
}

/// The welded id [`weld`] gives list entries `ks`, replaying only the buckets they fall in.
pub(crate) fn welded_of(c: &Corners, order: &Order, ks: &[usize]) -> Vec<u32> {
    let id_of = |k: usize| 3 * order.at(k / 3) + (k % 3) as u32;
    let pos_of = |k: usize| c.pos(id_of(k) as usize);
    let n = order.len() * 3;
    let Some(bk) = Buckets::new(n, pos_of) else { return Vec::new() };
    let mut wanted = vec![false; GROUPS];
    ks.iter().for_each(|&k| wanted[bk.of(&pos_of(k))] = true);
    // Each wanted bucket's entries in list order (the reference's stable bucket sort).
    let found: Vec<Vec<(u16, Tmp)>> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|ch| {
            (ch * CHUNK..n.min((ch + 1) * CHUNK))
                .filter_map(|k| {
                    let p = pos_of(k);
                    let g = bk.of(&p);
                    wanted[g].then_some((g as u16, Tmp { p, k: k as u32 }))
                })
                .collect()
        })
        .collect();
    let mut bufs: Vec<Vec<Tmp>> = vec![Vec::new(); GROUPS];
    for (g, t) in found.into_iter().flatten() {
        bufs[g as usize].push(t);
    }
    let mut answer: HashMap<usize, u32> = ks.iter().map(|&k| (k, id_of(k))).collect();
    for mut buf in bufs.into_iter().filter(|b| !b.is_empty()) {
        let mut reps = vec![SELF; buf.len()];
        merge(c, order, &mut buf, &mut reps);
        for (t, &r) in buf.iter().zip(&reps) {
            if let Some(a) = answer.get_mut(&(t.k as usize)) {
                if r != SELF {
                    *a = r;
                }
            }
        }
    }
    ks.iter().map(|k| answer[k]).collect()
}

/// Returns, for each list entry `k` (3 per internal triangle, good triangles first), the input
/// corner id of its welded representative.
pub(crate) fn weld(c: &Corners, order: &Order) -> Vec<u32> {
    let n = order.len() * 3;
    let id_of = |k: usize| 3 * order.at(k / 3) + (k % 3) as u32;
    let pos = list_positions(c, order);
    let mut welded: Vec<u32> = (0..n).into_par_iter().with_min_len(1 << 12).map(id_of).collect();
    let Some(bk) = Buckets::new(pos.len(), |k| pos[k]) else { return welded };
    let bucket_of = |p: &V3| bk.of(p);
    // Stable counting sort by bucket (the reference's `sort_by_key`), in parallel: each chunk of
    // the list sorts itself by bucket, then each bucket concatenates its segments chunk by chunk.
    let chunks: Vec<(Vec<Tmp>, Vec<u32>)> = pos
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(ci, ch)| {
            let mut start = vec![0u32; GROUPS + 1];
            let bs: Vec<u16> = ch.iter().map(|p| bucket_of(p) as u16).collect();
            for &b in &bs {
                start[b as usize + 1] += 1;
            }
            for g in 0..GROUPS {
                start[g + 1] += start[g];
            }
            let mut cursor = start.clone();
            let mut out = vec![Tmp { p: [0.0; 3], k: 0 }; ch.len()];
            for (i, (&b, &p)) in bs.iter().zip(ch).enumerate() {
                let slot = &mut cursor[b as usize];
                out[*slot as usize] = Tmp { p, k: (ci * CHUNK + i) as u32 };
                *slot += 1;
            }
            (out, start)
        })
        .collect();
    drop(pos);
    let results: Vec<(Vec<Tmp>, Vec<u32>)> = (0..GROUPS)
        .into_par_iter()
        .with_max_len(1)
        .filter_map(|g| {
            let len: usize = chunks.iter().map(|(_, st)| (st[g + 1] - st[g]) as usize).sum();
            if len < 2 {
                return None;
            }
            let mut buf = Vec::with_capacity(len);
            for (out, st) in &chunks {
                buf.extend_from_slice(&out[st[g] as usize..st[g + 1] as usize]);
            }
            // Representatives, aligned with the final (partitioned) buffer positions.
            let mut reps = vec![SELF; len];
            merge(c, order, &mut buf, &mut reps);
            Some((buf, reps))
        })
        .collect();
    for (buf, reps) in &results {
        for (t, &r) in buf.iter().zip(reps) {
            if r != SELF {
                welded[t.k as usize] = r;
            }
        }
    }
    welded
}

/// `merge_verts_fast` of the reference with an explicit stack. Each cell's bounding box is
/// gathered while its parent is partitioned (min/max ignore NaN and the order of folding; the
/// sign of a zero bound can differ but never changes a comparison the reference makes).
fn merge(c: &Corners, order: &Order, buf: &mut [Tmp], reps: &mut [u32]) {
    let mut bbox = EMPTY;
    buf.iter().for_each(|t| bbox.grow(t.p));
    let mut stack = vec![(0usize, buf.len(), bbox)];
    let mut attrs: Vec<(u32, [f32; 3], [f32; 2])> = Vec::new();
    while let Some((lo, hi, bbox)) = stack.pop() {
        let b = &mut buf[lo..hi];
        if b.len() < 2 {
            continue;
        }
        let (mn, mx) = bbox.bounds();
        let d = [mx[0] - mn[0], mx[1] - mn[1], mx[2] - mn[2]];
        let ax = longest_axis(d);
        let sep = 0.5f32 * (mx[ax] + mn[ax]);
        if !sep.is_finite() {
            // The reference gives up on this cell: nothing in it is welded.
            continue;
        }
        if !(mn[ax] < sep && sep < mx[ax]) {
            leaf(c, order, b, &mut reps[lo..hi], &mut attrs);
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
    let (mut left, mut right) = (EMPTY, EMPTY);
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
            left.grow(b[i].p);
        }
        let mut z = None;
        while start < end {
            end -= 1;
            if b[end].p[ax] < sep {
                z = Some(end);
                break;
            }
            right.grow(b[end].p);
        }
        match (a, z) {
            (Some(a), Some(z)) => {
                b.swap(a, z);
                left.grow(b[a].p);
                right.grow(b[z].p);
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
    for (i, e) in b.iter().enumerate().take(end).skip(start) {
        if i < part {
            left.grow(e.p);
        } else {
            right.grow(e.p);
        }
    }
    (part, left, right)
}

const SMALL_LEAF: usize = 24;

/// Welds every corner of a leaf onto the first equal corner in leaf order.
fn leaf(c: &Corners, order: &Order, b: &[Tmp], reps: &mut [u32], attrs: &mut Vec<(u32, [f32; 3], [f32; 2])>) {
    attrs.clear();
    attrs.extend(b.iter().map(|t| {
        let id = 3 * order.at(t.k as usize / 3) + t.k % 3;
        (id, c.nrm(id as usize), c.uv(id as usize))
    }));
    if b.len() <= SMALL_LEAF {
        for l in 1..b.len() {
            let (pa, (_, na, ua)) = (b[l].p, attrs[l]);
            for m in 0..l {
                if eq3(pa, b[m].p) && eq3(na, attrs[m].1) && ua == attrs[m].2 {
                    reps[l] = if reps[m] == SELF { attrs[m].0 } else { reps[m] };
                    break;
                }
            }
        }
        return;
    }
    let mut first: HashMap<[u32; 8], u32> = HashMap::with_capacity(b.len());
    for (l, t) in b.iter().enumerate() {
        let (id, n, u) = attrs[l];
        let all = [t.p[0], t.p[1], t.p[2], n[0], n[1], n[2], u[0], u[1]];
        if all.iter().any(|x| x.is_nan()) {
            continue; // never equal to anything, never a representative of another
        }
        let r = *first.entry(all.map(canon_bits)).or_insert(id);
        if r != id {
            reps[l] = r;
        }
    }
}
