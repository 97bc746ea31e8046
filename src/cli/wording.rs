//! The command line's names for the library's settings: the flags that set them. Installed once
//! at start (`main`), so every message the library words (errors, and the notes it writes into
//! reports) reads with these.

use bumpbake::error::{Setting, Wording};

/// Words settings as the flags that set them.
pub struct Flags;

impl Wording for Flags {
    fn name(&self, s: Setting) -> String {
        match s {
            Setting::High => "--from".into(),
            s => format!("--{}", s.name().replace('_', "-")),
        }
    }

    fn given(&self, s: Setting, value: &str) -> String {
        format!("{} {value}", self.name(s))
    }
}

/// The progress stage as the command line names it: by the flag that asks for the work.
pub fn stage(stage: &str) -> &str {
    if stage == bumpbake::transfer::STAGE {
        "bake --from"
    } else {
        stage
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_setting_is_a_flag_of_the_command_line() {
        use clap::CommandFactory;
        let cmd = super::super::Cli::command();
        let mut flags = std::collections::BTreeSet::new();
        for sub in cmd.get_subcommands() {
            flags.extend(sub.get_arguments().filter_map(|a| a.get_long()).map(|l| format!("--{l}")));
        }
        for s in Setting::EVERY {
            assert!(flags.contains(&Flags.name(s)), "{s:?} is worded {}, which no command takes", Flags.name(s));
        }
    }
}
