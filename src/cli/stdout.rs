//! Standard output for reports. A reader that stops early (`bumpbake inspect --json *.glb | head`)
//! closes the pipe; that ends the output quietly instead of a panic, and the command still exits
//! with the code its work earned, so a pipeline's status stays truthful.

use bumpbake::{Error, Result};
use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

static CLOSED: AtomicBool = AtomicBool::new(false);

/// Writes `s` to stdout; a closed pipe makes this and every later call a no-op.
pub fn print(s: &str) -> Result<()> {
    write_all(s.as_bytes())
}

pub fn write_all(bytes: &[u8]) -> Result<()> {
    if CLOSED.load(Ordering::Relaxed) {
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
