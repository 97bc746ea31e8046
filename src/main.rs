//! The `bumpbake` binary: parses the command line, runs the library, reports, and maps the
//! outcome onto the exit codes of the conventions (0 done, 1 validation failed, 2 unusable input).

mod cli;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    return_large_blocks_to_the_system();
    clean_up_on_signals();
    let args = cli::Cli::parse();
    if args.bakes_from_high() {
        keep_freed_heap_for_the_next_stage();
    }
    match cli::run(args) {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            eprintln!("bumpbake: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}

/// glibc serves allocations under its mmap threshold from heaps it keeps after they are freed,
/// and raises that threshold (up to 32 MB) each time a large block is freed. A mesh's
/// per-corner arrays are a few MB to tens of MB each and live one stage at a time, so with the
/// default they pile up as resident memory nobody uses: the 1M-triangle `tangents` run peaked at
/// 197 MB resident for 138 MB of live heap. A fixed 8 MB threshold maps every such array on its
/// own and unmaps it when it is freed: 150 MB, for about 0.05-0.1 s more (fresh pages are zeroed
/// by the kernel instead of reused).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn return_large_blocks_to_the_system() {
    // SAFETY: mallopt only sets an allocator parameter; it is called before any thread exists.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 8 << 20);
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn return_large_blocks_to_the_system() {}

/// `bake --from` frees, stage after stage, arrays of a few to tens of MB that the next stage's
/// arrays could live in (the BVH build's items and per-range trees, the tree's copy, the ray
/// stage's texels, the map's normals). By default glibc gives back the free top of a heap past
/// 128 KB, and the next array faults every page in again, zeroed by the kernel. Keeping 64 MB
/// free at the top of each heap lets the next stage reuse them: on the 600k-triangle bench,
/// 34k page faults instead of 45k and 4-5% less time, for 12 MB more peak (docs/transfer.md).
/// Other commands keep glibc's default: their figures are peak memory against the mesh.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn keep_freed_heap_for_the_next_stage() {
    // SAFETY: mallopt only sets an allocator parameter (under glibc's own lock).
    unsafe {
        libc::mallopt(libc::M_TOP_PAD, 64 << 20);
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn keep_freed_heap_for_the_next_stage() {}

/// SIGINT, SIGTERM and SIGHUP (Ctrl-C, a build system or CI cancelling the run) remove the
/// temporaries being written, then end the process with 128 + the signal, as a shell reports it.
/// The signals are blocked in every thread and taken by one that waits for them, so the cleanup
/// runs as ordinary code rather than in a signal handler. Children get a fresh mask from std.
#[cfg(unix)]
fn clean_up_on_signals() {
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
fn clean_up_on_signals() {}
