//! The library's progress as calls of a Python callable:
//! `progress(stage: str, done: int, total: int, unit: str)`, at most ten times a second per
//! stage plus once when a stage ends. The first exception the callable raises is kept and raised
//! when the work returns; later calls are skipped.

use bumpbake::progress::{Progress, Reporter};
use pyo3::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

const EVERY: Duration = Duration::from_millis(100);

struct Stage {
    name: String,
    unit: String,
    total: u64,
    last: Option<Instant>,
}

pub struct Callback {
    callable: Py<PyAny>,
    done: AtomicU64,
    stage: Mutex<Stage>,
    failed: Mutex<Option<PyErr>>,
}

impl Callback {
    /// A reporter for `callable`, or none for `None`; keep the `Arc` to take its error.
    pub fn reporter(callable: Option<Py<PyAny>>) -> (Reporter, Option<Arc<Callback>>) {
        let Some(callable) = callable else { return (Reporter::none(), None) };
        let cb = Arc::new(Callback {
            callable,
            done: AtomicU64::new(0),
            stage: Mutex::new(Stage { name: String::new(), unit: String::new(), total: 0, last: None }),
            failed: Mutex::new(None),
        });
        (Reporter::new(Shared(cb.clone())), Some(cb))
    }

    /// The callable's first exception, if it raised one.
    pub fn take_error(&self) -> Option<PyErr> {
        self.failed.lock().unwrap_or_else(|e| e.into_inner()).take()
    }

    fn call(&self, force: bool) {
        // A tick finds the stage busy while another thread reports it: that one call suffices.
        let mut s = match self.stage.try_lock() {
            Ok(s) => s,
            Err(_) if !force => return,
            Err(_) => self.stage.lock().unwrap_or_else(|e| e.into_inner()),
        };
        let now = Instant::now();
        if !force && s.last.is_some_and(|t| now - t < EVERY) {
            return;
        }
        s.last = Some(now);
        let done = self.done.load(Ordering::Relaxed).min(s.total);
        let mut failed = self.failed.lock().unwrap_or_else(|e| e.into_inner());
        if failed.is_some() {
            return;
        }
        Python::attach(|py| {
            if let Err(e) = self.callable.call1(py, (s.name.as_str(), done, s.total, s.unit.as_str())) {
                *failed = Some(e);
            }
        });
    }
}

/// The [`Progress`] the library holds.
struct Shared(Arc<Callback>);

impl Progress for Shared {
    fn start(&self, stage: &str, total: u64, unit: &str) {
        {
            let mut s = self.0.stage.lock().unwrap_or_else(|e| e.into_inner());
            *s = Stage { name: stage.to_string(), unit: unit.to_string(), total, last: None };
            self.0.done.store(0, Ordering::Relaxed);
        }
        self.0.call(true);
    }

    fn tick(&self, n: u64) {
        self.0.done.fetch_add(n, Ordering::Relaxed);
        self.0.call(false);
    }

    fn finish(&self) {
        let total = self.0.stage.lock().unwrap_or_else(|e| e.into_inner()).total;
        self.0.done.store(total, Ordering::Relaxed);
        self.0.call(true);
    }
}
