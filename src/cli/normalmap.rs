//! `bumpbake normalmap`: not built yet.

use bumpbake::Result;

#[derive(clap::Args, Debug)]
pub struct Args {}

pub fn run(_args: Args) -> Result<u8> {
    Err(bumpbake::Error::usage("normalmap: not built yet"))
}
