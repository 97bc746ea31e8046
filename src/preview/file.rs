//! The `preview` command's work, file to file: read a scene, render it (or two, and their
//! difference) and write the PNG atomically, returning what a front end reports
//! (`docs/json.md`, preview).

use super::compare::{compare_with, Comparison, DiffKind};
use super::{render, Camera, Facing, Options, Prepared, View};
use crate::output::write_atomic;
use crate::scene::ReadOptions;
use crate::Result;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// One picture rendered (`--json`: `docs/json.md`, preview).
#[derive(Debug, serde::Serialize)]
pub struct Rendered {
    pub input: PathBuf,
    pub output: PathBuf,
    pub view: &'static str,
    pub width: u32,
    pub height: u32,
    pub ssaa: u32,
    pub triangles: usize,
    pub camera: CameraReport,
    pub notes: Vec<String>,
    pub time_ms: f64,
    pub stages: Stages,
}

/// Where the picture was taken from.
#[derive(Debug, serde::Serialize)]
pub struct CameraReport {
    /// Degrees, as used.
    pub yaw: f32,
    pub pitch: f32,
    /// `front` (the default), `given` (angles the caller chose), or the view turned to face a
    /// flat object: `top`, `bottom`, `right`, `left`, `back`.
    pub view: &'static str,
    /// Why the view was turned, when it was.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub flat: Option<String>,
}

/// Where a preview's time went, in milliseconds.
#[derive(Debug, serde::Serialize)]
pub struct Stages {
    pub read_ms: f64,
    pub prepare_ms: f64,
    pub render_ms: f64,
    pub write_ms: f64,
}

/// The difference between two renders of the same view (`docs/preview.md`).
#[derive(Debug, serde::Serialize)]
pub struct Compared {
    pub reference: PathBuf,
    pub compare: PathBuf,
    pub output: PathBuf,
    pub time_ms: f64,
    pub comparison: Comparison,
}

/// Renders `input` with `opts` and writes the picture to `output` as PNG. `angles_given`: the
/// camera's yaw and pitch are the caller's; otherwise the default view turns to face a flat
/// object rather than its edge.
pub fn render_file(
    input: &Path,
    output: &Path,
    opts: &Options,
    read: &ReadOptions,
    angles_given: bool,
) -> Result<Rendered> {
    let start = Instant::now();
    let scene = crate::format::read(input, read)?;
    let t_read = start.elapsed().as_secs_f64() * 1e3;
    let prep = Prepared::with_frames(&scene, matches!(opts.view, View::Tangent | View::Bitangent | View::Handedness))?;
    let t_prep = start.elapsed().as_secs_f64() * 1e3;
    let facing = if angles_given { None } else { Facing::for_flat(prep.bounds, prep.face_normal()) };
    let spec = facing.map_or(opts.camera, |f| opts.camera.facing(f, prep.bounds, opts.width, opts.height));
    let cam = Camera::framed(prep.bounds, &spec, opts.width, opts.height);
    let frame = render(&prep, &cam, opts);
    let t_render = start.elapsed().as_secs_f64() * 1e3;
    write_atomic(output, &frame.to_png())?;
    let ms = start.elapsed().as_secs_f64() * 1e3;
    Ok(Rendered {
        input: input.to_path_buf(),
        output: output.to_path_buf(),
        view: opts.view.name(),
        width: opts.width,
        height: opts.height,
        ssaa: opts.ssaa,
        triangles: prep.triangle_count(),
        camera: CameraReport {
            yaw: spec.yaw,
            pitch: spec.pitch,
            view: match (facing, angles_given) {
                (Some(f), _) => f.name(),
                (None, true) => "given",
                (None, false) => "front",
            },
            flat: facing.map(|f| format!("flat in {}: {} view, from {}", f.plane(), f.name(), f.axis())),
        },
        notes: prep.notes,
        time_ms: ms,
        stages: Stages {
            read_ms: t_read,
            prepare_ms: t_prep - t_read,
            render_ms: t_render - t_prep,
            write_ms: ms - t_render,
        },
    })
}

/// What [`compare_files`] compares: the true surface and the asset measured against it, each
/// with its own render options.
pub struct Comparing<'a> {
    pub reference: &'a Path,
    pub reference_opts: &'a Options,
    pub compare: &'a Path,
    pub opts: &'a Options,
    pub diff: DiffKind,
}

/// Renders both scenes of `job` from the same camera and writes their difference to `output`
/// as PNG.
pub fn compare_files(job: &Comparing, output: &Path, read: &ReadOptions) -> Result<Compared> {
    let start = Instant::now();
    let r = crate::format::read(job.reference, read)?;
    let c = crate::format::read(job.compare, read)?;
    let (comparison, img) = compare_with(&r, job.reference_opts, &c, job.opts, job.diff)?;
    write_atomic(output, &img.to_png())?;
    Ok(Compared {
        reference: job.reference.to_path_buf(),
        compare: job.compare.to_path_buf(),
        output: output.to_path_buf(),
        time_ms: start.elapsed().as_secs_f64() * 1e3,
        comparison,
    })
}
