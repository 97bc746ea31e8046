//! Per-group sub-grouping and angle-weighted averaging, bit-exact with the reference.
//!
//! For every member `a` of a group the reference builds the sub-group of members `b` with
//! `any(a, b) || a == b || (s_a·s_b > -1 && t_a·t_b > -1)` (projected, normalised first-order
//! tangents; `any` = "group with anything"), sorts it, and sums the angle-weighted projected
//! tangents of its non-"any" members in that order. That is quadratic per vertex. Here:
//!
//! * the per-member contribution `angle * s'` is computed once per group;
//! * the threshold `-1` can only fail for (almost exactly) antipodal unit vectors, vectors with
//!   NaN, or pathological non-unit vectors. Antipodal pairs are found by hashing directions on a
//!   grid (candidates then checked with the reference's exact float expression); NaN members are
//!   incompatible with everybody; non-unit members are checked against every member. Small
//!   groups simply test all pairs;
//! * each distinct exclusion set is summed once, in the reference's order, restarting from the
//!   shared prefix sum before its first excluded member.
//!
//! In real meshes no pair is excluded and every group costs O(size). Exclusions cost
//! O(size - first excluded position) per distinct exclusion set.

use super::math::{acos, add, dot, normalized_or_zero, project, scale, sub, V3};

use super::{Corners, Welded};
use std::collections::HashMap;

const THRESHOLD: f32 = -1.0;
/// Groups up to this size test all pairs directly.
pub(crate) const BRUTE_MAX: usize = 32;

/// What one group needs to know about one member.
pub(crate) struct Member {
    s: V3,
    t: V3,
    gwa: bool,
    /// `angle * s'` for non-"any" members.
    c: V3,
}

#[inline]
fn compatible(a: &Member, b: &Member) -> bool {
    dot(a.s, b.s) > THRESHOLD && dot(a.t, b.t) > THRESHOLD
}

/// Computes the output tangent of every member of one group. `members` are list entries
/// `3 * t + j`, sorted ascending; `st(t)` gives triangle `t`'s first-order vectors; `out[i]`
/// receives member `i`'s normalised tangent.
// The arguments are the hot loop's inputs, each borrowed separately so callers can share the
// read-only ones across threads; bundling them into a struct measured no clearer.
#[allow(clippy::too_many_arguments)]
pub(crate) fn group_tangents<W: Welded + ?Sized>(
    c: &Corners,
    w: &W,
    st: &(impl Fn(usize) -> (V3, V3) + ?Sized),
    gwa: &[bool],
    rep: u32,
    members: &[u32],
    out: &mut [V3],
    scratch: &mut Vec<Member>,
) {
    let n = c.nrm(rep as usize);
    scratch.clear();
    scratch.extend(members.iter().map(|&k| {
        let (t, j) = ((k / 3) as usize, (k % 3) as usize);
        let (s0, t0) = st(t);
        let s = project(s0, n);
        let tt = project(t0, n);
        let gwa = gwa[t];
        let cc = if gwa {
            [0.0; 3]
        } else {
            let p = [
                c.pos(w.attr_corner(3 * t + (j + 1) % 3)),
                c.pos(w.attr_corner(3 * t + j)),
                c.pos(w.attr_corner(3 * t + (j + 2) % 3)),
            ];
            let v0 = project(sub(p[0], p[1]), n);
            let v1 = project(sub(p[2], p[1]), n);
            let cos = dot(v0, v1).clamp(-1.0, 1.0);
            scale(acos(cos), s)
        };
        Member { s, t: tt, gwa, c: cc }
    }));
    if all_compatible(scratch) {
        // Every sub-group is the whole group: one sum, in member order.
        let mut sum = [0.0f32; 3];
        for mb in scratch.iter().filter(|x| !x.gwa) {
            sum = add(sum, mb.c);
        }
        out.fill(finish(sum));
    } else if scratch.len() <= BRUTE_MAX {
        small(scratch, out);
    } else {
        large(scratch, out);
    }
}

/// A sufficient test, linear in the group size, that every pair of non-"any" members passes
/// the threshold: all vectors unit length (within 1e-3) and within about 53° of the first
/// member's. Then any two are within about 107° of each other, so their dot products are
/// near -0.29 or above, far from -1 whatever the rounding.
fn all_compatible(ms: &[Member]) -> bool {
    let near_unit = |v: V3| {
        let l = dot(v, v);
        l > 0.999 && l < 1.001
    };
    let mut pivot: Option<&Member> = None;
    for m in ms.iter().filter(|x| !x.gwa) {
        if !near_unit(m.s) || !near_unit(m.t) {
            return false;
        }
        match pivot {
            None => pivot = Some(m),
            Some(p) => {
                if !(dot(p.s, m.s) > 0.6 && dot(p.t, m.t) > 0.6) {
                    return false;
                }
            }
        }
    }
    true
}

fn finish(sum: V3) -> V3 {
    normalized_or_zero(sum)
}

/// Direct evaluation: exclusion bit masks, one sum per distinct mask.
fn small(ms: &[Member], out: &mut [V3]) {
    let m = ms.len();
    let mut cache = [(0u64, [0.0f32; 3]); BRUTE_MAX];
    let mut cached = 0usize;
    for a in 0..m {
        let mut incl: u64 = 0;
        for b in 0..m {
            if ms[a].gwa || ms[b].gwa || a == b || compatible(&ms[a], &ms[b]) {
                incl |= 1 << b;
            }
        }
        let v = match cache[..cached].iter().find(|x| x.0 == incl) {
            Some(x) => x.1,
            None => {
                let mut sum = [0.0f32; 3];
                for (b, mb) in ms.iter().enumerate() {
                    if incl & (1 << b) != 0 && !mb.gwa {
                        sum = add(sum, mb.c);
                    }
                }
                let v = finish(sum);
                cache[cached] = (incl, v);
                cached += 1;
                v
            }
        };
        out[a] = v;
    }
}

#[derive(PartialEq, Eq, Clone, Copy)]
enum Kind {
    Gwa,
    Nan,
    /// Both vectors finite and either unit (|len² - 1| <= 1e-5) or all components tiny.
    Regular,
    Irregular,
}

fn vec_regular(v: V3) -> bool {
    if !v.iter().all(|x| x.is_finite()) {
        return false;
    }
    if v.iter().all(|x| x.abs() <= 1e-30) {
        return true;
    }
    (dot(v, v) - 1.0).abs() <= 1e-5
}

fn unit(v: V3) -> bool {
    !v.iter().all(|x| x.abs() <= 1e-30)
}

/// Grid cell size for direction hashing. A pair of unit vectors whose float dot product is
/// `<= -1` is antipodal within a chord of 0.005; lookups include the neighbouring cell on
/// every axis where `-v` lies within `MARGIN` of a cell face (twice that distance).
const CELLS_PER_UNIT: f32 = 20.0;
const MARGIN: f32 = 0.01;

fn cell_key(c: [i32; 3]) -> u32 {
    ((c[0] + 32) as u32) | (((c[1] + 32) as u32) << 6) | (((c[2] + 32) as u32) << 12)
}

fn cell_of(v: V3) -> [i32; 3] {
    v.map(|x| (x * CELLS_PER_UNIT).floor() as i32)
}

/// Calls `f(b)` for every member hashed in a cell near `-v`.
fn antipode_candidates(map: &HashMap<u32, Vec<u32>>, v: V3, mut f: impl FnMut(u32)) {
    let q = v.map(|x| -x * CELLS_PER_UNIT);
    let base = q.map(|x| x.floor());
    let mut offs: [Vec<i32>; 3] = [vec![0], vec![0], vec![0]];
    for ax in 0..3 {
        let frac = q[ax] - base[ax];
        if frac < MARGIN * CELLS_PER_UNIT {
            offs[ax].push(-1);
        }
        if frac > 1.0 - MARGIN * CELLS_PER_UNIT {
            offs[ax].push(1);
        }
    }
    for &dx in &offs[0] {
        for &dy in &offs[1] {
            for &dz in &offs[2] {
                let c = [base[0] as i32 + dx, base[1] as i32 + dy, base[2] as i32 + dz];
                if let Some(list) = map.get(&cell_key(c)) {
                    list.iter().for_each(|&b| f(b));
                }
            }
        }
    }
}

fn large(ms: &[Member], out: &mut [V3]) {
    let m = ms.len();
    let kind: Vec<Kind> = ms
        .iter()
        .map(|x| {
            if x.gwa {
                Kind::Gwa
            } else if x.s.iter().chain(x.t.iter()).any(|v| v.is_nan()) {
                Kind::Nan
            } else if vec_regular(x.s) && vec_regular(x.t) {
                Kind::Regular
            } else {
                Kind::Irregular
            }
        })
        .collect();
    // Exclusions among non-NaN, non-"any" members (NaN members exclude and are excluded by all).
    let mut exc: Vec<Vec<u32>> = vec![Vec::new(); m];
    let add_pair = |exc: &mut Vec<Vec<u32>>, a: usize, b: usize| {
        exc[a].push(b as u32);
        exc[b].push(a as u32);
    };
    let live = |k: Kind| matches!(k, Kind::Regular | Kind::Irregular);
    for a in 0..m {
        if kind[a] != Kind::Irregular {
            continue;
        }
        for b in 0..m {
            if b != a && live(kind[b]) && (kind[b] == Kind::Regular || b > a) && !compatible(&ms[a], &ms[b]) {
                add_pair(&mut exc, a, b);
            }
        }
    }
    let mut map_s: HashMap<u32, Vec<u32>> = HashMap::new();
    let mut map_t: HashMap<u32, Vec<u32>> = HashMap::new();
    for a in 0..m {
        if kind[a] == Kind::Regular {
            if unit(ms[a].s) {
                map_s.entry(cell_key(cell_of(ms[a].s))).or_default().push(a as u32);
            }
            if unit(ms[a].t) {
                map_t.entry(cell_key(cell_of(ms[a].t))).or_default().push(a as u32);
            }
        }
    }
    let mut found: Vec<u32> = Vec::new();
    for a in 0..m {
        if kind[a] != Kind::Regular {
            continue;
        }
        found.clear();
        if unit(ms[a].s) {
            antipode_candidates(&map_s, ms[a].s, |b| found.push(b));
        }
        if unit(ms[a].t) {
            antipode_candidates(&map_t, ms[a].t, |b| found.push(b));
        }
        for &b in &found {
            let b = b as usize;
            if b > a && !compatible(&ms[a], &ms[b]) {
                add_pair(&mut exc, a, b);
            }
        }
    }
    // Base order: live members in sorted order, with prefix sums.
    let base: Vec<usize> = (0..m).filter(|&b| live(kind[b])).collect();
    let mut pos_in_base = vec![u32::MAX; m];
    let mut prefix: Vec<V3> = Vec::with_capacity(base.len() + 1);
    prefix.push([0.0; 3]);
    for (i, &b) in base.iter().enumerate() {
        pos_in_base[b] = i as u32;
        prefix.push(add(prefix[i], ms[b].c));
    }
    let base_value = finish(prefix[base.len()]);
    let has_nan = kind.contains(&Kind::Nan);
    let full_value = if has_nan {
        let mut sum = [0.0f32; 3];
        for mb in ms.iter().filter(|x| !x.gwa) {
            sum = add(sum, mb.c);
        }
        finish(sum)
    } else {
        base_value
    };
    let mut cache: HashMap<Vec<u32>, V3> = HashMap::new();
    for a in 0..m {
        out[a] = match kind[a] {
            Kind::Gwa => full_value,
            Kind::Nan => finish(add([0.0; 3], ms[a].c)),
            Kind::Regular | Kind::Irregular if exc[a].is_empty() => base_value,
            Kind::Regular | Kind::Irregular => {
                let mut key: Vec<u32> = exc[a].iter().map(|&b| pos_in_base[b as usize]).collect();
                key.sort_unstable();
                key.dedup();
                if let Some(v) = cache.get(&key) {
                    *v
                } else {
                    let first = key[0] as usize;
                    let mut sum = prefix[first];
                    let mut skip = key.iter().peekable();
                    for (i, &b) in base.iter().enumerate().skip(first) {
                        if skip.peek().is_some_and(|&&x| x as usize == i) {
                            skip.next();
                            continue;
                        }
                        sum = add(sum, ms[b].c);
                    }
                    let v = finish(sum);
                    cache.insert(key, v);
                    v
                }
            }
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference's definition, literally: per member, its sub-group, summed in order.
    fn brute(ms: &[Member], out: &mut [V3]) {
        for a in 0..ms.len() {
            let mut sum = [0.0f32; 3];
            for b in 0..ms.len() {
                let inc = ms[a].gwa || ms[b].gwa || a == b || compatible(&ms[a], &ms[b]);
                if inc && !ms[b].gwa {
                    sum = add(sum, ms[b].c);
                }
            }
            out[a] = finish(sum);
        }
    }

    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        }
        fn f(&mut self) -> f32 {
            (self.next() >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        }
        fn below(&mut self, n: u64) -> u64 {
            self.next() % n
        }
    }

    fn vector(r: &mut Rng, earlier: &[V3]) -> V3 {
        match r.below(12) {
            0 | 1 if !earlier.is_empty() => {
                let e = earlier[r.below(earlier.len() as u64) as usize];
                [-e[0], -e[1], -e[2]]
            }
            2 if !earlier.is_empty() => earlier[r.below(earlier.len() as u64) as usize],
            3 => [0.0; 3],
            4 if r.below(4) == 0 => [f32::NAN, 0.0, 1.0],
            5 if r.below(4) == 0 => {
                // Off unit length, or infinite.
                match r.below(3) {
                    0 => [1.001, 0.0, 0.0],
                    1 => [f32::INFINITY, 1.0, 0.0],
                    _ => [-0.7, -0.7, 0.2],
                }
            }
            6 => {
                // Axis-aligned units and their near-antipodes (rounding decides).
                let ax = r.below(3) as usize;
                let mut v = [0.0; 3];
                v[ax] = if r.below(2) == 0 { 1.0 } else { -1.0 };
                v
            }
            _ => normalized_or_zero([r.f(), r.f(), r.f()]),
        }
    }

    #[test]
    fn large_path_equals_definition() {
        let mut r = Rng(7);
        let mut differing = 0;
        for case in 0..400 {
            let m = 33 + r.below(150) as usize;
            let mut ss: Vec<V3> = Vec::new();
            let mut ts: Vec<V3> = Vec::new();
            let mut ms = Vec::new();
            for _ in 0..m {
                let s = vector(&mut r, &ss);
                let t = vector(&mut r, &ts);
                ss.push(s);
                ts.push(t);
                let gwa = r.below(20) == 0;
                let c = if gwa { [0.0; 3] } else { scale(r.f().abs() * 3.0, s) };
                ms.push(Member { s, t, gwa, c });
            }
            let mut a = vec![[0.0f32; 3]; m];
            let mut b = vec![[0.0f32; 3]; m];
            large(&ms, &mut a);
            brute(&ms, &mut b);
            for i in 0..m {
                let same =
                    a[i].iter().zip(&b[i]).all(|(x, y)| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()));
                assert!(same, "case {case} member {i}: {:?} vs {:?}", a[i], b[i]);
            }
            // Count cases whose outputs are not all equal (exclusions actually happened).
            if b.iter().any(|v| v.iter().zip(&b[0]).any(|(x, y)| x.to_bits() != y.to_bits())) {
                differing += 1;
            }
        }
        assert!(differing > 100, "too few cases exercise exclusions: {differing}");
    }

    #[test]
    fn quick_test_implies_definition() {
        let mut r = Rng(5);
        let mut hits = 0;
        for _ in 0..3000 {
            let m = 1 + r.below(60) as usize;
            let base = [normalized_or_zero([r.f(), r.f(), r.f()]), normalized_or_zero([r.f(), r.f(), r.f()])];
            let spread = [0.1f32, 0.5, 0.9, 1.5][r.below(4) as usize];
            let ms: Vec<Member> = (0..m)
                .map(|_| {
                    let jitter = |v: V3, r: &mut Rng| {
                        normalized_or_zero([v[0] + spread * r.f(), v[1] + spread * r.f(), v[2] + spread * r.f()])
                    };
                    let s = jitter(base[0], &mut r);
                    let t = jitter(base[1], &mut r);
                    let gwa = r.below(15) == 0;
                    Member { s, t, gwa, c: scale(r.f().abs(), s) }
                })
                .collect();
            if all_compatible(&ms) {
                hits += 1;
                for a in 0..m {
                    for b in 0..m {
                        assert!(ms[a].gwa || ms[b].gwa || compatible(&ms[a], &ms[b]));
                    }
                }
            }
        }
        assert!(hits > 500, "{hits}");
    }

    #[test]
    fn small_path_equals_definition() {
        let mut r = Rng(11);
        for _ in 0..2000 {
            let m = 1 + r.below(BRUTE_MAX as u64) as usize;
            let mut ss: Vec<V3> = Vec::new();
            let mut ms = Vec::new();
            for _ in 0..m {
                let s = vector(&mut r, &ss);
                ss.push(s);
                let t = vector(&mut r, &ss);
                let gwa = r.below(10) == 0;
                let c = if gwa { [0.0; 3] } else { scale(r.f().abs(), t) };
                ms.push(Member { s, t, gwa, c });
            }
            let mut a = vec![[0.0f32; 3]; m];
            let mut b = vec![[0.0f32; 3]; m];
            small(&ms, &mut a);
            brute(&ms, &mut b);
            for i in 0..m {
                assert!(a[i].iter().zip(&b[i]).all(|(x, y)| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan())));
            }
        }
    }
}
