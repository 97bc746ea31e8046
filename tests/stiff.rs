//! Stiff and extreme meshes, generated in code. Each case states what must come out; all of them
//! share the contract of `docs/conventions.md`: exit 0, every tangent finite, unit, orthogonal to
//! its (finite, unit) normal with `w = +-1`, substitutions counted, positions unchanged, and an
//! output the Khronos validator accepts (everything is written under `validated_dir`).

mod common;
use common::*;
use serde_json::{json, Value};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// A triangle mesh to put into a glTF: positions, optional normals, UVs (v down, as glTF
/// stores them), indices.
#[derive(Clone, Default)]
struct Mesh {
    pos: Vec<[f32; 3]>,
    nrm: Option<Vec<[f32; 3]>>,
    uv: Vec<[f32; 2]>,
    idx: Vec<u16>,
}

impl Mesh {
    /// `n x n` quads spanning `size` in XY at `origin`, UV = `uv0 + (i, j) / n * uv_size`.
    fn grid(n: usize, origin: [f32; 3], size: f32, uv0: [f32; 2], uv_size: f32) -> Mesh {
        let (p, nrm, uv, idx) = grid(n);
        Mesh {
            pos: p.iter().map(|q| [origin[0] + q[0] * size, origin[1] + q[1] * size, origin[2]]).collect(),
            nrm: Some(nrm),
            uv: uv.iter().map(|t| [uv0[0] + t[0] * uv_size, uv0[1] + t[1] * uv_size]).collect(),
            idx,
        }
    }

    fn tri(&mut self, p: [[f32; 3]; 3], uv: [[f32; 2]; 3]) {
        let b = self.pos.len() as u16;
        self.pos.extend(p);
        self.uv.extend(uv);
        if let Some(n) = &mut self.nrm {
            n.extend([[0.0, 0.0, 1.0]; 3]);
        }
        self.idx.extend([b, b + 1, b + 2]);
    }

    /// Adds this mesh to `g` with a normal-mapped material.
    fn add_to(&self, g: &mut Gltf) -> usize {
        let p = g.floats(&self.pos, Some(34962));
        let t = g.floats(&self.uv, Some(34962));
        let i = g.indices(&self.idx);
        let mut attrs = json!({ "POSITION": p, "TEXCOORD_0": t });
        if let Some(n) = &self.nrm {
            attrs["NORMAL"] = json!(g.floats(n, Some(34962)));
        }
        let tex = g.texture();
        let m = g.material(json!({ "normalTexture": { "index": tex } }));
        g.mesh(json!({ "attributes": attrs, "indices": i, "material": m }))
    }
}

struct Outcome {
    report: Value,
    tangents: Vec<[f32; 4]>,
    normals: Vec<[f32; 3]>,
    positions: Vec<[f32; 3]>,
}

/// Writes `mesh` as a GLB, runs `tangents` on it (within `limit`), checks the common contract
/// and returns the per-corner output.
fn bake(name: &str, mesh: &Mesh, limit: Duration) -> Outcome {
    let d = scratch_dir(&format!("stiff_in_{name}"));
    let v = validated_dir(&format!("stiff_{name}"));
    let mut g = Gltf::new();
    mesh.add_to(&mut g);
    let input = d.join(format!("{name}.glb"));
    g.write_glb(&input);
    let out = v.join(format!("{name}.glb"));
    let t0 = Instant::now();
    let o = run(&["tangents", s(&input), "-o", s(&out), "--json"]);
    let took = t0.elapsed();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{name}: exit {:?}: {err}", o.status.code());
    assert!(!err.contains("panicked"), "{err}");
    assert!(took < limit, "{name}: took {took:?}");
    let report: Value = serde_json::from_slice(&o.stdout).unwrap();
    let scene = load(&out);
    let tangents = corner_attr::<4>(&scene, P0, "TANGENT");
    let normals = corner_attr::<3>(&scene, P0, "NORMAL");
    let positions = corner_attr::<3>(&scene, P0, "POSITION");
    assert_eq!(tangents.len(), mesh.idx.len(), "{name}: every corner survives");
    for c in 0..tangents.len() {
        assert_valid_frame(tangents[c], normals[c], &format!("{name} corner {c}"));
        assert_eq!(positions[c], mesh.pos[mesh.idx[c] as usize], "{name} corner {c}: position unchanged");
    }
    let stats = &report["primitives"][0]["stats"];
    let fb = &stats["fallback"];
    assert_eq!(
        report["fallback_frames"].as_u64().unwrap(),
        fb["undefined"].as_u64().unwrap() + fb["invalid"].as_u64().unwrap(),
        "{name}: the total is the sum of its reasons"
    );
    Outcome { report, tangents, normals, positions }
}

fn fallbacks(o: &Outcome) -> (u64, u64) {
    let fb = &o.report["primitives"][0]["stats"]["fallback"];
    (fb["undefined"].as_u64().unwrap(), fb["invalid"].as_u64().unwrap())
}

fn xyz(t: [f32; 4]) -> glam::Vec3 {
    glam::Vec3::new(t[0], t[1], t[2])
}

const QUICK: Duration = Duration::from_secs(20);

#[test]
fn zero_area_and_sliver_triangles() {
    let mut m = Mesh { nrm: Some(vec![]), ..Default::default() };
    // A sliver: 1e-6 high over a unit base, with proper UV area: MikkTSpace has an answer.
    m.tri([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1e-6, 0.0]], [[0.0, 1.0], [1.0, 1.0], [0.5, 0.0]]);
    // Zero area: three equal positions; and three collinear ones.
    m.tri([[2.0, 0.0, 0.0]; 3], [[0.0, 1.0], [1.0, 1.0], [0.0, 0.0]]);
    m.tri([[3.0, 0.0, 0.0], [4.0, 0.0, 0.0], [5.0, 0.0, 0.0]], [[0.0, 1.0], [1.0, 1.0], [0.0, 0.0]]);
    let o = bake("sliver", &m, QUICK);
    assert!(xyz(o.tangents[0]).dot(glam::Vec3::X) > 0.999, "the sliver keeps its frame: {:?}", o.tangents[0]);
    let (undef, invalid) = fallbacks(&o);
    assert!(undef + invalid >= 6, "zero-area corners are substituted and counted: {}", o.report);
}

#[test]
fn zero_and_collinear_uv_area_and_repeated_indices() {
    let mut m = Mesh::grid(1, [0.0; 3], 1.0, [0.0, 0.0], 1.0);
    m.tri([[2.0, 0.0, 0.0], [3.0, 0.0, 0.0], [2.0, 1.0, 0.0]], [[0.5, 0.5]; 3]); // zero UV area
    m.tri([[4.0, 0.0, 0.0], [5.0, 0.0, 0.0], [4.0, 1.0, 0.0]], [[0.0, 0.0], [0.5, 0.5], [1.0, 1.0]]); // collinear UVs
    m.idx.extend([0, 0, 1, 2, 2, 2]); // repeated indices, sharing vertices with the good quad
    let o = bake("uv_area", &m, QUICK);
    let (undef, invalid) = fallbacks(&o);
    assert!(undef + invalid > 0, "{}", o.report);
    // The good quad keeps the exact frame (+X, glTF w convention).
    for c in 0..6 {
        assert_eq!(o.tangents[c], [1.0, 0.0, 0.0, 1.0], "corner {c}");
    }
    // Repeated-index corners at vertex 0 borrow its frame.
    assert_eq!(o.tangents[o.tangents.len() - 6], [1.0, 0.0, 0.0, 1.0]);
}

#[test]
fn twenty_thousand_triangles_on_one_vertex() {
    let n = 20_000usize;
    let mut m = Mesh { nrm: Some(vec![[0.0, 0.0, 1.0]; n + 1]), ..Default::default() };
    m.pos.push([0.0, 0.0, 0.0]);
    m.uv.push([0.5, 0.5]);
    for k in 0..n {
        let a = k as f32 / n as f32 * std::f32::consts::TAU;
        m.pos.push([a.cos(), a.sin(), 0.0]);
        m.uv.push([0.5 + 0.5 * a.cos(), 0.5 - 0.5 * a.sin()]);
    }
    for k in 0..n as u16 {
        m.idx.extend([0, 1 + k, 1 + (k + 1) % n as u16]);
    }
    // MikkTSpace groups the corners around a vertex in O(valence^2): about 30 s of CPU here. Bounded,
    // and far from the abort (stack overflow) it was before; see docs/robustness.md.
    let o = bake("fan", &m, Duration::from_secs(400));
    for (c, t) in o.tangents.iter().enumerate() {
        assert!(xyz(*t).dot(glam::Vec3::X) > 0.999 && t[3] == 1.0, "corner {c}: {t:?}");
    }
    let st = &o.report["primitives"][0]["stats"];
    assert_eq!(st["vertices_out"], st["vertices_in"], "one consistent frame: no vertex is split");
}

#[test]
fn coordinates_near_1e6_with_1e_2_spacing_collapse_in_float32() {
    // float32 spacing at 1e6 is 0.0625: the 1e-2 grid collapses onto a few points.
    let m = Mesh::grid(8, [1.0e6, 1.0e6, 0.0], 0.08, [0.0, 0.0], 1.0);
    let o = bake("far", &m, QUICK);
    let (undef, invalid) = fallbacks(&o);
    assert!(undef + invalid > 0, "collapsed triangles are substituted and counted: {}", o.report);
}

#[test]
fn uvs_near_1e4() {
    let m = Mesh::grid(4, [0.0; 3], 1.0, [1.0e4, 1.0e4], 1.0);
    let o = bake("uv_far", &m, QUICK);
    assert_eq!(fallbacks(&o), (0, 0));
    for t in &o.tangents {
        assert!(xyz(*t).dot(glam::Vec3::X) > 0.9999 && t[3] == 1.0, "{t:?}");
    }
}

#[test]
fn microscopic_triangles() {
    let m = Mesh::grid(4, [0.0; 3], 1e-6, [0.0, 0.0], 1.0);
    let o = bake("micro", &m, QUICK);
    assert_eq!(fallbacks(&o), (0, 0), "a 1e-6 grid is an ordinary grid: {}", o.report);
    for t in &o.tangents {
        assert!(xyz(*t).dot(glam::Vec3::X) > 0.9999 && t[3] == 1.0, "{t:?}");
    }
    // Without NORMAL, the generated normals are right too, however small the triangles.
    let mut m = Mesh::grid(2, [0.0; 3], 1e-12, [0.0, 0.0], 1.0);
    m.nrm = None;
    let o = bake("micro_no_normal", &m, QUICK);
    for n in &o.normals {
        assert_eq!(*n, [0.0, 0.0, 1.0]);
    }
}

#[test]
fn mirrored_uv_seam() {
    // Two quads sharing an edge; the right one's u runs backwards (a mirror seam).
    let mut m = Mesh::grid(2, [0.0; 3], 2.0, [0.0, 0.0], 1.0);
    for (p, uv) in m.pos.iter().zip(m.uv.iter_mut()) {
        if p[0] > 1.0 {
            uv[0] = 2.0 - p[0] / 2.0 * 2.0; // 1 at the seam, back to 0 at the right
        } else {
            uv[0] = p[0] / 2.0 * 2.0;
        }
    }
    let o = bake("mirror", &m, QUICK);
    let ws: std::collections::BTreeSet<i32> = o.tangents.iter().map(|t| t[3] as i32).collect();
    assert_eq!(ws.len(), 2, "both handedness signs appear");
    let st = &o.report["primitives"][0]["stats"];
    assert!(st["vertices_out"].as_u64() > st["vertices_in"].as_u64(), "seam vertices are split: {st}");
    // On each side of the seam, the corners at one position agree in w within their side.
    for (c, t) in o.tangents.iter().enumerate() {
        let tri_x: f32 = (0..3).map(|k| o.positions[c / 3 * 3 + k][0]).sum::<f32>() / 3.0;
        assert_eq!(t[3], if tri_x > 1.0 { -1.0 } else { 1.0 }, "corner {c}");
    }
}

#[test]
fn poles_of_a_uv_sphere() {
    let (rings, segs) = (12usize, 24usize);
    let mut m = Mesh { nrm: Some(vec![]), ..Default::default() };
    for r in 0..=rings {
        let th = r as f32 / rings as f32 * std::f32::consts::PI;
        for k in 0..=segs {
            let ph = k as f32 / segs as f32 * std::f32::consts::TAU;
            let p = [th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin()];
            m.pos.push(p);
            m.nrm.as_mut().unwrap().push(p);
            m.uv.push([k as f32 / segs as f32, r as f32 / rings as f32]);
        }
    }
    let w = (segs + 1) as u16;
    for r in 0..rings as u16 {
        for k in 0..segs as u16 {
            let a = r * w + k;
            // Counter-clockwise seen from outside.
            m.idx.extend([a, a + 1, a + w + 1, a, a + w + 1, a + w]);
        }
    }
    // The triangles touching the north pole have no area; their corners still get frames.
    let o = bake("sphere", &m, QUICK);
    // Away from the poles, the tangent follows +u (around the sphere, longitudes).
    for c in 0..o.tangents.len() {
        let p = glam::Vec3::from(o.positions[c]);
        if p.y.abs() < 0.9 {
            let along = glam::Vec3::new(-p.z, 0.0, p.x).normalize();
            assert!(xyz(o.tangents[c]).dot(along).abs() > 0.9, "corner {c} at {p:?}: {:?}", o.tangents[c]);
        }
    }
}

#[test]
fn primitive_without_normal_with_degenerate_faces() {
    let mut m = Mesh::grid(2, [0.0; 3], 1.0, [0.0, 0.0], 1.0);
    m.nrm = None;
    m.tri([[5.0, 5.0, 5.0]; 3], [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    let o = bake("no_normal", &m, QUICK);
    assert_eq!(o.report["primitives"][0]["stats"]["generated_normals"], true);
    for c in 0..o.normals.len() {
        assert_eq!(o.normals[c], [0.0, 0.0, 1.0], "flat normal (or +Z where there is no face) at corner {c}");
    }
}

#[test]
fn non_manifold_edges() {
    // Four triangles on one edge (a fin), each in its own plane, UVs sharing the edge's UVs.
    let mut m = Mesh { nrm: Some(vec![]), ..Default::default() };
    m.pos.extend([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    m.uv.extend([[0.0, 1.0], [0.0, 0.0]]);
    m.nrm.as_mut().unwrap().extend([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]);
    for k in 0..4 {
        let a = k as f32 * std::f32::consts::FRAC_PI_2 + 0.3;
        m.pos.push([a.cos(), 0.5, a.sin()]);
        m.uv.push([1.0, 0.5]);
        let nrm = glam::Vec3::new(a.cos(), 0.5, a.sin()).cross(glam::Vec3::Y).normalize();
        m.nrm.as_mut().unwrap().push(nrm.to_array());
        m.idx.extend([0, 1, 2 + k as u16]);
    }
    // Give the shared vertices a normal of one of the fins so frames can be orthogonal to it.
    let n0 = m.nrm.as_ref().unwrap()[2];
    m.nrm.as_mut().unwrap()[0] = n0;
    m.nrm.as_mut().unwrap()[1] = n0;
    bake("fin", &m, QUICK);
}

/// Several of the cases above in one scene, as one primitive each: byte-identical output with one
/// thread and with the default pool, run after run.
#[test]
fn multi_primitive_scene_is_deterministic_across_thread_counts() {
    let d = scratch_dir("stiff_multi_in");
    let v = validated_dir("stiff_multi");
    let mut g = Gltf::new();
    Mesh::grid(8, [1.0e6, 1.0e6, 0.0], 0.08, [0.0, 0.0], 1.0).add_to(&mut g);
    Mesh::grid(16, [0.0; 3], 1e-6, [1e4, 1e4], 1.0).add_to(&mut g);
    let mut m = Mesh::grid(8, [0.0; 3], 1.0, [0.0, 0.0], 1.0);
    m.tri([[2.0, 0.0, 0.0]; 3], [[0.0, 1.0], [1.0, 1.0], [0.0, 0.0]]);
    m.add_to(&mut g);
    for k in 0..5 {
        let mut m = Mesh::grid(12, [k as f32, 0.0, 0.0], 1.0, [0.0, 0.0], 2.0);
        m.nrm = None;
        m.add_to(&mut g);
    }
    let input = d.join("multi.glb");
    g.write_glb(&input);
    let a = v.join("a.glb");
    let b = v.join("b.glb");
    let outputs: Vec<Vec<u8>> = [("1", &a), ("", &b), ("3", &a)]
        .iter()
        .map(|(threads, out): &(&str, &PathBuf)| {
            let mut c = bin();
            if !threads.is_empty() {
                c.env("RAYON_NUM_THREADS", threads);
            }
            let o = c.args(["tangents", s(&input), "-o", s(out), "-q"]).output().unwrap();
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            std::fs::read(out).unwrap()
        })
        .collect();
    assert_eq!(outputs[0], outputs[1], "1 thread vs default");
    assert_eq!(outputs[0], outputs[2], "1 thread vs 3");
    assert_eq!(load(&a).primitives().len(), 8);
}
