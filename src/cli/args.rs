//! The command line every command over many inputs shares: the inputs, where their outputs go,
//! and how the batch runs (`print` prints its results).

use bumpbake::batch::{self, BatchOptions};
use bumpbake::format::image::ktx2::Codec;
use bumpbake::normalmap::specular_aa::DEFAULT_THRESHOLD;
use bumpbake::normalmap::{self as nm, Channel, Convention, Filter, Wrap};
use bumpbake::textures::EncodeOptions;
use bumpbake::{Error, Result};
use std::path::{Path, PathBuf};

/// A command-line twin of a library enum, mapped both ways by exhaustive matches: the library
/// stays free of clap, a variant added there fails to compile here until it has a spelling, and
/// the twin's doc comments are the help text of its values.
macro_rules! arg_enum {
    ($(#[$m:meta])* $vis:vis enum $name:ident => $lib:ident {
        $($(#[$vm:meta])* $var:ident => $lv:ident),+ $(,)?
    }) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
        $vis enum $name {
            $($(#[$vm])* $var),+
        }

        impl From<$name> for $lib {
            fn from(a: $name) -> $lib {
                match a {
                    $($name::$var => $lib::$lv),+
                }
            }
        }

        impl From<$lib> for $name {
            fn from(l: $lib) -> $name {
                match l {
                    $($lib::$lv => $name::$var),+
                }
            }
        }
    };
}
pub(crate) use arg_enum;

arg_enum! {
    /// How the height derivative is estimated ([`Filter`]).
    pub enum FilterArg => Filter {
        /// `[-1 0 1]/2`: sharpest 3-tap, no smoothing, most sensitive to noise.
        Central => Central,
        /// `[1 -8 0 8 -1]/12`: fourth-order accurate, no smoothing.
        Central4 => Central4,
        /// 3x3 Sobel: central difference smoothed by `[1 2 1]/4`.
        Sobel => Sobel,
        /// 3x3 Scharr: smoothing `[3 10 3]/16`, more rotation-invariant than Sobel.
        Scharr => Scharr,
        /// 3x3 Prewitt: smoothing `[1 1 1]/3`.
        Prewitt => Prewitt,
        /// 5x5 Sobel: `[-1 -2 0 2 1]/8` ⊗ `[1 4 6 4 1]/16`, smoothest.
        Sobel5 => Sobel5,
        /// FFT derivative: exact for band-limited periodic heights; costs an extra float plane.
        Spectral => Spectral,
    }
}

arg_enum! {
    /// What lies beyond the image edge ([`Wrap`]).
    pub enum WrapArg => Wrap {
        /// The opposite edge: for tiling textures.
        Repeat => Repeat,
        /// The edge texel repeated: no slope invented beyond the edge. Right for standalone maps.
        Clamp => Clamp,
        /// Reflected, edge texel included (GL_MIRRORED_REPEAT).
        Mirror => Mirror,
    }
}

arg_enum! {
    /// Which channel of the input carries the height ([`Channel`]).
    pub enum ChannelArg => Channel {
        /// Rec. 709 luma (0.2126 R + 0.7152 G + 0.0722 B) for colour, the gray value for gray.
        Luma => Luma,
        R => R,
        G => G,
        B => B,
        A => A,
    }
}

arg_enum! {
    /// Which way `+Y` points in a map written ([`Convention`]).
    pub enum ConventionArg => Convention {
        /// `+Y` up (OpenGL, glTF, Blender): the project's convention.
        Opengl => Opengl,
        /// `+Y` down (DirectX, Unreal): `n.y` negated before encoding, nothing else.
        Directx => Directx,
    }
}

/// The Basis Universal codec of KTX2 output.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Ktx2Codec {
    /// UASTC under Zstandard: the quality normal maps want.
    Uastc,
    /// ETC1S under BasisLZ: smaller, blockier.
    Etc1s,
}

/// The format normal maps are written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TexturesArg {
    /// PNG, the image every glTF client reads.
    Png,
    /// KTX2 (Basis Universal) with a mip chain made from the full-resolution normals;
    /// in glTF through KHR_texture_basisu.
    Ktx2,
}

/// The KTX2 codec and its quality, as `normalmap`, `bake` and `textures` take them.
#[derive(clap::Args, Debug)]
pub struct Ktx2Args {
    /// Basis Universal codec of KTX2 normal maps: uastc (Zstandard-supercompressed, higher
    /// quality) or etc1s (BasisLZ, smaller) [default: uastc].
    #[arg(long, value_enum)]
    pub ktx2: Option<Ktx2Codec>,
    /// KTX2 quality: UASTC pack level 0-4 [default: 2], ETC1S quality 1-255 [default: 128].
    #[arg(long, value_name = "Q")]
    pub ktx2_quality: Option<u32>,
}

impl Ktx2Args {
    /// The codec asked for; its range is checked where it is used (`Codec::check`).
    pub fn codec(&self) -> Codec {
        match (self.ktx2.unwrap_or(Ktx2Codec::Uastc), self.ktx2_quality) {
            (Ktx2Codec::Uastc, q) => Codec::Uastc { level: q.unwrap_or(nm::DEFAULT_UASTC_LEVEL), rdo: None },
            (Ktx2Codec::Etc1s, q) => Codec::Etc1s { quality: q.unwrap_or(nm::DEFAULT_ETC1S_QUALITY) },
        }
    }

    fn given(&self) -> Option<&'static str> {
        match (self.ktx2, self.ktx2_quality) {
            (Some(_), _) => Some("--ktx2"),
            (_, Some(_)) => Some("--ktx2-quality"),
            _ => None,
        }
    }
}

/// How glTF textures ship as KTX2 (`bake --textures ktx2`, `textures`).
#[derive(clap::Args, Debug)]
pub struct TextureEncodeArgs {
    #[command(flatten)]
    pub ktx2: Ktx2Args,
    /// Keep each PNG/JPEG as the texture's source for clients without KTX2
    /// (KHR_texture_basisu used, not required).
    #[arg(long)]
    pub ktx2_fallback: bool,
    /// Widen each roughness mip level by the variance its normal-map level lost (Toksvig;
    /// HDRP/Filament normal filtering), in a new metallicRoughness texture [default: on].
    #[arg(long, overrides_with = "no_specular_aa")]
    pub specular_aa: bool,
    /// Leave roughness as it is.
    #[arg(long, overrides_with = "specular_aa")]
    pub no_specular_aa: bool,
    /// Cap of the widening, in GGX alpha: a' = sqrt(a^2 + min(2 variance, T^2)) [default: 0.2].
    #[arg(long, value_name = "T")]
    pub specular_aa_threshold: Option<f32>,
}

impl TextureEncodeArgs {
    /// The options asked for, checked (`EncodeOptions::check`) before any work.
    pub fn options(&self) -> Result<EncodeOptions> {
        let o = EncodeOptions {
            codec: self.ktx2.codec(),
            fallback: self.ktx2_fallback,
            specular_aa: !self.no_specular_aa,
            threshold: self.specular_aa_threshold.unwrap_or(DEFAULT_THRESHOLD),
        };
        o.check()?;
        Ok(o)
    }

    /// The first option given that only KTX2 output reads.
    pub fn given(&self) -> Option<&'static str> {
        self.ktx2.given().or(if self.ktx2_fallback {
            Some("--ktx2-fallback")
        } else if self.specular_aa || self.no_specular_aa {
            Some("--specular-aa")
        } else if self.specular_aa_threshold.is_some() {
            Some("--specular-aa-threshold")
        } else {
            None
        })
    }
}

/// Mesh inputs and where their outputs go, shared by `tangents`, `bake` and `textures`.
#[derive(clap::Args, Debug)]
pub struct MeshIo {
    /// Input meshes: .obj (with its .mtl), .gltf or .glb.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Output file (one input): .gltf (with a .bin beside it) or .glb.
    #[arg(short, long, conflicts_with = "out_dir")]
    pub output: Option<PathBuf>,
    /// Extension of the outputs written into --out-dir.
    #[arg(long, value_parser = ["glb", "gltf"], default_value = "glb")]
    pub out_ext: String,
    /// Let URIs reach outside the input's folder.
    #[arg(long)]
    pub allow_outside: bool,
    /// Write a Make/Ninja depfile (one input) listing every file read.
    #[arg(long)]
    pub depfile: Option<PathBuf>,
}

impl MeshIo {
    /// The output path of each input, after checking the options fit the number of inputs.
    pub fn outputs(&self, out_dir: &Option<PathBuf>) -> Result<Vec<PathBuf>> {
        if self.depfile.is_some() && self.inputs.len() > 1 {
            return Err(Error::usage("--depfile takes one input"));
        }
        outputs(&self.inputs, &self.output, out_dir, &self.out_ext)
    }

    /// How each input is read: URIs kept inside its folder unless --allow-outside, and bars for
    /// a lone input.
    pub fn read_options(&self, batch: &BatchArgs) -> bumpbake::scene::ReadOptions {
        bumpbake::scene::ReadOptions {
            allow_outside: self.allow_outside,
            progress: batch.single_progress(self.inputs.len()),
            ..Default::default()
        }
    }

    /// Runs `job` on every input and its output (`outputs`, as [`MeshIo::outputs`] paired them)
    /// and prints the records.
    pub fn run_each<R: super::print::Record + Send>(
        &self,
        outputs: &[PathBuf],
        batch: &BatchArgs,
        job: impl Fn(&Path, &Path) -> Result<R> + Sync,
    ) -> Result<u8> {
        let opts = batch.options(self.inputs.len());
        let results = batch::run(&self.inputs, &opts, |input| job(input, paired(&self.inputs, outputs, input)))?;
        super::print::all(&self.inputs, results, batch.json, batch.quiet)
    }
}

/// The options every command over many inputs shares.
#[derive(clap::Args, Debug)]
pub struct BatchArgs {
    /// Output folder (any number of inputs); names follow the inputs.
    #[arg(long)]
    pub out_dir: Option<PathBuf>,
    /// Files processed at once (default: one per core).
    #[arg(short, long, default_value_t = 0)]
    pub jobs: usize,
    /// Print one JSON record per file on stdout (JSON Lines).
    #[arg(long)]
    pub json: bool,
    /// Show a progress bar even when not on a terminal.
    #[arg(long)]
    pub progress: bool,
    /// No report on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

impl BatchArgs {
    /// How to run `inputs`: a bar over the files when there are several and a person watches.
    pub fn options(&self, inputs: usize) -> BatchOptions {
        let bar = inputs > 1 && super::progress_bars::wanted(self.progress, self.quiet || self.json);
        BatchOptions { jobs: self.jobs, progress: super::progress_bars::reporter(bar) }
    }

    /// Bars for one input's reads and bakes, when it is the only one and a person watches.
    pub fn single_progress(&self, inputs: usize) -> bumpbake::progress::Reporter {
        super::progress_bars::reporter(
            inputs == 1 && super::progress_bars::wanted(self.progress, self.quiet || self.json),
        )
    }
}

/// Output paths for the inputs: `-o` for one input, or names derived into `--out-dir`.
pub fn outputs(
    inputs: &[PathBuf],
    output: &Option<PathBuf>,
    out_dir: &Option<PathBuf>,
    ext: &str,
) -> Result<Vec<PathBuf>> {
    let outs: Vec<PathBuf> = match (output, out_dir) {
        (Some(o), None) if inputs.len() == 1 => vec![o.clone()],
        (Some(_), None) => return Err(Error::usage("several inputs need --out-dir, not -o")),
        (None, Some(d)) => {
            std::fs::create_dir_all(d).map_err(|e| Error::output(d, e))?;
            inputs.iter().map(|i| batch::derived_output(i, d, ext)).collect()
        }
        _ => return Err(Error::usage("give -o OUT (one input) or --out-dir DIR")),
    };
    batch::unique_outputs(&outs)?;
    Ok(outs)
}

/// The output paired with `input` in a batch.
pub fn paired<'a>(inputs: &[PathBuf], outputs: &'a [PathBuf], input: &Path) -> &'a Path {
    &outputs[inputs.iter().position(|i| i == input).expect("input in batch")]
}
