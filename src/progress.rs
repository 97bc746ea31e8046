//! Progress of long work, reported through a caller's [`Progress`]. The library never draws:
//! the command line turns these calls into bars (`cli/progress_bars.rs`), on a terminal only.
//!
//! Work comes in stages (`read spot.obj`, `bake --from`, `files`), each with a total in one unit
//! (bytes, rows, files) and ticks as parts of it finish, from any thread.

use std::sync::Arc;

/// Receives the progress of long work. Ticks come from worker threads and must be cheap.
pub trait Progress: Send + Sync {
    /// A stage begins: `total` units of `unit` (`"bytes"`, `"rows"`, `"files"`).
    fn start(&self, stage: &str, total: u64, unit: &str);
    /// `n` more units of the current stage are done.
    fn tick(&self, n: u64);
    /// What the stage is working on now (a file name, say).
    fn message(&self, _msg: &str) {}
    /// The current stage is done.
    fn finish(&self);
}

/// A cloneable handle to a [`Progress`], or to nothing (the default), for option structs.
#[derive(Clone, Default)]
pub struct Reporter(Option<Arc<dyn Progress>>);

impl Reporter {
    pub fn new(p: impl Progress + 'static) -> Reporter {
        Reporter(Some(Arc::new(p)))
    }

    /// Reports nothing.
    pub fn none() -> Reporter {
        Reporter(None)
    }

    pub fn is_none(&self) -> bool {
        self.0.is_none()
    }

    pub fn start(&self, stage: &str, total: u64, unit: &str) {
        if let Some(p) = &self.0 {
            p.start(stage, total, unit);
        }
    }

    pub fn tick(&self, n: u64) {
        if let Some(p) = &self.0 {
            p.tick(n);
        }
    }

    pub fn message(&self, msg: &str) {
        if let Some(p) = &self.0 {
            p.message(msg);
        }
    }

    pub fn finish(&self) {
        if let Some(p) = &self.0 {
            p.finish();
        }
    }
}

impl std::fmt::Debug for Reporter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if self.0.is_some() { "Reporter(..)" } else { "Reporter(none)" })
    }
}

/// A reader that reports every byte read through it as a tick.
pub struct Counting<'a, R> {
    inner: R,
    progress: &'a Reporter,
}

impl<'a, R> Counting<'a, R> {
    pub fn new(inner: R, progress: &'a Reporter) -> Self {
        Counting { inner, progress }
    }
}

impl<R: std::io::Read> std::io::Read for Counting<'_, R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.progress.tick(n as u64);
        Ok(n)
    }
}
