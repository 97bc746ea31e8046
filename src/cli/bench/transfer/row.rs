//! One timed `bake --from` configuration of `bench transfer`: the command run as a new process
//! each time, its stages and peak, and the error of its map on the analytic torus.

use bumpbake::analytic::torus::{evaluate, Evaluation, Torus};
use bumpbake::error::{Error, Result};
use std::path::Path;

/// One timed configuration.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Row {
    pub high_triangles: usize,
    pub size: usize,
    pub samples: usize,
    pub runs: usize,
    /// Whole command (a new process each run): median and spread, seconds.
    pub median_s: f64,
    pub min_s: f64,
    pub max_s: f64,
    /// Median stage times of the baker, ms: reading HIGH, building the BVH, casting rays.
    pub read_high_ms: f64,
    pub bvh_ms: f64,
    pub rays_ms: f64,
    pub peak_mb: f64,
    /// What the baker's HIGH (tree, positions, triangles, normals) takes, per triangle.
    pub high_bytes_per_triangle: f64,
    pub error: Evaluation,
    /// FNV-1a 64 of the last run's OUT: equal for equal maps (OUT names no input file).
    pub out_fingerprint: String,
    /// Blender's bake of the same files, interleaved (`--blender`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub blender: Option<super::blender::BlenderRow>,
}

/// Runs `exe bake low --from high` `runs` times and measures the last output.
#[allow(clippy::too_many_arguments)]
pub(crate) fn time_one(
    exe: &Path,
    dir: &Path,
    low: &Path,
    high: &Path,
    tris: usize,
    size: usize,
    samples: usize,
    runs: usize,
    torus: &Torus,
    blender: Option<&super::blender::Blender>,
) -> Result<Row> {
    let out = dir.join(format!("out_{tris}_{size}_{samples}.glb"));
    let reach = 0.05 * 2.0 * (torus.major + torus.minor);
    let (mut times, mut stages, mut peak) = (Vec::new(), [Vec::new(), Vec::new(), Vec::new()], 0u64);
    let mut high_bytes = 0.0;
    let mut theirs = super::blender::Runs::default();
    for _ in 0..runs.max(1) {
        // Interleaved with bumpbake's runs, so both see the same machine.
        if let Some(b) = blender {
            b.run(dir, low, high, size, reach, &mut theirs)?;
        }
        let t = std::time::Instant::now();
        let o = std::process::Command::new(exe)
            .arg("bake")
            .arg(low)
            .arg("--from")
            .arg(high)
            .arg("-o")
            .arg(&out)
            .args(["--size", &size.to_string(), "--samples", &samples.to_string(), "--json"])
            .env("BUMPBAKE_MEMTRACE", "1")
            .output()
            .map_err(|e| Error::usage(format!("bench transfer: cannot run bumpbake: {e}")))?;
        times.push(t.elapsed().as_secs_f64());
        let stderr = String::from_utf8_lossy(&o.stderr);
        if !o.status.success() {
            return Err(Error::usage(format!("bench transfer: bake failed: {}", stderr.trim())));
        }
        peak = peak.max(super::super::command::peak_of(&stderr).unwrap_or(0));
        let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap_or_default();
        high_bytes = j.pointer("/transfer/high_bytes").and_then(|b| b.as_f64()).unwrap_or(f64::NAN);
        let st = j.pointer("/transfer/timings_ms/stages").and_then(|s| s.as_array()).cloned().unwrap_or_default();
        for (k, name) in ["read high", "bvh", "rays"].iter().enumerate() {
            let ms = st.iter().find(|s| s[0] == *name).and_then(|s| s[1].as_f64()).unwrap_or(f64::NAN);
            stages[k].push(ms);
        }
    }
    let error = evaluate(&out, &|p, d| torus.truth(p, d, reach), &|_| true)?;
    let out_fingerprint = std::fs::read(&out).map(|b| super::super::shared::fingerprint(&b)).unwrap_or_default();
    let _ = std::fs::remove_file(&out);
    let (min_s, max_s) = super::super::shared::spread(&times);
    let [mut a, mut b, mut c] = stages;
    let median_s = super::super::shared::median(&mut times);
    Ok(Row {
        high_triangles: tris,
        size,
        samples,
        runs: times.len(),
        median_s,
        min_s,
        max_s,
        read_high_ms: super::super::shared::median(&mut a),
        bvh_ms: super::super::shared::median(&mut b),
        rays_ms: super::super::shared::median(&mut c),
        peak_mb: peak as f64 * 1024.0 / 1e6,
        high_bytes_per_triangle: high_bytes / tris as f64,
        error,
        out_fingerprint,
        blender: blender.map(|_| theirs.row(median_s)),
    })
}
