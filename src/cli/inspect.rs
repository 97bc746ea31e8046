//! `bumpbake inspect FILE...`.

use bumpbake::scene::ReadOptions;
use bumpbake::Result;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake inspect fixtures/khronos/NormalTangentTest.glb
  bumpbake inspect fixtures/spot/spot.obj --json")]
pub struct Args {
    /// Files to inspect: .obj, .gltf or .glb.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// One JSON record per file on stdout (JSON Lines).
    #[arg(long)]
    pub json: bool,
    /// Let URIs reach outside the input's folder.
    #[arg(long)]
    pub allow_outside: bool,
}

pub fn run(a: Args) -> Result<u8> {
    let opts = ReadOptions { allow_outside: a.allow_outside, ..Default::default() };
    // One file at a time, each printed as soon as it is read: a bad file is a record of its
    // own, and the run ends with the worst exit code.
    let mut printer = super::print::Printer::new(a.inputs.len(), a.json, false);
    for input in &a.inputs {
        printer.result(input, bumpbake::inspect::inspect(input, &opts))?;
    }
    Ok(printer.finish())
}
