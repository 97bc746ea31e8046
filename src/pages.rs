//! Memory about to be written whole, its pages made present ahead of the writes: one call a few
//! megabytes instead of a page fault every four kilobytes. The build's and the reader's largest
//! arrays (the leaf-order triangles, the parsed vertices) are written once, into pages never
//! touched before, and the faults were a sixth of the tree build's time at 10M triangles
//! (`docs/transfer-history.md`). What is written, and so every output, is unchanged. And memory
//! about to be read, asked for ahead (`prefetch`), and a file's pages asked of the disk ahead of
//! its reader (`with_read_ahead`): hints, which change nothing either.

/// Makes the pages of `s` present and writable (Linux 5.14 and later; elsewhere, and where the
/// kernel declines, the writes fault the pages in as before), on every core.
pub fn prefault<T>(s: &mut [T]) {
    #[cfg(target_os = "linux")]
    linux::prefault(s.as_mut_ptr() as usize, std::mem::size_of_val(s));
    #[cfg(not(target_os = "linux"))]
    let _ = s;
}

/// Runs `read`, which reads `file` (`len` bytes) from its start to its end and tells how far it
/// has come (a byte offset) through the function it is given, while a thread of its own asks the
/// kernel for the file's pages up to 128 MB past that point. A file not wholly in the page
/// cache (just copied, or partly evicted since it was last read) is then read from disk behind
/// the reader, in large requests, instead of a page at a time as the reader's threads first
/// touch it, each waiting for its page. A file of a few MB is asked for whole before the read, with
/// no thread. The requests are hints (Linux's `POSIX_FADV_WILLNEED`;
/// elsewhere there is no thread): nothing read changes, and pages already cached cost a lookup.
pub fn with_read_ahead<R>(file: &std::fs::File, len: u64, read: impl FnOnce(&dyn Fn(u64)) -> R) -> R {
    #[cfg(target_os = "linux")]
    {
        linux::with_read_ahead(file, len, read)
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = (file, len);
        read(&|_| {})
    }
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

    /// How far ahead of its reader `with_read_ahead` asks for a file's pages: two of the OBJ
    /// reader's blocks, so that the next one is on its way while one is parsed.
    const READ_AHEAD: u64 = 128 << 20;
    /// Bytes a request: the kernel reads at most its readahead window a request (128 KB by
    /// default), so larger requests would be cut short.
    const READ_AHEAD_STEP: u64 = 128 << 10;
    /// Files up to this size are asked for whole before the read, on the reader's own thread: at
    /// most 32 requests, where a thread's start and end would cost more than the parse of a
    /// small file (a batch of many).
    const READ_AHEAD_INLINE: u64 = 4 << 20;

    pub fn with_read_ahead<R>(file: &std::fs::File, len: u64, read: impl FnOnce(&dyn Fn(u64)) -> R) -> R {
        use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
        if len <= READ_AHEAD_INLINE {
            (0..len)
                .step_by(READ_AHEAD_STEP as usize)
                .for_each(|at| will_need(file, at, READ_AHEAD_STEP.min(len - at)));
            return read(&|_| {});
        }
        let reached = AtomicU64::new(0);
        let stop = AtomicBool::new(false);
        std::thread::scope(|s| {
            let helper = std::thread::Builder::new()
                .name("read-ahead".into())
                .spawn_scoped(s, || {
                    let mut asked = 0;
                    while asked < len && !stop.load(Ordering::Acquire) {
                        let until = reached.load(Ordering::Acquire).saturating_add(READ_AHEAD).min(len);
                        if asked < until {
                            let n = READ_AHEAD_STEP.min(until - asked);
                            will_need(file, asked, n);
                            asked += n;
                        } else {
                            std::thread::park();
                        }
                    }
                })
                .ok();
            let wake = || {
                if let Some(h) = &helper {
                    h.thread().unpark();
                }
            };
            // Stops the thread however `read` ends, a panic included: the scope waits for it.
            struct Stop<'a, F: Fn()>(&'a AtomicBool, F);
            impl<F: Fn()> Drop for Stop<'_, F> {
                fn drop(&mut self) {
                    self.0.store(true, Ordering::Release);
                    (self.1)();
                }
            }
            let _stop = Stop(&stop, wake);
            read(&|at| {
                reached.fetch_max(at, Ordering::AcqRel);
                wake();
            })
        })
    }

    fn will_need(file: &std::fs::File, at: u64, len: u64) {
        use std::os::fd::AsRawFd;
        let (Ok(at), Ok(len)) = (libc::off_t::try_from(at), libc::off_t::try_from(len)) else { return };
        // SAFETY: the call reads no memory of ours; a descriptor it cannot use, or a range past
        // the end, is declined with an error, which a hint ignores.
        unsafe { libc::posix_fadvise(file.as_raw_fd(), at, len, libc::POSIX_FADV_WILLNEED) };
    }

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
    /// The reader's result comes back whatever it reports, its reports past the end included, and
    /// a reader that panics does not leave the helper waiting (the scope would never end).
    #[test]
    fn read_ahead_returns_and_ends() {
        // A small file (hints on the reader's thread) and a larger one (a helper thread).
        for (k, size) in [3u64 << 20, 9 << 20].into_iter().enumerate() {
            let path = std::env::temp_dir().join(format!("bumpbake-read-ahead-{}-{k}", std::process::id()));
            std::fs::write(&path, vec![7u8; size as usize]).unwrap();
            let file = std::fs::File::open(&path).unwrap();
            let len = file.metadata().unwrap().len();
            let sum = super::with_read_ahead(&file, len, |reached| {
                let bytes = std::fs::read(&path).unwrap();
                for at in (0..len + (1 << 20)).step_by(1 << 16) {
                    reached(at);
                }
                bytes.iter().map(|&b| b as u64).sum::<u64>()
            });
            assert_eq!(sum, 7 * size);
            let caught = std::panic::catch_unwind(|| super::with_read_ahead(&file, len, |_| -> u8 { panic!("stop") }));
            assert!(caught.is_err());
            std::fs::remove_file(&path).unwrap();
        }
    }

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
