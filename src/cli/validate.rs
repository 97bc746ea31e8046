//! `bumpbake validate IN...`.

use super::print::{github, junit, sarif, validate as report, Human};
use bumpbake::normalmap::Convention;
use bumpbake::scene::ReadOptions;
use bumpbake::validate::{self, Code, Options};
use bumpbake::{Error, Result};
use std::path::PathBuf;

/// Check tangent frames, handedness and normal maps; exit 1 on errors (for CI).
#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake validate model.glb
  bumpbake validate assets/*.gltf --strict --format junit > validate.xml
  bumpbake validate scene.gltf normal.png --format github --allow TANGENT_UNUSED --max-angle-deg 2
  bumpbake validate assets/*.glb --format sarif > bumpbake.sarif")]
pub struct Args {
    /// Inputs: .gltf, .glb, .obj, or normal-map images (.png, .tif, .exr).
    #[arg(required_unless_present = "list_codes")]
    pub inputs: Vec<PathBuf>,
    /// Report format on stdout (a human summary always goes to stderr unless -q).
    #[arg(long, value_enum, default_value = "text")]
    pub format: Format,
    /// Warnings fail too (exit 1).
    #[arg(long)]
    pub strict: bool,
    /// Treat these checks as errors (repeatable, or comma-separated).
    #[arg(long, value_name = "CODE", value_delimiter = ',')]
    pub deny: Vec<String>,
    /// Report these checks as info only, never failing (repeatable, or comma-separated).
    #[arg(long, value_name = "CODE", value_delimiter = ',')]
    pub allow: Vec<String>,
    /// Largest angle between stored and MikkTSpace tangents that still conforms, in degrees.
    #[arg(long, default_value_t = 1.0, value_name = "DEG")]
    pub max_angle_deg: f64,
    /// Convention expected of normal-map images given directly (glTF materials expect opengl).
    #[arg(long, value_enum, default_value = "opengl")]
    pub image_convention: ImageConvention,
    /// Let URIs reach outside the input's folder.
    #[arg(long)]
    pub allow_outside: bool,
    /// List every check code with its default severity, and exit.
    #[arg(long)]
    pub list_codes: bool,
    /// No human summary on stderr.
    #[arg(short, long)]
    pub quiet: bool,
    /// Files checked at once (default: one per core).
    #[arg(short, long, default_value_t = 0)]
    pub jobs: usize,
}

super::args::arg_enum! {
    /// Which way a normal map's green channel is expected to run ([`Convention`]).
    pub enum ImageConvention => Convention {
        /// `+Y` up in the image: OpenGL, glTF, Blender.
        Opengl => Opengl,
        /// `-Y`: DirectX, Unreal, 3ds Max.
        Directx => Directx,
    }
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Text,
    Json,
    Junit,
    Github,
    Sarif,
}

fn codes(list: &[String]) -> Result<Vec<Code>> {
    list.iter().filter(|s| !s.trim().is_empty()).map(|s| s.parse::<Code>().map_err(Error::usage)).collect()
}

pub fn run(a: Args) -> Result<u8> {
    if a.list_codes {
        for c in Code::ALL {
            outln!("{:<26} {:<8} {}", c.as_str(), c.severity().as_str(), c.hint());
        }
        return Ok(0);
    }
    if !(a.max_angle_deg.is_finite() && a.max_angle_deg >= 0.0) {
        return Err(Error::usage(format!(
            "--max-angle-deg must be a non-negative number of degrees, not {}",
            a.max_angle_deg
        )));
    }
    let opts = Options {
        max_angle_deg: a.max_angle_deg,
        strict: a.strict,
        deny: codes(&a.deny)?,
        allow: codes(&a.allow)?,
        image_convention: a.image_convention.into(),
        read: ReadOptions { allow_outside: a.allow_outside, ..Default::default() },
    };
    if let Some(c) = opts.deny.iter().find(|c| opts.allow.contains(c)) {
        return Err(Error::usage(format!("{c} is given to both --deny and --allow")));
    }
    let (rep, failed) = if a.inputs.len() == 1 {
        (validate::validate_paths(&a.inputs, &opts)?, Vec::new())
    } else {
        validate::validate_many(&a.inputs, &opts, a.jobs)?
    };
    match a.format {
        Format::Text => {}
        Format::Json => outln!("{}", report::json(&rep)),
        Format::Junit => out!("{}", junit::junit(&rep)),
        Format::Github => out!("{}", github::github(&rep)),
        Format::Sarif => {
            let unusable: Vec<String> = failed.iter().map(|e| e.to_string()).collect();
            outln!("{}", sarif::sarif(&rep, &unusable))
        }
    }
    if !a.quiet {
        eprint!("{}", rep.human());
    }
    // Unusable files come last, each on its own line; they make the run exit 2.
    for e in &failed {
        eprintln!("bumpbake: {e}");
    }
    Ok(if failed.is_empty() { rep.exit_code() } else { 2 })
}
