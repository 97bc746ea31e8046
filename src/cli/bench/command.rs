//! `bumpbake bench command`: the whole `tangents` command on a file, time and peak memory.

use bumpbake::Result;
use std::path::PathBuf;

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
    let r =
        super::shared::with_scratch("command", |exe, dir| bumpbake::bench::command::run(exe, &a.input, dir, a.runs))?;
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
