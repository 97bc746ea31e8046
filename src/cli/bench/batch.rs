//! `bumpbake bench batch`: a batch of small assets through `bake -j N` against one process each.

use bumpbake::error::{Error, Result};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake bench batch
  bumpbake bench batch --assets 50 --jobs 2 --runs 5 --json")]
pub struct BenchBatchArgs {
    /// How many small assets to bake.
    #[arg(long, default_value_t = 200)]
    pub assets: usize,
    /// Files at once in the batched run.
    #[arg(long, default_value_t = 2)]
    pub jobs: usize,
    /// Timed runs of each way; medians are reported.
    #[arg(long, default_value_t = 3)]
    pub runs: usize,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: BenchBatchArgs) -> Result<u8> {
    let r = super::shared::with_scratch("batch", |exe, dir| measure(exe, dir, a.assets, a.jobs, a.runs))?;
    super::shared::print(&r, a.json, |r| {
        format!(
            "{} assets: one process each {:.0} ms, one batch with -j {} {:.0} ms (medians of {}): ratio {:.2} (target <= 0.6)",
            r.assets, r.one_by_one_ms, r.jobs, r.batch_ms, r.runs, r.ratio
        )
    })?;
    Ok(0)
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct BatchBench {
    pub assets: usize,
    pub jobs: usize,
    pub runs: usize,
    pub one_by_one_ms: f64,
    pub batch_ms: f64,
    /// batch / one-by-one; the target is at most 0.6.
    pub ratio: f64,
}

/// Writes `n` small OBJ + MTL + height-map assets into `dir`; returns the OBJ paths.
pub fn make_assets(dir: &Path, n: usize) -> Result<Vec<PathBuf>> {
    let err = |e: std::io::Error| Error::output(dir, e);
    std::fs::create_dir_all(dir).map_err(err)?;
    let (nu, nv) = (24usize, 12usize);
    let mut obj = String::from("mtllib m.mtl\n");
    for j in 0..=nv {
        for i in 0..=nu {
            let (u, v) = (std::f32::consts::TAU * i as f32 / nu as f32, std::f32::consts::TAU * j as f32 / nv as f32);
            let (x, y, z) = ((1.0 + 0.3 * v.cos()) * u.cos(), 0.3 * v.sin(), (1.0 + 0.3 * v.cos()) * u.sin());
            obj += &format!("v {x} {y} {z}\nvt {} {}\n", i as f32 / nu as f32, j as f32 / nv as f32);
        }
    }
    obj += "usemtl m\n";
    let w = nu + 1;
    for j in 0..nv {
        for i in 0..nu {
            let a = j * w + i + 1;
            obj += &format!("f {a}/{a} {}/{} {}/{} {}/{}\n", a + 1, a + 1, a + w + 1, a + w + 1, a + w, a + w);
        }
    }
    let height = image::GrayImage::from_fn(64, 64, |x, y| image::Luma([((x * 7 + y * 3) % 64 * 4) as u8]));
    let mut paths = Vec::with_capacity(n);
    for k in 0..n {
        let sub = dir.join(format!("asset{k:03}"));
        std::fs::create_dir_all(&sub).map_err(err)?;
        std::fs::write(sub.join(format!("asset{k:03}.obj")), &obj).map_err(err)?;
        std::fs::write(sub.join("m.mtl"), "newmtl m\nKd 0.7 0.7 0.7\nbump h.png\n").map_err(err)?;
        height.save(sub.join("h.png")).map_err(|e| Error::output(&sub, e))?;
        paths.push(sub.join(format!("asset{k:03}.obj")));
    }
    Ok(paths)
}

fn run_ok(cmd: &mut Command) -> Result<()> {
    let out = cmd.output().map_err(|e| Error::usage(format!("bench batch: cannot run bumpbake: {e}")))?;
    if !out.status.success() {
        return Err(Error::usage(format!("bench batch: bake failed: {}", String::from_utf8_lossy(&out.stderr).trim())));
    }
    Ok(())
}

/// Times both ways `runs` times each, alternating, and reports medians.
fn measure(exe: &Path, dir: &Path, n: usize, jobs: usize, runs: usize) -> Result<BatchBench> {
    let assets = make_assets(&dir.join("in"), n)?;
    let out = dir.join("out");
    let (mut seq, mut par) = (Vec::new(), Vec::new());
    for _ in 0..runs.max(1) {
        let _ = std::fs::remove_dir_all(&out);
        std::fs::create_dir_all(&out).map_err(|e| Error::output(&out, e))?;
        let t = Instant::now();
        for a in &assets {
            let o = out.join(a.file_stem().unwrap_or_default()).with_extension("glb");
            run_ok(Command::new(exe).arg("bake").arg(a).arg("-o").arg(o).arg("-q").env("RAYON_NUM_THREADS", "1"))?;
        }
        seq.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        run_ok(
            Command::new(exe)
                .arg("bake")
                .args(&assets)
                .arg("--out-dir")
                .arg(&out)
                .arg("-j")
                .arg(jobs.to_string())
                .arg("-q"),
        )?;
        par.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let (one_by_one_ms, batch_ms) = (super::shared::median(&mut seq), super::shared::median(&mut par));
    Ok(BatchBench { assets: n, jobs, runs: runs.max(1), one_by_one_ms, batch_ms, ratio: batch_ms / one_by_one_ms })
}
