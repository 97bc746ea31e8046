//! Memory about to be written whole, its pages made present ahead of the writes: one call a few
//! megabytes instead of a page fault every four kilobytes. The build's and the reader's largest
//! arrays (the leaf-order triangles, the parsed vertices) are written once, into pages never
//! touched before, and the faults were a sixth of the tree build's time at 10M triangles
//! (`docs/transfer-history.md`). What is written, and so every output, is unchanged. And memory
//! about to be read, asked for ahead (`prefetch`): a hint, which changes nothing either.

/// Makes the pages of `s` present and writable (Linux 5.14 and later; elsewhere, and where the
/// kernel declines, the writes fault the pages in as before), on every core.
pub fn prefault<T>(s: &mut [T]) {
    #[cfg(target_os = "linux")]
    linux::prefault(s.as_mut_ptr() as usize, std::mem::size_of_val(s));
    #[cfg(not(target_os = "linux"))]
    let _ = s;
}

/// The most bytes [`prefetch`] asks for at once (four cache lines).
const PREFETCH_MAX: usize = 256;

/// Asks the CPU to start loading the first [`PREFETCH_MAX`] bytes of `s` into its cache, so that
/// a later read finds them there. A prefetch reads nothing and cannot fault.
#[inline(always)]
pub fn prefetch<T>(s: &[T]) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let start: *const u8 = s.as_ptr().cast();
        for off in (0..std::mem::size_of_val(s).min(PREFETCH_MAX)).step_by(64) {
            // SAFETY: a prefetch is a hint: it reads nothing and cannot fault, and the address
            // stays inside `s`.
            unsafe { _mm_prefetch::<_MM_HINT_T0>(start.wrapping_add(off).cast()) };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = s;
}

#[cfg(target_os = "linux")]
mod linux {
    use rayon::prelude::*;

    /// Below this, the faults cost less than the calls.
    const MIN_BYTES: usize = 1 << 20;
    /// Bytes a call: a fixed size, so that the work splits alike on any core count.
    const CHUNK: usize = 4 << 20;
    const PAGE: usize = 4096;

    pub fn prefault(at: usize, len: usize) {
        let (start, end) = (at.div_ceil(PAGE) * PAGE, (at + len) / PAGE * PAGE);
        if end < start + MIN_BYTES {
            return;
        }
        (start..end).into_par_iter().step_by(CHUNK).for_each(|a| {
            // SAFETY: the range lies inside memory the caller holds a unique borrow of; the call
            // only makes its pages present, leaving their bytes as they are. Its result is
            // ignored: declining leaves the memory as it was.
            unsafe { libc::madvise(a as *mut libc::c_void, CHUNK.min(end - a), libc::MADV_POPULATE_WRITE) };
        });
    }
}

#[cfg(test)]
mod tests {
    /// Bytes already written stay as they are, and memory made present is still written
    /// whole by its owner (a vector's spare capacity, as the build and the reader use it).
    #[test]
    fn prefault_keeps_what_is_there() {
        let n = 3 << 20;
        let mut v: Vec<u32> = (0..n as u32).map(|i| i.wrapping_mul(0x9e37_79b9)).collect();
        super::prefault(&mut v);
        assert!(v.iter().enumerate().all(|(i, &x)| x == (i as u32).wrapping_mul(0x9e37_79b9)));
        let mut w: Vec<u64> = Vec::with_capacity(n);
        super::prefault(w.spare_capacity_mut());
        w.extend((0..n as u64).map(|i| i * 3));
        assert_eq!(w.iter().sum::<u64>(), 3 * (n as u64 - 1) * n as u64 / 2);
    }
}
