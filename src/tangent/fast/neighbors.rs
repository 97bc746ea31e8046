//! Triangle adjacency with the reference's pairing, including its edge-sorting quirk.
//!
//! The reference sorts all edges `(i0 = min, i1 = max, triangle)` and, walking the sorted list,
//! pairs each edge with the first later edge of the same key that runs the opposite way and is
//! still free. Different keys never interact, so edges are grouped by key here with a counting
//! sort on `i0` and a small sort on `(i1, triangle)` per `i0`, and each group is paired with
//! the same greedy rule in linear time.
//!
//! The quirk (MikkTSpace issue 5): the reference's quicksort leaves the edges with the largest
//! `i0` in the order its first (unstable, `i0`-only) pass left them, only partly repaired. Edges
//! of one key that end up apart are not paired. That tail is reproduced exactly by replaying the
//! same seeded quicksort on the `i0` keys, but only on the sub-ranges that contain the largest
//! key (a quickselect: linear expected time), and only when the tail has 3 or more edges (with
//! fewer, every order pairs the same way).

use super::Welded;
use rayon::prelude::*;

pub(crate) const NONE: u32 = u32::MAX;

#[inline]
fn edge_ends<W: Welded + ?Sized>(w: &W, e: usize) -> (u32, u32) {
    let t = e / 3;
    let n = e % 3;
    (w.at(e), w.at(3 * t + (n + 1) % 3))
}

/// `nb[3 t + n]`: the internal index of the triangle across edge `n` (corners `n`, `n + 1`) of
/// good triangle `t`, or [`NONE`]. `w` gives the welded ids of the `n_edges` good triangles'
/// corners; `id_space` bounds them. `short_tail`: fewer than 3 edges are known to share the largest `i0`
/// (see [`super::shortcut`]), so no replay is needed whatever the ids.
pub(crate) fn build<W: Welded + ?Sized>(w: &W, n_edges: usize, id_space: usize, short_tail: bool) -> Vec<u32> {
    let mut nb = vec![NONE; n_edges];
    if n_edges == 0 {
        return nb;
    }
    let max_i0 = if short_tail { 0 } else { (0..n_edges).into_par_iter().with_min_len(1 << 14).map(|e| i0_of(w, e)).max().unwrap_or(0) };
    let tail_len = if short_tail { 0 } else { (0..n_edges).into_par_iter().with_min_len(1 << 14).filter(|&e| i0_of(w, e) == max_i0).count() };
    // Pair every i0 bucket except the quirky last one (when it needs the replay).
    let replay = tail_len >= 3;
    // Edges go to ranges of i0 (chunk by chunk, keeping triangle order), then each range is
    // counting-sorted by i0 and paired on its own: ranges never share a key.
    const RANGES: usize = 256;
    const CHUNK: usize = 1 << 16;
    let shift = {
        let mut s = 0u32;
        while (id_space >> s) >= RANGES {
            s += 1;
        }
        s
    };
    let per_chunk: Vec<Vec<Vec<u32>>> = (0..n_edges.div_ceil(CHUNK))
        .into_par_iter()
        .map(|ch| {
            let mut v: Vec<Vec<u32>> = vec![Vec::new(); RANGES];
            for e in ch * CHUNK..n_edges.min((ch + 1) * CHUNK) {
                let k = i0_of(w, e);
                if !(replay && k == max_i0) {
                    v[(k >> shift) as usize].push(e as u32);
                }
            }
            v
        })
        .collect();
    // Regroup the chunks' lists by range (moves, no copies), then pair the ranges a wave at a
    // time: each wave's lists are freed as it is paired and its pairs linked before the next,
    // so neither all edges twice nor all pairs are ever held at once.
    let mut by_range: Vec<Vec<Vec<u32>>> = (0..RANGES).map(|_| Vec::with_capacity(per_chunk.len())).collect();
    for chunk in per_chunk {
        for (r, list) in chunk.into_iter().enumerate() {
            by_range[r].push(list);
        }
    }
    let mut link = |a: u32, b: u32| {
        nb[a as usize] = b / 3;
        nb[b as usize] = a / 3;
    };
    const WAVE: usize = 16;
    for w0 in (0..RANGES).step_by(WAVE) {
        let wave: Vec<Vec<Vec<u32>>> = by_range[w0..w0 + WAVE].iter_mut().map(std::mem::take).collect();
        let pairs: Vec<Vec<(u32, u32)>> = wave
            .into_par_iter()
            .enumerate()
            .map(|(i, lists)| {
                let edges: Vec<u32> = lists.into_iter().flatten().collect();
                pair_range(w, &edges, ((w0 + i) as u32) << shift, 1usize << shift)
            })
            .collect();
        for (a, b) in pairs.into_iter().flatten() {
            link(a, b);
        }
    }
    if replay {
        let tail = legacy_tail(w, n_edges, max_i0);
        // Runs of equal i1, each sorted by triangle, except the last run (the off-by-one).
        let runs: Vec<&[u32]> =
            tail.chunk_by(|&a, &b| edge_ends_max(w, a as usize) == edge_ends_max(w, b as usize)).collect();
        for (r, run) in runs.iter().enumerate() {
            let mut run = run.to_vec();
            if r + 1 != runs.len() {
                run.sort_unstable_by_key(|&e| e / 3);
            }
            pair_run(w, &run, &mut link);
        }
    }
    nb
}

#[inline]
fn i0_of<W: Welded + ?Sized>(w: &W, e: usize) -> u32 {
    let (a, b) = edge_ends(w, e);
    a.min(b)
}

/// Pairs the edges of one range of `i0` keys (`base..base + span`), given in triangle order.
fn pair_range<W: Welded + ?Sized>(w: &W, edges: &[u32], base: u32, span: usize) -> Vec<(u32, u32)> {
    let mut out = Vec::with_capacity(edges.len() / 2);
    if edges.len() < 2 {
        return out;
    }
    // Counting sort by i0 within the range (stable).
    let mut start = vec![0u32; span + 1];
    for &e in edges {
        start[(i0_of(w, e as usize) - base) as usize + 1] += 1;
    }
    for i in 0..span {
        start[i + 1] += start[i];
    }
    let mut sorted = vec![0u32; edges.len()];
    for &e in edges {
        let c = &mut start[(i0_of(w, e as usize) - base) as usize];
        sorted[*c as usize] = e;
        *c += 1;
    }
    let mut scratch: Vec<(u32, u32)> = Vec::new();
    for bucket in sorted.chunk_by(|&a, &b| i0_of(w, a as usize) == i0_of(w, b as usize)) {
        pair_bucket(w, bucket, &mut scratch, &mut |a, b| out.push((a, b)));
    }
    out
}

/// Pairs the edges of one `i0` bucket (given in triangle order): runs of equal `i1`.
fn pair_bucket<W: Welded + ?Sized>(w: &W, bucket: &[u32], scratch: &mut Vec<(u32, u32)>, link: &mut impl FnMut(u32, u32)) {
    match bucket.len() {
        0 | 1 => {}
        2 => {
            if edge_ends_max(w, bucket[0] as usize) == edge_ends_max(w, bucket[1] as usize) {
                pair_run(w, bucket, link);
            }
        }
        _ => {
            scratch.clear();
            scratch.extend(bucket.iter().map(|&e| (edge_ends_max(w, e as usize), e)));
            // (i1, edge) order is (i1, triangle) order: one edge per triangle and key.
            scratch.sort_unstable();
            let mut run: Vec<u32> = Vec::new();
            for r in scratch.chunk_by(|a, b| a.0 == b.0) {
                if r.len() >= 2 {
                    run.clear();
                    run.extend(r.iter().map(|x| x.1));
                    pair_run(w, &run, link);
                }
            }
        }
    }
}

#[inline]
fn edge_ends_max<W: Welded + ?Sized>(w: &W, e: usize) -> u32 {
    let (a, b) = edge_ends(w, e);
    a.max(b)
}

/// Greedy pairing of one run of same-key edges in the given order: each free edge takes the
/// first later free edge running the opposite way. A pointer per direction makes it linear
/// (the taken edges after any position form a prefix of that direction's later edges).
fn pair_run<W: Welded + ?Sized>(w: &W, run: &[u32], link: &mut impl FnMut(u32, u32)) {
    let dir = |e: u32| {
        let (a, b) = edge_ends(w, e as usize);
        (a > b) as usize
    };
    match run.len() {
        0 | 1 => {}
        2 => {
            if dir(run[0]) != dir(run[1]) {
                link(run[0], run[1]);
            }
        }
        _ => {
            let mut lists: [Vec<usize>; 2] = [Vec::new(), Vec::new()];
            for (i, &e) in run.iter().enumerate() {
                lists[dir(e)].push(i);
            }
            let mut taken = vec![false; run.len()];
            let mut ptr = [0usize; 2];
            for i in 0..run.len() {
                if taken[i] {
                    continue;
                }
                let d = 1 - dir(run[i]);
                let l = &lists[d];
                while ptr[d] < l.len() && (l[ptr[d]] <= i || taken[l[ptr[d]]]) {
                    ptr[d] += 1;
                }
                if let Some(&j) = l.get(ptr[d]) {
                    taken[i] = true;
                    taken[j] = true;
                    link(run[i], run[j]);
                }
            }
        }
    }
}

const SORT_SEED: u32 = 39871946;

/// The edges with the largest `i0`, in the order the reference's seeded quicksort on `i0`
/// leaves them. Sub-ranges without a largest key are never sorted (they cannot move it).
fn legacy_tail<W: Welded + ?Sized>(w: &W, n_edges: usize, max_i0: u32) -> Vec<u32> {
    let mut v: Vec<(u32, u32)> = (0..n_edges)
        .map(|e| {
            let (a, b) = edge_ends(w, e);
            (a.min(b), e as u32)
        })
        .collect();
    let mut stack = vec![(0usize, v.len(), SORT_SEED)];
    while let Some((lo, hi, seed)) = stack.pop() {
        let s = &mut v[lo..hi];
        if s.len() <= 2 {
            if s.len() == 2 && s[1].0 < s[0].0 {
                s.swap(0, 1);
            }
            continue;
        }
        let seed = {
            let t = seed & 31;
            let t = seed.wrapping_shl(t) | seed.wrapping_shr(32u32.wrapping_sub(t));
            seed.wrapping_add(t).wrapping_add(3)
        };
        let pivot_index = seed.wrapping_rem(s.len() as u32) as usize;
        let pivot = s[pivot_index].0;
        let (mut a, mut b) = (0usize, s.len() - 1);
        // The reference's scans always find an element (the pivot bounds them); `None` would
        // only end the loop, never panic.
        loop {
            match (a..s.len()).find(|&l| s[l].0 >= pivot) {
                Some(x) => a = x,
                None => break,
            }
            match (0..=b).rev().find(|&r| s[r].0 <= pivot) {
                Some(x) => b = x,
                None => break,
            }
            if a <= b {
                s.swap(a, b);
                a += 1;
                if b == 0 {
                    // saturating_sub(1) in the reference; a > b ends the loop below.
                    if a > b {
                        break;
                    }
                } else {
                    b -= 1;
                }
            }
            if a > b {
                break;
            }
        }
        let lesser = b + 1;
        // Only ranges that hold the largest key matter: `greater` holds keys >= pivot, and
        // `lesser` keys <= pivot, so `lesser` can hold the largest key only if the pivot is it.
        if a < s.len() {
            stack.push((lo + a, hi, seed));
        }
        if pivot == max_i0 && lesser > 0 {
            stack.push((lo, lo + lesser, seed));
        }
    }
    v.into_iter().filter(|x| x.0 == max_i0).map(|x| x.1).collect()
}
