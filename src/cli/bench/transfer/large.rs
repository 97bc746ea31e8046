//! `bench transfer`'s production-scale rows: `bake --from` with a HIGH of 10 to 50 million
//! triangles (the bench's displaced torus, finer), generated in memory or read from the OBJ and
//! binary PLY files the bench writes, onto the same LOW at 2048²: stage times, peak memory and
//! bytes per HIGH triangle.

use super::row::time_one;
use bumpbake::analytic::torus::{evaluate, Evaluation, Torus};
use bumpbake::error::{Error, Result};
use bumpbake::transfer::high::HighMesh;
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::TAU;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Where a large row's HIGH comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Source {
    /// Generated in the bench's own process and handed to the baker: no reader.
    Memory,
    Obj,
    Ply,
}

impl Source {
    /// As `--large-from` spells it.
    pub fn name(self) -> &'static str {
        match self {
            Source::Memory => "memory",
            Source::Obj => "obj",
            Source::Ply => "ply",
        }
    }

    pub fn parse(s: &str) -> Option<Source> {
        [Source::Memory, Source::Obj, Source::Ply].into_iter().find(|x| x.name() == s.trim())
    }
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct LargeRow {
    pub high_triangles: usize,
    pub source: Source,
    pub size: usize,
    /// The HIGH file's size (0 in memory).
    pub file_mb: f64,
    /// The bake, from reading HIGH to the written OUT (for memory rows: in the bench's process);
    /// NaN when only the reader was timed.
    pub wall_s: f64,
    /// CPU time of the bake (user and system, every thread), seconds: the machine's other load
    /// does not inflate it as it does the wall time.
    pub cpu_s: f64,
    pub read_high_ms: f64,
    /// The file's size over the bake's read stage (0 in memory).
    pub read_mb_s: f64,
    pub bvh_ms: f64,
    pub rays_ms: f64,
    /// Peak resident memory of the bake, all included.
    pub peak_mb: f64,
    pub bytes_per_triangle: f64,
    /// What the baker's HIGH (tree, positions, triangles, normals) takes alone, per triangle.
    pub high_bytes_per_triangle: f64,
    pub error: Evaluation,
    /// FNV-1a 64 of OUT: the same HIGH from memory, OBJ and PLY bakes the same bytes.
    pub out_fingerprint: String,
    /// Runs of a file row (a memory row runs once); `wall_s` and the stages are medians.
    pub runs: usize,
    /// Blender's bake of the same files, interleaved (`--blender`, file rows only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub blender: Option<super::blender::BlenderRow>,
    /// The reader alone (`transfer::high::read_high` in the bench's process), for file rows.
    pub reader: Option<ReadTiming>,
}

/// `read_high` on a large row's file, timed in the bench's process (the file in the page cache).
#[derive(Debug, Clone, serde::Serialize)]
pub struct ReadTiming {
    pub runs: usize,
    pub median_ms: f64,
    pub min_ms: f64,
    /// The file's size over the median time.
    pub mb_s: f64,
    /// CPU time (user and system, every thread) of the median run, ms.
    pub cpu_ms: f64,
}

/// The tessellation with about `millions` million triangles, the ring twice the tube's count.
pub fn tessellation(millions: f64) -> (usize, usize) {
    let quads = millions * 1e6 / 2.0;
    let n_ph = (quads / 2.0).sqrt().round().max(1.0) as usize;
    (2 * n_ph, n_ph)
}

/// HIGH as [`Torus::high`] makes it, straight into the baker's form, built in parallel.
fn high_raw(torus: &Torus, n_th: usize, n_ph: usize) -> HighMesh {
    let vn: Vec<([f32; 3], [f32; 3])> = (0..n_th * n_ph)
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k % n_th, k / n_th);
            let (p, n) = torus.point_normal(TAU * i as f64 / n_th as f64, TAU * j as f64 / n_ph as f64);
            (p.as_vec3().to_array(), n.as_vec3().to_array())
        })
        .collect();
    let (positions, normals) = vn.into_iter().unzip();
    let triangles: Vec<[u32; 3]> = (0..n_th * n_ph)
        .into_par_iter()
        .flat_map_iter(|k| {
            let (i, j) = (k % n_th, k / n_th);
            let v = |i: usize, j: usize| ((j % n_ph) * n_th + (i % n_th)) as u32;
            let (a, b, c, d) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
            [[a, b, c], [a, c, d]]
        })
        .collect();
    let parts = vec![bumpbake::transfer::high::Part { name: "torus".into(), material: None, start: 0 }];
    HighMesh { positions, normals, normal_triangles: triangles.clone(), triangles, parts, ..Default::default() }
}

/// Writes `m` as OBJ (`v`, `vn`, `f a//a b//b c//c`), formatted in parallel blocks.
pub fn write_obj(m: &HighMesh, path: &Path) -> Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).map_err(|e| Error::output(path, e))?);
    let io = |e| Error::output(path, e);
    const BLOCK: usize = 1 << 16;
    for chunk in m.positions.chunks(BLOCK * 16).enumerate() {
        let (c, ps) = chunk;
        let base = c * BLOCK * 16;
        let text: Vec<Vec<u8>> = ps
            .par_chunks(BLOCK)
            .enumerate()
            .map(|(b, block)| {
                let mut s = Vec::with_capacity(block.len() * 80);
                for (k, p) in block.iter().enumerate() {
                    let n = m.normals[base + b * BLOCK + k];
                    let _ = writeln!(s, "v {} {} {}\nvn {} {} {}", p[0], p[1], p[2], n[0], n[1], n[2]);
                }
                s
            })
            .collect();
        text.iter().try_for_each(|t| f.write_all(t)).map_err(io)?;
    }
    for ts in m.triangles.chunks(BLOCK * 16) {
        let text: Vec<Vec<u8>> = ts
            .par_chunks(BLOCK)
            .map(|block| {
                let mut s = Vec::with_capacity(block.len() * 40);
                for t in block {
                    let [a, b, c] = t.map(|i| i + 1);
                    let _ = writeln!(s, "f {a}//{a} {b}//{b} {c}//{c}");
                }
                s
            })
            .collect();
        text.iter().try_for_each(|t| f.write_all(t)).map_err(io)?;
    }
    f.flush().map_err(io)
}

/// Writes `m` as binary little-endian PLY: float x/y/z/nx/ny/nz, `uchar int` face lists.
pub fn write_ply(m: &HighMesh, path: &Path) -> Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).map_err(|e| Error::output(path, e))?);
    let io = |e| Error::output(path, e);
    let header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment bumpbake bench\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        m.positions.len(),
        m.triangles.len()
    );
    f.write_all(header.as_bytes()).map_err(io)?;
    for (p, n) in m.positions.iter().zip(&m.normals) {
        for c in p.iter().chain(n) {
            f.write_all(&c.to_le_bytes()).map_err(io)?;
        }
    }
    for t in &m.triangles {
        f.write_all(&[3]).map_err(io)?;
        for i in t {
            f.write_all(&i.to_le_bytes()).map_err(io)?;
        }
    }
    f.flush().map_err(io)
}

/// Peak resident memory since the last [`reset_peak`], bytes (Linux; 0 elsewhere).
fn peak_bytes() -> u64 {
    let s = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let kb = s.lines().find(|l| l.starts_with("VmHWM:")).and_then(|l| l.split_whitespace().nth(1)?.parse().ok());
    kb.unwrap_or(0u64) * 1024
}

/// Starts a new peak at the current resident size (Linux's `clear_refs`).
fn reset_peak() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

/// CPU seconds (user and system) used so far by this process (`children: false`) or by its
/// children waited for (`true`); NaN where unknown.
pub(crate) fn cpu_seconds(children: bool) -> f64 {
    #[cfg(unix)]
    {
        let who = if children { libc::RUSAGE_CHILDREN } else { libc::RUSAGE_SELF };
        let mut u = std::mem::MaybeUninit::<libc::rusage>::zeroed();
        // SAFETY: getrusage writes one rusage into the buffer it is given.
        if unsafe { libc::getrusage(who, u.as_mut_ptr()) } == 0 {
            // SAFETY: initialised by the successful call above.
            let u = unsafe { u.assume_init() };
            let s = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
            return s(u.ru_utime) + s(u.ru_stime);
        }
    }
    let _ = children;
    f64::NAN
}

/// Bakes the LOW at `low` from HIGH generated in this process, as `bake` does, and measures it.
fn bake_in_memory(
    low: &Path,
    out: &Path,
    mesh: HighMesh,
    size: usize,
) -> Result<(bumpbake::bake::BakeReport, f64, f64, u64)> {
    use bumpbake::transfer::Settings;
    let job = bumpbake::bake::BakeJob {
        mesh: low.to_path_buf(),
        output: out.to_path_buf(),
        map: bumpbake::bake::MapSource::Transfer(Box::new(Settings {
            highs: vec![PathBuf::from("(generated)")],
            width: size,
            height: size,
            ..Default::default()
        })),
        ..Default::default()
    };
    // The generated mesh is HIGH as a reader would hand it over: it counts in the peak.
    reset_peak();
    let (t, cpu) = (std::time::Instant::now(), cpu_seconds(false));
    let r = bumpbake::bake::run_from(&job, vec![mesh])?;
    Ok((r, t.elapsed().as_secs_f64(), cpu_seconds(false) - cpu, peak_bytes()))
}

/// `read_high` on `path`, `runs` times in this process: the reader alone.
pub fn time_reader(path: &Path, runs: usize) -> Result<ReadTiming> {
    let mut times = Vec::new();
    let mut cpus = Vec::new();
    for _ in 0..runs.max(1) {
        let (t, cpu) = (std::time::Instant::now(), cpu_seconds(false));
        let m = bumpbake::transfer::high::read_high(path, &bumpbake::scene::ReadOptions::default())?;
        times.push(t.elapsed().as_secs_f64() * 1e3);
        cpus.push((cpu_seconds(false) - cpu) * 1e3);
        drop(m);
    }
    let mb = std::fs::metadata(path).map_or(0.0, |m| m.len() as f64 / 1e6);
    let min_ms = super::super::shared::spread(&times).0;
    let median_ms = super::super::shared::median(&mut times);
    Ok(ReadTiming {
        runs: times.len(),
        median_ms,
        min_ms,
        mb_s: mb / median_ms * 1e3,
        cpu_ms: super::super::shared::median(&mut cpus),
    })
}

/// One large row: HIGH of `n_th x n_ph` quads from `source`, LOW at `low`, as `plan` says.
pub fn large_row(
    exe: &Path,
    dir: &Path,
    low: &Path,
    (n_th, n_ph): (usize, usize),
    source: Source,
    plan: &Plan,
) -> Result<LargeRow> {
    let torus = Torus::default();
    let tris = 2 * n_th * n_ph;
    let reach = 0.05 * 2.0 * (torus.major + torus.minor);
    let truth = |p: DVec3, d: DVec3| torus.truth(p, d, reach);
    let mut row = LargeRow {
        high_triangles: tris,
        source,
        size: plan.size,
        file_mb: 0.0,
        wall_s: f64::NAN,
        cpu_s: f64::NAN,
        read_high_ms: f64::NAN,
        read_mb_s: 0.0,
        bvh_ms: f64::NAN,
        rays_ms: f64::NAN,
        peak_mb: f64::NAN,
        bytes_per_triangle: f64::NAN,
        high_bytes_per_triangle: f64::NAN,
        error: Evaluation::default(),
        reader: None,
        out_fingerprint: String::new(),
        runs: 1,
        blender: None,
    };
    let set_peak = |row: &mut LargeRow, peak: f64, high_bytes: f64| {
        row.peak_mb = peak / 1e6;
        row.bytes_per_triangle = peak / tris as f64;
        row.high_bytes_per_triangle = high_bytes / tris as f64;
    };
    if source == Source::Memory {
        if !plan.bake {
            return Ok(row);
        }
        let out = dir.join(format!("out_mem_{tris}.glb"));
        let (r, wall, cpu, peak) = bake_in_memory(low, &out, high_raw(&torus, n_th, n_ph), plan.size)?;
        let tr = r.transfer.ok_or_else(|| Error::usage("bench transfer: the bake made no transfer report"))?;
        let stage = |n: &str| tr.timings_ms.stages.iter().find(|s| s.0 == n).map_or(f64::NAN, |s| s.1);
        row.error = evaluate(&out, &truth, &|_| true)?;
        row.out_fingerprint = std::fs::read(&out).map(|b| super::super::shared::fingerprint(&b)).unwrap_or_default();
        let _ = std::fs::remove_file(&out);
        (row.wall_s, row.cpu_s) = (wall, cpu);
        (row.read_high_ms, row.bvh_ms, row.rays_ms) = (stage("read high"), stage("bvh"), stage("rays"));
        set_peak(&mut row, peak as f64, tr.high_bytes as f64);
        return Ok(row);
    }
    let path = dir.join(format!("high_{tris}.{}", if source == Source::Obj { "obj" } else { "ply" }));
    // A kept file is reused: the writer is deterministic, and a 50M-triangle OBJ takes a while.
    if !(plan.keep && path.exists()) {
        let mesh = high_raw(&torus, n_th, n_ph);
        match source {
            Source::Obj => write_obj(&mesh, &path)?,
            _ => write_ply(&mesh, &path)?,
        }
    }
    row.file_mb = std::fs::metadata(&path).map_or(0.0, |m| m.len() as f64 / 1e6);
    let r = (|| {
        if plan.read_runs > 0 {
            row.reader = Some(time_reader(&path, plan.read_runs)?);
        }
        if plan.bake {
            let cpu = cpu_seconds(true);
            let r = time_one(exe, dir, low, &path, tris, plan.size, 1, plan.runs, &torus, plan.blender.as_ref())?;
            // Blender's runs are children too: CPU time is the bake's only without it.
            row.cpu_s = if plan.blender.is_none() { (cpu_seconds(true) - cpu) / r.runs as f64 } else { f64::NAN };
            (row.wall_s, row.error) = (r.median_s, r.error);
            (row.read_high_ms, row.bvh_ms, row.rays_ms) = (r.read_high_ms, r.bvh_ms, r.rays_ms);
            row.read_mb_s = row.file_mb / r.read_high_ms * 1e3;
            set_peak(&mut row, r.peak_mb * 1e6, r.high_bytes_per_triangle * tris as f64);
            (row.runs, row.blender, row.out_fingerprint) = (r.runs, r.blender, r.out_fingerprint);
        }
        Ok(())
    })();
    if !plan.keep {
        let _ = std::fs::remove_file(&path);
    }
    r.map(|()| row)
}

/// The large rows as a text table.
pub fn table(rows: &[LargeRow]) -> String {
    let mut s = String::from(
        "HIGH tris  from     file MB  size  wall s  CPU s  read ms  read MB/s  bvh ms  rays ms  peak MB  B/tri  (HIGH alone)  mean°  p99°  OUT\n",
    );
    for r in rows {
        s += &format!(
            "{:>9}  {:<7} {:>8.0} {:>5} {:>7.2} {:>6} {:>8.0} {:>10.0} {:>7.0} {:>8.0} {:>8.0} {:>6.0} {:>13.0} {:>6.3} {:>5.3}  {}\n",
            r.high_triangles,
            r.source.name(),
            r.file_mb,
            r.size,
            r.wall_s,
            // Unknown with --blender: the children's CPU time includes Blender's.
            if r.cpu_s.is_finite() { format!("{:.2}", r.cpu_s) } else { "-".into() },
            r.read_high_ms,
            r.read_mb_s,
            r.bvh_ms,
            r.rays_ms,
            r.peak_mb,
            r.bytes_per_triangle,
            r.high_bytes_per_triangle,
            r.error.synced.mean,
            r.error.synced.p99,
            &r.out_fingerprint[..r.out_fingerprint.len().min(8)]
        );
    }
    for r in rows {
        if let Some(b) = &r.blender {
            s += &format!(
                "Blender {} on the same {} ({} triangles), {} runs: median {:.2} s ({:.2}-{:.2}; import {:.2} s, bake {:.2} s), peak {:.0} MB: bumpbake {:.1}x faster, {:.1}x less memory\n",
                b.version,
                r.source.name().to_uppercase(),
                r.high_triangles,
                b.runs,
                b.median_s,
                b.min_s,
                b.max_s,
                b.import_high_s,
                b.bake_s,
                b.peak_mb,
                b.ratio,
                b.peak_mb / r.peak_mb
            );
        }
    }
    let timed: Vec<&LargeRow> = rows.iter().filter(|r| r.reader.is_some()).collect();
    if !timed.is_empty() {
        s += "\nThe reader alone (read_high in the bench's process, median of runs):\n";
        s += "HIGH tris  from     file MB  runs  median ms  min ms   MB/s  CPU ms\n";
        for r in timed {
            let t = r.reader.as_ref().expect("filtered");
            s += &format!(
                "{:>9}  {:<7} {:>8.0} {:>5} {:>10.0} {:>7.0} {:>6.0} {:>7.0}\n",
                r.high_triangles,
                r.source.name(),
                r.file_mb,
                t.runs,
                t.median_ms,
                t.min_ms,
                t.mb_s,
                t.cpu_ms
            );
        }
    }
    s
}

/// Which large rows to run.
#[derive(Debug, Clone, Default)]
pub struct Plan {
    /// HIGH sizes, millions of triangles.
    pub millions: Vec<f64>,
    pub sources: Vec<Source>,
    pub size: usize,
    /// Runs of each file row (medians reported).
    pub runs: usize,
    /// Blender's bake of each file row's files, interleaved with bumpbake's runs.
    pub blender: Option<super::blender::Blender>,
    /// Runs of the reader alone on each file row (0: none).
    pub read_runs: usize,
    /// Whether to bake (false: only the reader is timed).
    pub bake: bool,
    /// Keep the HIGH files in the scratch folder, and reuse those found there.
    pub keep: bool,
}

/// Every row of `plan`, with the bench's LOW written into `dir`.
pub fn run(exe: &Path, dir: &Path, plan: &Plan, mut progress: impl FnMut(&LargeRow)) -> Result<Vec<LargeRow>> {
    let mut rows = Vec::new();
    if plan.millions.is_empty() || plan.sources.is_empty() {
        return Ok(rows);
    }
    std::fs::create_dir_all(dir).map_err(|e| Error::output(dir, e))?;
    let low = dir.join("low.glb");
    std::fs::write(&low, Torus::default().low(48, 24).glb()).map_err(|e| Error::output(&low, e))?;
    for &m in &plan.millions {
        for &source in &plan.sources {
            if source == Source::Memory && !plan.bake {
                continue;
            }
            let r = large_row(exe, dir, &low, tessellation(m), source, plan)?;
            progress(&r);
            rows.push(r);
        }
    }
    Ok(rows)
}
