//! The upper levels of a large tree, split at Morton-code boundaries: one sort, then no pass
//! over every item per level. Binned SAH builds only ranges of [`SAH_RANGE`] or fewer, whose
//! items fit in a core's cache. An item is a triangle or a pair of neighbours (`pairs.rs`).

use super::bounds::{bounds_of, Aabb, Item};
use super::collapse::{Slots, Upper};
use super::local::LOCAL;
use super::node::{Node, Nodes};
use super::pairs::{self, Pairs};
use super::range;
use super::sah;
use super::Tri;
use glam::Vec3A;
use std::mem::MaybeUninit;

/// From this many triangles on, the upper levels are split here rather than by SAH.
pub(super) const MORTON_MIN: usize = 64 * 1024;
const SAH_RANGE: usize = 256;
/// Splits of fewer items build both sides on the current thread: tasks of a few dozen ranges
/// each, not one a range.
const SERIAL_BELOW: usize = 8 * 1024;
/// A Morton key holds the code above a triangle's index, so keys are unique and sort alike on
/// any thread count: 12 bits an axis over 28 bits of index (HIGHs up to 268M triangles).
const INDEX_BITS: u32 = 28;
const INDEX_MASK: u64 = (1 << INDEX_BITS) - 1;
const AXIS_BITS: u32 = 12;
/// The code's bits below the bucket pass's 8, sorted within each bucket in passes of 7.
const LOW_BITS: u32 = 3 * AXIS_BITS - 8;
const DIGIT_BITS: u32 = 7;
const BUCKETS: usize = 1 << (3 * AXIS_BITS - LOW_BITS);
/// The bucket pass's chunks: a fixed count, so that the work splits alike on any thread count.
const CHUNKS: usize = 16;

/// Whether a tree over `n` triangles gets Morton-split upper levels: enough of them that a
/// pass over all per level costs more than the sort, few enough that an index fits its key.
pub(super) fn applies(n: usize) -> bool {
    (MORTON_MIN..1 << INDEX_BITS).contains(&n)
}

/// Builds the tree over the `n` triangles whose corners `corners` gives (`warm` as in
/// [`Mesh`]), its items in the order of the Morton codes of their centres; returns its
/// four-wide nodes (root at 0) and how many there are (the rest are unused slots), the
/// triangles' ids in leaf order and `tri` of each id in that order. The items are never
/// gathered into that order: each range computes its own from the mesh, and writes its
/// triangles in leaf order, and its four-wide nodes, into their places.
pub(super) fn build<C, T, W>(n: usize, corners: &C, tri: &T, warm: &W) -> (Nodes, usize, Vec<u32>, Vec<Tri>)
where
    C: Fn(usize) -> [[f32; 3]; 3] + Sync,
    T: Fn(u32) -> Tri + Sync,
    W: Fn(usize, usize, bool) + Sync,
{
    let item = |i: usize| Item::of(&corners(i), i as u32);
    let found = pairs::find(n, corners);
    let pairs = found.pairs;
    let mut keys = morton_keys(&found.ids, |t| pairs.item(t, item).centre(), &found.centres);
    drop(found.ids);
    let starts = triangle_starts(&keys, &pairs);
    let (mut tris, mut ids): (Vec<Tri>, Vec<u32>) = (Vec::with_capacity(n), Vec::with_capacity(n));
    crate::pages::prefault(tris.spare_capacity_mut());
    crate::pages::prefault(ids.spare_capacity_mut());
    let out = Out { tris: &mut tris.spare_capacity_mut()[..n], ids: &mut ids.spare_capacity_mut()[..n] };
    // The nodes above the ranges first, then a slot a triangle for the ranges' nodes: each part
    // of the build writes its own once, where it ends, with no copy into one array after.
    let front = front_slots(keys.len());
    let mut nodes = Nodes::zeroed(front + n);
    let mut slots = Slots::new(&mut nodes[front..], front);
    let upper = build_upper(&Mesh { item: &item, tri, pairs: &pairs, warm }, &mut keys, &starts, out, &mut slots);
    let count = upper.collapse(&mut nodes, front);
    // SAFETY: the ranges split the keys without gaps, the slots in step with their triangles,
    // and each range writes every slot of its own (`range`), so all `n` are written.
    unsafe {
        tris.set_len(n);
        ids.set_len(n);
    }
    (nodes, count, ids, tris)
}

/// Room for the four-wide nodes above the ranges of `items` items: at most one a binary split.
/// A split has more than [`SAH_RANGE`] items, so the splits at one depth hold that many
/// apart, and each split is at a lower bit of the code than its parent's (its items share
/// the bits above), so there are at most as many depths as the code has bits.
fn front_slots(items: usize) -> usize {
    (3 * AXIS_BITS) as usize * (items / (SAH_RANGE + 1)) + 1
}

/// What the ranges read the mesh through: a triangle's item, its record in leaf order, which
/// triangles are paired, and `warm(t, n, deep)`, which asks the CPU for what the items of
/// triangles `t..t + n` read (their records, or with `deep` their corners, read from the
/// records a first call asked for).
struct Mesh<'a, I, T, W> {
    item: &'a I,
    tri: &'a T,
    pairs: &'a Pairs,
    warm: &'a W,
}

/// Where a range writes its triangles and their ids, in leaf order.
struct Out<'a> {
    tris: &'a mut [MaybeUninit<Tri>],
    ids: &'a mut [MaybeUninit<u32>],
}

impl<'a> Out<'a> {
    fn split_at(self, k: usize) -> (Out<'a>, Out<'a>) {
        let (ta, tb) = self.tris.split_at_mut(k);
        let (ia, ib) = self.ids.split_at_mut(k);
        (Out { tris: ta, ids: ia }, Out { tris: tb, ids: ib })
    }
}

/// Where each sorted key's triangles start in leaf order: the sizes of the items before it.
fn triangle_starts(keys: &[u64], pairs: &Pairs) -> Vec<u32> {
    use rayon::prelude::*;
    let mut starts: Vec<u32> = keys.par_iter().map(|&k| pairs.size((k & INDEX_MASK) as u32)).collect();
    let mut at = 0;
    for s in starts.iter_mut() {
        (*s, at) = (at, at + *s);
    }
    starts
}

/// Each item's key (Morton code of its box's centre over the centres' bounds `c`, then its id
/// from `ids`), sorted.
fn morton_keys(ids: &[u32], centre: impl Fn(u32) -> Vec3A + Sync, c: &Aabb) -> Vec<u64> {
    use rayon::prelude::*;
    let n = ids.len();
    let cells = (1u32 << AXIS_BITS) as f32;
    let extent = c.max - c.min;
    let scale = Vec3A::select(extent.cmpgt(Vec3A::ZERO), Vec3A::splat(cells) / extent, Vec3A::ZERO);
    let keys: Vec<u64> = ids
        .par_iter()
        .map(|&i| {
            let q = ((centre(i) - c.min) * scale).min(Vec3A::splat(cells - 1.0));
            let code = spread(q.x as u64) | spread(q.y as u64) << 1 | spread(q.z as u64) << 2;
            code << INDEX_BITS | u64::from(i)
        })
        .collect();
    // One pass on the code's top bits into buckets, then each bucket sorted on its own, on every
    // core. The pass keeps the keys' order, by index, so a stable sort of a bucket on the code's
    // lower bits gives the order of the whole keys (which are unique). The pass runs on every
    // core too: each chunk of the keys writes its share of every bucket into a slice of its own,
    // after the earlier chunks' shares, so the order is the same on any thread count. 256
    // buckets, not more: the pass writes to as many places at once, and with 4096 it slowed
    // faster than the keys grew (docs/transfer.md, "The tree build").
    let top = |k: u64| (k >> (INDEX_BITS + LOW_BITS)) as usize;
    let chunk = n.div_ceil(CHUNKS).max(1);
    let counts: Vec<[usize; BUCKETS]> = keys
        .par_chunks(chunk)
        .map(|ks| {
            let mut h = [0usize; BUCKETS];
            ks.iter().for_each(|&k| h[top(k)] += 1);
            h
        })
        .collect();
    let mut sorted = vec![0u64; n];
    crate::pages::prefault(&mut sorted);
    let mut shares: Vec<Vec<&mut [u64]>> = counts.iter().map(|_| Vec::with_capacity(BUCKETS)).collect();
    let mut sizes = [0usize; BUCKETS];
    let mut rest = sorted.as_mut_slice();
    for (d, size) in sizes.iter_mut().enumerate() {
        for (h, s) in counts.iter().zip(shares.iter_mut()) {
            let (share, r) = rest.split_at_mut(h[d]);
            s.push(share);
            rest = r;
            *size += h[d];
        }
    }
    keys.par_chunks(chunk).zip(shares).for_each(|(ks, mut s)| {
        let mut at = [0usize; BUCKETS];
        for &k in ks {
            let d = top(k);
            s[d][at[d]] = k;
            at[d] += 1;
        }
    });
    drop(keys);
    let mut buckets: Vec<&mut [u64]> = Vec::with_capacity(BUCKETS);
    let mut rest = sorted.as_mut_slice();
    for size in sizes {
        let (b, r) = rest.split_at_mut(size);
        buckets.push(b);
        rest = r;
    }
    buckets.into_par_iter().for_each(radix_low);
    sorted
}

/// Sorts `keys` (of one bucket) stably on the code's lower [`LOW_BITS`] bits, in passes of
/// [`DIGIT_BITS`]: linear in the keys, where a comparison sort took twice the time at 10M.
fn radix_low(keys: &mut [u64]) {
    const PASSES: usize = (LOW_BITS / DIGIT_BITS) as usize;
    const DIGITS: usize = 1 << DIGIT_BITS;
    if keys.len() < 64 {
        // A few keys: a comparison sort of the whole keys gives the same order for less than
        // the passes' counts.
        keys.sort_unstable();
        return;
    }
    let digit = |k: u64, p: usize| (k >> (INDEX_BITS as usize + DIGIT_BITS as usize * p)) as usize & (DIGITS - 1);
    let mut count = [[0usize; DIGITS]; PASSES];
    for &k in keys.iter() {
        (0..PASSES).for_each(|p| count[p][digit(k, p)] += 1);
    }
    let mut other = vec![0u64; keys.len()];
    for (p, c) in count.iter().enumerate() {
        let mut at = [0usize; DIGITS];
        (1..DIGITS).for_each(|d| at[d] = at[d - 1] + c[d - 1]);
        let (from, to): (&[u64], &mut [u64]) = if p % 2 == 0 { (keys, &mut other) } else { (&other, keys) };
        for &k in from {
            let d = digit(k, p);
            to[at[d]] = k;
            at[d] += 1;
        }
    }
    if PASSES % 2 == 1 {
        keys.copy_from_slice(&other);
    }
}

/// The low 12 bits of `x`, two zero bits after each.
fn spread(x: u64) -> u64 {
    let mut x = x & 0xfff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

fn upper_bounds(u: &Upper) -> Aabb {
    let n = u.node();
    Aabb { min: Vec3A::from(n.min), max: Vec3A::from(n.max) }
}

/// The upper levels over the items `keys` names (sorted, each a code above an item's id), whose
/// triangles start at `starts` in leaf order: each split where the codes' highest differing bit
/// flips; ranges of [`SAH_RANGE`] or fewer (or of one code) are built by binned SAH. Writes
/// each slot of `out` (as many as the items' triangles), in leaf order.
fn build_upper<I, T, W>(mesh: &Mesh<I, T, W>, keys: &mut [u64], starts: &[u32], out: Out, slots: &mut Slots) -> Upper
where
    I: Fn(usize) -> Item + Sync,
    T: Fn(u32) -> Tri + Sync,
    W: Fn(usize, usize, bool) + Sync,
{
    let code = |k: u64| k >> INDEX_BITS;
    let (first, last) = (code(keys[0]), code(keys[keys.len() - 1]));
    if keys.len() <= SAH_RANGE || first == last {
        return range(mesh, keys, starts[0] as usize, out, slots);
    }
    let bit = 63 - (first ^ last).leading_zeros();
    let mid = keys.partition_point(|&k| code(k) >> bit & 1 == 0);
    let (l, r) = keys.split_at_mut(mid);
    let (ls, rs) = starts.split_at(mid);
    let (lo, ro) = out.split_at((rs[0] - ls[0]) as usize);
    // Built on this thread, both sides' ranges put their nodes in the same slots one after the
    // other; on two, each side takes the slots of its triangles.
    let (left, right) = if l.len() + r.len() < SERIAL_BELOW {
        (build_upper(mesh, l, ls, lo, slots), build_upper(mesh, r, rs, ro, slots))
    } else {
        let (mut sl, mut sr) = slots.split_at((rs[0] - ls[0]) as usize);
        rayon::join(|| build_upper(mesh, l, ls, lo, &mut sl), || build_upper(mesh, r, rs, ro, &mut sr))
    };
    let mut b = upper_bounds(&left);
    b.join(&upper_bounds(&right));
    Upper::Split(Node::inner(&b, 0), Box::new(left), Box::new(right))
}

thread_local! {
    /// A range's binary tree, in a buffer each thread reuses: only its four-wide tree is kept.
    static BIN: std::cell::RefCell<Vec<Node>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// The tree over the range of items `keys` names, their triangles starting at `offset` in leaf
/// order; writes every slot of `out`, and its four-wide nodes into the next of `slots`.
fn range<I, T, W>(mesh: &Mesh<I, T, W>, keys: &mut [u64], offset: usize, out: Out, slots: &mut Slots) -> Upper
where
    I: Fn(usize) -> Item + Sync,
    T: Fn(u32) -> Tri + Sync,
    W: Fn(usize, usize, bool) + Sync,
{
    keys.iter_mut().for_each(|k| *k &= INDEX_MASK);
    let triangles = |k: &u64| (*k as u32..).take(mesh.pairs.size(*k as u32) as usize);
    if keys.len() <= LOCAL {
        // Neighbours in space, the range's items are scattered over HIGH's arrays: their
        // records, then their corners, are asked for all at once ahead of the build, which
        // would otherwise wait on each item's in turn (`docs/transfer-history.md`).
        for deep in [false, true] {
            keys.iter().for_each(|&k| (mesh.warm)(k as usize, mesh.pairs.size(k as u32) as usize, deep));
        }
        let item = |t: usize| (mesh.pairs.item(t as u32, mesh.item), mesh.pairs.size(t as u32) as u8);
        return BIN.with(|b| {
            let mut nodes = b.borrow_mut();
            nodes.clear();
            range::build_by_index(item, keys, offset, &mut nodes);
            write(mesh, out, keys.iter().flat_map(triangles));
            slots.range(&nodes)
        });
    }
    // Many items with one code (a pile of duplicates): their triangles gathered one by one, then
    // split by count.
    let mut gathered: Vec<Item> = keys.iter().flat_map(triangles).map(|t| (mesh.item)(t as usize)).collect();
    let bc = bounds_of(&gathered);
    let nodes = sah::build_par(&mut gathered, offset, bc);
    write(mesh, out, gathered.iter().map(|it| it.id));
    slots.range(&nodes)
}

/// Writes the triangles `ids` (as many as `out` has slots) and their ids into `out`: the range's
/// triangles were just read for their items, and are still in cache.
fn write<I, T: Fn(u32) -> Tri, W>(mesh: &Mesh<I, T, W>, out: Out, ids: impl Iterator<Item = u32>) {
    let mut n = 0;
    for ((slot, id), t) in out.tris.iter_mut().zip(out.ids.iter_mut()).zip(ids) {
        slot.write((mesh.tri)(t));
        id.write(t);
        n += 1;
    }
    assert_eq!(n, out.tris.len(), "a range writes every slot of its own");
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The radix pass gives the comparison sort's order on a bucket whose keys come in index
    /// order, as the bucket pass leaves them.
    #[test]
    fn radix_low_sorts_as_the_whole_key() {
        let mut rng = crate::test_rng::XorShift64(0x9e37_79b9_7f4a_7c15);
        for n in [1, 63, 64, 1000, 5000] {
            let mut keys: Vec<u64> = (0..n as u64)
                .map(|i| {
                    let x = rng.next();
                    // Few codes, so that many keys share one and their indices decide.
                    (((x % 97) << 5) | (x % 3)) << INDEX_BITS | i
                })
                .collect();
            let mut want = keys.clone();
            want.sort_unstable();
            radix_low(&mut keys);
            assert_eq!(keys, want, "{n} keys");
        }
    }

    /// The bucket pass and the radix passes give the keys in sorted order, whatever the
    /// thread count (items spread unevenly, many sharing a cell).
    #[test]
    fn keys_come_sorted() {
        use super::super::bounds::bounds_of;
        let mut x = crate::test_rng::XorShift32(0x2545_f491);
        let mut next = || (x.next() % 10_000) as f32 / 10_000.0;
        let items: Vec<Item> = (0..50_000u32)
            .map(|id| {
                let p = [next().powi(3), next(), (next() * 8.0).floor() / 8.0];
                Item { min: p, max: p.map(|v| v + 0.001), id }
            })
            .collect();
        let (_, c) = bounds_of(&items);
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
        let centre = |i: u32| items[i as usize].centre();
        let ids: Vec<u32> = (0..items.len() as u32).collect();
        let keys = one.install(|| morton_keys(&ids, centre, &c));
        assert!(keys.windows(2).all(|w| w[0] < w[1]));
        let mut seen: Vec<u64> = keys.iter().map(|k| k & INDEX_MASK).collect();
        seen.sort_unstable();
        assert!(seen.iter().enumerate().all(|(i, &k)| k == i as u64), "every item once");
        let three = rayon::ThreadPoolBuilder::new().num_threads(3).build().expect("pool");
        assert_eq!(three.install(|| morton_keys(&ids, centre, &c)), keys);
    }

    #[test]
    fn spread_leaves_two_zero_bits_after_each() {
        for x in [0u64, 1, 0b101, 0xfff, 0xabc] {
            let mut want = 0;
            (0..12).for_each(|b| want |= (x >> b & 1) << (3 * b));
            assert_eq!(spread(x), want, "{x:#x}");
        }
    }
}
