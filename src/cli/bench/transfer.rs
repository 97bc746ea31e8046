//! `bumpbake bench transfer`: `bake --from` on an analytic surface, error against run time.

mod blender;
mod large;
mod row;

use bumpbake::analytic::torus::Torus;
use bumpbake::{Error, Result};
use large::{Plan, Source};
use row::{time_one, Row};
use std::path::Path;

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake bench transfer
  bumpbake bench transfer --runs 7 --json > transfer-bench.json
  bumpbake bench transfer --runs 0 --large 10 --large-from memory,obj
  bumpbake bench transfer --runs 0 --large 10.24 --large-from obj --large-runs 3 --blender python3
  bumpbake bench transfer --runs 0 --large 2 --large-from obj,ply --large-size 256
  bumpbake bench transfer --runs 0 --large 2 --large-from obj,ply --read-only --keep /tmp/high")]
pub struct BenchTransferArgs {
    /// Timed runs of each configuration (each a new process); medians are reported. 0 skips the
    /// 600k-and-below rows.
    #[arg(long, default_value_t = 5)]
    pub runs: usize,
    /// Map size and samples per axis of the error-against-time rows, as SIZE:N, comma-separated.
    #[arg(long, default_value = "512:1,1024:1,1024:2,2048:1,2048:2")]
    pub quality: String,
    /// Production-scale HIGH sizes, millions of triangles, comma-separated (`none` for none); each
    /// runs once per source, at --large-size.
    #[arg(long, default_value = "10,50")]
    pub large: String,
    /// Where the large HIGH comes from: memory (generated in this process), obj, ply (files the
    /// bench writes to its scratch folder).
    #[arg(long, default_value = "memory,obj,ply")]
    pub large_from: String,
    /// Map size of the large rows.
    #[arg(long, default_value_t = 2048)]
    pub large_size: usize,
    /// Runs of each large row read from a file (medians reported); memory rows run once.
    #[arg(long, default_value_t = 1)]
    pub large_runs: usize,
    /// A Python that imports `bpy` (Blender as a module): Blender bakes each large file row's
    /// files too, interleaved with bumpbake's runs, and the row gives the ratio.
    #[arg(long, value_name = "PYTHON")]
    pub blender: Option<std::path::PathBuf>,
    /// Also time the reader alone (`read_high`, in this process) this many times on each large
    /// row's OBJ or PLY file, for its MB/s.
    #[arg(long, default_value_t = 3)]
    pub large_read: usize,
    /// Time only the reader on the large rows' files: no bake (memory rows are skipped).
    #[arg(long)]
    pub read_only: bool,
    /// Use DIR as the scratch folder and keep what is written there; large HIGH files found
    /// there are reused (for profiling the reader or a bake on them).
    #[arg(long, value_name = "DIR")]
    pub keep: Option<std::path::PathBuf>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: BenchTransferArgs) -> Result<u8> {
    let quality = a
        .quality
        .split(',')
        .map(|q| {
            let (s, n) = q.split_once(':').unwrap_or((q, "1"));
            match (s.trim().parse::<usize>(), n.trim().parse::<usize>()) {
                (Ok(s), Ok(n)) if s > 0 && (1..=8).contains(&n) => Ok((s, n)),
                _ => Err(Error::usage(format!("--quality {q}: give SIZE:N, e.g. 1024:2"))),
            }
        })
        .collect::<Result<Vec<_>>>()?;
    let millions = if a.large.trim() == "none" {
        Vec::new()
    } else {
        a.large
            .split(',')
            .map(|m| match m.trim().parse::<f64>() {
                Ok(v) if v > 0.0 && v <= 200.0 => Ok(v),
                _ => Err(Error::usage(format!("--large {m}: give millions of triangles, e.g. 10,50 (or none)"))),
            })
            .collect::<Result<Vec<_>>>()?
    };
    let sources = a
        .large_from
        .split(',')
        .map(|s| Source::parse(s).ok_or_else(|| Error::usage(format!("--large-from {s}: memory, obj or ply"))))
        .collect::<Result<Vec<_>>>()?;
    if !(1..=8192).contains(&a.large_size) {
        return Err(Error::usage("--large-size: 1 to 8192 texels"));
    }
    let blender = a.blender.clone().map(|python| blender::Blender { python });
    let plan = Plan {
        millions,
        sources,
        size: a.large_size,
        runs: a.large_runs.max(1),
        blender,
        read_runs: a.large_read,
        bake: !a.read_only,
        keep: a.keep.is_some(),
    };
    let quiet = a.json;
    let body = |exe: &std::path::Path, dir: &std::path::Path| {
        let mut r = if a.runs == 0 || a.read_only {
            Report::empty()
        } else {
            measure(exe, dir, &quality, a.runs, a.keep.is_some(), |row| {
                if !quiet {
                    eprintln!(
                        "  {} triangles, {}², {} sample(s): {:.3} s, {:.3}° mean",
                        row.high_triangles,
                        row.size,
                        row.samples * row.samples,
                        row.median_s,
                        row.error.synced.mean
                    );
                }
            })?
        };
        r.large = large::run(exe, dir, &plan, |row| {
            if !quiet {
                eprintln!(
                    "  {} triangles from {:?}, {}²: {:.2} s, peak {:.0} MB ({:.0} B/triangle), {:.3}° mean",
                    row.high_triangles,
                    row.source,
                    row.size,
                    row.wall_s,
                    row.peak_mb,
                    row.bytes_per_triangle,
                    row.error.synced.mean
                );
            }
        })?;
        Ok(r)
    };
    let r = match &a.keep {
        Some(dir) => {
            let exe = std::env::current_exe()
                .map_err(|e| Error::usage(format!("bench transfer: cannot find bumpbake itself: {e}")))?;
            body(&exe, dir)?
        }
        None => super::shared::with_scratch("transfer", body)?,
    };
    super::shared::print(&r, a.json, table)?;
    Ok(0)
}

/// Writes the bench's HIGH (`n_th x n_ph` quads) and the 48 x 24 LOW into `dir`.
pub fn write_case(
    dir: &Path,
    torus: &Torus,
    n_th: usize,
    n_ph: usize,
) -> Result<(std::path::PathBuf, std::path::PathBuf)> {
    std::fs::create_dir_all(dir).map_err(|e| Error::output(dir, e))?;
    let high = dir.join(format!("high_{}.glb", 2 * n_th * n_ph));
    let low = dir.join("low.glb");
    std::fs::write(&high, torus.high(n_th, n_ph).glb()).map_err(|e| Error::output(&high, e))?;
    std::fs::write(&low, torus.low(48, 24).glb()).map_err(|e| Error::output(&low, e))?;
    Ok((high, low))
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct Report {
    pub torus: String,
    pub low_triangles: usize,
    pub threads: usize,
    /// Error and time for map sizes and sample counts (HIGH at its largest but one).
    pub quality: Vec<Row>,
    /// Time against HIGH's triangle count (1024², one sample).
    pub scaling: Vec<Row>,
    /// Production-scale HIGH (millions of triangles) from memory and from files.
    pub large: Vec<large::LargeRow>,
}

/// The HIGH tessellations of the scaling series: quads around the ring and around the tube.
pub const HIGHS: [(usize, usize); 4] = [(274, 68), (548, 137), (1096, 274), (1550, 387)];

impl Report {
    /// A report with no rows yet.
    pub fn empty() -> Report {
        let t = Torus::default();
        Report {
            torus: describe(&t),
            low_triangles: 2 * 48 * 24,
            threads: rayon::current_num_threads(),
            quality: Vec::new(),
            scaling: Vec::new(),
            large: Vec::new(),
        }
    }
}

fn describe(t: &Torus) -> String {
    format!("R {} r {} displaced by {}·(sin 8θ sin 4φ + ½ cos(3θ+6φ)); LOW 48x24 quads", t.major, t.minor, t.amp)
}

/// The whole bench: `quality` lists `(size, samples)` pairs run on the 600k-triangle HIGH; `keep`
/// leaves the cases in `dir`.
fn measure(
    exe: &Path,
    dir: &Path,
    quality: &[(usize, usize)],
    runs: usize,
    keep: bool,
    mut progress: impl FnMut(&Row),
) -> Result<Report> {
    let torus = Torus::default();
    let mut scaling = Vec::new();
    let mut rows = Vec::new();
    for (k, &(a, b)) in HIGHS.iter().enumerate() {
        let (high, low) = write_case(dir, &torus, a, b)?;
        let tris = 2 * a * b;
        if k == 2 {
            for &(size, samples) in quality {
                let r = time_one(exe, dir, &low, &high, tris, size, samples, runs, &torus, None)?;
                progress(&r);
                rows.push(r);
            }
        }
        let r = time_one(exe, dir, &low, &high, tris, 1024, 1, runs, &torus, None)?;
        progress(&r);
        scaling.push(r);
        if !keep {
            let _ = std::fs::remove_file(&high);
        }
    }
    Ok(Report {
        torus: describe(&torus),
        low_triangles: 2 * 48 * 24,
        threads: rayon::current_num_threads(),
        quality: rows,
        scaling,
        large: Vec::new(),
    })
}

/// The report as a text table.
pub fn table(r: &Report) -> String {
    let mut s = format!("{}; {} threads\n", r.torus, r.threads);
    s += "HIGH tris   size  samples  median s  (min-max)      read ms  bvh ms  rays ms  peak MB  mean°  p99°   mean° if normalised\n";
    for row in r.quality.iter().chain(&r.scaling) {
        s += &format!(
            "{:>9} {:>6} {:>8} {:>9.3}  ({:.3}-{:.3}) {:>8.0} {:>7.0} {:>8.0} {:>8.0} {:>6.3} {:>6.3} {:>6.3}\n",
            row.high_triangles,
            row.size,
            row.samples * row.samples,
            row.median_s,
            row.min_s,
            row.max_s,
            row.read_high_ms,
            row.bvh_ms,
            row.rays_ms,
            row.peak_mb,
            row.error.synced.mean,
            row.error.synced.p99,
            row.error.normalised_frame.mean
        );
    }
    if !r.large.is_empty() {
        s += "\n";
        s += &large::table(&r.large);
    }
    s
}
