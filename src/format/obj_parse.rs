//! Wavefront OBJ geometry, parsed on every core at memory speed.
//!
//! A file is read through a memory map, a window of a block (64 MB) at a time, so its text is
//! never copied and only one window of it is mapped at once; other readers (a pipe) and bytes in
//! memory go through the same blocks. Each block is parsed in parallel pieces and appended in
//! file order (`obj_block.rs`), so the result never depends on the thread count or the piece
//! size. Errors name the file's own line numbers.
//!
//! Values are kept as the file stores them (UV v up); the glue in `obj.rs` (a Scene) and
//! `raw.rs` (a RawMesh) converts. Polygons are fanned from their first corner, as `tobj` did.

use super::obj_block::Acc;
use super::obj_fast::{fast_corners, fast_floats};
pub use super::obj_fast::{lead_f32, parse_f32};
use super::short_int;
use crate::error::{Error, Result};
use crate::progress::{Counting, Reporter};
use memchr::{memchr, memrchr};
use std::io::Read;
use std::ops::Deref;
use std::path::Path;

/// The index of a corner that names no `vt` (or no `vn`).
pub const MISSING: u32 = u32::MAX;

/// Pieces are cut at about this many bytes; blocks of this many pieces are parsed at a time.
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
    let cannot = |e: std::io::Error| Error::input(path, format!("cannot read: {e}"));
    let file = std::fs::File::open(path).map_err(cannot)?;
    let meta = file.metadata().map_err(cannot)?;
    let len = meta.len();
    reported(path, len, progress, |p| {
        let map = |at: u64, n: usize| {
            // SAFETY: the map is only read, and dropped before the next one. Like every reader
            // that maps a file, this trusts nothing to truncate the file while it is read.
            unsafe { memmap2::MmapOptions::new().offset(at).len(n).map(&file) }
        };
        if meta.is_file() && len > 0 && map(0, 1).is_ok() {
            windows::<true, _>(path, len, piece_for(len), p, |at, n| map(at, n).map_err(cannot))
        } else {
            // Empty, or not mappable (a pipe): read it.
            parse_reader(path, Counting::new(&file, p), piece_for(len))
        }
    })
}

/// Pieces for a file of `len` bytes: [`PIECE`], or smaller for a file under a block, so that a
/// small file is still cut into pieces for every core and, read through a buffer, gets a buffer
/// its own size and not a whole block's (zeroed before the read fills it).
fn piece_for(len: u64) -> usize {
    PIECE.min(usize::try_from(len).unwrap_or(usize::MAX) / PIECES_PER_BLOCK + 4096)
}

/// Parses OBJ bytes already in memory, reported as [`parse_file`] reports a file.
pub fn parse_bytes(path: &Path, bytes: &[u8], progress: &Reporter) -> Result<ObjData> {
    let piece = piece_for(bytes.len() as u64);
    reported(path, bytes.len() as u64, progress, |p| parse_pieces::<true>(path, bytes, piece, p))
}

/// [`parse_bytes`] with pieces of about `piece` bytes (small in tests, to cut lines everywhere),
/// with or without the common lines' own path (the tests compare the two).
fn parse_pieces<const FAST: bool>(path: &Path, bytes: &[u8], piece: usize, progress: &Reporter) -> Result<ObjData> {
    windows::<FAST, _>(path, bytes.len() as u64, piece, progress, |at, n| Ok(&bytes[at as usize..][..n]))
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

/// Parses `len` bytes seen through `window(at, n)` (bytes `at..at + n`), a block at a time: each
/// window runs to the last line end in it (it grows when one line is longer than a block).
fn windows<const FAST: bool, W: Deref<Target = [u8]>>(
    path: &Path,
    len: u64,
    piece: usize,
    progress: &Reporter,
    mut window: impl FnMut(u64, usize) -> Result<W>,
) -> Result<ObjData> {
    let piece = piece.max(1);
    let mut acc = Acc::new(progress.clone());
    let mut at = 0;
    let mut want = piece * PIECES_PER_BLOCK;
    while at < len {
        let n = usize::try_from(len - at).unwrap_or(usize::MAX).min(want);
        let w = window(at, n)?;
        let last = at + n as u64 == len;
        let Some(cut) = (if last { Some(n) } else { memrchr(b'\n', &w).map(|i| i + 1) }) else {
            want *= 2;
            continue;
        };
        let start = if at == 0 && w.starts_with(b"\xEF\xBB\xBF") { 3 } else { 0 };
        progress.tick(start.min(cut) as u64);
        acc.block::<FAST>(path, &w[start.min(cut)..cut], piece)?;
        at += cut as u64;
        want = piece * PIECES_PER_BLOCK;
    }
    acc.finish(path)
}

/// Parses from `r`, read a block at a time into one buffer, with pieces of about `piece` bytes.
pub fn parse_reader(path: &Path, mut r: impl Read, piece: usize) -> Result<ObjData> {
    let piece = piece.max(1);
    let block = piece * PIECES_PER_BLOCK;
    // `r` reports its own bytes as they are read.
    let mut acc = Acc::new(Reporter::none());
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
        let cut = if eof { filled } else { memrchr(b'\n', data).map_or(start, |i| i + 1) };
        acc.block::<true>(path, &data[start..cut], piece)?;
        buf.copy_within(cut..filled, 0);
        kept = filled - cut;
    }
    acc.finish(path)
}

/// How many `v`, `vt`, `vn` and lines a piece holds (or come before it).
#[derive(Default, Clone, Copy)]
pub(super) struct Counts {
    pub v: u64,
    pub t: u64,
    pub n: u64,
    pub lines: u64,
}

/// A reference past what was defined when its face was read, checked at the end.
pub(super) struct Forward {
    pub attr: u8,
    pub index: u32,
    pub line: u64,
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

pub(super) fn count(b: &[u8]) -> Counts {
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

/// One piece of a block, as parsed; its arrays are cleared and reused for the next block.
#[derive(Default)]
pub(super) struct Piece {
    pub pos: Vec<[f32; 3]>,
    pub nrm: Vec<[f32; 3]>,
    pub uv: Vec<[f32; 2]>,
    pub tv: Vec<[u32; 3]>,
    pub tt: Vec<[u32; 3]>,
    pub tn: Vec<[u32; 3]>,
    /// With the number of the piece's triangles before each.
    pub statements: Vec<(u32, Statement)>,
    pub mtllibs: Vec<String>,
    /// With the piece's own line numbers (its first line is 1).
    pub forward: Vec<Forward>,
    pub any_t: bool,
    pub any_n: bool,
    /// The largest `v`, `vt` and `vn` index the faces name, plus one (0 for none).
    pub max: [u32; 3],
    /// The piece's `v`/`vt`/`vn` and lines.
    pub counts: Counts,
    /// Parsed without its base, it stopped at a relative index: it must be parsed again.
    pub needs_base: bool,
    /// The first error, at the piece's own line number.
    pub error: Option<(u64, String)>,
}

/// Why a line stops the piece.
enum Stop {
    /// A relative index, in a piece parsed without its base.
    NeedsBase,
    Error(String),
}

impl From<String> for Stop {
    fn from(s: String) -> Stop {
        Stop::Error(s)
    }
}

impl From<&str> for Stop {
    fn from(s: &str) -> Stop {
        Stop::Error(s.to_string())
    }
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
    ///
    /// `base` is how many `v`, `vt` and `vn` come before the piece. Without it (`None`), indices
    /// are not checked against what is defined so far, and a relative index stops the parse with
    /// `needs_base` set.
    pub(super) fn parse<const FAST: bool>(&mut self, b: &[u8], base: Option<[u64; 3]>) {
        self.clear();
        let mut i = 0;
        let mut line = 0;
        let mut corners: Vec<Corner> = Vec::new();
        let mut pending: Vec<Forward> = Vec::new();
        // Without a base, every index a face names counts as defined already.
        let limit = |p: &Piece| match base {
            Some(b) => [b[0] + p.pos.len() as u64, b[1] + p.uv.len() as u64, b[2] + p.nrm.len() as u64],
            None => [MISSING as u64; 3],
        };
        while i < b.len() {
            line += 1;
            if FAST {
                if let Some(next) = self.fast_line(b, i, limit(self), &mut corners) {
                    i = next;
                    continue;
                }
            }
            let end = line_end(b, i);
            let (kind, after) = keyword(b, i);
            let mut l = Line { b: &b[..end], i: after };
            let r: std::result::Result<(), Stop> = match kind {
                Kind::V => self.vertex(&mut l).map_err(Stop::from),
                Kind::Vt => (|| {
                    self.uv.push([l.float("vt")?, l.float("vt")?]);
                    Ok(())
                })(),
                Kind::Vn => (|| {
                    self.nrm.push([l.float("vn")?, l.float("vn")?, l.float("vn")?]);
                    Ok(())
                })(),
                Kind::F => {
                    let now = base.map(|_| limit(self));
                    self.face(&mut l, now, line, &mut corners, &mut pending)
                }
                Kind::Name => {
                    let name = l.rest();
                    let name = if name.is_empty() { "unnamed_object".to_string() } else { name };
                    self.statements.push((self.tv.len() as u32, Statement::Name(name)));
                    Ok(())
                }
                Kind::Usemtl => {
                    let name = l.rest();
                    if name.is_empty() {
                        Err("usemtl names no material".into())
                    } else {
                        self.statements.push((self.tv.len() as u32, Statement::Material(name)));
                        Ok(())
                    }
                }
                Kind::Mtllib => {
                    self.mtllibs.push(l.rest());
                    Ok(())
                }
                Kind::Other => Ok(()),
            };
            match r {
                Ok(()) => i = end + 1,
                Err(Stop::NeedsBase) => {
                    self.needs_base = true;
                    return;
                }
                Err(Stop::Error(m)) => {
                    self.error = Some((line, m));
                    return;
                }
            }
        }
        self.counts =
            Counts { v: self.pos.len() as u64, t: self.uv.len() as u64, n: self.nrm.len() as u64, lines: line };
    }

    fn clear(&mut self) {
        for v in [&mut self.pos, &mut self.nrm] {
            v.clear();
        }
        self.uv.clear();
        for v in [&mut self.tv, &mut self.tt, &mut self.tn] {
            v.clear();
        }
        self.statements.clear();
        self.mtllibs.clear();
        self.forward.clear();
        (self.any_t, self.any_n, self.max, self.counts) = (false, false, [0; 3], Counts::default());
        (self.needs_base, self.error) = (false, None);
    }

    /// The line at `i` if it is a common one, parsed; where the next line starts. `None` (nothing
    /// kept) for any other line, which the general path then reads.
    #[inline]
    fn fast_line(&mut self, b: &[u8], i: usize, limit: [u64; 3], corners: &mut Vec<Corner>) -> Option<usize> {
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
        let next = fast_corners(b, i + 2, limit, corners)?;
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

    /// A face line; `now` is how many of each kind are defined so far, `None` when the piece's
    /// base is not known.
    fn face(
        &mut self,
        l: &mut Line,
        now: Option<[u64; 3]>,
        line: u64,
        corners: &mut Vec<Corner>,
        pending: &mut Vec<Forward>,
    ) -> std::result::Result<(), Stop> {
        corners.clear();
        pending.clear();
        while let Some(t) = l.token() {
            let mut c = [MISSING; 3];
            for (k, part) in t.split(|&ch| ch == b'/').enumerate() {
                if part.is_empty() && k > 0 {
                    continue;
                }
                if k > 2 {
                    return Err(format!("face corner '{}' has more than v/vt/vn", String::from_utf8_lossy(t)).into());
                }
                let x = short_int(part).ok_or_else(|| {
                    format!("face corner '{}' is not v, v/vt, v//vn or v/vt/vn", String::from_utf8_lossy(t))
                })?;
                let what = ["vertex", "texture coordinate", "normal"][k];
                let idx = if x > 0 {
                    x - 1
                } else if x < 0 {
                    let Some(now) = now else { return Err(Stop::NeedsBase) };
                    let r = now[k] as i64 + x;
                    if r < 0 {
                        return Err(format!(
                            "relative {what} index {x} reaches before the first (only {} defined)",
                            now[k]
                        )
                        .into());
                    }
                    r
                } else {
                    return Err(format!("{what} index 0 (OBJ indices start at 1)").into());
                };
                if idx >= MISSING as i64 {
                    return Err(format!("{what} index {x} is too large").into());
                }
                if now.is_some_and(|now| idx as u64 >= now[k]) {
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
        // The face's largest index of each kind, plus one: 0 when no corner names that kind.
        let mut top = [0u32; 3];
        for c in corners {
            for (m, x) in top.iter_mut().zip(c) {
                *m = (*m).max(x.wrapping_add(1));
            }
        }
        for (m, x) in self.max.iter_mut().zip(top) {
            *m = (*m).max(x);
        }
        let (has_t, has_n) = (top[1] > 0, top[2] > 0);
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
