//! `raycast::nearest` against a brute-force scan: for any triangle soup and any ray, the tree
//! finds the hit a test of every triangle finds (same triangle, same distance and barycentrics,
//! bit for bit), under the documented order: nearest `|t|` within `[-back, front]`, then the
//! lower triangle index.
//!
//! The soups are built to hurt a BVH: few distinct coordinates (shared vertices, coplanar and
//! duplicated triangles, flat boxes), repeated corners and collinear corners (zero area), and
//! rays aimed at vertices and edges, along axes (slab bounds of `0 * inf`) and within planes.
//!
//! Two misses of the tree are known, and allowed here only where they can occur (about 1% of
//! the rays that hit): a ray in a box's lower face along an axis it has no part of, and a hit
//! on a box's boundary that the slab test's rounding puts outside (see `in_an_axis_plane` and
//! `on_box_boundary`). Even then, what the tree finds must be a true hit, no nearer than the
//! scan's. The two ignored tests at the end hold one instance of each.

use bumpbake::transfer::bvh::Bvh;
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
    /// Parallel to the xy plane, which the grid's coplanar triangles lie in.
    Flat(f32, f32),
    Any([f32; 3]),
}

fn aim() -> impl Strategy<Value = Aim> {
    let along = prop_oneof![Just(0.0f32), Just(0.5), Just(1.0), 0.0f32..1.0];
    prop_oneof![
        any::<u32>().prop_map(Aim::Vertex),
        (any::<u32>(), any::<u32>(), along).prop_map(|(a, b, s)| Aim::Edge(a, b, s)),
        (any::<u32>(), 0.0f32..1.0, 0.0f32..1.0).prop_map(|(t, u, v)| Aim::Inside(t, u, v)),
        (0u8..6).prop_map(Aim::Axis),
        (-1.0f32..1.0, -1.0f32..1.0).prop_map(|(x, y)| Aim::Flat(x, y)),
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
        Aim::Flat(x, y) => Vec3A::new(x, y, 0.0),
        Aim::Any(d) => Vec3A::from(d),
    };
    (dir != Vec3A::ZERO && dir.is_finite()).then(|| Ray::new(o, dir))
}

/// Whether `ray` runs in the plane `x = c` (or `y`, `z`) of some corner's coordinate `c`, along
/// an axis its direction has no part of. On a box's lower face in that axis, the slab test's
/// `0 * inf` is NaN, and `min`/`max` keep the other operand, `+-inf`: the box is missed. See
/// `an_axis_parallel_ray_in_a_lower_face_is_not_lost`.
fn in_an_axis_plane(ray: &Ray, pts: &[[f32; 3]]) -> bool {
    (0..3).any(|a| ray.dir[a] == 0.0 && pts.iter().any(|p| p[a] == ray.origin[a]))
}

/// In how many axes the hit at `t` on triangle `corners` lies, up to rounding, on the boundary
/// of the triangle's box (and so of every box around it that shares that face). The slab test
/// has no rounding margin: at a face the box's entry distance can come out an ulp past the
/// triangle's `t`, and a box whose entry lies past the best hit so far is skipped; at an edge or
/// corner (two axes or more) entry and exit meet, and rounding can empty the interval. See
/// `a_ray_through_a_box_corner_is_not_lost`.
fn on_box_boundary(ray: &Ray, corners: &[[f32; 3]; 3], t: f32) -> usize {
    let p = ray.origin.as_dvec3() + ray.dir.as_dvec3() * t as f64;
    let scale = 1.0 + ray.origin.abs().max_element() as f64 + (ray.dir * t).abs().max_element() as f64;
    let near = |x: f64, bound: f32| (x - bound as f64).abs() <= 1e-5 * scale;
    let on_boundary = |a: usize| {
        let (lo, hi) = corners.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), c| (l.min(c[a]), h.max(c[a])));
        near(p[a], lo) || near(p[a], hi)
    };
    (0..3).filter(|&a| on_boundary(a)).count()
}

/// Whether two distances are within a few ulps of each other.
fn ulps_apart(a: f32, b: f32) -> bool {
    (a.abs().to_bits() as i64 - b.abs().to_bits() as i64).abs() <= 4
}

/// How many rays hit, and how many of them were excused as one of the two known misses.
fn check(pts: &[[f32; 3]], tris: &[[u32; 3]], rays: &[RaySpec]) -> Result<(usize, usize), TestCaseError> {
    let bvh = Bvh::build_indexed(pts, tris.to_vec(), shading_index);
    let (mut hits, mut excused) = (0, 0);
    for spec in rays {
        let Some(ray) = make_ray(pts, tris, spec) else { continue };
        let (back, front) = (spec.2, spec.3);
        let want = brute_force(pts, tris, &ray, back, front);
        let got = traced(&bvh, pts, tris, &ray, back, front);
        hits += want.is_some() as usize;
        if bits(got) == bits(want) {
            continue;
        }
        let known = |(id, t, _): Found| {
            let faces = on_box_boundary(&ray, &tris[id as usize].map(|k| pts[k as usize]), t);
            let skipped_by_an_ulp = match got {
                Some((_, g, _)) => ulps_apart(g, t),
                None => ulps_apart(t, front) || ulps_apart(t, back),
            };
            in_an_axis_plane(&ray, pts) || faces >= 2 || (faces == 1 && skipped_by_an_ulp)
        };
        prop_assert!(
            want.is_some_and(known),
            "ray {:?} back {} front {}: tree {:?}, scan {:?}",
            spec,
            back,
            front,
            got,
            want
        );
        // A known miss: the tree may lose the best hit, but what it finds is a true hit, in
        // range, and no nearer than the scan's.
        excused += 1;
        if let Some((id, t, bary)) = got {
            let corners = tris[id as usize].map(|k| pts[k as usize]);
            prop_assert_eq!(bits(intersect(&ray, &corners).map(|(d, b)| (id, d, b))), bits(Some((id, t, bary))));
            prop_assert!(t >= -back && t <= front);
            let (wid, wt, _) = want.expect("the scan finds what the tree finds");
            prop_assert!((wt.abs(), wid) < (t.abs(), id), "tree {:?} beats scan {:?}", got, want);
        }
    }
    Ok((hits, excused))
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
        let tris: Vec<[u32; 3]> = (0..n as u32)
            .map(|i| {
                // Small triangles near vertex i, one in 16 with a repeated corner.
                let mut j = |d: u32| (i + 1 + next() % d) % n as u32;
                if i % 16 == 0 {
                    [i, j(8), i]
                } else {
                    [i, j(8), j(8)]
                }
            })
            .collect();
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
        let (hits, _) = check(&pts, &tris, &rays).unwrap_or_else(|e| panic!("{n} triangles: {e}"));
        assert!(hits > 20, "{n} triangles: only {hits} rays hit");
    }
}

/// One triangle, one ray, as the scan sees it and as the tree does.
fn alone(corners: [[f32; 3]; 3], origin: [f32; 3], dir: [f32; 3]) -> (Option<Found>, Option<Found>) {
    let ray = Ray::new(Vec3A::from(origin), Vec3A::from(dir));
    let bvh = Bvh::build(&corners, vec![[0, 1, 2]]);
    let tris = [[0, 1, 2]];
    (brute_force(&corners, &tris, &ray, 1.0, 8.0), traced(&bvh, &corners, &tris, &ray, 1.0, 8.0))
}

/// Known to fail: the ray runs in the plane `y = -2` (no y in its direction), the box's lower
/// y face, and meets the triangle's corner there at `t = 1`. The slab test's `(-2 - -2) * inf`
/// is NaN, `min`/`max` keep `+inf`, and the box is missed.
#[test]
#[ignore = "known miss: NaN in the slab test on a box's lower face"]
fn an_axis_parallel_ray_in_a_lower_face_is_not_lost() {
    let (scan, tree) =
        alone([[0.0, 1.0, -0.5], [0.0, 2.0, -1.0], [0.0, -2.0, -1.5]], [2.0, -2.0, 0.5], [-2.0, 0.0, -2.0]);
    assert!(scan.is_some());
    assert_eq!(bits(tree), bits(scan));
}

/// Known to fail: the ray meets the triangle at a corner of its box, where the slab test's
/// entry (1.0) comes out one ulp past its exit (0.99999994), and the box is missed.
#[test]
#[ignore = "known miss: the slab test has no rounding margin"]
fn a_ray_through_a_box_corner_is_not_lost() {
    let (scan, tree) = alone(
        [[-1.3209722, -2.121176, 1.0], [-1.3484824, 3.289475, 1.2744124], [1.0, -1.0, -3.347548]],
        [-3.8230305, 0.0, 0.5],
        [2.474548, 3.289475, 0.7744124],
    );
    assert!(scan.is_some());
    assert_eq!(bits(tree), bits(scan));
}
