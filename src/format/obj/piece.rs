//! One piece of an OBJ block (about a megabyte of whole lines), parsed into arrays of its own:
//! the line reader, with the common lines' own path (`fast.rs`) tried first.

use super::continuation::continues;
use super::fast::{fast_corners, fast_floats, Corner};
use crate::format::mesh::text_number::{is_space, parse_f32, short_int};
use crate::format::mesh::{Statement, MISSING};
use memchr::memchr;

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
    Smooth,
    Other,
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
        b"s" => Kind::Smooth,
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
    /// It stopped at a line continued by a `\` (`continuation.rs`): it must be parsed again,
    /// joined.
    pub continued: bool,
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
        self.optional_float(what)?.ok_or_else(|| format!("{what} has too few numbers"))
    }

    /// The next number if the line has one more token, `None` at its end.
    fn optional_float(&mut self, what: &str) -> std::result::Result<Option<f32>, String> {
        match self.token() {
            None => Ok(None),
            Some(t) => parse_f32(t)
                .map(Some)
                .ok_or_else(|| format!("{what}: '{}' is not a number", String::from_utf8_lossy(t))),
        }
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
        #[cfg(target_arch = "x86_64")]
        if crate::format::mesh::decimal16::available() {
            // SAFETY: the CPU has SSE4.1, just checked.
            return unsafe { self.parse_sse41::<FAST>(b, base) };
        }
        self.parse_lines::<FAST>(b, base);
    }

    /// [`Piece::parse`] compiled with SSE4.1, so that the vector number reader is inlined into
    /// the line reader and its results stay in registers.
    ///
    /// # Safety
    /// The CPU must have SSE4.1.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "sse4.1")]
    unsafe fn parse_sse41<const FAST: bool>(&mut self, b: &[u8], base: Option<[u64; 3]>) {
        self.parse_lines::<FAST>(b, base);
    }

    #[inline(always)]
    fn parse_lines<const FAST: bool>(&mut self, b: &[u8], base: Option<[u64; 3]>) {
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
            // Only here, before the line is read: a continued line never takes the common
            // path, whose lines end in a number or an index.
            if end < b.len() && continues(b, end) {
                self.continued = true;
                return;
            }
            let (kind, after) = keyword(b, i);
            let mut l = Line { b: &b[..end], i: after };
            let r: std::result::Result<(), Stop> = match kind {
                Kind::V => self.vertex(&mut l).map_err(Stop::from),
                Kind::Vt => (|| {
                    // `vt u` alone: the specification's optional v is 0.
                    let u = l.float("vt")?;
                    let v = l.optional_float("vt")?.unwrap_or(0.0);
                    self.uv.push([u, v]);
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
                Kind::Smooth => {
                    // `off`, and anything that is not a group number, is no group, as Blender
                    // reads it.
                    let group = l.token().and_then(|t| std::str::from_utf8(t).ok()?.parse().ok()).unwrap_or(0);
                    self.statements.push((self.tv.len() as u32, Statement::Smooth(group)));
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
        (self.needs_base, self.continued, self.error) = (false, false, None);
    }

    /// The line at `i` if it is a common one, parsed; where the next line starts. `None` (nothing
    /// kept) for any other line, which the general path then reads.
    #[inline(always)]
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
