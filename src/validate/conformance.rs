//! Conformance: are the stored tangents the MikkTSpace frames a renderer would compute?
//!
//! A normal map is only correct under the frames it was baked against, and bakers (Blender,
//! Substance, xNormal, bumpbake) bake against MikkTSpace. Stored tangents far from MikkTSpace's
//! mean the file shades differently from the bake, even though every tangent is individually valid.
//!
//! Comparison is per corner, because MikkTSpace gives one frame per triangle corner. Corners an
//! earlier check already explained, and triangles where the reference is undefined (zero area in
//! space or UV space), are skipped.

use super::frames::{Explained, PrimData};
use super::{Code, Example, Finding, Subject, Worst};
use crate::tangent::mikk::{self, Engine};
use crate::tangent::TriMesh;
use glam::DVec3;

/// The stored frames against regenerated MikkTSpace frames.
pub fn check(d: &PrimData, max_angle_deg: f64, ex: &mut Explained, s: &mut Subject) {
    check_against(d, max_angle_deg, ex, s, |mesh| mikk::generate(mesh, Engine::Fast))
}

/// [`check`] against the frames `engine` makes: the test of a failing engine gives its own.
fn check_against(
    d: &PrimData,
    max_angle_deg: f64,
    ex: &mut Explained,
    s: &mut Subject,
    engine: impl Fn(&TriMesh) -> Vec<Option<[f32; 4]>>,
) {
    let (Some(t), Some(normals), Some(uvs)) = (&d.tangents, &d.normals, &d.uvs) else { return };
    // The engine trusts its input; give it finite values so no input can upset it.
    let clean3 = |v: &[f32; 3]| if v.iter().all(|x| x.is_finite()) { *v } else { [0.0; 3] };
    let normals_c: Vec<[f32; 3]> = normals.iter().map(clean3).collect();
    let uvs_c: Vec<[f32; 2]> =
        uvs.iter().map(|v| if v.iter().all(|x| x.is_finite()) { *v } else { [0.0; 2] }).collect();
    let mesh = TriMesh { positions: &d.positions, normals: &normals_c, uvs: &uvs_c, indices: &d.indices };
    // The fast engine: bit-identical to the reference (held to it by the differential tests),
    // linear in time and without the reference's recursion, which a high-valence vertex overflows.
    // The engine is not expected to fail on anything the reader accepts; if it does, that is a
    // bug to report, and the file must not pass as if it had been checked.
    let reference = match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| engine(&mesh))) {
        Ok(r) => r,
        Err(_) => {
            let f = Finding::new(
                Code::TANGENT_MIKK_UNCHECKED,
                1,
                1,
                "primitives",
                "the MikkTSpace comparison failed on this primitive, so its tangents were not compared",
            );
            s.check(Code::TANGENT_MIKK_UNCHECKED, Some(f));
            return;
        }
    };
    // What quantization explains, per vertex, on top of the threshold (none for float data).
    let (slack, may_flip) = d.quant.slack(&d.positions, &uvs_c, &d.indices);
    let frame_slack = d.quant.frame_angle();
    let mut angles: Vec<f64> = Vec::with_capacity(reference.len());
    let (mut sign_bad, mut above) = (0usize, 0usize);
    let (mut w_sign, mut w_angle) = (Worst::default(), Worst::default());
    for (c, r) in reference.iter().enumerate() {
        let v = d.indices[c] as usize;
        let Some(r) = r else { continue };
        if !ex.open(c, v) || !r.iter().all(|x| x.is_finite()) {
            continue;
        }
        let stored = t[v];
        let ref_w = crate::tangent::gltf_w(r[3]);
        if (stored[3] > 0.0) != (ref_w > 0.0) {
            if may_flip.get(c / 3).copied().unwrap_or(false) {
                // Rounding may have turned the triangle over in UV space: its frame says nothing.
                continue;
            }
            sign_bad += 1;
            ex.corner[c] = true;
            w_sign.push(1.0 / (1.0 + c as f64), || Example {
                kind: "corner",
                index: c as u64,
                at: None,
                detail: format!("triangle {} vertex {v}: stored w {}, MikkTSpace {}", c / 3, stored[3], ref_w),
            });
            continue;
        }
        let a = DVec3::new(stored[0] as f64, stored[1] as f64, stored[2] as f64).normalize_or_zero();
        let b = DVec3::new(r[0] as f64, r[1] as f64, r[2] as f64).normalize_or_zero();
        if a == DVec3::ZERO || b == DVec3::ZERO {
            continue;
        }
        // atan2 keeps precision near 0, where acos of a dot product loses it.
        let deg = a.cross(b).length().atan2(a.dot(b)).to_degrees();
        angles.push(deg);
        let limit = match slack.get(v) {
            Some(turn) => max_angle_deg + (turn + frame_slack).to_degrees(),
            None => max_angle_deg,
        };
        if deg > limit {
            above += 1;
            ex.corner[c] = true;
            w_angle.push(deg, || Example {
                kind: "corner",
                index: c as u64,
                at: None,
                detail: format!(
                    "triangle {} vertex {v}: stored ({:.4}, {:.4}, {:.4}) vs MikkTSpace ({:.4}, {:.4}, {:.4}): {deg:.2}°",
                    c / 3,
                    stored[0],
                    stored[1],
                    stored[2],
                    r[0],
                    r[1],
                    r[2]
                ),
            });
        }
    }
    let compared = angles.len();
    let max = angles.iter().cloned().fold(0.0f64, f64::max);
    let p99 = percentile(&mut angles, 0.99);
    s.check(
        Code::TANGENT_MIKK_SIGN,
        (sign_bad > 0).then(|| {
            let total = compared + sign_bad;
            Finding::new(
                Code::TANGENT_MIKK_SIGN,
                sign_bad,
                total,
                "corners",
                format!("{sign_bad} of {total} corners have w opposite to MikkTSpace's"),
            )
            .examples(w_sign.into_examples())
        }),
    );
    s.check(Code::TANGENT_MIKK_ANGLE, (above > 0).then(|| {
        Finding::new(
            Code::TANGENT_MIKK_ANGLE,
            above,
            compared,
            "corners",
            format!("{above} of {compared} corners differ from MikkTSpace by more than {max_angle_deg}° (max {max:.2}°, p99 {p99:.2}°)"),
        )
        .examples(w_angle.into_examples())
        .metric("max_angle_deg", max)
        .metric("p99_angle_deg", p99)
        .metric("threshold_deg", max_angle_deg)
    }));
    s.conformance = Some(Conformance { compared, max_angle_deg: max, p99_angle_deg: p99, sign_mismatches: sign_bad });
}

/// The agreement figures of a primitive, reported even when it passes.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Conformance {
    pub compared: usize,
    pub max_angle_deg: f64,
    pub p99_angle_deg: f64,
    pub sign_mismatches: usize,
}

/// The `q` quantile (nearest rank) in linear time; reorders `v`.
fn percentile(v: &mut [f64], q: f64) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let k = (((v.len() as f64) * q).ceil() as usize).clamp(1, v.len()) - 1;
    let (_, x, _) = v.select_nth_unstable_by(k, |a, b| a.total_cmp(b));
    *x
}

#[cfg(test)]
mod tests {
    #[test]
    fn percentile_nearest_rank() {
        let mut v: Vec<f64> = (1..=100).map(|x| x as f64).collect();
        assert_eq!(super::percentile(&mut v, 0.99), 99.0);
        assert_eq!(super::percentile(&mut [5.0], 0.99), 5.0);
        assert_eq!(super::percentile(&mut [], 0.99), 0.0);
    }
}

#[cfg(test)]
mod engine_tests {
    use super::*;
    use crate::validate::frames::Quant;

    /// A comparison that could not run is an error finding, never a primitive passed as checked.
    /// No input the reader accepts is known to make the engine panic, so the test gives one that
    /// does.
    #[test]
    fn a_failed_comparison_is_an_error_not_a_silence() {
        let d = PrimData {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            normals: Some(vec![[0.0, 0.0, 1.0]; 3]),
            uvs: Some(vec![[0.0, 1.0], [1.0, 1.0], [0.0, 0.0]]),
            tangents: Some(vec![[1.0, 0.0, 0.0, 1.0]; 3]),
            quant: Quant::default(),
            indices: vec![0, 1, 2],
        };
        let run = |engine: &dyn Fn(&TriMesh) -> Vec<Option<[f32; 4]>>| {
            let mut s = Subject::new("primitive", "test");
            check_against(&d, 1.0, &mut Explained::new(3, 3), &mut s, engine);
            s.findings.iter().map(|f| f.code).collect::<Vec<_>>()
        };
        assert_eq!(run(&|_| panic!("a failing engine")), vec![Code::TANGENT_MIKK_UNCHECKED]);
        assert_eq!(run(&|m| mikk::generate(m, Engine::Fast)), vec![]);
    }
}
