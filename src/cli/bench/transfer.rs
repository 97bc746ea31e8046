//! `bumpbake bench transfer`: `bake --from` on an analytic surface, error against run time.

use bumpbake::bench::transfer_large::{Plan, Source};
use bumpbake::{Error, Result};

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake bench transfer
  bumpbake bench transfer --runs 7 --json > transfer-bench.json
  bumpbake bench transfer --runs 0 --large 10 --large-from memory,obj
  bumpbake bench transfer --runs 0 --large 10.24 --large-from obj --large-runs 3 --blender python3")]
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
    let blender = a.blender.clone().map(|python| bumpbake::bench::blender::Blender { python });
    let plan = Plan { millions, sources, size: a.large_size, runs: a.large_runs.max(1), blender };
    let quiet = a.json;
    let r = super::shared::with_scratch("transfer", |exe, dir| {
        let mut r = if a.runs == 0 {
            bumpbake::bench::transfer::Report::empty()
        } else {
            bumpbake::bench::transfer::run(exe, dir, &quality, a.runs, |row| {
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
        r.large = bumpbake::bench::transfer_large::run(exe, dir, &plan, |row| {
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
    })?;
    super::shared::print(&r, a.json, bumpbake::bench::transfer::table)?;
    Ok(0)
}
