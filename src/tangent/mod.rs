//! Tangent frames: MikkTSpace generation ([`mikk`]), the fallback for corners the reference
//! leaves undefined ([`fallback`]), and applying both to a primitive, splitting vertices whose
//! corners got different frames and merging identical ones ([`primitive_with_tangents`]), with
//! TANGENT deltas for the morph targets that move the surface (`morph.rs`).
//! [`apply`] decides which primitives of a scene need tangents.

pub mod apply;
pub mod command;
pub mod fallback;
pub mod fast;
pub mod frames;
pub mod mikk;
mod morph;

use crate::scene::weld::{CornerStream, CornerValues, SplitPlan};
use crate::scene::{flat_normals, Geometry, Primitive, UvSource};
use fallback::FallbackCounts;
use glam::Vec3;
use std::borrow::Cow;

pub use crate::scene::view::gltf_w;

/// An indexed triangle list as MikkTSpace sees it: one normal and one UV per vertex.
#[derive(Debug, Clone, Copy)]
pub struct TriMesh<'a> {
    pub positions: &'a [[f32; 3]],
    pub normals: &'a [[f32; 3]],
    pub uvs: &'a [[f32; 2]],
    /// Three indices per triangle, each `< positions.len()`.
    pub indices: &'a [u32],
}

/// How frames are made.
#[derive(Debug, Clone, Copy, Default)]
pub struct Options {
    /// Also write `_BITANGENT = cross(N, T) * w`.
    pub bitangents: bool,
    pub engine: mikk::Engine,
}

/// What happened to one primitive.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct FrameStats {
    pub vertices_in: usize,
    pub vertices_out: usize,
    pub triangles: usize,
    /// NORMAL was missing and flat normals were made, as the glTF spec asks of a client.
    pub generated_normals: bool,
    pub fallback: FallbackCounts,
}

/// [`gltf_w`] on every frame.
fn to_gltf_w(frames: &mut frames::Frames) {
    frames.values.iter_mut().for_each(|t| t[3] = gltf_w(t[3]));
}

/// The primitive with MikkTSpace tangents from UV set `uv_set` (glTF UVs, fed as stored).
/// The primitive must be a triangle list with that UV set; its old TANGENT is replaced.
pub fn primitive_with_tangents(p: Primitive, uv_set: u32, opts: &Options) -> Primitive {
    primitive_with_stats(p, uv_set, opts).0
}

/// [`primitive_with_tangents`], with what it did. Takes the primitive by value so that each of
/// its streams can be freed as soon as the output's copy of it is made.
pub fn primitive_with_stats(p: Primitive, uv_set: u32, opts: &Options) -> (Primitive, FrameStats) {
    with_frames(Geometry::new(p, UvSource { set: uv_set, transform: None }), opts)
}

/// The primitive of `g` with MikkTSpace tangents from the UVs its tangents follow
/// ([`Geometry::tangent_uvs`]): through a `KHR_texture_transform` the frames follow the
/// transformed UVs (the ones the renderer samples with), while the stored UVs stay as they are.
/// `g` must be a triangle list; its old TANGENT is replaced.
pub fn with_frames(g: Geometry, opts: &Options) -> (Primitive, FrameStats) {
    let p = &g.primitive;
    let vertices_in = p.vertex_count();
    let triangles = p.indices.len() / 3;
    let generated_normals = p.attr("NORMAL").is_none();
    let (plan, fallback) = split_plan(&g, opts);
    let mut out = plan.apply(g.primitive);
    out.mode = 4;
    crate::timings::mem_mark("split");
    let stats = FrameStats { vertices_in, vertices_out: out.vertex_count(), triangles, generated_normals, fallback };
    (out, stats)
}

/// The engine's frames for every corner of a primitive, repaired, with the normals they were made
/// against: what the writers store and [`corner_frames`] returns.
struct Made<'a> {
    frames: frames::Frames,
    normals: Cow<'a, [[f32; 3]]>,
    /// Per corner, the index of its normal in `normals`.
    normal_of: Cow<'a, [u32]>,
    generated_normals: bool,
    fallback: FallbackCounts,
}

impl Made<'_> {
    fn tangent(&self, c: usize) -> [f32; 4] {
        self.frames.get(c, self.normal_of[c]).unwrap_or([0.0; 4])
    }

    /// `cross(N, T) * w`, the `_BITANGENT` every writer stores.
    fn bitangent(&self, c: usize) -> [f32; 3] {
        let t = self.tangent(c);
        let n = Vec3::from(self.normals[self.normal_of[c] as usize]).normalize_or_zero();
        (n.cross(Vec3::new(t[0], t[1], t[2])) * t[3]).to_array()
    }
}

fn made<'a>(g: &'a Geometry, opts: &Options) -> Made<'a> {
    let p = &g.primitive;
    let n_vertices = p.vertex_count();
    // Borrowed from the streams where possible. Without POSITION (callers skip such primitives)
    // the surface is a point.
    let positions = g.positions();
    let uvs = g.tangent_uv_values().unwrap_or_else(|| vec![[0.0; 2]; n_vertices].into());

    // Without NORMAL, flat normals are made per corner (as the glTF spec asks of a client), and
    // MikkTSpace, which only sees values per corner, runs on the unwelded triangles.
    let (normals, normal_of, mut frames, generated_normals): (Cow<[[f32; 3]]>, Cow<[u32]>, _, _) = match g.normals() {
        None => {
            let cp: Vec<[f32; 3]> = p.indices.iter().map(|&i| positions[i as usize]).collect();
            let flat = flat_normals(&cp).0;
            let cu: Vec<[f32; 2]> = p.indices.iter().map(|&i| uvs[i as usize]).collect();
            let corner_ids: Vec<u32> = (0..p.indices.len() as u32).collect();
            let frames = generate_with_stack(
                &TriMesh { positions: &cp, normals: &flat, uvs: &cu, indices: &corner_ids },
                opts.engine,
            );
            (flat.into(), corner_ids.into(), frames, true)
        }
        Some(n) => {
            let frames = generate_with_stack(
                &TriMesh { positions: &positions, normals: &n, uvs: &uvs, indices: &p.indices },
                opts.engine,
            );
            (n, p.indices.as_slice().into(), frames, false)
        }
    };
    drop((positions, uvs));
    crate::timings::mem_mark("engine");
    to_gltf_w(&mut frames);
    let fallback = fallback::repair(
        &mut frames,
        fallback::CornerNormals { normals: &normals, normal_of: &normal_of, vertex: &p.indices },
    );
    crate::timings::mem_mark("repair");
    Made { frames, normals, normal_of, generated_normals, fallback }
}

/// Every corner's frame, as the writers store it (glTF's `w`, fallback frames where MikkTSpace
/// gives none), and its bitangent when [`Options::bitangents`] asks: for callers that keep
/// their own vertices (a DCC's corners), where [`with_frames`] splits and welds a primitive.
#[derive(Debug, Clone)]
pub struct CornerFrames {
    /// `(t.x, t.y, t.z, w)` per corner of the index list.
    pub tangents: Vec<[f32; 4]>,
    /// `cross(N, T) * w` per corner.
    pub bitangents: Option<Vec<[f32; 3]>>,
    pub fallback: FallbackCounts,
    /// NORMAL was missing and flat normals were made.
    pub generated_normals: bool,
}

/// [`CornerFrames`] of `g`, a triangle list.
pub fn corner_frames(g: &Geometry, opts: &Options) -> CornerFrames {
    let m = made(g, opts);
    let corners = g.primitive.indices.len();
    CornerFrames {
        tangents: (0..corners).map(|c| m.tangent(c)).collect(),
        bitangents: opts.bitangents.then(|| (0..corners).map(|c| m.bitangent(c)).collect()),
        fallback: m.fallback,
        generated_normals: m.generated_normals,
    }
}

/// Frames for every corner of `g`, repaired, and the vertices and streams they make: everything
/// that reads the frames, which are freed on return.
fn split_plan(g: &Geometry, opts: &Options) -> (SplitPlan, FallbackCounts) {
    let p = &g.primitive;
    let uv_name = g.tangent_uvs.attribute();
    let m = made(g, opts);
    let (normals, generated_normals) = (&m.normals, m.generated_normals);
    // Every corner has a frame now. Tangents and bitangents are read through the compact frames,
    // never spelt out per corner.
    let tangent = |c: usize| m.tangent(c);
    let bitangent = |c: usize| {
        let b = m.bitangent(c);
        [b[0], b[1], b[2], 0.0]
    };
    let mut extra = Vec::new();
    if generated_normals {
        extra.push(CornerStream {
            at: 1,
            name: "NORMAL",
            ty: "VEC3",
            values: CornerValues::Flat(normals.as_flattened()),
        });
    }
    extra.push(CornerStream { at: usize::MAX, name: "TANGENT", ty: "VEC4", values: CornerValues::Fn(&tangent) });
    if opts.bitangents {
        extra.push(CornerStream {
            at: usize::MAX,
            name: "_BITANGENT",
            ty: "VEC3",
            values: CornerValues::Fn(&bitangent),
        });
    }
    let morph = if morph::needed(p, &uv_name) {
        let base = morph::Base { tangent: &tangent, normals, generated_normals };
        morph::deltas(g, &base, opts.engine)
    } else {
        Vec::new()
    };
    let target_extra: Vec<(usize, CornerStream)> = morph
        .iter()
        .enumerate()
        .map(|(t, d)| {
            (
                t,
                CornerStream {
                    at: usize::MAX,
                    name: "TANGENT",
                    ty: "VEC3",
                    values: CornerValues::Flat(d.as_flattened()),
                },
            )
        })
        .collect();
    (SplitPlan::with_targets(p, &["TANGENT", "_BITANGENT"], &extra, &target_extra), m.fallback)
}

/// Stack bytes the reference needs per triangle around one vertex, with a wide margin.
const STACK_PER_TRIANGLE: usize = 1024;

/// [`mikk::generate`] with enough stack. The reference groups the triangles around each vertex
/// recursively, one stack frame per triangle: 20 000 triangles on one vertex overflow a 2 MiB
/// worker stack and abort the process. When the mesh has a vertex position shared by more than
/// a thousand corners, generation runs on a thread whose stack grows with that count.
/// Only the `bevy_mikktspace` engine recurses; ours walks groups with an explicit stack.
fn generate_with_stack(mesh: &TriMesh, engine: mikk::Engine) -> frames::Frames {
    if engine != mikk::Engine::Bevy {
        return mikk::compact(mesh, engine);
    }
    let mut per_position: std::collections::HashMap<[u32; 3], usize> = std::collections::HashMap::new();
    let mut most = 0;
    for &i in mesh.indices {
        let p = mesh.positions[i as usize];
        let n = per_position.entry([p[0].to_bits(), p[1].to_bits(), p[2].to_bits()]).or_insert(0);
        *n += 1;
        most = most.max(*n);
    }
    if most <= 1000 {
        return mikk::compact(mesh, engine);
    }
    let stack = (4 << 20) + most * STACK_PER_TRIANGLE;
    std::thread::scope(|s| {
        match std::thread::Builder::new()
            .name("mikktspace".into())
            .stack_size(stack)
            .spawn_scoped(s, || mikk::compact(mesh, engine))
        {
            Ok(h) => h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)),
            // No thread to be had: try on this one.
            Err(_) => mikk::compact(mesh, engine),
        }
    })
}
