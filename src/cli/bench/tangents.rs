//! `bumpbake bench tangents`: tangent engines on surfaces with known exact tangents.

mod plot;

use bumpbake::analytic::tangents::{build, Case, Surface};
use bumpbake::tangent::mikk::{compact, Engine};
use bumpbake::Result;
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;

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
        measure(&opts, |row| {
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
        bumpbake::output::write_atomic(path, plot::svg(&report).as_bytes())?;
    }
    if let Some(path) = &a.scaling_plot {
        bumpbake::output::write_atomic(path, plot::scaling_svg(&report).as_bytes())?;
    }
    if a.json {
        let s = serde_json::to_string_pretty(&report).map_err(|e| bumpbake::Error::usage(e.to_string()))?;
        outln!("{s}");
    } else {
        out!("{}", table(&report));
    }
    Ok(0)
}

/// Engines in the order they are reported.
pub fn engine_name(e: Engine) -> &'static str {
    match e {
        Engine::Bevy => "bevy_mikktspace",
        Engine::Fast => "fast",
    }
}

/// A mesh file as a case: every triangle primitive with UVs (set 0) in one mesh; primitives without
/// normals get the smooth normals an OBJ without them gets. It has no exact tangent.
fn case_from_file(path: &std::path::Path) -> Result<Case> {
    let scene = bumpbake::format::read(path, &Default::default())?;
    let label = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let mut c = Case {
        surface: Surface::Mesh,
        positions: vec![],
        normals: vec![],
        uvs: vec![],
        indices: vec![],
        exact: vec![],
        label,
    };
    for r in scene.primitives() {
        let p = bumpbake::scene::to_triangle_list(scene.primitive(r)?);
        let Some(uv) = p.attr("TEXCOORD_0") else { continue };
        let pos = p.positions();
        let nrm = match p.attr("NORMAL") {
            Some(n) => n.to_f32(),
            None => bumpbake::scene::smooth_normals(pos.as_flattened(), &p.indices).0,
        };
        let base = c.positions.len() as u32;
        c.indices.extend(p.indices.iter().map(|&i| i + base));
        c.positions.extend(pos);
        c.normals.extend(nrm);
        c.uvs.extend(uv.to_f32::<2>());
    }
    if c.indices.is_empty() {
        return Err(bumpbake::error::Error::input(path, "no triangle primitive with TEXCOORD_0 to benchmark"));
    }
    Ok(c)
}
/// Angular error statistics in degrees.
#[derive(Debug, Clone, Default, Serialize)]
pub struct ErrorStats {
    pub mean_deg: f64,
    pub p99_deg: f64,
    pub max_deg: f64,
    /// Corners whose sign differs (from +1, or from the reference's).
    pub sign_errors: usize,
    /// Corners with no frame (or whose presence differs from the reference's).
    pub missing: usize,
    /// Corners compared.
    pub corners: usize,
}

/// The reference engine's frames, with its median and fastest time in ms.
type Reference = (Vec<Option<[f32; 4]>>, f64, f64);

fn angle_deg(a: [f32; 3], b: [f32; 3]) -> f64 {
    let (a, b) = (a.map(f64::from), b.map(f64::from));
    let la = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    let lb = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
    if !(la > 0.0 && lb > 0.0 && la.is_finite() && lb.is_finite()) {
        return 180.0;
    }
    let d = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (la * lb);
    d.clamp(-1.0, 1.0).acos().to_degrees()
}

fn stats(mut errs: Vec<f64>, sign_errors: usize, missing: usize) -> ErrorStats {
    let corners = errs.len();
    if errs.is_empty() {
        return ErrorStats { sign_errors, missing, ..Default::default() };
    }
    errs.sort_by(f64::total_cmp);
    let mean = errs.iter().sum::<f64>() / errs.len() as f64;
    let p99 = errs[((errs.len() as f64 * 0.99).ceil() as usize).clamp(1, errs.len()) - 1];
    ErrorStats { mean_deg: mean, p99_deg: p99, max_deg: errs[errs.len() - 1], sign_errors, missing, corners }
}

/// Error against the exact frame of each corner's vertex.
pub fn error_vs_exact(case: &Case, out: &[Option<[f32; 4]>]) -> Option<ErrorStats> {
    if case.exact.is_empty() {
        return None;
    }
    let mut errs = Vec::with_capacity(out.len());
    let (mut sign, mut missing) = (0, 0);
    for (k, o) in out.iter().enumerate() {
        match o {
            Some(t) => {
                errs.push(angle_deg([t[0], t[1], t[2]], case.exact[case.indices[k] as usize]));
                if t[3] != 1.0 {
                    sign += 1;
                }
            }
            None => missing += 1,
        }
    }
    Some(stats(errs, sign, missing))
}

/// Error against another engine's output (the reference).
pub fn error_vs(out: &[Option<[f32; 4]>], reference: &[Option<[f32; 4]>]) -> (ErrorStats, usize) {
    let mut errs = Vec::with_capacity(out.len());
    let (mut sign, mut missing, mut identical) = (0, 0, 0);
    for (o, r) in out.iter().zip(reference) {
        match (o, r) {
            (Some(a), Some(b)) => {
                if a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()) {
                    identical += 1;
                    errs.push(0.0);
                } else {
                    errs.push(angle_deg([a[0], a[1], a[2]], [b[0], b[1], b[2]]));
                }
                if a[3] != b[3] {
                    sign += 1;
                }
            }
            (None, None) => identical += 1,
            _ => missing += 1,
        }
    }
    (stats(errs, sign, missing), identical)
}

/// One engine on one case.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    pub surface: Surface,
    /// The surface's name, or the mesh's file name.
    pub name: String,
    pub triangles: usize,
    pub engine: &'static str,
    pub runs: usize,
    /// Median wall time of one `mikk::compact` call, milliseconds.
    pub median_ms: f64,
    pub min_ms: f64,
    pub mtriangles_per_s: f64,
    /// Against the exact tangent (absent for meshes from files).
    pub vs_exact: Option<ErrorStats>,
    /// Against `bevy_mikktspace` in the same run (absent when it was not run).
    pub vs_reference: Option<ErrorStats>,
    /// Corners bit-identical to the reference (frame and sign, or both without a frame).
    pub identical_to_reference: Option<usize>,
    /// Median time of the reference divided by this engine's median time.
    pub speedup_vs_reference: Option<f64>,
}

/// What to run.
#[derive(Debug, Clone)]
pub struct Options {
    pub surfaces: Vec<Surface>,
    pub sizes: Vec<usize>,
    pub fan_triangles: usize,
    pub engines: Vec<Engine>,
    pub runs: usize,
    /// Skip the reference above this many triangles (0: never skip).
    pub reference_max: usize,
    /// Mesh files, run after the surfaces.
    pub meshes: Vec<std::path::PathBuf>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            surfaces: vec![Surface::Sphere, Surface::Torus, Surface::WavyGrid],
            sizes: vec![10_000, 100_000, 1_000_000],
            fan_triangles: 20_000,
            engines: if bumpbake::tangent::mikk::REFERENCE_BUILT_IN {
                vec![Engine::Fast, Engine::Bevy]
            } else {
                vec![Engine::Fast]
            },
            runs: 5,
            reference_max: 0,
            meshes: Vec::new(),
        }
    }
}

/// The whole report.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    pub threads: usize,
    pub rows: Vec<Row>,
}

/// Times `engine` on `case`: returns the last output and the run times in milliseconds.
pub fn time_engine(case: &Case, engine: Engine, runs: usize) -> (Vec<Option<[f32; 4]>>, Vec<f64>) {
    let mesh = case.mesh();
    let mut times = Vec::with_capacity(runs);
    let mut out = Vec::new();
    for _ in 0..runs.max(1) {
        drop(std::mem::take(&mut out));
        let t = Instant::now();
        // The compact frames the tangents command uses; spelling them out per corner is not timed.
        let frames = compact(&mesh, engine);
        times.push(t.elapsed().as_secs_f64() * 1e3);
        out = frames.to_flat(mesh.indices).into_iter().map(|f| (f[3] != 0.0).then_some(f)).collect();
    }
    (out, times)
}

/// Runs the benchmark; `progress` receives one line per finished row. Fails only when a mesh
/// file cannot be read.
fn measure(opts: &Options, mut progress: impl FnMut(&Row)) -> bumpbake::error::Result<Report> {
    let mut cases: Vec<Box<dyn Fn() -> bumpbake::error::Result<Case>>> = Vec::new();
    for &s in &opts.surfaces {
        for &n in &opts.sizes {
            cases.push(Box::new(move || Ok(build(s, n))));
        }
    }
    if opts.fan_triangles > 0 {
        let n = opts.fan_triangles;
        cases.push(Box::new(move || Ok(build(Surface::Fan, n))));
    }
    for m in &opts.meshes {
        cases.push(Box::new(move || case_from_file(m)));
    }
    let mut rows = Vec::new();
    for make in cases {
        let case = make()?;
        let s = case.surface;
        let tris = case.triangles();
        let with_ref = opts.engines.contains(&Engine::Bevy) && (opts.reference_max == 0 || tris <= opts.reference_max);
        // The reference runs first; its output is what the other engines are compared with.
        let mut reference: Option<Reference> = None;
        if with_ref {
            let (out, mut times) = time_engine(&case, Engine::Bevy, opts.runs);
            let min = times.iter().copied().fold(f64::INFINITY, f64::min);
            reference = Some((out, super::shared::median(&mut times), min));
        }
        for &e in &opts.engines {
            let (out, med, min_ms) = if e == Engine::Bevy {
                let Some((out, med, min)) = reference.as_ref() else { continue };
                (out.clone(), *med, *min)
            } else {
                let (out, mut times) = time_engine(&case, e, opts.runs);
                let min = times.iter().copied().fold(f64::INFINITY, f64::min);
                (out, super::shared::median(&mut times), min)
            };
            let (vs_ref, identical) = match &reference {
                Some((r, _, _)) => {
                    let (st, id) = error_vs(&out, r);
                    (Some(st), Some(id))
                }
                None => (None, None),
            };
            let row = Row {
                surface: s,
                name: case.label.clone(),
                triangles: tris,
                engine: engine_name(e),
                runs: opts.runs.max(1),
                median_ms: med,
                min_ms,
                mtriangles_per_s: tris as f64 / (med * 1e-3) / 1e6,
                vs_exact: error_vs_exact(&case, &out),
                vs_reference: vs_ref,
                identical_to_reference: identical,
                speedup_vs_reference: reference.as_ref().map(|(_, rm, _)| rm / med),
            };
            progress(&row);
            rows.push(row);
        }
    }
    Ok(Report { threads: rayon::current_num_threads(), rows })
}

/// A fixed-width text table of the report.
pub fn table(r: &Report) -> String {
    let nw = r.rows.iter().map(|x| x.name.len()).max().unwrap_or(0).max(10);
    let mut s = format!(
        "threads: {}\n{:<nw$} {:>9} {:<16} {:>10} {:>9} {:>8} {:>9} {:>9} {:>9} {:>6} {:>7} {:>10} {:>9}\n",
        r.threads,
        "surface",
        "triangles",
        "engine",
        "median ms",
        "Mtri/s",
        "x bevy",
        "mean deg",
        "p99 deg",
        "max deg",
        "sign!",
        "none",
        "ref max deg",
        "identical"
    );
    for x in &r.rows {
        let speed = x.speedup_vs_reference.map_or("-".into(), |v| format!("{v:.2}"));
        let refmax = x.vs_reference.as_ref().map_or("-".into(), |v| format!("{:.2e}", v.max_deg));
        let ident = x
            .identical_to_reference
            .map_or("-".into(), |v| format!("{:.2}%", 100.0 * v as f64 / (3 * x.triangles).max(1) as f64));
        let ex = |f: fn(&ErrorStats) -> String| x.vs_exact.as_ref().map_or("-".into(), f);
        s += &format!(
            "{:<nw$} {:>9} {:<16} {:>10.2} {:>9.2} {:>8} {:>9} {:>9} {:>9} {:>6} {:>7} {:>10} {:>9}\n",
            x.name,
            x.triangles,
            x.engine,
            x.median_ms,
            x.mtriangles_per_s,
            speed,
            ex(|e| format!("{:.4}", e.mean_deg)),
            ex(|e| format!("{:.4}", e.p99_deg)),
            ex(|e| format!("{:.4}", e.max_deg)),
            ex(|e| e.sign_errors.to_string()),
            ex(|e| e.missing.to_string()),
            refmax,
            ident
        );
    }
    s
}

// Both need the reference engine to compare with.
#[cfg(all(test, feature = "reference"))]
mod tests {
    use super::*;

    #[test]
    fn both_engines_agree_and_are_accurate_on_a_small_torus() {
        let opts = Options {
            surfaces: vec![Surface::Torus],
            sizes: vec![2_000],
            fan_triangles: 100,
            runs: 1,
            ..Options::default()
        };
        let r = measure(&opts, |_| {}).expect("no files to read");
        assert_eq!(r.rows.len(), 4);
        for row in &r.rows {
            assert_eq!(row.identical_to_reference, Some(3 * row.triangles), "{row:?}");
            let ex = row.vs_exact.as_ref().expect("surfaces have exact tangents");
            assert_eq!(ex.sign_errors, 0);
            assert_eq!(ex.missing, 0);
            assert!(ex.max_deg < 5.0, "{row:?}");
        }
        let svg = plot::svg(&r);
        assert!(svg.starts_with("<svg") && svg.contains("</svg>"));
        // One line per surface and engine (the fan is not a size series).
        let scaling = plot::scaling_svg(&r);
        assert_eq!(scaling.matches("<polyline").count(), 2, "{scaling}");
        assert!(scaling.contains("torus fast") && scaling.contains("torus bevy_mikktspace"));
        assert!(serde_json::to_string(&r).is_ok());
    }

    #[test]
    fn real_meshes_are_compared_with_the_reference_only() {
        let spot = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/spot/spot.obj");
        let opts = Options { surfaces: vec![], fan_triangles: 0, runs: 1, meshes: vec![spot], ..Options::default() };
        let r = measure(&opts, |_| {}).expect("spot reads");
        assert_eq!(r.rows.len(), 2);
        for row in &r.rows {
            assert_eq!((row.name.as_str(), row.triangles, row.surface), ("spot.obj", 5856, Surface::Mesh));
            assert!(row.vs_exact.is_none());
            assert_eq!(row.identical_to_reference, Some(3 * 5856), "{row:?}");
        }
        let missing = Options { meshes: vec!["no/such.obj".into()], ..opts };
        assert!(measure(&missing, |_| {}).is_err());
    }
}
