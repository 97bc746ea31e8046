//! A displaced torus whose true normal is known in closed form, tessellated as HIGH (fine, exact
//! vertex normals) and LOW (coarse, with a UV layout, seams included), and the error of a map
//! baked onto LOW measured the way a renderer sees it: the map decoded through the frames written
//! into the output, against the normal of the surface where LOW's ray meets it (found by root
//! finding on the closed form, not by the baker's ray caster). `bumpbake bench transfer` and the
//! tests share it.

use crate::error::{Error, Result};
use crate::scene::ReadOptions;
use glam::DVec3;
use std::f64::consts::TAU;
use std::path::Path;

/// A torus of radii `major` and `minor`, its tube pushed out along its normal by
/// `h(θ, φ) = amp·(sin(8θ)·sin(4φ) + 0.5·cos(3θ + 6φ))`.
#[derive(Debug, Clone, Copy)]
pub struct Torus {
    pub major: f64,
    pub minor: f64,
    pub amp: f64,
}

impl Default for Torus {
    fn default() -> Self {
        Torus { major: 1.0, minor: 0.35, amp: 0.02 }
    }
}

/// An indexed triangle mesh with per-vertex normals and, optionally, UVs (glTF, v down).
#[derive(Debug, Clone, Default)]
pub struct Mesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    pub indices: Vec<u32>,
}

impl Torus {
    fn h(&self, th: f64, ph: f64) -> (f64, f64, f64) {
        let a = self.amp;
        let h = a * ((8.0 * th).sin() * (4.0 * ph).sin() + 0.5 * (3.0 * th + 6.0 * ph).cos());
        let h_th = a * (8.0 * (8.0 * th).cos() * (4.0 * ph).sin() - 1.5 * (3.0 * th + 6.0 * ph).sin());
        let h_ph = a * (4.0 * (8.0 * th).sin() * (4.0 * ph).cos() - 3.0 * (3.0 * th + 6.0 * ph).sin());
        (h, h_th, h_ph)
    }

    fn n0(th: f64, ph: f64) -> DVec3 {
        DVec3::new(ph.cos() * th.cos(), ph.cos() * th.sin(), ph.sin())
    }

    /// The displaced surface's point and exact unit normal at `(θ, φ)`.
    pub fn point_normal(&self, th: f64, ph: f64) -> (DVec3, DVec3) {
        let (h, h_th, h_ph) = self.h(th, ph);
        let n0 = Self::n0(th, ph);
        let c = DVec3::new(th.cos(), th.sin(), 0.0) * self.major;
        let p = c + n0 * (self.minor + h);
        let dc = DVec3::new(-th.sin(), th.cos(), 0.0) * self.major;
        let dn_th = DVec3::new(-th.sin(), th.cos(), 0.0) * ph.cos();
        let dn_ph = DVec3::new(-ph.sin() * th.cos(), -ph.sin() * th.sin(), ph.cos());
        let r_th = dc + n0 * h_th + dn_th * (self.minor + h);
        let r_ph = n0 * h_ph + dn_ph * (self.minor + h);
        let mut n = r_th.cross(r_ph).normalize();
        if n.dot(n0) < 0.0 {
            n = -n;
        }
        (p, n)
    }

    /// `(θ, φ)` of a point near the tube, and how far it is outside the displaced surface.
    fn locate(&self, x: DVec3) -> (f64, f64, f64) {
        let th = x.y.atan2(x.x);
        let rho = (x.x * x.x + x.y * x.y).sqrt() - self.major;
        let ph = x.z.atan2(rho);
        let d = (rho * rho + x.z * x.z).sqrt();
        (th, ph, d - self.minor - self.h(th, ph).0)
    }

    /// The true normal where the ray `p + s·dir` meets the displaced surface, `|s| <= reach`.
    pub fn truth(&self, p: DVec3, dir: DVec3, reach: f64) -> Option<DVec3> {
        let g = |s: f64| self.locate(p + dir * s).2;
        // Secant steps from LOW's surface; the surface is within a few amplitudes of it.
        let (mut s0, mut s1) = (0.0, 1e-3);
        let (mut g0, mut g1) = (g(s0), g(s1));
        for _ in 0..30 {
            if g1 == g0 {
                break;
            }
            let s2 = s1 - g1 * (s1 - s0) / (g1 - g0);
            (s0, g0) = (s1, g1);
            s1 = s2;
            g1 = g(s1);
            if g1.abs() < 1e-12 {
                break;
            }
        }
        if !(g1.abs() < 1e-7 && s1.abs() <= reach) {
            return None;
        }
        let (th, ph, _) = self.locate(p + dir * s1);
        Some(self.point_normal(th, ph).1)
    }

    /// HIGH: `n_th x n_ph` quads of the displaced torus (two triangles each), exact normals.
    pub fn high(&self, n_th: usize, n_ph: usize) -> Mesh {
        let mut m = Mesh::default();
        for j in 0..n_ph {
            for i in 0..n_th {
                let (p, n) = self.point_normal(TAU * i as f64 / n_th as f64, TAU * j as f64 / n_ph as f64);
                m.positions.push(p.as_vec3().to_array());
                m.normals.push(n.as_vec3().to_array());
            }
        }
        for j in 0..n_ph {
            for i in 0..n_th {
                let v = |i: usize, j: usize| ((j % n_ph) * n_th + (i % n_th)) as u32;
                let (a, b, c, d) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
                m.indices.extend([a, b, c, a, c, d]);
            }
        }
        m
    }

    /// LOW: the plain torus, `n_th x n_ph` quads, UVs over the whole square (seams at the edges).
    pub fn low(&self, n_th: usize, n_ph: usize) -> Mesh {
        let mut m = Mesh::default();
        for j in 0..=n_ph {
            for i in 0..=n_th {
                let (th, ph) = (TAU * i as f64 / n_th as f64, TAU * j as f64 / n_ph as f64);
                let n0 = Self::n0(th, ph);
                let p = DVec3::new(th.cos(), th.sin(), 0.0) * self.major + n0 * self.minor;
                m.positions.push(p.as_vec3().to_array());
                m.normals.push(n0.as_vec3().to_array());
                m.uvs.push([i as f32 / n_th as f32, 1.0 - j as f32 / n_ph as f32]);
            }
        }
        let w = n_th + 1;
        for j in 0..n_ph {
            for i in 0..n_th {
                let a = (j * w + i) as u32;
                let (b, c, d) = (a + 1, a + 1 + w as u32, a + w as u32);
                m.indices.extend([a, b, c, a, c, d]);
            }
        }
        m
    }
}

impl Mesh {
    /// A GLB with this mesh (one primitive; a material when it has UVs, so `bake` maps it).
    pub fn glb(&self) -> Vec<u8> {
        let mut bin: Vec<u8> = Vec::new();
        let mut views = Vec::new();
        let mut accessors = Vec::new();
        let mut push = |bytes: &[u8],
                        count: usize,
                        ty: &str,
                        ct: u32,
                        target: u32,
                        minmax: Option<([f32; 3], [f32; 3])>| {
            while !bin.len().is_multiple_of(4) {
                bin.push(0);
            }
            views.push(serde_json::json!({ "buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len(), "target": target }));
            bin.extend_from_slice(bytes);
            let mut a =
                serde_json::json!({ "bufferView": views.len() - 1, "componentType": ct, "count": count, "type": ty });
            if let Some((lo, hi)) = minmax {
                crate::scene::set_key(&mut a, "min", serde_json::json!(lo));
                crate::scene::set_key(&mut a, "max", serde_json::json!(hi));
            }
            accessors.push(a);
            accessors.len() - 1
        };
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for p in &self.positions {
            for c in 0..3 {
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
            }
        }
        let pos =
            push(bytemuck::cast_slice(&self.positions), self.positions.len(), "VEC3", 5126, 34962, Some((lo, hi)));
        let nrm = push(bytemuck::cast_slice(&self.normals), self.normals.len(), "VEC3", 5126, 34962, None);
        let mut attrs = serde_json::json!({ "POSITION": pos, "NORMAL": nrm });
        if !self.uvs.is_empty() {
            let uv = push(bytemuck::cast_slice(&self.uvs), self.uvs.len(), "VEC2", 5126, 34962, None);
            crate::scene::set_key(&mut attrs, "TEXCOORD_0", serde_json::json!(uv));
        }
        let idx = push(bytemuck::cast_slice(&self.indices), self.indices.len(), "SCALAR", 5125, 34963, None);
        let mut prim = serde_json::json!({ "attributes": attrs, "indices": idx });
        let mut json = serde_json::json!({
            "asset": { "version": "2.0", "generator": "bumpbake bench" },
            "scene": 0, "scenes": [{ "nodes": [0] }], "nodes": [{ "mesh": 0 }],
        });
        if !self.uvs.is_empty() {
            crate::scene::material::give_plain_material(&mut json, &mut prim, "low");
        }
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        for (key, v) in [
            ("meshes", serde_json::json!([{ "primitives": [prim] }])),
            ("bufferViews", serde_json::json!(views)),
            ("accessors", serde_json::json!(accessors)),
            ("buffers", serde_json::json!([{ "byteLength": bin.len() }])),
        ] {
            crate::scene::set_key(&mut json, key, v);
        }
        let mut j = serde_json::to_vec(&json).expect("serialises");
        while !j.len().is_multiple_of(4) {
            j.push(b' ');
        }
        let mut out = Vec::with_capacity(28 + j.len() + bin.len());
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&((28 + j.len() + bin.len()) as u32).to_le_bytes());
        out.extend_from_slice(&(j.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&j);
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
        out
    }
}

/// Angles between decoded and true normals, in degrees.
#[derive(Debug, Clone, Copy, Default, serde::Serialize, PartialEq)]
pub struct AngleError {
    pub texels: usize,
    pub mean: f64,
    pub p99: f64,
    pub max: f64,
}

impl AngleError {
    fn of(mut a: Vec<f64>) -> AngleError {
        if a.is_empty() {
            return AngleError::default();
        }
        a.sort_by(f64::total_cmp);
        let n = a.len();
        AngleError {
            texels: n,
            mean: a.iter().sum::<f64>() / n as f64,
            p99: a[(n * 99 / 100).min(n - 1)],
            max: a[n - 1],
        }
    }
}

/// How a baked OUT renders against the truth.
#[derive(Debug, Clone, Copy, Default, serde::Serialize, PartialEq)]
pub struct Evaluation {
    /// Decoded as the conventions say: per-pixel interpolated, unnormalised N and T.
    pub synced: AngleError,
    /// Decoded by a renderer that normalises T, B and N per pixel and interpolates a per-vertex
    /// bitangent (as the glTF sample viewer does): what a renderer off the convention sees.
    pub normalised_frame: AngleError,
    /// Texels whose centre lies inside a LOW triangle but whose ray meets no surface.
    pub no_truth: usize,
}

/// Decodes the normal map of `out` (material 0's normal texture, mesh 0) through the frames in
/// it, at every texel whose centre a UV triangle holds, and compares with `truth(p, dir)`: the
/// true normal where the ray from LOW's point along its interpolated normal meets the surface.
/// `keep(p)` selects the texels measured by their LOW position.
pub fn evaluate(
    out: &Path,
    truth: &(dyn Fn(DVec3, DVec3) -> Option<DVec3> + Sync),
    keep: &(dyn Fn(DVec3) -> bool + Sync),
) -> Result<Evaluation> {
    let scene = crate::format::read(out, &ReadOptions::default())?;
    let r = crate::scene::PrimRef { mesh: 0, primitive: 0 };
    let p = scene.primitive(r)?;
    let get = |n: &str| p.attr(n).ok_or_else(|| scene.err(format!("no {n}")));
    let pos: Vec<[f32; 3]> = get("POSITION")?.to_f32();
    let nrm: Vec<[f32; 3]> = get("NORMAL")?.to_f32();
    let tan: Vec<[f32; 4]> = get("TANGENT")?.to_f32();
    let uv: Vec<[f32; 2]> = get("TEXCOORD_0")?.to_f32();
    let mats = scene.materials();
    let normal = mats.get(0).and_then(|m| m.texture(crate::scene::Slot::Normal));
    let img = normal.and_then(|t| t.image()).ok_or_else(|| scene.err("no normal texture"))?;
    let bytes = scene.image_bytes(img)?;
    let map = image::load_from_memory(&bytes).map_err(|e| Error::input(out, e.to_string()))?;
    let (w, h) = (map.width() as usize, map.height() as usize);
    let sixteen = matches!(map.color(), image::ColorType::Rgb16 | image::ColorType::Rgba16);
    let texel: Vec<[f64; 3]> = if sixteen {
        map.to_rgb16().pixels().map(|q| q.0.map(|c| c as f64 / 65535.0 * 2.0 - 1.0)).collect()
    } else {
        map.to_rgb8().pixels().map(|q| q.0.map(|c| c as f64 / 255.0 * 2.0 - 1.0)).collect()
    };
    let v3 = |a: [f32; 3]| DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
    let tris: Vec<[usize; 3]> =
        p.indices.chunks_exact(3).map(|t| [t[0] as usize, t[1] as usize, t[2] as usize]).collect();
    use rayon::prelude::*;
    let per_tri: Vec<(Vec<f64>, Vec<f64>, usize)> = tris
        .par_iter()
        .map(|t| {
            let (mut a, mut b, mut miss) = (Vec::new(), Vec::new(), 0);
            let q = t.map(|i| (uv[i][0] as f64 * w as f64, uv[i][1] as f64 * h as f64));
            let area = (q[1].0 - q[0].0) * (q[2].1 - q[0].1) - (q[1].1 - q[0].1) * (q[2].0 - q[0].0);
            if area.abs() < 1e-12 {
                return (a, b, miss);
            }
            let x0 = q.iter().map(|c| c.0).fold(f64::INFINITY, f64::min).floor().max(0.0) as usize;
            let x1 = (q.iter().map(|c| c.0).fold(f64::NEG_INFINITY, f64::max).ceil() as usize).min(w);
            let y0 = q.iter().map(|c| c.1).fold(f64::INFINITY, f64::min).floor().max(0.0) as usize;
            let y1 = (q.iter().map(|c| c.1).fold(f64::NEG_INFINITY, f64::max).ceil() as usize).min(h);
            for y in y0..y1 {
                for x in x0..x1 {
                    let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                    let e = |i: usize, j: usize| (q[j].0 - q[i].0) * (py - q[i].1) - (q[j].1 - q[i].1) * (px - q[i].0);
                    let bc = [e(1, 2) / area, e(2, 0) / area, e(0, 1) / area];
                    // Strictly inside: each texel is measured once, through one triangle.
                    if bc.iter().any(|&v| v <= 0.0) {
                        continue;
                    }
                    let mix3 = |f: &dyn Fn(usize) -> DVec3| f(t[0]) * bc[0] + f(t[1]) * bc[1] + f(t[2]) * bc[2];
                    let pp = mix3(&|i| v3(pos[i]));
                    if !keep(pp) {
                        continue;
                    }
                    let nn = mix3(&|i| v3(nrm[i]));
                    let tt = mix3(&|i| v3([tan[i][0], tan[i][1], tan[i][2]]));
                    let wsum: f64 = (0..3).map(|k| tan[t[k]][3] as f64 * bc[k]).sum();
                    let sign = if wsum < 0.0 { -1.0 } else { 1.0 };
                    let Some(truth) = truth(pp, nn.normalize()) else {
                        miss += 1;
                        continue;
                    };
                    let c = texel[y * w + x];
                    let bb = nn.cross(tt) * sign;
                    let synced = (tt * c[0] + bb * c[1] + nn * c[2]).normalize();
                    let bv = mix3(&|i| v3(nrm[i]).cross(v3([tan[i][0], tan[i][1], tan[i][2]])) * tan[i][3] as f64);
                    let normed = (tt.normalize() * c[0] + bv.normalize() * c[1] + nn.normalize() * c[2]).normalize();
                    let ang = |v: DVec3| v.cross(truth).length().atan2(v.dot(truth)).to_degrees();
                    a.push(ang(synced));
                    b.push(ang(normed));
                }
            }
            (a, b, miss)
        })
        .collect();
    let (mut a, mut b, mut miss) = (Vec::new(), Vec::new(), 0);
    for (x, y, m) in per_tri {
        a.extend(x);
        b.extend(y);
        miss += m;
    }
    Ok(Evaluation { synced: AngleError::of(a), normalised_frame: AngleError::of(b), no_truth: miss })
}
