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
use super::triangles::Order;
use super::Corners;
use crate::scene::weld::{first_equal, hash_words};
use rayon::prelude::*;

/// Beyond this many edges that could share the largest `i0`, replaying their buckets is not
/// worth it: the full replay runs instead.
const MAX_CANDIDATES: usize = 256;

/// Welded ids as [`super::weld::weld`] gives them, up to the choice of representative within each
/// class, per input vertex (every corner of a vertex has its vertex's id), or `None` when that choice could change the output (or the input has NaN or huge
/// coordinates): the caller then replays the reference.
pub(crate) fn weld(c: &Corners, order: &Order, n_good: usize) -> Option<Vec<u32>> {
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
    // Each used vertex's class: the first vertex (by index) with equal canonical bits.
    let key = |v: usize| {
        let (p, n, u) = (c.mesh.positions[v], c.mesh.normals[v], c.mesh.uvs[v]);
        [p[0], p[1], p[2], n[0], n[1], n[2], u[0], u[1]]
    };
    const HUGE: f32 = f32::MAX / 4.0;
    let unusable = (0..n_vertices).into_par_iter().with_min_len(1 << 14).any(|v| {
        let all = key(v);
        first[v] != u32::MAX && (all.iter().any(|x| x.is_nan()) || all[..3].iter().any(|x| x.abs() >= HUGE))
    });
    if unusable {
        return None; // no shortcut for NaN or huge coordinates
    }
    let hashes: Vec<u64> = (0..n_vertices)
        .into_par_iter()
        .with_min_len(1 << 14)
        .map(|v| if first[v] == u32::MAX { 0 } else { hash_words(key(v).map(canon_bits)) })
        .collect();
    let class = first_equal(&hashes, |a, b| key(a).map(canon_bits) == key(b).map(canon_bits));
    drop(hashes);
    for v in 0..n_vertices {
        let r = class[v] as usize;
        if r != v {
            if key(r).map(f32::to_bits) != key(v).map(f32::to_bits) {
                return None; // zeros of different signs: the representative decides the bits
            }
            first[r] = first[r].min(first[v]);
            last[r] = last[r].max(last[v]);
        }
    }
    let class_of = |id: usize| class[idx[id] as usize] as usize;
    let id_of = |k: usize| 3 * order.at(k / 3) as usize + k % 3;
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
    Some((0..n_vertices).into_par_iter().with_min_len(1 << 14).map(|v| first[class[v] as usize]).collect())
}
