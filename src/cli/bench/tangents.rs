//! `bumpbake bench tangents`: tangent engines on surfaces with known exact tangents.

use bumpbake::bench::tangents::{self, Options, Surface};
use bumpbake::tangent::mikk::Engine;
use bumpbake::Result;
use std::path::PathBuf;

/// Tangent engines on parametric surfaces with known exact tangents, a high-valence fan, and
/// real meshes.
#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake bench tangents
  bumpbake bench tangents --sizes 10k,100k,1m,4m --surfaces wavy-grid --json > scaling.json
  bumpbake bench tangents --engines fast --fan 20k --sizes 1m --plot tangents.svg
  bumpbake bench tangents --sizes 10k --fan 0 --mesh fixtures/spot/spot.obj --mesh scan.glb")]
pub struct BenchTangentsArgs {
    /// Triangle counts per surface (suffixes k and m allowed), comma separated.
    #[arg(long, value_delimiter = ',', default_value = "10k,100k,1m", value_parser = parse_count)]
    pub sizes: Vec<usize>,
    /// Surfaces: sphere, torus, wavy-grid.
    #[arg(long, value_delimiter = ',', default_value = "sphere,torus,wavy-grid", value_parser = parse_surface)]
    pub surfaces: Vec<Surface>,
    /// Triangles of the one-vertex fan (0 skips it).
    #[arg(long, default_value = "20k", value_parser = parse_count)]
    pub fan: usize,
    /// Engines: fast, bevy (bevy_mikktspace, the reference every other engine is compared with;
    /// built in with `cargo build --features reference`).
    #[arg(long, value_delimiter = ',', default_value = DEFAULT_ENGINES, value_parser = parse_engine)]
    pub engines: Vec<Engine>,
    /// Timed runs per engine and case; the median is reported.
    #[arg(long, default_value_t = 5)]
    pub runs: usize,
    /// Skip the reference on cases above this many triangles (0: never).
    #[arg(long, default_value = "0", value_parser = parse_count)]
    pub reference_max: usize,
    /// Worker threads (default: rayon's, one per core).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Print the report as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Also write error-versus-time as an SVG plot.
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Also write median time against triangle count as an SVG plot (log-log, one line per
    /// surface and engine).
    #[arg(long, value_name = "FILE.svg")]
    pub scaling_plot: Option<PathBuf>,
    /// A real mesh (OBJ, glTF or GLB) to run too, compared with the reference only (it has no
    /// exact tangent). Repeatable.
    #[arg(long, value_name = "FILE")]
    pub mesh: Vec<PathBuf>,
}

fn parse_count(s: &str) -> std::result::Result<usize, String> {
    let t = s.trim().to_ascii_lowercase();
    let (num, mul) = match t.strip_suffix('k') {
        Some(n) => (n, 1_000.0),
        None => match t.strip_suffix('m') {
            Some(n) => (n, 1_000_000.0),
            None => (t.as_str(), 1.0),
        },
    };
    let v: f64 = num.parse().map_err(|_| format!("not a count: {s}"))?;
    if !(v >= 0.0 && v * mul <= 1.0e9) {
        return Err(format!("count out of range: {s}"));
    }
    Ok((v * mul).round() as usize)
}

fn parse_surface(s: &str) -> std::result::Result<Surface, String> {
    Surface::parse(s.trim()).ok_or_else(|| format!("unknown surface {s} (sphere, torus, wavy-grid)"))
}

/// The reference takes part whenever it is built in.
const DEFAULT_ENGINES: &str = if bumpbake::tangent::mikk::REFERENCE_BUILT_IN { "fast,bevy" } else { "fast" };

fn parse_engine(s: &str) -> std::result::Result<Engine, String> {
    match s.trim() {
        "fast" => Ok(Engine::Fast),
        "bevy" | "bevy_mikktspace" | "reference" if !bumpbake::tangent::mikk::REFERENCE_BUILT_IN => {
            Err("the reference engine (bevy_mikktspace) is not built in: build bumpbake with `--features reference`"
                .into())
        }
        "bevy" | "bevy_mikktspace" | "reference" => Ok(Engine::Bevy),
        _ => Err(format!("unknown engine {s} (fast, bevy)")),
    }
}

pub fn run(a: BenchTangentsArgs) -> Result<u8> {
    if a.runs == 0 {
        return Err(bumpbake::Error::usage("bench tangents: --runs must be at least 1"));
    }
    let opts = Options {
        surfaces: a.surfaces,
        sizes: a.sizes,
        fan_triangles: a.fan,
        engines: a.engines,
        runs: a.runs,
        reference_max: a.reference_max,
        meshes: a.mesh,
    };
    let go = || {
        tangents::run(&opts, |row| {
            eprintln!(
                "{:<10} {:>9} {:<16} {:>10.2} ms {:>8.2} Mtri/s",
                row.name, row.triangles, row.engine, row.median_ms, row.mtriangles_per_s
            )
        })
    };
    let report = match a.threads {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| bumpbake::Error::usage(format!("bench tangents: --threads {n}: {e}")))?
            .install(go),
        None => go(),
    }?;
    if let Some(path) = &a.plot {
        bumpbake::output::write_atomic(path, tangents::svg(&report).as_bytes())?;
    }
    if let Some(path) = &a.scaling_plot {
        bumpbake::output::write_atomic(path, tangents::scaling_svg(&report).as_bytes())?;
    }
    if a.json {
        let s = serde_json::to_string_pretty(&report).map_err(|e| bumpbake::Error::usage(e.to_string()))?;
        outln!("{s}");
    } else {
        out!("{}", tangents::table(&report));
    }
    Ok(0)
}
