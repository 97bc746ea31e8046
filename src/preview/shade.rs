//! The shading model of the reference shaders (`shaders/bump.vert`, `shaders/bump.frag`), step for step.
//!
//! Vertex stage (per triangle corner): `N` and `T` are moved to world space and normalised,
//! `B = cross(N, T) * w`; the direction to the eye, the direction to every light and every spot
//! axis are projected onto `(T, B, N)`, i.e. moved into tangent space. Those tangent-space vectors
//! are interpolated across the triangle, unnormalised, exactly as GLSL varyings are.
//! Fragment stage: the normal-map texel is decoded `2 * texel - 1` (x, y times
//! `normalTexture.scale`), normalised, and lit with Blinn-Phong diffuse and specular terms against
//! the renormalised light and view vectors; spot lights cut off at their cone angle. The GLSL in
//! `shaders/bump.vert` and `shaders/bump.frag` is the same model for a GPU.
//!
//! Lighting in tangent space never needs the fragment's world-space normal; it is computed only
//! for the debug views and the pipeline-error statistics, as `normalize(n.x*T + n.y*B + n.z*N)`
//! with the interpolated (not renormalised) frame, which is what MikkTSpace expects.

use super::gather::{Draw, Material};
use super::pbr;
use super::texture::{Footprint, Mips};
use glam::{Vec2, Vec3, Vec4};

/// A light. Directions need not be unit length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Light {
    /// Light travelling along `dir` (the seeds' `position.w == 0`: L = -dir).
    Directional { dir: Vec3, color: Vec3 },
    /// Light from `pos`, no falloff (the seeds have none).
    Point { pos: Vec3, color: Vec3 },
    /// A point light that only lights inside the cone of half-angle `angle` (degrees) about `dir`.
    Spot { pos: Vec3, dir: Vec3, angle: f32, color: Vec3 },
}

impl Light {
    /// Parses `dir:x,y,z`, `point:x,y,z` or `spot:x,y,z:dx,dy,dz:angle`, each optionally followed
    /// by `@intensity`.
    pub fn parse(s: &str) -> Result<Light, String> {
        let (body, intensity) = match s.rsplit_once('@') {
            Some((b, i)) => (
                b,
                i.trim()
                    .parse::<f32>()
                    .ok()
                    .filter(|x| x.is_finite() && *x >= 0.0)
                    .ok_or_else(|| format!("light '{s}': bad intensity '{i}'"))?,
            ),
            None => (s, 1.0),
        };
        let color = Vec3::splat(intensity);
        let vec = |t: &str| -> Result<Vec3, String> {
            let v: Vec<f32> = t
                .split(',')
                .map(|x| x.trim().parse::<f32>())
                .collect::<Result<_, _>>()
                .map_err(|_| format!("light '{s}': '{t}' is not x,y,z"))?;
            if v.len() != 3 || v.iter().any(|x| !x.is_finite()) {
                return Err(format!("light '{s}': '{t}' is not three finite numbers x,y,z"));
            }
            Ok(Vec3::new(v[0], v[1], v[2]))
        };
        let parts: Vec<&str> = body.split(':').collect();
        match parts.as_slice() {
            ["dir", v] => {
                let dir = vec(v)?;
                if dir.length_squared() == 0.0 {
                    return Err(format!("light '{s}': direction is zero"));
                }
                Ok(Light::Directional { dir, color })
            }
            ["point", p] => Ok(Light::Point { pos: vec(p)?, color }),
            ["spot", p, d, a] => {
                let angle: f32 = a
                    .trim()
                    .parse()
                    .ok()
                    .filter(|x: &f32| x.is_finite() && *x > 0.0 && *x <= 180.0)
                    .ok_or_else(|| format!("light '{s}': cone angle '{a}' is not in (0, 180] degrees"))?;
                let dir = vec(d)?;
                if dir.length_squared() == 0.0 {
                    return Err(format!("light '{s}': spot direction is zero"));
                }
                Ok(Light::Spot { pos: vec(p)?, dir, angle, color })
            }
            _ => Err(format!("light '{s}': expected dir:x,y,z, point:x,y,z or spot:x,y,z:dx,dy,dz:angle")),
        }
    }

    fn color(&self) -> Vec3 {
        match *self {
            Light::Directional { color, .. } | Light::Point { color, .. } | Light::Spot { color, .. } => color,
        }
    }

    /// World-space vector from `p` towards the light (unnormalised, as the vertex shader makes it).
    fn towards(&self, p: Vec3) -> Vec3 {
        match *self {
            Light::Directional { dir, .. } => -dir,
            Light::Point { pos, .. } | Light::Spot { pos, .. } => pos - p,
        }
    }
}

/// The lighting model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Shading {
    /// The course notes' (and `shaders/`') Blinn-Phong with [`Params`]' specular and shininess.
    #[default]
    BlinnPhong,
    /// glTF's metallic-roughness BRDF as three.js shades it ([`pbr`]), from the material's
    /// factors and `metallicRoughnessTexture`.
    Pbr,
}

/// The constants of the lighting model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    /// Ambient term, as a fraction of the base colour.
    pub ambient: f32,
    /// Specular colour (grey).
    pub specular: f32,
    /// Blinn-Phong exponent.
    pub shininess: f32,
    pub shading: Shading,
}

impl Default for Params {
    fn default() -> Self {
        Params { ambient: 0.06, specular: 0.25, shininess: 32.0, shading: Shading::BlinnPhong }
    }
}

/// The default rig, relative to the camera: a key light from the upper left behind the viewer and
/// a dim fill from the right, so that bumps read without any flags.
pub fn default_lights(eye: Vec3, target: Vec3) -> Vec<Light> {
    let fwd = (target - eye).normalize_or_zero();
    let fwd = if fwd == Vec3::ZERO { Vec3::NEG_Z } else { fwd };
    let up0 = if fwd.y.abs() > 0.999 { Vec3::Z } else { Vec3::Y };
    let right = fwd.cross(up0).normalize();
    let up = right.cross(fwd);
    let key = (-right * 0.5 + up * 0.6 - fwd * 0.75).normalize();
    let fill = (right * 0.8 - up * 0.1 - fwd * 0.6).normalize();
    vec![
        Light::Directional { dir: -key, color: Vec3::splat(0.9) },
        Light::Directional { dir: -fill, color: Vec3::splat(0.25) },
    ]
}

/// What a fragment needs from its triangle.
pub struct Fragment<'a> {
    pub draw: &'a Draw,
    pub material: &'a Material,
    pub tri: [u32; 3],
    /// Barycentrics in the whole triangle (perspective-correct).
    pub bary: Vec3,
    /// The camera sees the back of a double-sided surface: glTF flips the normal there, which in
    /// tangent space means negating every projected vector.
    pub back: bool,
    /// How far each UV set moves per screen sample (for the mip level).
    pub duv: [Footprint; 2],
    pub mips: Mips,
}

/// The interpolated frame and vertex-stage outputs at a fragment.
pub struct Interp {
    pub t: Vec3,
    pub b: Vec3,
    pub n: Vec3,
    pub w: f32,
    pub uv: [Vec2; 2],
}

impl Fragment<'_> {
    fn frame(&self, v: usize) -> (Vec3, Vec3, Vec3) {
        let n = self.draw.normals[v];
        let t4 = self.draw.tangents[v];
        let t = t4.truncate();
        let b = n.cross(t) * t4.w;
        (t, b, n)
    }

    /// Interpolated vertex attributes (no tangent-space lighting vectors).
    pub fn interp(&self) -> Interp {
        let (mut t, mut b, mut n, mut w) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO, 0.0);
        let mut uv = [Vec2::ZERO; 2];
        for k in 0..3 {
            let v = self.tri[k] as usize;
            let (tk, bk, nk) = self.frame(v);
            let c = self.bary[k];
            t += tk * c;
            b += bk * c;
            n += nk * c;
            w += self.draw.tangents[v].w * c;
            for (s, u) in uv.iter_mut().enumerate() {
                if let Some(x) = self.draw.uvs[s].get(v) {
                    *u += *x * c;
                }
            }
        }
        Interp { t, b, n, w, uv }
    }

    /// The seeds' vertex stage for every corner, interpolated: `(to eye, to light k, spot axis k)`
    /// in tangent space.
    fn tangent_space(&self, eye: Vec3, lights: &[Light]) -> (Vec3, Vec<(Vec3, Vec3)>) {
        let mut view = Vec3::ZERO;
        let mut ls = vec![(Vec3::ZERO, Vec3::ZERO); lights.len()];
        for k in 0..3 {
            let v = self.tri[k] as usize;
            let (t, b, n) = self.frame(v);
            let p = self.draw.positions[v];
            let to_ts = |x: Vec3| Vec3::new(x.dot(t), x.dot(b), x.dot(n));
            let c = self.bary[k];
            view += to_ts(eye - p) * c;
            for (l, out) in lights.iter().zip(ls.iter_mut()) {
                out.0 += to_ts(l.towards(p)) * c;
                if let Light::Spot { dir, .. } = l {
                    out.1 += to_ts(*dir) * c;
                }
            }
        }
        if self.back {
            view = -view;
            for l in ls.iter_mut() {
                *l = (-l.0, -l.1);
            }
        }
        (view, ls)
    }

    /// The decoded, scaled, normalised tangent-space normal (`+Z` where there is no map).
    pub fn map_normal(&self, i: &Interp) -> Vec3 {
        let Some(nt) = &self.material.normal_texture else { return Vec3::Z };
        if self.draw.uvs[nt.texcoord as usize].is_empty() {
            return Vec3::Z;
        }
        let texel = nt.sample(&i.uv, &self.duv, self.mips);
        let s = self.material.normal_scale;
        let n = (texel.truncate() * 2.0 - Vec3::ONE) * Vec3::new(s, s, 1.0);
        let n = n.normalize_or_zero();
        if n == Vec3::ZERO || !n.is_finite() {
            Vec3::Z
        } else {
            n
        }
    }

    /// `baseColorFactor * baseColorTexture`, linear RGB.
    pub fn base_color(&self, i: &Interp) -> Vec3 {
        let mut c: Vec4 = self.material.base_color;
        if let Some(bt) = &self.material.base_texture {
            if !self.draw.uvs[bt.texcoord as usize].is_empty() {
                c *= bt.sample(&i.uv, &self.duv, self.mips);
            }
        }
        c.truncate().max(Vec3::ZERO)
    }

    /// The PBR material at the fragment: factors times `metallicRoughnessTexture` (roughness in
    /// G, metalness in B).
    pub fn surface(&self, i: &Interp, base_color: Vec3) -> pbr::Surface {
        let m = self.material;
        let (mut metallic, mut roughness) = (m.metallic, m.roughness);
        if let Some(t) = &m.metal_rough_texture {
            if !self.draw.uvs[t.texcoord as usize].is_empty() {
                let texel = t.sample(&i.uv, &self.duv, self.mips);
                roughness *= texel.y;
                metallic *= texel.z;
            }
        }
        pbr::Surface { base_color, metallic: metallic.clamp(0.0, 1.0), roughness: roughness.clamp(0.0, 1.0) }
    }

    /// World-space shading normal for the tangent-space normal `n` (flipped on back faces).
    pub fn world_normal(&self, i: &Interp, n: Vec3) -> Vec3 {
        let v = (i.t * n.x + i.b * n.y + i.n * n.z).normalize_or_zero();
        if self.back {
            -v
        } else {
            v
        }
    }

    /// The lit colour (linear RGB) with tangent-space normal `n`.
    pub fn lit(&self, i: &Interp, n: Vec3, eye: Vec3, lights: &[Light], p: &Params) -> Vec3 {
        let base = self.base_color(i);
        let (view, ls) = self.tangent_space(eye, lights);
        let v = view.normalize_or_zero();
        let surface = (p.shading == Shading::Pbr).then(|| self.surface(i, base));
        let mut c = match &surface {
            Some(s) => s.diffuse() * p.ambient,
            None => base * p.ambient,
        };
        for (light, (to_l, axis)) in lights.iter().zip(ls) {
            let l = to_l.normalize_or_zero();
            if let Light::Spot { angle, .. } = light {
                if (-l).dot(axis.normalize_or_zero()) < angle.to_radians().cos() {
                    continue;
                }
            }
            let nl = n.dot(l).max(0.0);
            if nl <= 0.0 {
                continue;
            }
            if let Some(s) = &surface {
                c += light.color() * pbr::direct(n, l, v, s);
                continue;
            }
            let h = (l + v).normalize_or_zero();
            let spec = n.dot(h).max(0.0).powf(p.shininess);
            c += light.color() * (base * nl + Vec3::splat(p.specular * spec));
        }
        if c.is_finite() {
            c
        } else {
            Vec3::ZERO
        }
    }
}
