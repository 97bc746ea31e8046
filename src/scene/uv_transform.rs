//! `KHR_texture_transform`: the UVs a texture is sampled at.

use serde::Serialize;
use serde_json::Value;

/// `KHR_texture_transform` on one texture-info object.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct UvTransform {
    pub offset: [f32; 2],
    /// Radians; rotates the UVs counter-clockwise (as the spec's example and three.js do).
    pub rotation: f32,
    pub scale: [f32; 2],
}

impl UvTransform {
    /// The UV the texture is sampled at: `translation * rotation * scale * uv`, with the
    /// rotation matrix rows `(cos, sin)` and `(-sin, cos)`.
    /// Computed in f64 so that dequantizing transforms (gltfpack's) round once, at the end.
    pub fn apply(&self, uv: [f32; 2]) -> [f32; 2] {
        let (s, c) = (self.rotation as f64).sin_cos();
        let (u, v) = (uv[0] as f64 * self.scale[0] as f64, uv[1] as f64 * self.scale[1] as f64);
        [(c * u + s * v + self.offset[0] as f64) as f32, (-s * u + c * v + self.offset[1] as f64) as f32]
    }

    /// The most a UV difference can grow through the transform (the larger of the scales).
    pub fn max_stretch(&self) -> f64 {
        (self.scale[0] as f64).abs().max((self.scale[1] as f64).abs())
    }

    /// Whether applying it changes nothing.
    pub fn is_identity(&self) -> bool {
        self.offset == [0.0, 0.0] && self.rotation == 0.0 && self.scale == [1.0, 1.0]
    }

    /// The transform a texture-info's extension describes, or `None` for none or the identity.
    pub fn from_texture_info(info: &Value) -> Option<UvTransform> {
        let t = info.pointer("/extensions/KHR_texture_transform")?;
        let pair = |key: &str, default: [f32; 2]| {
            t.get(key)
                .and_then(|v| v.as_array())
                .filter(|a| a.len() == 2)
                .and_then(|a| Some([a[0].as_f64()? as f32, a[1].as_f64()? as f32]))
                .filter(|p| p.iter().all(|x| x.is_finite()))
                .unwrap_or(default)
        };
        let rotation = t.get("rotation").and_then(|r| r.as_f64()).map(|r| r as f32).filter(|r| r.is_finite());
        let tr = UvTransform {
            offset: pair("offset", [0.0, 0.0]),
            rotation: rotation.unwrap_or(0.0),
            scale: pair("scale", [1.0, 1.0]),
        };
        (!tr.is_identity()).then_some(tr)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_turns_uvs_counter_clockwise() {
        // The spec's example: the lower-left quadrant, rotated clockwise 90 degrees.
        let t = UvTransform { offset: [0.0, 1.0], rotation: std::f32::consts::FRAC_PI_2, scale: [0.5, 0.5] };
        let close = |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6;
        assert!(close(t.apply([0.0, 0.0]), [0.0, 1.0]));
        assert!(close(t.apply([1.0, 0.0]), [0.0, 0.5]));
        assert!(close(t.apply([0.0, 1.0]), [0.5, 1.0]));
        assert!(close(t.apply([1.0, 1.0]), [0.5, 0.5]));
    }
}
