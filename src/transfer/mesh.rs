//! LOW and HIGH as the baker sees them: flat arrays in a local frame centred on LOW.
//!
//! Positions are moved into the local frame in f64 before they become f32, so a model far from
//! the origin keeps the precision it has near it. Meshes are taken in their own (mesh-local)
//! coordinates: node transforms are not applied, the frames bumpbake writes are mesh-local too.

use crate::error::{Error, Result};
use crate::scene::to_triangle_list;
use crate::scene::{smooth_normals, PrimRef, Primitive, ReadOptions, Scene, Slot};
use glam::{DVec3, Vec3A};
use std::path::Path;

/// LOW after tangents: per-vertex streams of every baked primitive, appended.
#[derive(Debug, Default)]
pub struct Low {
    pub positions: Vec<Vec3A>,
    pub normals: Vec<Vec3A>,
    /// xyz and w, as written into OUT.
    pub tangents: Vec<[f32; 4]>,
    /// Texel coordinates before scaling: glTF UVs (v down).
    pub uvs: Vec<[f32; 2]>,
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle corner, when a cage is given.
    pub cage: Option<Vec<[Vec3A; 3]>>,
    /// The local frame's origin in mesh coordinates.
    pub origin: DVec3,
    /// Diagonal of LOW's bounding box.
    pub diagonal: f64,
}

/// HIGH: triangles (corners in the local frame) and smooth per-vertex normals.
#[derive(Debug, Default)]
pub struct High {
    pub corners: Vec<[Vec3A; 3]>,
    pub normals: Vec<Vec3A>,
    pub normal_index: Vec<[u32; 3]>,
}

fn local(p: [f32; 3], o: DVec3) -> Vec3A {
    let d = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) - o;
    Vec3A::new(d.x as f32, d.y as f32, d.z as f32)
}

pub fn is_triangles(scene: &Scene, r: PrimRef) -> bool {
    let pj = scene.prim_json(r);
    (4..=6).contains(&pj.get("mode").and_then(|m| m.as_u64()).unwrap_or(4))
        && pj.pointer("/attributes/POSITION").is_some()
}

/// Gathers the primitives `prims` of LOW (which now carry tangents).
pub fn low(scene: &Scene, prims: &[PrimRef]) -> Result<Low> {
    let mut out = Low::default();
    let mut parts: Vec<(Primitive, u32)> = Vec::new();
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    let mats = scene.materials();
    for &r in prims {
        let set = mats.default_of(scene, r).and_then(|m| m.texture(Slot::Normal)).map_or(0, |t| t.tex_coord);
        let p = scene.primitive(r)?;
        let where_ = format!("mesh {} primitive {}", r.mesh, r.primitive);
        for need in [&format!("TEXCOORD_{set}"), "POSITION", "NORMAL", "TANGENT"] {
            if p.attr(need).is_none() {
                return Err(scene.err(format!(
                    "{where_} has no {need}; baking from HIGH needs LOW's UV layout (give LOW UVs, or choose another material with --material)"
                )));
            }
        }
        for q in p.positions() {
            let q = DVec3::new(q[0] as f64, q[1] as f64, q[2] as f64);
            lo = lo.min(q);
            hi = hi.max(q);
        }
        parts.push((p, set));
    }
    if parts.is_empty() {
        return Err(scene.err("no triangle primitive to bake onto (the material has no mesh)"));
    }
    out.origin = (lo + hi) * 0.5;
    out.diagonal = (hi - lo).length();
    for (p, set) in parts {
        let base = out.positions.len() as u32;
        out.positions.extend(p.positions().into_iter().map(|q| local(q, out.origin)));
        out.normals.extend(p.attr("NORMAL").map(|s| s.to_f32::<3>()).unwrap_or_default().into_iter().map(Vec3A::from));
        out.tangents.extend(p.attr("TANGENT").map(|s| s.to_f32::<4>()).unwrap_or_default());
        let uvs: Vec<[f32; 2]> = p.attr(&format!("TEXCOORD_{set}")).map(|s| s.to_f32()).unwrap_or_default();
        out.uvs.extend(uvs);
        out.triangles.extend(p.indices.chunks_exact(3).map(|t| [base + t[0], base + t[1], base + t[2]]));
    }
    Ok(out)
}

/// Every triangle primitive of the file at `path`, in document order, as per-corner positions
/// and per-vertex normals (smooth normals where the file has none).
fn read_triangles(path: &Path, read: &ReadOptions, origin: DVec3, into: &mut High) -> Result<usize> {
    let scene = Scene::read(path, read)?;
    let before = into.corners.len();
    for r in scene.primitives() {
        if !is_triangles(&scene, r) {
            continue;
        }
        let p = to_triangle_list(scene.primitive(r)?);
        let pos = p.positions();
        let base = into.normals.len() as u32;
        match p.attr("NORMAL") {
            Some(n) => {
                into.normals.extend(n.to_f32::<3>().into_iter().map(|v| Vec3A::from(v).normalize_or_zero()));
                into.normal_index.extend(p.indices.chunks_exact(3).map(|t| [base + t[0], base + t[1], base + t[2]]));
            }
            None => {
                let (n, _) = smooth_normals(pos.as_flattened(), &p.indices);
                into.normals.extend(n.into_iter().map(Vec3A::from));
                into.normal_index.extend(
                    (0..p.indices.len() as u32 / 3).map(|k| [base + 3 * k, base + 3 * k + 1, base + 3 * k + 2]),
                );
            }
        }
        into.corners.extend(p.indices.chunks_exact(3).map(|t| [0, 1, 2].map(|k| local(pos[t[k] as usize], origin))));
    }
    Ok(into.corners.len() - before)
}

/// Reads every HIGH file; returns the triangles and each file's triangle count.
pub fn high(paths: &[std::path::PathBuf], read: &ReadOptions, origin: DVec3) -> Result<(High, Vec<usize>)> {
    let mut h = High::default();
    let mut counts = Vec::new();
    for p in paths {
        let n = read_triangles(p, read, origin, &mut h)?;
        if n == 0 {
            return Err(Error::input(p, "has no triangles to bake from (HIGH must be a triangle mesh)"));
        }
        counts.push(n);
    }
    Ok((h, counts))
}

/// The cage: a mesh with LOW's topology, its corners matched to LOW's triangles in order.
pub fn cage(path: &Path, read: &ReadOptions, low: &Low) -> Result<Vec<[Vec3A; 3]>> {
    let mut h = High::default();
    read_triangles(path, read, low.origin, &mut h)?;
    if h.corners.len() != low.triangles.len() {
        return Err(Error::input(
            path,
            format!(
                "the cage has {} triangles, LOW has {}; a cage must be LOW with its vertices moved (same triangles, same order)",
                h.corners.len(),
                low.triangles.len()
            ),
        ));
    }
    Ok(h.corners)
}
