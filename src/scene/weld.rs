//! Turning per-corner attributes into indexed vertices: corners whose every attribute is equal,
//! byte for byte, become one vertex; all others stay apart. Vertices are numbered in the order
//! their first corner appears, so the result is deterministic.

use super::{Primitive, Stream};
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// FxHash (rustc's): the keys are attribute bytes we made ourselves, so a fast non-keyed hash is
/// safe, and SipHash would cost more than the rest of the weld.
#[derive(Default)]
pub(crate) struct Fx(u64);

impl Hasher for Fx {
    fn write(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            self.add(u64::from_le_bytes(c.try_into().expect("8 bytes")));
        }
        for &b in chunks.remainder() {
            self.add(b as u64);
        }
    }
    fn write_usize(&mut self, n: usize) {
        self.add(n as u64);
    }
    fn finish(&self) -> u64 {
        self.0
    }
}

impl Fx {
    fn add(&mut self, w: u64) {
        self.0 = (self.0.rotate_left(5) ^ w).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

/// Builds an indexed primitive from streams that hold one element per corner.
pub fn weld(attributes: Vec<(String, Stream)>, targets: Vec<Vec<(String, Stream)>>, mode: u32) -> Primitive {
    let all: Vec<&Stream> = attributes.iter().map(|(_, s)| s).chain(targets.iter().flatten().map(|(_, s)| s)).collect();
    let corners = all.first().map(|s| s.len()).unwrap_or(0);
    let stride: usize = all.iter().map(|s| s.format.elem_size()).sum();
    let mut keys = Vec::with_capacity(corners * stride);
    for c in 0..corners {
        for s in &all {
            keys.extend_from_slice(s.elem(c));
        }
    }
    let key = |c: usize| &keys[c * stride..(c + 1) * stride];
    // Equal corners found on every core (`first_equal`), each corner's hash computed there too.
    let hashes: Vec<u64> = {
        use rayon::prelude::*;
        (0..corners)
            .into_par_iter()
            .map(|c| {
                let mut h = Fx::default();
                h.write(key(c));
                h.0 | 1
            })
            .collect()
    };
    let first = first_equal(&hashes, |a, b| key(a) == key(b));
    // Vertices numbered in the order their first corner appears (a corner's first comes no
    // later than itself, so it is numbered already).
    let mut number = vec![0u32; corners];
    let mut order: Vec<u32> = Vec::new();
    let mut indices = Vec::with_capacity(corners);
    for (c, &f) in first.iter().enumerate() {
        if f as usize == c {
            number[c] = order.len() as u32;
            order.push(c as u32);
        }
        indices.push(number[f as usize]);
    }
    let gather = |list: Vec<(String, Stream)>| list.into_iter().map(|(n, s)| (n, s.gather(&order))).collect::<Vec<_>>();
    Primitive { attributes: gather(attributes), targets: targets.into_iter().map(gather).collect(), indices, mode }
}

/// For each item, the first item (lowest index) equal to it. `hashes[i]` is item `i`'s hash, or 0
/// for an item to leave alone (it maps to itself); `eq` decides equality of items with equal
/// hashes. Items are split into shards by hash (equal items share one), each resolved with its
/// own open-addressing table in parallel: the answer does not depend on the thread count.
pub(crate) fn first_equal(hashes: &[u64], eq: impl Fn(usize, usize) -> bool + Sync) -> Vec<u32> {
    use rayon::prelude::*;
    const SHARD_BITS: u32 = 4;
    let mut shards: Vec<Vec<u32>> = vec![Vec::new(); 1 << SHARD_BITS];
    for (i, &h) in hashes.iter().enumerate() {
        if h != 0 {
            shards[(h >> (64 - SHARD_BITS)) as usize].push(i as u32);
        }
    }
    let found: Vec<Vec<(u32, u32)>> = shards
        .par_iter()
        .map(|items| {
            let mask = (2 * items.len()).next_power_of_two().max(16) - 1;
            let mut slots: Vec<(u32, u32)> = vec![(u32::MAX, 0); mask + 1];
            let mut out = Vec::new();
            for &i in items {
                let h = hashes[i as usize];
                let tag = (h >> 32) as u32;
                let mut at = h as usize & mask;
                loop {
                    let (s, t) = slots[at];
                    if s == u32::MAX {
                        slots[at] = (i, tag);
                        break;
                    }
                    if t == tag && eq(s as usize, i as usize) {
                        out.push((i, s));
                        break;
                    }
                    at = (at + 1) & mask;
                }
            }
            out
        })
        .collect();
    let mut first: Vec<u32> = (0..hashes.len() as u32).collect();
    for (i, f) in found.into_iter().flatten() {
        first[i as usize] = f;
    }
    first
}

/// FxHash of 32-bit words, never 0 (0 marks an item [`first_equal`] leaves alone).
pub(crate) fn hash_words(words: impl IntoIterator<Item = u32>) -> u64 {
    let mut h = Fx::default();
    for w in words {
        h.add(w as u64);
    }
    h.0 | 1
}

/// A stream with one `f32` vector per corner, to be added to a primitive by [`split_corners`].
#[derive(Clone, Copy)]
pub struct CornerStream<'a> {
    /// Where the stream goes among the attributes (`usize::MAX` appends).
    pub at: usize,
    pub name: &'a str,
    /// `VEC2`, `VEC3` or `VEC4`.
    pub ty: &'a str,
    pub values: CornerValues<'a>,
}

/// Where a [`CornerStream`]'s values come from.
#[derive(Clone, Copy)]
pub enum CornerValues<'a> {
    /// The components, corner after corner.
    Flat(&'a [f32]),
    /// Corner -> value (components past the stream's width are ignored): for values kept
    /// compactly or cheap to recompute, never stored per corner.
    Fn(&'a (dyn Fn(usize) -> [f32; 4] + Sync)),
}

impl CornerStream<'_> {
    fn width(&self) -> usize {
        super::accessor::component_count(self.ty).unwrap_or(1)
    }
    #[inline]
    fn get(&self, c: usize) -> [f32; 4] {
        match self.values {
            CornerValues::Flat(v) => {
                let n = self.width();
                let mut out = [0.0; 4];
                out[..n].copy_from_slice(&v[c * n..(c + 1) * n]);
                out
            }
            CornerValues::Fn(f) => f(c),
        }
    }
}

/// Re-indexes an indexed primitive to which per-corner streams are being added (tangents, flat
/// normals). The result is exactly [`weld`] of the unwelded primitive plus those streams, without
/// unwelding, leaving out the attributes named in `leave_out`. See [`SplitPlan`], which does the
/// same without copying the primitive.
pub fn split_corners(base: &Primitive, leave_out: &[&str], extra: &[CornerStream]) -> Primitive {
    SplitPlan::new(base, leave_out, extra).apply(base.clone())
}

/// The new vertices and indices of [`split_corners`], with the added streams already made; then
/// [`SplitPlan::apply`] moves the primitive's own streams over one at a time. Two steps, so that
/// whatever the added streams are read from (per-corner frames) can be freed before the
/// primitive's streams are gathered.
pub struct SplitPlan {
    indices: Vec<u32>,
    /// Source vertex of each new vertex.
    origins: Vec<u32>,
    leave_out: Vec<String>,
    extra: Vec<(usize, String, Stream)>,
    /// Streams added to morph targets: (target, name, stream).
    target_extra: Vec<(usize, String, Stream)>,
}

impl SplitPlan {
    /// Byte-identical vertices are found once (by hashing vertices, not corners), and a corner
    /// then only compares its new values (bit for bit) with the vertices already made from its
    /// vertex's class.
    pub fn new(base: &Primitive, leave_out: &[&str], extra: &[CornerStream]) -> SplitPlan {
        SplitPlan::with_targets(base, leave_out, extra, &[])
    }

    /// [`SplitPlan::new`] that also adds per-corner streams to morph targets (`(target, stream)`;
    /// a target's stream is appended to it). `leave_out` applies to the targets' streams too, so
    /// that a target's old TANGENT gives way to the new one.
    pub fn with_targets(
        base: &Primitive,
        leave_out: &[&str],
        extra: &[CornerStream],
        target_extra: &[(usize, CornerStream)],
    ) -> SplitPlan {
        use rayon::prelude::*;
        let corners = base.indices.len();
        let kept: Vec<&(String, Stream)> =
            base.attributes.iter().filter(|(n, _)| !leave_out.contains(&n.as_str())).collect();
        let kept_targets = base.targets.iter().flatten().filter(|(n, _)| !leave_out.contains(&n.as_str()));
        let vertex_streams: Vec<&Stream> = kept.iter().map(|(_, s)| s).chain(kept_targets.map(|(_, s)| s)).collect();
        // Target streams are added values like any other: a vertex splits where they differ.
        let all_extra: Vec<CornerStream> = extra.iter().chain(target_extra.iter().map(|(_, s)| s)).copied().collect();
        let extra = all_extra.as_slice();
        let n_vertices = base.vertex_count().max(base.indices.iter().map(|&v| v as usize + 1).max().unwrap_or(0));
        let mut used = vec![false; n_vertices];
        for &v in &base.indices {
            used[v as usize] = true;
        }
        let hashes: Vec<u64> = (0..n_vertices)
            .into_par_iter()
            .with_min_len(1 << 14)
            .map(|v| {
                if !used[v] {
                    return 0;
                }
                let mut h = Fx::default();
                for s in &vertex_streams {
                    h.write(s.elem(v));
                }
                h.0 | 1
            })
            .collect();
        drop(used);
        // The class of each vertex: the first byte-identical vertex.
        let class = first_equal(&hashes, |a, b| vertex_streams.iter().all(|s| s.elem(a) == s.elem(b)));
        drop(hashes);
        // Each corner's added values are read once; a vertex's are kept as it is made (they are
        // the added streams), and later corners compare against those bytes.
        let widths: Vec<usize> = extra.iter().map(|s| s.width()).collect();
        let mut data: Vec<Vec<u8>> = widths.iter().map(|w| Vec::with_capacity(n_vertices * w * 4)).collect();
        let mut cur = vec![[0.0f32; 4]; extra.len()];
        let same = |data: &[Vec<u8>], cur: &[[f32; 4]], m: u32| {
            data.iter().zip(cur).zip(&widths).all(|((d, v), &w)| {
                d[m as usize * w * 4..][..w * 4].chunks_exact(4).zip(&v[..w]).all(|(b, x)| b == x.to_le_bytes())
            })
        };
        let mut made_first = vec![u32::MAX; n_vertices];
        let mut made_more: HashMap<u32, Vec<u32>, BuildHasherDefault<Fx>> = HashMap::default();
        let mut origins: Vec<u32> = Vec::new();
        let mut indices = Vec::with_capacity(corners);
        for c in 0..corners {
            for (v, s) in cur.iter_mut().zip(extra) {
                *v = s.get(c);
            }
            let v = class[base.indices[c] as usize];
            let first = made_first[v as usize];
            let found = if first == u32::MAX {
                None
            } else if same(&data, &cur, first) {
                Some(first)
            } else {
                made_more.get(&v).and_then(|more| more.iter().copied().find(|&m| same(&data, &cur, m)))
            };
            let m = found.unwrap_or_else(|| {
                let m = origins.len() as u32;
                if first == u32::MAX {
                    made_first[v as usize] = m;
                } else {
                    made_more.entry(v).or_default().push(m);
                }
                origins.push(base.indices[c]);
                for ((d, v), &w) in data.iter_mut().zip(&cur).zip(&widths) {
                    for x in &v[..w] {
                        d.extend_from_slice(&x.to_le_bytes());
                    }
                }
                m
            });
            indices.push(m);
        }
        drop((made_first, made_more, class));
        let mut made: Vec<(usize, String, Stream)> = extra
            .iter()
            .zip(data)
            .map(|(s, data)| {
                (s.at, s.name.to_string(), Stream { format: super::accessor::Format::f32(s.ty), data, template: None })
            })
            .collect();
        let target_made = made.split_off(made.len() - target_extra.len());
        let target_extra = target_extra.iter().zip(target_made).map(|((t, _), (_, n, s))| (*t, n, s)).collect();
        SplitPlan {
            indices,
            origins,
            leave_out: leave_out.iter().map(|s| s.to_string()).collect(),
            extra: made,
            target_extra,
        }
    }

    /// Number of vertices the primitive will have.
    pub fn vertex_count(&self) -> usize {
        self.origins.len()
    }

    /// The re-indexed primitive. Each of `base`'s streams is freed as soon as it is gathered.
    pub fn apply(self, base: Primitive) -> Primitive {
        let Primitive { attributes, targets, indices, mode } = base;
        drop(indices);
        let origins = &self.origins;
        let gather =
            |list: Vec<(String, Stream)>| list.into_iter().map(|(n, s)| (n, s.gather(origins))).collect::<Vec<_>>();
        let mut attributes = gather(attributes.into_iter().filter(|(n, _)| !self.leave_out.contains(n)).collect());
        for (at, name, stream) in self.extra {
            if at < attributes.len() {
                attributes.insert(at, (name, stream));
            } else {
                attributes.push((name, stream));
            }
        }
        let mut targets: Vec<Vec<(String, Stream)>> = targets
            .into_iter()
            .map(|t| gather(t.into_iter().filter(|(n, _)| !self.leave_out.contains(n)).collect()))
            .collect();
        for (t, name, stream) in self.target_extra {
            if let Some(target) = targets.get_mut(t) {
                target.push((name, stream));
            }
        }
        Primitive { attributes, targets, indices: self.indices, mode }
    }
}

/// Named streams, as a primitive's attributes or one morph target's.
pub type Streams = Vec<(String, Stream)>;

/// Expands an indexed primitive to one element per corner (the inverse of [`weld`]).
pub fn unweld(p: &Primitive) -> (Streams, Vec<Streams>) {
    let per_corner =
        |list: &Vec<(String, Stream)>| list.iter().map(|(n, s)| (n.clone(), s.gather(&p.indices))).collect::<Vec<_>>();
    (per_corner(&p.attributes), p.targets.iter().map(per_corner).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_corners_merge_and_different_ones_split() {
        let pos = Stream::from_f32("VEC3", &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]);
        let uv = Stream::from_f32("VEC2", &[[0.0, 0.0], [1.0, 0.0], [0.0, 0.0], [0.5, 0.0]]);
        let p = weld(vec![("POSITION".into(), pos), ("TEXCOORD_0".into(), uv)], vec![], 4);
        assert_eq!(p.indices, vec![0, 1, 0, 2]);
        assert_eq!(p.vertex_count(), 3);
        assert_eq!(p.attr("TEXCOORD_0").unwrap().to_f32::<2>()[2], [0.5, 0.0]);
        let (attrs, _) = unweld(&p);
        assert_eq!(attrs[1].1.to_f32::<2>(), vec![[0.0, 0.0], [1.0, 0.0], [0.0, 0.0], [0.5, 0.0]]);
    }

    /// Many corners over few values: vertices numbered in the order their first corner appears,
    /// as a plain map over the corners in order numbers them.
    #[test]
    fn vertices_come_in_first_use_order() {
        let mut x = crate::test_rng::XorShift32(0x2545_f491);
        let pos: Vec<[f32; 3]> = (0..5000).map(|_| [(x.next() % 300) as f32, 1.0, 0.0]).collect();
        let p = weld(vec![("POSITION".into(), Stream::from_f32("VEC3", &pos))], vec![], 4);
        let mut seen = std::collections::HashMap::new();
        let want: Vec<u32> = pos
            .iter()
            .map(|v| {
                let n = seen.len() as u32;
                *seen.entry(v[0].to_bits()).or_insert(n)
            })
            .collect();
        assert_eq!(p.indices, want);
        assert_eq!(p.vertex_count(), seen.len());
    }

    #[test]
    fn split_corners_splits_by_the_new_streams_and_merges_equal_vertices() {
        // Vertices 1 and 2 are byte-identical; vertex 0's last corner gets another tangent.
        let uv = Stream::from_f32("VEC2", &[[0.0, 0.0], [1.0, 0.0], [1.0, 0.0]]);
        let p = Primitive {
            attributes: vec![("TEXCOORD_0".into(), uv)],
            targets: vec![],
            indices: vec![0, 1, 2, 0],
            mode: 4,
        };
        let t = [[1.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, 1.0], [-1.0, 0.0, 0.0, -1.0f32]];
        let out = split_corners(
            &p,
            &[],
            &[CornerStream {
                at: usize::MAX,
                name: "TANGENT",
                ty: "VEC4",
                values: CornerValues::Flat(t.as_flattened()),
            }],
        );
        assert_eq!(out.indices, vec![0, 1, 1, 2]);
        assert_eq!(out.attr("TANGENT").unwrap().to_f32::<4>()[2], [-1.0, 0.0, 0.0, -1.0]);
        assert_eq!(out.attributes.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>(), ["TEXCOORD_0", "TANGENT"]);
    }
}
