//! `raycast::nearest` against a brute-force scan: for any triangle soup and any ray, the tree
//! finds the hit a test of every triangle finds (same triangle, same distance and barycentrics,
//! bit for bit), under the documented order: nearest `|t|` within `[-back, front]`, then the
//! lower triangle index.
//!
//! The soups are built to hurt a BVH: few distinct coordinates (shared vertices, coplanar and
//! duplicated triangles, flat boxes), repeated corners and collinear corners (zero area), and
//! rays aimed at vertices and edges, along axes (slab bounds of `0 * inf`) and within planes.
//!
//! Every check also walks the rays in packets (`packet::nearest_packet`), of neighbouring
//! rays as a bake sends them and of unrelated ones, and holds each ray's hit to the scan's.
//!
//! Hard-surface soups join them: axis-aligned boxes, bevelled cubes and grids on integer
//! coordinates, where edges and whole faces lie in the planes of the tree's boxes, with rays
//! from grid points aimed at their vertices and edges and along their faces. There, a box test
//! without a rounding margin skips hits on a box's boundary, and one that computes `0 * inf`
//! for a ray lying in a box's face loses the box (the last two tests hold one case of each).

use bumpbake::transfer::bvh::Bvh;
use bumpbake::transfer::packet::{nearest_packet, PacketStack, PACKET};
use bumpbake::transfer::raycast::{intersect, nearest, Hit, Ray, Stack};
use glam::Vec3A;
use proptest::prelude::*;

/// A hit: the triangle's index in the input, `t`, barycentrics.
type Found = (u32, f32, [f32; 3]);

/// What a scan of every triangle finds; the order is the one `nearest` documents.
fn brute_force(positions: &[[f32; 3]], tris: &[[u32; 3]], ray: &Ray, back: f32, front: f32) -> Option<Found> {
    let mut best: Option<Found> = None;
    for (id, t) in tris.iter().enumerate() {
        let corners = t.map(|k| positions[k as usize]);
        let Some((d, bary)) = intersect(ray, &corners) else { continue };
        assert!(d.is_finite(), "the soups keep distances finite");
        if d < -back || d > front {
            continue;
        }
        // Ids rise as the scan goes, so on a tie the one kept is the lower.
        if best.is_none_or(|(_, b, _)| d.abs() < b.abs()) {
            best = Some((id as u32, d, bary));
        }
    }
    best
}

/// The tree's answer, checked against what its leaf-order arrays say about the triangle.
fn traced(bvh: &Bvh, positions: &[[f32; 3]], tris: &[[u32; 3]], ray: &Ray, back: f32, front: f32) -> Option<Found> {
    let hit: Hit = nearest(bvh, ray, back, front, &mut Stack::default())?;
    let slot = hit.slot as usize;
    assert_eq!(bvh.ids[slot], hit.id);
    let t = tris[hit.id as usize];
    assert_eq!(*bvh.corners(slot), t.map(|k| positions[k as usize]));
    assert_eq!(bvh.index(slot), shading_index(hit.id).unwrap_or(t));
    Some((hit.id, hit.t, hit.bary))
}

/// Shading indices of their own for every third triangle, as an OBJ's `vn` gives.
fn shading_index(id: u32) -> Option<[u32; 3]> {
    id.is_multiple_of(3).then_some([id, id + 1, id + 2])
}

/// Bit patterns, so that `-0.0` and `0.0` (or two NaNs) are told apart.
fn bits(h: Option<Found>) -> Option<(u32, u32, [u32; 3])> {
    h.map(|(id, t, b)| (id, t.to_bits(), b.map(f32::to_bits)))
}

fn coord() -> impl Strategy<Value = f32> {
    prop_oneof![
        // A coarse grid: coplanar and duplicated triangles, shared vertices, flat boxes.
        4 => (-4i32..5).prop_map(|i| i as f32 * 0.5),
        2 => -4.0f32..4.0,
        1 => (-1.0f32..1.0).prop_map(|x| x * 1e-4),
    ]
}

fn point() -> impl Strategy<Value = [f32; 3]> {
    [coord(), coord(), coord()]
}

/// How a ray is aimed; the `u32`s pick vertices and triangles (modulo their count), the `f32`s
/// a place between them.
#[derive(Debug, Clone)]
enum Aim {
    Vertex(u32),
    Edge(u32, u32, f32),
    Inside(u32, f32, f32),
    Axis(u8),
    /// Parallel to a coordinate plane (0: yz, 1: zx, 2: xy), which the grid's coplanar
    /// triangles and the boxes' faces lie in.
    Flat(u8, f32, f32),
    Any([f32; 3]),
}

fn aim() -> impl Strategy<Value = Aim> {
    let along = prop_oneof![Just(0.0f32), Just(0.5), Just(1.0), 0.0f32..1.0];
    prop_oneof![
        any::<u32>().prop_map(Aim::Vertex),
        (any::<u32>(), any::<u32>(), along).prop_map(|(a, b, s)| Aim::Edge(a, b, s)),
        (any::<u32>(), 0.0f32..1.0, 0.0f32..1.0).prop_map(|(t, u, v)| Aim::Inside(t, u, v)),
        (0u8..6).prop_map(Aim::Axis),
        (0u8..3, -1.0f32..1.0, -1.0f32..1.0).prop_map(|(a, x, y)| Aim::Flat(a, x, y)),
        point().prop_map(Aim::Any),
    ]
}

fn reach() -> impl Strategy<Value = f32> {
    prop_oneof![Just(0.0f32), Just(0.25), Just(1.0), Just(8.0), Just(1e30)]
}

/// A ray's origin, aim, `back` and `front`.
type RaySpec = ([f32; 3], Aim, f32, f32);

/// Points, some of them midpoints of others (collinear corners), and triangles over them.
type Soup = (Vec<[f32; 3]>, Vec<[u32; 3]>);

fn soup() -> impl Strategy<Value = Soup> {
    (prop::collection::vec(point(), 3..40), prop::collection::vec(any::<(u8, u8)>(), 0..8)).prop_flat_map(
        |(mut pts, mids)| {
            let n = pts.len();
            for (a, b) in mids {
                let (a, b) = (Vec3A::from(pts[a as usize % n]), Vec3A::from(pts[b as usize % n]));
                pts.push(((a + b) * 0.5).to_array());
            }
            let m = pts.len() as u32;
            let tris = prop::collection::vec(
                prop_oneof![
                    6 => [0..m, 0..m, 0..m],
                    // A repeated corner: zero area.
                    1 => (0..m, 0..m).prop_map(|(a, b)| [a, b, a]),
                ],
                1..150,
            );
            (Just(pts), tris).prop_map(|(pts, mut tris)| {
                // Duplicates, some with their winding reversed.
                let n = tris.len();
                for k in 0..n / 8 {
                    let t = tris[(k * 7) % n];
                    tris.push(if k % 2 == 0 { t } else { [t[2], t[1], t[0]] });
                }
                (pts, tris)
            })
        },
    )
}

/// A piece of a hard-surface model, on integer coordinates (a bevel's on quarters).
#[derive(Debug, Clone)]
enum Shape {
    /// An axis-aligned box: its lowest corner and its size (at least 1 along each axis).
    Box([i32; 3], [i32; 3]),
    /// A cube with every edge and corner bevelled: its centre and half its side, the bevel a
    /// quarter of that.
    Bevelled([i32; 3], i32),
    /// A square grid of quads in the plane `axis = offset` from `corner`, each vertex raised
    /// off the plane by a whole number (0 for a flat panel).
    Grid { axis: u8, offset: i32, corner: [i32; 2], side: u8, raise: Vec<u8> },
}

fn shape() -> impl Strategy<Value = Shape> {
    let at = || [-3i32..3, -3i32..3, -3i32..3];
    prop_oneof![
        (at(), [1i32..4, 1i32..4, 1i32..4]).prop_map(|(c, s)| Shape::Box(c, s)),
        (at(), 1i32..3).prop_map(|(c, h)| Shape::Bevelled(c, h)),
        (
            0u8..3,
            -3i32..3,
            [-3i32..1, -3i32..1],
            1u8..5,
            prop::collection::vec(prop_oneof![3 => Just(0u8), 1 => 0u8..3], 25)
        )
            .prop_map(|(axis, offset, corner, side, raise)| Shape::Grid { axis, offset, corner, side, raise }),
    ]
}

/// `shape`'s triangles, added to `pts` and `tris` (quads split along a diagonal).
fn add_shape(shape: &Shape, pts: &mut Vec<[f32; 3]>, tris: &mut Vec<[u32; 3]>) {
    let mut quad = |q: [[f32; 3]; 4], pts: &mut Vec<[f32; 3]>| {
        let k = pts.len() as u32;
        pts.extend(q);
        tris.push([k, k + 1, k + 2]);
        tris.push([k, k + 2, k + 3]);
    };
    match shape {
        Shape::Box(lo, size) => {
            let lo = lo.map(|x| x as f32);
            let hi = [0, 1, 2].map(|a| lo[a] + size[a] as f32);
            for a in 0..3 {
                let (b, c) = ((a + 1) % 3, (a + 2) % 3);
                for side in [lo[a], hi[a]] {
                    let p = |u: f32, v: f32| {
                        let mut p = [0.0; 3];
                        (p[a], p[b], p[c]) = (side, u, v);
                        p
                    };
                    quad([p(lo[b], lo[c]), p(hi[b], lo[c]), p(hi[b], hi[c]), p(lo[b], hi[c])], pts);
                }
            }
        }
        Shape::Bevelled(centre, half) => {
            let (h, inner) = (*half as f32, *half as f32 * 0.75);
            let at = |p: [f32; 3]| [0, 1, 2].map(|a| centre[a] as f32 + p[a]);
            let put = |v: [(usize, f32); 3]| {
                let mut p = [0.0; 3];
                v.iter().for_each(|&(a, x)| p[a] = x);
                at(p)
            };
            for a in 0..3 {
                let (b, c) = ((a + 1) % 3, (a + 2) % 3);
                for s in [-1.0f32, 1.0] {
                    // The face, inset by the bevel.
                    let f = |u: f32, v: f32| put([(a, s * h), (b, u * inner), (c, v * inner)]);
                    quad([f(-1.0, -1.0), f(1.0, -1.0), f(1.0, 1.0), f(-1.0, 1.0)], pts);
                    // The bevel along the edge between this face and the face `b = t * h`.
                    for t in [-1.0f32, 1.0] {
                        let e = |sa: f32, sb: f32, w: f32| put([(a, s * sa), (b, t * sb), (c, w * inner)]);
                        quad([e(h, inner, -1.0), e(h, inner, 1.0), e(inner, h, 1.0), e(inner, h, -1.0)], pts);
                    }
                }
            }
            for sx in [-1.0f32, 1.0] {
                for sy in [-1.0f32, 1.0] {
                    for sz in [-1.0f32, 1.0] {
                        let k = pts.len() as u32;
                        pts.push(at([sx * h, sy * inner, sz * inner]));
                        pts.push(at([sx * inner, sy * h, sz * inner]));
                        pts.push(at([sx * inner, sy * inner, sz * h]));
                        tris.push([k, k + 1, k + 2]);
                    }
                }
            }
        }
        Shape::Grid { axis, offset, corner, side, raise } => {
            let a = *axis as usize;
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            let n = *side as usize;
            let p = |i: usize, j: usize| {
                let mut p = [0.0; 3];
                p[a] = (*offset + raise[(i * 5 + j) % raise.len()] as i32) as f32;
                p[b] = (corner[0] + i as i32) as f32;
                p[c] = (corner[1] + j as i32) as f32;
                p
            };
            for i in 0..n {
                for j in 0..n {
                    quad([p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)], pts);
                }
            }
        }
    }
}

/// A hard-surface model: a few shapes, overlapping where they fall so.
fn hard_surface() -> impl Strategy<Value = Soup> {
    prop::collection::vec(shape(), 1..6).prop_map(|shapes| {
        let (mut pts, mut tris) = (Vec::new(), Vec::new());
        shapes.iter().for_each(|s| add_shape(s, &mut pts, &mut tris));
        (pts, tris)
    })
}

/// Grid points and the quarters between them, where the shapes' vertices, edges and faces lie.
fn grid_point() -> impl Strategy<Value = [f32; 3]> {
    let c = || prop_oneof![3 => (-5i32..6).prop_map(|i| i as f32), 1 => (-20i32..21).prop_map(|i| i as f32 * 0.25)];
    [c(), c(), c()]
}

/// The ray `spec` describes over `pts` and `tris`; `None` when its direction comes out zero.
fn make_ray(pts: &[[f32; 3]], tris: &[[u32; 3]], (origin, aim, _, _): &RaySpec) -> Option<Ray> {
    let o = Vec3A::from(*origin);
    let p = |k: u32| Vec3A::from(pts[k as usize % pts.len()]);
    let dir = match *aim {
        Aim::Vertex(k) => p(k) - o,
        Aim::Edge(a, b, s) => p(a).lerp(p(b), s) - o,
        Aim::Inside(t, u, v) => {
            let [a, b, c] = tris[t as usize % tris.len()].map(p);
            let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
            a + (b - a) * u + (c - a) * v - o
        }
        Aim::Axis(k) => [Vec3A::X, Vec3A::Y, Vec3A::Z, -Vec3A::X, -Vec3A::Y, -Vec3A::Z][k as usize],
        Aim::Flat(a, x, y) => {
            let mut d = [x, y, x - y];
            d[a as usize] = 0.0;
            Vec3A::from(d)
        }
        Aim::Any(d) => Vec3A::from(d),
    };
    (dir != Vec3A::ZERO && dir.is_finite()).then(|| Ray::new(o, dir))
}

/// How many rays hit; the tree's answer must be the scan's, bit for bit, on every ray, walked
/// alone and in packets.
fn check(pts: &[[f32; 3]], tris: &[[u32; 3]], rays: &[RaySpec]) -> Result<usize, TestCaseError> {
    let bvh = Bvh::build_indexed(pts, tris.to_vec(), shading_index);
    let mut hits = 0;
    let mut wanted = Vec::new();
    for spec in rays {
        let Some(ray) = make_ray(pts, tris, spec) else { continue };
        let (back, front) = (spec.2, spec.3);
        let want = brute_force(pts, tris, &ray, back, front);
        let got = traced(&bvh, pts, tris, &ray, back, front);
        hits += want.is_some() as usize;
        prop_assert!(
            bits(got) == bits(want),
            "ray {:?} back {} front {}: tree {:?}, scan {:?}",
            spec,
            back,
            front,
            got,
            want
        );
        wanted.push(((ray, back, front), want));
    }
    in_packets(&bvh, &wanted)?;
    Ok(hits)
}

/// A ray with how far it reaches behind and ahead, as `nearest_packet` takes it.
type Reach = (Ray, f32, f32);

/// Packets of the rays with a part of every axis (those a packet walks together; a packet with
/// another walks each ray alone), then of all the rays in their order, of every size up to
/// [`PACKET`]: each ray's hit must be the scan's `want`.
fn in_packets(bvh: &Bvh, wanted: &[(Reach, Option<Found>)]) -> Result<(), TestCaseError> {
    let free: Vec<_> = wanted.iter().filter(|(r, _)| r.0.has_every_axis()).cloned().collect();
    let mut stack = PacketStack::default();
    for (group, size) in [(&free, PACKET), (&free, 3), (&wanted.to_vec(), PACKET), (&free, 1)] {
        for chunk in group.chunks(size) {
            let rays: Vec<Reach> = chunk.iter().map(|w| w.0).collect();
            let mut out = vec![None; rays.len()];
            nearest_packet(bvh, &rays, &mut out, &mut stack);
            for (got, (ray, want)) in out.iter().zip(chunk) {
                let got = got.map(|h| (h.id, h.t, h.bary));
                prop_assert!(
                    bits(got) == bits(*want),
                    "ray {:?} in a packet of {}: tree {:?}, scan {:?}",
                    ray,
                    rays.len(),
                    got,
                    want
                );
            }
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn nearest_equals_a_scan_of_every_triangle(
        (pts, tris) in soup(),
        rays in prop::collection::vec((point(), aim(), reach(), reach()), 32),
    ) {
        check(&pts, &tris, &rays)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn nearest_equals_a_scan_on_hard_surfaces(
        (pts, tris) in hard_surface(),
        rays in prop::collection::vec((grid_point(), aim(), reach(), reach()), 48),
    ) {
        check(&pts, &tris, &rays)?;
    }
}

/// A soup large enough for the parallel SAH build (16k triangles and more) and the
/// Morton-split upper levels (64k and more), which the small soups above never reach.
#[test]
fn nearest_equals_a_scan_on_large_soups() {
    let mut state = 0x9e37_79b9u32;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state
    };
    for n in [17_000usize, 66_000] {
        // Vertices on a grid of 1/8 over a 48-unit cube: coplanar and repeated corners abound.
        let mut grid = || (next() % 385) as f32 * 0.125 - 24.0;
        let pts: Vec<[f32; 3]> = (0..n).map(|_| [grid(), grid(), grid()]).collect();
        let mut tris: Vec<[u32; 3]> = Vec::with_capacity(n);
        for i in 0..n as u32 {
            // Small triangles near vertex i, one in 16 with a repeated corner, one in 4 sharing
            // an edge with the one before (a pair the large build makes one item of).
            let mut j = |d: u32| (i + 1 + next() % d) % n as u32;
            tris.push(match (i % 16, tris.last()) {
                (0, _) => [i, j(8), i],
                (1 | 5 | 9 | 13, Some(&[a, _, c])) => [a, c, j(8)],
                _ => [i, j(8), j(8)],
            });
        }
        let mut rng = || next();
        let rays: Vec<RaySpec> = (0..60)
            .map(|k| {
                let origin = [
                    (rng() % 97) as f32 * 0.5 - 24.0,
                    (rng() % 97) as f32 * 0.5 - 24.0,
                    (rng() % 97) as f32 * 0.5 - 24.0,
                ];
                let aim = match k % 3 {
                    0 => Aim::Vertex(rng()),
                    1 => Aim::Axis((rng() % 6) as u8),
                    _ => Aim::Inside(rng(), 0.25, 0.25),
                };
                (origin, aim, 48.0, 48.0)
            })
            .collect();
        let hits = check(&pts, &tris, &rays).unwrap_or_else(|e| panic!("{n} triangles: {e}"));
        assert!(hits > 20, "{n} triangles: only {hits} rays hit");
    }
}

/// What a bake sends: packets of neighbouring, nearly parallel rays, from a plane above a
/// terrace of integer heights (faces and edges in the planes of the tree's boxes), some of them
/// aimed through its vertices and edges, both ways along the line. Every ray alone and in
/// packets gets the scan's hit.
#[test]
fn neighbouring_rays_in_packets_equal_a_scan() {
    // The second terrace has enough triangles for the large build, which pairs a quad's halves.
    for side in [48u32, 184] {
        terrace(side);
    }
}

fn terrace(side: u32) {
    let height = |i: u32, j: u32| ((i / 6 + j / 9) % 4) as f32;
    let pts: Vec<[f32; 3]> =
        (0..=side).flat_map(|j| (0..=side).map(move |i| [i as f32, j as f32, height(i, j)])).collect();
    let at = |i: u32, j: u32| j * (side + 1) + i;
    let tris: Vec<[u32; 3]> = (0..side)
        .flat_map(|j| {
            (0..side).flat_map(move |i| {
                [[at(i, j), at(i + 1, j), at(i + 1, j + 1)], [at(i, j), at(i + 1, j + 1), at(i, j + 1)]]
            })
        })
        .collect();
    let mut rays: Vec<RaySpec> = Vec::new();
    // Tiles of 4 x 4 origins a quarter apart, each tile's rays along one direction; every
    // other tile's origins on the vertex grid, so that its rays pass through vertices and edges.
    for (k, (ti, tj)) in [(3.0f32, 5.0f32), (17.0, 30.0), (40.0, 11.0), (25.0, 44.0)].into_iter().enumerate() {
        let offset = if k % 2 == 0 { 0.0 } else { 0.125 };
        let dir = [[0.01, -0.02, -1.0], [0.0, 0.0, -1.0], [0.3, 0.2, -1.0], [-0.25, 0.01, 1.0]][k];
        for b in 0..4 {
            for a in 0..4 {
                let o = [
                    ti + a as f32 * 0.25 + offset,
                    tj + b as f32 * 0.25 + offset,
                    if dir[2] < 0.0 { 6.0 } else { -2.0 },
                ];
                rays.push((o, Aim::Any(dir), 9.0, 9.0));
            }
        }
    }
    let hits = check(&pts, &tris, &rays).expect("every ray as the scan");
    assert!(hits > 50, "only {hits} rays hit");
}

/// One triangle, one ray, as the scan sees it and as the tree does.
fn alone(corners: [[f32; 3]; 3], origin: [f32; 3], dir: [f32; 3]) -> (Option<Found>, Option<Found>) {
    let ray = Ray::new(Vec3A::from(origin), Vec3A::from(dir));
    let bvh = Bvh::build(&corners, vec![[0, 1, 2]]);
    let tris = [[0, 1, 2]];
    (brute_force(&corners, &tris, &ray, 1.0, 8.0), traced(&bvh, &corners, &tris, &ray, 1.0, 8.0))
}

/// The ray runs in the plane `y = -2` (no y in its direction), the box's lower y face, and
/// meets the triangle's corner there at `t = 1`; a slab test computing `(-2 - -2) * inf` gets
/// NaN there and loses the box.
#[test]
fn an_axis_parallel_ray_in_a_lower_face_is_not_lost() {
    let (scan, tree) =
        alone([[0.0, 1.0, -0.5], [0.0, 2.0, -1.0], [0.0, -2.0, -1.5]], [2.0, -2.0, 0.5], [-2.0, 0.0, -2.0]);
    assert!(scan.is_some());
    assert_eq!(bits(tree), bits(scan));
}

/// The ray meets the triangle at a corner of its box, where the slab test's entry (1.0) comes
/// out one ulp past its exit (0.99999994): without a rounding margin the box is missed.
#[test]
fn a_ray_through_a_box_corner_is_not_lost() {
    let (scan, tree) = alone(
        [[-1.3209722, -2.121176, 1.0], [-1.3484824, 3.289475, 1.2744124], [1.0, -1.0, -3.347548]],
        [-3.8230305, 0.0, 0.5],
        [2.474548, 3.289475, 0.7744124],
    );
    assert!(scan.is_some());
    assert_eq!(bits(tree), bits(scan));
}
