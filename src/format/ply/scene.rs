//! A PLY mesh as a [`Scene`]: the PLY side of `format::read`, beside the reader.

use crate::error::{Error, Result};
use crate::format::mesh::to_gltf::{build_primitive, empty_scene, set_nodes, Model};
use crate::format::mesh::StoredMesh;
use crate::scene::{set_key, PrimRef, ReadOptions, Scene, SourceFormat};
use serde_json::json;
use std::path::Path;

/// A PLY mesh as a scene: one node and mesh named after the file, one primitive built exactly
/// as an OBJ face list with the same corners would be (values one per position, unrenumbered).
pub fn scene(path: &Path, ply: StoredMesh, opts: &ReadOptions) -> Result<Scene> {
    if ply.triangles.is_empty() {
        return Err(Error::input(path, "PLY has no faces (a point cloud cannot be used as a mesh)"));
    }
    let name = super::mesh_name(path);
    let indices: Vec<u32> = ply.triangles.into_flattened();
    let with = |present: bool| if present { indices.clone() } else { Vec::new() };
    let model = Model {
        normal_indices: with(!ply.normals.is_empty()),
        texcoord_indices: with(!ply.uvs.is_empty()),
        positions: ply.positions.into_flattened(),
        normals: ply.normals.into_flattened(),
        texcoords: ply.uvs.into_flattened(),
        indices,
    };
    let mut scene = empty_scene(path, opts, SourceFormat::Ply, Vec::new());
    let prim = build_primitive(path, &model, opts.obj_normals, &mut scene.notes, &name)?;
    set_key(&mut scene.json, "meshes", json!([{ "name": name, "primitives": [{ "attributes": {} }] }]));
    scene.put_primitive(PrimRef { mesh: 0, primitive: 0 }, prim);
    set_nodes(&mut scene, vec![json!({ "name": name, "mesh": 0 })]);
    Ok(scene)
}
