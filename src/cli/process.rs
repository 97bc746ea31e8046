//! What the process does before any work: glibc's allocator tuned for the command's arrays, and
//! signals that remove the temporaries being written. For whatever runs the command line as a
//! whole process: the `bumpbake` binary, and the Python package's console script.

/// Two of glibc's allocator parameters, set before any other thread exists.
///
/// The mmap threshold, fixed at 8 MB: glibc serves allocations under it from heaps it keeps
/// after they are freed, and raises it (up to 32 MB) each time a large block is freed. A mesh's
/// per-corner arrays are a few MB to tens of MB each and live one stage at a time, so with the
/// default they pile up as resident memory nobody uses: the 1M-triangle `tangents` run peaked at
/// 197 MB resident for 138 MB of live heap. Fixed, every such array is mapped on its own and
/// unmapped when freed: 150 MB, for about 0.05-0.1 s more (fresh pages are zeroed by the kernel
/// instead of reused).
///
/// The top pad, 64 MB for `bake --from` only: that command frees, stage after stage, arrays the
/// next stage's arrays could live in (the tree build's items and per-range trees, the texels, the
/// map's normals). By default glibc gives back the free top of a heap past 128 KB, and the next
/// array faults every page in again. Keeping 64 MB free at the top of each heap lets the next
/// stage reuse them: on the 600k-triangle bench, 34k page faults instead of 45k and 4-5% less
/// time, for 12 MB more peak (docs/transfer-history.md). Other commands keep the default pad: their
/// figures are peak memory against the mesh.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
pub fn tune_the_allocator(bakes_from_high: bool) {
    // SAFETY: mallopt only sets allocator parameters; no other thread exists yet.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 8 << 20);
        if bakes_from_high {
            libc::mallopt(libc::M_TOP_PAD, 64 << 20);
        }
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
pub fn tune_the_allocator(_bakes_from_high: bool) {}

/// SIGINT, SIGTERM and SIGHUP (Ctrl-C, a build system or CI cancelling the run) remove the
/// temporaries being written, then end the process with 128 + the signal, as a shell reports it.
/// The signals are blocked in every thread and taken by one that waits for them, so the cleanup
/// runs as ordinary code rather than in a signal handler. Children get a fresh mask from std.
#[cfg(unix)]
pub fn clean_up_on_signals() {
    // SAFETY: plain libc calls on a sigset_t owned here, before any other thread exists, so every
    // thread started later inherits the blocked mask.
    unsafe {
        let mut set: libc::sigset_t = std::mem::zeroed();
        libc::sigemptyset(&mut set);
        for sig in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
            libc::sigaddset(&mut set, sig);
        }
        if libc::pthread_sigmask(libc::SIG_BLOCK, &set, std::ptr::null_mut()) != 0 {
            return;
        }
        std::thread::spawn(move || {
            let mut sig = 0;
            if libc::sigwait(&set, &mut sig) == 0 {
                bumpbake::output::abandon_temporaries();
                std::process::exit(128 + sig);
            }
        });
    }
}

#[cfg(not(unix))]
pub fn clean_up_on_signals() {}
