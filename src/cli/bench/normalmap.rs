//! `bumpbake bench normalmap`: every filter on analytic height fields, and the whole command.

use bumpbake::bench::normalmap as bn;
use bumpbake::normalmap::Filter;
use bumpbake::Result;
use std::path::PathBuf;

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
    let cfg = bn::Config {
        size: a.size,
        runs: a.runs,
        pipeline_size: a.pipeline_size,
        filters: if a.filter.is_empty() {
            Filter::ALL.to_vec()
        } else {
            a.filter.into_iter().map(Filter::from).collect()
        },
    };
    let report = bn::run(&cfg, &|m| eprintln!("bench: {m}"))?;
    if let Some(path) = &a.plot {
        let svg = bumpbake::bench::plot::error_vs_time_svg(&report);
        bumpbake::output::write_atomic(path, svg.as_bytes())?;
    }
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&report).expect("report serialises"));
    } else {
        out!("{}", bn::render_text(&report));
    }
    Ok(0)
}
