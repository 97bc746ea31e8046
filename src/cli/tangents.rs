//! `bumpbake tangents IN... -o OUT | --out-dir DIR`.

use bumpbake::format::WriteOptions;
use bumpbake::scene::{NormalMode, ReadOptions};
use bumpbake::tangent::apply::ApplyOptions;
use bumpbake::tangent::command::{run as run_job, TangentsJob};
use bumpbake::tangent::Options;
use bumpbake::Result;
use std::path::Path;

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake tangents fixtures/spot/spot.obj -o spot.glb --all
  bumpbake tangents scene.gltf -o scene.gltf --overwrite --bitangents
  bumpbake tangents assets/*.glb --out-dir build/ -j 4 --json > report.jsonl")]
pub struct Args {
    #[command(flatten)]
    pub io: super::args::MeshIo,
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
    /// Normals for OBJ meshes without `vn`: smooth within the file's smoothing groups (`s`;
    /// faces in none are flat), or flat everywhere.
    #[arg(long, value_enum, default_value = "smooth")]
    pub normals: Normals,
    #[command(flatten)]
    pub batch: super::args::BatchArgs,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum Normals {
    Flat,
    Smooth,
}

pub fn run(a: Args) -> Result<u8> {
    let outputs = a.io.outputs(&a.batch.out_dir)?;
    let job = |input: &Path, output: &Path| TangentsJob {
        input: input.to_path_buf(),
        output: output.to_path_buf(),
        read: ReadOptions {
            allow_outside: a.io.allow_outside,
            obj_normals: match a.normals {
                Normals::Flat => NormalMode::Flat,
                Normals::Smooth => NormalMode::Smooth,
            },
            progress: a.batch.single_progress(a.io.inputs.len()),
        },
        apply: ApplyOptions {
            all: a.all,
            overwrite: a.overwrite,
            frames: Options { bitangents: a.bitangents, ..Default::default() },
        },
        write: WriteOptions { embed: a.embed, ..Default::default() },
        depfile: a.io.depfile.clone(),
    };
    a.io.run_each(&outputs, &a.batch, |input, output| run_job(&job(input, output)))
}
