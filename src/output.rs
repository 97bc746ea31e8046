//! Writing outputs safely: every file goes to a temporary name in the target directory and is
//! renamed into place only when complete, so a failed run never leaves a partial file and never
//! touches its input (even when the output path is the input path).
//!
//! Temporaries are named `.NAME.PID.tmp`. A run that is interrupted (SIGINT, SIGTERM) removes its
//! own through [`abandon_temporaries`], which the binary calls from its signal thread; one that
//! is killed outright cannot, so writing `NAME` first removes the `.NAME.PID.tmp` of processes
//! that no longer exist.

use crate::error::{Error, Result};
use std::borrow::Cow;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The temporaries this process has created and not yet renamed, and whether it is exiting.
/// Creating a temporary happens under this lock, so none can appear after the cleanup ran.
static TEMPS: Mutex<(Vec<PathBuf>, bool)> = Mutex::new((Vec::new(), false));

fn temps() -> std::sync::MutexGuard<'static, (Vec<PathBuf>, bool)> {
    TEMPS.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes every temporary this process is writing and keeps any new one from being created;
/// the caller then exits. For the binary's signal handling.
pub fn abandon_temporaries() {
    let mut t = temps();
    t.1 = true;
    for p in t.0.drain(..) {
        let _ = std::fs::remove_file(p);
    }
    // The lock stays held: a writer thread must not create a file between this and the exit.
    std::mem::forget(t);
}

fn forget_temp(tmp: &Path) {
    temps().0.retain(|p| p != tmp);
}

/// Removes `.NAME.PID.tmp` files beside `path` whose process is gone (killed while writing).
fn sweep_stale(dir: &Path, name: &str) {
    let prefix = format!(".{name}.");
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let file = e.file_name();
        let Some(pid) = file
            .to_str()
            .and_then(|f| f.strip_prefix(&prefix))
            .and_then(|rest| rest.strip_suffix(".tmp"))
            .and_then(|pid| pid.parse::<u32>().ok())
        else {
            continue;
        };
        if pid != std::process::id() && !process_exists(pid) {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

#[cfg(unix)]
fn process_exists(pid: u32) -> bool {
    let Ok(pid) = libc::pid_t::try_from(pid) else { return true };
    // SAFETY: signal 0 only asks whether the process exists; nothing is sent.
    let r = unsafe { libc::kill(pid, 0) };
    r == 0 || std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
}

/// Without a cheap way to ask, every process is taken to exist: nothing is swept.
#[cfg(not(unix))]
fn process_exists(_pid: u32) -> bool {
    true
}

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
                        forget_temp(tmp);
                    }
                    return Err(e);
                }
            }
        }
        for (i, (tmp, path)) in temps.iter().enumerate() {
            let renamed = std::fs::rename(tmp, path);
            forget_temp(tmp);
            if let Err(e) = renamed {
                for (t, _) in &temps[i..] {
                    let _ = std::fs::remove_file(t);
                    forget_temp(t);
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
    let renamed = std::fs::rename(&tmp, path);
    forget_temp(&tmp);
    renamed.map_err(|e| {
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
    let name = name.to_string_lossy();
    sweep_stale(&dir, &name);
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    let file = {
        let mut t = temps();
        if t.1 {
            return Err(Error::output(path, "interrupted"));
        }
        let f = std::fs::File::create(&tmp).map_err(|e| Error::output(path, e))?;
        t.0.push(tmp.clone());
        f
    };
    let result = (|| {
        // Buffered: a GLB's binary chunk can be thousands of small parts (views and padding).
        let mut f = std::io::BufWriter::with_capacity(1 << 16, file);
        for bytes in parts {
            f.write_all(bytes.as_ref())?;
        }
        f.into_inner().map_err(|e| e.into_error())?.sync_all()
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        forget_temp(&tmp);
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
