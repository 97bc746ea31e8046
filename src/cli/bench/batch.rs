//! `bumpbake bench batch`: a batch of small assets through `bake -j N` against one process each.

use bumpbake::Result;

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake bench batch
  bumpbake bench batch --assets 50 --jobs 2 --runs 5 --json")]
pub struct BenchBatchArgs {
    /// How many small assets to bake.
    #[arg(long, default_value_t = 200)]
    pub assets: usize,
    /// Files at once in the batched run.
    #[arg(long, default_value_t = 2)]
    pub jobs: usize,
    /// Timed runs of each way; medians are reported.
    #[arg(long, default_value_t = 3)]
    pub runs: usize,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: BenchBatchArgs) -> Result<u8> {
    let r = super::shared::with_scratch("batch", |exe, dir| {
        bumpbake::bench::batch::run(exe, dir, a.assets, a.jobs, a.runs)
    })?;
    super::shared::print(&r, a.json, |r| {
        format!(
            "{} assets: one process each {:.0} ms, one batch with -j {} {:.0} ms (medians of {}): ratio {:.2} (target <= 0.6)",
            r.assets, r.one_by_one_ms, r.jobs, r.batch_ms, r.runs, r.ratio
        )
    })?;
    Ok(0)
}
