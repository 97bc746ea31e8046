//! Command-line types (clap derive), one file per subcommand, each with its `run`.

mod bench;
mod normalmap;
mod preview;
mod tangents;

use bumpbake::Result;
use clap::{Parser, Subcommand};

#[derive(Parser, Debug)]
#[command(name = "bumpbake", version, about = "Prepares 3D assets for bump and normal mapping", long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Generate MikkTSpace tangents (and optionally bitangents) and write glTF/GLB.
    Tangents(tangents::Args),
    /// Convert a height map into a tangent-space normal map.
    Normalmap(normalmap::Args),
    /// Measure error against run time.
    Bench(bench::Args),
    Preview(preview::Args),
}

/// Runs one parsed command line and returns the process exit code.
pub fn run(cli: Cli) -> Result<u8> {
    match cli.command {
        Command::Tangents(a) => tangents::run(a),
        Command::Normalmap(a) => normalmap::run(a),
        Command::Bench(a) => bench::run(a),
        Command::Preview(a) => preview::run(a),
    }
}
