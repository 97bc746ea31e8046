use crate::tangent::mikk::{generate as gen, Engine};
use crate::tangent::TriMesh;

/// Positions, normals, UVs and indices.
type Mesh = (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<[f32; 2]>, Vec<u32>);

fn cube() -> Mesh {
    let mut p = Vec::new();
    let mut n = Vec::new();
    let mut uv = Vec::new();
    let mut idx = Vec::new();
    let faces: [([f32; 3], [f32; 3], [f32; 3]); 6] = [
        ([1., 0., 0.], [0., 1., 0.], [0., 0., 1.]),
        ([-1., 0., 0.], [0., 0., 1.], [0., 1., 0.]),
        ([0., 1., 0.], [0., 0., 1.], [1., 0., 0.]),
        ([0., -1., 0.], [1., 0., 0.], [0., 0., 1.]),
        ([0., 0., 1.], [1., 0., 0.], [0., 1., 0.]),
        ([0., 0., -1.], [0., 1., 0.], [1., 0., 0.]),
    ];
    for (nn, a, b) in faces {
        let base = p.len() as u32;
        for (u, v) in [(0., 0.), (1., 0.), (1., 1.), (0., 1.)] {
            let s = |x: f32| x * 2.0 - 1.0;
            p.push([
                nn[0] + s(u) * a[0] + s(v) * b[0],
                nn[1] + s(u) * a[1] + s(v) * b[1],
                nn[2] + s(u) * a[2] + s(v) * b[2],
            ]);
            n.push(nn);
            uv.push([u, v]);
        }
        idx.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    (p, n, uv, idx)
}

fn same(a: &[Option<[f32; 4]>], b: &[Option<[f32; 4]>]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(x, y)| match (x, y) {
            (Some(x), Some(y)) => x.iter().zip(y).all(|(p, q)| p.to_bits() == q.to_bits()),
            (None, None) => true,
            _ => false,
        })
}

#[test]
fn cube_matches_reference() {
    let (p, n, uv, idx) = cube();
    let m = TriMesh { positions: &p, normals: &n, uvs: &uv, indices: &idx };
    let a = gen(&m, Engine::Fast);
    let b = gen(&m, Engine::Bevy);
    assert!(same(&a, &b), "{a:?}\n{b:?}");
}

#[test]
fn invalid_and_empty_inputs_do_not_panic() {
    let p = [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let n = [[0.0f32, 0.0, 1.0]; 3];
    let uv = [[0.0f32, 0.0], [1.0, 0.0], [0.0, 1.0]];
    let bad = [0u32, 1, 7];
    let m = TriMesh { positions: &p, normals: &n, uvs: &uv, indices: &bad };
    assert_eq!(gen(&m, Engine::Fast), vec![None; 3]);
    let empty = TriMesh { positions: &p, normals: &n, uvs: &uv, indices: &[] };
    assert!(gen(&empty, Engine::Fast).is_empty());
    // A trailing partial triangle gets no frame, as with the reference wrapper.
    let partial = [0u32, 1, 2, 0];
    let m = TriMesh { positions: &p, normals: &n, uvs: &uv, indices: &partial };
    let a = gen(&m, Engine::Fast);
    assert!(same(&a, &gen(&m, Engine::Bevy)));
    assert_eq!(a[3], None);
    // Non-finite everything: no panic, and the reference's answer.
    let pw = [[f32::NAN, f32::INFINITY, 0.0], [f32::NEG_INFINITY, 0.0, f32::NAN], [3e38, -3e38, 1e-40]];
    let nw = [[f32::NAN; 3], [f32::INFINITY, 0.0, 0.0], [0.0; 3]];
    let uw = [[f32::NAN, 0.0], [f32::INFINITY, 1.0], [1e-40, -0.0]];
    let idx = [0u32, 1, 2, 2, 1, 0, 0, 0, 1];
    let m = TriMesh { positions: &pw, normals: &nw, uvs: &uw, indices: &idx };
    let a = gen(&m, Engine::Fast);
    let b = gen(&m, Engine::Bevy);
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        match (x, y) {
            (Some(x), Some(y)) => {
                assert!(x.iter().zip(y).all(|(p, q)| p.to_bits() == q.to_bits() || (p.is_nan() && q.is_nan())))
            }
            (None, None) => {}
            _ => panic!("{x:?} vs {y:?}"),
        }
    }
}

/// The welded classes of a weld result: `k ~ j` iff they share a representative.
fn classes(w: &[u32]) -> Vec<usize> {
    let mut first = std::collections::HashMap::new();
    w.iter().enumerate().map(|(k, &r)| *first.entry(r).or_insert(k)).collect()
}

/// A grid of `n x n` quads with duplicated seam vertices (equal values, other indices), so that
/// welding merges corners of different vertex indices.
fn seamed_grid(n: usize) -> Mesh {
    let (mut p, mut nr, mut uv, mut idx) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for j in 0..=n {
        for i in 0..=n {
            let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
            p.push([u, v, (3.0 * u).sin() * 0.1]);
            nr.push([0.0, 0.0, 1.0]);
            uv.push([u, v]);
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    for j in 0..n {
        for i in 0..n {
            // The right half's quads use copies of their left column's vertices.
            let left = if i == n / 2 {
                let copy = |v: u32, p: &mut Vec<[f32; 3]>, nr: &mut Vec<[f32; 3]>, uv: &mut Vec<[f32; 2]>| {
                    p.push(p[v as usize]);
                    nr.push(nr[v as usize]);
                    uv.push(uv[v as usize]);
                    (p.len() - 1) as u32
                };
                (copy(id(i, j), &mut p, &mut nr, &mut uv), copy(id(i, j + 1), &mut p, &mut nr, &mut uv))
            } else {
                (id(i, j), id(i, j + 1))
            };
            idx.extend([left.0, id(i + 1, j), id(i + 1, j + 1), left.0, id(i + 1, j + 1), left.1]);
        }
    }
    (p, nr, uv, idx)
}

#[test]
fn the_weld_shortcut_finds_the_replayed_classes_and_is_taken_on_plain_meshes() {
    let (p, n, uv, idx) = seamed_grid(24);
    let m = TriMesh { positions: &p, normals: &n, uvs: &uv, indices: &idx };
    let c = super::Corners { mesh: &m };
    let tri = super::triangles::Triangles::build(&c);
    let of_vertex = super::shortcut::weld(&c, &tri.order, tri.n_good).expect("a plain grid takes the shortcut");
    // Per vertex, read through the index buffer as the engine does.
    let w = super::ByVertex { of_vertex, idx: &idx, order: &tri.order };
    let short: Vec<u32> = (0..idx.len()).map(|k| super::Welded::at(&w, k)).collect();
    let replayed = super::weld::weld(&c, &tri.order);
    assert_eq!(classes(&short), classes(&replayed));
    // Seam copies weld with the originals: fewer classes than vertex indices in use.
    let distinct: std::collections::HashSet<u32> = replayed.iter().copied().collect();
    assert_eq!(distinct.len(), 25 * 25);
    assert!(same(&gen(&m, Engine::Fast), &gen(&m, Engine::Bevy)));
}

#[test]
fn the_weld_shortcut_refuses_signed_zeros_nan_and_huge_coordinates() {
    let (p0, n0, uv0, idx) = seamed_grid(6);
    let refuses = |p: &[[f32; 3]], n: &[[f32; 3]], uv: &[[f32; 2]]| {
        let m = TriMesh { positions: p, normals: n, uvs: uv, indices: &idx };
        let c = super::Corners { mesh: &m };
        let tri = super::triangles::Triangles::build(&c);
        let refused = super::shortcut::weld(&c, &tri.order, tri.n_good).is_none();
        // Whatever route it takes, the output is the reference's.
        assert!(same(&gen(&m, Engine::Fast), &gen(&m, Engine::Bevy)));
        refused
    };
    assert!(!refuses(&p0, &n0, &uv0));
    // A seam copy whose normal has -0.0 where the original has +0.0: equal values, other bits.
    let mut n = n0.clone();
    let copy = n0.len() - 1;
    n[copy][0] = -0.0;
    assert!(refuses(&p0, &n, &uv0));
    let mut uv = uv0.clone();
    uv[3][1] = f32::NAN;
    assert!(refuses(&p0, &n0, &uv));
    let mut p = p0.clone();
    p[0][2] = 1e38;
    assert!(refuses(&p, &n0, &uv0));
}
