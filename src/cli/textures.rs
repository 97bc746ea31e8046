//! `bumpbake textures IN... -o OUT | --out-dir DIR`.

use bumpbake::format::WriteOptions;
use bumpbake::textures::{run as run_job, TexturesJob};
use bumpbake::Result;
use std::path::Path;

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake textures scene.glb -o scene_ktx2.glb
  bumpbake textures assets/*.glb --out-dir shipped/ --ktx2-fallback
  bumpbake textures model.gltf -o model_ktx2.gltf --images external --no-specular-aa --json")]
pub struct Args {
    #[command(flatten)]
    pub io: super::args::MeshIo,
    #[command(flatten)]
    pub encode: super::args::TextureEncodeArgs,
    /// Images inside the output (GLB, or .gltf's buffer) or as files beside a .gltf.
    #[arg(long, value_parser = ["embed", "external"], default_value = "embed")]
    pub images: String,
    #[command(flatten)]
    pub batch: super::args::BatchArgs,
}

pub fn run(a: Args) -> Result<u8> {
    let outputs = a.io.outputs(&a.batch.out_dir)?;
    let options = a.encode.options()?;
    let job = |input: &Path, output: &Path| TexturesJob {
        input: input.to_path_buf(),
        output: output.to_path_buf(),
        options,
        read: a.io.read_options(&a.batch),
        write: WriteOptions { images_external: a.images == "external", ..Default::default() },
        depfile: a.io.depfile.clone(),
    };
    a.io.run_each(&outputs, &a.batch, |input, output| run_job(&job(input, output)))
}
