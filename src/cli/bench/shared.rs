//! What every `bench` subcommand shares: a scratch folder and the JSON-or-text printout.

use bumpbake::{Error, Result};
use std::path::Path;

/// Runs `f(bumpbake's own executable, a scratch folder)` for benchmark `what`, then removes the
/// folder.
pub(super) fn with_scratch<T>(what: &str, f: impl FnOnce(&Path, &Path) -> Result<T>) -> Result<T> {
    let exe =
        std::env::current_exe().map_err(|e| Error::usage(format!("bench {what}: cannot find bumpbake itself: {e}")))?;
    let dir = std::env::temp_dir().join(format!("bumpbake-bench-{what}-{}", std::process::id()));
    let r = f(&exe, &dir);
    let _ = std::fs::remove_dir_all(&dir);
    r
}

/// Prints `r` as JSON, or as `text(r)`.
pub(super) fn print<T: serde::Serialize>(r: &T, json: bool, text: impl FnOnce(&T) -> String) -> Result<()> {
    if json {
        outln!("{}", serde_json::to_string_pretty(r).expect("serialises"));
    } else {
        outln!("{}", text(r));
    }
    Ok(())
}

/// FNV-1a 64 of `bytes` as hex: tells two runs' outputs apart in a report (not a checksum).
pub(super) fn fingerprint(bytes: &[u8]) -> String {
    let h = bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ b as u64).wrapping_mul(0x100_0000_01b3));
    format!("{h:016x}")
}

/// CPU seconds so far (user + system, every thread) of this process and of its children that
/// have been waited for, from `/proc/self/stat` (`None` where there is none). Linux counts them
/// in ticks of 1/100 s (`USER_HZ`, fixed by its ABI). Wall time on a shared machine carries the
/// neighbours' load; CPU time is the work itself.
pub(super) fn cpu_seconds() -> Option<(f64, f64)> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // The fields after the command name, which is in parentheses and may hold spaces.
    let rest = stat.get(stat.rfind(')')? + 2..)?;
    let f: Vec<f64> = rest.split(' ').skip(11).take(4).map(|x| x.parse().ok()).collect::<Option<_>>()?;
    (f.len() == 4).then(|| ((f[0] + f[1]) / 100.0, (f[2] + f[3]) / 100.0))
}

/// The smallest and largest of `v` ((inf, 0) when empty: times are never negative).
pub(super) fn spread(v: &[f64]) -> (f64, f64) {
    (v.iter().copied().fold(f64::INFINITY, f64::min), v.iter().copied().fold(0.0, f64::max))
}

/// The median of `v` (sorted in place), the mean of the middle two for an even count; 0 when empty.
pub(super) fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        0.0
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

#[cfg(test)]
mod tests {
    /// Busy work on this thread shows in this process's CPU time and not in its children's. The
    /// work runs until its CPU time shows, not for a fixed wall time: on a loaded machine 300 ms of
    /// wall time held 0.15 s of CPU. Only a clock that never moves fails (after 60 s).
    #[test]
    #[cfg(target_os = "linux")]
    fn cpu_seconds_count_this_process() {
        let (a, ca) = super::cpu_seconds().expect("/proc/self/stat");
        let t = std::time::Instant::now();
        let mut x = 0u64;
        let mut b = a;
        while b - a < 0.2 && t.elapsed().as_secs() < 60 {
            for _ in 0..1_000_000 {
                x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
            }
            b = super::cpu_seconds().expect("/proc/self/stat").0;
        }
        let (b, cb) = super::cpu_seconds().expect("/proc/self/stat");
        assert!(b - a >= 0.2, "{a} -> {b} in {:?}", t.elapsed());
        assert_eq!(ca, cb);
    }
}
