//! The library's errors as the package's exceptions (python/bumpbake/_errors.py), worded in
//! Python's terms: an option is named by its keyword, never by its command-line flag.

use pyo3::prelude::*;
use pyo3::types::PyModule;

/// Which exception class of `bumpbake` an error raises.
#[derive(Clone, Copy)]
pub enum Kind {
    /// A file or array that cannot be used (the command line's exit 2 on input).
    Input,
    /// An option that asks for something impossible; also a `ValueError`.
    Usage,
    /// An output that could not be written; also an `OSError`.
    Output,
}

impl Kind {
    fn class(self) -> &'static str {
        match self {
            Kind::Input => "InputError",
            Kind::Usage => "UsageError",
            Kind::Output => "OutputError",
        }
    }
}

/// The exception `kind` with `msg`.
pub fn raise(py: Python<'_>, kind: Kind, msg: impl Into<String>) -> PyErr {
    let msg = msg.into();
    match PyModule::import(py, "bumpbake._errors").and_then(|m| m.getattr(kind.class())) {
        Ok(class) => match class.call1((msg,)) {
            Ok(e) => PyErr::from_value(e),
            Err(e) => e,
        },
        Err(e) => e,
    }
}

/// A library error as its exception, its words through `words` (the command line's flags turned
/// into keywords).
pub fn from_library(py: Python<'_>, e: &bumpbake::Error, words: impl Fn(&str) -> String) -> PyErr {
    let kind = match e {
        bumpbake::Error::Input { .. } => Kind::Input,
        bumpbake::Error::Usage(_) => Kind::Usage,
        bumpbake::Error::Output { .. } => Kind::Output,
    };
    raise(py, kind, words(&e.to_string()))
}
