//! Binary PLY's two big elements read on every core: a scan of tens of millions of vertices and
//! faces is almost all of its file.
//!
//! Vertex records without lists have one size, so record `k` is found by multiplying. Face
//! records differ in size when polygons do, so one cheap pass hops from record to record (a count
//! and an add each) to find where every block of [`BLOCK`] faces starts and how many triangles
//! come before it; then the blocks are read in parallel, each into its own part of the output.
//! Errors are those of the sequential reader, for the same first record.

use super::{fan, Element, Ty};
use rayon::prelude::*;

/// Faces a parallel task reads.
const BLOCK: usize = 64 * 1024;

/// Why a binary element could not be read: the record (from 0) and what was wrong.
pub(super) enum Fault {
    Truncated(u64),
    /// A face naming a vertex past the end (or negative).
    Index {
        face: u64,
        v: i64,
    },
}

/// The `N` bytes at the start of `b`, in little-endian order.
#[inline(always)]
fn get<const N: usize>(b: &[u8], big: bool) -> [u8; N] {
    let mut a: [u8; N] = b[..N].try_into().expect("a whole value");
    if big {
        a.reverse();
    }
    a
}

/// An integer at the start of `b` (list counts and indices are integers: the header reader
/// refuses others; a float here reads as its integer part).
#[inline(always)]
pub(super) fn int(b: &[u8], ty: Ty, big: bool) -> i64 {
    match ty {
        Ty::I8 => b[0] as i8 as i64,
        Ty::U8 => b[0] as i64,
        Ty::I16 => i16::from_le_bytes(get(b, big)) as i64,
        Ty::U16 => u16::from_le_bytes(get(b, big)) as i64,
        Ty::I32 => i32::from_le_bytes(get(b, big)) as i64,
        Ty::U32 => u32::from_le_bytes(get(b, big)) as i64,
        Ty::F32 => f32::from_le_bytes(get(b, big)) as i64,
        Ty::F64 => f64::from_le_bytes(get(b, big)) as i64,
    }
}

/// A value at the start of `b` as f32, as the sequential reader gives it (a double rounded once).
#[inline(always)]
pub(super) fn float(b: &[u8], ty: Ty, big: bool) -> f32 {
    match ty {
        Ty::F32 => f32::from_le_bytes(get(b, big)),
        Ty::F64 => f64::from_le_bytes(get(b, big)) as f32,
        _ => int(b, ty, big) as f32,
    }
}

/// The vertex element's columns, when its records have one size (no lists): `cols[j]` is the
/// (offset, type) of property `j`, and the record size.
pub(super) fn fixed_layout(el: &Element) -> Option<(Vec<(usize, Ty)>, usize)> {
    let mut off = 0;
    let mut cols = Vec::with_capacity(el.props.len());
    for p in &el.props {
        if p.list.is_some() {
            return None;
        }
        cols.push((off, p.ty));
        off += p.ty.size();
    }
    Some((cols, off))
}

/// The columns `want` of `n` fixed-size records of `stride` bytes at the start of `b` (which the
/// caller has checked holds them all), as `N`-vectors of f32.
pub(super) fn columns<const N: usize>(
    b: &[u8],
    n: usize,
    stride: usize,
    want: [(usize, Ty); N],
    big: bool,
) -> Vec<[f32; N]> {
    let rows = (0..n).into_par_iter().with_min_len(4096);
    // The common case, float columns, without a type switch per value.
    if want.iter().all(|c| c.1 == Ty::F32) {
        return rows.map(|k| want.map(|(off, _)| f32::from_le_bytes(get(&b[k * stride + off..], big)))).collect();
    }
    rows.map(|k| want.map(|(off, ty)| float(&b[k * stride + off..], ty, big))).collect()
}

/// Reads the face element `el` at the start of `b`, whose index list is property `list`, with
/// `nv` vertices: polygons fanned from their first corner. Returns the triangles and the bytes
/// the element took.
pub(super) fn faces(el: &Element, list: usize, b: &[u8], nv: u64, big: bool) -> Result<(Vec<[u32; 3]>, usize), Fault> {
    // Where each block starts (bytes) and how many triangles come before it.
    let mut starts: Vec<(usize, usize)> = Vec::with_capacity(el.count as usize / BLOCK + 2);
    let (mut at, mut tris) = (0usize, 0usize);
    // The records before a truncation are still read: a bad index there is the first error.
    let mut end = el.count;
    for k in 0..el.count {
        if k % BLOCK as u64 == 0 {
            starts.push((at, tris));
        }
        let Some(corners) = record(el, list, b, big, &mut at, |_| {}) else {
            end = k;
            break;
        };
        tris += corners.saturating_sub(2);
    }
    starts.push((at, tris));
    let mut out = vec![[0u32; 3]; tris];
    // Each block's own part of the output.
    let mut parts = Vec::with_capacity(starts.len());
    let mut rest = out.as_mut_slice();
    for w in starts.windows(2) {
        let (part, tail) = rest.split_at_mut(w[1].1 - w[0].1);
        parts.push((w[0].0, part));
        rest = tail;
    }
    let item = el.props[list].ty;
    let isize = item.size();
    parts.into_par_iter().enumerate().try_for_each(|(blk, (mut at, part))| {
        let first = (blk * BLOCK) as u64;
        let last = (first + BLOCK as u64).min(end);
        let mut t = 0;
        let mut idx: Vec<i64> = Vec::new();
        for k in first..last {
            record(el, list, b, big, &mut at, |bytes| {
                idx.clear();
                // One type switch per record, not per index.
                match item {
                    Ty::U32 => idx.extend(bytes.chunks_exact(4).map(|c| u32::from_le_bytes(get(c, big)) as i64)),
                    Ty::I32 => idx.extend(bytes.chunks_exact(4).map(|c| i32::from_le_bytes(get(c, big)) as i64)),
                    _ => idx.extend(bytes.chunks_exact(isize).map(|c| int(c, item, big))),
                }
            })
            .expect("the first pass read every record");
            if let Some(&v) = idx.iter().find(|&&v| v < 0 || v as u64 >= nv) {
                return Err(Fault::Index { face: k, v });
            }
            for tri in fan(&idx) {
                part[t] = tri.map(|v| v as u32);
                t += 1;
            }
        }
        Ok(())
    })?;
    if end < el.count {
        return Err(Fault::Truncated(end));
    }
    Ok((out, at))
}

/// Steps over one face record at `b[*at..]`, handing `list`'s index bytes to `f`; the number of
/// corners, or `None` when the record runs past the end (or its count is negative).
#[inline(always)]
fn record(el: &Element, list: usize, b: &[u8], big: bool, at: &mut usize, mut f: impl FnMut(&[u8])) -> Option<usize> {
    let mut corners = 0;
    for (j, p) in el.props.iter().enumerate() {
        let Some(ct) = p.list else {
            *at += p.ty.size();
            continue;
        };
        let head = b.get(*at..*at + ct.size())?;
        let n = int(head, ct, big);
        if n < 0 {
            return None;
        }
        let len = (n as usize).checked_mul(p.ty.size())?;
        let items = b.get(*at + ct.size()..(*at + ct.size()).checked_add(len)?)?;
        if j == list {
            corners = n as usize;
            f(items);
        }
        *at += ct.size() + len;
    }
    (*at <= b.len()).then_some(corners)
}
