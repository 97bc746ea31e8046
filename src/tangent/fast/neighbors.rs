//! Triangle adjacency with the reference's pairing, including its edge-sorting quirk.
//!
//! The reference sorts all edges `(i0 = min, i1 = max, triangle)` and, walking the sorted list,
//! pairs each edge with the first later edge of the same key that runs the opposite way and is
//! still free. Different keys never interact, so edges are grouped by key here with a counting
//! sort on `i0` and a small sort on `(i1, triangle)` per `i0`, and each group is paired with
//! the same greedy rule in linear time.
//!
//! The quirk (reported upstream as issue 5 of the C MikkTSpace repository, mmikk/MikkTSpace): the reference's quicksort leaves the edges with the largest
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
    let max_i0 = if short_tail {
        0
    } else {
        (0..n_edges).into_par_iter().with_min_len(1 << 14).map(|e| i0_of(w, e)).max().unwrap_or(0)
    };
    let tail_len = if short_tail {
        0
    } else {
        (0..n_edges).into_par_iter().with_min_len(1 << 14).filter(|&e| i0_of(w, e) == max_i0).count()
    };
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
    // One flat array, range after range, each range's edges in triangle order: counted per
    // chunk, then written by the chunks in parallel into their own slices. One allocation, freed
    // whole when the pairing is done.
    let n_chunks = n_edges.div_ceil(CHUNK);
    let chunk = |ch: usize| ch * CHUNK..n_edges.min((ch + 1) * CHUNK);
    let range_of = |e: usize| {
        let k = i0_of(w, e);
        (!(replay && k == max_i0)).then_some((k >> shift) as usize)
    };
    let counts: Vec<Vec<usize>> = (0..n_chunks)
        .into_par_iter()
        .map(|ch| {
            let mut n = vec![0usize; RANGES];
            chunk(ch).filter_map(range_of).for_each(|r| n[r] += 1);
            n
        })
        .collect();
    let total: usize = counts.iter().flatten().sum();
    let mut flat = vec![0u32; total];
    let mut range_start = vec![0usize; RANGES + 1];
    {
        let mut slices: Vec<Vec<&mut [u32]>> = (0..n_chunks).map(|_| Vec::with_capacity(RANGES)).collect();
        let mut rest = flat.as_mut_slice();
        for r in 0..RANGES {
            for ch in 0..n_chunks {
                let (head, tail) = std::mem::take(&mut rest).split_at_mut(counts[ch][r]);
                slices[ch].push(head);
                rest = tail;
            }
            range_start[r + 1] = range_start[r] + counts.iter().map(|c| c[r]).sum::<usize>();
        }
        slices.into_par_iter().enumerate().for_each(|(ch, mut out)| {
            let mut at = vec![0usize; RANGES];
            for e in chunk(ch) {
                if let Some(r) = range_of(e) {
                    out[r][at[r]] = e as u32;
                    at[r] += 1;
                }
            }
        });
    }
    // Ranges are paired a wave at a time and each wave's pairs linked before the next, so all
    // pairs are never held at once.
    let mut link = |a: u32, b: u32| {
        nb[a as usize] = b / 3;
        nb[b as usize] = a / 3;
    };
    const WAVE: usize = 16;
    for w0 in (0..RANGES).step_by(WAVE) {
        let pairs: Vec<Vec<(u32, u32)>> = (w0..w0 + WAVE)
            .into_par_iter()
            .map(|r| pair_range(w, &flat[range_start[r]..range_start[r + 1]], (r as u32) << shift, 1usize << shift))
            .collect();
        for (a, b) in pairs.into_iter().flatten() {
            link(a, b);
        }
    }
    drop(flat);
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
    // Counting sort by i0 within the range (stable), each key read once.
    let keys: Vec<u32> = edges.iter().map(|&e| i0_of(w, e as usize) - base).collect();
    let mut start = vec![0u32; span + 1];
    for &k in &keys {
        start[k as usize + 1] += 1;
    }
    for i in 0..span {
        start[i + 1] += start[i];
    }
    let mut sorted = vec![(0u32, 0u32); edges.len()];
    for (&e, &k) in edges.iter().zip(&keys) {
        let c = &mut start[k as usize];
        sorted[*c as usize] = (k, e);
        *c += 1;
    }
    drop(keys);
    let mut scratch: Vec<(u32, u32)> = Vec::new();
    let mut bucket: Vec<u32> = Vec::new();
    for run in sorted.chunk_by(|a, b| a.0 == b.0) {
        bucket.clear();
        bucket.extend(run.iter().map(|x| x.1));
        pair_bucket(w, &bucket, &mut scratch, &mut |a, b| out.push((a, b)));
    }
    out
}

/// Pairs the edges of one `i0` bucket (given in triangle order): runs of equal `i1`.
fn pair_bucket<W: Welded + ?Sized>(
    w: &W,
    bucket: &[u32],
    scratch: &mut Vec<(u32, u32)>,
    link: &mut impl FnMut(u32, u32),
) {
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
        while let Some(x) = (a..s.len()).find(|&l| s[l].0 >= pivot) {
            a = x;
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
