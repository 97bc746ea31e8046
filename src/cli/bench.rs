//! `bumpbake bench ...`: error against run time for each stage.

use super::{bench_batch, bench_command, bench_normalmap, bench_tangents};
use bumpbake::Result;
use clap::Subcommand;

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
}

pub fn run(args: Args) -> Result<u8> {
    match args.what {
        What::Normalmap(a) => bench_normalmap::run(a),
        What::Tangents(a) => bench_tangents::run(a),
        What::Batch(a) => bench_batch::run(a),
        What::Command(a) => bench_command::run(a),
    }
}
