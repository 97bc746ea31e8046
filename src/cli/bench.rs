//! `bumpbake bench ...`: error against run time for each stage.

use super::{bench_batch, bench_command, bench_normalmap, bench_tangents, bench_transfer};
use bumpbake::{Error, Result};
use clap::Subcommand;
use std::path::Path;

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake bench normalmap --json > normalmap.json
  bumpbake bench tangents --sizes 10k,100k,1m
  bumpbake bench command scan.glb")]
pub struct Args {
    #[command(subcommand)]
    pub what: What,
}

#[derive(Subcommand, Debug)]
pub enum What {
    /// Every normal-map filter on analytic height fields.
    Normalmap(bench_normalmap::BenchNormalmapArgs),
    /// Every tangent algorithm on parametric surfaces and real meshes.
    Tangents(bench_tangents::BenchTangentsArgs),
    /// Many small assets through `bake -j N` against one process each.
    Batch(bench_batch::BenchBatchArgs),
    /// The whole `tangents` command on a file: time and peak memory.
    Command(bench_command::BenchCommandArgs),
    /// `bake --from` on an analytic surface: error against time, time against HIGH and map size.
    Transfer(bench_transfer::BenchTransferArgs),
}

pub fn run(args: Args) -> Result<u8> {
    match args.what {
        What::Normalmap(a) => bench_normalmap::run(a),
        What::Tangents(a) => bench_tangents::run(a),
        What::Batch(a) => bench_batch::run(a),
        What::Command(a) => bench_command::run(a),
        What::Transfer(a) => bench_transfer::run(a),
    }
}

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
