//! Running one job over many inputs: in parallel, one failure never stopping the others, results
//! in input order so reports are deterministic, and a progress bar only where a person watches.

use crate::error::{Error, Result};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

/// How a batch runs.
#[derive(Debug, Clone, Copy, Default)]
pub struct BatchOptions {
    /// Files processed at once; 0 means one per core.
    pub jobs: usize,
    /// Show a progress bar even when stderr is not a terminal or CI is set.
    pub force_progress: bool,
    /// Never show a progress bar.
    pub quiet: bool,
}

/// True when a progress bar should be drawn: a terminal, not CI, not quiet.
pub fn progress_wanted(force: bool, quiet: bool) -> bool {
    if quiet {
        return false;
    }
    force
        || (std::io::stderr().is_terminal()
            && std::env::var_os("CI").map(|v| v.is_empty() || v == "false").unwrap_or(true))
}

/// Runs `job` on every input, `opts.jobs` at a time; results come back in input order.
pub fn run<T: Send>(
    inputs: &[PathBuf],
    opts: &BatchOptions,
    job: impl Fn(&Path) -> Result<T> + Sync,
) -> Result<Vec<Result<T>>> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs)
        .build()
        .map_err(|e| Error::usage(format!("cannot start {} worker threads: {e}", opts.jobs)))?;
    let bar = (inputs.len() > 1 && progress_wanted(opts.force_progress, opts.quiet)).then(|| {
        let b = indicatif::ProgressBar::new(inputs.len() as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} files {elapsed} {wide_msg}")
                .expect("valid template"),
        );
        b
    });
    let results = pool.install(|| {
        use rayon::prelude::*;
        inputs
            .par_iter()
            .map(|p| {
                let r = job(p);
                if let Some(b) = &bar {
                    b.set_message(p.display().to_string());
                    b.inc(1);
                }
                r
            })
            .collect()
    });
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    Ok(results)
}

/// The output path for `input` in `dir`, with extension `ext`. Two inputs with the same stem
/// would collide, so callers check [`unique_outputs`].
pub fn derived_output(input: &Path, dir: &Path, ext: &str) -> PathBuf {
    let stem = input.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "out".into());
    dir.join(format!("{stem}.{ext}"))
}

/// Refuses a batch in which two inputs would write the same output.
pub fn unique_outputs(outputs: &[PathBuf]) -> Result<()> {
    let mut seen = std::collections::HashSet::new();
    for o in outputs {
        if !seen.insert(o) {
            return Err(Error::usage(format!(
                "two inputs would both write {}; give them different names",
                o.display()
            )));
        }
    }
    Ok(())
}
