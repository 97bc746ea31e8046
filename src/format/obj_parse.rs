//! Wavefront OBJ geometry, parsed on every core at memory speed.
//!
//! The file is read in blocks; each block is cut at line starts into pieces of about a megabyte,
//! the pieces are parsed in parallel and appended in file order, so the result never depends on
//! the thread count or the piece size. A first quick pass counts each piece's `v`/`vt`/`vn`
//! lines, so every piece knows the index its lines start at: relative (negative) indices are
//! resolved and indices checked during the parallel parse, with the file's own line numbers.
//! Only a reference to an element defined further down (legal, rare) waits for the end of the
//! file to be checked.
//!
//! Values are kept as the file stores them (UV v up); the glue in `obj.rs` (a Scene) and
//! `raw.rs` (a RawMesh) converts. Polygons are fanned from their first corner, as `tobj` did.

use super::obj_fast::{fast_corners, fast_floats, parse_int};
pub use super::obj_fast::{lead_f32, parse_f32};
use crate::error::{Error, Result};
use crate::progress::{Counting, Reporter};
use memchr::memchr;
use rayon::prelude::*;
use std::io::Read;
use std::path::Path;

/// The index of a corner that names no `vt` (or no `vn`).
pub const MISSING: u32 = u32::MAX;

/// Pieces are cut at about this many bytes; blocks of this many pieces are read at a time.
const PIECE: usize = 1 << 20;
const PIECES_PER_BLOCK: usize = 64;

#[derive(Debug, Clone, PartialEq)]
pub enum Statement {
    /// `o` or `g` with its name (the rest of the line; `unnamed_object` when empty).
    Name(String),
    /// `usemtl` with its material name.
    Material(String),
}

/// An OBJ file's geometry as stored, triangulated.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct ObjData {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    /// As stored: v up.
    pub uvs: Vec<[f32; 2]>,
    /// Per triangle, three indices into `positions`.
    pub tri_v: Vec<[u32; 3]>,
    /// Per triangle, indices into `uvs` ([`MISSING`] for a corner without one); empty when no
    /// corner names one.
    pub tri_t: Vec<[u32; 3]>,
    /// Per triangle, indices into `normals`, as `tri_t`.
    pub tri_n: Vec<[u32; 3]>,
    /// `o`/`g`/`usemtl` in file order, each with the number of triangles before it.
    pub statements: Vec<(u32, Statement)>,
    /// `mtllib` file names in file order.
    pub mtllibs: Vec<String>,
}

/// Reads and parses the OBJ file at `path`, a block at a time, reporting the bytes read as the
/// progress stage `read NAME`.
pub fn parse_file(path: &Path, progress: &Reporter) -> Result<ObjData> {
    let file = std::fs::File::open(path).map_err(|e| Error::input(path, format!("cannot read: {e}")))?;
    let len = file.metadata().map_or(0, |m| m.len());
    reported(path, len, progress, |p| parse_reader(path, Counting::new(file, p), piece_for(len)))
}

/// Pieces for a file of `len` bytes: [`PIECE`], or smaller for a file under a block, so that a
/// small file's buffer is its own size and not a whole block's (zeroed before the read fills it).
fn piece_for(len: u64) -> usize {
    PIECE.min(usize::try_from(len).unwrap_or(usize::MAX) / PIECES_PER_BLOCK + 4096)
}

/// Parses OBJ bytes already in memory, reported as [`parse_file`] reports a file.
pub fn parse_bytes(path: &Path, bytes: &[u8], progress: &Reporter) -> Result<ObjData> {
    let piece = piece_for(bytes.len() as u64);
    reported(path, bytes.len() as u64, progress, |p| parse_reader(path, Counting::new(bytes, p), piece))
}

fn reported(
    path: &Path,
    len: u64,
    progress: &Reporter,
    read: impl FnOnce(&Reporter) -> Result<ObjData>,
) -> Result<ObjData> {
    let name = path.file_name().map(|n| n.to_string_lossy()).unwrap_or_default();
    progress.start(&format!("read {name}"), len, "bytes");
    let out = read(progress);
    progress.finish();
    out
}

/// Parses from `r` with pieces of about `piece` bytes (small in tests, to cut lines everywhere).
pub fn parse_reader(path: &Path, r: impl Read, piece: usize) -> Result<ObjData> {
    parse_with::<true>(path, r, piece)
}

/// [`parse_reader`], with or without the common lines' own path (the tests compare the two).
fn parse_with<const FAST: bool>(path: &Path, mut r: impl Read, piece: usize) -> Result<ObjData> {
    let piece = piece.max(1);
    let block = piece * PIECES_PER_BLOCK;
    let mut acc = Acc::default();
    // `buf[..kept]` holds what the last block left (a line not yet ended); the buffer keeps its
    // length between blocks, so it is zeroed once, not at every block.
    let mut buf: Vec<u8> = Vec::new();
    let mut kept = 0;
    let mut eof = false;
    let mut first = true;
    while !eof {
        // Fill the buffer to a block (more when one line is longer than a block).
        let want = kept + block;
        let mut filled = kept;
        if buf.len() < want {
            buf.resize(want, 0);
        }
        while filled < want {
            match r.read(&mut buf[filled..]) {
                Ok(0) => {
                    eof = true;
                    break;
                }
                Ok(n) => filled += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(Error::input(path, format!("cannot read: {e}"))),
            }
        }
        let data = &buf[..filled];
        let start = if first && data.starts_with(b"\xEF\xBB\xBF") { 3 } else { 0 };
        first = false;
        let cut = if eof { filled } else { data.iter().rposition(|&c| c == b'\n').map_or(start, |i| i + 1) };
        acc.block::<FAST>(path, &data[start..cut], piece)?;
        buf.copy_within(cut..filled, 0);
        kept = filled - cut;
    }
    acc.finish(path)
}

#[derive(Default, Clone, Copy)]
struct Counts {
    v: u64,
    t: u64,
    n: u64,
    lines: u64,
}

/// A reference past what was defined when its face was read, checked at the end.
struct Forward {
    attr: u8,
    index: u32,
    line: u64,
}

#[derive(Default)]
struct Acc {
    data: ObjData,
    any_t: bool,
    any_n: bool,
    forward: Vec<Forward>,
    lines: u64,
}

impl Acc {
    fn block<const FAST: bool>(&mut self, path: &Path, bytes: &[u8], piece: usize) -> Result<()> {
        let pieces = split(bytes, piece);
        let counts: Vec<Counts> = pieces.par_iter().map(|p| count(p)).collect();
        let mut bases = Vec::with_capacity(pieces.len());
        let mut b = Counts {
            v: self.data.positions.len() as u64,
            t: self.data.uvs.len() as u64,
            n: self.data.normals.len() as u64,
            lines: self.lines,
        };
        for c in &counts {
            bases.push(b);
            b = Counts { v: b.v + c.v, t: b.t + c.t, n: b.n + c.n, lines: b.lines + c.lines };
        }
        if b.v.max(b.t).max(b.n) >= MISSING as u64 {
            return Err(Error::input(path, "more than 4 billion vertices: too large for 32-bit indices"));
        }
        let parsed: Vec<std::result::Result<Piece, (u64, String)>> =
            pieces.par_iter().zip(&bases).map(|(p, base)| Piece::parse::<FAST>(p, *base)).collect();
        for p in parsed {
            let p = p.map_err(|(line, msg)| Error::input(path, format!("OBJ line {line}: {msg}")))?;
            self.append(p);
        }
        self.lines = b.lines;
        Ok(())
    }

    fn append(&mut self, p: Piece) {
        let d = &mut self.data;
        let before = d.tri_v.len();
        let tris = p.tv.len();
        for (at, s) in p.statements {
            d.statements.push((at + before as u32, s));
        }
        d.mtllibs.extend(p.mtllibs);
        d.positions.extend_from_slice(&p.pos);
        d.normals.extend_from_slice(&p.nrm);
        d.uvs.extend_from_slice(&p.uv);
        d.tri_v.extend_from_slice(&p.tv);
        let attrs = [(&mut self.any_t, &mut d.tri_t, &p.tt, p.any_t), (&mut self.any_n, &mut d.tri_n, &p.tn, p.any_n)];
        for (any, mine, theirs, piece_has) in attrs {
            if piece_has && !*any {
                *any = true;
                mine.resize(before, [MISSING; 3]);
            }
            if *any {
                if !piece_has {
                    mine.resize(before + tris, [MISSING; 3]);
                } else {
                    mine.extend_from_slice(theirs);
                }
            }
        }
        self.forward.extend(p.forward);
    }

    fn finish(mut self, path: &Path) -> Result<ObjData> {
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
        if d.uvs.is_empty() {
            d.tri_t.clear();
        }
        if d.normals.is_empty() {
            d.tri_n.clear();
        }
        Ok(self.data)
    }
}

/// Cuts `bytes` after a newline near every `piece` bytes.
fn split(bytes: &[u8], piece: usize) -> Vec<&[u8]> {
    let mut out = Vec::with_capacity(bytes.len() / piece + 1);
    let mut rest = bytes;
    while rest.len() > piece {
        match memchr(b'\n', &rest[piece - 1..]) {
            Some(k) => {
                let (a, b) = rest.split_at(piece + k);
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

#[derive(PartialEq, Clone, Copy)]
enum Kind {
    V,
    Vt,
    Vn,
    F,
    Name,
    Usemtl,
    Mtllib,
    Other,
}

pub(super) fn is_space(c: u8) -> bool {
    matches!(c, b' ' | b'\t' | b'\r' | 0x0b | 0x0c)
}

/// The keyword of the line starting at `i`, and where it ends.
fn keyword(b: &[u8], mut i: usize) -> (Kind, usize) {
    while i < b.len() && is_space(b[i]) {
        i += 1;
    }
    let s = i;
    while i < b.len() && !is_space(b[i]) && b[i] != b'\n' {
        i += 1;
    }
    let k = match &b[s..i] {
        b"v" => Kind::V,
        b"vt" => Kind::Vt,
        b"vn" => Kind::Vn,
        b"f" => Kind::F,
        b"o" | b"g" => Kind::Name,
        b"usemtl" => Kind::Usemtl,
        b"mtllib" => Kind::Mtllib,
        _ => Kind::Other,
    };
    (k, i)
}

fn line_end(b: &[u8], i: usize) -> usize {
    memchr(b'\n', &b[i.min(b.len())..]).map_or(b.len(), |k| i + k)
}

fn count(b: &[u8]) -> Counts {
    let mut c = Counts::default();
    let mut i = 0;
    while i < b.len() {
        // Only a line starting with `v` or with blanks can be a `v`/`vt`/`vn` line.
        if b[i] == b'v' || is_space(b[i]) {
            match keyword(b, i).0 {
                Kind::V => c.v += 1,
                Kind::Vt => c.t += 1,
                Kind::Vn => c.n += 1,
                _ => {}
            }
        }
        i = line_end(b, i) + 1;
        c.lines += 1;
    }
    c
}

#[derive(Default)]
struct Piece {
    pos: Vec<[f32; 3]>,
    nrm: Vec<[f32; 3]>,
    uv: Vec<[f32; 2]>,
    tv: Vec<[u32; 3]>,
    tt: Vec<[u32; 3]>,
    tn: Vec<[u32; 3]>,
    statements: Vec<(u32, Statement)>,
    mtllibs: Vec<String>,
    forward: Vec<Forward>,
    any_t: bool,
    any_n: bool,
}

pub(super) type Corner = [u32; 3];

/// A cursor over one line.
struct Line<'a> {
    b: &'a [u8],
    i: usize,
}

impl<'a> Line<'a> {
    /// The next whitespace-separated token, or None at the end of the line or at a `#` comment.
    fn token(&mut self) -> Option<&'a [u8]> {
        while self.i < self.b.len() && is_space(self.b[self.i]) {
            self.i += 1;
        }
        if self.i >= self.b.len() || self.b[self.i] == b'#' {
            return None;
        }
        let s = self.i;
        while self.i < self.b.len() && !is_space(self.b[self.i]) {
            self.i += 1;
        }
        Some(&self.b[s..self.i])
    }

    fn float(&mut self, what: &str) -> std::result::Result<f32, String> {
        let t = self.token().ok_or_else(|| format!("{what} has too few numbers"))?;
        parse_f32(t).ok_or_else(|| format!("{what}: '{}' is not a number", String::from_utf8_lossy(t)))
    }

    /// The rest of the line, trimmed, as text.
    fn rest(&self) -> String {
        String::from_utf8_lossy(self.b[self.i..].trim_ascii()).into_owned()
    }
}

impl Piece {
    /// Parses one piece; with `FAST` (always, but in the tests that compare both), the common
    /// lines (`v`/`vn`/`vt` with plain numbers, faces of positive indices already defined) take a
    /// path of their own; anything else on such a line sends it down the general path.
    fn parse<const FAST: bool>(b: &[u8], base: Counts) -> std::result::Result<Piece, (u64, String)> {
        let mut p = Piece::default();
        let mut i = 0;
        let mut line = base.lines;
        let mut corners: Vec<Corner> = Vec::new();
        let mut pending: Vec<Forward> = Vec::new();
        while i < b.len() {
            line += 1;
            if FAST {
                if let Some(next) = p.fast_line(b, i, base, &mut corners) {
                    i = next;
                    continue;
                }
            }
            let end = line_end(b, i);
            let (kind, after) = keyword(b, i);
            let mut l = Line { b: &b[..end], i: after };
            let r = match kind {
                Kind::V => p.vertex(&mut l),
                Kind::Vt => (|| {
                    p.uv.push([l.float("vt")?, l.float("vt")?]);
                    Ok(())
                })(),
                Kind::Vn => (|| {
                    p.nrm.push([l.float("vn")?, l.float("vn")?, l.float("vn")?]);
                    Ok(())
                })(),
                Kind::F => {
                    let now = [base.v + p.pos.len() as u64, base.t + p.uv.len() as u64, base.n + p.nrm.len() as u64];
                    p.face(&mut l, now, line, &mut corners, &mut pending)
                }
                Kind::Name => {
                    let name = l.rest();
                    let name = if name.is_empty() { "unnamed_object".to_string() } else { name };
                    p.statements.push((p.tv.len() as u32, Statement::Name(name)));
                    Ok(())
                }
                Kind::Usemtl => {
                    let name = l.rest();
                    if name.is_empty() {
                        Err("usemtl names no material".to_string())
                    } else {
                        p.statements.push((p.tv.len() as u32, Statement::Material(name)));
                        Ok(())
                    }
                }
                Kind::Mtllib => {
                    p.mtllibs.push(l.rest());
                    Ok(())
                }
                Kind::Other => Ok(()),
            };
            r.map_err(|m| (line, m))?;
            i = end + 1;
        }
        Ok(p)
    }

    /// The line at `i` if it is a common one, parsed; where the next line starts. `None` (nothing
    /// kept) for any other line, which the general path then reads.
    #[inline]
    fn fast_line(&mut self, b: &[u8], i: usize, base: Counts, corners: &mut Vec<Corner>) -> Option<usize> {
        let (c0, c1) = (b[i], *b.get(i + 1)?);
        if c0 == b'v' {
            if c1 == b' ' {
                let (v, next) = fast_floats::<3>(b, i + 2)?;
                self.pos.push(v);
                return Some(next);
            }
            if *b.get(i + 2)? == b' ' {
                if c1 == b'n' {
                    let (v, next) = fast_floats::<3>(b, i + 3)?;
                    self.nrm.push(v);
                    return Some(next);
                }
                if c1 == b't' {
                    let (v, next) = fast_floats::<2>(b, i + 3)?;
                    self.uv.push(v);
                    return Some(next);
                }
            }
            return None;
        }
        if c0 != b'f' || c1 != b' ' {
            return None;
        }
        let now = [base.v + self.pos.len() as u64, base.t + self.uv.len() as u64, base.n + self.nrm.len() as u64];
        let next = fast_corners(b, i + 2, now, corners)?;
        self.fan(corners);
        Some(next)
    }

    fn vertex(&mut self, l: &mut Line) -> std::result::Result<(), String> {
        let mut v = [l.float("v")?, l.float("v")?, l.float("v")?];
        let mut extra: [&[u8]; 4] = [&[]; 4];
        let mut n = 0;
        while n < 4 {
            match l.token() {
                Some(t) => extra[n] = t,
                None => break,
            }
            n += 1;
        }
        match n {
            0 | 3 => {} // x y z, or x y z r g b (colours are not kept)
            1 => {
                let w = parse_f32(extra[0]).ok_or("v: its w is not a number")?;
                if w == 0.0 {
                    return Err("v has w = 0 (a point at infinity)".to_string());
                }
                v = v.map(|x| x / w);
            }
            _ => return Err(format!("v has {} numbers (expected 3, 4 with w, or 6 with a colour)", n + 3)),
        }
        self.pos.push(v);
        Ok(())
    }

    fn face(
        &mut self,
        l: &mut Line,
        now: [u64; 3],
        line: u64,
        corners: &mut Vec<Corner>,
        pending: &mut Vec<Forward>,
    ) -> std::result::Result<(), String> {
        corners.clear();
        pending.clear();
        while let Some(t) = l.token() {
            let mut c = [MISSING; 3];
            for (k, part) in t.split(|&ch| ch == b'/').enumerate() {
                if part.is_empty() && k > 0 {
                    continue;
                }
                if k > 2 {
                    return Err(format!("face corner '{}' has more than v/vt/vn", String::from_utf8_lossy(t)));
                }
                let x = parse_int(part).ok_or_else(|| {
                    format!("face corner '{}' is not v, v/vt, v//vn or v/vt/vn", String::from_utf8_lossy(t))
                })?;
                let what = ["vertex", "texture coordinate", "normal"][k];
                let idx = if x > 0 {
                    x - 1
                } else if x < 0 {
                    let r = now[k] as i64 + x;
                    if r < 0 {
                        return Err(format!(
                            "relative {what} index {x} reaches before the first (only {} defined)",
                            now[k]
                        ));
                    }
                    r
                } else {
                    return Err(format!("{what} index 0 (OBJ indices start at 1)"));
                };
                if idx >= MISSING as i64 {
                    return Err(format!("{what} index {x} is too large"));
                }
                if idx as u64 >= now[k] {
                    pending.push(Forward { attr: k as u8, index: idx as u32, line });
                }
                c[k] = idx as u32;
            }
            corners.push(c);
        }
        if corners.len() < 3 {
            return Ok(()); // points and lines carry no surface
        }
        self.forward.append(pending);
        self.fan(corners);
        Ok(())
    }

    /// A polygon's triangles, fanned from its first corner (at least three corners).
    #[inline]
    fn fan(&mut self, corners: &[Corner]) {
        let has_t = corners.iter().any(|c| c[1] != MISSING);
        let has_n = corners.iter().any(|c| c[2] != MISSING);
        if has_t && !self.any_t {
            self.any_t = true;
            self.tt.resize(self.tv.len(), [MISSING; 3]);
        }
        if has_n && !self.any_n {
            self.any_n = true;
            self.tn.resize(self.tv.len(), [MISSING; 3]);
        }
        let a = corners[0];
        for w in corners[1..].windows(2) {
            let (b, c) = (w[0], w[1]);
            self.tv.push([a[0], b[0], c[0]]);
            if self.any_t {
                self.tt.push([a[1], b[1], c[1]]);
            }
            if self.any_n {
                self.tn.push([a[2], b[2], c[2]]);
            }
        }
    }
}

#[cfg(test)]
#[path = "obj_parse_tests.rs"]
mod tests;
