//! Searches over large arrays on every core, a block of items a task: rayon's `position_first`
//! and `any` on single items check a shared flag item by item, which made the check for
//! non-finite vertices take 48 ms on 5M vertices (5 ms a block at a time).

use rayon::prelude::*;

/// Items a task: a fixed number, so that the work splits alike on any core count.
const BLOCK: usize = 1 << 14;

/// The index of the first item of `v` for which `bad` holds, searched on every core.
pub fn first<T: Sync>(v: &[T], bad: impl Fn(&T) -> bool + Sync) -> Option<usize> {
    let b = v.par_chunks(BLOCK).position_first(|c| c.iter().any(&bad))?;
    let k = v[b * BLOCK..].iter().position(&bad)?;
    Some(b * BLOCK + k)
}

/// Whether `bad` holds for any item of `v`, searched on every core.
pub fn any<T: Sync>(v: &[T], bad: impl Fn(&T) -> bool + Sync) -> bool {
    v.par_chunks(BLOCK).any(|c| c.iter().any(&bad))
}

/// Whether `a` and `b` hold the same items, compared on every core.
pub fn same<T: PartialEq + Sync>(a: &[T], b: &[T]) -> bool {
    a.len() == b.len() && a.par_chunks(BLOCK).zip(b.par_chunks(BLOCK)).all(|(x, y)| x == y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_finds_the_first_match_across_blocks() {
        assert!(!same(&[0u32; 3], &[0u32; 2]));
        let mut v = vec![0u32; 3 * BLOCK + 7];
        assert_eq!(first(&v, |&x| x > 0), None);
        assert!(!any(&v, |&x| x > 0));
        for at in [0, BLOCK - 1, BLOCK, 2 * BLOCK + 3, v.len() - 1] {
            v[at] = 1;
            // A later match does not hide the first.
            let last = v.len() - 1;
            v[last] = 1;
            assert_eq!(first(&v, |&x| x > 0), Some(at));
            assert!(any(&v, |&x| x > 0));
            assert!(!same(&v, &vec![0u32; v.len()]) && same(&v, &v.clone()));
            v.iter_mut().for_each(|x| *x = 0);
        }
    }
}
