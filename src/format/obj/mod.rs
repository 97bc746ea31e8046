//! Reading Wavefront OBJ (+ MTL) into the glTF model: the geometry through the parallel parser
//! (`parse.rs`, `block.rs`, `piece.rs`, `fast.rs`, `continuation.rs`), the MTL libraries through `tobj` (`mtl.rs`).
//! Each run of one name and material becomes a primitive, its corners renumbered in first-use
//! order as tobj numbers a model's, so the welded output matches tobj's reading of the file.
//!
//! OBJ's UVs run v up; they are turned into glTF's v down on building (`format::build`), so no
//! stage after the reader knows the mesh came from an OBJ (MikkTSpace's sign flips with v, and
//! the glTF `w` rule, the reference sign negated, flips it back: the frames are the same).

mod block;
mod continuation;
mod fast;
mod mtl;
pub mod parse;
mod piece;
mod smoothing;

use super::mesh::to_gltf::{build_primitive, empty_scene, set_nodes, Model};
use super::mesh::{runs, StoredMesh, MISSING};
use crate::error::{Error, Result};
use crate::scene::{array_mut, set_key, NormalMode, PrimRef, ReadOptions, Scene, SourceFormat};
use mtl::{add_material, load_materials};
use serde_json::json;
pub use smoothing::normals_from_groups;
use std::path::Path;

/// Reads the OBJ file at `path`, streaming it through the parallel parser.
pub fn read_file(path: &Path, opts: &ReadOptions) -> Result<Scene> {
    let data = parse::parse_file(path, &opts.progress)?;
    build_scene(path, data, opts)
}

/// Reads OBJ bytes already in memory; `path` names them in messages and MTL names resolve
/// beside it.
pub fn read(path: &Path, bytes: &[u8], opts: &ReadOptions) -> Result<Scene> {
    let data = parse::parse_bytes(path, bytes, &opts.progress)?;
    build_scene(path, data, opts)
}

fn build_scene(path: &Path, mut data: StoredMesh, opts: &ReadOptions) -> Result<Scene> {
    // Flat normals are asked for everywhere; smooth ones within the file's smoothing groups.
    let directionless = match opts.obj_normals {
        NormalMode::Smooth => normals_from_groups(&mut data),
        NormalMode::Flat => 0,
    };
    let base_dir = path.parent().map(|p| p.to_path_buf()).unwrap_or_default();
    let (materials, material_ids, mtl_files) = load_materials(path, &base_dir, &data.mtllibs, opts)?;

    let mut scene = empty_scene(path, opts, SourceFormat::Obj, mtl_files);
    if directionless > 0 {
        scene.notes.push(format!(
            "{directionless} normals of the smoothing groups had no direction (only faces without area around them); they point along +Z"
        ));
    }
    for (i, m) in materials.iter().enumerate() {
        add_material(&mut scene, i, m)?;
    }

    let mut nodes = Vec::new();
    let mut remap = Remaps::new(&data);
    for run in runs(&data.statements, data.triangles.len(), "unnamed_object", |m| material_ids.get(m).copied()) {
        let name = &run.name;
        let meshes = scene.array("meshes");
        let mesh_idx = match meshes.last() {
            Some(last) if last.get("name") == Some(&json!(name)) => meshes.len() - 1,
            _ => {
                let meshes = array_mut(&mut scene.json, "meshes");
                meshes.push(json!({ "name": name, "primitives": [] }));
                nodes.push(json!({ "name": name, "mesh": meshes.len() - 1 }));
                meshes.len() - 1
            }
        };
        let model = remap.model(&data, run.tris.clone());
        let prim = build_primitive(path, &model, opts.obj_normals, &mut scene.notes, name)?;
        let mut pj = json!({ "attributes": {} });
        if let Some(m) = run.material.filter(|&m| m < materials.len()) {
            set_key(&mut pj, "material", json!(m));
        }
        let mesh = array_mut(&mut scene.json, "meshes").get_mut(mesh_idx);
        let prims = array_mut(mesh.ok_or_else(|| Error::input(path, "OBJ mesh vanished"))?, "primitives");
        prims.push(pj);
        let r = PrimRef { mesh: mesh_idx, primitive: prims.len() - 1 };
        scene.put_primitive(r, prim);
    }
    if nodes.is_empty() {
        return Err(Error::input(path, "OBJ has no faces"));
    }
    set_nodes(&mut scene, nodes);
    Ok(scene)
}

/// Global-to-local index maps, one per attribute, reset between runs by what they touched.
struct Remaps {
    maps: [Vec<u32>; 3],
    touched: Vec<(usize, u32)>,
}

impl Remaps {
    fn new(d: &StoredMesh) -> Remaps {
        let m = |n: usize| vec![MISSING; n];
        Remaps { maps: [m(d.positions.len()), m(d.uvs.len()), m(d.normals.len())], touched: Vec::new() }
    }

    /// The local index of global `g` of attribute `a`, and whether it is new.
    fn local(&mut self, a: usize, g: u32, next: usize) -> (u32, bool) {
        let slot = &mut self.maps[a][g as usize];
        if *slot == MISSING {
            *slot = next as u32;
            self.touched.push((a, g));
            (*slot, true)
        } else {
            (*slot, false)
        }
    }

    fn model(&mut self, d: &StoredMesh, tris: std::ops::Range<usize>) -> Model {
        let mut m = Model::default();
        for t in &d.triangles[tris.clone()] {
            for &g in t {
                let (l, new) = self.local(0, g, m.positions.len() / 3);
                if new {
                    m.positions.extend_from_slice(&d.positions[g as usize]);
                }
                m.indices.push(l);
            }
        }
        // A corner without `vt` (`vn`) in a run where others have one takes the previous
        // corner's (the first one's: the file's first), as tobj did.
        let attrs: [(&[[u32; 3]], usize); 2] = [(&d.uv_triangles, 1), (&d.normal_triangles, 2)];
        for (tri, a) in attrs {
            let Some(run) = tri.get(tris.clone()) else { continue };
            if run.iter().flatten().all(|&i| i == MISSING) {
                continue;
            }
            let mut prev = 0;
            for &g in run.iter().flatten() {
                let g = if g == MISSING { prev } else { g };
                prev = g;
                let (values, indices) = if a == 1 {
                    (&mut m.texcoords, &mut m.texcoord_indices)
                } else {
                    (&mut m.normals, &mut m.normal_indices)
                };
                let (l, new) = self.local(a, g, values.len() / (a + 1));
                if new {
                    if a == 1 {
                        values.extend_from_slice(&d.uvs[g as usize]);
                    } else {
                        values.extend_from_slice(&d.normals[g as usize]);
                    }
                }
                indices.push(l);
            }
        }
        for (a, g) in self.touched.drain(..) {
            self.maps[a][g as usize] = MISSING;
        }
        m
    }
}

#[cfg(test)]
#[path = "tests.rs"]
mod tests;
