//! A stored mesh's corners as glTF: the primitive the OBJ and PLY scene builders both make
//! (checked, normals made or made unit, welded, UVs turned v down), and the scene around it.

use super::v_down;
use crate::error::{Error, Result};
use crate::scene::normals::{flat_normals, smooth_normals, unit_or_up};
use crate::scene::weld::weld;
use crate::scene::{set_key, NormalMode, Primitive, ReadOptions, Scene, SourceFormat, Stream};
use serde_json::{json, Value};
use std::path::Path;

/// A scene with no meshes yet, read from the OBJ or PLY file at `path`.
pub(in crate::format) fn empty_scene(
    path: &Path,
    opts: &ReadOptions,
    format: SourceFormat,
    deps: Vec<std::path::PathBuf>,
) -> Scene {
    Scene {
        json: json!({ "asset": { "version": "2.0", "generator": concat!("bumpbake ", env!("CARGO_PKG_VERSION")) } }),
        buffers: Vec::new(),
        source: path.to_path_buf(),
        base_dir: path.parent().map(|p| p.to_path_buf()).unwrap_or_default(),
        allow_outside: opts.allow_outside,
        source_format: format,
        notes: Vec::new(),
        deps,
        height_maps: Vec::new(),
        ledger: Default::default(),
        material_cache: Default::default(),
        absent_buffers: Default::default(),
        own_images: true,
        decoded_steps: Default::default(),
    }
}

pub(in crate::format) fn set_nodes(scene: &mut Scene, nodes: Vec<Value>) {
    let roots: Vec<usize> = (0..nodes.len()).collect();
    set_key(&mut scene.json, "nodes", Value::Array(nodes));
    set_key(&mut scene.json, "scenes", json!([{ "nodes": roots }]));
    set_key(&mut scene.json, "scene", json!(0));
}

/// One primitive's corners: flat values and, per attribute, an index per corner (an OBJ run
/// renumbered in first-use order as tobj numbered a model's; a PLY mesh as stored).
#[derive(Default)]
pub(in crate::format) struct Model {
    pub positions: Vec<f32>,
    pub indices: Vec<u32>,
    pub normals: Vec<f32>,
    pub normal_indices: Vec<u32>,
    pub texcoords: Vec<f32>,
    pub texcoord_indices: Vec<u32>,
}

/// The welded glTF primitive of `m`'s corners, UVs v down; normals from the file (made unit, a
/// zero one pointing up) or, when it has none, made as `normals` asks. `name` names the object in
/// messages.
pub(in crate::format) fn build_primitive(
    path: &Path,
    m: &Model,
    normals: NormalMode,
    notes: &mut Vec<String>,
    name: &str,
) -> Result<crate::scene::Primitive> {
    let np = m.positions.len() / 3;
    if let Some(i) = m.positions.iter().position(|x| !x.is_finite()) {
        return Err(Error::input(path, format!("object '{name}': vertex {} has a non-finite coordinate", i / 3 + 1)));
    }
    let corners = m.indices.len();
    let check = |idx: &[u32], n: usize, what: &str| -> Result<()> {
        match idx.iter().find(|&&i| i as usize >= n) {
            Some(bad) => Err(Error::input(
                path,
                format!("object '{name}': {what} index {} is out of range ({n} defined)", bad + 1),
            )),
            None => Ok(()),
        }
    };
    check(&m.indices, np, "vertex")?;
    let pos: Vec<[f32; 3]> = m
        .indices
        .iter()
        .map(|&i| {
            let i = i as usize * 3;
            [m.positions[i], m.positions[i + 1], m.positions[i + 2]]
        })
        .collect();
    let has_n = m.normal_indices.len() == corners && !m.normals.is_empty();
    let nrm: Vec<[f32; 3]> = if has_n {
        check(&m.normal_indices, m.normals.len() / 3, "normal")?;
        m.normal_indices
            .iter()
            .map(|&i| {
                let i = i as usize * 3;
                unit_or_up([m.normals[i], m.normals[i + 1], m.normals[i + 2]])
            })
            .collect()
    } else {
        let (n, fixed) = match normals {
            NormalMode::Smooth => smooth_normals(&m.positions, &m.indices),
            NormalMode::Flat => flat_normals(&pos),
        };
        if fixed > 0 {
            notes.push(format!(
                "object '{name}': {fixed} corners had no defined normal (degenerate faces); they point along +Z"
            ));
        }
        n
    };
    let mut attrs = vec![
        ("POSITION".to_string(), Stream::from_f32("VEC3", &pos)),
        ("NORMAL".to_string(), Stream::from_f32("VEC3", &nrm)),
    ];
    if m.texcoord_indices.len() == corners && !m.texcoords.is_empty() {
        check(&m.texcoord_indices, m.texcoords.len() / 2, "texture coordinate")?;
        let uv: Vec<[f32; 2]> = m
            .texcoord_indices
            .iter()
            .map(|&i| [m.texcoords[i as usize * 2], m.texcoords[i as usize * 2 + 1]])
            .collect();
        if uv.iter().flatten().any(|x| !x.is_finite()) {
            return Err(Error::input(path, format!("object '{name}': a texture coordinate is not finite")));
        }
        attrs.push(("TEXCOORD_0".to_string(), Stream::from_f32("VEC2", &uv)));
    }
    let mut prim = weld(attrs, vec![], 4);
    uvs_to_gltf(&mut prim);
    Ok(prim)
}

/// Every float TEXCOORD of `p` turned from v up (OBJ, PLY) to v down (glTF), per welded vertex:
/// after welding, so vertices merge on the values the file holds.
fn uvs_to_gltf(p: &mut Primitive) {
    for (name, s) in p.attributes.iter_mut() {
        if name.starts_with("TEXCOORD_") && s.format.component_type == crate::scene::accessor::FLOAT {
            let mut uv = s.to_f32::<2>();
            v_down(&mut uv);
            let template = s.template.take();
            *s = Stream::from_f32("VEC2", &uv);
            s.template = template;
        }
    }
}
