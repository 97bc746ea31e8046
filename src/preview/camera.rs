//! The perspective camera, framed on the scene's bounds so that one command shows the whole
//! asset without the user knowing its size or where it sits.

use glam::{Mat4, Vec3, Vec4};

/// Where to look from. Angles are in degrees; `None` distance means "fit the bounds".
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraSpec {
    /// Rotation about world +Y; 0 looks from +Z towards -Z (glTF's "front").
    pub yaw: f32,
    /// Elevation above the XZ plane; positive looks down on the asset.
    pub pitch: f32,
    /// Distance from the centre of the bounds, in scene units.
    pub distance: Option<f32>,
    /// Vertical field of view.
    pub fov: f32,
}

impl Default for CameraSpec {
    fn default() -> Self {
        CameraSpec { yaw: 0.0, pitch: 0.0, distance: None, fov: 40.0 }
    }
}

/// A camera ready to project.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub view_proj: Mat4,
    pub width: u32,
    pub height: u32,
}

impl Camera {
    /// Frames the bounding sphere of `bounds` in a `width` x `height` image.
    pub fn framed(bounds: (Vec3, Vec3), spec: &CameraSpec, width: u32, height: u32) -> Camera {
        let (lo, hi) = bounds;
        let center = (lo + hi) * 0.5;
        let radius = ((hi - lo).length() * 0.5).max(1e-6);
        let aspect = width.max(1) as f32 / height.max(1) as f32;
        let fov = spec.fov.clamp(1.0, 170.0).to_radians();
        let fov_x = 2.0 * ((fov * 0.5).tan() * aspect).atan();
        let fit = radius / (fov.min(fov_x) * 0.5).sin() * 1.02;
        let distance = spec.distance.filter(|d| d.is_finite() && *d > 0.0).unwrap_or(fit);
        let (yaw, pitch) = (spec.yaw.to_radians(), spec.pitch.clamp(-90.0, 90.0).to_radians());
        let dir = Vec3::new(yaw.sin() * pitch.cos(), pitch.sin(), yaw.cos() * pitch.cos());
        let eye = center + dir * distance;
        let up = if dir.y.abs() > 0.999 { Vec3::new(-yaw.sin(), 0.0, -yaw.cos()) * dir.y.signum() } else { Vec3::Y };
        let view = Mat4::look_at_rh(eye, center, up);
        // Depth range hugs the bounds so 24-bit-like precision is not wasted on empty space.
        let near = (distance - radius * 1.5).max(radius * 1e-3).max(distance * 1e-4);
        let far = distance + radius * 1.5;
        let proj = Mat4::perspective_rh_gl(fov, aspect, near, far.max(near * 2.0));
        Camera { eye, target: center, view_proj: proj * view, width, height }
    }

    /// Clip-space position of a world point.
    pub fn clip(&self, p: Vec3) -> Vec4 {
        self.view_proj * p.extend(1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_camera_sees_front_with_x_right_y_up() {
        let c = Camera::framed((Vec3::splat(-1.0), Vec3::splat(1.0)), &CameraSpec::default(), 100, 100);
        assert!(c.eye.z > 1.0);
        let r = c.clip(Vec3::new(0.5, 0.0, 0.0));
        let u = c.clip(Vec3::new(0.0, 0.5, 0.0));
        assert!(r.x / r.w > 0.0 && u.y / u.w > 0.0);
        for corner in [Vec3::splat(-1.0), Vec3::splat(1.0), Vec3::new(1.0, -1.0, 1.0)] {
            let p = c.clip(corner);
            assert!(p.w > 0.0 && (p.x / p.w).abs() <= 1.0 && (p.y / p.w).abs() <= 1.0 && (p.z / p.w).abs() <= 1.0);
        }
    }
}
