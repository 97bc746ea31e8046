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
use super::triangles::Triangles;

/// Groups as flat arrays (CSR): group `g` owns `members[start[g]..start[g + 1]]`, each member a
/// list entry `3 * t + j` (good triangle `t`, corner `j` at the group's vertex).
pub(crate) struct Groups {
    pub start: Vec<u32>,
    pub members: Vec<u32>,
    /// Welded id (input corner id) of each group's vertex.
    pub rep: Vec<u32>,
    pub orient: Vec<bool>,
}

#[inline]
fn corner_of(w: &[u32], u: usize, rep: u32) -> Option<usize> {
    (0..3).find(|&j| w[3 * u + j] == rep)
}

pub(crate) fn build(w: &[u32], nb: &[u32], tri: &mut Triangles) -> Groups {
    let ng = tri.n_good;
    let mut assigned = vec![false; 3 * ng];
    let mut g = Groups {
        start: vec![0],
        members: Vec::with_capacity(3 * ng),
        rep: Vec::new(),
        orient: Vec::new(),
    };
    let mut stack: Vec<u32> = Vec::new();
    for t in 0..ng {
        if tri.gwa[t] {
            continue;
        }
        for i in 0..3 {
            let k = 3 * t + i;
            if assigned[k] {
                continue;
            }
            let rep = w[k];
            let o = tri.orient[t];
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
                if tri.gwa[u] && !assigned[3 * u] && !assigned[3 * u + 1] && !assigned[3 * u + 2] {
                    tri.orient[u] = o;
                }
                if tri.orient[u] != o {
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
            g.rep.push(rep);
            g.orient.push(o);
        }
    }
    g
}
