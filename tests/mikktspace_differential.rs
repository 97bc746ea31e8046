//! Differential test: `Engine::Fast` against `Engine::Bevy` (the reference), bit for bit.
//!
//! Meshes are built from a recipe (a kind and a list of random words) so that proptest can
//! shrink failures and the long soak (`cargo test --release --test mikktspace_differential --
//! --ignored`) can draw recipes from a plain RNG. Kinds:
//! 0. a triangle soup over a small vertex pool whose attributes come from small palettes:
//!    duplicate positions, split vertices (same position, other UV/normal), repeated indices
//!    (degenerate triangles), zero-area and mirrored UVs, exactly opposite tangents, `-0.0`;
//! 1. a grid patch with random per-vertex UV palettes and randomly duplicated vertex entries;
//! 2. a fan of 33-120 triangles around one vertex (groups past the all-pairs size, so the
//!    hashed antipode search and prefix sums run), with random UV rotations and flips;
//! 3. a soup as in 0 with NaN, infinities, huge and subnormal values mixed in;
//! 4. a closed strip whose last vertices are referenced by many edges (the legacy sort's
//!    unpaired tail).
//!
//! Comparison: both `None`, or both `Some` with identical bits in all four components (NaN
//! compares equal to NaN whatever its payload).

use bumpbake::tangent::mikk::{generate, Engine};
use bumpbake::tangent::TriMesh;
use proptest::prelude::*;

struct Words<'a> {
    w: &'a [u32],
    i: usize,
    salt: u32,
}

impl Words<'_> {
    fn next(&mut self) -> u32 {
        let v = self.w.get(self.i).copied().unwrap_or_else(|| {
            // Past the recipe: a fixed hash of the position keeps meshes deterministic.
            (self.i as u32 ^ self.salt).wrapping_mul(2654435761).rotate_left(13)
        });
        self.i += 1;
        v
    }
    fn below(&mut self, n: u32) -> u32 {
        self.next() % n.max(1)
    }
}

#[derive(Debug, Default, Clone)]
struct Mesh {
    p: Vec<[f32; 3]>,
    n: Vec<[f32; 3]>,
    uv: Vec<[f32; 2]>,
    idx: Vec<u32>,
}

impl Mesh {
    fn tri(&self) -> TriMesh<'_> {
        TriMesh { positions: &self.p, normals: &self.n, uvs: &self.uv, indices: &self.idx }
    }
}

const COORDS: [f32; 10] = [0.0, -0.0, 1.0, -1.0, 0.5, 2.0, 0.25, 3.0, -2.5, 1.5];
const UVS: [f32; 8] = [0.0, -0.0, 1.0, 0.5, -1.0, 2.0, 0.25, 0.75];
const WILD: [f32; 9] =
    [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 3.0e38, -3.0e38, 1.0e-40, -1.0e-42, 1.0e-20, f32::MIN_POSITIVE];

fn coord(r: &mut Words, wild: bool) -> f32 {
    let x = r.next();
    match x % 16 {
        0..=9 => COORDS[(x >> 4) as usize % COORDS.len()],
        15 if wild => WILD[(x >> 4) as usize % WILD.len()],
        _ => ((x >> 8) % 2001) as f32 * 0.0031 - 3.1,
    }
}

fn uvc(r: &mut Words, wild: bool) -> f32 {
    let x = r.next();
    match x % 16 {
        0..=10 => UVS[(x >> 4) as usize % UVS.len()],
        15 if wild => WILD[(x >> 4) as usize % WILD.len()],
        _ => ((x >> 8) % 1001) as f32 * 0.001,
    }
}

fn normal(r: &mut Words, wild: bool) -> [f32; 3] {
    let x = r.next();
    const S: f32 = std::f32::consts::FRAC_1_SQRT_2;
    let pal: [[f32; 3]; 10] = [
        [0.0, 0.0, 1.0],
        [0.0, 1.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 0.0, -1.0],
        [S, S, 0.0],
        [0.0, -S, S],
        [-0.0, 0.0, 1.0],
        [0.0, 0.0, 0.0],
        [0.3, 0.4, 0.5],
        [2.0, 0.0, 0.0],
    ];
    match x % 8 {
        0..=5 => pal[(x >> 3) as usize % pal.len()],
        7 if wild => [coord(r, true), coord(r, true), coord(r, true)],
        _ => {
            let v = [coord(r, false), coord(r, false), coord(r, false)];
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if l > 0.0 {
                v.map(|c| c / l)
            } else {
                [0.0, 0.0, 1.0]
            }
        }
    }
}

fn soup(r: &mut Words, wild: bool) -> Mesh {
    let mut m = Mesh::default();
    let nv = 1 + r.below(24) as usize;
    for _ in 0..nv {
        let dup = !m.p.is_empty() && r.below(4) == 0;
        if dup {
            // Same position as an earlier vertex; sometimes all attributes (a weldable copy),
            // sometimes a split vertex.
            let j = r.below(m.p.len() as u32) as usize;
            let p = m.p[j];
            let (n, uv) = match r.below(3) {
                0 => (m.n[j], m.uv[j]),
                1 => (m.n[j], [uvc(r, wild), uvc(r, wild)]),
                _ => (normal(r, wild), m.uv[j]),
            };
            m.p.push(p);
            m.n.push(n);
            m.uv.push(uv);
        } else {
            m.p.push([coord(r, wild), coord(r, wild), coord(r, wild)]);
            m.n.push(normal(r, wild));
            m.uv.push([uvc(r, wild), uvc(r, wild)]);
        }
    }
    let nt = 1 + r.below(48) as usize;
    for _ in 0..nt {
        if nv >= 3 && r.below(3) != 0 && !m.idx.is_empty() {
            // Share an edge with an earlier triangle (either winding) for real adjacency.
            let t = r.below((m.idx.len() / 3) as u32) as usize;
            let e = r.below(3) as usize;
            let (a, b) = (m.idx[3 * t + e], m.idx[3 * t + (e + 1) % 3]);
            let c = r.below(nv as u32);
            if r.below(4) == 0 {
                m.idx.extend([a, b, c]);
            } else {
                m.idx.extend([b, a, c]);
            }
        } else {
            for _ in 0..3 {
                m.idx.push(r.below(nv as u32));
            }
        }
    }
    m
}

fn grid(r: &mut Words) -> Mesh {
    let mut m = Mesh::default();
    let (w, h) = (2 + r.below(7) as usize, 2 + r.below(7) as usize);
    let mode = r.below(4);
    for y in 0..=h {
        for x in 0..=w {
            let (fx, fy) = (x as f32 / w as f32, y as f32 / h as f32);
            let z = match mode {
                0 => 0.0,
                1 => (fx * 3.0).sin() * 0.3,
                _ => ((r.below(5) as f32) - 2.0) * 0.1,
            };
            m.p.push([fx, fy, z]);
            m.n.push(if mode == 0 { [0.0, 0.0, 1.0] } else { normal(r, false) });
            let uv = match r.below(6) {
                0 => [1.0 - fx, fy],
                1 => [fy, fx],
                2 => [uvc(r, false), uvc(r, false)],
                _ => [fx, fy],
            };
            m.uv.push(uv);
        }
    }
    let id = |x: usize, y: usize| (y * (w + 1) + x) as u32;
    for y in 0..h {
        for x in 0..w {
            let (a, b, c, d) = (id(x, y), id(x + 1, y), id(x + 1, y + 1), id(x, y + 1));
            let diag = r.below(2) == 0;
            let mut quad = |i: [u32; 3]| {
                // Sometimes reference a duplicated vertex entry instead (split or weldable).
                let i = i.map(|v| {
                    if r.below(6) == 0 {
                        let v = v as usize;
                        m.p.push(m.p[v]);
                        m.n.push(m.n[v]);
                        let uv = if r.below(2) == 0 { m.uv[v] } else { [uvc(r, false), uvc(r, false)] };
                        m.uv.push(uv);
                        (m.p.len() - 1) as u32
                    } else {
                        v
                    }
                });
                m.idx.extend(i);
            };
            if diag {
                quad([a, b, c]);
                quad([a, c, d]);
            } else {
                quad([a, b, d]);
                quad([b, c, d]);
            }
        }
    }
    shuffle(r, &mut m);
    m
}

fn fan(r: &mut Words) -> Mesh {
    let mut m = Mesh::default();
    let uvmode = r.below(5);
    // Mode 3 and 4 need an even count: rim vertex i + k/2 is the exact negation of vertex i.
    let k = (33 + r.below(88) as usize) & !1;
    let closed = r.below(4) != 0;
    let wild = r.below(6) == 0;
    // Tiny scales push normalised vectors off unit length (subnormal intermediate values).
    let scale = match r.below(8) {
        0 => 1.0e-21,
        1 => 1.0e-19,
        _ => 1.0,
    };
    m.p.push([0.0, 0.0, 0.0]);
    m.n.push([0.0, 0.0, 1.0]);
    m.uv.push([0.0, 0.0]);
    let half = k / 2;
    let mut rim: Vec<[f32; 3]> = Vec::new();
    for i in 0..k {
        let p = if i < half {
            let a = i as f32 / k as f32 * std::f32::consts::TAU;
            let z = if r.below(5) == 0 { 0.1 } else { 0.0 };
            [a.cos() * scale, a.sin() * scale, z * scale]
        } else {
            let q = rim[i - half];
            [-q[0], -q[1], q[2]]
        };
        rim.push(p);
    }
    for (i, &p) in rim.iter().enumerate() {
        let mut p = p;
        if wild && r.below(10) == 0 {
            p[r.below(3) as usize] = WILD[r.below(WILD.len() as u32) as usize];
        }
        m.p.push(p);
        m.n.push(if r.below(4) == 0 { normal(r, wild) } else { [0.0, 0.0, 1.0] });
        let (x, y) = (p[0] / scale, p[1] / scale);
        let uv = match uvmode {
            0 => [0.5 + 0.5 * x, 0.5 + 0.5 * y],
            1 => [uvc(r, wild), uvc(r, wild)],
            2 => {
                // Exact quarter-turn rotations of a planar map.
                let (x, y) = match r.below(4) {
                    0 => (x, y),
                    1 => (-y, x),
                    2 => (-x, -y),
                    _ => (y, -x),
                };
                [0.5 + 0.5 * x, 0.5 + 0.5 * y]
            }
            // uv = z^2: the tangent turns once around the fan, and the exact negation of the
            // rim gives exactly opposite tangents half a turn apart (dot products at -1).
            _ => {
                let (x, y) = if i >= half { (-x, -y) } else { (x, y) };
                [x * x - y * y, 2.0 * x * y]
            }
        };
        m.uv.push(uv);
    }
    // Mode 4: the rim order interleaves the halves, so both appear in one closed fan order.
    let last = if closed { k } else { k - 1 };
    let order: Vec<usize> = if uvmode == 4 {
        (0..k).map(|i| if i % 2 == 0 { i / 2 } else { half + i / 2 }).collect()
    } else {
        (0..k).collect()
    };
    for i in 0..last {
        let (a, b) = (1 + order[i] as u32, 1 + order[(i + 1) % k] as u32);
        m.idx.extend([0, a, b]);
    }
    shuffle(r, &mut m);
    m
}

fn strip(r: &mut Words) -> Mesh {
    // Many triangles meet the last-numbered vertices: non-manifold edges on the largest ids.
    let mut m = Mesh::default();
    let k = 3 + r.below(10) as usize;
    for i in 0..k + 3 {
        m.p.push([i as f32, (i % 2) as f32, (i % 3) as f32 * 0.5]);
        m.n.push([0.0, 0.0, 1.0]);
        m.uv.push([uvc(r, false), uvc(r, false)]);
    }
    let (x, y) = ((k + 1) as u32, (k + 2) as u32);
    for i in 0..k as u32 {
        match r.below(3) {
            0 => m.idx.extend([i, x, y]),
            1 => m.idx.extend([y, x, i]),
            _ => m.idx.extend([x, i, y]),
        }
    }
    shuffle(r, &mut m);
    m
}

/// Shuffles triangle order and rotates corners (the reference is order-sensitive only
/// through its documented quirks, which is exactly what must match).
fn shuffle(r: &mut Words, m: &mut Mesh) {
    let n = m.idx.len() / 3;
    let mut tris: Vec<[u32; 3]> = m.idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    for i in (1..n).rev() {
        let j = r.below(i as u32 + 1) as usize;
        tris.swap(i, j);
    }
    for t in &mut tris {
        t.rotate_left(r.below(3) as usize);
    }
    m.idx = tris.concat();
}

fn build(kind: u8, words: &[u32]) -> Mesh {
    let mut r = Words { w: words, i: 0, salt: kind as u32 * 7919 };
    match kind % 5 {
        0 => soup(&mut r, false),
        1 => grid(&mut r),
        2 => fan(&mut r),
        3 => soup(&mut r, true),
        _ => strip(&mut r),
    }
}

fn same(a: Option<[f32; 4]>, b: Option<[f32; 4]>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan())),
        _ => false,
    }
}

/// `Err` with the first differing corner.
fn check(m: &Mesh) -> Result<(), String> {
    let t = m.tri();
    let fast = generate(&t, Engine::Fast);
    let reference = generate(&t, Engine::Bevy);
    if fast.len() != reference.len() {
        return Err(format!("length {} vs {}", fast.len(), reference.len()));
    }
    for (i, (a, b)) in fast.iter().zip(&reference).enumerate() {
        if !same(*a, *b) {
            return Err(format!("corner {i}: fast {a:?} reference {b:?}"));
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2500, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn fast_equals_reference(kind in 0u8..5, words in prop::collection::vec(any::<u32>(), 0..600)) {
        let m = build(kind, &words);
        if let Err(e) = check(&m) {
            prop_assert!(false, "kind {kind}: {e}\nmesh {m:?}");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 500, failure_persistence: None, ..ProptestConfig::default() })]

    /// Kinds with large groups, separately so they always get their share.
    #[test]
    fn fast_equals_reference_on_fans(words in prop::collection::vec(any::<u32>(), 0..800)) {
        let m = build(2, &words);
        if let Err(e) = check(&m) {
            prop_assert!(false, "{e}\nmesh {m:?}");
        }
    }
}

#[test]
fn spot_matches_reference() {
    let (models, _) = tobj::load_obj(
        concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/spot/spot.obj"),
        &tobj::LoadOptions { single_index: true, triangulate: true, ..Default::default() },
    )
    .expect("fixture loads");
    let mesh = &models[0].mesh;
    let chunks = |v: &[f32]| -> Vec<[f32; 3]> { v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect() };
    let m = Mesh {
        p: chunks(&mesh.positions),
        n: chunks(&mesh.normals),
        uv: mesh.texcoords.chunks_exact(2).map(|c| [c[0], c[1]]).collect(),
        idx: mesh.indices.clone(),
    };
    assert!(m.idx.len() > 10_000 && m.n.len() == m.p.len() && m.uv.len() == m.p.len());
    check(&m).unwrap();
    // Also with every triangle's corners rotated and the triangle order reversed.
    let mut m2 = m.clone();
    m2.idx = m.idx.chunks_exact(3).rev().flat_map(|c| [c[1], c[2], c[0]]).collect();
    check(&m2).unwrap();
}

/// Long run: `MIKK_SOAK_SECS` seconds (default 600) of random recipes from a plain RNG.
/// `cargo test --release --test mikktspace_differential -- --ignored --nocapture`
#[test]
#[ignore]
fn soak() {
    let secs: u64 = std::env::var("MIKK_SOAK_SECS").ok().and_then(|s| s.parse().ok()).unwrap_or(600);
    let seed0: u64 = std::env::var("MIKK_SOAK_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(1);
    let t0 = std::time::Instant::now();
    let mut state = seed0;
    let mut next = || {
        // splitmix64
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    };
    let mut cases = [0u64; 5];
    while t0.elapsed().as_secs() < secs {
        let kind = (next() % 5) as u8;
        let len = (next() % 800) as usize;
        let words: Vec<u32> = (0..len).map(|_| next() as u32).collect();
        let m = build(kind, &words);
        if let Err(e) = check(&m) {
            panic!("soak mismatch after {cases:?} cases: kind {kind} words {words:?}: {e}");
        }
        cases[kind as usize] += 1;
    }
    let total: u64 = cases.iter().sum();
    println!("soak: {total} meshes in {secs} s without a mismatch (per kind {cases:?}, seed {seed0})");
}

/// Writes the OBJ scans' reference tangents (`fixtures/spot/spot.tangents.txt`,
/// `fixtures/blub/blub.tangents.txt`): the reference engine on primitive 0 as bumpbake's reader
/// hands it over (UVs already turned to glTF's v down, normals as the reader makes them), `w` in
/// glTF's convention. Rerun only when what the reader hands over changes:
/// `cargo test --features reference --test mikktspace_differential -- --ignored write_obj_references`
#[test]
#[ignore]
fn write_obj_references() {
    use bumpbake::scene::ReadOptions;
    use std::fmt::Write;
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    for (obj, out) in
        [("spot/spot.obj", "spot/spot.tangents.txt"), ("blub/blub_triangulated.obj", "blub/blub.tangents.txt")]
    {
        let scene = bumpbake::format::read(&dir.join(obj), &ReadOptions::default()).expect("fixture reads");
        let p = scene.primitive(scene.primitives()[0]).expect("primitive 0");
        let positions = p.positions();
        let normals: Vec<[f32; 3]> = p.attr("NORMAL").expect("normals").to_f32();
        let uvs: Vec<[f32; 2]> = p.attr("TEXCOORD_0").expect("UVs").to_f32();
        let mesh = TriMesh { positions: &positions, normals: &normals, uvs: &uvs, indices: &p.indices };
        let mut text = String::new();
        for (c, f) in generate(&mesh, Engine::Bevy).iter().enumerate() {
            // Corners without a reference frame (degenerate triangles) are not compared.
            let [x, y, z, w] = f.unwrap_or([0.0, 0.0, 0.0, -1.0]);
            writeln!(text, "{} {} {x:?} {y:?} {z:?} {}", c / 3, c % 3, bumpbake::tangent::gltf_w(w)).unwrap();
        }
        std::fs::write(dir.join(out), text).expect("reference written");
    }
}
