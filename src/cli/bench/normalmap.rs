//! `bumpbake bench normalmap`: every filter on analytic height fields, and the whole command.

pub(super) mod heights;
mod plot;

use bumpbake::normalmap::{
    self as nm, Channel, Convert, Depth, EncodeOptions, Filter, HeightPlane, NormalImage, Options, PngSettings, Wrap,
};
use bumpbake::progress::Reporter;
use bumpbake::{Error, Result};
use heights::Surface;
use rayon::prelude::*;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake bench normalmap
  bumpbake bench normalmap --json --plot error-vs-time.svg > bench.json
  RAYON_NUM_THREADS=1 bumpbake bench normalmap --size 512 --pipeline-size 0 --filter sobel --filter spectral")]
pub struct BenchNormalmapArgs {
    /// Side of the square analytic surfaces (errors and per-filter throughput).
    #[arg(long, default_value_t = 1024)]
    pub size: usize,
    /// Timed runs per figure; medians are reported.
    #[arg(long, default_value_t = 5)]
    pub runs: usize,
    /// Side of the 16-bit PNG for the whole-command measurement (0 skips it).
    #[arg(long, default_value_t = 4096)]
    pub pipeline_size: usize,
    /// Only these filters (repeatable); all by default.
    #[arg(long, value_enum)]
    pub filter: Vec<super::super::args::FilterArg>,
    /// Print JSON instead of tables.
    #[arg(long)]
    pub json: bool,
    /// Also draw mean error against time per pixel as an SVG.
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
}

pub fn run(a: BenchNormalmapArgs) -> Result<u8> {
    let cfg = Config {
        size: a.size,
        runs: a.runs,
        pipeline_size: a.pipeline_size,
        filters: if a.filter.is_empty() {
            Filter::ALL.to_vec()
        } else {
            a.filter.into_iter().map(Filter::from).collect()
        },
    };
    let report = measure(&cfg, &|m| eprintln!("bench: {m}"))?;
    if let Some(path) = &a.plot {
        let svg = plot::error_vs_time_svg(&report);
        bumpbake::output::write_atomic(path, svg.as_bytes())?;
    }
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&report).expect("report serialises"));
    } else {
        out!("{}", render_text(&report));
    }
    Ok(0)
}

/// What to measure.
#[derive(Clone, Debug)]
pub struct Config {
    /// Side of the square analytic surfaces.
    pub size: usize,
    /// Timed runs per figure (the median is reported).
    pub runs: usize,
    /// Side of the 16-bit PNG for the whole-command measurement; 0 skips it.
    pub pipeline_size: usize,
    pub filters: Vec<Filter>,
}

impl Default for Config {
    fn default() -> Self {
        Config { size: 1024, runs: 5, pipeline_size: 4096, filters: Filter::ALL.to_vec() }
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct ErrorStats {
    pub mean_deg: f64,
    pub p99_deg: f64,
    pub max_deg: f64,
}

/// One filter on one surface.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub filter: Filter,
    pub surface: String,
    #[serde(flatten)]
    pub error: ErrorStats,
    /// Filter + 8-bit encode into a reused buffer, all worker threads.
    pub mpx_s: f64,
    /// The same on one thread.
    pub mpx_s_1t: f64,
}

/// The error that encoding exact normals adds on its own.
#[derive(Clone, Debug, Serialize)]
pub struct EncodingRow {
    pub bits: u8,
    pub surface: String,
    #[serde(flatten)]
    pub error: ErrorStats,
}

#[derive(Clone, Debug, Serialize)]
pub struct PngRow {
    pub compression: String,
    pub filter: String,
    pub encode_ms: f64,
    pub bytes: usize,
}

/// The whole command on a large 16-bit map against decoding and encoding the same images alone.
#[derive(Clone, Debug, Serialize)]
pub struct Pipeline {
    pub size: usize,
    pub filter: Filter,
    pub decode_ms: f64,
    pub encode_ms: f64,
    pub write_ms: f64,
    /// decode + encode + write, each measured alone.
    pub baseline_ms: f64,
    /// `convert_file`: decode, heights, filter, encode, write.
    pub command_ms: f64,
    /// Stage times of the command's median run: decode (with the float conversion), filter,
    /// encode, write.
    pub command_stages: Vec<(String, f64)>,
    pub ratio: f64,
    pub filter_ms: f64,
    pub filter_ms_1t: f64,
    pub filter_mpx_s: f64,
    pub filter_mpx_s_1t: f64,
    /// The one-thread figure from the thread's CPU time instead of wall time.
    pub filter_mpx_s_1t_cpu: Option<f64>,
    pub png: Vec<PngRow>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Report {
    pub threads: usize,
    pub size: usize,
    pub runs: usize,
    pub surfaces: Vec<(String, String, f64)>,
    pub rows: Vec<Row>,
    pub encoding: Vec<EncodingRow>,
    pub pipeline: Option<Pipeline>,
}

fn angle_deg(a: [f32; 3], b: [f64; 3]) -> f64 {
    let a = [a[0] as f64, a[1] as f64, a[2] as f64];
    let c = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let cross = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
    let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    cross.atan2(dot).to_degrees()
}

fn stats(mut angles: Vec<f64>) -> ErrorStats {
    let n = angles.len();
    let mean = angles.iter().sum::<f64>() / n as f64;
    let max = angles.iter().cloned().fold(0.0, f64::max);
    let k = ((n - 1) as f64 * 0.99).round() as usize;
    let (_, p99, _) = angles.select_nth_unstable_by(k, |a, b| a.total_cmp(b));
    ErrorStats { mean_deg: mean, p99_deg: *p99, max_deg: max }
}

fn errors(got: &[[f32; 3]], exact: &[[f64; 3]]) -> ErrorStats {
    stats(got.par_iter().zip(exact).map(|(g, e)| angle_deg(*g, *e)).collect())
}

/// Median wall time of `runs` calls, in milliseconds.
pub fn median_ms(runs: usize, mut f: impl FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..runs.max(1))
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    t.sort_by(|a, b| a.total_cmp(b));
    t[t.len() / 2]
}

/// CPU time of the calling thread in ns (Linux), which load from other processes on a shared
/// machine does not inflate the way it inflates wall time.
fn thread_cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

/// Median thread CPU time of `runs` calls, in milliseconds, where the platform tells it.
pub fn median_cpu_ms(runs: usize, mut f: impl FnMut()) -> Option<f64> {
    let mut t = Vec::new();
    for _ in 0..runs.max(1) {
        let a = thread_cpu_ns()?;
        f();
        t.push((thread_cpu_ns()? - a) as f64 / 1e6);
    }
    t.sort_by(|a, b| a.total_cmp(b));
    Some(t[t.len() / 2])
}

fn one_thread() -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("a one-thread pool")
}

const ENC8: EncodeOptions =
    EncodeOptions { depth: Depth::Bits8, convention: nm::Convention::Opengl, alpha_height: false };

/// Runs the whole benchmark.
fn measure(cfg: &Config, log: &dyn Fn(&str)) -> Result<Report> {
    if cfg.size < 16 {
        return Err(Error::usage("bench normalmap: --size must be at least 16"));
    }
    let single = one_thread();
    let surfaces = heights::all(cfg.size);
    let mut rows = Vec::new();
    let mut encoding = Vec::new();
    let mpx = (cfg.size * cfg.size) as f64 / 1e6;
    for s in &surfaces {
        log(&format!("surface {} ({})", s.name, s.what));
        let plane = s.plane();
        let exact = s.exact_normals();
        for &filter in &cfg.filters {
            let opts = Options { strength: s.strength as f32, filter, wrap: Wrap::Repeat, invert: false };
            let normals = nm::height_to_normal(&plane, &opts);
            let error = errors(&normals.data, &exact);
            let mut img = nm::encode_normals(&plane, &opts, &ENC8, &Reporter::none());
            let mut run = || nm::encode_normals_into(&plane, &opts, &ENC8, &Reporter::none(), &mut img);
            let t = median_ms(cfg.runs, &mut run);
            let t1 = single.install(|| median_ms(cfg.runs, &mut run));
            rows.push(Row {
                filter,
                surface: s.name.to_string(),
                error,
                mpx_s: mpx / (t / 1e3),
                mpx_s_1t: mpx / (t1 / 1e3),
            });
        }
        encoding.extend(encoding_error(s, &exact));
    }
    let pipeline = if cfg.pipeline_size > 0 { Some(pipeline(cfg, log)?) } else { None };
    Ok(Report {
        threads: rayon::current_num_threads(),
        size: cfg.size,
        runs: cfg.runs,
        surfaces: surfaces.iter().map(|s| (s.name.to_string(), s.what.clone(), s.strength)).collect(),
        rows,
        encoding,
        pipeline,
    })
}

/// Exact normals through 8- and 16-bit encoding and back: the floor under every filter.
fn encoding_error(s: &Surface, exact: &[[f64; 3]]) -> Vec<EncodingRow> {
    let n = s.n;
    let plane = nm::NormalPlane {
        width: n,
        height: n,
        data: exact.iter().map(|e| [e[0] as f32, e[1] as f32, e[2] as f32]).collect(),
    };
    [(8u8, Depth::Bits8), (16, Depth::Bits16)]
        .into_iter()
        .map(|(bits, depth)| {
            let img = nm::encode_plane(&plane, &EncodeOptions { depth, ..ENC8 }, None);
            let back = img.decode(nm::Convention::Opengl);
            EncodingRow { bits, surface: s.name.to_string(), error: errors(&back.data, exact) }
        })
        .collect()
}

/// A 16-bit relief of `n x n` from products of sines (table-driven, so it takes a moment
/// even at 4096²), detailed at every scale like a scanned or sculpted height map.
fn pipeline_heights(n: usize) -> Vec<u16> {
    let waves: Vec<(f64, f64, f64)> =
        (0..12).map(|k| (2f64.powi(k / 2 + 1), 0.7 * k as f64, 2f64.powf(-(k as f64) * 0.6))).collect();
    let total: f64 = waves.iter().map(|w| w.2).sum();
    let tables: Vec<Vec<f64>> = waves
        .iter()
        .flat_map(|&(f, ph, _)| {
            let fy = f * 1.3 + 1.0;
            let tx = (0..n).map(|x| (std::f64::consts::TAU * f * x as f64 / n as f64 + ph).sin()).collect();
            let ty = (0..n).map(|y| (std::f64::consts::TAU * fy * y as f64 / n as f64 + 2.0 * ph).sin()).collect();
            [tx, ty]
        })
        .collect();
    let mut out = vec![0u16; n * n];
    out.par_chunks_mut(n).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            let mut h = 0.0;
            for (k, w) in waves.iter().enumerate() {
                h += w.2 * tables[2 * k][x] * tables[2 * k + 1][y];
            }
            *o = ((0.5 + 0.5 * h / total).clamp(0.0, 1.0) * 65535.0).round() as u16;
        }
    });
    out
}

fn pipeline(cfg: &Config, log: &dyn Fn(&str)) -> Result<Pipeline> {
    let n = cfg.pipeline_size;
    log(&format!("pipeline: {n}x{n} 16-bit PNG"));
    let dir = std::env::temp_dir().join(format!("bumpbake-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| Error::output(&dir, e))?;
    let result = pipeline_in(cfg, &dir, n);
    let _ = std::fs::remove_dir_all(&dir);
    result
}

fn pipeline_in(cfg: &Config, dir: &Path, n: usize) -> Result<Pipeline> {
    let input = dir.join("height16.png");
    let output = dir.join("normal.png");
    let heights = pipeline_heights(n);
    let mut bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut bytes, n as u32, n as u32);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::Sixteen);
        let be: Vec<u8> = heights.iter().flat_map(|v| v.to_be_bytes()).collect();
        let mut w = enc.write_header().map_err(|e| Error::output(&input, e))?;
        w.write_image_data(&be).map_err(|e| Error::output(&input, e))?;
    }
    drop(heights);
    bumpbake::output::write_atomic(&input, &bytes)?;
    drop(bytes);

    let filter = Filter::default();
    let opts = Options { strength: 8.0, filter, wrap: Wrap::Clamp, invert: false };
    let plane: HeightPlane = nm::load_height(&input, Channel::Luma, u64::MAX)?;
    let img: NormalImage = nm::encode_normals(&plane, &opts, &ENC8, &Reporter::none());
    let runs = cfg.runs;
    let png = PngSettings::default();

    // Alone: what any tool that reads this PNG and writes that one must spend.
    let decode_ms = median_ms(runs, || drop(nm::open_image(&input, u64::MAX).expect("decodes")));
    let encoded = nm::png_bytes(&img, png).map_err(|m| Error::output(&output, m))?;
    let encode_ms = median_ms(runs, || drop(nm::png_bytes(&img, png).expect("encodes")));
    let write_ms = median_ms(runs, || bumpbake::output::write_atomic(&output, &encoded).expect("writes"));
    let mut reused = img.clone();
    let mut run = || nm::encode_normals_into(&plane, &opts, &ENC8, &Reporter::none(), &mut reused);
    let filter_ms = median_ms(runs, &mut run);
    let filter_ms_1t = one_thread().install(|| median_ms(runs, &mut run));
    let filter_cpu_ms_1t = one_thread().install(|| median_cpu_ms(runs, &mut run));
    drop(reused);
    drop(plane);

    let convert = Convert {
        input: input.clone(),
        output: output.clone(),
        channel: Channel::Luma,
        max_pixels: nm::DEFAULT_MAX_PIXELS,
        options: opts,
        encode: ENC8,
        png,
        ktx2: bumpbake::format::image::ktx2::Codec::Uastc { level: nm::DEFAULT_UASTC_LEVEL, rdo: None },
    };
    let mut stage_runs: Vec<(f64, Vec<(String, f64)>)> = Vec::new();
    let command_ms = median_ms(runs, || {
        let s = Instant::now();
        let t = nm::convert_file(&convert, &Reporter::none()).expect("converts").timings_ms;
        stage_runs.push((s.elapsed().as_secs_f64(), t.stages));
    });
    stage_runs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let command_stages = stage_runs.swap_remove(stage_runs.len() / 2).1;

    let mut png_rows = Vec::new();
    for (cname, compression) in [("fast", png::Compression::Fast), ("balanced", png::Compression::Balanced)] {
        for (fname, f) in [
            ("none", png::Filter::NoFilter),
            ("sub", png::Filter::Sub),
            ("up", png::Filter::Up),
            ("avg", png::Filter::Avg),
            ("paeth", png::Filter::Paeth),
            ("adaptive", png::Filter::Adaptive),
        ] {
            if cname == "balanced" && fname != "adaptive" {
                continue; // the `image` crate's default, for reference only
            }
            let s = PngSettings { compression, filter: f };
            let size = nm::png_bytes(&img, s).map(|b| b.len()).unwrap_or(0);
            let t = median_ms(runs.min(3), || drop(nm::png_bytes(&img, s)));
            png_rows.push(PngRow { compression: cname.into(), filter: fname.into(), encode_ms: t, bytes: size });
        }
    }
    let baseline_ms = decode_ms + encode_ms + write_ms;
    let mpx = (n * n) as f64 / 1e6;
    Ok(Pipeline {
        size: n,
        filter,
        decode_ms,
        encode_ms,
        write_ms,
        baseline_ms,
        command_ms,
        command_stages,
        ratio: command_ms / baseline_ms,
        filter_ms,
        filter_ms_1t,
        filter_mpx_s: mpx / (filter_ms / 1e3),
        filter_mpx_s_1t: mpx / (filter_ms_1t / 1e3),
        filter_mpx_s_1t_cpu: filter_cpu_ms_1t.map(|t| mpx / (t / 1e3)),
        png: png_rows,
    })
}

/// The report as aligned text tables.
pub fn render_text(r: &Report) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "bench normalmap: {}x{} surfaces, wrap repeat, median of {} runs, {} threads",
        r.size, r.size, r.runs, r.threads
    );
    for (name, what, strength) in &r.surfaces {
        let _ = writeln!(s, "  {name:<10} {what} (strength {strength:.3})");
    }
    let _ = writeln!(
        s,
        "\n{:<10} {:<10} {:>9} {:>9} {:>9} {:>10} {:>10}",
        "filter", "surface", "mean°", "p99°", "max°", "Mpx/s", "Mpx/s 1t"
    );
    for row in &r.rows {
        let e = &row.error;
        let _ = writeln!(
            s,
            "{:<10} {:<10} {:>9.4} {:>9.4} {:>9.4} {:>10.1} {:>10.1}",
            row.filter.name(),
            row.surface,
            e.mean_deg,
            e.p99_deg,
            e.max_deg,
            row.mpx_s,
            row.mpx_s_1t
        );
    }
    let _ = writeln!(s, "\nencoding alone (exact normals, encoded and decoded):");
    for row in &r.encoding {
        let e = &row.error;
        let _ = writeln!(
            s,
            "{:<10} {:<10} {:>9.4} {:>9.4} {:>9.4}",
            format!("{}-bit", row.bits),
            row.surface,
            e.mean_deg,
            e.p99_deg,
            e.max_deg
        );
    }
    if let Some(p) = &r.pipeline {
        let _ = writeln!(
            s,
            "\nwhole command on a {0}x{0} 16-bit PNG -> 8-bit RGB PNG (filter {1}), medians in ms:",
            p.size,
            p.filter.name()
        );
        let _ = writeln!(
            s,
            "  decode alone {:.1}, encode alone {:.1}, write alone {:.1}: baseline {:.1}",
            p.decode_ms, p.encode_ms, p.write_ms, p.baseline_ms
        );
        let stages: Vec<String> = p.command_stages.iter().map(|(n, t)| format!("{n} {t:.1}")).collect();
        let _ = writeln!(
            s,
            "  whole command {:.1} ({}): ratio {:.3} (target <= 1.5)",
            p.command_ms,
            stages.join(", "),
            p.ratio
        );
        let _ = writeln!(
            s,
            "  filter+encode-to-buffer {:.1} ms ({:.0} Mpx/s), one thread {:.1} ms ({:.0} Mpx/s, target >= 200)",
            p.filter_ms, p.filter_mpx_s, p.filter_ms_1t, p.filter_mpx_s_1t
        );
        if let Some(cpu) = p.filter_mpx_s_1t_cpu {
            let _ = writeln!(s, "  one thread by thread CPU time (unaffected by other load): {cpu:.0} Mpx/s");
        }
        let _ = writeln!(s, "  PNG settings for the 8-bit output:");
        for row in &p.png {
            let _ = writeln!(
                s,
                "    {:<9} {:<9} {:>8.1} ms {:>11} bytes",
                row.compression, row.filter, row.encode_ms, row.bytes
            );
        }
    }
    s
}
