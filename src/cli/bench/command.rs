//! `bumpbake bench command`: the whole `tangents` command on a file, time and peak memory.

use bumpbake::error::{Error, Result};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake bench command scan.glb
  bumpbake bench command scan.glb --runs 9 --json")]
pub struct BenchCommandArgs {
    /// The mesh (OBJ, glTF or GLB) to run `bumpbake tangents` on.
    pub input: PathBuf,
    /// Runs, each a new process; the median time and the largest peak are reported.
    #[arg(long, default_value_t = 7)]
    pub runs: usize,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: BenchCommandArgs) -> Result<u8> {
    let r = super::shared::with_scratch("command", |exe, dir| measure(exe, &a.input, dir, a.runs))?;
    super::shared::print(&r, a.json, |r| {
        format!(
            "tangents {} ({:.1} MB) -> {:.1} MB: median {:.2} s (min {:.2}, max {:.2}, {} runs); peak memory {:.1} MB = {:.2}x the input",
            r.input.display(),
            r.input_bytes as f64 / 1e6,
            r.output_bytes as f64 / 1e6,
            r.median_s,
            r.min_s,
            r.max_s,
            r.runs,
            r.peak_kib as f64 * 1024.0 / 1e6,
            r.peak_over_input
        )
    })?;
    Ok(0)
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct CommandBench {
    pub input: PathBuf,
    pub input_bytes: u64,
    pub output_bytes: u64,
    pub runs: usize,
    pub median_s: f64,
    pub min_s: f64,
    pub max_s: f64,
    /// Largest peak resident set over the runs, KiB (Linux `VmHWM`, read by the child just
    /// before it exits).
    pub peak_kib: u64,
    /// `peak_kib` over the input's size; the target is under 3 on large meshes (a small
    /// file is dominated by the process's own few megabytes).
    pub peak_over_input: f64,
}

/// Runs `exe tangents input -o dir/out.glb` `runs` times.
fn measure(exe: &Path, input: &Path, dir: &Path, runs: usize) -> Result<CommandBench> {
    let input_bytes = std::fs::metadata(input).map_err(|e| Error::input(input, format!("cannot read: {e}")))?.len();
    std::fs::create_dir_all(dir).map_err(|e| Error::output(dir, e))?;
    let out = dir.join("out.glb");
    let (mut times, mut peak_kib) = (Vec::new(), 0);
    for _ in 0..runs.max(1) {
        let t = Instant::now();
        let o = Command::new(exe)
            .arg("tangents")
            .arg(input)
            .arg("-o")
            .arg(&out)
            .arg("-q")
            .env("BUMPBAKE_MEMTRACE", "1")
            .output()
            .map_err(|e| Error::usage(format!("bench command: cannot run bumpbake: {e}")))?;
        times.push(t.elapsed().as_secs_f64());
        let stderr = String::from_utf8_lossy(&o.stderr);
        if !o.status.success() {
            return Err(Error::usage(format!("bench command: tangents failed: {}", stderr.trim())));
        }
        peak_kib = peak_kib
            .max(peak_of(&stderr).ok_or_else(|| Error::usage("bench command: no memory figures (is /proc mounted?)"))?);
    }
    let output_bytes = std::fs::metadata(&out).map(|m| m.len()).unwrap_or(0);
    times.sort_by(f64::total_cmp);
    let n = times.len();
    let median_s = if n % 2 == 1 { times[n / 2] } else { 0.5 * (times[n / 2 - 1] + times[n / 2]) };
    Ok(CommandBench {
        input: input.to_path_buf(),
        input_bytes,
        output_bytes,
        runs: n,
        median_s,
        min_s: times[0],
        max_s: times[n - 1],
        peak_kib,
        peak_over_input: peak_kib as f64 * 1024.0 / input_bytes.max(1) as f64,
    })
}

/// The largest `peak N kB` of the `memtrace` lines.
pub(crate) fn peak_of(stderr: &str) -> Option<u64> {
    stderr
        .lines()
        .filter(|l| l.starts_with("memtrace "))
        .filter_map(|l| l.split(" peak ").nth(1)?.split_whitespace().next()?.parse().ok())
        .max()
}

#[cfg(test)]
mod tests {
    #[test]
    fn reads_the_largest_peak() {
        let s = "memtrace read: rss 10 kB peak 12 kB\nother\nmemtrace write: rss 9 kB peak 30 kB\nmemtrace x: rss 1 kB peak 2 kB\n";
        assert_eq!(super::peak_of(s), Some(30));
        assert_eq!(super::peak_of("nothing"), None);
    }
}
