//! The command line every command over many inputs shares: the inputs, where their outputs go,
//! and how the batch runs (`print` prints its results).

use bumpbake::batch::{self, BatchOptions};
use bumpbake::{Error, Result};
use std::path::{Path, PathBuf};

/// Mesh inputs and where their outputs go, shared by `tangents` and `bake`.
#[derive(clap::Args, Debug)]
pub struct MeshIo {
    /// Input meshes: .obj (with its .mtl), .gltf or .glb.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Output file (one input): .gltf (with a .bin beside it) or .glb.
    #[arg(short, long, conflicts_with = "out_dir")]
    pub output: Option<PathBuf>,
    /// Extension of the outputs written into --out-dir.
    #[arg(long, value_parser = ["glb", "gltf"], default_value = "glb")]
    pub out_ext: String,
    /// Let URIs reach outside the input's folder.
    #[arg(long)]
    pub allow_outside: bool,
    /// Write a Make/Ninja depfile (one input) listing every file read.
    #[arg(long)]
    pub depfile: Option<PathBuf>,
}

impl MeshIo {
    /// The output path of each input, after checking the options fit the number of inputs.
    pub fn outputs(&self, out_dir: &Option<PathBuf>) -> Result<Vec<PathBuf>> {
        if self.depfile.is_some() && self.inputs.len() > 1 {
            return Err(Error::usage("--depfile takes one input"));
        }
        outputs(&self.inputs, &self.output, out_dir, &self.out_ext)
    }
}

/// The options every command over many inputs shares.
#[derive(clap::Args, Debug)]
pub struct BatchArgs {
    /// Output folder (any number of inputs); names follow the inputs.
    #[arg(long)]
    pub out_dir: Option<PathBuf>,
    /// Files processed at once (default: one per core).
    #[arg(short, long, default_value_t = 0)]
    pub jobs: usize,
    /// Print one JSON record per file on stdout (JSON Lines).
    #[arg(long)]
    pub json: bool,
    /// Show a progress bar even when not on a terminal.
    #[arg(long)]
    pub progress: bool,
    /// No report on stderr.
    #[arg(short, long)]
    pub quiet: bool,
}

impl BatchArgs {
    /// How to run `inputs`: a bar over the files when there are several and a person watches.
    pub fn options(&self, inputs: usize) -> BatchOptions {
        let bar = inputs > 1 && super::progress::wanted(self.progress, self.quiet || self.json);
        BatchOptions { jobs: self.jobs, progress: super::progress::reporter(bar) }
    }

    /// Bars for one input's reads and bakes, when it is the only one and a person watches.
    pub fn single_progress(&self, inputs: usize) -> bumpbake::progress::Reporter {
        super::progress::reporter(inputs == 1 && super::progress::wanted(self.progress, self.quiet || self.json))
    }
}

/// Output paths for the inputs: `-o` for one input, or names derived into `--out-dir`.
pub fn outputs(
    inputs: &[PathBuf],
    output: &Option<PathBuf>,
    out_dir: &Option<PathBuf>,
    ext: &str,
) -> Result<Vec<PathBuf>> {
    let outs: Vec<PathBuf> = match (output, out_dir) {
        (Some(o), None) if inputs.len() == 1 => vec![o.clone()],
        (Some(_), None) => return Err(Error::usage("several inputs need --out-dir, not -o")),
        (None, Some(d)) => {
            std::fs::create_dir_all(d).map_err(|e| Error::output(d, e))?;
            inputs.iter().map(|i| batch::derived_output(i, d, ext)).collect()
        }
        _ => return Err(Error::usage("give -o OUT (one input) or --out-dir DIR")),
    };
    batch::unique_outputs(&outs)?;
    Ok(outs)
}

/// The output paired with `input` in a batch.
pub fn paired<'a>(inputs: &[PathBuf], outputs: &'a [PathBuf], input: &Path) -> &'a Path {
    &outputs[inputs.iter().position(|i| i == input).expect("input in batch")]
}
