//! The weld without replaying the reference's partitioning, when that provably changes nothing.
//!
//! [`super::weld`] replays the legacy partition only to learn *which* corner of each welded
//! class the reference picks as its representative. The classes themselves are simply the sets
//! of corners with equal position, normal and UV (`-0` equal to `+0`), as long as no coordinate
//! is NaN and no cell's midpoint can overflow: equal corners always fall into the same bucket and
//! the same side of every split. The representative's identity then matters in two places only:
//! - attributes are read back through it, so a class whose members differ in the sign of a zero
//!   would read different bits;
//! - its id orders the edge list, and only the edges with the largest smaller end (`i0`) are
//!   subject to the legacy sort's quirk when there are 3 or more of them ([`super::neighbors`]).
//!   Within a class the representative lies between the smallest and the largest member id, so
//!   bounding every edge's `i0` leaves a few edges that could have the largest. The exact
//!   representatives of their classes come from replaying only the buckets they fall in
//!   ([`super::weld::welded_of`]); when fewer than 3 edges share the largest `i0`, the quirk does
//!   not arise, and every other pairing depends on classes and triangle order alone.
//!
//! When all of that holds, any member represents its class, and classes are found by hashing the
//! input vertices (corners sharing an index are equal) instead of the corners.

use super::math::canon_bits;
use super::Corners;
use rayon::prelude::*;

/// Beyond this many edges that could share the largest `i0`, replaying their buckets is not
/// worth it: the full replay runs instead.
const MAX_CANDIDATES: usize = 256;

/// Welded ids as [`super::weld::weld`] gives them, up to the choice of representative within each
/// class, or `None` when that choice could change the output (or the input has NaN or huge
/// coordinates): the caller then replays the reference.
pub(crate) fn weld(c: &Corners, order: &[u32], n_good: usize) -> Option<Vec<u32>> {
    let idx = &c.mesh.indices[..3 * order.len()];
    let n_vertices = c.mesh.positions.len().min(c.mesh.normals.len()).min(c.mesh.uvs.len());
    // First and last corner id of each vertex (corner ids are 3 * face + j, in input order).
    let mut first = vec![u32::MAX; n_vertices];
    let mut last = vec![0u32; n_vertices];
    for (id, &v) in idx.iter().enumerate() {
        let v = v as usize;
        if first[v] == u32::MAX {
            first[v] = id as u32;
        }
        last[v] = id as u32;
    }
    // Each used vertex's class: the first vertex (by index) with equal canonical bits. Vertices
    // are split into shards by hash (equal keys share a shard), and each shard is resolved with
    // its own small open-addressing table of vertex ids, in parallel.
    let key = |v: usize| {
        let (p, n, u) = (c.mesh.positions[v], c.mesh.normals[v], c.mesh.uvs[v]);
        [p[0], p[1], p[2], n[0], n[1], n[2], u[0], u[1]]
    };
    const HUGE: f32 = f32::MAX / 4.0;
    let hashes: Vec<u64> = (0..n_vertices)
        .into_par_iter()
        .with_min_len(1 << 14)
        .map(|v| {
            let all = key(v);
            if first[v] == u32::MAX {
                return 0;
            }
            if all.iter().any(|x| x.is_nan()) || all[..3].iter().any(|x| !(x.abs() < HUGE)) {
                return u64::MAX; // no shortcut for NaN or huge coordinates
            }
            all.map(canon_bits).iter().fold(0u64, |h, &x| (h.rotate_left(5) ^ x as u64).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95)) | 1
        })
        .collect();
    if hashes.par_iter().any(|&h| h == u64::MAX) {
        return None;
    }
    const SHARD_BITS: u32 = 4;
    let mut shards: Vec<Vec<u32>> = vec![Vec::new(); 1 << SHARD_BITS];
    for (v, &h) in hashes.iter().enumerate() {
        if h != 0 {
            shards[(h >> (64 - SHARD_BITS)) as usize].push(v as u32);
        }
    }
    let resolved: Option<Vec<Vec<(u32, u32)>>> = shards
        .par_iter()
        .map(|vs| {
            let mask = (2 * vs.len()).next_power_of_two().max(16) - 1;
            let mut slots: Vec<(u32, u32)> = vec![(u32::MAX, 0); mask + 1];
            let mut out = Vec::new();
            for &v in vs {
                let h = hashes[v as usize];
                let all = key(v as usize);
                let mut i = h as usize & mask;
                loop {
                    let (s, t) = slots[i];
                    if s == u32::MAX {
                        slots[i] = (v, (h >> 32) as u32);
                        break;
                    }
                    if t == (h >> 32) as u32 && key(s as usize).map(canon_bits) == all.map(canon_bits) {
                        if key(s as usize).map(f32::to_bits) != all.map(f32::to_bits) {
                            return None; // zeros of different signs: the representative decides the bits
                        }
                        out.push((v, s));
                        break;
                    }
                    i = (i + 1) & mask;
                }
            }
            Some(out)
        })
        .collect();
    let mut class: Vec<u32> = (0..n_vertices as u32).collect();
    for (v, rep) in resolved?.into_iter().flatten() {
        let (v, rep) = (v as usize, rep as usize);
        first[rep] = first[rep].min(first[v]);
        last[rep] = last[rep].max(last[v]);
        class[v] = rep as u32;
    }
    drop((hashes, shards));
    let class_of = |id: usize| class[idx[id] as usize] as usize;
    let id_of = |k: usize| 3 * order[k / 3] as usize + k % 3;
    // Fewer than 3 edges can have the largest i0 (see the module comment).
    let bound = |k: usize| {
        let next = k - k % 3 + (k + 1) % 3;
        let (a, b) = (class_of(id_of(k)), class_of(id_of(next)));
        (first[a].min(first[b]), last[a].min(last[b]))
    };
    let lower = (0..3 * n_good).into_par_iter().with_min_len(1 << 14).map(|k| bound(k).0).max().unwrap_or(0);
    let candidates: Vec<usize> =
        (0..3 * n_good).into_par_iter().with_min_len(1 << 14).filter(|&k| bound(k).1 >= lower).collect();
    if candidates.len() > MAX_CANDIDATES {
        return None;
    }
    if candidates.len() >= 3 {
        // The exact representatives of the classes these edges join (a replay of their buckets
        // only) give their exact i0, hence how many share the largest.
        let ends: Vec<usize> = candidates.iter().flat_map(|&k| [k, k - k % 3 + (k + 1) % 3]).collect();
        let exact = super::weld::welded_of(c, order, &ends);
        let i0: Vec<u32> = exact.chunks(2).map(|e| e[0].min(e[1])).collect();
        let largest = i0.iter().copied().max().unwrap_or(0);
            if i0.iter().filter(|&&x| x == largest).count() >= 3 {
            return None;
        }
    }
    Some((0..idx.len()).into_par_iter().with_min_len(1 << 14).map(|k| first[class_of(id_of(k))]).collect())
}
