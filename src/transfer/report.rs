//! What a `bake --from` run did: for the whole run, per material (one map each) and per LOW
//! part, with the parts paired by name and those left unmatched.

use crate::timings::Timings;
use std::path::PathBuf;

/// Counts of what happened, per texel unless named otherwise.
#[derive(Debug, Clone, Default, serde::Serialize, PartialEq)]
pub struct Counts {
    /// Texels with a sample inside a UV triangle.
    pub covered: usize,
    /// Texels just outside an island, filled by continuing its border triangle.
    pub extended: usize,
    pub padded: usize,
    /// Texels left flat: no triangle and no island within the padding.
    pub uncovered: usize,
    pub rays: usize,
    /// Rays that met nothing within reach: their samples are flat.
    pub missed_rays: usize,
    pub texels_with_misses: usize,
    /// Samples inside two or more UV triangles (the lowest-numbered triangle is baked).
    pub overlapping_samples: usize,
    /// LOW triangles without UV area (nothing to bake them into).
    pub zero_uv_triangles: usize,
    /// Hits whose normal faces away from LOW's side (tangent-space z < 0): clamped to z = 0.
    pub clamped_below: usize,
    /// Samples where LOW's frame is degenerate (zero normal or tangent): flat.
    pub degenerate_frames: usize,
}

impl Counts {
    pub fn add(&mut self, o: &Counts) {
        self.covered += o.covered;
        self.extended += o.extended;
        self.padded += o.padded;
        self.uncovered += o.uncovered;
        self.rays += o.rays;
        self.missed_rays += o.missed_rays;
        self.texels_with_misses += o.texels_with_misses;
        self.overlapping_samples += o.overlapping_samples;
        self.zero_uv_triangles += o.zero_uv_triangles;
        self.clamped_below += o.clamped_below;
        self.degenerate_frames += o.degenerate_frames;
    }
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct HighFile {
    pub file: PathBuf,
    pub triangles: usize,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct HighPartReport {
    pub name: String,
    pub file: PathBuf,
    pub triangles: usize,
}

/// LOW parts and the HIGH parts their rays meet (and only those).
#[derive(Debug, Clone, serde::Serialize)]
pub struct Pair {
    pub low: Vec<String>,
    pub high: Vec<String>,
}

/// One LOW part within one material's map.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct PartStats {
    pub name: String,
    pub triangles: usize,
    /// Texels (covered or at island borders) whose first sample came from this part.
    pub texels: usize,
    pub rays: usize,
    pub missed_rays: usize,
    /// Signed distance from LOW to HIGH along this part's rays (world units), over all hits.
    pub distance_range: Option<[f32; 2]>,
}

impl PartStats {
    pub fn add(&mut self, o: &PartStats) {
        self.texels += o.texels;
        self.rays += o.rays;
        self.missed_rays += o.missed_rays;
        self.distance_range = match (self.distance_range, o.distance_range) {
            (Some([a, b]), Some([c, d])) => Some([a.min(c), b.max(d)]),
            (x, None) => x,
            (None, y) => y,
        };
    }

    pub fn hit(&mut self, t: f32) {
        self.distance_range = Some(match self.distance_range {
            Some([a, b]) => [a.min(t), b.max(t)],
            None => [t, t],
        });
    }
}

/// What baking one material's map did.
#[derive(Debug, Clone, serde::Serialize)]
pub struct MaterialBake {
    pub material: usize,
    pub name: Option<String>,
    /// The extra files written for it (`--map-out`, `--height-out`, `--miss-mask`).
    pub files: Vec<PathBuf>,
    pub low_triangles: usize,
    pub counts: Counts,
    pub height_range: Option<[f32; 2]>,
    pub parts: Vec<PartStats>,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct TransferReport {
    pub high: Vec<HighFile>,
    pub cage: Option<PathBuf>,
    /// Over every material baked.
    pub low_triangles: usize,
    pub width: usize,
    pub height: usize,
    pub samples_per_texel: usize,
    pub ray_front: f64,
    pub ray_back: f64,
    /// Summed over every material's map.
    pub counts: Counts,
    /// Signed distance from LOW to HIGH along the rays (world units), over all hits.
    pub height_range: Option<[f32; 2]>,
    pub bvh_nodes: usize,
    /// Bytes HIGH takes while rays are cast (trees, positions, triangles, normals).
    pub high_bytes: usize,
    /// `auto` or `none`.
    pub matching: String,
    pub pairs: Vec<Pair>,
    pub unmatched_low: Vec<String>,
    pub unmatched_high: Vec<String>,
    pub high_parts: Vec<HighPartReport>,
    pub materials: Vec<MaterialBake>,
    pub timings_ms: Timings,
}
