//! What every `bench` subcommand shares: a scratch folder and the JSON-or-text printout.

use bumpbake::{Error, Result};
use std::path::Path;

/// Runs `f(bumpbake's own executable, a scratch folder)` for benchmark `what`, then removes the
/// folder.
pub(super) fn with_scratch<T>(what: &str, f: impl FnOnce(&Path, &Path) -> Result<T>) -> Result<T> {
    let exe =
        std::env::current_exe().map_err(|e| Error::usage(format!("bench {what}: cannot find bumpbake itself: {e}")))?;
    let dir = std::env::temp_dir().join(format!("bumpbake-bench-{what}-{}", std::process::id()));
    let r = f(&exe, &dir);
    let _ = std::fs::remove_dir_all(&dir);
    r
}

/// Prints `r` as JSON, or as `text(r)`.
pub(super) fn print<T: serde::Serialize>(r: &T, json: bool, text: impl FnOnce(&T) -> String) -> Result<()> {
    if json {
        outln!("{}", serde_json::to_string_pretty(r).expect("serialises"));
    } else {
        outln!("{}", text(r));
    }
    Ok(())
}
