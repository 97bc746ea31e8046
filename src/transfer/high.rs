//! HIGH for `bake --from`: every triangle a mesh file shows, in world space, before any welding.
//!
//! Each attribute keeps its own index stream (an OBJ face corner names `v`, `vt` and `vn`
//! separately), so a 20M-triangle sculpt is held with no per-corner hash maps and, from OBJ and
//! PLY, in the arrays their parsers filled. Positions are in world space (glTF node transforms are
//! applied here; OBJ and PLY have none), normals unit and through the normal matrix, UVs in glTF's
//! convention (v down).

use crate::error::Result;
use crate::format::mesh::{check_finite, check_finite_uv, runs, v_down, StoredMesh, MISSING};
use crate::scene::nodes::instances;
use crate::scene::normals::unit_or_up_all;
use crate::scene::{to_triangle_list, PrimRef, ReadOptions, Scene};
use glam::Vec3;
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

/// A mesh as HIGH holds it (see the module): world space, unit normals, v down.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct HighMesh {
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

/// The triangle range of part `k` of `parts`, in a mesh of `triangles` triangles.
pub fn part_range(parts: &[Part], k: usize, triangles: usize) -> std::ops::Range<usize> {
    let end = parts.get(k + 1).map_or(triangles, |p| p.start as usize);
    parts[k].start as usize..end
}

/// Reads any mesh file bumpbake reads as a [`HighMesh`]: every triangle primitive the scene shows,
/// in world space, one part per node (named after the node, else its mesh).
///
/// OBJ and PLY take a fast path: the parsed arrays become the mesh as they are, with no Scene,
/// no welding and no per-corner copies; of `opts`, OBJ uses only the progress reporter.
pub fn read_high(path: &Path, opts: &ReadOptions) -> Result<HighMesh> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    match ext.as_str() {
        "obj" => from_obj(path, crate::format::obj::parse::parse_file(path, &opts.progress)?),
        "ply" => from_ply(path, crate::format::ply::read_file(path)?),
        _ => from_scene(&crate::format::read(path, opts)?),
    }
}

/// An OBJ file's arrays as a mesh: parts at `o`/`g` and at `usemtl` changes.
pub fn from_obj(path: &Path, mut d: StoredMesh) -> Result<HighMesh> {
    // The PLY parser checks its positions as it reads them; the OBJ parser leaves it to the glue,
    // which names the object on the Scene path.
    check_finite(path, &d.positions)?;
    crate::format::obj::normals_from_groups(&mut d);
    from_stored(path, d, "unnamed_object")
}

/// A PLY mesh as one part named after the file.
pub fn from_ply(path: &Path, p: StoredMesh) -> Result<HighMesh> {
    from_stored(path, p, &crate::format::ply::mesh_name(path))
}

/// A stored mesh's arrays taken over: UVs turned v down, normals made unit (zero ones point up,
/// as for every OBJ and PLY read). A kind of index some corners lack (a `vt` here and there) is
/// dropped whole; values one per position get `triangles` as their index stream.
fn from_stored(path: &Path, m: StoredMesh, first_name: &str) -> Result<HighMesh> {
    // Whole triangles per item: a flattened parallel iterator costs more than the test itself.
    let indices = |own: Vec<[u32; 3]>, values: usize, triangles: &[[u32; 3]]| {
        if values == 0 {
            None
        } else if own.is_empty() {
            Some(triangles.to_vec())
        } else {
            (!crate::scan::any(&own, |c| c.contains(&MISSING))).then_some(own)
        }
    };
    let normal_triangles = indices(m.normal_triangles, m.normals.len(), &m.triangles);
    let uv_triangles = indices(m.uv_triangles, m.uvs.len(), &m.triangles);
    let parts = runs(&m.statements, m.triangles.len(), first_name, |name| Some(name.to_string()))
        .into_iter()
        .map(|r| Part { name: r.name, material: r.material, start: r.tris.start as u32 })
        .collect();
    let mut out = HighMesh { positions: m.positions, triangles: m.triangles, parts, ..Default::default() };
    if let Some(t) = normal_triangles {
        out.normals = m.normals;
        out.normals.par_chunks_mut(64 * 1024).for_each(unit_or_up_all);
        out.normal_triangles = t;
    }
    if let Some(t) = uv_triangles {
        out.uvs = m.uvs;
        v_down(&mut out.uvs);
        check_finite_uv(path, &out.uvs)?;
        out.uv_triangles = t;
    }
    Ok(out)
}

/// A scene's shown triangle primitives as one [`HighMesh`] in world space.
pub fn from_scene(scene: &Scene) -> Result<HighMesh> {
    let mut out = HighMesh::default();
    let meshes = scene.json.get("meshes").and_then(|m| m.as_array()).map_or(0, |m| m.len());
    let mut with_normals = true;
    for inst in instances(scene) {
        if inst.mesh >= meshes {
            continue;
        }
        let Some(mesh_json) = scene.array("meshes").get(inst.mesh) else { continue };
        let name = inst
            .node
            .and_then(|n| scene.node_name(n))
            .or_else(|| scene.mesh_name(inst.mesh))
            .map_or_else(|| format!("mesh {}", inst.mesh), str::to_string);
        let place = inst.placement();
        let prims = mesh_json.get("primitives").and_then(|p| p.as_array()).map_or(0, |p| p.len());
        for k in 0..prims {
            let r = PrimRef { mesh: inst.mesh, primitive: k };
            if !crate::scene::view::is_surface(scene, r) {
                continue;
            }
            let p = to_triangle_list(scene.primitive(r)?);
            let base = out.positions.len() as u32;
            let material = scene.material_index(r).map(|m| m.to_string());
            out.parts.push(Part { name: name.clone(), material, start: out.triangles.len() as u32 });
            out.positions.extend(p.positions().into_iter().map(|q| place.point(Vec3::from(q)).to_array()));
            match p.attr("NORMAL") {
                Some(n) if with_normals => out.normals.extend(
                    n.to_f32::<3>().into_iter().map(|v| place.normal(Vec3::from(v)).normalize_or_zero().to_array()),
                ),
                _ => with_normals = false,
            }
            for t in p.indices.chunks_exact(3) {
                out.triangles.push(place.triangle([base + t[0], base + t[1], base + t[2]]));
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
