//! `bumpbake bake MESH [--height H | --normal N] -o OUT`.

use super::args::{ChannelArg, ConventionArg, FilterArg, TexturesArg};
use bumpbake::bake::maps::HeightSettings;
use bumpbake::bake::{run as run_job, BakeJob, MapSource};
use bumpbake::format::WriteOptions;
use bumpbake::normalmap::{Channel, Filter};
use bumpbake::scene::ReadOptions;
use bumpbake::transfer::{Match, Settings};

super::args::arg_enum! {
    /// How LOW parts find their HIGH parts ([`Match`]).
    pub enum MatchArg => Match {
        /// Pair parts whose names differ only by `_low`/`_high` (or `_lo`/`_hi`).
        Auto => Auto,
        /// Every LOW part sees every HIGH part.
        None => None,
    }
}
use bumpbake::{Error, Result};
use std::path::{Path, PathBuf};

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake bake fixtures/bake/torus.obj -o torus.glb
  bumpbake bake scene.gltf --height bumps.png --material Stone --strength 4 -o scene.glb
  bumpbake bake model.obj --normal normal_dx.png --convention directx -o model.gltf --images external
  bumpbake bake low.glb --from sculpt.glb -o low_baked.glb --size 2048 --samples 2 --miss-mask misses.png
  bumpbake bake fixtures/bake/torus.obj -o torus.glb --textures ktx2 --ktx2-fallback")]
pub struct Args {
    #[command(flatten)]
    pub io: super::args::MeshIo,
    /// Height map to convert into the normal map (PNG, JPEG, WebP, TIFF or EXR).
    #[arg(long, conflicts_with_all = ["normal", "from"])]
    pub height: Option<PathBuf>,
    /// High-poly mesh to bake the normal map from, onto the input's UV layout (repeatable).
    #[arg(long, conflicts_with = "normal")]
    pub from: Vec<PathBuf>,
    /// With --from: a cage (the input with its vertices moved out); rays run from LOW towards it.
    #[arg(long, requires = "from")]
    pub cage: Option<PathBuf>,
    /// With --from: how far rays reach outside LOW, scene units (default 5% of LOW's diagonal).
    #[arg(long, requires = "from")]
    pub ray_front: Option<f64>,
    /// With --from: how far rays reach inside LOW, scene units (default 5% of LOW's diagonal).
    #[arg(long, requires = "from")]
    pub ray_back: Option<f64>,
    /// With --from: N x N rays per texel.
    #[arg(long, default_value_t = 1, requires = "from")]
    pub samples: usize,
    /// With --from: map size, N or WxH.
    #[arg(long, default_value = "1024", requires = "from")]
    pub size: String,
    /// With --from: texels of padding around UV islands.
    #[arg(long, default_value_t = 16, requires = "from")]
    pub padding: usize,
    /// With --from: also write the map to this file (.png, .tif, .exr; --convention, --bits16);
    /// with several materials, one file each, named `<stem>_<material>.<ext>`.
    #[arg(long, requires = "from")]
    pub map_out: Option<PathBuf>,
    /// With --from: write the height map (signed distance LOW to HIGH, 16-bit PNG).
    #[arg(long, requires = "from")]
    pub height_out: Option<PathBuf>,
    /// With --from: write where rays missed HIGH (8-bit PNG, white: every ray of the texel missed).
    #[arg(long, requires = "from")]
    pub miss_mask: Option<PathBuf>,
    /// With --from: pair LOW and HIGH parts by name (`ring_low` bakes only from `ring_high`; also
    /// `_lo`/`_hi`, any case, before a `.001` number), or let every part see all of HIGH.
    #[arg(long = "match", value_enum, default_value_t = MatchArg::from(Match::default()), requires = "from")]
    pub matching: MatchArg,
    /// With --from: dither the 8-bit map (triangular noise of one level, from a hash of the
    /// texel's position: the same bytes on every run) so gentle gradients do not band.
    #[arg(long, requires = "from")]
    pub dither: bool,
    /// With --from: hit HIGH triangles from their front only (counter-clockwise), as rays cast
    /// from the cage towards LOW see them: a thin part's inner wall, facing LOW, is passed through.
    #[arg(long, requires = "from")]
    pub ignore_backfaces: bool,
    /// With --from: the node to bake a LOW mesh through when several nodes show it.
    #[arg(long, requires = "from")]
    pub node: Option<String>,
    /// Normal map to attach (PNG/JPEG kept, WebP/TIFF/EXR stored as PNG; DirectX converted to glTF's +Y).
    #[arg(long)]
    pub normal: Option<PathBuf>,
    /// The material that gets the map (default: those with a bump map, or the only one; with
    /// --from, every material LOW's triangles use, each its own map).
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
    /// Height of h = 1 in the scene's units (Blender's Bump Distance). Alone, the map is made
    /// through the mesh: each texel as large as the mesh lays it out, so stretched UVs, curved
    /// and scaled meshes shade as Blender's Bump node shades them. With --texel-size, one size
    /// for every texel.
    #[arg(long)]
    pub height_range: Option<f32>,
    /// Physical units: size of one texel, in metres (with --height-range).
    #[arg(long, requires = "height_range")]
    pub texel_size: Option<f32>,
    /// Derivative filter for height maps.
    #[arg(long, value_enum, default_value_t = FilterArg::from(Filter::default()))]
    pub filter: FilterArg,
    /// Height channel of colour images.
    #[arg(long, value_enum, default_value_t = ChannelArg::from(Channel::default()))]
    pub channel: ChannelArg,
    /// The height map holds depth.
    #[arg(long)]
    pub invert: bool,
    /// Write 16-bit normal maps.
    #[arg(long)]
    pub bits16: bool,
    /// Green-channel convention of --normal (default: detect it), or of --map-out.
    #[arg(long, value_enum)]
    pub convention: Option<ConventionArg>,
    /// Keep everything, even what nothing uses.
    #[arg(long)]
    pub keep_all: bool,
    /// Also write _BITANGENT.
    #[arg(long)]
    pub bitangents: bool,
    /// Images inside the output (GLB, or .gltf's buffer) or as files beside a .gltf.
    #[arg(long, value_parser = ["embed", "external"], default_value = "embed")]
    pub images: String,
    /// Normal maps as PNG, or as KTX2 (KHR_texture_basisu) with mips made from the
    /// full-resolution normals and, unless --no-specular-aa, roughness widened to match.
    #[arg(long, value_enum, default_value_t = TexturesArg::Png)]
    pub textures: TexturesArg,
    #[command(flatten)]
    pub encode: super::args::TextureEncodeArgs,
    #[command(flatten)]
    pub batch: super::args::BatchArgs,
}

pub fn run(a: Args) -> Result<u8> {
    let outputs = a.io.outputs(&a.batch.out_dir)?;
    let (strength, height_range) = match (a.height_range, a.texel_size) {
        // Alone, the range is a height on the mesh, whose texels have their own sizes.
        (Some(r), None) => {
            // Checks the range as a length; the strength stays 1 (the mesh sets each texel's size).
            bumpbake::normalmap::Options::strength_from(None, Some(r as f64), Some(1.0))?;
            (1.0, Some(r as f64))
        }
        (r, t) => {
            let strength = (r.is_none()).then_some(a.strength);
            (bumpbake::normalmap::Options::strength_from(strength, r.map(f64::from), t.map(f64::from))?, None)
        }
    };
    let transfer = transfer_settings(&a)?;
    let textures = match (a.textures, a.encode.given()) {
        (TexturesArg::Ktx2, _) => Some(a.encode.options()?),
        (TexturesArg::Png, Some(flag)) => return Err(Error::usage(format!("{flag} needs --textures ktx2"))),
        (TexturesArg::Png, None) => None,
    };
    let job = |input: &Path, output: &Path| BakeJob {
        mesh: input.to_path_buf(),
        output: output.to_path_buf(),
        map: match (&a.height, &a.normal, &transfer) {
            (_, _, Some(t)) => MapSource::Transfer(Box::new(t.clone())),
            (Some(h), _, _) => MapSource::Height(h.clone()),
            (None, Some(n), _) => MapSource::Normal(n.clone()),
            _ => MapSource::Scene,
        },
        material: a.material.clone(),
        height: HeightSettings {
            strength,
            height_range,
            filter: a.filter.into(),
            invert: a.invert,
            channel: a.channel.into(),
            sixteen_bit: a.bits16,
            ..Default::default()
        },
        normal_convention: if transfer.is_some() { None } else { a.convention.map(Into::into) },
        keep_all: a.keep_all,
        bitangents: a.bitangents,
        read: a.io.read_options(&a.batch),
        write: WriteOptions { images_external: a.images == "external", ..Default::default() },
        depfile: a.io.depfile.clone(),
        textures,
    };
    a.io.run_each(&outputs, &a.batch, |input, output| run_job(&job(input, output)))
}

/// The `--from` options, checked; `None` without `--from`.
fn transfer_settings(a: &Args) -> Result<Option<Settings>> {
    if a.from.is_empty() {
        return Ok(None);
    }
    let files = [&a.map_out, &a.height_out, &a.miss_mask];
    if a.io.inputs.len() > 1 && files.iter().any(|f| f.is_some()) {
        return Err(Error::usage("--map-out, --height-out and --miss-mask take one input"));
    }
    let (width, height) = parse_size(&a.size)?;
    let progress = a.batch.single_progress(a.io.inputs.len());
    Ok(Some(Settings {
        highs: a.from.clone(),
        cage: a.cage.clone(),
        ray_front: a.ray_front,
        ray_back: a.ray_back,
        samples: a.samples,
        width,
        height,
        padding: a.padding,
        sixteen_bit: a.bits16,
        dither: a.dither,
        ignore_backfaces: a.ignore_backfaces,
        map_out: a.map_out.clone(),
        convention: a.convention.map(Into::into).unwrap_or_default(),
        height_out: a.height_out.clone(),
        miss_mask: a.miss_mask.clone(),
        read: ReadOptions { allow_outside: a.io.allow_outside, progress: progress.clone(), ..Default::default() },
        matching: a.matching.into(),
        node: a.node.clone(),
        progress,
    }))
}

/// `N` or `WxH`.
fn parse_size(s: &str) -> Result<(usize, usize)> {
    let bad = || Error::usage(format!("--size {s}: give N or WxH (e.g. 2048 or 2048x1024)"));
    let num = |t: &str| t.trim().parse::<usize>().map_err(|_| bad());
    match s.split_once(['x', 'X']) {
        Some((w, h)) => Ok((num(w)?, num(h)?)),
        None => num(s).map(|n| (n, n)),
    }
}
