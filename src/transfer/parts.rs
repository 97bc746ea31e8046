//! LOW and HIGH parts paired by name, as Substance Painter's "match by mesh name" and Marmoset
//! Toolbag's bake groups do: `ring_low` bakes only from `ring_high`, so touching parts do not bake
//! into each other.
//!
//! A name's key is the name without any `.001`-style number at its end, lower-cased, and without
//! a `_low`/`_lo` (LOW) or `_high`/`_hi` (HIGH) suffix. A LOW and a HIGH part pair when their keys
//! are equal and at least one of the two had a suffix; every part sharing a key forms one group.
//! Rays from a LOW part in a group meet only that group's HIGH parts; the other LOW parts see
//! every HIGH part no group took.

/// How LOW parts find their HIGH parts.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Match {
    /// Pair parts whose names differ only by `_low`/`_high` (or `_lo`/`_hi`).
    #[default]
    Auto,
    /// Every LOW part sees every HIGH part.
    None,
}

/// The HIGH parts each LOW part's rays may meet.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Groups {
    /// Per set, the HIGH parts in it (ascending). One set per group, then the unmatched set.
    pub sets: Vec<Vec<usize>>,
    /// Per LOW part, the set its rays meet.
    pub low_set: Vec<usize>,
    /// Per group: the LOW and HIGH part indices paired.
    pub pairs: Vec<(Vec<usize>, Vec<usize>)>,
}

/// `name` without a trailing `.NNN`, lower-cased, and whether one of `suffixes` came off it.
fn key(name: &str, suffixes: &[&str]) -> (String, bool) {
    let mut n = name.trim();
    if let Some((head, tail)) = n.rsplit_once('.') {
        if !tail.is_empty() && tail.bytes().all(|b| b.is_ascii_digit()) {
            n = head;
        }
    }
    let lower = n.to_lowercase();
    for s in suffixes {
        if let Some(k) = lower.strip_suffix(s) {
            if !k.is_empty() {
                return (k.to_string(), true);
            }
        }
    }
    (lower, false)
}

pub fn low_key(name: &str) -> (String, bool) {
    key(name, &["_low", "_lo"])
}

pub fn high_key(name: &str) -> (String, bool) {
    key(name, &["_high", "_hi"])
}

/// Pairs LOW parts `low` with HIGH parts `high` (names).
pub fn group(low: &[String], high: &[String], m: Match) -> Groups {
    let all: Vec<usize> = (0..high.len()).collect();
    if m == Match::None {
        return Groups { sets: vec![all], low_set: vec![0; low.len()], pairs: Vec::new() };
    }
    let lk: Vec<(String, bool)> = low.iter().map(|n| low_key(n)).collect();
    let hk: Vec<(String, bool)> = high.iter().map(|n| high_key(n)).collect();
    let mut g = Groups::default();
    let mut low_group: Vec<Option<usize>> = vec![None; low.len()];
    let mut taken = vec![false; high.len()];
    for i in 0..low.len() {
        if low_group[i].is_some() {
            continue;
        }
        let (k, ls) = &lk[i];
        let highs: Vec<usize> = (0..high.len()).filter(|&j| hk[j].0 == *k && (*ls || hk[j].1)).collect();
        if highs.is_empty() {
            continue;
        }
        // Every LOW part with this key joins (a `ring_low.001` beside `ring_low`).
        let lows: Vec<usize> = (i..low.len()).filter(|&x| lk[x].0 == *k && low_group[x].is_none()).collect();
        for &x in &lows {
            low_group[x] = Some(g.sets.len());
        }
        for &j in &highs {
            taken[j] = true;
        }
        g.sets.push(highs.clone());
        g.pairs.push((lows, highs));
    }
    let rest = g.sets.len();
    g.sets.push((0..high.len()).filter(|&j| !taken[j]).collect());
    g.low_set = low_group.into_iter().map(|x| x.unwrap_or(rest)).collect();
    g
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn keys_drop_numbers_case_and_suffixes() {
        assert_eq!(low_key("Ring_LOW.001"), ("ring".into(), true));
        assert_eq!(low_key("cap_lo"), ("cap".into(), true));
        assert_eq!(high_key("cap_Hi.12"), ("cap".into(), true));
        assert_eq!(high_key("bolt"), ("bolt".into(), false));
        // Only a trailing all-digit part is a number, and a bare suffix is a name.
        assert_eq!(high_key("v1.5a_high"), ("v1.5a".into(), true));
        assert_eq!(low_key("_low"), ("_low".into(), false));
    }

    #[test]
    fn pairs_by_suffix_and_leaves_the_rest_together() {
        let low = names(&["ring_low", "cap_low", "base", "Cap_low.001"]);
        let high = names(&["cap_high", "ring_high", "ring_high.001", "base", "screw_high"]);
        let g = group(&low, &high, Match::Auto);
        assert_eq!(g.pairs, vec![(vec![0], vec![1, 2]), (vec![1, 3], vec![0])]);
        // `base` carries no suffix on either side: unmatched, it sees every unmatched HIGH part.
        assert_eq!(g.sets, vec![vec![1, 2], vec![0], vec![3, 4]]);
        assert_eq!(g.low_set, vec![0, 1, 2, 1]);
        let n = group(&low, &high, Match::None);
        assert_eq!((n.sets, n.low_set, n.pairs.len()), (vec![vec![0, 1, 2, 3, 4]], vec![0; 4], 0));
    }
}
