//! What the OBJ and PLY readers share: the mesh as either file stores it ([`StoredMesh`]: values
//! in the file's own conventions, UVs v up, each attribute with its own index stream or, as PLY
//! stores them, one value per position), the numbers of their text (`text_number.rs`, the
//! common plain decimal in one vector: `decimal16.rs`) and the
//! corners made a glTF primitive (`to_gltf.rs`). The Scene builders (`obj/`, `ply/scene.rs`) and
//! HIGH's reader (`transfer/high.rs`) take a `StoredMesh` from there, and turn v down through
//! [`v_down`], the one flip.

#[cfg(target_arch = "x86_64")]
pub(super) mod decimal16;
pub(super) mod text_number;
pub(super) mod to_gltf;

use crate::error::{Error, Result};
use rayon::prelude::*;
use std::path::Path;

/// The index of a corner that names no `vt` (or no `vn`).
pub const MISSING: u32 = u32::MAX;

#[derive(Debug, Clone, PartialEq)]
pub enum Statement {
    /// `o` or `g` with its name (the rest of the line; `unnamed_object` when empty).
    Name(String),
    /// `usemtl` with its material name.
    Material(String),
    /// `s` with its smoothing group: 0 for `off` (each face flat).
    Smooth(u64),
}

/// A mesh as stored, triangulated (polygons fanned from their first corner).
#[derive(Debug, Default, Clone, PartialEq)]
pub struct StoredMesh {
    pub positions: Vec<[f32; 3]>,
    /// As stored: not necessarily unit.
    pub normals: Vec<[f32; 3]>,
    /// As stored: v up.
    pub uvs: Vec<[f32; 2]>,
    /// Per triangle, three indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle, indices into `uvs` ([`MISSING`] for a corner without one). Empty when the
    /// UVs are one per position (PLY) or absent: an OBJ whose faces name no `vt` keeps no `uvs`.
    pub uv_triangles: Vec<[u32; 3]>,
    /// Per triangle, indices into `normals`, as `uv_triangles`.
    pub normal_triangles: Vec<[u32; 3]>,
    /// `o`/`g`/`usemtl` in file order, each with the number of triangles before it (OBJ only).
    pub statements: Vec<(u32, Statement)>,
    /// `mtllib` file names in file order (OBJ only).
    pub mtllibs: Vec<String>,
}

/// A run of triangles with one name and one material.
pub struct Run<M> {
    pub name: String,
    pub material: Option<M>,
    pub tris: std::ops::Range<usize>,
}

/// The runs of `triangles` triangles that `statements` cut, as tobj split an OBJ into models: at
/// every `o`/`g`, and at a `usemtl` whose material (as `material` resolves its name) differs from
/// the run's; runs without triangles are dropped. The first run is called `first_name`.
pub fn runs<M: Clone + PartialEq>(
    statements: &[(u32, Statement)],
    triangles: usize,
    first_name: &str,
    material: impl Fn(&str) -> Option<M>,
) -> Vec<Run<M>> {
    fn close<M: Clone>(name: &str, material: &Option<M>, tris: std::ops::Range<usize>, out: &mut Vec<Run<M>>) {
        if !tris.is_empty() {
            out.push(Run { name: name.to_string(), material: material.clone(), tris });
        }
    }
    let (mut out, mut name, mut current, mut start) = (Vec::new(), first_name.to_string(), None, 0);
    for (at, s) in statements {
        let at = *at as usize;
        match s {
            Statement::Name(n) => {
                close(&name, &current, start..at, &mut out);
                start = at;
                name = n.clone();
            }
            Statement::Material(m) => {
                let m = material(m);
                if m != current {
                    close(&name, &current, start..at, &mut out);
                    start = at;
                    current = m;
                }
            }
            Statement::Smooth(_) => {}
        }
    }
    close(&name, &current, start..triangles, &mut out);
    out
}

/// UVs from v up (OBJ, PLY) to glTF's v down, in place: the one place a reader flips them.
pub fn v_down(uvs: &mut [[f32; 2]]) {
    uvs.par_iter_mut().for_each(|uv| uv[1] = 1.0 - uv[1]);
}

/// The first vertex with a coordinate that is not finite, as an error naming `path` (every
/// reader's words for it); on every core.
pub fn check_finite(path: &Path, p: &[[f32; 3]]) -> Result<()> {
    match crate::scan::first(p, |q| !q.iter().all(|c| c.is_finite())) {
        Some(i) => Err(Error::input(path, format!("vertex {} has a non-finite coordinate", i + 1))),
        None => Ok(()),
    }
}

/// [`check_finite`] for texture coordinates.
pub fn check_finite_uv(path: &Path, uv: &[[f32; 2]]) -> Result<()> {
    match crate::scan::first(uv, |q| !q.iter().all(|c| c.is_finite())) {
        Some(i) => Err(Error::input(path, format!("texture coordinate {} is not finite", i + 1))),
        None => Ok(()),
    }
}
