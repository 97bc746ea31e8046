//! Writing outputs safely: every file goes to a temporary name in the target directory and is
//! renamed into place only when complete, so a failed run never leaves a partial file and never
//! touches its input (even when the output path is the input path).

use crate::error::{Error, Result};
use std::borrow::Cow;
use std::io::Write;
use std::path::{Path, PathBuf};

/// A set of files that appear together or not at all (a `.gltf` and its `.bin`, say).
/// Parts may borrow what they write (a scene's buffers), so the bytes need not exist twice.
#[derive(Default)]
pub struct Outputs<'a> {
    /// Each file as parts written one after the other (a GLB's header and JSON, then its
    /// binary chunk, need not be copied into one buffer).
    files: Vec<(PathBuf, Vec<Cow<'a, [u8]>>)>,
}

impl<'a> Outputs<'a> {
    pub fn new() -> Self {
        Self::default()
    }
    /// Queues `bytes` to be written at `path`.
    pub fn add(&mut self, path: impl Into<PathBuf>, bytes: Vec<u8>) {
        self.files.push((path.into(), vec![Cow::Owned(bytes)]));
    }
    /// Queues a file made of `parts`, in order.
    pub fn add_parts(&mut self, path: impl Into<PathBuf>, parts: Vec<Cow<'a, [u8]>>) {
        self.files.push((path.into(), parts));
    }
    /// The same files, owning their bytes (for when what they borrow from goes away).
    pub fn into_owned(self) -> Outputs<'static> {
        let files = self
            .files
            .into_iter()
            .map(|(p, parts)| (p, parts.into_iter().map(|b| Cow::Owned(b.into_owned())).collect()))
            .collect();
        Outputs { files }
    }
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.files.iter().map(|(p, _)| p.as_path())
    }
    /// Writes every queued file to a temporary sibling, then renames them all into place.
    /// If any write fails, every temporary is removed and nothing is renamed.
    pub fn commit(self) -> Result<()> {
        // Renames are the one step that cannot be undone once a later one fails, so everything
        // that would make one fail is checked before the first temporary is written.
        for (path, _) in &self.files {
            if path.is_dir() {
                return Err(Error::output(path, "a directory is in the way"));
            }
        }
        let mut temps: Vec<(PathBuf, PathBuf)> = Vec::new();
        for (path, parts) in &self.files {
            match write_temp(path, parts) {
                Ok(tmp) => temps.push((tmp, path.clone())),
                Err(e) => {
                    for (tmp, _) in &temps {
                        let _ = std::fs::remove_file(tmp);
                    }
                    return Err(e);
                }
            }
        }
        for (i, (tmp, path)) in temps.iter().enumerate() {
            if let Err(e) = std::fs::rename(tmp, path) {
                for (t, _) in &temps[i..] {
                    let _ = std::fs::remove_file(t);
                }
                return Err(Error::output(path, e));
            }
        }
        Ok(())
    }
}

/// Writes one file atomically.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = write_temp(path, &[bytes])?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Error::output(path, e)
    })
}

fn write_temp(path: &Path, parts: &[impl AsRef<[u8]>]) -> Result<PathBuf> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = path.file_name().ok_or_else(|| Error::output(path, "not a file name"))?;
    let tmp = dir.join(format!(".{}.{}.tmp", name.to_string_lossy(), std::process::id()));
    let result = (|| {
        // Buffered: a GLB's binary chunk can be thousands of small parts (views and padding).
        let mut f = std::io::BufWriter::with_capacity(1 << 16, std::fs::File::create(&tmp)?);
        for bytes in parts {
            f.write_all(bytes.as_ref())?;
        }
        f.into_inner().map_err(|e| e.into_error())?.sync_all()
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::output(path, e));
    }
    Ok(tmp)
}

/// A Make/Ninja depfile: `target: dep dep ...`, spaces in paths escaped.
pub fn depfile(targets: &[&Path], deps: &[PathBuf]) -> Vec<u8> {
    let esc =
        |p: &Path| p.to_string_lossy().replace('\\', "/").replace(' ', "\\ ").replace('#', "\\#").replace('$', "$$");
    let t: Vec<String> = targets.iter().map(|p| esc(p)).collect();
    let d: Vec<String> = deps.iter().map(|p| esc(p)).collect();
    format!("{}: {}\n", t.join(" "), d.join(" \\\n  ")).into_bytes()
}
