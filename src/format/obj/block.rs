//! One block of an OBJ file (tens of megabytes), parsed on every core and placed in file order.
//!
//! The block is cut at line starts into pieces, and every piece is parsed at once without
//! knowing how many `v`/`vt`/`vn` come before it: positive indices are absolute anyway, and each
//! piece keeps the largest index it names. Only then are the pieces' counts summed into bases,
//! so no pass over the text comes first. A piece that does need its base is parsed again knowing
//! it: one with a relative (negative) index stops at the first one, is counted, and parsed again;
//! one naming an element past its own end (a forward reference, legal and rare) is parsed again
//! so that the line of an index found past the file's end can be named. The result is the same
//! whatever the piece size or thread count. The pieces' arrays are reused from block to block and
//! copied into the growing output on every core, each at its place.

use super::continuation::{join, next_line_end};
use super::piece::{count, Counts, Forward, Piece};
use crate::error::{Error, Result};
use crate::format::mesh::{StoredMesh, MISSING};
use crate::progress::Reporter;
use rayon::prelude::*;
use std::mem::MaybeUninit;
use std::path::Path;

#[derive(Default)]
pub(super) struct Acc {
    data: StoredMesh,
    any_t: bool,
    any_n: bool,
    forward: Vec<Forward>,
    lines: u64,
    /// The pieces of the last block, kept for their arrays' capacity.
    pool: Vec<Piece>,
    /// Ticked with each piece's bytes as it is parsed.
    progress: Reporter,
}

impl Acc {
    pub(super) fn new(progress: Reporter) -> Acc {
        Acc { progress, ..Default::default() }
    }

    pub(super) fn block<const FAST: bool>(&mut self, path: &Path, bytes: &[u8], piece: usize) -> Result<()> {
        let texts = split(bytes, piece);
        let mut pool = std::mem::take(&mut self.pool);
        if pool.len() < texts.len() {
            pool.resize_with(texts.len(), Piece::default);
        }
        let out = self.parse_and_place::<FAST>(path, &texts, &mut pool[..texts.len()]);
        self.pool = pool;
        out
    }

    fn parse_and_place<const FAST: bool>(&mut self, path: &Path, texts: &[&[u8]], pieces: &mut [Piece]) -> Result<()> {
        // A piece holding a continued line is read again, joined: the parse stops at the first
        // such line, so no pass over the text looks for one first.
        let mut joined: Vec<Option<Vec<u8>>> = vec![None; texts.len()];
        pieces.par_iter_mut().zip(texts).zip(&mut joined).for_each(|((p, t), j)| {
            p.parse::<FAST>(t, None);
            if p.continued {
                let v = join(t).into_owned();
                p.parse::<FAST>(&v, None);
                *j = Some(v);
            }
            self.progress.tick(t.len() as u64);
        });
        let texts: Vec<&[u8]> = texts.iter().zip(&joined).map(|(&t, j)| j.as_deref().unwrap_or(t)).collect();
        let texts = &texts[..];
        pieces.par_iter_mut().zip(texts).filter(|(p, _)| p.needs_base).for_each(|(p, t)| p.counts = count(t));

        // Bases up to the first piece that failed: an error there is the block's first unless a
        // piece before it, parsed again, finds an earlier one.
        let d = &self.data;
        let mut b = Counts { v: d.positions.len() as u64, t: d.uvs.len() as u64, n: d.normals.len() as u64, lines: 0 };
        b.lines = self.lines;
        let mut bases = Vec::with_capacity(pieces.len());
        let mut again = Vec::with_capacity(pieces.len());
        for p in pieces.iter() {
            if p.error.is_some() && !p.needs_base {
                break;
            }
            let c = p.counts;
            let past_end = |k: usize, base: u64, n: u64| p.max[k] as u64 > base + n;
            again.push(p.needs_base || past_end(0, b.v, c.v) || past_end(1, b.t, c.t) || past_end(2, b.n, c.n));
            bases.push(b);
            b = Counts { v: b.v + c.v, t: b.t + c.t, n: b.n + c.n, lines: b.lines + c.lines };
        }
        if b.v.max(b.t).max(b.n) >= MISSING as u64 {
            return Err(Error::input(path, "more than 4 billion vertices: too large for 32-bit indices"));
        }
        let known = bases.len();
        pieces[..known]
            .par_iter_mut()
            .zip(texts)
            .zip(&bases)
            .zip(&again)
            .filter(|(_, again)| **again)
            .for_each(|(((p, t), base), _)| p.parse::<FAST>(t, Some([base.v, base.t, base.n])));
        let line_base = |k: usize| bases.get(k).map_or(b.lines, |c| c.lines);
        for (k, p) in pieces.iter().enumerate().take(known + 1) {
            if let Some((line, msg)) = &p.error {
                return Err(Error::input(path, format!("OBJ line {}: {msg}", line_base(k) + line)));
            }
        }
        self.place(pieces, &bases);
        self.lines = b.lines;
        Ok(())
    }

    /// Appends the block's pieces, all parsed, in file order.
    fn place(&mut self, pieces: &mut [Piece], bases: &[Counts]) {
        let d = &mut self.data;
        let tris_before = d.triangles.len();
        let mut at = tris_before;
        for (p, base) in pieces.iter_mut().zip(bases) {
            for (t, s) in p.statements.drain(..) {
                d.statements.push((t + at as u32, s));
            }
            d.mtllibs.append(&mut p.mtllibs);
            self.forward.extend(p.forward.drain(..).map(|f| Forward { line: f.line + base.lines, ..f }));
            at += p.tv.len();
        }
        append(&mut d.positions, pieces, [0.0; 3], |p| (&p.pos, p.pos.len()));
        append(&mut d.normals, pieces, [0.0; 3], |p| (&p.nrm, p.nrm.len()));
        append(&mut d.uvs, pieces, [0.0; 2], |p| (&p.uv, p.uv.len()));
        append(&mut d.triangles, pieces, [0; 3], |p| (&p.tv, p.tv.len()));
        // A kind of index some pieces lack is filled in as missing for their triangles.
        let lists = [(&mut self.any_t, &mut d.uv_triangles, false), (&mut self.any_n, &mut d.normal_triangles, true)];
        for (any, list, normals) in lists {
            fn of(p: &Piece, normals: bool) -> (bool, &[[u32; 3]]) {
                if normals {
                    (p.any_n, &p.tn)
                } else {
                    (p.any_t, &p.tt)
                }
            }
            if !*any && pieces.iter().any(|p| of(p, normals).0) {
                *any = true;
                list.resize(tris_before, [MISSING; 3]);
            }
            if *any {
                append(list, pieces, [MISSING; 3], |p| (of(p, normals).1, p.tv.len()));
            }
        }
    }

    pub(super) fn finish(mut self, path: &Path) -> Result<StoredMesh> {
        let d = &mut self.data;
        let totals = [d.positions.len(), d.uvs.len(), d.normals.len()];
        for f in &self.forward {
            // Indices into a kind the file never defines are ignored, as tobj did.
            if f.index as usize >= totals[f.attr as usize] && (f.attr == 0 || totals[f.attr as usize] > 0) {
                let what = ["vertex", "texture coordinate", "normal"][f.attr as usize];
                return Err(Error::input(
                    path,
                    format!(
                        "OBJ line {}: {what} index {} is past the {} defined in the file (indices start at 1; negative ones count back from the last)",
                        f.line,
                        f.index as u64 + 1,
                        totals[f.attr as usize]
                    ),
                ));
            }
        }
        // Values without indices would read as one per position (PLY's way): those no corner
        // names are dropped, as indices into values the file never defines are.
        if d.uvs.is_empty() || d.uv_triangles.is_empty() {
            (d.uvs, d.uv_triangles) = Default::default();
        }
        if d.normals.is_empty() || d.normal_triangles.is_empty() {
            (d.normals, d.normal_triangles) = Default::default();
        }
        Ok(self.data)
    }
}

/// Appends to `out`, for each piece in order, `n` items: the piece's slice, then `fill` for the
/// rest (`part` gives both). The copies run on every core, each straight into its place, into
/// pages made present first (`pages.rs`).
fn append<T: Copy + Send + Sync>(
    out: &mut Vec<T>,
    pieces: &[Piece],
    fill: T,
    part: impl Fn(&Piece) -> (&[T], usize) + Sync,
) {
    let total: usize = pieces.iter().map(|p| part(p).1).sum();
    out.reserve(total);
    let mut rest: &mut [MaybeUninit<T>] = &mut out.spare_capacity_mut()[..total];
    crate::pages::prefault(rest);
    let mut slots = Vec::with_capacity(pieces.len());
    for p in pieces {
        let (slot, after) = std::mem::take(&mut rest).split_at_mut(part(p).1);
        slots.push(slot);
        rest = after;
    }
    slots.into_par_iter().zip(pieces).for_each(|(slot, p)| {
        let src = part(p).0;
        let (head, tail) = slot.split_at_mut(src.len());
        for (d, s) in head.iter_mut().zip(src) {
            d.write(*s);
        }
        for d in tail {
            d.write(fill);
        }
    });
    // SAFETY: the `total` items after the old length were all written just above (the slots
    // split that range without gaps, and each slot is written whole).
    unsafe { out.set_len(out.len() + total) };
}

/// Cuts `bytes` after a line end near every `piece` bytes (never inside a continued line).
fn split(bytes: &[u8], piece: usize) -> Vec<&[u8]> {
    let mut out = Vec::with_capacity(bytes.len() / piece + 1);
    let mut rest = bytes;
    while rest.len() > piece {
        match next_line_end(rest, piece - 1) {
            Some(end) => {
                let (a, b) = rest.split_at(end);
                out.push(a);
                rest = b;
            }
            None => break,
        }
    }
    if !rest.is_empty() || out.is_empty() {
        out.push(rest);
    }
    out
}
