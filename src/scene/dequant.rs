//! What a renderer sees of quantized attributes (KHR_mesh_quantization): normals brought back to
//! unit length, and UVs through the KHR_texture_transform that dequantizes them (gltfpack puts one
//! on every texture of a material whose UVs it quantized).
//!
//! Positions are left in mesh space, as the conventions ask. glTF-Transform and gltfpack
//! dequantize them with a uniform scale and a translation on the node, which keep every angle and
//! direction MikkTSpace measures. Even a non-uniform node matrix `M` would change little: each
//! triangle's tangent (dP/du) maps to exactly `M` times itself, and orthogonality to the normal
//! survives (normals map by `M^-T`); only the angle weights of MikkTSpace's vertex average change.

use super::accessor::{Stream, FLOAT};
use super::material::UvTransform;
use std::borrow::Cow;

/// UVs as the texture lookup sees them.
pub fn transformed_uvs<'a>(uvs: Cow<'a, [[f32; 2]]>, t: Option<&UvTransform>) -> Cow<'a, [[f32; 2]]> {
    match t {
        Some(t) => Cow::Owned(uvs.iter().map(|&uv| t.apply(uv)).collect()),
        None => uvs,
    }
}

/// NORMAL as a renderer uses it: float normals as stored (the reference MikkTSpace sees them so),
/// quantized ones brought back to unit length, since 8- and 16-bit components are never exactly
/// unit.
pub fn unit_normals(s: &Stream) -> Cow<'_, [[f32; 3]]> {
    if s.format.component_type == FLOAT {
        return s.as_f32();
    }
    Cow::Owned(
        s.to_f32::<3>()
            .into_iter()
            .map(|n| {
                let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                if len > 0.0 {
                    [n[0] / len, n[1] / len, n[2] / len]
                } else {
                    n
                }
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::accessor::{Format, BYTE};
    use serde_json::json;

    #[test]
    fn transform_matches_the_extension_s_matrix() {
        let info = json!({"extensions": {"KHR_texture_transform":
            {"offset": [0.5, 0.25], "rotation": std::f64::consts::FRAC_PI_2, "scale": [2.0, 3.0]}}});
        let t = UvTransform::from_texture_info(&info).unwrap();
        // scale -> (2u, 3v); rotation by 90° -> (3v, -2u); offset.
        let [u, v] = t.apply([1.0, 1.0]);
        assert!((u - 3.5).abs() < 1e-6 && (v - (-1.75)).abs() < 1e-6, "{u} {v}");
        assert!((t.max_stretch() - 3.0).abs() < 1e-12);
        assert!(UvTransform::from_texture_info(&json!({"extensions": {"KHR_texture_transform": {}}})).is_none());
        assert!(UvTransform::from_texture_info(&json!({"index": 0})).is_none());
    }

    #[test]
    fn quantized_normals_come_back_unit_and_float_ones_stay_as_stored() {
        let s = Stream {
            format: Format { component_type: BYTE, ty: "VEC3".into(), normalized: true },
            data: vec![90, 90, 0, 0, 0, 0],
            template: None,
        };
        let n = unit_normals(&s);
        assert!(((n[0][0] as f64).hypot(n[0][1] as f64) - 1.0).abs() < 1e-6);
        assert_eq!(n[1], [0.0, 0.0, 0.0]);
        let f = Stream::from_f32("VEC3", &[[0.0, 0.0, 2.0]]);
        assert_eq!(unit_normals(&f)[0], [0.0, 0.0, 2.0]);
    }
}
