//! Wavefront OBJ geometry, parsed on every core at memory speed.
//!
//! A file is read through a memory map, a window of a block (64 MB) at a time, so its text is
//! never copied and only one window of it is mapped at once, while a thread asks the disk for the
//! pages of the next (`pages::with_read_ahead`); other readers (a pipe) and bytes in memory go
//! through the same blocks. Each block is parsed in parallel pieces (`piece.rs`) and
//! appended in file order (`block.rs`), so the result never depends on the thread count or the
//! piece size. Errors name the file's own line numbers.
//!
//! Values are kept as the file stores them (UV v up, a [`StoredMesh`]); `obj/mod.rs` (a Scene)
//! and `raw.rs` (HIGH's mesh) convert. Polygons are fanned from their first corner, as `tobj` did.

use super::block::Acc;
use super::continuation::last_line_end;
use crate::error::{Error, Result};
use crate::format::mesh::StoredMesh;
use crate::progress::{Counting, Reporter};
use std::io::Read;
use std::ops::Deref;
use std::path::Path;

/// Pieces are cut at about this many bytes; blocks of this many pieces are parsed at a time.
const PIECE: usize = 1 << 20;
const PIECES_PER_BLOCK: usize = 64;

/// Reads and parses the OBJ file at `path`, a block at a time, reporting the bytes read as the
/// progress stage `read NAME`.
pub fn parse_file(path: &Path, progress: &Reporter) -> Result<StoredMesh> {
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
            crate::pages::with_read_ahead(&file, len, |reached| {
                windows::<true, _>(path, len, piece_for(len), p, |at, n| {
                    reached(at);
                    map(at, n).map_err(cannot)
                })
            })
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
pub fn parse_bytes(path: &Path, bytes: &[u8], progress: &Reporter) -> Result<StoredMesh> {
    let piece = piece_for(bytes.len() as u64);
    reported(path, bytes.len() as u64, progress, |p| parse_pieces::<true>(path, bytes, piece, p))
}

/// [`parse_bytes`] with pieces of about `piece` bytes (small in tests, to cut lines everywhere),
/// with or without the common lines' own path (the tests compare the two).
fn parse_pieces<const FAST: bool>(path: &Path, bytes: &[u8], piece: usize, progress: &Reporter) -> Result<StoredMesh> {
    windows::<FAST, _>(path, bytes.len() as u64, piece, progress, |at, n| Ok(&bytes[at as usize..][..n]))
}

fn reported(
    path: &Path,
    len: u64,
    progress: &Reporter,
    read: impl FnOnce(&Reporter) -> Result<StoredMesh>,
) -> Result<StoredMesh> {
    let name = path.file_name().map(|n| n.to_string_lossy()).unwrap_or_default();
    progress.start(&format!("read {name}"), len, "bytes");
    let out = read(progress);
    progress.finish();
    out
}

/// Parses `len` bytes seen through `window(at, n)` (bytes `at..at + n`), a block at a time: each
/// window runs to the last line end in it that is not continued (it grows when one line is
/// longer than a block).
fn windows<const FAST: bool, W: Deref<Target = [u8]> + Send + Sync>(
    path: &Path,
    len: u64,
    piece: usize,
    progress: &Reporter,
    mut window: impl FnMut(u64, usize) -> Result<W>,
) -> Result<StoredMesh> {
    let piece = piece.max(1);
    let mut acc = Acc::new(progress.clone());
    let mut at = 0;
    let mut want = piece * PIECES_PER_BLOCK;
    let mut last_window = None;
    while at < len {
        let n = usize::try_from(len - at).unwrap_or(usize::MAX).min(want);
        let w = window(at, n)?;
        let last = at + n as u64 == len;
        let Some(cut) = (if last { Some(n) } else { last_line_end(&w) }) else {
            want *= 2;
            continue;
        };
        let start = if at == 0 && w.starts_with(b"\xEF\xBB\xBF") { 3 } else { 0 };
        progress.tick(start.min(cut) as u64);
        // The last block's window is unmapped on one core while this one's parse starts on the
        // other: unmapping 64 MB of a file's pages takes milliseconds, with both cores waiting.
        let old = last_window.take();
        let text = &w[start.min(cut)..cut];
        rayon::join(move || drop(old), || acc.block::<FAST>(path, text, piece)).1?;
        last_window = Some(w);
        at += cut as u64;
        want = piece * PIECES_PER_BLOCK;
    }
    acc.finish(path)
}

/// Parses from `r`, read a block at a time into one buffer, with pieces of about `piece` bytes.
pub fn parse_reader(path: &Path, mut r: impl Read, piece: usize) -> Result<StoredMesh> {
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
        let cut = if eof { filled } else { last_line_end(data).unwrap_or(start) };
        acc.block::<true>(path, &data[start..cut], piece)?;
        buf.copy_within(cut..filled, 0);
        kept = filled - cut;
    }
    acc.finish(path)
}

#[cfg(test)]
#[path = "parse_tests.rs"]
mod tests;
