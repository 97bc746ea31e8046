//! `bumpbake normalmap HEIGHT -o NORMAL`: parses, checks the numbers, shows progress on a
//! terminal, and hands the rest to `bumpbake::normalmap::convert_file`.

use super::args::{ChannelArg, ConventionArg, FilterArg, WrapArg};
use bumpbake::batch;
use bumpbake::format::image::ktx2::Codec;
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

/// The Basis Universal codec of KTX2 output.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Ktx2Codec {
    Uastc,
    Etc1s,
}

fn codec(args: &Args) -> Result<Codec> {
    match (args.ktx2, args.ktx2_quality) {
        (Ktx2Codec::Uastc, q) => match q.unwrap_or(nm::DEFAULT_UASTC_LEVEL) {
            level @ 0..=4 => Ok(Codec::Uastc { level, rdo: None }),
            q => Err(Error::usage(format!("--ktx2-quality {q}: UASTC levels are 0 to 4"))),
        },
        (Ktx2Codec::Etc1s, q) => match q.unwrap_or(nm::DEFAULT_ETC1S_QUALITY) {
            quality @ 1..=255 => Ok(Codec::Etc1s { quality }),
            q => Err(Error::usage(format!("--ktx2-quality {q}: ETC1S quality is 1 to 255"))),
        },
    }
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
    /// Basis Universal codec of .ktx2 outputs: uastc (Zstandard-supercompressed, higher quality)
    /// or etc1s (BasisLZ, smaller).
    #[arg(long, value_enum, default_value_t = Ktx2Codec::Uastc)]
    pub ktx2: Ktx2Codec,
    /// KTX2 quality: UASTC pack level 0-4 [default: 2], ETC1S quality 1-255 [default: 128].
    #[arg(long, value_name = "Q")]
    pub ktx2_quality: Option<u32>,
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
    let s = match (args.strength, args.height_range, args.texel_size) {
        (Some(s), _, _) => s,
        (None, Some(range), Some(texel)) => {
            if !(texel.is_finite() && texel > 0.0) {
                return Err(Error::usage(format!("--texel-size {texel}: must be a positive length")));
            }
            if !(range.is_finite() && range >= 0.0) {
                return Err(Error::usage(format!("--height-range {range}: must be zero or a positive length")));
            }
            Options::physical_strength(range, texel)
        }
        _ => Options::default().strength,
    };
    if !(s.is_finite() && s >= 0.0) {
        return Err(Error::usage(format!(
            "strength {s}: must be finite and not negative (use --invert for depth maps)"
        )));
    }
    Ok(s)
}

pub fn run(args: Args) -> Result<u8> {
    let outputs = super::args::outputs(&args.heights, &args.output, &args.batch.out_dir, &args.out_ext)?;
    let ktx2 = codec(&args)?;
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
