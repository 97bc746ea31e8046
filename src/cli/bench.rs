//! `bumpbake bench ...`: error against run time for each stage.

use bumpbake::Result;
use clap::Subcommand;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(subcommand)]
    pub what: What,
}

#[derive(Subcommand, Debug)]
pub enum What {
    /// Every normal-map filter on analytic height fields.
    Normalmap,
    /// Every tangent algorithm on parametric surfaces and real meshes.
    Tangents,
}

pub fn run(args: Args) -> Result<u8> {
    match args.what {
        What::Normalmap | What::Tangents => Err(bumpbake::Error::usage("bench: not built yet")),
    }
}
