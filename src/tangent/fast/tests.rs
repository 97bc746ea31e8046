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
