//! What a pixel shows. The debug views exist to answer one question each: does the map agree
//! with the frames (`normal`), are the frames themselves sane (`tangent`, `bitangent`), where do
//! mirrored UVs flip the handedness (`handedness`), and what does the map add (`nomap`).

use super::shade::{Fragment, Light, Params};
use super::texture::linear_to_srgb;
use glam::Vec3;

/// A render mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum View {
    /// The seeds' lighting with the normal map.
    #[default]
    Shaded,
    /// World-space shading normal as colour (`0.5 + 0.5 * n`).
    Normal,
    /// World-space tangent as colour.
    Tangent,
    /// World-space bitangent `cross(N, T) * w` as colour.
    Bitangent,
    /// `w = +1` and `w = -1` in two colours.
    Handedness,
    /// The same lighting with geometry normals only.
    Nomap,
}

/// Handedness view colour where `w = +1` (display values).
pub const RIGHT_HANDED: [f32; 3] = [0.15, 0.55, 0.95];
/// Handedness view colour where `w = -1`.
pub const LEFT_HANDED: [f32; 3] = [0.95, 0.45, 0.10];
/// Where nothing is drawn.
pub const BACKGROUND: [f32; 3] = [0.12, 0.12, 0.13];

impl View {
    /// Every view, in the order `--help` lists them.
    pub const ALL: [View; 6] =
        [View::Shaded, View::Normal, View::Tangent, View::Bitangent, View::Handedness, View::Nomap];

    pub fn name(self) -> &'static str {
        match self {
            View::Shaded => "shaded",
            View::Normal => "normal",
            View::Tangent => "tangent",
            View::Bitangent => "bitangent",
            View::Handedness => "handedness",
            View::Nomap => "nomap",
        }
    }
}

/// One shaded sample: its display colour, its world-space shading normal and, in the lit views,
/// the linear radiance before the display clamps it.
pub struct Shaded {
    pub color: [f32; 3],
    pub normal: Vec3,
    pub radiance: Option<Vec3>,
}

fn as_color(v: Vec3) -> [f32; 3] {
    let d = v.normalize_or_zero() * 0.5 + Vec3::splat(0.5);
    d.clamp(Vec3::ZERO, Vec3::ONE).to_array()
}

/// Runs the fragment stage for one sample in the given view.
pub fn shade(view: View, f: &Fragment, eye: Vec3, lights: &[Light], p: &Params) -> Shaded {
    let i = f.interp();
    let n_ts = if view == View::Nomap { Vec3::Z } else { f.map_normal(&i) };
    let normal = f.world_normal(&i, n_ts);
    let mut radiance = None;
    let color = match view {
        View::Shaded | View::Nomap => {
            let c = f.lit(&i, n_ts, eye, lights, p);
            radiance = Some(c);
            [linear_to_srgb(c.x), linear_to_srgb(c.y), linear_to_srgb(c.z)]
        }
        View::Normal => as_color(normal),
        View::Tangent => as_color(i.t),
        View::Bitangent => as_color(i.b),
        View::Handedness => {
            if i.w < 0.0 {
                LEFT_HANDED
            } else {
                RIGHT_HANDED
            }
        }
    };
    Shaded { color, normal, radiance }
}
