//! Parametric surfaces whose exact tangent frame is known in closed form, and a high-valence
//! fan: what `bumpbake bench tangents` and the tests measure tangent engines against.
//!
//! Each surface is a `(u, v)` grid with `uv = (u, v)`, analytic unit normals, and triangles
//! wound so that the UV orientation is preserved: the exact frame at a vertex is
//! `t = normalize(P_u - (P_u·N) N)` with sign `+1`.

use crate::tangent::TriMesh;
use serde::Serialize;
use std::f32::consts::{PI, TAU};

/// A test surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Surface {
    /// Unit sphere, latitude band 0.1π..0.9π (the poles have no `P_u`).
    Sphere,
    /// Torus R = 1, r = 0.35.
    Torus,
    /// Height field `z = 0.05 sin(6πu) sin(6πv)` over the unit square.
    WavyGrid,
    /// A flat disk of triangles all sharing the centre vertex (planar UVs).
    Fan,
    /// A mesh read from a file (its rows carry the file name).
    Mesh,
}

impl Surface {
    pub fn name(self) -> &'static str {
        match self {
            Surface::Sphere => "sphere",
            Surface::Torus => "torus",
            Surface::WavyGrid => "wavy-grid",
            Surface::Fan => "fan",
            Surface::Mesh => "mesh",
        }
    }
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "sphere" => Some(Surface::Sphere),
            "torus" => Some(Surface::Torus),
            "wavy-grid" | "grid" => Some(Surface::WavyGrid),
            "fan" => Some(Surface::Fan),
            _ => None,
        }
    }
}

/// A generated mesh and its exact per-vertex tangents.
pub struct Case {
    pub surface: Surface,
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    pub indices: Vec<u32>,
    /// Exact unit tangent per vertex (sign is +1 everywhere); empty for a mesh from a file.
    pub exact: Vec<[f32; 3]>,
    /// The surface's name, or the file name of a mesh.
    pub label: String,
}

impl Case {
    pub fn triangles(&self) -> usize {
        self.indices.len() / 3
    }
    pub fn mesh(&self) -> TriMesh<'_> {
        TriMesh { positions: &self.positions, normals: &self.normals, uvs: &self.uvs, indices: &self.indices }
    }
}

fn norm(v: [f32; 3]) -> [f32; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if l > 0.0 {
        [v[0] / l, v[1] / l, v[2] / l]
    } else {
        v
    }
}

fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Position and `P_u`, `P_v` of a parametric surface.
fn eval(s: Surface, u: f32, v: f32) -> ([f32; 3], [f32; 3], [f32; 3]) {
    match s {
        Surface::Sphere => {
            let (ph, th) = (TAU * u, PI * (0.1 + 0.8 * v));
            let (sp, cp, st, ct) = (ph.sin(), ph.cos(), th.sin(), th.cos());
            // Pv points from the south band towards the north: v up along +z.
            let p = [st * cp, st * sp, -ct];
            let pu = [-TAU * st * sp, TAU * st * cp, 0.0];
            let pv = [0.8 * PI * ct * cp, 0.8 * PI * ct * sp, 0.8 * PI * st];
            (p, pu, pv)
        }
        Surface::Torus => {
            let (big, r) = (1.0f32, 0.35f32);
            let (ph, th) = (TAU * u, TAU * v);
            let (sp, cp, st, ct) = (ph.sin(), ph.cos(), th.sin(), th.cos());
            let p = [(big + r * ct) * cp, (big + r * ct) * sp, r * st];
            let pu = [-TAU * (big + r * ct) * sp, TAU * (big + r * ct) * cp, 0.0];
            let pv = [-TAU * r * st * cp, -TAU * r * st * sp, TAU * r * ct];
            (p, pu, pv)
        }
        Surface::WavyGrid | Surface::Fan | Surface::Mesh => {
            let (a, k) = (0.05f32, 3.0 * TAU);
            let z = a * (k * u).sin() * (k * v).sin();
            let pu = [1.0, 0.0, a * k * (k * u).cos() * (k * v).sin()];
            let pv = [0.0, 1.0, a * k * (k * u).sin() * (k * v).cos()];
            ([u, v, z], pu, pv)
        }
    }
}

/// Builds `surface` with about `triangles` triangles.
pub fn build(surface: Surface, triangles: usize) -> Case {
    if surface == Surface::Fan {
        return fan(triangles.max(3));
    }
    // Grid of nu x nv quads, two triangles each; aspect 2:1 for the closed surfaces.
    let quads = (triangles / 2).max(1) as f64;
    let (nu, nv) = match surface {
        Surface::WavyGrid => {
            let n = quads.sqrt().round().max(1.0) as usize;
            (n, ((quads / n as f64).round() as usize).max(1))
        }
        _ => {
            let nv = (quads / 2.0).sqrt().round().max(1.0) as usize;
            (((quads / nv as f64).round() as usize).max(1), nv)
        }
    };
    let mut c = Case {
        surface,
        positions: Vec::with_capacity((nu + 1) * (nv + 1)),
        normals: Vec::new(),
        uvs: Vec::new(),
        indices: Vec::with_capacity(nu * nv * 6),
        exact: Vec::new(),
        label: surface.name().into(),
    };
    for j in 0..=nv {
        for i in 0..=nu {
            let (u, v) = (i as f32 / nu as f32, j as f32 / nv as f32);
            let (p, pu, pv) = eval(surface, u, v);
            let n = norm(cross(pu, pv));
            let t = norm([pu[0] - dot(pu, n) * n[0], pu[1] - dot(pu, n) * n[1], pu[2] - dot(pu, n) * n[2]]);
            c.positions.push(p);
            c.normals.push(n);
            c.uvs.push([u, v]);
            c.exact.push(t);
        }
    }
    let id = |i: usize, j: usize| (j * (nu + 1) + i) as u32;
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, cc, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            c.indices.extend([a, b, cc, a, cc, d]);
        }
    }
    c
}

/// `n` triangles around one centre vertex on the unit disk, planar UVs: one vertex of valence
/// `n`, exact tangent `+x` everywhere.
fn fan(n: usize) -> Case {
    let mut c = Case {
        surface: Surface::Fan,
        positions: vec![[0.0, 0.0, 0.0]],
        normals: vec![[0.0, 0.0, 1.0]],
        uvs: vec![[0.5, 0.5]],
        indices: Vec::with_capacity(3 * n),
        exact: vec![[1.0, 0.0, 0.0]],
        label: "fan".into(),
    };
    for i in 0..n {
        let a = i as f32 / n as f32 * TAU;
        let p = [a.cos(), a.sin(), 0.0];
        c.positions.push(p);
        c.normals.push([0.0, 0.0, 1.0]);
        c.uvs.push([0.5 + 0.5 * p[0], 0.5 + 0.5 * p[1]]);
        c.exact.push([1.0, 0.0, 0.0]);
    }
    for i in 0..n as u32 {
        c.indices.extend([0, 1 + i, 1 + (i + 1) % n as u32]);
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn surfaces_have_about_the_asked_size_and_exact_frames_are_unit() {
        for s in [Surface::Sphere, Surface::Torus, Surface::WavyGrid] {
            let c = build(s, 10_000);
            let t = c.triangles();
            assert!((9_000..=11_000).contains(&t), "{s:?}: {t}");
            for (e, n) in c.exact.iter().zip(&c.normals) {
                assert!((dot(*e, *e) - 1.0).abs() < 1e-4 && dot(*e, *n).abs() < 1e-4);
            }
        }
        assert_eq!(build(Surface::Fan, 200).triangles(), 200);
    }
}
