//! `bumpbake completions SHELL` and `bumpbake man`: generated from the clap definitions, so they
//! never drift from the real options.

use bumpbake::{Error, Result};
use clap::CommandFactory;

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake completions bash > /etc/bash_completion.d/bumpbake
  bumpbake completions zsh > ~/.zfunc/_bumpbake
  bumpbake completions fish > ~/.config/fish/completions/bumpbake.fish")]
pub struct CompletionArgs {
    pub shell: clap_complete::Shell,
}

#[derive(clap::Args, Debug)]
#[command(after_help = "Examples:
  bumpbake man > bumpbake.1 && man ./bumpbake.1")]
pub struct ManArgs {}

pub fn completions(a: CompletionArgs) -> Result<u8> {
    let mut cmd = super::Cli::command();
    let mut script = Vec::new();
    clap_complete::generate(a.shell, &mut cmd, "bumpbake", &mut script);
    super::stdout::write_all(&script)?;
    Ok(0)
}

pub fn man(_a: ManArgs) -> Result<u8> {
    let cmd = super::Cli::command();
    let mut out = Vec::new();
    let render = |out: &mut Vec<u8>| -> std::io::Result<()> {
        clap_mangen::Man::new(cmd.clone()).render(out)?;
        // Each subcommand's options follow, so one page documents the whole tool.
        for sub in cmd.get_subcommands().filter(|s| s.get_name() != "help") {
            use std::io::Write;
            writeln!(out, ".SH \"BUMPBAKE {}\"", sub.get_name().to_uppercase())?;
            if let Some(about) = sub.get_about() {
                writeln!(out, "{about}")?;
            }
            clap_mangen::Man::new(sub.clone()).render_options_section(out)?;
        }
        Ok(())
    };
    render(&mut out).map_err(|e| Error::output("stdout", e))?;
    super::stdout::write_all(&out)?;
    Ok(0)
}
