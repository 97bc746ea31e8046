//! Timing of pipeline stages (each command's report carries its `Timings`), and memory marks.

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

/// With `BUMPBAKE_MEMTRACE` set, prints the process's resident and peak memory after `stage` to
/// stderr (Linux only): how the memory figures in `docs/tangents-bench.md` were found.
pub fn mem_mark(stage: &str) {
    if std::env::var_os("BUMPBAKE_MEMTRACE").is_none() {
        return;
    }
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let field = |k: &str| {
        status.lines().find(|l| l.starts_with(k)).map(|l| l[k.len()..].trim().to_string()).unwrap_or_default()
    };
    eprintln!("memtrace {stage}: rss {} peak {}", field("VmRSS:"), field("VmHWM:"));
}
