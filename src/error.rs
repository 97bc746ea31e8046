//! The one error type of the library. Every variant maps onto the exit codes of
//! `docs/conventions.md`: anything that stops a command is exit 2, with one line that names the
//! file and the problem.

use std::path::{Path, PathBuf};

/// Why a command could not finish.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The input could not be used: unreadable, malformed or unsupported.
    #[error("{}: {msg}", path.display())]
    Input { path: PathBuf, msg: String },
    /// The command line asks for something impossible.
    #[error("{0}")]
    Usage(String),
    /// An output could not be written.
    #[error("{}: cannot write: {msg}", path.display())]
    Output { path: PathBuf, msg: String },
}

impl Error {
    pub fn input(path: impl AsRef<Path>, msg: impl Into<String>) -> Self {
        Error::Input { path: path.as_ref().to_path_buf(), msg: msg.into() }
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

/// Attaches the file name to errors from lower layers that do not know it.
pub trait Context<T> {
    fn in_file(self, path: &Path) -> Result<T>;
}

impl<T, E: std::fmt::Display> Context<T> for std::result::Result<T, E> {
    fn in_file(self, path: &Path) -> Result<T> {
        self.map_err(|e| Error::input(path, e.to_string()))
    }
}
