//! Which primitives of a scene get tangents, and putting them there.
//!
//! Like gltfpack's `needsTangents`, the material decides: a triangle primitive gets frames when a
//! material it can show (its own, or one a `KHR_materials_variants` mapping switches to) has a
//! normal texture, a clearcoat normal texture or anisotropy, from the UVs that texture reads,
//! transformed as `KHR_texture_transform` says (the one rule, [`PrimView::tangent_uvs`]).
//! Everything else is skipped with a reason the report names.

use super::{with_frames, FrameStats, Options};
use crate::error::{Result, Setting, Words};
use crate::scene::view::{views, PrimView};
use crate::scene::{Geometry, PrimRef, Primitive, Scene};
use rayon::prelude::*;

#[derive(Debug, Clone, Copy, Default)]
pub struct ApplyOptions {
    /// Give every triangle primitive with UVs tangents, whatever its material.
    pub all: bool,
    /// Replace valid existing tangents too.
    pub overwrite: bool,
    pub frames: Options,
}

/// What tangent generation did to one primitive, and why.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PrimTangents {
    pub mesh: usize,
    pub primitive: usize,
    /// `generated`, `kept` (valid tangents already there) or `skipped`.
    pub action: &'static str,
    /// Why it was skipped, kept or regenerated.
    pub reason: Option<String>,
    pub uv_set: Option<u32>,
    /// What needs the tangents: `normal texture reads TEXCOORD_0`, `KHR_materials_anisotropy of
    /// variant material 2 needs tangents from TEXCOORD_0`...
    pub needed_by: Option<String>,
    pub stats: Option<FrameStats>,
}

/// Why a primitive gets no tangents, or `Ok` when it gets them (from [`PrimView::tangent_uvs`]).
/// With `all`, a primitive nothing needs tangents for gets them from set 0.
pub fn needs_tangents(view: &PrimView, all: bool) -> std::result::Result<(), String> {
    if !view.mode.has_triangles() {
        return Err(format!("not triangles (mode {})", view.mode));
    }
    if !view.has_position {
        // glTF lets a primitive leave POSITION out (clients skip drawing it); there is no surface.
        return Err("no POSITION (nothing to draw)".into());
    }
    match &view.tangent_need {
        Some(_) => {}
        None if all => {}
        None if view.material.is_none() => return Err("no material".into()),
        None => return Err("material has no normal texture".into()),
    }
    let uvs = view.tangent_uvs();
    if !view.has(&uvs.attribute()) {
        let what = view.tangent_need.as_ref().map(|n| n.describe()).unwrap_or_else(|| {
            Words::from(format!("TEXCOORD_{} ", uvs.set)).name(Setting::All).text(" reads").to_string()
        });
        return Err(format!("no UVs (the {what}, which the primitive does not have)"));
    }
    Ok(())
}

/// Gives every primitive that needs them MikkTSpace tangents; returns a report per primitive.
pub fn apply(scene: &mut Scene, opts: &ApplyOptions) -> Result<Vec<PrimTangents>> {
    let mut reports = Vec::new();
    let mut work: Vec<(PrimRef, Geometry)> = Vec::new();
    let mats = scene.materials().clone();
    for view in views(scene, &mats) {
        let r = view.at;
        let report = |action, reason: Option<String>, with_uvs: bool| PrimTangents {
            mesh: r.mesh,
            primitive: r.primitive,
            action,
            reason,
            uv_set: with_uvs.then(|| view.tangent_uvs().set),
            needed_by: view.tangent_need.as_ref().filter(|_| with_uvs).map(|n| n.describe()),
            stats: None,
        };
        match needs_tangents(&view, opts.all) {
            Err(why) => reports.push(report("skipped", Some(why), false)),
            Ok(()) => {
                let g = view.read(scene)?;
                if g.primitive.indices.is_empty() {
                    // Nothing to make frames for; rewriting it would only write empty accessors.
                    reports.push(report("skipped", Some("no triangles (too few indices)".into()), false));
                    continue;
                }
                let repaired = g.normal_repair.describe();
                let why = match g.primitive.attr("TANGENT") {
                    // Frames follow the normals: repaired normals need new tangents.
                    Some(_) if repaired.is_some() => Some("existing tangents replaced (the normals changed)".into()),
                    Some(t) if !opts.overwrite => match invalid_tangents(t) {
                        0 => {
                            let kept = Words::from("valid tangents already present (").name(Setting::Overwrite);
                            let kept = kept.text(" replaces them)");
                            reports.push(report("kept", Some(kept.to_string()), true));
                            continue;
                        }
                        n => Some(format!("replaced {n} invalid existing tangents (NaN, non-unit, zero or w not +-1)")),
                    },
                    Some(_) => {
                        Some(Words::from("existing tangents replaced (").name(Setting::Overwrite).text(")").to_string())
                    }
                    None => None,
                };
                let conflicts = view.tangent_need.iter().flat_map(|n| n.conflicts.iter().cloned());
                let why = repaired.into_iter().chain(why).chain(conflicts).collect::<Vec<_>>();
                reports.push(report("generated", (!why.is_empty()).then(|| why.join("; ")), true));
                work.push((r, g));
            }
        }
    }
    // The decoded copies are all that is needed now: free the bytes they came from.
    let refs: Vec<PrimRef> = work.iter().map(|w| w.0).collect();
    scene.release_primitives(&refs);
    let done: Vec<(Primitive, FrameStats)> = work.into_par_iter().map(|(_, g)| with_frames(g, &opts.frames)).collect();
    for (r, (p, stats)) in refs.iter().zip(done) {
        scene.put_primitive(*r, p);
        if let Some(rep) = reports.iter_mut().find(|x| x.mesh == r.mesh && x.primitive == r.primitive) {
            rep.stats = Some(stats);
        }
    }
    Ok(reports)
}

/// How many elements of a TANGENT stream break the glTF rules. Quantized tangents
/// (KHR_mesh_quantization: normalized BYTE or SHORT) are valid when they are unit to within what
/// their step explains.
pub fn invalid_tangents(t: &crate::scene::Stream) -> usize {
    use crate::scene::accessor::{BYTE, FLOAT, SHORT};
    let f = &t.format;
    let quantized = f.normalized && matches!(f.component_type, BYTE | SHORT);
    if f.ty != "VEC4" || !(f.component_type == FLOAT || quantized) {
        return t.len().max(1);
    }
    let tolerance = (super::fallback::UNIT_TOLERANCE * 5.0).max(3f32.sqrt() / 2.0 * t.step());
    t.to_f32::<4>()
        .iter()
        .filter(|v| {
            let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            !(len.is_finite() && (len - 1.0).abs() <= tolerance && (v[3] == 1.0 || v[3] == -1.0))
        })
        .count()
}
