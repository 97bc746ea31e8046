//! `bumpbake bench tangents`: every tangent engine on parametric surfaces whose exact tangent is
//! known, plus a high-valence fan.
//!
//! Each surface is a `(u, v)` grid with `uv = (u, v)`, analytic unit normals, and triangles
//! wound so that the UV orientation is preserved: the exact frame at a vertex is
//! `t = normalize(P_u - (P_u·N) N)` with sign `+1`. For each engine the bench reports the angular
//! error against that exact tangent and against the reference engine (`bevy_mikktspace`), sign
//! errors, corners without a frame, and throughput (median of several runs). Real meshes
//! (`--mesh FILE`) have no exact tangent: they are compared with the reference only.

#![forbid(unsafe_code)]

use crate::tangent::mikk::{compact, Engine};
use crate::tangent::TriMesh;
use serde::Serialize;
use std::f32::consts::{PI, TAU};
use std::time::Instant;

/// A test surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Surface {
    /// Unit sphere, latitude band 0.1π..0.9π (the poles have no `P_u`).
    Sphere,
    /// Torus R = 1, r = 0.35.
    Torus,
    /// Height field `z = 0.05 sin(6πu) sin(6πv)` over the unit square.
    WavyGrid,
    /// A flat disk of triangles all sharing the centre vertex (planar UVs).
    Fan,
    /// A mesh read from a file (its rows carry the file name).
    Mesh,
}

impl Surface {
    pub fn name(self) -> &'static str {
        match self {
            Surface::Sphere => "sphere",
            Surface::Torus => "torus",
            Surface::WavyGrid => "wavy-grid",
            Surface::Fan => "fan",
            Surface::Mesh => "mesh",
        }
    }
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "sphere" => Some(Surface::Sphere),
            "torus" => Some(Surface::Torus),
            "wavy-grid" | "grid" => Some(Surface::WavyGrid),
            "fan" => Some(Surface::Fan),
            _ => None,
        }
    }
}

/// Engines in the order they are reported.
pub fn engine_name(e: Engine) -> &'static str {
    match e {
        Engine::Bevy => "bevy_mikktspace",
        Engine::Fast => "fast",
    }
}

/// A generated mesh and its exact per-vertex tangents.
pub struct Case {
    pub surface: Surface,
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    pub indices: Vec<u32>,
    /// Exact unit tangent per vertex (sign is +1 everywhere); empty for a mesh from a file.
    pub exact: Vec<[f32; 3]>,
    /// The surface's name, or the file name of a mesh.
    pub label: String,
}

impl Case {
    pub fn triangles(&self) -> usize {
        self.indices.len() / 3
    }
    /// Every triangle primitive of a mesh file with UVs (set 0) in one mesh; primitives without
    /// normals get the smooth normals an OBJ without them gets.
    pub fn from_file(path: &std::path::Path) -> crate::error::Result<Case> {
        let scene = crate::scene::Scene::read(path, &Default::default())?;
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
            let p = crate::scene::to_triangle_list(scene.primitive(r)?);
            let Some(uv) = p.attr("TEXCOORD_0") else { continue };
            let pos = p.positions();
            let nrm = match p.attr("NORMAL") {
                Some(n) => n.to_f32(),
                None => crate::scene::smooth_normals(pos.as_flattened(), &p.indices).0,
            };
            let base = c.positions.len() as u32;
            c.indices.extend(p.indices.iter().map(|&i| i + base));
            c.positions.extend(pos);
            c.normals.extend(nrm);
            c.uvs.extend(uv.to_f32::<2>());
        }
        if c.indices.is_empty() {
            return Err(crate::error::Error::input(path, "no triangle primitive with TEXCOORD_0 to benchmark"));
        }
        Ok(c)
    }
    pub fn mesh(&self) -> TriMesh<'_> {
        TriMesh { positions: &self.positions, normals: &self.normals, uvs: &self.uvs, indices: &self.indices }
    }
}

fn norm(v: [f32; 3]) -> [f32; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if l > 0.0 {
        [v[0] / l, v[1] / l, v[2] / l]
    } else {
        v
    }
}

fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Position and `P_u`, `P_v` of a parametric surface.
fn eval(s: Surface, u: f32, v: f32) -> ([f32; 3], [f32; 3], [f32; 3]) {
    match s {
        Surface::Sphere => {
            let (ph, th) = (TAU * u, PI * (0.1 + 0.8 * v));
            let (sp, cp, st, ct) = (ph.sin(), ph.cos(), th.sin(), th.cos());
            // Pv points from the south band towards the north: v up along +z.
            let p = [st * cp, st * sp, -ct];
            let pu = [-TAU * st * sp, TAU * st * cp, 0.0];
            let pv = [0.8 * PI * ct * cp, 0.8 * PI * ct * sp, 0.8 * PI * st];
            (p, pu, pv)
        }
        Surface::Torus => {
            let (big, r) = (1.0f32, 0.35f32);
            let (ph, th) = (TAU * u, TAU * v);
            let (sp, cp, st, ct) = (ph.sin(), ph.cos(), th.sin(), th.cos());
            let p = [(big + r * ct) * cp, (big + r * ct) * sp, r * st];
            let pu = [-TAU * (big + r * ct) * sp, TAU * (big + r * ct) * cp, 0.0];
            let pv = [-TAU * r * st * cp, -TAU * r * st * sp, TAU * r * ct];
            (p, pu, pv)
        }
        Surface::WavyGrid | Surface::Fan | Surface::Mesh => {
            let (a, k) = (0.05f32, 3.0 * TAU);
            let z = a * (k * u).sin() * (k * v).sin();
            let pu = [1.0, 0.0, a * k * (k * u).cos() * (k * v).sin()];
            let pv = [0.0, 1.0, a * k * (k * u).sin() * (k * v).cos()];
            ([u, v, z], pu, pv)
        }
    }
}

/// Builds `surface` with about `triangles` triangles.
pub fn build(surface: Surface, triangles: usize) -> Case {
    if surface == Surface::Fan {
        return fan(triangles.max(3));
    }
    // Grid of nu x nv quads, two triangles each; aspect 2:1 for the closed surfaces.
    let quads = (triangles / 2).max(1) as f64;
    let (nu, nv) = match surface {
        Surface::WavyGrid => {
            let n = quads.sqrt().round().max(1.0) as usize;
            (n, ((quads / n as f64).round() as usize).max(1))
        }
        _ => {
            let nv = (quads / 2.0).sqrt().round().max(1.0) as usize;
            (((quads / nv as f64).round() as usize).max(1), nv)
        }
    };
    let mut c = Case {
        surface,
        positions: Vec::with_capacity((nu + 1) * (nv + 1)),
        normals: Vec::new(),
        uvs: Vec::new(),
        indices: Vec::with_capacity(nu * nv * 6),
        exact: Vec::new(),
        label: surface.name().into(),
    };
    for j in 0..=nv {
        for i in 0..=nu {
            let (u, v) = (i as f32 / nu as f32, j as f32 / nv as f32);
            let (p, pu, pv) = eval(surface, u, v);
            let n = norm(cross(pu, pv));
            let t = norm([pu[0] - dot(pu, n) * n[0], pu[1] - dot(pu, n) * n[1], pu[2] - dot(pu, n) * n[2]]);
            c.positions.push(p);
            c.normals.push(n);
            c.uvs.push([u, v]);
            c.exact.push(t);
        }
    }
    let id = |i: usize, j: usize| (j * (nu + 1) + i) as u32;
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, cc, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            c.indices.extend([a, b, cc, a, cc, d]);
        }
    }
    c
}

/// `n` triangles around one centre vertex on the unit disk, planar UVs: one vertex of valence
/// `n`, exact tangent `+x` everywhere.
fn fan(n: usize) -> Case {
    let mut c = Case {
        surface: Surface::Fan,
        positions: vec![[0.0, 0.0, 0.0]],
        normals: vec![[0.0, 0.0, 1.0]],
        uvs: vec![[0.5, 0.5]],
        indices: Vec::with_capacity(3 * n),
        exact: vec![[1.0, 0.0, 0.0]],
        label: "fan".into(),
    };
    for i in 0..n {
        let a = i as f32 / n as f32 * TAU;
        let p = [a.cos(), a.sin(), 0.0];
        c.positions.push(p);
        c.normals.push([0.0, 0.0, 1.0]);
        c.uvs.push([0.5 + 0.5 * p[0], 0.5 + 0.5 * p[1]]);
        c.exact.push([1.0, 0.0, 0.0]);
    }
    for i in 0..n as u32 {
        c.indices.extend([0, 1 + i, 1 + (i + 1) % n as u32]);
    }
    c
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
            engines: if crate::tangent::mikk::REFERENCE_BUILT_IN {
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
pub fn run(opts: &Options, mut progress: impl FnMut(&Row)) -> crate::error::Result<Report> {
    let mut cases: Vec<Box<dyn Fn() -> crate::error::Result<Case>>> = Vec::new();
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
        cases.push(Box::new(move || Case::from_file(m)));
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
            reference = Some((out, super::median(&mut times), min));
        }
        for &e in &opts.engines {
            let (out, med, min_ms) = if e == Engine::Bevy {
                let Some((out, med, min)) = reference.as_ref() else { continue };
                (out.clone(), *med, *min)
            } else {
                let (out, mut times) = time_engine(&case, e, opts.runs);
                let min = times.iter().copied().fold(f64::INFINITY, f64::min);
                (out, super::median(&mut times), min)
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

pub use super::tangents_plot::{scaling_svg, svg};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn surfaces_have_about_the_asked_size_and_exact_frames_are_unit() {
        for s in [Surface::Sphere, Surface::Torus, Surface::WavyGrid] {
            let c = build(s, 10_000);
            let t = c.triangles();
            assert!((9_000..=11_000).contains(&t), "{s:?}: {t}");
            for (e, n) in c.exact.iter().zip(&c.normals) {
                assert!((dot(*e, *e) - 1.0).abs() < 1e-4 && dot(*e, *n).abs() < 1e-4);
            }
        }
        assert_eq!(build(Surface::Fan, 200).triangles(), 200);
    }

    #[test]
    #[cfg(feature = "reference")]
    fn both_engines_agree_and_are_accurate_on_a_small_torus() {
        let opts = Options {
            surfaces: vec![Surface::Torus],
            sizes: vec![2_000],
            fan_triangles: 100,
            runs: 1,
            ..Options::default()
        };
        let r = run(&opts, |_| {}).expect("no files to read");
        assert_eq!(r.rows.len(), 4);
        for row in &r.rows {
            assert_eq!(row.identical_to_reference, Some(3 * row.triangles), "{row:?}");
            let ex = row.vs_exact.as_ref().expect("surfaces have exact tangents");
            assert_eq!(ex.sign_errors, 0);
            assert_eq!(ex.missing, 0);
            assert!(ex.max_deg < 5.0, "{row:?}");
        }
        let svg = svg(&r);
        assert!(svg.starts_with("<svg") && svg.contains("</svg>"));
        // One line per surface and engine (the fan is not a size series).
        let scaling = scaling_svg(&r);
        assert_eq!(scaling.matches("<polyline").count(), 2, "{scaling}");
        assert!(scaling.contains("torus fast") && scaling.contains("torus bevy_mikktspace"));
        assert!(serde_json::to_string(&r).is_ok());
    }

    #[test]
    #[cfg(feature = "reference")]
    fn real_meshes_are_compared_with_the_reference_only() {
        let spot = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/spot/spot.obj");
        let opts = Options { surfaces: vec![], fan_triangles: 0, runs: 1, meshes: vec![spot], ..Options::default() };
        let r = run(&opts, |_| {}).expect("spot reads");
        assert_eq!(r.rows.len(), 2);
        for row in &r.rows {
            assert_eq!((row.name.as_str(), row.triangles, row.surface), ("spot.obj", 5856, Surface::Mesh));
            assert!(row.vs_exact.is_none());
            assert_eq!(row.identical_to_reference, Some(3 * 5856), "{row:?}");
        }
        let missing = Options { meshes: vec!["no/such.obj".into()], ..opts };
        assert!(run(&missing, |_| {}).is_err());
    }
}
