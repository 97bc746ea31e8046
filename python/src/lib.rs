//! `bumpbake._native`, the extension module under the `bumpbake` Python package: the library on
//! NumPy arrays (`arrays.rs`), and the command line (`commands.rs`) both as `bumpbake ...` and as
//! the file-level calls that return its JSON.
//!
//! The package's Python side (python/bumpbake/) checks and converts arrays, names the keywords
//! and raises the typed exceptions; this side does the work with the GIL released.

// The command line is the binary's (src/cli/): compiled in here as it is, so that
// `python -m bumpbake` and the console script are the same program as `bumpbake`, and the
// file-level calls print the same JSON.
#[path = "../../src/cli/mod.rs"]
#[allow(dead_code)]
mod cli;

mod arrays;
mod commands;
mod errors;
mod progress;

use pyo3::prelude::*;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(arrays::tangents, m)?)?;
    m.add_function(wrap_pyfunction!(arrays::normalmap, m)?)?;
    m.add_function(wrap_pyfunction!(arrays::bump_to_normal, m)?)?;
    m.add_function(wrap_pyfunction!(arrays::strength, m)?)?;
    m.add_function(wrap_pyfunction!(commands::run, m)?)?;
    m.add_function(wrap_pyfunction!(commands::main, m)?)?;
    m.add_function(wrap_pyfunction!(commands::options, m)?)?;
    Ok(())
}
