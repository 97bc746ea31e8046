//! The command line in-process: `bumpbake ...` as a console script ([`main`]), and the
//! package's file-level calls ([`run`]), which pass the keywords as the flags they stand for and
//! take back the JSON the command prints. Either way the parsing, the checks and the JSON are
//! the command line's own, so the two cannot drift apart.

use crate::cli;
use crate::errors::{from_library, raise, Kind};
use crate::progress::Callback;
use clap::error::{ContextKind, ContextValue, ErrorKind};
use clap::{CommandFactory, Parser};
use pyo3::prelude::*;
use std::collections::HashMap;

/// `bumpbake ARGS...` as the binary runs it; returns the exit code. For the console script and
/// `python -m bumpbake`, which own the process.
#[pyfunction]
pub fn main(py: Python<'_>, argv: Vec<String>) -> u8 {
    let args = match cli::Cli::try_parse_from(&argv) {
        Ok(a) => a,
        Err(e) => {
            let _ = e.print();
            return e.exit_code().clamp(0, 255) as u8;
        }
    };
    // This process is the command line: its messages name flags.
    bumpbake::error::install(&cli::wording::Flags);
    cli::process::tune_the_allocator(args.bakes_from_high());
    cli::process::clean_up_on_signals();
    py.detach(|| match cli::run(args) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("bumpbake: {e}");
            e.exit_code()
        }
    })
}

/// Runs `argv` (built from keywords by the Python side) with its standard output captured;
/// returns the exit code and that output. Errors are raised as the package's exceptions, worded
/// with keywords.
#[pyfunction]
#[pyo3(signature = (argv, progress=None))]
pub fn run(py: Python<'_>, argv: Vec<String>, progress: Option<Py<PyAny>>) -> PyResult<(u8, String)> {
    let args = cli::Cli::try_parse_from(&argv).map_err(|e| raise(py, Kind::Usage, parse_error(&e)))?;
    crate::errors::speak_keywords();
    let (reporter, callback) = Callback::reporter(progress);
    let (result, out) = py.detach(|| {
        cli::progress_bars::report_to((!reporter.is_none()).then_some(reporter));
        let r = cli::stdout::captured(|| cli::run(args));
        cli::progress_bars::report_to(None);
        r
    });
    if let Some(e) = callback.and_then(|c| c.take_error()) {
        return Err(e);
    }
    let code = result.map_err(|e| from_library(py, &e, keywords))?;
    Ok((code, String::from_utf8_lossy(&out).into_owned()))
}

/// One option of a command as a keyword: `(keyword, flag or None for a positional, takes a
/// value, takes several)`.
type Keyword = (String, Option<String>, bool, bool);

/// The options of the command line's `command`, as keywords (clap's ids are the fields' names,
/// which are the keywords).
#[pyfunction]
pub fn options(py: Python<'_>, command: &str) -> PyResult<Vec<Keyword>> {
    let root = cli::Cli::command();
    let Some(cmd) = root.get_subcommands().find(|c| c.get_name() == command) else {
        return Err(raise(py, Kind::Usage, format!("bumpbake has no command {command:?}")));
    };
    Ok(cmd
        .get_arguments()
        .filter(|a| !matches!(a.get_id().as_str(), "help" | "version"))
        .map(|a| {
            let takes = a.get_action().takes_values();
            let many = matches!(a.get_action(), clap::ArgAction::Append)
                || a.get_num_args().is_some_and(|n| n.max_values() > 1)
                || a.get_value_delimiter().is_some();
            (a.get_id().to_string(), a.get_long().map(str::to_string), takes, many)
        })
        .collect())
}

/// Every long flag of every command, and the keyword and value-taking it stands for.
fn flags() -> HashMap<String, (String, bool)> {
    let root = cli::Cli::command();
    let mut m = HashMap::new();
    for cmd in root.get_subcommands() {
        for a in cmd.get_arguments() {
            if let Some(long) = a.get_long() {
                m.insert(long.to_string(), (a.get_id().to_string(), a.get_action().takes_values()));
            }
        }
    }
    m
}

/// `text` with every command-line flag named as its keyword: `--height-range` becomes
/// `height_range`, and `--bits 16` becomes `bits=16`. Flags are looked up in the command line's
/// own table, so only real flags change.
pub fn keywords(text: &str) -> String {
    let table = flags();
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find("--") {
        out.push_str(&rest[..at]);
        let after = &rest[at + 2..];
        let len = after.find(|c: char| !(c.is_ascii_alphanumeric() || c == '-')).unwrap_or(after.len());
        match table.get(&after[..len]) {
            Some((kw, takes)) => {
                out.push_str(kw);
                rest = &after[len..];
                // `--flag VALUE`: the value follows as `keyword=VALUE`.
                let value_len = rest
                    .strip_prefix(' ')
                    .filter(|_| *takes)
                    .map(|v| v.find(|c: char| c.is_whitespace() || c == ':' || c == ')' || c == ',').unwrap_or(v.len()))
                    .filter(|&n| n > 0 && !rest[1..].starts_with("--") && !rest[1..].starts_with('<'));
                if let Some(n) = value_len {
                    out.push('=');
                    out.push_str(&rest[1..1 + n]);
                    rest = &rest[1 + n..];
                }
            }
            None => {
                out.push_str("--");
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

/// A clap parse error in keywords: which keyword, which value, and what is allowed.
fn parse_error(e: &clap::Error) -> String {
    let string = |k: ContextKind| match e.get(k) {
        Some(ContextValue::String(s)) => Some(s.clone()),
        Some(ContextValue::Strings(v)) => Some(v.join(", ")),
        _ => None,
    };
    // "--strength <S>" -> "strength"
    let keyword = |s: String| keywords(s.split_whitespace().next().unwrap_or(""));
    let arg = string(ContextKind::InvalidArg).map(keyword);
    let value = string(ContextKind::InvalidValue);
    match (e.kind(), arg, value) {
        (ErrorKind::InvalidValue, Some(a), Some(v)) => match string(ContextKind::ValidValue) {
            Some(valid) => format!("{a}={v:?} is not one of: {valid}"),
            None => format!("{a} needs a value"),
        },
        (ErrorKind::ValueValidation, Some(a), Some(v)) => {
            let why = std::error::Error::source(e).map(|s| keywords(&s.to_string())).unwrap_or_default();
            format!("{a}={v:?}: {why}")
        }
        (ErrorKind::ArgumentConflict, Some(a), _) => match string(ContextKind::PriorArg) {
            Some(p) => format!("{a} cannot be given with {}", keyword(p)),
            None => format!("{a} cannot be given with the other options"),
        },
        (ErrorKind::MissingRequiredArgument, Some(a), _) => format!("missing: {a}"),
        _ => {
            // Other kinds are the front end's own mistakes; clap's words, flags turned to keywords.
            let text = e.render().to_string();
            let first = text.lines().next().unwrap_or("").trim_start_matches("error: ");
            keywords(first)
        }
    }
}
