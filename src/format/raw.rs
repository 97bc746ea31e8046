//! A triangle mesh as a file stores it, before any welding: what a baker's HIGH needs, and what
//! the OBJ and PLY readers hand over before a [`Scene`] is built from them.
//!
//! Each attribute keeps its own index stream (an OBJ face corner names `v`, `vt` and `vn`
//! separately), so a 20M-triangle sculpt is held as the file holds it, with no per-corner hash
//! maps. Positions are in the mesh's world space: glTF node transforms are applied here (OBJ and
//! PLY have none), normals through the normal matrix. UVs are in glTF's convention (v down).

use super::check_finite;
use super::obj_parse::{ObjData, Statement, MISSING};
use super::ply::PlyMesh;
use crate::error::{Error, Result};
use crate::scene::nodes::instances;
use crate::scene::normals::unit_or_up;
use crate::scene::{to_triangle_list, PrimRef, ReadOptions, Scene};
use glam::{Mat3, Vec3};
use rayon::prelude::*;
use std::path::Path;

/// A run of triangles that belong to one named part (OBJ `o`/`g`, a glTF node, a PLY file).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Part {
    pub name: String,
    /// The material the run uses (OBJ `usemtl` name, glTF material index as text), if any.
    pub material: Option<String>,
    /// First triangle of the run; it ends where the next part starts.
    pub start: u32,
}

#[derive(Debug, Clone, PartialEq, Default)]
pub struct RawMesh {
    pub positions: Vec<[f32; 3]>,
    /// Unit normals, or empty when the file has none.
    pub normals: Vec<[f32; 3]>,
    /// glTF-oriented UVs (v down), or empty.
    pub uvs: Vec<[f32; 2]>,
    /// Per triangle, three indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle, three indices into `normals`; empty when there are no normals.
    pub normal_triangles: Vec<[u32; 3]>,
    /// Per triangle, three indices into `uvs`; empty when there are no UVs.
    pub uv_triangles: Vec<[u32; 3]>,
    /// Consecutive runs, in triangle order; the first starts at 0 (when there are triangles).
    pub parts: Vec<Part>,
}

impl RawMesh {
    /// The triangle range of part `k`.
    pub fn part_range(&self, k: usize) -> std::ops::Range<usize> {
        let end = self.parts.get(k + 1).map_or(self.triangles.len(), |p| p.start as usize);
        self.parts[k].start as usize..end
    }
}

/// Reads any mesh file bumpbake reads as a [`RawMesh`]: every triangle primitive the scene shows,
/// in world space, one part per node (named after the node, else its mesh).
///
/// OBJ and PLY take a fast path: the parsed arrays become the mesh as they are, with no Scene,
/// no welding and no per-corner copies; of `opts`, OBJ uses only the progress reporter.
pub fn read_raw(path: &Path, opts: &ReadOptions) -> Result<RawMesh> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    match ext.as_str() {
        "obj" => from_obj(path, super::obj_parse::parse_file(path, &opts.progress)?),
        "ply" => from_ply(path, super::ply::read_file(path)?),
        _ => from_scene(&Scene::read(path, opts)?),
    }
}

/// An OBJ file's arrays as a mesh: parts at `o`/`g` and at `usemtl` changes, UVs flipped to
/// glTF's convention once, normals made unit (zero ones point up, as for every OBJ read).
/// A kind of index some corners lack (a `vt` here and there) is dropped whole.
pub fn from_obj(path: &Path, d: ObjData) -> Result<RawMesh> {
    check_finite(path, &d.positions)?;
    // Whole triangles per item: a flattened parallel iterator costs more than the test itself.
    let complete = |t: &Vec<[u32; 3]>| !t.is_empty() && !t.par_iter().any(|c| c.contains(&MISSING));
    let (with_n, with_t) = (complete(&d.tri_n), complete(&d.tri_t));
    let mut parts = Vec::new();
    let mut cur = Part { name: "unnamed_object".into(), material: None, start: 0 };
    for (at, s) in d.statements {
        let next = match s {
            Statement::Name(n) => Part { name: n, material: cur.material.clone(), start: at },
            Statement::Material(m) if cur.material.as_deref() != Some(m.as_str()) => {
                Part { name: cur.name.clone(), material: Some(m), start: at }
            }
            Statement::Material(_) => continue,
        };
        if at > cur.start {
            parts.push(std::mem::replace(&mut cur, next));
        } else {
            cur = next;
        }
    }
    if (d.tri_v.len() as u32) > cur.start {
        parts.push(cur);
    }
    let mut out = RawMesh { positions: d.positions, triangles: d.tri_v, parts, ..Default::default() };
    if with_n {
        out.normals = d.normals;
        out.normals.par_iter_mut().for_each(|n| *n = unit_or_up(*n));
        out.normal_triangles = d.tri_n;
    }
    if with_t {
        out.uvs = flip_v(d.uvs);
        check_finite_uv(path, &out.uvs)?;
        out.uv_triangles = d.tri_t;
    }
    Ok(out)
}

/// A PLY mesh as one part named after the file.
pub fn from_ply(path: &Path, p: PlyMesh) -> Result<RawMesh> {
    let name = path.file_stem().map_or("mesh".into(), |s| s.to_string_lossy().into_owned());
    let parts = if p.triangles.is_empty() { Vec::new() } else { vec![Part { name, material: None, start: 0 }] };
    let mut out = RawMesh { positions: p.positions, parts, ..Default::default() };
    if !p.normals.is_empty() {
        out.normals = p.normals;
        out.normals.par_iter_mut().for_each(|n| *n = unit_or_up(*n));
        out.normal_triangles = p.triangles.clone();
    }
    if !p.uvs.is_empty() {
        out.uvs = flip_v(p.uvs);
        check_finite_uv(path, &out.uvs)?;
        out.uv_triangles = p.triangles.clone();
    }
    out.triangles = p.triangles;
    Ok(out)
}

fn flip_v(mut uvs: Vec<[f32; 2]>) -> Vec<[f32; 2]> {
    uvs.par_iter_mut().for_each(|uv| uv[1] = 1.0 - uv[1]);
    uvs
}

fn check_finite_uv(path: &Path, uv: &[[f32; 2]]) -> Result<()> {
    match uv.par_iter().position_first(|q| !q.iter().all(|c| c.is_finite())) {
        Some(i) => Err(Error::input(path, format!("texture coordinate {} is not finite", i + 1))),
        None => Ok(()),
    }
}

/// A scene's shown triangle primitives as one [`RawMesh`] in world space.
pub fn from_scene(scene: &Scene) -> Result<RawMesh> {
    let mut out = RawMesh::default();
    let meshes = scene.json.get("meshes").and_then(|m| m.as_array()).map_or(0, |m| m.len());
    let nodes = scene.json.get("nodes").and_then(|n| n.as_array());
    let mut with_normals = true;
    for inst in instances(scene) {
        if inst.mesh >= meshes {
            continue;
        }
        let Some(mesh_json) = scene.array("meshes").get(inst.mesh) else { continue };
        let name = inst
            .node
            .and_then(|n| nodes.and_then(|a| a.get(n)).and_then(|n| n.get("name")).and_then(|s| s.as_str()))
            .or_else(|| mesh_json.get("name").and_then(|s| s.as_str()))
            .map_or_else(|| format!("mesh {}", inst.mesh), str::to_string);
        let m3 = Mat3::from_mat4(inst.world);
        let normal_matrix = m3.inverse().transpose();
        let mirrored = inst.mirrored();
        let prims = mesh_json.get("primitives").and_then(|p| p.as_array()).map_or(0, |p| p.len());
        for k in 0..prims {
            let r = PrimRef { mesh: inst.mesh, primitive: k };
            let pj = scene.prim_json(r);
            if !crate::scene::Mode::of(pj).has_triangles() || pj.pointer("/attributes/POSITION").is_none() {
                continue;
            }
            let p = to_triangle_list(scene.primitive(r)?);
            let base = out.positions.len() as u32;
            let material = pj.get("material").and_then(|m| m.as_u64()).map(|m| m.to_string());
            out.parts.push(Part { name: name.clone(), material, start: out.triangles.len() as u32 });
            out.positions
                .extend(p.positions().into_iter().map(|q| inst.world.transform_point3(Vec3::from(q)).to_array()));
            match p.attr("NORMAL") {
                Some(n) if with_normals => out.normals.extend(
                    n.to_f32::<3>().into_iter().map(|v| (normal_matrix * Vec3::from(v)).normalize_or_zero().to_array()),
                ),
                _ => with_normals = false,
            }
            for t in p.indices.chunks_exact(3) {
                let t = [base + t[0], base + t[1], base + t[2]];
                // A mirroring transform turns counter-clockwise into clockwise; swapping two
                // corners keeps the face's front where its normals point.
                out.triangles.push(if mirrored { [t[0], t[2], t[1]] } else { t });
            }
        }
    }
    if with_normals {
        out.normal_triangles = out.triangles.clone();
    } else {
        out.normals.clear();
    }
    Ok(out)
}
