//! Which primitives of a scene get tangents, and putting them there.
//!
//! Like gltfpack's `needs_tangents`, the material decides: a triangle primitive whose material has
//! a `normalTexture` gets frames from the UV set that texture reads. Everything else is skipped
//! with a reason the report names.

use super::{primitive_with_stats, FrameStats, Options};
use crate::error::Result;
use crate::scene::{PrimRef, Primitive, Scene};
use rayon::prelude::*;

#[derive(Debug, Clone, Copy, Default)]
pub struct ApplyOptions {
    /// Give every triangle primitive with UVs tangents, whatever its material.
    pub all: bool,
    /// Replace valid existing tangents too.
    pub overwrite: bool,
    pub frames: Options,
}

/// What happened to one primitive.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PrimReport {
    pub mesh: usize,
    pub primitive: usize,
    /// `generated`, `kept` (valid tangents already there) or `skipped`.
    pub action: &'static str,
    /// Why it was skipped, kept or regenerated.
    pub reason: Option<String>,
    pub uv_set: Option<u32>,
    pub stats: Option<FrameStats>,
}

/// Why a primitive needs no tangents, or the UV set it needs them from.
pub fn needs_tangents(scene: &Scene, r: PrimRef, all: bool) -> std::result::Result<u32, String> {
    let pj = scene.prim_json(r);
    let mode = pj.get("mode").and_then(|m| m.as_u64()).unwrap_or(4);
    if !(4..=6).contains(&mode) {
        return Err(format!("not triangles (mode {mode})"));
    }
    if pj.pointer("/attributes/POSITION").is_none() {
        // glTF lets a primitive leave POSITION out (clients skip drawing it); there is no surface.
        return Err("no POSITION (nothing to draw)".into());
    }
    let set = match (scene.material_of(r), scene.normal_texcoord(r)) {
        (_, Some(set)) => set,
        (_, None) if all => 0,
        (None, None) => return Err("no material".into()),
        (Some(_), None) => return Err("material has no normal texture".into()),
    };
    if pj.pointer(&format!("/attributes/TEXCOORD_{set}")).is_none() {
        return Err(format!("no UVs (TEXCOORD_{set}, which the normal texture reads)"));
    }
    Ok(set)
}

/// Gives every primitive that needs them MikkTSpace tangents; returns a report per primitive.
pub fn apply(scene: &mut Scene, opts: &ApplyOptions) -> Result<Vec<PrimReport>> {
    let mut reports = Vec::new();
    let mut work: Vec<(PrimRef, u32, Primitive, Options)> = Vec::new();
    for r in scene.primitives() {
        let report = |action, reason: Option<String>, uv_set| PrimReport {
            mesh: r.mesh,
            primitive: r.primitive,
            action,
            reason,
            uv_set,
            stats: None,
        };
        match needs_tangents(scene, r, opts.all) {
            Err(why) => reports.push(report("skipped", Some(why), None)),
            Ok(set) => {
                let p = to_triangle_list(scene.primitive(r)?);
                let why = match p.attr("TANGENT") {
                    Some(t) if !opts.overwrite => match invalid_tangents(t) {
                        0 => {
                            reports.push(report(
                                "kept",
                                Some("valid tangents already present (--overwrite replaces them)".into()),
                                Some(set),
                            ));
                            continue;
                        }
                        n => Some(format!("replaced {n} invalid existing tangents (NaN, non-unit, zero or w not +-1)")),
                    },
                    Some(_) => Some("existing tangents replaced (--overwrite)".into()),
                    None => None,
                };
                reports.push(report("generated", why, Some(set)));
                let frames = Options { uv_transform: scene.normal_uv_transform(r), ..opts.frames };
                work.push((r, set, p, frames));
            }
        }
    }
    // The decoded copies are all that is needed now: free the bytes they came from.
    let refs: Vec<PrimRef> = work.iter().map(|w| w.0).collect();
    scene.release_primitives(&refs);
    let v_up = scene.uv_v_up;
    let done: Vec<(Primitive, FrameStats)> =
        work.into_par_iter().map(|(_, set, p, frames)| primitive_with_stats(p, set, v_up, &frames)).collect();
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

/// Strips and fans become lists, so every later stage sees three indices per triangle.
pub fn to_triangle_list(mut p: Primitive) -> Primitive {
    let i = &p.indices;
    let list: Vec<u32> = match p.mode {
        5 => (2..i.len())
            .flat_map(|k| if k % 2 == 0 { [i[k - 2], i[k - 1], i[k]] } else { [i[k - 1], i[k - 2], i[k]] })
            .collect(),
        6 => (2..i.len()).flat_map(|k| [i[0], i[k - 1], i[k]]).collect(),
        _ => {
            let n = i.len() / 3 * 3;
            i[..n].to_vec()
        }
    };
    p.indices = list;
    p.mode = 4;
    p
}
