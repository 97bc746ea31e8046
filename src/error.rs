//! The one error type of the library. Every variant maps onto the exit codes of
//! `docs/conventions.md`: anything that stops a command is exit 2, with one line that names the
//! file and the problem.

use std::path::{Path, PathBuf};

/// Why a command could not finish.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The input could not be used: unreadable, malformed or unsupported.
    #[error("{}: {msg}", path.display())]
    Input {
        path: PathBuf,
        msg: String,
        /// What a library reported underneath, when a [`Fault`] carried it.
        #[source]
        cause: Option<Box<dyn std::error::Error + Send + Sync + 'static>>,
    },
    /// The command line asks for something impossible.
    #[error("{0}")]
    Usage(String),
    /// An output could not be written.
    #[error("{}: cannot write: {msg}", path.display())]
    Output { path: PathBuf, msg: String },
}

impl Error {
    pub fn input(path: impl AsRef<Path>, msg: impl Into<String>) -> Self {
        Error::Input { path: path.as_ref().to_path_buf(), msg: msg.into(), cause: None }
    }
    /// A reader's [`Fault`] in the file `path`, its cause kept.
    pub fn in_file(path: impl AsRef<Path>, fault: Fault) -> Self {
        Error::Input { path: path.as_ref().to_path_buf(), msg: fault.msg, cause: fault.source }
    }
    pub fn output(path: impl AsRef<Path>, msg: impl std::fmt::Display) -> Self {
        Error::Output { path: path.as_ref().to_path_buf(), msg: msg.to_string() }
    }
    pub fn usage(msg: impl Into<String>) -> Self {
        Error::Usage(msg.into())
    }
    /// The process exit code the conventions give this error.
    pub fn exit_code(&self) -> u8 {
        2
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

/// What went wrong inside some bytes, before the caller knows which file they came from: the
/// words a user reads and, where a library reported it, the error underneath (kept as the
/// `source`, so the chain is there for whoever walks it). The readers' and decoders' error;
/// [`Error::in_file`] turns it into an [`Error`] that names the file.
#[derive(Debug, thiserror::Error)]
#[error("{msg}")]
pub struct Fault {
    msg: String,
    #[source]
    source: Option<Box<dyn std::error::Error + Send + Sync + 'static>>,
}

impl Fault {
    pub fn new(msg: impl Into<String>) -> Self {
        Fault { msg: msg.into(), source: None }
    }

    /// A fault whose cause is `source`; `msg` says what it meant here.
    pub fn caused_by(msg: impl Into<String>, source: impl std::error::Error + Send + Sync + 'static) -> Self {
        Fault { msg: msg.into(), source: Some(Box::new(source)) }
    }

    /// The same fault, its words prefixed with where it happened.
    pub fn at(self, place: impl std::fmt::Display) -> Self {
        Fault { msg: format!("{place}: {}", self.msg), source: self.source }
    }
}

impl From<String> for Fault {
    fn from(msg: String) -> Self {
        Fault::new(msg)
    }
}

impl From<&str> for Fault {
    fn from(msg: &str) -> Self {
        Fault::new(msg)
    }
}

/// A reader's result, its file not named yet.
pub type Faulty<T> = std::result::Result<T, Fault>;
