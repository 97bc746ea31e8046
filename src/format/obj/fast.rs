//! The numbers of an OBJ file and the path of its common lines: `v`/`vn`/`vt` with plain
//! numbers and faces of positive indices, read straight from the bytes with no token scanned
//! twice. Whatever else such a line holds sends it back to the general path in `piece.rs`.

use crate::format::mesh::text_number::{digits8, lead_f32};
use crate::format::mesh::MISSING;

/// A face corner's `v`, `vt` and `vn` indices, 0-based ([`MISSING`] where it names none).
pub(super) type Corner = [u32; 3];

/// `N` numbers from `i` on, each after one or more blanks, then the line's end (blanks and a
/// `\r` allowed before it); the numbers and where the next line starts. `None` for anything else
/// (a comment, a fourth number, text), which the general path reads.
#[inline(always)]
pub(super) fn fast_floats<const N: usize>(b: &[u8], mut i: usize) -> Option<([f32; N], usize)> {
    let mut v = [0f32; N];
    for x in v.iter_mut() {
        while *b.get(i)? == b' ' {
            i += 1;
        }
        let (f, used) = lead_f32(&b[i..])?;
        *x = f;
        i += used;
    }
    Some((v, end_of_line(b, i)?))
}

/// Where the next line starts if only blanks (and a `\r`) are left on this one.
#[inline]
fn end_of_line(b: &[u8], mut i: usize) -> Option<usize> {
    while i < b.len() && matches!(b[i], b' ' | b'\r') {
        i += 1;
    }
    match b.get(i) {
        None => Some(i),
        Some(b'\n') => Some(i + 1),
        _ => None,
    }
}

/// A positive decimal index at `i` (no sign), as 0-based, if below `limit` (already defined);
/// and where it ends.
#[inline]
fn fast_index(b: &[u8], mut i: usize, limit: u64) -> Option<(u32, usize)> {
    let s = i;
    let mut x: u64 = 0;
    if let Some((n, v)) = digits8(b, i) {
        if n < 8 {
            return (v >= 1 && v <= limit).then(|| ((v - 1) as u32, i + n));
        }
    }
    while i < b.len() && b[i].is_ascii_digit() && i - s < 10 {
        x = x * 10 + (b[i] - b'0') as u64;
        i += 1;
    }
    (x >= 1 && x <= limit && i > s).then(|| ((x - 1) as u32, i))
}

/// A face's corners from `i` on when every one is `v`, `v/vt`, `v//vn` or `v/vt/vn` with positive
/// indices to what is already defined, followed by the line's end; where the next line starts.
#[inline(always)]
pub(super) fn fast_corners(b: &[u8], mut i: usize, now: [u64; 3], corners: &mut Vec<Corner>) -> Option<usize> {
    corners.clear();
    loop {
        while *b.get(i)? == b' ' {
            i += 1;
        }
        if matches!(b[i], b'\r' | b'\n') {
            break;
        }
        let mut c = [MISSING; 3];
        (c[0], i) = fast_index(b, i, now[0])?;
        if b.get(i) == Some(&b'/') {
            i += 1;
            if b.get(i) != Some(&b'/') {
                (c[1], i) = fast_index(b, i, now[1])?;
            }
            if b.get(i) == Some(&b'/') {
                (c[2], i) = fast_index(b, i + 1, now[2])?;
            }
        }
        if !matches!(b.get(i), Some(b' ' | b'\r' | b'\n') | None) {
            return None;
        }
        corners.push(c);
        if i >= b.len() {
            break;
        }
    }
    if corners.len() < 3 {
        return None;
    }
    end_of_line(b, i)
}
