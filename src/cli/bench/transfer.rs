//! `bumpbake bench transfer`: `bake --from` on an analytic surface, error against run time.

use bumpbake::{Error, Result};

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake bench transfer
  bumpbake bench transfer --runs 7 --json > transfer-bench.json")]
pub struct BenchTransferArgs {
    /// Timed runs of each configuration (each a new process); medians are reported.
    #[arg(long, default_value_t = 5)]
    pub runs: usize,
    /// Map size and samples per axis of the error-against-time rows, as SIZE:N, comma-separated.
    #[arg(long, default_value = "512:1,1024:1,1024:2,2048:1,2048:2")]
    pub quality: String,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: BenchTransferArgs) -> Result<u8> {
    let quality = a
        .quality
        .split(',')
        .map(|q| {
            let (s, n) = q.split_once(':').unwrap_or((q, "1"));
            match (s.trim().parse::<usize>(), n.trim().parse::<usize>()) {
                (Ok(s), Ok(n)) if s > 0 && (1..=8).contains(&n) => Ok((s, n)),
                _ => Err(Error::usage(format!("--quality {q}: give SIZE:N, e.g. 1024:2"))),
            }
        })
        .collect::<Result<Vec<_>>>()?;
    let quiet = a.json;
    let r = super::shared::with_scratch("transfer", |exe, dir| {
        bumpbake::bench::transfer::run(exe, dir, &quality, a.runs, |row| {
            if !quiet {
                eprintln!(
                    "  {} triangles, {}², {} sample(s): {:.3} s, {:.3}° mean",
                    row.high_triangles,
                    row.size,
                    row.samples * row.samples,
                    row.median_s,
                    row.error.synced.mean
                );
            }
        })
    })?;
    super::shared::print(&r, a.json, bumpbake::bench::transfer::table)?;
    Ok(0)
}
