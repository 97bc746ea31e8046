//! LOW and HIGH as the baker sees them: flat arrays in a local frame centred on LOW.
//!
//! Positions are moved into the local frame in f64 before they become f32, so a model far from
//! the origin keeps the precision it has near it. Meshes are taken in their own (mesh-local)
//! coordinates: node transforms are not applied, the frames bumpbake writes are mesh-local too.

use crate::error::{Error, Result};
use crate::format::raw::{read_raw, RawMesh};
use crate::scene::{smooth_vertex_normals, PrimRef, Primitive, ReadOptions, Scene, Slot};
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

/// HIGH, held once: positions in the local frame, indexed triangles, unit normals. About 40
/// bytes a triangle for a closed mesh whose normals follow its positions.
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
    /// normals where it has none. Its arrays are taken over, not copied, when HIGH is empty.
    pub fn append(&mut self, raw: RawMesh, origin: DVec3) {
        let RawMesh { mut positions, mut normals, triangles, normal_triangles, .. } = raw;
        let shared = normals.is_empty() || normal_triangles == triangles;
        if normals.is_empty() {
            normals = smooth_vertex_normals(&positions, &triangles);
        }
        positions.iter_mut().for_each(|p| *p = local(*p, origin).to_array());
        let (base_p, base_n) = (self.positions.len() as u32, self.normals.len() as u32);
        if shared && self.normal_triangles.is_none() && base_p == base_n {
            if self.triangles.is_empty() {
                self.triangles = triangles;
            } else {
                self.triangles.extend(triangles.iter().map(|t| t.map(|i| i + base_p)));
            }
        } else {
            let nt = self.normal_triangles.get_or_insert_with(|| self.triangles.clone());
            let own = if shared { &triangles } else { &normal_triangles };
            nt.extend(own.iter().map(|t| t.map(|i| i + base_n)));
            self.triangles.extend(triangles.iter().map(|t| t.map(|i| i + base_p)));
        }
        if self.positions.is_empty() {
            self.positions = positions;
            self.normals = normals;
        } else {
            self.positions.extend(positions);
            self.normals.extend(normals);
        }
    }
}

pub(crate) fn local(p: [f32; 3], o: DVec3) -> Vec3A {
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
        out.uvs.extend(uvs.into_iter().map(|[u, v]| if scene.uv_v_up { [u, 1.0 - v] } else { [u, v] }));
        out.triangles.extend(p.indices.chunks_exact(3).map(|t| [base + t[0], base + t[1], base + t[2]]));
    }
    Ok(out)
}

/// Every triangle the file at `path` shows, appended to `into`; returns how many.
fn read_triangles(path: &Path, read: &ReadOptions, origin: DVec3, into: &mut High) -> Result<usize> {
    let raw = read_raw(path, read)?;
    let n = raw.triangles.len();
    into.append(raw, origin);
    Ok(n)
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
    if h.triangles.len() != low.triangles.len() {
        return Err(Error::input(
            path,
            format!(
                "the cage has {} triangles, LOW has {}; a cage must be LOW with its vertices moved (same triangles, same order)",
                h.triangles.len(),
                low.triangles.len()
            ),
        ));
    }
    Ok(h.triangles.iter().map(|t| t.map(|i| Vec3A::from(h.positions[i as usize]))).collect())
}
