//! `bumpbake bake MESH [--height H | --normal N] -o OUT`.

use bumpbake::bake::maps::HeightSettings;
use bumpbake::bake::{run as run_job, BakeJob, BakeReport, MapSource};
use bumpbake::batch;
use bumpbake::normalmap::{Channel, Convention, Filter};
use bumpbake::scene::{ReadOptions, WriteOptions};
use bumpbake::{Error, Result};
use std::path::{Path, PathBuf};

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake bake fixtures/bake/torus.obj -o torus.glb
  bumpbake bake scene.gltf --height bumps.png --material Stone --strength 4 -o scene.glb
  bumpbake bake model.obj --normal normal_dx.png --convention directx -o model.gltf --images external")]
pub struct Args {
    #[command(flatten)]
    pub io: super::report::MeshIo,
    /// Height map to convert into the normal map (PNG, JPEG, WebP, TIFF or EXR).
    #[arg(long, conflicts_with = "normal")]
    pub height: Option<PathBuf>,
    /// Normal map to attach (PNG/JPEG kept, WebP/TIFF/EXR stored as PNG; DirectX converted to glTF's +Y).
    #[arg(long)]
    pub normal: Option<PathBuf>,
    /// The material that gets the map (default: those with a bump map, or the only one).
    #[arg(long)]
    pub material: Option<String>,
    /// Strength S: how tall the whole black-to-white height range stands, in texels.
    ///
    /// At 1, a slope from black to white across 100 texels tilts the normal by only 0.6°: right
    /// for maps that use their whole range in a few texels (rivets, cracks), too little for gentle
    /// relief. When the result comes out nearly flat, bake warns and names a strength that shows
    /// it. An MTL bump map's -bm multiplies it.
    #[arg(long, default_value_t = 1.0, conflicts_with = "height_range")]
    pub strength: f32,
    /// Physical units: height of h = 1, in metres (with --texel-size).
    #[arg(long, requires = "texel_size")]
    pub height_range: Option<f32>,
    /// Physical units: size of one texel, in metres.
    #[arg(long, requires = "height_range")]
    pub texel_size: Option<f32>,
    /// Derivative filter for height maps.
    #[arg(long, value_enum, default_value_t = Filter::default())]
    pub filter: Filter,
    /// Height channel of colour images.
    #[arg(long, value_enum, default_value_t = Channel::Luma)]
    pub channel: Channel,
    /// The height map holds depth.
    #[arg(long)]
    pub invert: bool,
    /// Write 16-bit normal maps.
    #[arg(long)]
    pub bits16: bool,
    /// Green-channel convention of --normal (default: detect it).
    #[arg(long, value_enum)]
    pub convention: Option<Convention>,
    /// Keep everything, even what nothing uses.
    #[arg(long)]
    pub keep_all: bool,
    /// Also write _BITANGENT.
    #[arg(long)]
    pub bitangents: bool,
    /// Images inside the output (GLB, or .gltf's buffer) or as files beside a .gltf.
    #[arg(long, value_parser = ["embed", "external"], default_value = "embed")]
    pub images: String,
    #[command(flatten)]
    pub batch: super::report::BatchArgs,
}

pub fn run(a: Args) -> Result<u8> {
    let outputs = a.io.outputs(&a.batch.out_dir)?;
    let strength = match (a.height_range, a.texel_size) {
        (Some(r), Some(t)) if t > 0.0 && r.is_finite() && t.is_finite() => r / t,
        (Some(_), Some(_)) => return Err(Error::usage("--texel-size must be a positive number")),
        _ => a.strength,
    };
    if !strength.is_finite() {
        return Err(Error::usage("--strength must be finite"));
    }
    let job = |input: &Path, output: &Path| BakeJob {
        mesh: input.to_path_buf(),
        output: output.to_path_buf(),
        map: match (&a.height, &a.normal) {
            (Some(h), _) => MapSource::Height(h.clone()),
            (None, Some(n)) => MapSource::Normal(n.clone()),
            _ => MapSource::Scene,
        },
        material: a.material.clone(),
        height: HeightSettings {
            strength,
            filter: a.filter,
            invert: a.invert,
            channel: a.channel,
            sixteen_bit: a.bits16,
            ..Default::default()
        },
        normal_convention: a.convention,
        keep_all: a.keep_all,
        bitangents: a.bitangents,
        read: ReadOptions { allow_outside: a.io.allow_outside, ..Default::default() },
        write: WriteOptions { images_external: a.images == "external", ..Default::default() },
        depfile: a.io.depfile.clone(),
    };
    let opts = a.batch.options();
    let results = batch::run(&a.io.inputs, &opts, |input| {
        run_job(&job(input, super::report::paired(&a.io.inputs, &outputs, input)))
    })?;
    super::report::print("bumpbake-bake/1", &a.io.inputs, results, a.batch.json, a.batch.quiet, BakeReport::text)
}
