//! A fast MikkTSpace with the reference's exact output.
//!
//! Same result as `bevy_mikktspace` 1.0 with default features (a byte-identical port of the C
//! reference), bit for bit, including the reference's legacy vertex welding and edge sorting.
//! What changes is the cost: the reference's quadratic paths (weld leaves, edge runs,
//! per-vertex sub-groups, degenerate-triangle lookups) become hashing, counting sorts and
//! prefix sums over flat arrays, and the independent per-triangle, per-weld-bucket and
//! per-group work runs on rayon. Every parallel step writes disjoint outputs computed from
//! inputs that do not depend on scheduling, so the output is the same for every thread count.
//!
//! Stages (each a module):
//! 1. `triangles.rs`: degenerate test, first-order tangents, the reference's triangle order;
//! 2. `shortcut.rs` or `weld.rs`: welded vertex ids, by hashing vertices when the representatives
//!    provably do not matter, else by replaying the legacy weld's partitioning;
//! 3. `neighbors.rs`: triangle adjacency, including the legacy sort's unpaired tail;
//! 4. `groups.rs`: orientation-consistent fans around each welded vertex;
//! 5. `accumulate.rs`: sub-groups by the angular threshold and angle-weighted sums;
//! 6. here: degenerate triangles borrow from the first good corner of the same welded vertex,
//!    and the output is [`Frames`]: each summed value once, found through the vertex.
//!
//! At its peak the engine holds, beside its input, the adjacency and its edge list (a `u32` per
//! corner each): nothing else per triangle or per corner is kept that a later stage can recompute
//! or read through the index buffer.

#![forbid(unsafe_code)]

mod accumulate;
mod groups;
mod math;
mod neighbors;
mod shortcut;
mod triangles;
mod weld;

use super::frames::{Builder, Frames};
use super::TriMesh;
use math::V3;
use rayon::prelude::*;
use triangles::Order;

/// Read access to the mesh by input corner id (`3 * face + corner`). Every index has been
/// checked against the attribute arrays before one is built.
pub(crate) struct Corners<'a> {
    mesh: &'a TriMesh<'a>,
}

impl Corners<'_> {
    #[inline]
    pub(crate) fn pos(&self, corner: usize) -> V3 {
        self.mesh.positions[self.mesh.indices[corner] as usize]
    }
    #[inline]
    pub(crate) fn nrm(&self, corner: usize) -> V3 {
        self.mesh.normals[self.mesh.indices[corner] as usize]
    }
    #[inline]
    pub(crate) fn uv(&self, corner: usize) -> [f32; 2] {
        self.mesh.uvs[self.mesh.indices[corner] as usize]
    }
    #[inline]
    pub(crate) fn n_faces(&self) -> usize {
        self.mesh.indices.len() / 3
    }
}

/// Why [`generate`] could not run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unsupported {
    /// An index is out of range for one of the attribute arrays.
    IndexOutOfRange,
    /// More corners than fit the 32-bit internal ids (over 1.4 billion triangles).
    TooLarge,
}

/// Per-corner frames `(t.x, t.y, t.z, sign)`, identical to the reference's, one value per group
/// of corners the reference summed together; no frame where the reference gives no answer. One
/// slot per index (a trailing partial triangle gets none, as with the reference wrapper).
pub fn generate(mesh: &TriMesh) -> Result<Frames, Unsupported> {
    generate_timed(mesh, &mut crate::timings::Timings::default())
}

/// [`generate`], recording the wall time of each stage in `timings`.
pub fn generate_timed(mesh: &TriMesh, timings: &mut crate::timings::Timings) -> Result<Frames, Unsupported> {
    let n_faces = mesh.indices.len() / 3;
    if n_faces.checked_mul(3).is_none_or(|n| n >= (u32::MAX as usize) - 4) {
        return Err(Unsupported::TooLarge);
    }
    let limit = mesh.positions.len().min(mesh.normals.len()).min(mesh.uvs.len());
    if crate::scan::any(&mesh.indices[..3 * n_faces], |&i| i as usize >= limit) {
        return Err(Unsupported::IndexOutOfRange);
    }
    let c = Corners { mesh };
    if n_faces == 0 {
        return Ok(Frames::none(mesh.indices));
    }
    let mut tri = timings.time("triangles", || triangles::Triangles::build(&c));
    let ng = tri.n_good;
    // The shortcut's ids are the same for every corner of an input vertex: they are kept per
    // vertex (a sixth of the memory on a typical mesh) and read through the index buffer.
    let by_vertex = timings.time("weld", || shortcut::weld(&c, &tri.order, ng));
    let (orient, gwa) = (std::mem::take(&mut tri.orient), std::mem::take(&mut tri.gwa));
    Ok(match by_vertex {
        Some(of_vertex) => finish(
            &c,
            mesh.indices,
            ByVertex { of_vertex, idx: mesh.indices, order: &tri.order },
            true,
            gwa,
            orient,
            &tri.order,
            ng,
            timings,
        ),
        None => {
            let w = timings.time("weld", || weld::weld(&c, &tri.order));
            finish(&c, mesh.indices, w, false, gwa, orient, &tri.order, ng, timings)
        }
    })
}

/// Welded ids by internal corner (`3 t + j`, `t` in [`triangles::Triangles::order`]), for every
/// corner of the mesh: degenerate triangles' corners come after the good ones.
pub(crate) trait Welded: Sync {
    fn at(&self, k: usize) -> u32;
    /// An input corner whose attributes have the same bits as the welded vertex of `k`'s.
    #[inline]
    fn attr_corner(&self, k: usize) -> usize {
        self.at(k) as usize
    }
}

impl Welded for Vec<u32> {
    #[inline]
    fn at(&self, k: usize) -> u32 {
        self[k]
    }
}

/// Welded ids kept per input vertex.
struct ByVertex<'a> {
    of_vertex: Vec<u32>,
    idx: &'a [u32],
    order: &'a Order,
}

impl ByVertex<'_> {
    #[inline]
    fn corner(&self, k: usize) -> usize {
        3 * self.order.at(k / 3) as usize + k % 3
    }
}

impl Welded for ByVertex<'_> {
    #[inline]
    fn at(&self, k: usize) -> u32 {
        self.of_vertex[self.idx[self.corner(k)] as usize]
    }
    /// The corner itself: the shortcut is only taken when every member of a class has the same
    /// bits.
    #[inline]
    fn attr_corner(&self, k: usize) -> usize {
        self.corner(k)
    }
}

/// The stages after the weld: adjacency, groups, sums, output.
#[allow(clippy::too_many_arguments)]
fn finish<W: Welded>(
    c: &Corners,
    idx: &[u32],
    w: W,
    short_tail: bool,
    gwa: Vec<bool>,
    mut orient: Vec<bool>,
    order: &Order,
    ng: usize,
    timings: &mut crate::timings::Timings,
) -> Frames {
    let n_faces = order.len();
    let nb = timings.time("neighbors", || neighbors::build(&w, 3 * ng, 3 * n_faces, short_tail));
    crate::timings::mem_mark("engine neighbors");
    let mut grp = timings.time("groups", || groups::build(&w, &nb, &gwa, &mut orient));
    crate::timings::mem_mark("engine groups");
    drop((nb, orient));
    // Sums are made a slice of groups at a time and kept compactly: one value for a group whose
    // members all got the same bits (the usual case), else one per member.
    let t_acc = std::time::Instant::now();
    let n_groups = grp.orient.len();
    let mut first_slot: Vec<u32> = Vec::with_capacity(n_groups + 1);
    let mut values: Vec<[f32; 4]> = Vec::with_capacity(n_groups);
    let mut g0 = 0;
    while g0 < n_groups {
        let limit = grp.start[g0] as usize + PASS;
        let g1 = (g0 + 1).max(grp.start.partition_point(|&x| (x as usize) <= limit) - 1).min(n_groups);
        let vals = accumulate_all(c, &w, order, &gwa, &mut grp, g0..g1);
        let base = grp.start[g0] as usize;
        for g in g0..g1 {
            let v = &vals[grp.start[g] as usize - base..grp.start[g + 1] as usize - base];
            let sign = if grp.orient[g] { 1.0 } else { -1.0 };
            first_slot.push(values.len() as u32);
            if v.iter().all(|x| x.map(f32::to_bits) == v[0].map(f32::to_bits)) {
                values.push([v[0][0], v[0][1], v[0][2], sign]);
            } else {
                values.extend(v.iter().map(|x| [x[0], x[1], x[2], sign]));
            }
        }
        g0 = g1;
    }
    first_slot.push(values.len() as u32);
    timings.stages.push(("accumulate".into(), t_acc.elapsed().as_secs_f64() * 1e3));
    crate::timings::mem_mark("engine accumulate");
    let t_out = std::time::Instant::now();
    // Only what the scatter below needs stays: the welded ids only for degenerate triangles.
    drop(gwa);
    grp.orient = Vec::new();
    let w = (ng < n_faces).then_some(w);
    let mut out = Builder::new(idx);
    for g in 0..n_groups {
        let range = grp.start[g] as usize..grp.start[g + 1] as usize;
        let uniform = first_slot[g + 1] - first_slot[g] == 1;
        for (i, &k) in grp.members[range].iter().enumerate() {
            let corner = 3 * order.at((k / 3) as usize) as usize + (k % 3) as usize;
            out.put(corner, first_slot[g] + if uniform { 0 } else { i as u32 });
        }
    }
    drop(grp);
    if let Some(w) = w {
        degenerate(&w, order, ng, &mut out);
    }
    let frames = out.finish(values);
    timings.stages.push(("output".into(), t_out.elapsed().as_secs_f64() * 1e3));
    frames
}

/// Members per pass of the sums (see [`generate_timed`]).
const PASS: usize = 1 << 18;

/// Runs [`accumulate::group_tangents`] on the groups in `groups`, in parallel batches of whole
/// groups; returns their members' sums. Sorts each group's members (the reference sums in
/// triangle order).
fn accumulate_all<W: Welded>(
    c: &Corners,
    w: &W,
    order: &Order,
    gwa: &[bool],
    grp: &mut groups::Groups,
    groups: std::ops::Range<usize>,
) -> Vec<V3> {
    const BATCH: usize = 8192;
    let n_groups = groups.end;
    let (lo, hi) = (grp.start[groups.start] as usize, grp.start[groups.end] as usize);
    let mut vals = vec![[0.0f32; 3]; hi - lo];
    // Each triangle's first-order vectors are needed by the groups of its three corners, which
    // on a mesh with any locality fall in the same pass: computed once per pass for the span of
    // triangles the pass reaches, unless that span is much wider than the pass.
    let members = &grp.members[lo..hi];
    let t_lo = members.par_iter().map(|&k| k / 3).min().unwrap_or(0) as usize;
    let t_hi = members.par_iter().map(|&k| k / 3 + 1).max().unwrap_or(0) as usize;
    let cache: Vec<(V3, V3)> = if t_hi - t_lo <= 2 * members.len() {
        (t_lo..t_hi)
            .into_par_iter()
            .with_min_len(1 << 12)
            .map(|t| triangles::first_order(c, order.at(t) as usize))
            .collect()
    } else {
        Vec::new()
    };
    let st = |t: usize| match cache.get(t.wrapping_sub(t_lo)) {
        Some(&v) => v,
        None => triangles::first_order(c, order.at(t) as usize),
    };
    let mut batches = Vec::new();
    let mut rest_m = &mut grp.members[lo..hi];
    let mut rest_v = vals.as_mut_slice();
    let mut g0 = groups.start;
    while g0 < n_groups {
        let mut g1 = g0 + 1;
        while g1 < n_groups && ((grp.start[g1] - grp.start[g0]) as usize) < BATCH {
            g1 += 1;
        }
        let len = (grp.start[g1] - grp.start[g0]) as usize;
        let (hm, tm) = rest_m.split_at_mut(len);
        let (hv, tv) = rest_v.split_at_mut(len);
        batches.push((g0, g1, hm, hv));
        rest_m = tm;
        rest_v = tv;
        g0 = g1;
    }
    let start = &grp.start;
    batches.into_par_iter().for_each(|(g0, g1, ms, vs)| {
        let base = start[g0] as usize;
        let mut scratch = Vec::new();
        for g in g0..g1 {
            let r = start[g] as usize - base..start[g + 1] as usize - base;
            let m = &mut ms[r.clone()];
            m.sort_unstable();
            accumulate::group_tangents(c, w, &st, gwa, w.at(m[0] as usize), m, &mut vs[r], &mut scratch);
        }
    });
    vals
}

/// Corners of degenerate triangles copy the output of the first good corner (in the
/// reference's good-triangle order) with the same welded id, if any.
fn degenerate<W: Welded>(w: &W, order: &Order, ng: usize, out: &mut Builder) {
    let corner = |k: usize| 3 * order.at(k / 3) as usize + k % 3;
    let mut first_good = vec![u32::MAX; 3 * order.len()];
    for k in 0..3 * ng {
        let slot = &mut first_good[w.at(k) as usize];
        if *slot == u32::MAX {
            *slot = k as u32;
        }
    }
    for k in 3 * ng..3 * order.len() {
        let src = first_good[w.at(k) as usize];
        if let Some(slot) = (src != u32::MAX).then(|| out.slot(corner(src as usize))).flatten() {
            out.put(corner(k), slot);
        }
    }
}

// Every test here compares with the reference engine.
#[cfg(all(test, feature = "reference"))]
mod tests;
