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
//! 1. [`triangles`]: degenerate test, first-order tangents, the reference's triangle order;
//! 2. [`shortcut`] or [`weld`]: welded vertex ids, by hashing vertices when the representatives
//!    provably do not matter, else by replaying the legacy weld's partitioning;
//! 3. [`neighbors`]: triangle adjacency, including the legacy sort's unpaired tail;
//! 4. [`groups`]: orientation-consistent fans around each welded vertex;
//! 5. [`accumulate`]: sub-groups by the angular threshold and angle-weighted sums;
//! 6. here: degenerate triangles borrow from the first good corner of the same welded vertex.

#![forbid(unsafe_code)]

mod accumulate;
mod groups;
mod math;
mod neighbors;
mod shortcut;
mod triangles;
mod weld;

use super::TriMesh;
use math::V3;
use rayon::prelude::*;

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

/// Per-corner frames `(t.x, t.y, t.z, sign)`, identical to the reference's; all zero (`w == 0`)
/// where the reference gives no answer. The vector has one entry per index (a trailing partial
/// triangle gets none, as with the reference wrapper).
pub fn generate(mesh: &TriMesh) -> Result<Vec<[f32; 4]>, Unsupported> {
    generate_timed(mesh, &mut crate::report::Timings::default())
}

/// [`generate`], recording the wall time of each stage in `timings`.
pub fn generate_timed(
    mesh: &TriMesh,
    timings: &mut crate::report::Timings,
) -> Result<Vec<[f32; 4]>, Unsupported> {
    let n_faces = mesh.indices.len() / 3;
    if n_faces.checked_mul(3).is_none_or(|n| n >= (u32::MAX as usize) - 4) {
        return Err(Unsupported::TooLarge);
    }
    let limit = mesh.positions.len().min(mesh.normals.len()).min(mesh.uvs.len());
    if mesh.indices[..3 * n_faces].par_iter().any(|&i| i as usize >= limit) {
        return Err(Unsupported::IndexOutOfRange);
    }
    let c = Corners { mesh };
    if n_faces == 0 {
        return Ok(vec![[0.0; 4]; mesh.indices.len()]);
    }
    let mut tri = timings.time("triangles", || triangles::Triangles::build(&c));
    let ng = tri.n_good;
    let (welded, short_tail) = timings.time("weld", || match shortcut::weld(&c, &tri.order, ng) {
        Some(w) => (w, true),
        None => (weld::weld(&c, &tri.order), false),
    });
    let w = &welded[..3 * ng];
    let nb = timings.time("neighbors", || neighbors::build(w, 3 * n_faces, short_tail));
    crate::report::mem_mark("engine neighbors");
    let mut grp = timings.time("groups", || groups::build(w, &nb, &mut tri));
    crate::report::mem_mark("engine groups");
    drop(nb);
    // Sums are made a slice of groups at a time and kept compactly: one value for a group whose
    // members all got the same bits (the usual case), else one per member. Only then are the
    // per-triangle and welding arrays dropped and the per-corner output allocated, so the two
    // never coexist.
    let t_acc = std::time::Instant::now();
    let n_groups = grp.rep.len();
    let mut first_slot: Vec<u32> = Vec::with_capacity(n_groups);
    let mut uniform: Vec<bool> = Vec::with_capacity(n_groups);
    let mut slots: Vec<V3> = Vec::with_capacity(n_groups);
    let mut g0 = 0;
    while g0 < n_groups {
        let limit = grp.start[g0] as usize + PASS;
        let g1 = (g0 + 1).max(grp.start.partition_point(|&x| (x as usize) <= limit) - 1).min(n_groups);
        let vals = accumulate_all(&c, w, &tri, &mut grp, g0..g1);
        let base = grp.start[g0] as usize;
        for g in g0..g1 {
            let v = &vals[grp.start[g] as usize - base..grp.start[g + 1] as usize - base];
            let same = v.iter().all(|x| x.map(f32::to_bits) == v[0].map(f32::to_bits));
            first_slot.push(slots.len() as u32);
            uniform.push(same);
            if same {
                slots.push(v[0]);
            } else {
                slots.extend_from_slice(v);
            }
        }
        g0 = g1;
    }
    timings.stages.push(("accumulate".into(), t_acc.elapsed().as_secs_f64() * 1e3));
    crate::report::mem_mark("engine accumulate");
    let t_out = std::time::Instant::now();
    (tri.s, tri.t, tri.gwa, grp.rep) = Default::default();
    let welded = (ng < tri.order.len()).then_some(welded);
    // Zeroed in parallel: the first touch of each page (a page fault) is shared between threads.
    let mut out: Vec<[f32; 4]> = (0..mesh.indices.len()).into_par_iter().with_min_len(1 << 14).map(|_| [0.0; 4]).collect();
    for g in 0..n_groups {
        let sign = if grp.orient[g] { 1.0 } else { -1.0 };
        let range = grp.start[g] as usize..grp.start[g + 1] as usize;
        for (i, &k) in grp.members[range].iter().enumerate() {
            let v = slots[first_slot[g] as usize + if uniform[g] { 0 } else { i }];
            let corner = 3 * tri.order[(k / 3) as usize] as usize + (k % 3) as usize;
            out[corner] = [v[0], v[1], v[2], sign];
        }
    }
    if let Some(welded) = welded {
        degenerate(&welded, &tri, n_faces, &mut out);
    }
    timings.stages.push(("output".into(), t_out.elapsed().as_secs_f64() * 1e3));
    Ok(out)
}

/// Members per pass of the sums (see [`generate_timed`]).
const PASS: usize = 1 << 18;

/// Runs [`accumulate::group_tangents`] on the groups in `groups`, in parallel batches of whole
/// groups; returns their members' sums. Sorts each group's members (the reference sums in
/// triangle order).
fn accumulate_all(c: &Corners, w: &[u32], tri: &triangles::Triangles, grp: &mut groups::Groups, groups: std::ops::Range<usize>) -> Vec<V3> {
    const BATCH: usize = 8192;
    let n_groups = groups.end;
    let (lo, hi) = (grp.start[groups.start] as usize, grp.start[groups.end] as usize);
    let mut vals = vec![[0.0f32; 3]; hi - lo];
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
    let (start, rep) = (&grp.start, &grp.rep);
    batches.into_par_iter().for_each(|(g0, g1, ms, vs)| {
        let base = start[g0] as usize;
        let mut scratch = Vec::new();
        for g in g0..g1 {
            let r = start[g] as usize - base..start[g + 1] as usize - base;
            let m = &mut ms[r.clone()];
            m.sort_unstable();
            accumulate::group_tangents(c, w, tri, rep[g], m, &mut vs[r], &mut scratch);
        }
    });
    vals
}

/// Corners of degenerate triangles copy the output of the first good corner (in the
/// reference's good-triangle order) with the same welded id, if any.
fn degenerate(welded: &[u32], tri: &triangles::Triangles, n_faces: usize, out: &mut [[f32; 4]]) {
    let ng = tri.n_good;
    let corner = |k: usize| 3 * tri.order[k / 3] as usize + k % 3;
    let mut first_good = vec![u32::MAX; 3 * n_faces];
    for (k, &id) in welded[..3 * ng].iter().enumerate() {
        let slot = &mut first_good[id as usize];
        if *slot == u32::MAX {
            *slot = k as u32;
        }
    }
    for (k, &id) in welded.iter().enumerate().skip(3 * ng) {
        let src = first_good[id as usize];
        if src != u32::MAX {
            out[corner(k)] = out[corner(src as usize)];
        }
    }
}

#[cfg(test)]
mod tests;
