//! The reference's "4-rule" groups: around each welded vertex, the fan of triangles reachable
//! across shared edges without changing UV orientation.
//!
//! Groups are seeded in the reference's order (good triangle, then corner) and grown over the
//! adjacency. The set a walk reaches does not depend on the walk order (a corner is passable or
//! not for the whole walk), so an explicit stack replaces the reference's recursion; member
//! order is irrelevant downstream (members are sorted before summation). The one global order
//! dependency of the reference is kept: a "group with anything" triangle takes the orientation
//! of the first group, in seeding order, that reaches it.

use super::neighbors::NONE;
use super::Welded;

/// Groups as flat arrays (CSR): group `g` owns `members[start[g]..start[g + 1]]`, each member a
/// list entry `3 * t + j` (good triangle `t`, corner `j` at the group's vertex); every member's
/// welded id is the group vertex's.
pub(crate) struct Groups {
    pub start: Vec<u32>,
    pub members: Vec<u32>,
    pub orient: Vec<bool>,
}

#[inline]
fn corner_of<W: Welded + ?Sized>(w: &W, u: usize, rep: u32) -> Option<usize> {
    (0..3).find(|&j| w.at(3 * u + j) == rep)
}

/// `gwa` and `orient` are [`super::triangles::Triangles`]' (`orient` is updated for "group with
/// anything" triangles).
pub(crate) fn build<W: Welded + ?Sized>(w: &W, nb: &[u32], gwa: &[bool], orient: &mut [bool]) -> Groups {
    let ng = gwa.len();
    let mut assigned = vec![false; 3 * ng];
    let mut g = Groups { start: vec![0], members: Vec::with_capacity(3 * ng), orient: Vec::new() };
    let mut stack: Vec<u32> = Vec::new();
    for t in 0..ng {
        if gwa[t] {
            continue;
        }
        for i in 0..3 {
            let k = 3 * t + i;
            if assigned[k] {
                continue;
            }
            let rep = w.at(k);
            let o = orient[t];
            assigned[k] = true;
            g.members.push(k as u32);
            stack.clear();
            // The reference recurses into edge (i + 2) % 3 first, then edge i.
            for e in [k - i + (i + 2) % 3, k] {
                if nb[e] != NONE {
                    stack.push(nb[e]);
                }
            }
            while let Some(u) = stack.pop() {
                let u = u as usize;
                let Some(j) = corner_of(w, u, rep) else { continue };
                let ku = 3 * u + j;
                if assigned[ku] {
                    continue;
                }
                if gwa[u] && !assigned[3 * u] && !assigned[3 * u + 1] && !assigned[3 * u + 2] {
                    orient[u] = o;
                }
                if orient[u] != o {
                    continue;
                }
                assigned[ku] = true;
                g.members.push(ku as u32);
                for e in [3 * u + (j + 2) % 3, ku] {
                    if nb[e] != NONE {
                        stack.push(nb[e]);
                    }
                }
            }
            g.start.push(g.members.len() as u32);
            g.orient.push(o);
        }
    }
    g
}
