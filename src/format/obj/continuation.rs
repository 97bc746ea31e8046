//! OBJ's line continuation: a `\` ending a line (only whitespace after it) joins the next line
//! to it, on any line, as Blender's importer reads it (the backslash and the line end become
//! spaces there). The parser never sees one: blocks and pieces are cut only at line ends that
//! are not continued ([`last_line_end`], [`next_line_end`]), and a piece holding one is read
//! through [`join`], which keeps every later line's number.

use memchr::{memchr, memchr_iter, memrchr};
use std::borrow::Cow;

/// Where the line end that continues the line through the `\` at `at` is: only whitespace (a
/// byte up to a space, `\r` and tabs included) between them, as Blender's importer takes it.
fn continued_to(bytes: &[u8], at: usize) -> Option<usize> {
    let rest = bytes.get(at + 1..)?;
    let n = rest.iter().position(|&c| c == b'\n' || c > b' ')?;
    (rest[n] == b'\n').then_some(at + 1 + n)
}

/// Whether the line end at `nl` continues its line.
pub(super) fn continues(bytes: &[u8], nl: usize) -> bool {
    let before = &bytes[..nl];
    match before.iter().rposition(|&c| c == b'\n' || c > b' ') {
        Some(k) => before[k] == b'\\',
        None => false,
    }
}

/// The end (just past its `\n`) of the last line of `bytes` that is not continued.
pub(super) fn last_line_end(bytes: &[u8]) -> Option<usize> {
    let mut end = bytes.len();
    while let Some(nl) = memrchr(b'\n', &bytes[..end]) {
        if !continues(bytes, nl) {
            return Some(nl + 1);
        }
        end = nl;
    }
    None
}

/// The end (just past its `\n`) of the first line end at or after `from` that is not continued.
pub(super) fn next_line_end(bytes: &[u8], from: usize) -> Option<usize> {
    let mut at = from;
    while let Some(k) = memchr(b'\n', bytes.get(at..)?) {
        let nl = at + k;
        if !continues(bytes, nl) {
            return Some(nl + 1);
        }
        at = nl + 1;
    }
    None
}

/// `bytes` with each continuation joined: the `\`, the whitespace after it and its line end
/// become spaces, and the line ends taken out follow the joined line's own, so the text keeps
/// its length and every line after it its number (an error in a joined line names its first).
/// Borrowed when there is nothing to join.
pub(super) fn join(bytes: &[u8]) -> Cow<'_, [u8]> {
    if !memchr_iter(b'\\', bytes).any(|at| continued_to(bytes, at).is_some()) {
        return Cow::Borrowed(bytes);
    }
    let mut out = Vec::with_capacity(bytes.len());
    let (mut i, mut owed) = (0, 0);
    while i < bytes.len() {
        let c = bytes[i];
        if c == b'\\' {
            if let Some(nl) = continued_to(bytes, i) {
                out.resize(out.len() + (nl - i), b' ');
                owed += 1;
                i = nl + 1;
                continue;
            }
        }
        out.push(c);
        if c == b'\n' {
            out.resize(out.len() + owed, b'\n');
            owed = 0;
        }
        i += 1;
    }
    out.resize(out.len() + owed, b'\n');
    Cow::Owned(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joins_as_blender_reads_and_keeps_the_line_numbers() {
        let s = b"f 1 2 \\\n 3\nv 1 \\  \t\r\n2 3\nwithout eol \\ is \\\\ left\n\\";
        let j = join(s);
        assert_eq!(j.len(), s.len());
        assert_eq!(&j[..], &b"f 1 2   3\n\nv 1      2 3\n\nwithout eol \\ is \\\\ left\n\\"[..]);
        assert!(matches!(join(b"v 1 2 3\nmtllib C:\\a\\b.mtl\n"), Cow::Borrowed(_)));
    }

    #[test]
    fn cuts_only_where_a_line_ends() {
        let s = b"a \\\nb\nc\\\n";
        assert_eq!(last_line_end(s), Some(6));
        assert_eq!(last_line_end(b"a\\\n"), None);
        assert_eq!(next_line_end(s, 0), Some(6));
        assert_eq!(next_line_end(s, 6), None);
        assert_eq!(next_line_end(b"\n\\\n\n", 1), Some(4));
    }
}
