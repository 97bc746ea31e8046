//! `bake LOW --from HIGH`: HIGH's surface detail baked into a normal map over LOW's UV layout.
//!
//! For every sample of every texel LOW's UV triangles cover ([`raster`]), a ray leaves LOW's
//! surface along its interpolated smooth normal (or towards the cage) and the hit nearest LOW
//! within `[-back, front]` is found in a BVH over HIGH ([`bvh`], [`raycast`]). HIGH's
//! interpolated normal there is written in the tangent frame a renderer rebuilds from the
//! `NORMAL`, `TANGENT` and `w` bumpbake writes into OUT, interpolated per pixel and not
//! normalised (`B = w * cross(N, T)`, the MikkTSpace pixel-shader convention): the map decodes
//! to HIGH's normal exactly, up to the encoding's rounding. Islands are padded ([`pad`]).

pub mod bvh;
pub mod dither;
pub mod files;
pub mod high;
pub mod mesh;
pub mod packet;
pub mod pad;
pub mod parts;
pub mod raster;
pub mod raycast;
pub mod report;
mod tracer;

use crate::error::{Error, Result, Setting, Words};
use crate::normalmap::Convention;
use crate::progress::Reporter;
use crate::scene::{PrimRef, ReadOptions, Scene};
use crate::timings::Timings;
use high::HighMesh;
use mesh::{High, Placed};
pub use parts::Match;
use rayon::prelude::*;
pub use report::{Counts, TransferReport};
use report::{HighFile, HighPartReport, MaterialBake, Pair};
use std::path::PathBuf;
use tracer::{Coverage, Tracer};

/// The progress stage of the rays, in rows of the maps.
pub const STAGE: &str = "trace rays";

/// Default ray reach on each side of LOW, as a fraction of LOW's bounding-box diagonal.
pub const DEFAULT_REACH: f64 = 0.05;

#[derive(Debug, Clone)]
pub struct Settings {
    pub highs: Vec<PathBuf>,
    pub cage: Option<PathBuf>,
    /// Reach outside LOW (along the normal), scene units; default [`DEFAULT_REACH`].
    pub ray_front: Option<f64>,
    /// Reach inside LOW.
    pub ray_back: Option<f64>,
    /// Samples per texel along each axis (`n x n` rays per texel).
    pub samples: usize,
    pub width: usize,
    pub height: usize,
    pub padding: usize,
    pub sixteen_bit: bool,
    /// 8-bit maps get the deterministic triangular dither of [`dither`] before rounding, so a
    /// gentle gradient does not band (16-bit and float maps are never dithered).
    pub dither: bool,
    /// HIGH triangles are hit only from their front (counter-clockwise corners, as glTF and OBJ
    /// wind them), as if every ray came from beyond its outer end (the cage, or the reach
    /// outside LOW) towards LOW: a triangle facing into LOW is passed through, whichever side
    /// of LOW it lies on.
    pub ignore_backfaces: bool,
    /// Also write the map to this file (PNG, TIFF or EXR), in `convention`.
    pub map_out: Option<PathBuf>,
    pub convention: Convention,
    pub height_out: Option<PathBuf>,
    pub miss_mask: Option<PathBuf>,
    pub read: ReadOptions,
    /// Told how the rays advance (stage [`STAGE`], in rows of the maps).
    pub progress: Reporter,
    /// How LOW parts find their HIGH parts.
    pub matching: Match,
    /// The node to bake a LOW mesh shown by several nodes through.
    pub node: Option<String>,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            highs: Vec::new(),
            cage: None,
            ray_front: None,
            ray_back: None,
            samples: 1,
            width: 1024,
            height: 1024,
            padding: 16,
            sixteen_bit: false,
            dither: false,
            ignore_backfaces: false,
            map_out: None,
            convention: Convention::Opengl,
            height_out: None,
            miss_mask: None,
            read: ReadOptions::default(),
            progress: Reporter::none(),
            matching: Match::Auto,
            node: None,
        }
    }
}

/// What the bake made: one map per material (glTF convention, PNG) and any extra files asked for.
pub struct Baked {
    /// `(material, PNG)`, in the order the materials were given.
    pub maps: Vec<(usize, Vec<u8>)>,
    pub files: Vec<(PathBuf, Vec<u8>)>,
    pub report: TransferReport,
}

/// The triangle primitives of LOW that use material `m`.
pub fn material_prims(scene: &Scene, m: usize) -> Vec<PrimRef> {
    scene
        .primitives()
        .into_iter()
        .filter(|&r| scene.material_index(r) == Some(m) && crate::scene::view::is_surface(scene, r))
        .collect()
}

/// HIGH's triangles grouped for the rays of each LOW part: one BVH per set of HIGH parts, each
/// holding its triangles' corners, and their normals' indices, in leaf order.
struct Sets {
    bvhs: Vec<bvh::Bvh>,
}

/// The trees over `sets`; a tree's triangles then index `normal_triangles`' normals, if HIGH has
/// its own normal indices (an OBJ's `vn`), else the normals that follow the positions.
fn build_sets(
    positions: Vec<[f32; 3]>,
    mut triangles: Vec<[u32; 3]>,
    normal_triangles: Option<Vec<[u32; 3]>>,
    parts: &[mesh::HighPart],
    sets: &[Vec<usize>],
) -> Sets {
    let mut bvhs: Vec<Option<bvh::Bvh>> = sets.iter().map(|_| None).collect();
    let nt = normal_triangles.as_deref();
    for (k, set) in sets.iter().enumerate() {
        if set.len() == parts.len() {
            continue;
        }
        let tris: Vec<u32> = set.iter().flat_map(|&k| parts[k].start..parts[k].end).collect();
        let sub: Vec<[u32; 3]> = tris.iter().map(|&t| triangles[t as usize]).collect();
        let index = |i: u32| nt.map(|nt| nt[tris[i as usize] as usize]);
        bvhs[k] = Some(bvh::Bvh::build_indexed(&positions, sub, index));
    }
    // Every HIGH part: the tree takes HIGH's triangles over (permuted into leaf order), no copy.
    for (k, set) in sets.iter().enumerate() {
        if set.len() == parts.len() {
            let index = |i: u32| nt.map(|nt| nt[i as usize]);
            bvhs[k] = Some(bvh::Bvh::build_indexed(&positions, std::mem::take(&mut triangles), index));
        }
    }
    Sets { bvhs: bvhs.into_iter().map(|b| b.expect("every set built")).collect() }
}

/// Bakes HIGH into LOW: one map per material in `materials`, over the triangle primitives that
/// use it (which must carry tangents already). HIGH is read and its trees built once. `high`:
/// HIGH meshes already in memory, as [`high::read_high`] hands them over, which stand for the
/// first of `s.highs` (whose names then only label the report; the rest are read); empty, all
/// are read.
pub fn bake_from(scene: &Scene, materials: &[usize], s: &Settings, high: Vec<HighMesh>) -> Result<Baked> {
    check(s)?;
    let mut t = Timings::default();
    let per_mat: Vec<Vec<PrimRef>> = materials.iter().map(|&m| material_prims(scene, m)).collect();
    let all: Vec<PrimRef> = per_mat.iter().flatten().copied().collect();
    let placed = t.time("low", || mesh::place(scene, &all, s.node.as_deref()))?;
    if placed.is_empty() {
        return Err(scene.err("no triangle primitive to bake onto (the material has no mesh)"));
    }
    let (low_names, low_part) = mesh::low_parts(&placed);
    let (origin, diagonal) = mesh::frame(scene, &placed)?;
    let (high, counts, high_parts) = t.time("read high", || mesh::high(&s.highs, &s.read, origin, high))?;
    crate::timings::mem_mark("transfer read");
    let high_names: Vec<String> = high_parts.iter().map(|p| p.name.clone()).collect();
    let groups = parts::group(&low_names, &high_names, s.matching);
    let High { positions, triangles, normals, normal_triangles } = high;
    let sets = t.time("bvh", || build_sets(positions, triangles, normal_triangles, &high_parts, &groups.sets));
    crate::timings::mem_mark("transfer bvh");
    let high_bytes = sets.bvhs.iter().map(|b| b.bytes()).sum::<usize>() + normals.capacity() * 12;
    let front = s.ray_front.unwrap_or(DEFAULT_REACH * diagonal);
    let back = s.ray_back.unwrap_or(DEFAULT_REACH * diagonal);
    let labels = files::unique_labels(scene, materials);
    let mut maps = Vec::new();
    let mut files = Vec::new();
    let mut mats = Vec::new();
    let mut offset = 0;
    let n_maps = materials.len();
    s.progress.start(STAGE, (s.height * n_maps) as u64, "rows");
    for (k, &m) in materials.iter().enumerate() {
        let pick: Vec<(Placed, u32)> =
            placed.iter().zip(&low_part).skip(offset).take(per_mat[k].len()).map(|(p, &i)| (p.clone(), i)).collect();
        offset += per_mat[k].len();
        let (pl, part): (Vec<Placed>, Vec<u32>) = pick.into_iter().unzip();
        let mut low = t.time("low", || mesh::low(scene, &pl, &part, origin, diagonal))?;
        if let Some(c) = &s.cage {
            low.cage = Some(t.time("cage", || mesh::cage(c, &s.read, s.node.as_deref(), &pl, &low))?);
        }
        let tracer = Tracer {
            low: &low,
            trees: &sets.bvhs,
            low_set: &groups.low_set,
            parts: low_names.len(),
            normals: &normals,
            front,
            back,
            front_faces_only: s.ignore_backfaces,
        };
        let (texels, mut c, mut part_stats) = t.time("rays", || tracer.trace(s));
        crate::timings::mem_mark("transfer rays");
        let (w, h) = (s.width, s.height);
        let mut n: Vec<[f32; 3]> = texels.par_iter().map(|x| x.normal).collect();
        let mut filled: Vec<bool> = texels.par_iter().map(|x| x.coverage != Coverage::None).collect();
        c.padded = t.time("pad", || pad::pad(w, h, &mut n, &mut filled, s.padding));
        c.uncovered = filled.iter().filter(|&&f| !f).count();
        let mut sk = s.clone();
        if n_maps > 1 {
            for f in [&mut sk.map_out, &mut sk.height_out, &mut sk.miss_mask].into_iter().flatten() {
                *f = files::labelled(f, &labels[k]);
            }
        }
        let (png, extra, height_range) = t.time("encode", || files::encode(&sk, &texels, &n))?;
        for (i, st) in part_stats.iter_mut().enumerate() {
            st.name = low_names[i].clone();
            st.triangles = low.tri_part.iter().filter(|&&p| p as usize == i).count();
        }
        let names = scene.materials();
        mats.push(MaterialBake {
            material: m,
            name: names.get(m).and_then(|x| x.name.clone()),
            files: extra.iter().map(|(p, _)| p.clone()).collect(),
            low_triangles: low.triangles.len(),
            counts: c,
            height_range,
            parts: part_stats.into_iter().filter(|p| p.triangles > 0).collect(),
        });
        maps.push((m, png));
        files.extend(extra);
    }
    s.progress.finish();
    let mut counts_all = Counts::default();
    mats.iter().for_each(|m| counts_all.add(&m.counts));
    let height_range = mats.iter().filter_map(|m| m.height_range).reduce(|a, b| [a[0].min(b[0]), a[1].max(b[1])]);
    let rest = groups.sets.len() - 1;
    let report = TransferReport {
        high: s.highs.iter().zip(counts).map(|(f, n)| HighFile { file: f.clone(), triangles: n }).collect(),
        cage: s.cage.clone(),
        low_triangles: mats.iter().map(|m| m.low_triangles).sum(),
        width: s.width,
        height: s.height,
        samples_per_texel: s.samples * s.samples,
        ray_front: front,
        ray_back: back,
        counts: counts_all,
        height_range,
        bvh_nodes: sets.bvhs.iter().map(|b| b.node_count()).sum(),
        high_bytes,
        matching: if s.matching == Match::Auto { "auto" } else { "none" }.to_string(),
        pairs: groups
            .pairs
            .iter()
            .map(|(l, h)| Pair {
                low: l.iter().map(|&i| low_names[i].clone()).collect(),
                high: h.iter().map(|&i| high_names[i].clone()).collect(),
            })
            .collect(),
        unmatched_low: (0..low_names.len())
            .filter(|&i| groups.low_set[i] == rest)
            .map(|i| low_names[i].clone())
            .collect(),
        unmatched_high: groups.sets[rest].iter().map(|&i| high_names[i].clone()).collect(),
        high_parts: high_parts
            .iter()
            .map(|p| HighPartReport {
                name: p.name.clone(),
                file: s.highs[p.file].clone(),
                triangles: (p.end - p.start) as usize,
            })
            .collect(),
        materials: mats,
        timings_ms: t,
    };
    Ok(Baked { maps, files, report })
}

fn check(s: &Settings) -> Result<()> {
    if s.highs.is_empty() {
        let msg = Words::from("no HIGH mesh to bake from (give at least one as ").name(Setting::High).text(")");
        return Err(Error::setting(Setting::High, None, msg));
    }
    // About 40 bytes per texel are held while baking: 8192² is 2.7 GB.
    if s.width == 0 || s.height == 0 || s.width > 8192 || s.height > 8192 {
        let size = format!("{}x{}", s.width, s.height);
        let msg = Words::new().name(Setting::Size).text(": each side must be 1 to 8192 texels");
        return Err(Error::setting(Setting::Size, Some(size), msg));
    }
    if !(1..=8).contains(&s.samples) {
        let msg = Words::new().name(Setting::Samples).text(": 1 to 8 (samples per texel along each axis)");
        return Err(Error::setting(Setting::Samples, Some(s.samples.to_string()), msg));
    }
    for (setting, v) in [(Setting::RayFront, s.ray_front), (Setting::RayBack, s.ray_back)] {
        if let Some(v) = v {
            if !(v.is_finite() && v >= 0.0) {
                let msg = Words::new().name(setting).text(" must be a distance >= 0");
                return Err(Error::setting(setting, Some(v.to_string()), msg));
            }
        }
    }
    Ok(())
}
