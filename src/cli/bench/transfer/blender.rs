//! Blender's bake of the same files in the same run, for `bench transfer --blender PYTHON`: the
//! baseline the speed targets are ratios against. The script (`blender_bake.py`, written
//! into the scratch folder) imports LOW and HIGH and bakes Cycles' selected-to-active tangent-space
//! normal map at one sample per texel, with cage extrusion and ray distance set to the bench's
//! reach; it reports its own stage times and peak resident memory.

use bumpbake::error::{Error, Result};
use std::path::{Path, PathBuf};

const SCRIPT: &str = include_str!("blender_bake.py");

/// A Python interpreter that imports `bpy` (Blender as a module).
#[derive(Debug, Clone)]
pub struct Blender {
    pub python: PathBuf,
}

/// One Blender run, as the script reports it.
#[derive(Debug, Clone, serde::Deserialize)]
struct Run {
    stages_s: std::collections::BTreeMap<String, f64>,
    peak_mb: f64,
    blender: String,
}

/// Blender's runs of one row: medians of the whole script (wall, measured here) and its stages.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct BlenderRow {
    pub version: String,
    pub runs: usize,
    pub median_s: f64,
    pub min_s: f64,
    pub max_s: f64,
    /// Median of the script's HIGH import and of its bake (Cycles' BVH build and rays).
    pub import_high_s: f64,
    pub bake_s: f64,
    pub peak_mb: f64,
    /// Blender's median over bumpbake's median, the same files in the same run.
    pub ratio: f64,
}

/// Collects one row's Blender runs.
#[derive(Debug, Default)]
pub struct Runs {
    wall: Vec<f64>,
    import_high: Vec<f64>,
    bake: Vec<f64>,
    peak_mb: f64,
    version: String,
}

impl Blender {
    /// Bakes `high` onto `low` at `size`² once, adding the run to `runs`.
    pub fn run(&self, dir: &Path, low: &Path, high: &Path, size: usize, reach: f64, runs: &mut Runs) -> Result<()> {
        let script = dir.join("blender_bake.py");
        if !script.exists() {
            std::fs::write(&script, SCRIPT).map_err(|e| Error::output(&script, e))?;
        }
        let out = dir.join("blender_out.png");
        let t = std::time::Instant::now();
        let o = std::process::Command::new(&self.python)
            .arg(&script)
            .args([low, high, &out])
            .args([size.to_string(), reach.to_string()])
            .output()
            .map_err(|e| {
                Error::usage(format!("bench transfer --blender: cannot run {}: {e}", self.python.display()))
            })?;
        let wall = t.elapsed().as_secs_f64();
        let _ = std::fs::remove_file(&out);
        let stdout = String::from_utf8_lossy(&o.stdout);
        let run: Option<Run> = stdout.lines().rev().find_map(|l| serde_json::from_str(l).ok());
        let Some(run) = run.filter(|_| o.status.success()) else {
            let err = String::from_utf8_lossy(&o.stderr);
            let last = err.lines().rev().find(|l| !l.trim().is_empty()).unwrap_or("no output");
            return Err(Error::usage(format!(
                "bench transfer --blender: {} failed on {} ({last}); give a Python that imports bpy (pip install bpy)",
                self.python.display(),
                high.display()
            )));
        };
        let stage = |n: &str| run.stages_s.get(n).copied().unwrap_or(f64::NAN);
        runs.wall.push(wall);
        runs.import_high.push(stage("import high"));
        runs.bake.push(stage("bake"));
        runs.peak_mb = runs.peak_mb.max(run.peak_mb);
        runs.version = run.blender;
        Ok(())
    }
}

impl Runs {
    /// The row, its ratio taken against bumpbake's median `ours_s`.
    pub fn row(mut self, ours_s: f64) -> BlenderRow {
        let (min_s, max_s) = super::super::shared::spread(&self.wall);
        let median_s = super::super::shared::median(&mut self.wall);
        BlenderRow {
            version: self.version,
            runs: self.wall.len(),
            median_s,
            min_s,
            max_s,
            import_high_s: super::super::shared::median(&mut self.import_high),
            bake_s: super::super::shared::median(&mut self.bake),
            peak_mb: self.peak_mb,
            ratio: median_s / ours_s,
        }
    }
}
