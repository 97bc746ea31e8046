//! Running one job over many inputs: in parallel, one failure never stopping the others, results
//! in input order so reports are deterministic, and files done told to the caller's progress.

use crate::error::{Error, Result};
use crate::progress::Reporter;
use std::path::{Path, PathBuf};

/// How a batch runs.
#[derive(Debug, Clone, Default)]
pub struct BatchOptions {
    /// Files processed at once; 0 means one per core.
    pub jobs: usize,
    /// Told of every file done (stage `files`).
    pub progress: Reporter,
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
    let progress = &opts.progress;
    progress.start("files", inputs.len() as u64, "files");
    let results = pool.install(|| {
        use rayon::prelude::*;
        inputs
            .par_iter()
            .map(|p| {
                let r = job(p);
                progress.message(&p.display().to_string());
                progress.tick(1);
                r
            })
            .collect()
    });
    progress.finish();
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
