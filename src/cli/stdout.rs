//! Standard output for reports. A reader that stops early (`bumpbake inspect --json *.glb | head`)
//! closes the pipe; that ends the output quietly instead of a panic, and the command still exits
//! with the code its work earned, so a pipeline's status stays truthful.

use bumpbake::{Error, Result};
use std::cell::RefCell;
use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

static CLOSED: AtomicBool = AtomicBool::new(false);

thread_local! {
    /// Where this thread's output goes instead of stdout while [`captured`] runs.
    static CAPTURE: RefCell<Option<Vec<u8>>> = const { RefCell::new(None) };
}

/// Runs `f` with this thread's output collected instead of printed: how a front end that calls
/// the command line in-process (the Python package's file-level calls) takes its JSON.
#[allow(dead_code, reason = "the Python binding (python/) compiles this module and calls it")]
pub fn captured<T>(f: impl FnOnce() -> T) -> (T, Vec<u8>) {
    CAPTURE.with(|c| *c.borrow_mut() = Some(Vec::new()));
    let r = f();
    (r, CAPTURE.with(|c| c.borrow_mut().take()).unwrap_or_default())
}

/// Writes `s` to stdout; a closed pipe makes this and every later call a no-op.
pub fn print(s: &str) -> Result<()> {
    write_all(s.as_bytes())
}

pub fn write_all(bytes: &[u8]) -> Result<()> {
    let taken = CAPTURE.with(|c| c.borrow_mut().as_mut().map(|buf| buf.extend_from_slice(bytes)).is_some());
    if taken || CLOSED.load(Ordering::Relaxed) {
        return Ok(());
    }
    let mut o = std::io::stdout().lock();
    match o.write_all(bytes).and_then(|_| o.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => {
            CLOSED.store(true, Ordering::Relaxed);
            Ok(())
        }
        Err(e) => Err(Error::output("standard output", e)),
    }
}

/// `println!` through [`print`]; an error returns from the calling function.
macro_rules! outln {
    ($($t:tt)*) => {
        $crate::cli::stdout::print(&format!("{}\n", format_args!($($t)*)))?
    };
}

/// `print!` through [`print`].
macro_rules! out {
    ($($t:tt)*) => {
        $crate::cli::stdout::print(&format!($($t)*))?
    };
}
