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
    for input in &a.inputs {
        let i = bumpbake::inspect::inspect(input, &opts)?;
        if a.json {
            let mut v = serde_json::to_value(&i).expect("serialises");
            v["schema"] = serde_json::json!("bumpbake-inspect/1");
            outln!("{v}");
        } else {
            out!("{}", i.text());
        }
    }
    Ok(0)
}
