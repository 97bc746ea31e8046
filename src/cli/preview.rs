//! `bumpbake preview IN -o OUT.png` and `bumpbake preview --reference A --compare B -o diff.png`.

use bumpbake::preview::compare::DiffKind;
use bumpbake::preview::{
    compare_files, render_file, CameraSpec, Comparing, Light, Mips, Options, Params, Resolve, Shading, View,
};
use bumpbake::scene::ReadOptions;
use bumpbake::{Error, Result};
use clap::builder::PossibleValue;
use std::path::PathBuf;
use std::sync::LazyLock;

/// Render an asset with the reference bump-mapping model (shaders/) on the CPU, or measure pipeline error.
#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake preview fixtures/khronos/NormalTangentMirrorTest.glb -o mirror.png --size 384x384 --ssaa 2
  bumpbake preview fixtures/spot/spot.obj -o spot.png --yaw 150 --pitch 15 --light dir:-1,-1,-1 --light point:0,1,2@0.4
  bumpbake preview --reference high.glb --compare low.glb -o diff.png --json
  bumpbake preview --reference plane.gltf --reference-mips off --reference-ssaa 16 --compare plane-ktx2.gltf --shading pbr -o diff.png")]
pub struct Args {
    /// Input mesh: .glb, .gltf or .obj (with its .mtl).
    pub input: Option<PathBuf>,
    /// Output image (.png).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "512x512", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Supersampling: N x N samples per pixel (1 to 32), box-filtered.
    #[arg(long, default_value_t = 1)]
    pub ssaa: u32,
    /// Where textures' mip levels come from: off (level 0 only; the supersampled truth), box
    /// (the renderer's own 2x2 box chain, as generateMipmap makes), file (a KTX2's own levels,
    /// else box).
    #[arg(long, value_enum, default_value_t = MipsArg::from(Mips::default()))]
    pub mips: MipsArg,
    /// Lighting model: the course notes' Blinn-Phong, or glTF's metallic-roughness BRDF as
    /// three.js's MeshStandardMaterial shades it.
    #[arg(long, value_enum, default_value_t = ShadingArg::from(Shading::default()))]
    pub shading: ShadingArg,
    /// With --shading pbr and --ssaa: clamped (each sample clamped to white, then averaged: a plain
    /// canvas's MSAA) or hdr (linear radiance averaged, then clamped: an HDR target's resolve).
    #[arg(long, value_enum, default_value_t = ResolveArg::from(Resolve::default()))]
    pub resolve: ResolveArg,
    /// Camera rotation about +Y in degrees (0 looks from +Z) [default: 0, or facing a flat
    /// object].
    #[arg(long, allow_negative_numbers = true)]
    pub yaw: Option<f32>,
    /// Camera elevation in degrees (positive looks down) [default: 0, or facing a flat object].
    #[arg(long, allow_negative_numbers = true)]
    pub pitch: Option<f32>,
    /// Camera distance from the centre of the bounds (default: fit the bounds).
    #[arg(long)]
    pub distance: Option<f32>,
    /// Vertical field of view in degrees.
    #[arg(long, default_value_t = 40.0)]
    pub fov: f32,
    /// A light: dir:x,y,z (travelling along x,y,z), point:x,y,z or spot:x,y,z:dx,dy,dz:angle,
    /// each optionally followed by @intensity. Repeat for several; none gives a default rig.
    #[arg(long, allow_hyphen_values = true)]
    pub light: Vec<String>,
    /// What to show.
    #[arg(long, value_enum, default_value = "shaded")]
    pub view: ViewArg,
    /// Pipeline error: the true surface (fine geometry with its own normals).
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// Pipeline error: the asset to measure against the reference (or against IN).
    #[arg(long)]
    pub compare: Option<PathBuf>,
    /// Compare mode: --mips for the reference render (default: as --mips).
    #[arg(long, value_enum)]
    pub reference_mips: Option<MipsArg>,
    /// Compare mode: --ssaa for the reference render (default: as --ssaa); the truth takes 16.
    #[arg(long)]
    pub reference_ssaa: Option<u32>,
    /// What the difference image shows in compare mode.
    #[arg(long, value_enum, default_value_t = DiffArg::from(DiffKind::default()))]
    pub diff: DiffArg,
    /// Ambient term (fraction of the base colour).
    #[arg(long, default_value_t = 0.06)]
    pub ambient: f32,
    /// Specular intensity.
    #[arg(long, default_value_t = 0.25)]
    pub specular: f32,
    /// Blinn-Phong exponent.
    #[arg(long, default_value_t = 32.0)]
    pub shininess: f32,
    /// Let URIs reach outside the input's folder.
    #[arg(long)]
    pub allow_outside: bool,
    /// Print the report (and comparison figures) as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// No report on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

/// What `--view` takes: every view the library renders, and `diff` for `--compare`. The values
/// and their names are the library's `View`; this only adds `diff` and keeps clap out of it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewArg {
    Render(View),
    /// The difference between IN (or --reference) and --compare.
    Diff,
}

impl clap::ValueEnum for ViewArg {
    fn value_variants<'a>() -> &'a [Self] {
        static ALL: LazyLock<Vec<ViewArg>> =
            LazyLock::new(|| View::ALL.iter().map(|&v| ViewArg::Render(v)).chain([ViewArg::Diff]).collect());
        &ALL
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        Some(match self {
            ViewArg::Render(v) => PossibleValue::new(v.name()),
            ViewArg::Diff => {
                PossibleValue::new("diff").help("The difference between IN (or --reference) and --compare")
            }
        })
    }
}

super::args::arg_enum! {
    /// What the difference image shows ([`DiffKind`]).
    pub enum DiffArg => DiffKind {
        Angle => Angle,
        Shaded => Shaded,
    }
}

super::args::arg_enum! {
    /// Where mip levels come from ([`Mips`]).
    pub enum MipsArg => Mips {
        Off => Off,
        Box => Box,
        File => File,
    }
}

super::args::arg_enum! {
    /// How a physically based pixel averages its samples ([`Resolve`]).
    pub enum ResolveArg => Resolve {
        Clamped => Clamped,
        Hdr => Hdr,
    }
}

super::args::arg_enum! {
    /// The lighting model ([`Shading`]).
    pub enum ShadingArg => Shading {
        BlinnPhong => BlinnPhong,
        Pbr => Pbr,
    }
}

fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("'{s}' is not WIDTHxHEIGHT"))?;
    let p = |v: &str| {
        v.trim()
            .parse::<u32>()
            .ok()
            .filter(|&x| (1..=16384).contains(&x))
            .ok_or_else(|| format!("'{s}': sizes are 1 to 16384"))
    };
    Ok((p(w)?, p(h)?))
}

pub fn run(a: Args) -> Result<u8> {
    if a.output.extension().and_then(|e| e.to_str()).map(|e| e.eq_ignore_ascii_case("png")) != Some(true) {
        return Err(Error::usage(format!("{}: the preview is written as PNG; name it .png", a.output.display())));
    }
    let lights =
        a.light.iter().map(|l| Light::parse(l)).collect::<std::result::Result<Vec<_>, _>>().map_err(Error::usage)?;
    let view = match a.view {
        ViewArg::Render(v) => v,
        // The difference of the shaded renders (or of their normals, by --diff).
        ViewArg::Diff => View::Shaded,
    };
    let opts = Options {
        width: a.size.0,
        height: a.size.1,
        ssaa: a.ssaa,
        mips: a.mips.into(),
        resolve: a.resolve.into(),
        camera: CameraSpec {
            yaw: a.yaw.unwrap_or(0.0),
            pitch: a.pitch.unwrap_or(0.0),
            distance: a.distance,
            fov: a.fov,
        },
        lights,
        view,
        params: Params { ambient: a.ambient, specular: a.specular, shininess: a.shininess, shading: a.shading.into() },
    };
    opts.check()?;
    let reference_opts = Options {
        mips: a.reference_mips.map(Into::into).unwrap_or(opts.mips),
        ssaa: a.reference_ssaa.unwrap_or(opts.ssaa),
        ..opts.clone()
    };
    reference_opts.check()?;
    if a.compare.is_none() && (a.reference_mips.is_some() || a.reference_ssaa.is_some()) {
        return Err(Error::usage("preview: --reference-mips and --reference-ssaa need --compare"));
    }
    let read = ReadOptions { allow_outside: a.allow_outside, ..Default::default() };

    if let Some(cand) = &a.compare {
        let reference = match (&a.reference, &a.input) {
            (Some(r), None) => r,
            (None, Some(i)) => i,
            (Some(_), Some(_)) => {
                return Err(Error::usage("preview: give the reference either as IN or as --reference, not both"))
            }
            (None, None) => return Err(Error::usage("preview: --compare needs a reference (IN or --reference)")),
        };
        if !matches!(a.view, ViewArg::Render(View::Shaded) | ViewArg::Diff) {
            return Err(Error::usage("preview: --compare writes the difference image; --view must be shaded or diff"));
        }
        let job =
            Comparing { reference, reference_opts: &reference_opts, compare: cand, opts: &opts, diff: a.diff.into() };
        let done = compare_files(&job, &a.output, &read)?;
        super::print::document(&done, a.json, a.quiet)?;
        return Ok(0);
    }

    if a.view == ViewArg::Diff {
        return Err(Error::usage("preview: --view diff needs --compare OTHER"));
    }
    if a.reference.is_some() {
        return Err(Error::usage("preview: --reference needs --compare"));
    }
    let input = a.input.as_ref().ok_or_else(|| Error::usage("preview: no input file"))?;
    let done = render_file(input, &a.output, &opts, &read, a.yaw.is_some() || a.pitch.is_some())?;
    super::print::document(&done, a.json, a.quiet)?;
    Ok(0)
}
