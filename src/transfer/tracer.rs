//! The rays of one map: per texel of LOW's UV layout, its samples' rays into HIGH's trees, and
//! what they gave ([`Texel`]).

use super::mesh::Low;
use super::raster::{self, Edges, UvTri};
use super::report::{Counts, PartStats};
use super::{bvh, packet, raycast, Settings};
use glam::{Mat3A, Vec3A};
use rayon::prelude::*;

/// Texel rows rasterised together.
const BAND: usize = 8;
/// The side of a square of texels whose rays are cast together: [`packet::PACKET`] rays at one
/// sample a texel (on the 600k HIGH at 1024², 3.2 rays of a packet reach each leaf it visits
/// from a 4 x 4 block, 2.4 from two rows of 8).
const BLOCK: usize = 4;

/// How far a texel's samples found LOW; ordered, so that a texel keeps the best any sample gave.
#[derive(Clone, Copy, Default, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(super) enum Coverage {
    /// No sample: left for the padding.
    #[default]
    None,
    /// Samples just outside an island only, continuing its border triangle.
    Extended,
    /// A sample inside a UV triangle.
    Covered,
}

/// Per texel, what its samples gave.
#[derive(Clone, Copy, Default)]
pub(super) struct Texel {
    pub(super) normal: [f32; 3],
    pub(super) coverage: Coverage,
    pub(super) samples: u16,
    pub(super) missed: u16,
    pub(super) height: f32,
    pub(super) hits: u16,
    /// The LOW part of the texel's first sample.
    pub(super) part: u32,
}

/// What the rays of one material's map share: LOW, HIGH's trees, and how far a ray reaches.
pub(super) struct Tracer<'a> {
    pub(super) low: &'a Low,
    /// HIGH's trees, one per set of HIGH parts (`low_set` picks a LOW part's).
    pub(super) trees: &'a [bvh::Bvh],
    /// Per LOW part, the set of HIGH parts its rays meet.
    pub(super) low_set: &'a [usize],
    pub(super) parts: usize,
    /// HIGH's normals, which the trees' triangles index.
    pub(super) normals: &'a [[f32; 3]],
    pub(super) front: f64,
    pub(super) back: f64,
    /// Whether HIGH is hit from its front only ([`raycast::Ray::front_faces_only`]).
    pub(super) front_faces_only: bool,
}

/// What one ray gave: the tangent-space normal and the signed distance to HIGH, if it hit.
struct Sample {
    ts: Vec3A,
    t: Option<f32>,
}

impl Sample {
    /// A sample without a hit, or without a frame to shade one in.
    const FLAT: Sample = Sample { ts: Vec3A::Z, t: None };
}

/// A sample's ray, before it is traced, and the frame its hit is shaded in.
struct Pending {
    ray: raycast::Ray,
    back: f32,
    front: f32,
    /// Which of HIGH's trees the ray goes into.
    set: usize,
    nrm: Vec3A,
    tan: Vec3A,
    sign: f32,
}

/// The value `f` gives at corners `tri`, interpolated with barycentrics `b`.
#[inline(always)]
fn mix(tri: [u32; 3], b: [f32; 3], f: impl Fn(usize) -> Vec3A) -> Vec3A {
    f(tri[0] as usize) * b[0] + f(tri[1] as usize) * b[1] + f(tri[2] as usize) * b[2]
}

/// A sample as it waits for its packet.
enum Prep {
    Done(Sample),
    Trace(Pending),
}

/// Samples waiting for their packet ([`packet::nearest_packet`]): neighbouring samples' rays
/// are traced together once [`packet::PACKET`] of them into one tree are queued.
#[derive(Default)]
struct Queue {
    /// Each sample's index in the band, its texel's, and what it waits with.
    samples: Vec<(usize, usize, Prep)>,
    /// The queued samples' rays, with their reach behind and ahead.
    rays: Vec<(raycast::Ray, f32, f32)>,
    /// Which of HIGH's trees they go into.
    set: usize,
    /// After [`Queue::trace`], the rays' hits.
    hits: Vec<Option<raycast::Hit>>,
    stack: packet::PacketStack,
}

impl Queue {
    /// Whether the queued rays must be traced before `prep` joins them: the packet is full, or
    /// `prep`'s ray goes into another tree.
    fn full_for(&self, prep: &Prep) -> bool {
        let full = self.rays.len() == packet::PACKET;
        matches!(prep, Prep::Trace(p) if full || (!self.rays.is_empty() && p.set != self.set))
    }

    fn push(&mut self, s: usize, texel: usize, prep: Prep) {
        if let Prep::Trace(p) = &prep {
            self.rays.push((p.ray, p.back, p.front));
            self.set = p.set;
        }
        self.samples.push((s, texel, prep));
    }

    /// Traces the queued rays into `hits`.
    fn trace(&mut self, trees: &[bvh::Bvh]) {
        self.hits.clear();
        self.hits.resize(self.rays.len(), None);
        if !self.rays.is_empty() {
            packet::nearest_packet(&trees[self.set], &self.rays, &mut self.hits, &mut self.stack);
        }
    }
}

impl Tracer<'_> {
    /// Every texel of the map: its samples' rays, summed.
    pub(super) fn trace(&self, s: &Settings) -> (Vec<Texel>, Counts, Vec<PartStats>) {
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
        // A task a band: in larger tasks the last one left ran on one core for a tenth of the
        // rays' time.
        let band_counts: Vec<(Counts, Vec<PartStats>)> = texels
            .par_chunks_mut(BAND * w)
            .with_max_len(1)
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
        let rows = samples.owner.len() / sw;
        let mut queue = Queue::default();
        // Traces the queued samples' rays and sums what each sample gave into its texel, in the
        // samples' order.
        let mut record = |queue: &mut Queue, c: &mut Counts| {
            queue.trace(self.trees);
            let mut hits = queue.hits.iter();
            for (s, texel, prep) in queue.samples.drain(..) {
                let t = samples.owner[s];
                let r = match prep {
                    Prep::Done(r) => r,
                    Prep::Trace(p) => self.finish(&p, *hits.next().expect("a hit a ray"), c),
                };
                let part = self.low.tri_part[t as usize];
                let ps = &mut parts[part as usize];
                ps.rays += 1;
                let o = &mut out[texel];
                if o.samples == 0 {
                    o.part = part;
                }
                o.coverage = o.coverage.max(if samples.inside(s) { Coverage::Covered } else { Coverage::Extended });
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
            queue.rays.clear();
        };
        // Blocks of BLOCK x BLOCK texels, one after another, down the band and then across it:
        // a packet's rays come from one block, whose rays meet nearly the same nodes, and the
        // next blocks' rays meet the same part of HIGH's tree while it is still in cache. Each
        // texel's samples lie in one block and keep their order (rows, then columns), so the
        // sums are the same as row by row.
        for bx in 0..w.div_ceil(BLOCK) {
            let columns = bx * BLOCK * n..((bx + 1) * BLOCK).min(w) * n;
            for by in 0..rows.div_ceil(BLOCK * n) {
                for sy in by * BLOCK * n..((by + 1) * BLOCK * n).min(rows) {
                    for sx in columns.clone() {
                        let s = sy * sw + sx;
                        let t = samples.owner[s];
                        if t == u32::MAX {
                            continue;
                        }
                        let (x, y) = raster::sample_pos(sx, sy, y0, n);
                        let e = edges[t as usize].as_ref().expect("owners have edges");
                        let prep = self.prepare(t as usize, e.bary(x, y), &mut c);
                        if queue.full_for(&prep) {
                            record(&mut queue, &mut c);
                        }
                        queue.push(s, (sy / n) * w + sx / n, prep);
                    }
                }
            }
        }
        record(&mut queue, &mut c);
        // The band's texels are counted here, on the core that traced them.
        for o in out.iter_mut() {
            match o.coverage {
                Coverage::Covered => c.covered += 1,
                Coverage::Extended => c.extended += 1,
                Coverage::None => {}
            }
            c.texels_with_misses += (o.missed > 0) as usize;
            if o.coverage != Coverage::None {
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

    /// One sample from LOW triangle `t` at barycentrics `b`: its ray, or what it gives if it
    /// has none.
    fn prepare(&self, t: usize, b: [f32; 3], c: &mut Counts) -> Prep {
        let low = self.low;
        let tri = low.triangles[t];
        let p = mix(tri, b, |i| low.positions[i]);
        let nrm = mix(tri, b, |i| low.normals[i]);
        let tan = mix(tri, b, |i| Vec3A::from_slice(&low.tangents[i][..3]));
        let w = low.tangents[tri[0] as usize][3] * b[0]
            + low.tangents[tri[1] as usize][3] * b[1]
            + low.tangents[tri[2] as usize][3] * b[2];
        let sign = if w < 0.0 { -1.0 } else { 1.0 };
        c.rays += 1;
        let Some(nhat) = nrm.try_normalize() else {
            c.degenerate_frames += 1;
            c.missed_rays += 1;
            return Prep::Done(Sample::FLAT);
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
        let mut ray = raycast::Ray::new(p, dir);
        if self.front_faces_only {
            ray = ray.front_faces_only();
        }
        Prep::Trace(Pending { ray, back, front, set, nrm, tan, sign })
    }

    /// What sample `p`'s ray gave, in LOW's tangent space.
    fn finish(&self, p: &Pending, hit: Option<raycast::Hit>, c: &mut Counts) -> Sample {
        let Some(hit) = hit else {
            c.missed_rays += 1;
            return Sample::FLAT;
        };
        let tree = &self.trees[p.set];
        let ni = tree.index(hit.slot as usize);
        let n = |k: usize| Vec3A::from(self.normals[ni[k] as usize]) * hit.bary[k];
        let hn = (n(0) + n(1) + n(2)).normalize_or_zero();
        let (tan, nrm) = (p.tan, p.nrm);
        let bit = nrm.cross(tan) * p.sign;
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
