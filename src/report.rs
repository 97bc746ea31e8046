//! Timing of pipeline stages, shared by every command's report.

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
