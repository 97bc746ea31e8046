//! The `tangents` job as a library call: read, generate, write, report.

use super::apply::{apply, ApplyOptions, PrimTangents};
use crate::error::Result;
use crate::format::{self, WriteOptions, WriteStats};
use crate::scene::ReadOptions;
use crate::timings::Timings;
use std::path::{Path, PathBuf};

#[derive(Debug, Clone, Default)]
pub struct TangentsJob {
    pub input: PathBuf,
    pub output: PathBuf,
    pub read: ReadOptions,
    pub apply: ApplyOptions,
    pub write: WriteOptions,
    /// Write a Make/Ninja depfile here.
    pub depfile: Option<PathBuf>,
}

/// Everything the job did; printed as text or JSON by the binary.
#[derive(Debug, Clone, serde::Serialize)]
pub struct TangentsReport {
    pub input: PathBuf,
    pub output: PathBuf,
    pub primitives: Vec<PrimTangents>,
    pub generated: usize,
    pub kept: usize,
    pub skipped: usize,
    pub vertices_in: usize,
    pub vertices_out: usize,
    pub fallback_frames: usize,
    pub notes: Vec<String>,
    pub written: WriteStats,
    pub timings_ms: Timings,
}

/// Runs the job. Nothing is written unless every step succeeds.
pub fn run(job: &TangentsJob) -> Result<TangentsReport> {
    let mut t = Timings::default();
    let mut scene = t.time("read", || crate::format::read(&job.input, &job.read))?;
    crate::timings::mem_mark("read");
    let prims = t.time("tangents", || apply(&mut scene, &job.apply))?;
    crate::timings::mem_mark("tangents");
    let (mut files, written) = t.time("encode", || format::write(&scene, &job.output, &job.write))?;
    crate::timings::mem_mark("encode");
    if let Some(d) = &job.depfile {
        files.add(d, crate::output::depfile(&[&job.output], &scene.dependencies()));
    }
    t.time("write", || files.commit())?;
    crate::timings::mem_mark("write");
    let mut notes = std::mem::take(&mut scene.notes);
    // `bake` converts these; `tangents` leaves them, and says so.
    for h in &scene.height_maps {
        let name = scene.materials().get(h.material).and_then(|m| m.name.as_deref());
        notes.push(format!(
            "material '{}': bump map '{}' is a height map, left out; `bumpbake bake` converts it to a normal map",
            name.unwrap_or("(unnamed)"),
            h.path.file_name().map(|f| f.to_string_lossy()).unwrap_or_default()
        ));
    }
    Ok(summarise(&job.input, &job.output, prims, notes, written, t))
}

fn summarise(
    input: &Path,
    output: &Path,
    prims: Vec<PrimTangents>,
    notes: Vec<String>,
    written: WriteStats,
    t: Timings,
) -> TangentsReport {
    let count = |a: &str| prims.iter().filter(|p| p.action == a).count();
    let stats = prims.iter().filter_map(|p| p.stats.as_ref());
    TangentsReport {
        input: input.to_path_buf(),
        output: output.to_path_buf(),
        generated: count("generated"),
        kept: count("kept"),
        skipped: count("skipped"),
        vertices_in: stats.clone().map(|s| s.vertices_in).sum(),
        vertices_out: stats.clone().map(|s| s.vertices_out).sum(),
        fallback_frames: stats.map(|s| s.fallback.total()).sum(),
        primitives: prims,
        notes,
        written,
        timings_ms: t,
    }
}
