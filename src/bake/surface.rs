//! A height map through a mesh: the tangent-space normal map that, drawn with the mesh's own
//! MikkTSpace frames, shades as Cycles' Bump node shades the mesh with that height.
//!
//! Cycles' Bump node (`svm_node_set_bump`) offsets the surface by `D·h` along the shading normal
//! `N` and takes the height's gradient on the surface from two nearby points `P + dPdx`,
//! `P + dPdy`:
//!
//! ```text
//! Rx = dPdy × N,  Ry = N × dPdx,  det = dPdx · Rx
//! n  = normalize(|det|·N − D·sign(det)·((h_x − h)·Rx + (h_y − h)·Ry))
//! n' = normalize(s·n + (1 − s)·N)              (Strength s; Invert negates D)
//! ```
//!
//! `surfgrad/det` does not depend on which two directions span the surface, so it is taken along
//! the texel axes, where the mesh's UV Jacobian gives `P_x = dP/dx`, `P_y = dP/dy` per triangle and
//! the derivative filter gives `h_x`, `h_y` per texel:
//! `∇h = ((h_x·P_y − h_y·P_x) × N) / (N · (P_x × P_y))`. A texel's world-space extent along
//! the tangent and bitangent is therefore the mesh's, not one size for the whole map: stretched
//! UVs, a sphere's poles and a scaled node all come out as Cycles shades them.
//!
//! The normal is then written in the frame a renderer rebuilds per pixel, interpolated and not
//! normalised (`T`, `B = w·(N × T)`, `N`), through that frame's inverse, as Blender's bake
//! (`RE_bake_normal_world_to_tangent`) and [`crate::transfer`] do: the map decodes to `n'`.

use crate::normalmap::{self, Filter, HeightPlane, NormalPlane, Options, Wrap};
use crate::transfer::{pad, raster};
use glam::{DVec3, Vec3A};
use rayon::prelude::*;

/// A triangle mesh placed in the world: corners indexed by `triangles`, one entry per vertex in
/// every other slice. `uvs` are glTF's (origin top-left, v down) in the map's `[0, 1]` square.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceMesh<'a> {
    pub positions: &'a [[f32; 3]],
    pub normals: &'a [[f32; 3]],
    /// MikkTSpace `xyz` and handedness `w`, as written for the renderer.
    pub tangents: &'a [[f32; 4]],
    pub uvs: &'a [[f32; 2]],
    pub triangles: &'a [[u32; 3]],
}

/// The Bump node's settings, and how the height is differentiated.
#[derive(Clone, Copy, Debug)]
pub struct Bump {
    /// Surface height of `h = 1`, in the mesh's units (the Bump node's Distance).
    pub distance: f64,
    /// The Bump node's Strength: the bumped normal mixed with the unbumped one, then normalised
    /// (clamped at 0, as Cycles does).
    pub strength: f64,
    /// The height holds depth (the Bump node's Invert).
    pub invert: bool,
    pub filter: Filter,
    pub wrap: Wrap,
    /// Rings of texels around the UV islands given their nearest island's normals.
    pub padding: usize,
}

impl Default for Bump {
    fn default() -> Self {
        Bump { distance: 1.0, strength: 1.0, invert: false, filter: Filter::Central, wrap: Wrap::Repeat, padding: 16 }
    }
}

/// The map, and how much of it the mesh covers.
#[derive(Clone, Debug)]
pub struct SurfaceMap {
    /// Unit tangent-space normals, OpenGL/glTF convention (+Y up), the height's size.
    pub normals: NormalPlane,
    /// Texels whose centre a UV triangle holds, or lies within a texel of.
    pub covered: usize,
    /// Texels around the islands filled by padding.
    pub padded: usize,
    /// Texels left flat (`(0, 0, 1)`), beyond the padding.
    pub uncovered: usize,
}

/// Rows of the map one task rasterises and converts.
const BAND: usize = 32;

/// The world-space layout of one triangle over texel space (solved in f64, used in f32: the
/// per-texel arithmetic is the conversion's cost).
#[derive(Clone, Copy)]
struct Jacobian {
    /// `dP/dx`, `dP/dy` per texel (y down, as rows run).
    px: Vec3A,
    py: Vec3A,
}

fn jacobian(p: [DVec3; 3], t: [[f64; 2]; 3]) -> Jacobian {
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let (d1, d2) = ([t[1][0] - t[0][0], t[1][1] - t[0][1]], [t[2][0] - t[0][0], t[2][1] - t[0][1]]);
    let det = d1[0] * d2[1] - d2[0] * d1[1];
    if det == 0.0 || !det.is_finite() {
        return Jacobian { px: Vec3A::ZERO, py: Vec3A::ZERO };
    }
    // [e1 e2] = [px py]·[d1 d2]  =>  [px py] = [e1 e2]·[d1 d2]⁻¹
    let inv = 1.0 / det;
    let f = |v: DVec3| Vec3A::new(v.x as f32, v.y as f32, v.z as f32);
    Jacobian { px: f((e1 * d2[1] - e2 * d1[1]) * inv), py: f((e2 * d1[0] - e1 * d2[0]) * inv) }
}

fn dvec(v: [f32; 3]) -> DVec3 {
    DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
}

/// The bumped world normal at a point whose shading normal is `n` (unit), height slope `(hx, hy)`
/// per texel (y down), on a triangle laid out by `j`.
fn bumped(n: Vec3A, j: &Jacobian, hx: f32, hy: f32, b: &Bump) -> Vec3A {
    let det = n.dot(j.px.cross(j.py));
    if det == 0.0 || !det.is_finite() {
        return n;
    }
    let d = if b.invert { -b.distance } else { b.distance } as f32;
    let grad = (j.py * hx - j.px * hy).cross(n) / det;
    let bumped = (n - grad * d).normalize_or(n);
    let s = b.strength.max(0.0) as f32;
    if s == 1.0 {
        return bumped;
    }
    (bumped * s + n * (1.0 - s)).normalize_or(n)
}

/// `v` in the frame `(t, b, n)`: the solution of `x·t + y·b + z·n = v`, normalised; the frame's
/// transpose when it is singular.
fn in_frame(v: Vec3A, t: Vec3A, b: Vec3A, n: Vec3A) -> [f32; 3] {
    let det = t.dot(b.cross(n));
    let x = if det.abs() > 1e-6 {
        Vec3A::new(v.dot(b.cross(n)), v.dot(n.cross(t)), v.dot(t.cross(b))) / det
    } else {
        Vec3A::new(v.dot(t), v.dot(b), v.dot(n))
    };
    x.normalize_or(Vec3A::Z).to_array()
}

/// The normal map of `height` through `mesh` (at the height's size). A texel outside every UV
/// triangle (and beyond the padding) is flat.
pub fn surface_normals(mesh: &SurfaceMesh, height: &HeightPlane, b: &Bump) -> SurfaceMap {
    let (w, h) = (height.width, height.height);
    let grad = normalmap::gradients(height, &Options { strength: 1.0, filter: b.filter, wrap: b.wrap, invert: false });
    let texel = |uv: [f32; 2]| [uv[0] as f64 * w as f64, uv[1] as f64 * h as f64];
    let uv_tris: Vec<raster::UvTri> = mesh
        .triangles
        .iter()
        .map(|t| raster::UvTri { p: t.map(|i| texel(mesh.uvs[i as usize]).map(|c| c as f32)) })
        .collect();
    let edges: Vec<Option<raster::Edges>> = uv_tris.iter().map(raster::Edges::new).collect();
    let jac: Vec<Jacobian> = mesh
        .triangles
        .iter()
        .map(|t| jacobian(t.map(|i| dvec(mesh.positions[i as usize])), t.map(|i| texel(mesh.uvs[i as usize]))))
        .collect();
    // Bands of rows, each rasterised and converted by one task: the triangles that reach a band
    // are its candidates, in index order (the first wins where UVs overlap).
    let rows = BAND.min(h.max(1));
    let bands = h.div_ceil(rows);
    let mut candidates: Vec<Vec<u32>> = vec![Vec::new(); bands];
    for (t, e) in edges.iter().enumerate() {
        let Some(e) = e else { continue };
        let band_of = |y: f32| ((y.max(0.0) as usize) / rows).min(bands.saturating_sub(1));
        (band_of(e.min[1])..=band_of(e.max[1])).for_each(|b| candidates[b].push(t as u32));
    }
    let mut normals = vec![[0.0f32, 0.0, 1.0]; w * h];
    let mut filled = vec![false; w * h];
    let chunk = w.max(1) * rows;
    normals.par_chunks_mut(chunk).zip(filled.par_chunks_mut(chunk)).enumerate().for_each(|(k, (out, fill))| {
        let y0 = k * rows;
        let owners = raster::band(&edges, &candidates[k], y0, y0 + out.len() / w.max(1), w, 1);
        for (j, out) in out.iter_mut().enumerate() {
            let t = owners.owner[j];
            if t == u32::MAX {
                continue;
            }
            let Some(e) = &edges[t as usize] else { continue };
            fill[j] = true;
            let (x, y) = (j % w, y0 + j / w);
            let i = y * w + x;
            let (sx, sy) = raster::sample_pos(x, y, 0, 1);
            let bc = e.bary(sx, sy);
            let tri = mesh.triangles[t as usize].map(|v| v as usize);
            let [b0, b1, b2] = bc;
            let lerp =
                |a: [f32; 3], b: [f32; 3], c: [f32; 3]| Vec3A::from(a) * b0 + Vec3A::from(b) * b1 + Vec3A::from(c) * b2;
            let (nv, tv) = (mesh.normals, mesh.tangents);
            let n = lerp(nv[tri[0]], nv[tri[1]], nv[tri[2]]);
            let xyz = |q: [f32; 4]| [q[0], q[1], q[2]];
            let tan = lerp(xyz(tv[tri[0]]), xyz(tv[tri[1]]), xyz(tv[tri[2]]));
            let sign = tv[tri[0]][3] + tv[tri[1]][3] + tv[tri[2]][3];
            let bit = n.cross(tan) * if sign < 0.0 { -1.0 } else { 1.0 };
            let unit = n.normalize_or(Vec3A::Z);
            let [gx, gy_up] = grad[i];
            let world = bumped(unit, &jac[t as usize], gx, -gy_up, b);
            *out = in_frame(world, tan, bit, n);
        }
    });
    let covered = filled.iter().filter(|&&f| f).count();
    let padded = pad::pad(w, h, &mut normals, &mut filled, b.padding);
    let uncovered = filled.iter().filter(|&&f| !f).count();
    SurfaceMap { normals: NormalPlane { width: w, height: h, data: normals }, covered, padded, uncovered }
}

#[cfg(test)]
mod tests {
    use super::*;

    type Quad = (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<[f32; 4]>, Vec<[f32; 2]>, Vec<[u32; 3]>);

    /// A flat quad over `[0, sx] x [0, sy]` (z up), its UV square mapped whole, v down towards -y.
    fn quad(sx: f32, sy: f32) -> Quad {
        let p = vec![[0.0, sy, 0.0], [sx, sy, 0.0], [sx, 0.0, 0.0], [0.0, 0.0, 0.0]];
        let uv = vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        (p, vec![[0.0, 0.0, 1.0]; 4], vec![[1.0, 0.0, 0.0, 1.0]; 4], uv, vec![[0, 3, 2], [0, 2, 1]])
    }

    /// A linear ramp on a flat quad: every texel's normal is the analytic one, whatever the
    /// quad's aspect: `(-D·dh/dX, -D·dh/dY, 1)` with `dh/dX` per world unit.
    #[test]
    fn a_ramp_on_a_stretched_quad_is_exact() {
        let (sx, sy) = (3.0f32, 1.0f32);
        let (p, n, t, uv, tris) = quad(sx, sy);
        let mesh = SurfaceMesh { positions: &p, normals: &n, tangents: &t, uvs: &uv, triangles: &tris };
        let (w, h) = (32usize, 32usize);
        // h = 0.01·x + 0.02·row: rises towards +X and towards -Y (rows run down the image).
        let plane = HeightPlane::from_fn(w, h, |x, y| 0.01 * x as f32 + 0.02 * y as f32);
        let b = Bump { distance: 2.0, wrap: Wrap::Clamp, ..Default::default() };
        let map = surface_normals(&mesh, &plane, &b);
        assert_eq!(map.covered, w * h);
        let (dhdx, dhdy) = (0.01 * w as f64 / sx as f64, -0.02 * h as f64 / sy as f64);
        let want = DVec3::new(-2.0 * dhdx, -2.0 * dhdy, 1.0).normalize();
        for y in 1..h - 1 {
            for x in 1..w - 1 {
                let got = map.normals.get(x, y);
                let got = DVec3::new(got[0] as f64, got[1] as f64, got[2] as f64);
                assert!(got.angle_between(want) < 1e-5, "texel {x},{y}: {got} vs {want}");
            }
        }
    }

    /// Strength mixes as Cycles mixes; Invert negates the distance.
    #[test]
    fn strength_and_invert_follow_the_bump_node() {
        let n = Vec3A::Z;
        let j = Jacobian { px: Vec3A::X, py: -Vec3A::Y };
        let full = bumped(n, &j, 0.5, 0.0, &Bump::default());
        assert!((full - Vec3A::new(-0.5, 0.0, 1.0).normalize()).length() < 1e-6);
        let half = bumped(n, &j, 0.5, 0.0, &Bump { strength: 0.5, ..Default::default() });
        assert!((half - (full * 0.5 + n * 0.5).normalize()).length() < 1e-6);
        let inv = bumped(n, &j, 0.5, 0.0, &Bump { invert: true, ..Default::default() });
        assert!((inv - Vec3A::new(0.5, 0.0, 1.0).normalize()).length() < 1e-6);
    }

    /// A frame that is not orthonormal is inverted, not transposed.
    #[test]
    fn skewed_frames_are_inverted() {
        let (t, b, n) = (Vec3A::new(1.0, 0.2, 0.1), Vec3A::new(0.1, 1.0, 0.0), Vec3A::new(0.0, 0.1, 1.0));
        let v = (t * 0.3 + b * -0.2 + n * 0.9).normalize();
        let x = in_frame(v, t, b, n);
        let back = (t * x[0] + b * x[1] + n * x[2]).normalize();
        assert!(back.angle_between(v) < 1e-5);
    }
}
