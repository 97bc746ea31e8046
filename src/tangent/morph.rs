//! Morph-target tangents. A target that moves a primitive's positions, normals or UVs turns its
//! surface frames too; glTF morphs TANGENT like any other attribute, by a per-vertex delta
//! (`VEC3`, `w` is not morphed). The delta is MikkTSpace on the fully morphed mesh (weight 1)
//! minus the base frame, corner by corner, as Blender's exporter writes with morph tangents on.
//! Renderers blend the deltas linearly with the weights, as they do positions and normals.
//!
//! The morphed mesh is the one the output file describes: base normals plus the target's NORMAL
//! delta (normalised, as a renderer does), or the base's flat normals where bumpbake made them
//! (the file then has no NORMAL delta either).

use super::{fallback, generate_with_stack, mikk, TriMesh};
use crate::scene::{Geometry, Primitive};
use glam::Vec3;

/// Whether `p`'s targets need TANGENT deltas: one moves what frames are made from (POSITION,
/// NORMAL, the UV set `uv_name`) or already carries TANGENT, which new base frames outdate.
pub(super) fn needed(p: &Primitive, uv_name: &str) -> bool {
    p.targets.iter().flatten().any(|(n, _)| matches!(n.as_str(), "POSITION" | "NORMAL" | "TANGENT") || n == uv_name)
}

/// Positions, UVs and normals of a morphed mesh, and its index list.
type Streams<'a> = (Vec<[f32; 3]>, Vec<[f32; 2]>, Vec<[f32; 3]>, &'a [u32]);

/// The base mesh as the frames saw it.
pub(super) struct Base<'a> {
    /// The frame of each corner (output `w` convention).
    pub tangent: &'a (dyn Fn(usize) -> [f32; 4] + Sync),
    /// Per vertex, or per corner when bumpbake made flat normals.
    pub normals: &'a [[f32; 3]],
    pub generated_normals: bool,
}

/// For each target, one TANGENT delta per corner of `p`: the morphed frame minus the base frame.
pub(super) fn deltas(g: &Geometry, base: &Base, engine: mikk::Engine) -> Vec<Vec<[f32; 3]>> {
    let p = &g.primitive;
    let uv_name = g.tangent_uvs.attribute();
    let corners = p.indices.len();
    let pos = p.positions();
    let corner_ids: Vec<u32> = if base.generated_normals { (0..corners as u32).collect() } else { Vec::new() };
    p.targets
        .iter()
        .map(|t| {
            let find = |name: &str| t.iter().find(|(k, _)| k == name).map(|(_, s)| s);
            let dp: Option<Vec<[f32; 3]>> = find("POSITION").map(|s| s.to_f32());
            let mpos: Vec<[f32; 3]> = match &dp {
                Some(d) => pos.iter().zip(d).map(|(a, b)| [a[0] + b[0], a[1] + b[1], a[2] + b[2]]).collect(),
                None => pos.clone(),
            };
            // Morphed, then through the texture's transform, as the base frames' UVs were.
            let muv = g.morphed_tangent_uvs(find(&uv_name));
            // Corner-wise where bumpbake made flat normals (as the base frames were), else by vertex.
            let (positions, uvs, normals, idx): Streams = if base.generated_normals {
                let cp = p.indices.iter().map(|&i| mpos[i as usize]).collect();
                let cu = p.indices.iter().map(|&i| muv[i as usize]).collect();
                (cp, cu, base.normals.to_vec(), &corner_ids)
            } else {
                let dn: Option<Vec<[f32; 3]>> = find("NORMAL").map(|s| s.to_f32());
                let normals = match &dn {
                    Some(d) => base
                        .normals
                        .iter()
                        .zip(d)
                        .map(|(a, b)| {
                            let m = Vec3::from(*a) + Vec3::from(*b);
                            m.try_normalize().unwrap_or(m).to_array()
                        })
                        .collect(),
                    None => base.normals.to_vec(),
                };
                (mpos, muv, normals, &p.indices)
            };
            let mesh = TriMesh { positions: &positions, normals: &normals, uvs: &uvs, indices: idx };
            let mut frames = generate_with_stack(&mesh, engine);
            super::to_gltf_w(&mut frames);
            fallback::repair(
                &mut frames,
                fallback::CornerNormals { normals: &normals, normal_of: idx, vertex: &p.indices },
            );
            (0..corners)
                .map(|c| {
                    let b = (base.tangent)(c);
                    let m = frames.get(c, idx[c]).unwrap_or(b);
                    [m[0] - b[0], m[1] - b[1], m[2] - b[2]]
                })
                .collect()
        })
        .collect()
}
