//! `bumpbake normalmap HEIGHT -o NORMAL`: parses, checks the numbers, shows progress on a
//! terminal, and hands the rest to `bumpbake::normalmap::convert_file`.

use super::args::{ChannelArg, ConventionArg, FilterArg, TexturesArg, WrapArg};
use bumpbake::batch;
use bumpbake::normalmap::{self as nm, Channel, Convention, Convert, Converted, EncodeOptions, Filter, Options, Wrap};
use bumpbake::progress::Reporter;
use bumpbake::{Error, Result};
use clap::builder::TypedValueParser;
use std::path::{Path, PathBuf};

/// What alpha holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Alpha {
    /// The height (after --invert), for parallax mapping.
    Height,
}

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake normalmap bricks_height.png -o bricks_normal.png --strength 4
  bumpbake normalmap terrain16.png -o terrain_n.png --bits 16 --height-range 0.05 --texel-size 0.001 --wrap repeat
  bumpbake normalmap depth.exr -o n.png --invert --convention directx --alpha height --filter spectral
  bumpbake normalmap bricks_height.png -o bricks_normal.ktx2 --strength 4 --ktx2 uastc --ktx2-quality 3")]
pub struct Args {
    /// Height maps: PNG (8/16-bit gray, gray+alpha, RGB, RGBA), JPEG, WebP, TIFF or EXR.
    #[arg(required = true)]
    pub heights: Vec<PathBuf>,
    /// Normal map to write (one input): .png (8 or 16-bit), .tif, .exr (32-bit float), or .ktx2
    /// (Basis Universal with a mip chain built from the full-resolution normals).
    #[arg(short, long, value_name = "NORMAL", conflicts_with = "out_dir")]
    pub output: Option<PathBuf>,
    /// Extension of the outputs written into --out-dir.
    #[arg(long, value_parser = ["png", "tif", "exr", "ktx2"], default_value = "png")]
    pub out_ext: String,
    /// png: -o's extension decides (.png, .tif, .exr); ktx2: a .ktx2 output (the default
    /// extension of --out-dir outputs becomes ktx2).
    #[arg(long, value_enum)]
    pub textures: Option<TexturesArg>,
    #[command(flatten)]
    pub ktx2: super::args::Ktx2Args,
    /// Which channel holds the height (luma is Rec. 709; gray images use their gray value).
    #[arg(long, value_enum, default_value_t = ChannelArg::from(Channel::default()))]
    pub channel: ChannelArg,
    /// Strength S: how tall the whole black-to-white height range stands, in texels [default: 1].
    ///
    /// At 1, a slope from black to white across 100 texels tilts the normal by only 0.6°: right
    /// for maps that use their whole range in a few texels (rivets, cracks), too little for gentle
    /// relief. When the result comes out nearly flat, bumpbake warns and names a strength that
    /// shows it. With real sizes, give --height-range and --texel-size instead.
    #[arg(long, allow_negative_numbers = true, conflicts_with_all = ["height_range", "texel_size"])]
    pub strength: Option<f32>,
    /// Height of the full 0..1 sample range, in metres (with --texel-size: S = range / texel).
    #[arg(long, value_name = "METRES", allow_negative_numbers = true, requires = "texel_size")]
    pub height_range: Option<f64>,
    /// Size of one texel, in metres.
    #[arg(long, value_name = "METRES", allow_negative_numbers = true, requires = "height_range")]
    pub texel_size: Option<f64>,
    /// Derivative filter (all estimate the true slope; see docs/normalmap.md).
    #[arg(long, value_enum, default_value_t = FilterArg::from(Filter::default()))]
    pub filter: FilterArg,
    /// What lies beyond the edges: repeat for tiling textures.
    #[arg(long, value_enum, default_value_t = WrapArg::from(Wrap::default()))]
    pub wrap: WrapArg,
    /// +Y up (opengl, glTF) or down (directx).
    #[arg(long, value_enum, default_value_t = ConventionArg::from(Convention::default()))]
    pub convention: ConventionArg,
    /// Bits per PNG/TIFF sample: 8 or 16 (EXR is always float).
    #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(["8", "16"]).map(|s| s.parse::<u8>().unwrap()))]
    pub bits: Option<u8>,
    /// Store the height in alpha, for parallax mapping.
    #[arg(long, value_enum)]
    pub alpha: Option<Alpha>,
    /// The input is a depth map (white is deep): use 1 - h.
    #[arg(long)]
    pub invert: bool,
    /// Refuse images whose header claims more pixels than this.
    #[arg(long, default_value_t = nm::DEFAULT_MAX_PIXELS)]
    pub max_pixels: u64,
    #[command(flatten)]
    pub batch: super::args::BatchArgs,
}

fn strength(args: &Args) -> Result<f32> {
    Options::strength_from(args.strength, args.height_range, args.texel_size)
}

/// The extension of the outputs, after checking `--textures` against `-o` and `--out-ext`.
fn out_ext(args: &Args) -> Result<String> {
    let is_ktx2 = |e: &str| e.eq_ignore_ascii_case("ktx2");
    let named = args.output.as_ref().map(|o| o.extension().and_then(|e| e.to_str()).unwrap_or("").to_string());
    match (args.textures, named) {
        (Some(TexturesArg::Ktx2), Some(e)) if !is_ktx2(&e) => {
            Err(Error::usage(format!("--textures ktx2 writes .ktx2, but -o names a .{e} file")))
        }
        (Some(TexturesArg::Png), Some(e)) if is_ktx2(&e) => {
            Err(Error::usage("--textures png contradicts -o NAME.ktx2: drop one of them"))
        }
        (Some(TexturesArg::Ktx2), None) if args.out_ext == "png" || is_ktx2(&args.out_ext) => Ok("ktx2".into()),
        (Some(TexturesArg::Ktx2), None) => {
            Err(Error::usage(format!("--textures ktx2 writes .ktx2, but --out-ext is {}", args.out_ext)))
        }
        (Some(TexturesArg::Png), None) if is_ktx2(&args.out_ext) => {
            Err(Error::usage("--textures png contradicts --out-ext ktx2: drop one of them"))
        }
        _ => Ok(args.out_ext.clone()),
    }
}

pub fn run(args: Args) -> Result<u8> {
    let outputs = super::args::outputs(&args.heights, &args.output, &args.batch.out_dir, &out_ext(&args)?)?;
    let ktx2 = args.ktx2.codec();
    ktx2.check()?;
    let options =
        Options { strength: strength(&args)?, filter: args.filter.into(), wrap: args.wrap.into(), invert: args.invert };
    let convert = |input: &Path, output: &Path| -> Result<Convert> {
        let format = nm::OutputFormat::from_path(output)?;
        Ok(Convert {
            input: input.to_path_buf(),
            output: output.to_path_buf(),
            channel: args.channel.into(),
            max_pixels: args.max_pixels,
            options,
            encode: EncodeOptions {
                depth: format.depth(output, args.bits)?,
                convention: args.convention.into(),
                alpha_height: args.alpha == Some(Alpha::Height),
            },
            png: nm::PngSettings::default(),
            ktx2,
        })
    };
    let results = if args.heights.len() == 1 {
        let progress = args.batch.single_progress(1);
        vec![convert(&args.heights[0], &outputs[0]).and_then(|c| nm::convert_file(&c, &progress))]
    } else {
        let opts = args.batch.options(args.heights.len());
        batch::run(&args.heights, &opts, |input| {
            let c = convert(input, super::args::paired(&args.heights, &outputs, input))?;
            nm::convert_file(&c, &Reporter::none()).map(|r| Converted { batch: true, ..r })
        })?
    };
    super::print::all(&args.heights, results, args.batch.json, args.batch.quiet)
}
