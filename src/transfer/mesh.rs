//! LOW and HIGH as the baker sees them: flat arrays in world space, moved into a local frame
//! centred on LOW.
//!
//! Every mesh is placed by its node's world transform (the whole parent chain; OBJ and PLY are at
//! identity). Positions are moved in f64 and into the local frame before they become f32, so a
//! model far from the origin keeps the precision it has near it. LOW's frames are the ones
//! written into OUT as a renderer places them: normals through the normal matrix, tangents
//! through the node's matrix (as three.js, Babylon.js and the glTF sample viewer do), each
//! normalised per vertex, and `w` negated on a mirroring node.

use super::high::{part_range, read_high, HighMesh};
use crate::error::{Error, Result, Setting, Words};
use crate::scene::nodes::{instances, Instance, Placement};
use crate::scene::to_triangle_list;
use crate::scene::{smooth_vertex_normals, PrimRef, PrimView, ReadOptions, Scene};
use glam::{DVec3, Mat4, Vec3, Vec3A};
use rayon::prelude::*;
use std::path::Path;

/// LOW after tangents: per-vertex streams of every baked primitive, appended.
#[derive(Debug, Default)]
pub struct Low {
    pub positions: Vec<Vec3A>,
    pub normals: Vec<Vec3A>,
    /// xyz and w, as a renderer places them in the world.
    pub tangents: Vec<[f32; 4]>,
    /// Texel coordinates before scaling: glTF UVs (v down).
    pub uvs: Vec<[f32; 2]>,
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle, its part (index into [`Placed`] names as [`low_parts`] lists them).
    pub tri_part: Vec<u32>,
    /// Per triangle corner, when a cage is given.
    pub cage: Option<Vec<[Vec3A; 3]>>,
    /// The local frame's origin in world coordinates.
    pub origin: DVec3,
    /// Diagonal of LOW's bounding box (all baked materials).
    pub diagonal: f64,
}

/// HIGH, held once: positions in the local frame, indexed triangles, unit normals (world
/// space). About 50 bytes a triangle for a closed mesh whose normals follow its positions.
#[derive(Debug, Default)]
pub struct High {
    pub positions: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
    pub normals: Vec<[f32; 3]>,
    /// Per triangle, indices into `normals`; `None` when those are `triangles` (one normal per
    /// position, as most files store them).
    pub normal_triangles: Option<Vec<[u32; 3]>>,
}

impl High {
    /// Appends a mesh as read, moving its positions into the frame centred on `origin`; smooth
    /// normals where it has none, per part (each part's primitive has its own vertices). Its
    /// arrays are taken over, not copied, when HIGH is empty.
    fn append(&mut self, raw: HighMesh, origin: DVec3) {
        let (mut normal_triangles, mut normals) = (raw.normal_triangles, raw.normals);
        let (mut positions, triangles) = (raw.positions, raw.triangles);
        // HighMesh normals are unit already; only a HIGH without any gets smooth ones, per part.
        if normals.is_empty() {
            normal_triangles = Vec::with_capacity(triangles.len());
            for k in 0..raw.parts.len().max(1) {
                let r =
                    if raw.parts.is_empty() { 0..triangles.len() } else { part_range(&raw.parts, k, triangles.len()) };
                let tris = &triangles[r];
                let Some(lo) = tris.iter().flatten().min().copied() else { continue };
                let hi = tris.iter().flatten().max().copied().unwrap_or(lo);
                let shifted: Vec<[u32; 3]> = tris.iter().map(|t| t.map(|i| i - lo)).collect();
                let b = normals.len() as u32;
                normals.extend(smooth_vertex_normals(&positions[lo as usize..=hi as usize], &shifted));
                normal_triangles.extend(shifted.iter().map(|t| t.map(|i| i + b)));
            }
        }
        let shared = crate::scan::same(&normal_triangles, &triangles);
        positions.par_iter_mut().for_each(|p| *p = local(dvec(*p), origin).to_array());
        let (base_p, base_n) = (self.positions.len() as u32, self.normals.len() as u32);
        if shared && self.normal_triangles.is_none() && base_p == base_n {
            drop(normal_triangles);
        } else {
            let nt = self.normal_triangles.get_or_insert_with(|| self.triangles.clone());
            nt.extend(normal_triangles.iter().map(|t| t.map(|i| i + base_n)));
        }
        if self.positions.is_empty() {
            self.triangles = triangles;
            self.positions = positions;
            self.normals = normals;
        } else {
            self.triangles.extend(triangles.iter().map(|t| t.map(|i| i + base_p)));
            self.positions.extend(positions);
            self.normals.extend(normals);
        }
    }
}

/// A named run of HIGH triangles, from one file.
#[derive(Debug, Clone, PartialEq)]
pub struct HighPart {
    pub name: String,
    pub file: usize,
    pub start: u32,
    pub end: u32,
}

/// A LOW primitive where the scene shows it.
#[derive(Debug, Clone)]
pub struct Placed {
    pub prim: PrimRef,
    /// How the node places it; `None` at identity (kept bit for bit).
    pub placement: Option<Placement>,
    /// The part: the node's name, else the mesh's.
    pub part: String,
}

fn local(p: DVec3, o: DVec3) -> Vec3A {
    let d = p - o;
    Vec3A::new(d.x as f32, d.y as f32, d.z as f32)
}

fn dvec(p: [f32; 3]) -> DVec3 {
    DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
}

fn node_name(scene: &Scene, n: usize) -> String {
    scene.node_name(n).map_or_else(|| format!("node {n}"), str::to_string)
}

fn mesh_name(scene: &Scene, m: usize) -> String {
    scene.mesh_name(m).map_or_else(|| format!("mesh {m}"), str::to_string)
}

/// Where the primitives `prims` are shown. A mesh shown by two nodes has one UV layout in two
/// places and cannot be baked twice into one map: it is refused unless `node` names one of them.
pub fn place(scene: &Scene, prims: &[PrimRef], node: Option<&str>) -> Result<Vec<Placed>> {
    let all = instances(scene);
    if let Some(want) = node {
        let names: Vec<String> = all.iter().filter_map(|i| i.node).map(|n| node_name(scene, n)).collect();
        if !names.iter().any(|n| n == want) {
            let have = if names.is_empty() { "none".to_string() } else { names.join(", ") };
            let msg = format!(": no node of that name shows a mesh (nodes: {have})");
            return Err(scene.err(Words::new().given(Setting::Node, want).text(msg)));
        }
    }
    let mut out = Vec::new();
    for &r in prims {
        let shown: Vec<&Instance> = all.iter().filter(|i| i.mesh == r.mesh).collect();
        let inst = match shown.as_slice() {
            [] => None,
            [one] => Some(**one),
            many => {
                let names: Vec<String> =
                    many.iter().map(|i| i.node.map_or("(root)".into(), |n| node_name(scene, n))).collect();
                match node.and_then(|w| many.iter().find(|i| i.node.is_some_and(|n| node_name(scene, n) == w))) {
                    Some(i) => Some(**i),
                    None => {
                        let msg = format!(
                            "LOW mesh '{}' is shown by nodes '{}' (one UV layout in {} places, one map); bake one of them with ",
                            mesh_name(scene, r.mesh),
                            names.join("' and '"),
                            names.len(),
                        );
                        return Err(scene.err(Words::from(msg).given(Setting::Node, &names[0])));
                    }
                }
            }
        };
        let part = inst.and_then(|i| i.node).and_then(|n| scene.node_name(n));
        out.push(Placed {
            prim: r,
            placement: inst.filter(|i| i.world != Mat4::IDENTITY).map(|i| i.placement()),
            part: part.map_or_else(|| mesh_name(scene, r.mesh), str::to_string),
        });
    }
    Ok(out)
}

/// LOW's part names, in order of first appearance in `placed`, and each primitive's part.
pub fn low_parts(placed: &[Placed]) -> (Vec<String>, Vec<u32>) {
    let mut names: Vec<String> = Vec::new();
    let idx = placed
        .iter()
        .map(|p| match names.iter().position(|n| *n == p.part) {
            Some(i) => i as u32,
            None => {
                names.push(p.part.clone());
                names.len() as u32 - 1
            }
        })
        .collect();
    (names, idx)
}

fn world_positions(scene: &Scene, p: &Placed) -> Result<Vec<DVec3>> {
    let pos = scene.primitive(p.prim)?.positions();
    Ok(match &p.placement {
        None => pos.into_iter().map(dvec).collect(),
        Some(place) => pos.into_iter().map(|q| place.point_f64(dvec(q))).collect(),
    })
}

/// The local frame of LOW's primitives `placed`: the centre and diagonal of their world bounds.
pub fn frame(scene: &Scene, placed: &[Placed]) -> Result<(DVec3, f64)> {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for p in placed {
        for q in world_positions(scene, p)? {
            lo = lo.min(q);
            hi = hi.max(q);
        }
    }
    Ok(((lo + hi) * 0.5, (hi - lo).length()))
}

/// Gathers LOW's primitives `placed` (which now carry tangents); `part[k]` is the part of
/// `placed[k]`.
pub fn low(scene: &Scene, placed: &[Placed], part: &[u32], origin: DVec3, diagonal: f64) -> Result<Low> {
    let mut out = Low { origin, diagonal, ..Default::default() };
    let mats = scene.materials();
    if placed.is_empty() {
        return Err(scene.err("no triangle primitive to bake onto (the material has no mesh)"));
    }
    for (pl, &part) in placed.iter().zip(part) {
        let r = pl.prim;
        // The map is laid out in the UVs the renderer samples the normal texture with, the ones
        // the tangents follow (the view's one rule).
        let view = PrimView::new(scene, mats, r);
        let uv_set = view.tangent_uvs();
        let g = view.read(scene)?;
        let p = &g.primitive;
        let where_ = format!("mesh {} primitive {}", r.mesh, r.primitive);
        for need in [&uv_set.attribute(), "POSITION", "NORMAL", "TANGENT"] {
            if p.attr(need).is_none() {
                let msg = format!(
                    "{where_} has no {need}; baking from HIGH needs LOW's UV layout (give LOW UVs, or choose another material with "
                );
                return Err(scene.err(Words::from(msg).name(Setting::Material).text(")")));
            }
        }
        let base = out.positions.len() as u32;
        out.positions.extend(world_positions(scene, pl)?.into_iter().map(|q| local(q, origin)));
        let normals = g.normals().unwrap_or_default();
        let tangents: Vec<[f32; 4]> = g.tangents().unwrap_or_default();
        match &pl.placement {
            None => {
                out.normals.extend(normals.iter().map(|&n| Vec3A::from(n)));
                out.tangents.extend(tangents);
            }
            Some(place) => {
                out.normals
                    .extend(normals.iter().map(|&n| Vec3A::from(place.normal(Vec3::from(n))).normalize_or_zero()));
                out.tangents.extend(tangents.into_iter().map(|t| {
                    let (v, w) = place.tangent(t);
                    let v = v.normalize_or_zero();
                    [v.x, v.y, v.z, w]
                }));
            }
        }
        out.uvs.extend(g.uvs(uv_set).unwrap_or_default().iter());
        out.triangles.extend(p.indices.chunks_exact(3).map(|t| [base + t[0], base + t[1], base + t[2]]));
        out.tri_part.resize(out.triangles.len(), part);
    }
    Ok(out)
}

/// Reads every HIGH file in world space (the meshes `given` stand for the first files);
/// returns the triangles, each file's triangle count and the named parts (consecutive runs with
/// one name).
pub fn high(
    paths: &[std::path::PathBuf],
    read: &ReadOptions,
    origin: DVec3,
    given: Vec<HighMesh>,
) -> Result<(High, Vec<usize>, Vec<HighPart>)> {
    let mut h = High::default();
    let mut counts = Vec::new();
    let mut parts: Vec<HighPart> = Vec::new();
    let mut given = given.into_iter();
    for (f, path) in paths.iter().enumerate() {
        let raw = match given.next() {
            Some(m) => m,
            None => read_high(path, read)?,
        };
        if raw.triangles.is_empty() {
            return Err(Error::input(path, "has no triangles to bake from (HIGH must be a triangle mesh)"));
        }
        let base_tri = h.triangles.len() as u32;
        for (k, p) in raw.parts.iter().enumerate() {
            let r = part_range(&raw.parts, k, raw.triangles.len());
            let (start, end) = (base_tri + r.start as u32, base_tri + r.end as u32);
            match parts.last_mut() {
                Some(last) if last.file == f && last.name == p.name && last.end == start => last.end = end,
                _ => parts.push(HighPart { name: p.name.clone(), file: f, start, end }),
            }
        }
        counts.push(raw.triangles.len());
        h.append(raw, origin);
    }
    Ok((h, counts, parts))
}

/// The cage: a mesh with LOW's topology, its corners matched to LOW's triangles in order. When
/// the cage file has LOW's primitives (LOW with its vertices moved), the primitives baked now are
/// taken from it; otherwise all of its triangles, in order.
pub fn cage(
    path: &Path,
    read: &ReadOptions,
    node: Option<&str>,
    placed: &[Placed],
    low: &Low,
) -> Result<Vec<[Vec3A; 3]>> {
    let scene = crate::format::read(path, read)?;
    let prims: Vec<PrimRef> =
        scene.primitives().into_iter().filter(|&r| crate::scene::view::is_surface(&scene, r)).collect();
    let same = placed.iter().all(|p| prims.contains(&p.prim));
    let chosen: Vec<PrimRef> = if same { placed.iter().map(|p| p.prim).collect() } else { prims };
    let mut corners = Vec::new();
    for pl in place(&scene, &chosen, node)? {
        let pos = world_positions(&scene, &pl)?;
        let p = to_triangle_list(scene.primitive(pl.prim)?);
        corners.extend(p.indices.chunks_exact(3).map(|t| [0, 1, 2].map(|k| local(pos[t[k] as usize], low.origin))));
    }
    if corners.len() != low.triangles.len() {
        return Err(Error::input(
            path,
            format!(
                "the cage has {} triangles, LOW has {}; a cage must be LOW with its vertices moved (same triangles, same order)",
                corners.len(),
                low.triangles.len()
            ),
        ));
    }
    Ok(corners)
}
