use crate::tangent::mikk::{generate as gen, Engine};
use crate::tangent::TriMesh;

fn cube() -> (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<[f32; 2]>, Vec<u32>) {
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
            (Some(x), Some(y)) => assert!(x.iter().zip(y).all(|(p, q)| p.to_bits() == q.to_bits() || (p.is_nan() && q.is_nan()))),
            (None, None) => {}
            _ => panic!("{x:?} vs {y:?}"),
        }
    }
}
