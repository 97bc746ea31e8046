//! Command-line types (clap derive), one file per subcommand, each with its `run`.

#[macro_use]
pub mod stdout;

mod args;
mod bake;
mod bench;
mod completions;
mod inspect;
mod normalmap;
mod preview;
mod print;
pub mod process;
pub mod progress_bars;
mod tangents;
mod textures;
mod validate;
pub mod wording;

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
    /// Mesh + height map, normal map or high-poly mesh (--from) -> a render-ready glTF with nothing it does not need.
    Bake(Box<bake::Args>),
    /// Measure error against run time.
    Bench(bench::Args),
    /// Check tangent frames, handedness and normal maps; exit 1 on errors (for CI).
    Validate(validate::Args),
    /// Show what a mesh file holds: primitives, attributes, materials, tangents, images.
    Inspect(inspect::Args),
    /// Print shell completions.
    Completions(completions::CompletionArgs),
    /// Print the man page.
    Man(completions::ManArgs),
    /// Render an asset with the reference bump-mapping model (CPU), or compare two.
    Preview(preview::Args),
    /// Re-encode glTF normal maps as KTX2 (KHR_texture_basisu) with mips made from the normals, and widen roughness to match.
    Textures(textures::Args),
}

impl Cli {
    /// Whether this run bakes from HIGH meshes (`bake --from`).
    pub fn bakes_from_high(&self) -> bool {
        matches!(&self.command, Command::Bake(a) if !a.from.is_empty())
    }
}

/// Runs one parsed command line and returns the process exit code.
pub fn run(cli: Cli) -> Result<u8> {
    // `bench command` and `bench transfer` set this on the runs they measure and read the peak
    // back from the `memtrace` lines (`bench::command::peak_of`).
    let trace = std::env::var_os("BUMPBAKE_MEMTRACE").is_some();
    if trace {
        bumpbake::timings::trace_memory();
    }
    let code = run_command(cli);
    if trace {
        for m in bumpbake::timings::memory_marks() {
            eprintln!("memtrace {}: rss {} kB peak {} kB", m.stage, m.rss_kib, m.peak_kib);
        }
    }
    code
}

fn run_command(cli: Cli) -> Result<u8> {
    match cli.command {
        Command::Tangents(a) => tangents::run(a),
        Command::Normalmap(a) => normalmap::run(a),
        Command::Bake(a) => bake::run(*a),
        Command::Bench(a) => bench::run(a),
        Command::Validate(a) => validate::run(a),
        Command::Inspect(a) => inspect::run(a),
        Command::Completions(a) => completions::completions(a),
        Command::Man(a) => completions::man(a),
        Command::Preview(a) => preview::run(a),
        Command::Textures(a) => textures::run(a),
    }
}
