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
pub mod files;
pub mod high;
pub mod mesh;
pub mod pad;
pub mod parts;
pub mod raster;
pub mod raycast;
pub mod report;

use crate::error::{Error, Result};
use crate::normalmap::Convention;
use crate::progress::Reporter;
use crate::scene::{PrimRef, ReadOptions, Scene};
use crate::timings::Timings;
use glam::{Mat3A, Vec3A};
use high::HighMesh;
use mesh::{High, Low, Placed};
pub use parts::Match;
use raster::{Edges, UvTri};
use rayon::prelude::*;
pub use report::{Counts, TransferReport};
use report::{HighFile, HighPartReport, MaterialBake, Pair, PartStats};
use std::path::PathBuf;

/// Default ray reach on each side of LOW, as a fraction of LOW's bounding-box diagonal.
pub const DEFAULT_REACH: f64 = 0.05;
/// Texel rows rasterised together.
const BAND: usize = 8;

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
    /// Also write the map to this file (PNG, TIFF or EXR), in `convention`.
    pub map_out: Option<PathBuf>,
    pub convention: Convention,
    pub height_out: Option<PathBuf>,
    pub miss_mask: Option<PathBuf>,
    pub read: ReadOptions,
    /// Told how the rays advance (stage `bake --from`, in rows of the maps).
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

/// Per texel, what its samples gave.
#[derive(Clone, Copy, Default)]
pub(super) struct Texel {
    pub(super) normal: [f32; 3],
    /// 0: nothing, 1: extended, 2: covered.
    pub(super) state: u8,
    pub(super) samples: u16,
    pub(super) missed: u16,
    pub(super) height: f32,
    pub(super) hits: u16,
    /// The LOW part of the texel's first sample.
    pub(super) part: u32,
}

/// Bakes HIGH into LOW once per material in `materials` (each its own map, over the triangle
/// primitives that use it).
pub fn bake_materials(scene: &Scene, materials: &[usize], s: &Settings) -> Result<Baked> {
    bake(scene, materials, s)
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
/// use it (which must carry tangents already). HIGH is read and its trees built once.
pub fn bake(scene: &Scene, materials: &[usize], s: &Settings) -> Result<Baked> {
    bake_from(scene, materials, s, Vec::new())
}

/// [`bake`] with HIGH meshes already in memory, as [`read_high`](crate::transfer::high) hands them
/// over: they stand for the first of `s.highs` (whose names then only label the report), and
/// the rest are read.
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
    s.progress.start("bake --from", (s.height * n_maps) as u64, "rows");
    for (k, &m) in materials.iter().enumerate() {
        let pick: Vec<(Placed, u32)> =
            placed.iter().zip(&low_part).skip(offset).take(per_mat[k].len()).map(|(p, &i)| (p.clone(), i)).collect();
        offset += per_mat[k].len();
        let (pl, part): (Vec<Placed>, Vec<u32>) = pick.into_iter().unzip();
        let mut low = t.time("low", || mesh::low(scene, &pl, &part, origin, diagonal))?;
        if let Some(c) = &s.cage {
            low.cage = Some(t.time("cage", || mesh::cage(c, &s.read, s.node.as_deref(), &pl, &low))?);
        }
        let ctx = Ctx {
            low: &low,
            sets: &sets,
            low_set: &groups.low_set,
            parts: low_names.len(),
            normals: &normals,
            front,
            back,
        };
        let (texels, mut c, mut part_stats) = t.time("rays", || ctx.trace(s));
        crate::timings::mem_mark("transfer rays");
        let (w, h) = (s.width, s.height);
        let mut n: Vec<[f32; 3]> = texels.par_iter().map(|x| x.normal).collect();
        let mut filled: Vec<bool> = texels.par_iter().map(|x| x.state > 0).collect();
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
        bvh_nodes: sets.bvhs.iter().map(|b| b.nodes.len()).sum(),
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
        return Err(Error::usage("bake --from: give at least one HIGH mesh"));
    }
    // About 40 bytes per texel are held while baking: 8192² is 2.7 GB.
    if s.width == 0 || s.height == 0 || s.width > 8192 || s.height > 8192 {
        return Err(Error::usage("--size: each side must be 1 to 8192 texels"));
    }
    if !(1..=8).contains(&s.samples) {
        return Err(Error::usage("--samples: 1 to 8 (samples per texel along each axis)"));
    }
    for (name, v) in [("--ray-front", s.ray_front), ("--ray-back", s.ray_back)] {
        if let Some(v) = v {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::usage(format!("{name} must be a distance >= 0")));
            }
        }
    }
    Ok(())
}

struct Ctx<'a> {
    low: &'a Low,
    sets: &'a Sets,
    /// Per LOW part, the set of HIGH parts its rays meet.
    low_set: &'a [usize],
    parts: usize,
    /// HIGH's normals, which the trees' triangles index.
    normals: &'a [[f32; 3]],
    front: f64,
    back: f64,
}

/// What one ray gave: the tangent-space normal and the signed distance to HIGH, if it hit.
struct Sample {
    ts: Vec3A,
    t: Option<f32>,
}

impl Ctx<'_> {
    fn trace(&self, s: &Settings) -> (Vec<Texel>, Counts, Vec<PartStats>) {
        let (w, h, n) = (s.width, s.height, s.samples);
        let low = self.low;
        let mut c = Counts::default();
        let edges: Vec<Option<Edges>> = low
            .triangles
            .iter()
            .map(|t| {
                let p = t.map(|i| {
                    let uv = low.uvs[i as usize];
                    [uv[0] * w as f32, uv[1] * h as f32]
                });
                Edges::new(&UvTri { p })
            })
            .collect();
        c.zero_uv_triangles = edges.iter().filter(|e| e.is_none()).count();
        let bands = h.div_ceil(BAND);
        let mut per_band: Vec<Vec<u32>> = vec![Vec::new(); bands];
        for (i, e) in edges.iter().enumerate() {
            let Some(e) = e else { continue };
            if !(e.max[1] >= 0.0 && e.min[1] < h as f32 && e.max[0] >= 0.0 && e.min[0] < w as f32) {
                continue;
            }
            let b0 = (e.min[1].max(0.0) as usize / BAND).min(bands - 1);
            let b1 = (e.max[1].max(0.0) as usize / BAND).min(bands - 1);
            (b0..=b1).for_each(|b| per_band[b].push(i as u32));
        }
        // Written on every core: each page is first touched, and faulted in, by one of them.
        let mut texels: Vec<Texel> = (0..w * h).into_par_iter().map(|_| Texel::default()).collect();
        let band_counts: Vec<(Counts, Vec<PartStats>)> = texels
            .par_chunks_mut(BAND * w)
            .enumerate()
            .map(|(b, out)| {
                let y0 = b * BAND;
                let y1 = (y0 + BAND).min(h);
                let r = self.band(&edges, &per_band[b], y0, y1, w, n, out);
                s.progress.tick((y1 - y0) as u64);
                r
            })
            .collect();
        let mut parts = vec![PartStats::default(); self.parts];
        for (b, ps) in band_counts {
            parts.iter_mut().zip(&ps).for_each(|(a, x)| a.add(x));
            c.add(&b);
        }
        (texels, c, parts)
    }

    #[allow(clippy::too_many_arguments)]
    fn band(
        &self,
        edges: &[Option<Edges>],
        cand: &[u32],
        y0: usize,
        y1: usize,
        w: usize,
        n: usize,
        out: &mut [Texel],
    ) -> (Counts, Vec<PartStats>) {
        let mut c = Counts::default();
        let mut parts = vec![PartStats::default(); self.parts];
        let samples = raster::band(edges, cand, y0, y1, w, n);
        c.overlapping_samples = samples.overlapping;
        let sw = w * n;
        let mut stack = raycast::Stack::default();
        // Square tiles of BAND x BAND texels, one after another: neighbouring rays meet the same
        // part of HIGH's tree while it is still in cache. Each texel's samples keep their order
        // (rows, then columns), so the sums are the same as row by row.
        let order = (0..w.div_ceil(BAND)).flat_map(|tx| {
            let (a, b) = (tx * BAND * n, ((tx + 1) * BAND).min(w) * n);
            (0..samples.owner.len() / sw).flat_map(move |sy| (a..b).map(move |sx| sy * sw + sx))
        });
        for s in order {
            let t = samples.owner[s];
            if t == u32::MAX {
                continue;
            }
            let (sx, sy) = (s % sw, s / sw);
            let (x, y) = raster::sample_pos(sx, sy, y0, n);
            let texel = (sy / n) * w + sx / n;
            let e = edges[t as usize].as_ref().expect("owners have edges");
            let r = self.sample(t as usize, e.bary(x, y), &mut c, &mut stack);
            let part = self.low.tri_part[t as usize];
            let ps = &mut parts[part as usize];
            ps.rays += 1;
            let o = &mut out[texel];
            if o.samples == 0 {
                o.part = part;
            }
            o.state = o.state.max(if samples.inside(s) { 2 } else { 1 });
            o.samples += 1;
            // The samples' sum, normalised below.
            o.normal = (Vec3A::from(o.normal) + r.ts).to_array();
            match r.t {
                Some(d) => {
                    o.height += d;
                    o.hits += 1;
                    ps.hit(d);
                }
                None => {
                    o.missed += 1;
                    ps.missed_rays += 1;
                }
            }
        }
        // The band's texels are counted here, on the core that traced them.
        for o in out.iter_mut() {
            match o.state {
                2 => c.covered += 1,
                1 => c.extended += 1,
                _ => {}
            }
            c.texels_with_misses += (o.missed > 0) as usize;
            if o.state > 0 {
                parts[o.part as usize].texels += 1;
            }
            if o.samples > 0 {
                let v = Vec3A::from(o.normal).normalize_or(Vec3A::Z);
                o.normal = v.to_array();
                if o.hits > 0 {
                    o.height /= o.hits as f32;
                }
            }
        }
        (c, parts)
    }

    /// One ray from LOW triangle `t` at barycentrics `b`.
    fn sample(&self, t: usize, b: [f32; 3], c: &mut Counts, stack: &mut raycast::Stack) -> Sample {
        let low = self.low;
        let tri = low.triangles[t];
        let mix = |f: &dyn Fn(usize) -> Vec3A| {
            f(tri[0] as usize) * b[0] + f(tri[1] as usize) * b[1] + f(tri[2] as usize) * b[2]
        };
        let p = mix(&|i| low.positions[i]);
        let nrm = mix(&|i| low.normals[i]);
        let tan = mix(&|i| Vec3A::from_slice(&low.tangents[i][..3]));
        let w = low.tangents[tri[0] as usize][3] * b[0]
            + low.tangents[tri[1] as usize][3] * b[1]
            + low.tangents[tri[2] as usize][3] * b[2];
        let sign = if w < 0.0 { -1.0 } else { 1.0 };
        c.rays += 1;
        let flat = Sample { ts: Vec3A::Z, t: None };
        let Some(nhat) = nrm.try_normalize() else {
            c.degenerate_frames += 1;
            c.missed_rays += 1;
            return flat;
        };
        let (dir, front, back) = match &low.cage {
            Some(cage) => {
                let q = cage[t][0] * b[0] + cage[t][1] * b[1] + cage[t][2] * b[2];
                let d = q - p;
                let len = d.length();
                if len > 1e-7 * low.diagonal as f32 {
                    (d / len, len, self.back as f32)
                } else {
                    (nhat, 0.0, self.back as f32)
                }
            }
            None => (nhat, self.front as f32, self.back as f32),
        };
        let set = self.low_set[low.tri_part[t] as usize];
        let tree = &self.sets.bvhs[set];
        let Some(hit) = raycast::nearest(tree, &raycast::Ray::new(p, dir), back, front, stack) else {
            c.missed_rays += 1;
            return flat;
        };
        let ni = tree.index(hit.slot as usize);
        let n = |k: usize| Vec3A::from(self.normals[ni[k] as usize]) * hit.bary[k];
        let hn = (n(0) + n(1) + n(2)).normalize_or_zero();
        let bit = nrm.cross(tan) * sign;
        let m = Mat3A::from_cols(tan, bit, nrm);
        let det = m.determinant();
        let scale = tan.length() * bit.length() * nrm.length();
        if hn == Vec3A::ZERO || det.is_nan() || det.abs() <= 1e-6 * scale {
            c.degenerate_frames += 1;
            return Sample { ts: Vec3A::Z, t: Some(hit.t) };
        }
        let mut ts = (m.inverse() * hn).normalize_or(Vec3A::Z);
        if ts.z < 0.0 {
            c.clamped_below += 1;
            ts.z = 0.0;
            ts = ts.normalize_or(Vec3A::Z);
        }
        Sample { ts, t: Some(hit.t) }
    }
}
