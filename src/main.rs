//! The `bumpbake` binary: parses the command line, runs the library, reports, and maps the
//! outcome onto the exit codes of the conventions (0 done, 1 validation failed, 2 unusable input).

mod cli;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args = cli::Cli::parse();
    bumpbake::error::install(&cli::wording::Flags);
    cli::process::tune_the_allocator(args.bakes_from_high());
    cli::process::clean_up_on_signals();
    match cli::run(args) {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            eprintln!("bumpbake: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
