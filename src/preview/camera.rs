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

/// A view along one axis, named as modelling tools name them (glTF's +Y up, +Z front).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Facing {
    Front,
    Back,
    Right,
    Left,
    Top,
    Bottom,
}

/// An object is flat when its thinnest extent is at most this share of its largest: seen along
/// its plane, it would cover at most this share of the image.
pub const FLAT_RATIO: f32 = 0.02;

impl Facing {
    pub fn name(self) -> &'static str {
        match self {
            Facing::Front => "front",
            Facing::Back => "back",
            Facing::Right => "right",
            Facing::Left => "left",
            Facing::Top => "top",
            Facing::Bottom => "bottom",
        }
    }

    /// The axis the view looks from, as `+Y`.
    pub fn axis(self) -> &'static str {
        match self {
            Facing::Front => "+Z",
            Facing::Back => "-Z",
            Facing::Right => "+X",
            Facing::Left => "-X",
            Facing::Top => "+Y",
            Facing::Bottom => "-Y",
        }
    }

    /// The plane a flat object seen from this view lies in.
    pub fn plane(self) -> &'static str {
        match self {
            Facing::Front | Facing::Back => "XY",
            Facing::Right | Facing::Left => "YZ",
            Facing::Top | Facing::Bottom => "XZ",
        }
    }

    /// Yaw and pitch (degrees) of the view.
    pub fn angles(self) -> (f32, f32) {
        match self {
            Facing::Front => (0.0, 0.0),
            Facing::Back => (180.0, 0.0),
            Facing::Right => (90.0, 0.0),
            Facing::Left => (-90.0, 0.0),
            Facing::Top => (0.0, 90.0),
            Facing::Bottom => (0.0, -90.0),
        }
    }

    /// The view that shows a flat object its face, or `None` when the object is not flat (or
    /// the default front view already faces it). `bounds` are the object's; `face_normal` is the
    /// sum of its triangles' area-weighted normals (by winding), which says which side of the
    /// plane the faces look to: single-sided faces are only seen from there.
    pub fn for_flat(bounds: (Vec3, Vec3), face_normal: Vec3) -> Option<Facing> {
        let e = bounds.1 - bounds.0;
        let axis = if e.x <= e.y && e.x <= e.z {
            0
        } else if e.y <= e.z {
            1
        } else {
            2
        };
        if !(e.max_element() > 0.0 && e[axis] <= FLAT_RATIO * e.max_element()) {
            return None;
        }
        let positive = face_normal[axis] >= 0.0;
        let facing = match (axis, positive) {
            (0, true) => Facing::Right,
            (0, false) => Facing::Left,
            (1, true) => Facing::Top,
            (1, false) => Facing::Bottom,
            (_, true) => Facing::Front,
            (_, false) => Facing::Back,
        };
        (facing != Facing::Front).then_some(facing)
    }
}

impl CameraSpec {
    /// This spec looking from `facing` at a flat object of `bounds` in a `width` x `height`
    /// image. Unless the spec sets a distance, the face's rectangle fills the view (with the
    /// margin [`Camera::framed`] leaves): framing the bounding sphere would leave a square plane
    /// at half the image.
    pub fn facing(self, facing: Facing, bounds: (Vec3, Vec3), width: u32, height: u32) -> CameraSpec {
        let (yaw, pitch) = facing.angles();
        let e = bounds.1 - bounds.0;
        // Extents across the image, up it, and along the view.
        let (across, up, depth) = match facing {
            Facing::Front | Facing::Back => (e.x, e.y, e.z),
            Facing::Right | Facing::Left => (e.z, e.y, e.x),
            Facing::Top | Facing::Bottom => (e.x, e.z, e.y),
        };
        let aspect = width.max(1) as f32 / height.max(1) as f32;
        let half_fov = self.fov.clamp(1.0, 170.0).to_radians() * 0.5;
        let half_fov_x = (half_fov.tan() * aspect).atan();
        let fit = (up * 0.5 / half_fov.tan()).max(across * 0.5 / half_fov_x.tan()) * 1.02 + depth * 0.5;
        CameraSpec { yaw, pitch, distance: self.distance.or(Some(fit.max(1e-6))), ..self }
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

    #[test]
    fn a_flat_object_is_seen_from_the_side_its_faces_look_to() {
        let plane = |lo: [f32; 3], hi: [f32; 3]| (Vec3::from(lo), Vec3::from(hi));
        let xz = plane([-1.0, 0.0, -1.0], [1.0, 0.0, 1.0]);
        assert_eq!(Facing::for_flat(xz, Vec3::Y), Some(Facing::Top));
        assert_eq!(Facing::for_flat(xz, -Vec3::Y), Some(Facing::Bottom));
        assert_eq!(Facing::for_flat(plane([0.0, -1.0, -1.0], [0.01, 1.0, 1.0]), Vec3::X), Some(Facing::Right));
        let xy = plane([-1.0, -1.0, 0.0], [1.0, 1.0, 0.0]);
        assert_eq!(Facing::for_flat(xy, Vec3::Z), None, "the default view faces it already");
        assert_eq!(Facing::for_flat(xy, -Vec3::Z), Some(Facing::Back));
        assert_eq!(Facing::for_flat(plane([-1.0; 3], [1.0; 3]), Vec3::Y), None, "a cube is not flat");
        assert_eq!(Facing::for_flat(plane([0.0; 3], [0.0; 3]), Vec3::Y), None, "nor is a point");
        // Seen from the top, the plane fills the view with +X to the right.
        let spec = CameraSpec::default().facing(Facing::Top, xz, 100, 100);
        let c = Camera::framed(xz, &spec, 100, 100);
        assert!(c.eye.y > 1.0);
        // Face-on and filling the view: +X right, the far edge (-Z) up, corners just inside.
        let ndc = |p: Vec3| {
            let q = c.clip(p);
            (q.x / q.w, q.y / q.w)
        };
        let (x, y) = ndc(Vec3::new(1.0, 0.0, -1.0));
        assert!(x > 0.95 && x <= 1.0 && y > 0.95 && y <= 1.0, "{x} {y}");
        let (x, y) = ndc(Vec3::new(-1.0, 0.0, 1.0));
        assert!(x < -0.95 && y < -0.95, "{x} {y}");
    }
}
