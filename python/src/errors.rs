//! The library's errors as the package's exceptions (python/bumpbake/_errors.py), worded in
//! Python's terms: an option is named by its keyword, never by its command-line flag.

use bumpbake::error::{Setting, Wording};
use pyo3::prelude::*;
use pyo3::types::PyModule;

/// Settings as the package's keywords: `max_pixels`, `convention="directx"`, `overwrite=True`.
pub struct Keywords;

impl Wording for Keywords {
    fn name(&self, s: Setting) -> String {
        // The library's own names are the command line's field names, which are the keywords.
        s.name().to_string()
    }

    fn given(&self, s: Setting, value: &str) -> String {
        match value.parse::<f64>() {
            Ok(_) => format!("{}={value}", self.name(s)),
            Err(_) => format!("{}={value:?}", self.name(s)),
        }
    }

    fn on(&self, s: Setting) -> String {
        format!("{}=True", self.name(s))
    }
}

/// Words the library's messages in keywords from now on in this process. Called by the API's
/// calls, not at import: the console script imports this module too, and its process is the
/// command line, which installs its flags (the first wording installed stays).
pub fn speak_keywords() {
    bumpbake::error::install(&Keywords);
}

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

/// A library error as its exception, in [`Keywords`]; `words` then names as keywords any flag the
/// command line's own checks wrote into it.
pub fn from_library(py: Python<'_>, e: &bumpbake::Error, words: impl Fn(&str) -> String) -> PyErr {
    let kind = match e {
        bumpbake::Error::Input { .. } => Kind::Input,
        bumpbake::Error::Usage { .. } => Kind::Usage,
        bumpbake::Error::Output { .. } => Kind::Output,
    };
    raise(py, kind, words(&e.worded(&Keywords)))
}
