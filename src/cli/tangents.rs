//! `bumpbake tangents IN -o OUT`.

use bumpbake::scene::{NormalMode, ReadOptions, WriteOptions};
use bumpbake::tangent::apply::ApplyOptions;
use bumpbake::tangent::command::{run as run_job, TangentsJob};
use bumpbake::tangent::Options;
use bumpbake::Result;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake tangents fixtures/spot/spot.obj -o spot.glb
  bumpbake tangents scene.gltf -o scene.gltf --overwrite --bitangents
  bumpbake tangents model.glb -o out.gltf --embed --json > report.json")]
pub struct Args {
    /// Input mesh: .obj (with its .mtl), .gltf or .glb.
    pub input: PathBuf,
    /// Output file: .gltf (with a .bin beside it) or .glb.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Put buffers and images inside a .gltf as data URIs.
    #[arg(long)]
    pub embed: bool,
    /// Give every triangle primitive with UVs tangents, not only those with a normal texture.
    #[arg(long)]
    pub all: bool,
    /// Replace existing valid tangents too.
    #[arg(long)]
    pub overwrite: bool,
    /// Also write the bitangent cross(N, T) * w as a _BITANGENT attribute.
    #[arg(long)]
    pub bitangents: bool,
    /// Normals for OBJ meshes without `vn`.
    #[arg(long, value_enum, default_value = "smooth")]
    pub normals: Normals,
    /// Let URIs reach outside the input's folder.
    #[arg(long)]
    pub allow_outside: bool,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// No report on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum Normals {
    Flat,
    Smooth,
}

pub fn run(a: Args) -> Result<u8> {
    let job = TangentsJob {
        input: a.input,
        output: a.output,
        read: ReadOptions {
            allow_outside: a.allow_outside,
            obj_normals: match a.normals {
                Normals::Flat => NormalMode::Flat,
                Normals::Smooth => NormalMode::Smooth,
            },
        },
        apply: ApplyOptions { all: a.all, overwrite: a.overwrite, frames: Options { bitangents: a.bitangents, ..Default::default() } },
        write: WriteOptions { embed: a.embed },
    };
    let report = run_job(&job)?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report).expect("report serialises"));
    }
    if !a.quiet && !a.json {
        eprint!("{}", report.text());
    }
    Ok(0)
}
