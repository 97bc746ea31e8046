//! Timing of pipeline stages (each command's report carries its `Timings`), and memory marks.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// Wall-clock time of named stages, in the order they ran.
#[derive(Debug, Default, Clone, serde::Serialize)]
pub struct Timings {
    pub stages: Vec<(String, f64)>,
}

impl Timings {
    /// Runs `f` and records its duration in milliseconds under `name`.
    pub fn time<T>(&mut self, name: &str, f: impl FnOnce() -> T) -> T {
        let t = Instant::now();
        let out = f();
        self.stages.push((name.to_string(), t.elapsed().as_secs_f64() * 1e3));
        out
    }
}

/// Resident and peak memory of the process after a stage, in KiB (Linux: `/proc/self/status`'s
/// `VmRSS` and `VmHWM`; 0 where it cannot be read).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MemoryMark {
    pub stage: String,
    pub rss_kib: u64,
    pub peak_kib: u64,
}

static TRACING: AtomicBool = AtomicBool::new(false);
static MARKS: Mutex<Vec<MemoryMark>> = Mutex::new(Vec::new());

/// From now on, [`mem_mark`] records the process's memory after each stage, for
/// [`memory_marks`]: how the memory figures in `docs/tangents-bench.md` were found. A profiling
/// switch for the whole process, as the stages that mark memory are deep inside the engines.
pub fn trace_memory() {
    TRACING.store(true, Ordering::Relaxed);
}

/// The marks recorded since [`trace_memory`], in the order the stages ran (taken: a second call
/// returns only later ones).
pub fn memory_marks() -> Vec<MemoryMark> {
    std::mem::take(&mut *MARKS.lock().unwrap_or_else(|e| e.into_inner()))
}

/// Records the process's memory after `stage`, once [`trace_memory`] was called; else nothing.
pub fn mem_mark(stage: &str) {
    if !TRACING.load(Ordering::Relaxed) {
        return;
    }
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let kib = |k: &str| {
        let line = status.lines().find(|l| l.starts_with(k));
        line.and_then(|l| l[k.len()..].split_whitespace().next()?.parse().ok()).unwrap_or(0)
    };
    let mark = MemoryMark { stage: stage.to_string(), rss_kib: kib("VmRSS:"), peak_kib: kib("VmHWM:") };
    MARKS.lock().unwrap_or_else(|e| e.into_inner()).push(mark);
}
