//! ASCII PLY's vertex and face elements read on every core, when each record is one line (as
//! exporters write them).
//!
//! The lines are counted in parallel to find where an element ends, then cut into pieces of about
//! [`PIECE`] bytes at line ends, each parsed on its own and joined in order. The sequential reader
//! stays the reference: anything this path does not take as it is (a record over two lines, a
//! blank line, a value that is not a number, an index out of range, a missing last newline) makes
//! it give up, and the sequential reader reads the element again and names the first bad record.

use super::{fan, Element};
use crate::format::mesh::text_number::{parse_f32, short_int};
use memchr::{memchr, memchr_iter};
use rayon::prelude::*;

/// Bytes a parallel task parses.
const PIECE: usize = 1 << 20;

/// Where the `n`-th line of `b` ends (just past its newline); `None` when `b` has fewer.
fn lines_end(b: &[u8], n: u64) -> Option<usize> {
    if n == 0 {
        return Some(0);
    }
    let counts: Vec<u64> = b.par_chunks(PIECE).map(|c| memchr_iter(b'\n', c).count() as u64).collect();
    let mut before = 0;
    for (i, &k) in counts.iter().enumerate() {
        if before + k >= n {
            let chunk = &b[i * PIECE..((i + 1) * PIECE).min(b.len())];
            let at = memchr_iter(b'\n', chunk).nth((n - before - 1) as usize)?;
            return Some(i * PIECE + at + 1);
        }
        before += k;
    }
    None
}

/// `b` (whole lines) cut into pieces of about [`PIECE`] bytes, each ending at a line end.
fn pieces(b: &[u8]) -> Vec<&[u8]> {
    let mut out = Vec::with_capacity(b.len() / PIECE + 1);
    let mut rest = b;
    while !rest.is_empty() {
        let cut = if rest.len() <= PIECE {
            rest.len()
        } else {
            memchr(b'\n', &rest[PIECE..]).map_or(rest.len(), |k| PIECE + k + 1)
        };
        let (piece, tail) = rest.split_at(cut);
        out.push(piece);
        rest = tail;
    }
    out
}

/// The lines of the element's `el.count` records at the start of `b`, in pieces; `None` when
/// there are not that many whole lines.
fn element_pieces<'a>(el: &Element, b: &'a [u8]) -> Option<(Vec<&'a [u8]>, usize)> {
    let end = lines_end(b, el.count)?;
    Some((pieces(&b[..end]), end))
}

/// The whitespace-separated tokens of a line (the sequential reader's whitespace: ASCII's).
struct Tokens<'a> {
    b: &'a [u8],
    i: usize,
}

impl<'a> Iterator for Tokens<'a> {
    type Item = &'a [u8];

    #[inline]
    fn next(&mut self) -> Option<&'a [u8]> {
        next_token(self.b, &mut self.i)
    }
}

/// The token at or after `b[*i]`, with `*i` moved past it; `None` at the end.
#[inline]
pub(super) fn next_token<'a>(b: &'a [u8], i: &mut usize) -> Option<&'a [u8]> {
    while *i < b.len() && b[*i].is_ascii_whitespace() {
        *i += 1;
    }
    let start = *i;
    while *i < b.len() && !b[*i].is_ascii_whitespace() {
        *i += 1;
    }
    (*i > start).then(|| &b[start..*i])
}

fn tokens(line: &[u8]) -> Tokens<'_> {
    Tokens { b: line, i: 0 }
}

/// The lines of `piece` (which ends at a line end), newline left off.
fn lines(piece: &[u8]) -> impl Iterator<Item = &[u8]> {
    let mut start = 0;
    memchr_iter(b'\n', piece).map(move |end| {
        let line = &piece[start..end];
        start = end + 1;
        line
    })
}

/// An integer as `str::parse::<i64>` reads it: the shared short parser, and the standard one for
/// what that leaves (a number too long for it, or not a number).
#[inline]
pub(super) fn int(t: &[u8]) -> Option<i64> {
    short_int(t).or_else(|| std::str::from_utf8(t).ok()?.parse().ok())
}

/// Vertex columns as the sequential reader keeps them.
pub(super) struct Columns {
    pub xyz: [usize; 3],
    pub nrm: Option<[usize; 3]>,
    pub uv: Option<[usize; 2]>,
}

/// Positions, normals (empty without `nrm`) and texture coordinates (empty without `uv`).
pub(super) type Vertices = (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<[f32; 2]>);

/// The vertex element `el` (no list properties) at the start of `b`, and the bytes it took.
pub(super) fn vertices(el: &Element, b: &[u8], c: &Columns) -> Option<(Vertices, usize)> {
    let (parts, used) = element_pieces(el, b)?;
    let np = el.props.len();
    let read = |piece: &[u8]| -> Option<Vertices> {
        let mut out: Vertices = Default::default();
        let mut vals = vec![0f32; np];
        for line in lines(piece) {
            let mut k = 0;
            for t in tokens(line) {
                *vals.get_mut(k)? = parse_f32(t)?;
                k += 1;
            }
            if k != np {
                return None;
            }
            let q = c.xyz.map(|j| vals[j]);
            if !q.iter().all(|v| v.is_finite()) {
                return None;
            }
            out.0.push(q);
            if let Some(n) = c.nrm {
                out.1.push(n.map(|j| vals[j]));
            }
            if let Some(uv) = c.uv {
                out.2.push(uv.map(|j| vals[j]));
            }
        }
        Some(out)
    };
    let got: Vec<Vertices> = parts.into_par_iter().map(read).collect::<Option<_>>()?;
    let mut all: Vertices = Default::default();
    all.0.reserve_exact(el.count as usize);
    for (p, n, uv) in got {
        all.0.extend(p);
        all.1.extend(n);
        all.2.extend(uv);
    }
    Some((all, used))
}

/// The face element `el` at the start of `b`, whose index list is property `list`, over `nv`
/// vertices: polygons fanned from their first corner, and the bytes the element took.
pub(super) fn faces(el: &Element, list: usize, b: &[u8], nv: u64) -> Option<(Vec<[u32; 3]>, usize)> {
    let (parts, used) = element_pieces(el, b)?;
    let read = |piece: &[u8]| -> Option<Vec<[u32; 3]>> {
        let mut out = Vec::with_capacity(piece.len() / 12);
        let mut idx: Vec<u32> = Vec::new();
        for line in lines(piece) {
            let mut t = tokens(line);
            for (j, p) in el.props.iter().enumerate() {
                if p.list.is_none() {
                    t.next()?;
                    continue;
                }
                let n = int(t.next()?)?;
                if n < 0 {
                    return None;
                }
                if j != list {
                    for _ in 0..n {
                        t.next()?;
                    }
                    continue;
                }
                idx.clear();
                for _ in 0..n {
                    let v = int(t.next()?)?;
                    if v < 0 || v as u64 >= nv {
                        return None;
                    }
                    idx.push(v as u32);
                }
                out.extend(fan(&idx));
            }
            if t.next().is_some() {
                return None;
            }
        }
        Some(out)
    };
    let got: Vec<Vec<[u32; 3]>> = parts.into_par_iter().map(read).collect::<Option<_>>()?;
    let mut all = Vec::with_capacity(got.iter().map(Vec::len).sum());
    got.into_iter().for_each(|g| all.extend(g));
    Some((all, used))
}

#[cfg(test)]
mod tests {
    #[test]
    fn int_reads_as_the_standard_parser() {
        for t in [
            "0",
            "-0",
            "+7",
            "42",
            "-13",
            "",
            "-",
            "+",
            "1.5",
            "1e3",
            "0x10",
            " 1",
            "٣",
            "999999999999999999",
            "9223372036854775807",
            "9223372036854775808",
            "-9223372036854775808",
            "00000000000000000000012",
        ] {
            assert_eq!(super::int(t.as_bytes()), t.parse::<i64>().ok(), "{t:?}");
        }
    }
}
