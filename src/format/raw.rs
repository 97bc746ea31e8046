//! A triangle mesh as a file stores it, before any welding: what a baker's HIGH needs, and what
//! the OBJ and PLY readers hand over before a [`Scene`] is built from them.
//!
//! Each attribute keeps its own index stream (an OBJ face corner names `v`, `vt` and `vn`
//! separately), so a 20M-triangle sculpt is held as the file holds it, with no per-corner hash
//! maps. Positions are in the mesh's world space: glTF node transforms are applied here (OBJ and
//! PLY have none), normals through the normal matrix. UVs are in glTF's convention (v down).

use crate::error::Result;
use crate::scene::nodes::instances;
use crate::scene::{to_triangle_list, PrimRef, ReadOptions, Scene};
use glam::{Mat3, Vec3};
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
pub fn read_raw(path: &Path, opts: &ReadOptions) -> Result<RawMesh> {
    let scene = Scene::read(path, opts)?;
    from_scene(&scene)
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
        let mesh_json = &scene.json["meshes"][inst.mesh];
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
            if !(4..=6).contains(&pj.get("mode").and_then(|m| m.as_u64()).unwrap_or(4))
                || pj.pointer("/attributes/POSITION").is_none()
            {
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
