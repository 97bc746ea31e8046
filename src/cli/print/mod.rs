//! The one output layer. The library returns typed values; this is where they become text,
//! through printers that sit beside each other as ripgrep's do:
//!
//! - `human`: the text people read ([`Human`], one impl per record);
//! - `jsonl`: one JSON record per input, schema-tagged ([`Record`], `docs/json.md`);
//! - `validate` (its text and JSON document), `junit`, `github`, `sarif`: `validate`'s formats,
//!   one document per run.
//!
//! Commands over many inputs print through [`Printer`], which also keeps their shared rules: a
//! bad input is a record (or a line) of its own and never stops the others, a batch ends with a
//! summary, and the exit code is the worst any input earned.

pub mod github;
mod human;
mod jsonl;
pub mod junit;
pub mod sarif;
pub mod validate;

use bumpbake::{Error, Result};
use std::marker::PhantomData;
use std::path::{Path, PathBuf};

/// What the human printer says of a value.
pub trait Human {
    fn human(&self) -> String;
}

/// A per-input result as the printers know it: its schema, and the few ways a command's
/// records differ. The defaults are every command's but `inspect`'s.
pub trait Record: serde::Serialize + Human {
    /// `bumpbake-<command>/N`.
    const SCHEMA: &'static str;
    /// What an error record calls the input (`inspect`'s records name it `file`).
    const INPUT_FIELD: &'static str = "input";
    /// Whether an ok record says `"status": "ok"` (`inspect`'s schema came without it, and its
    /// records stay as they were).
    const OK_STATUS: bool = true;
    /// The records are the command's output rather than a report of work done: their text
    /// goes to stdout, and a batch summary is printed only when an input failed.
    const IS_OUTPUT: bool = false;
    /// What the batch summary calls an input that went well.
    const DONE: &'static str = "written";
}

impl Record for bumpbake::tangent::command::TangentsReport {
    const SCHEMA: &'static str = "bumpbake-tangents/1";
}

impl Record for bumpbake::bake::BakeReport {
    const SCHEMA: &'static str = "bumpbake-bake/1";
}

impl Record for bumpbake::textures::TexturesRun {
    const SCHEMA: &'static str = "bumpbake-textures/1";
}

impl Record for bumpbake::normalmap::Converted {
    const SCHEMA: &'static str = "bumpbake-normalmap/1";
}

impl Record for bumpbake::inspect::Inspection {
    const SCHEMA: &'static str = "bumpbake-inspect/1";
    const INPUT_FIELD: &'static str = "file";
    const OK_STATUS: bool = false;
    const IS_OUTPUT: bool = true;
    const DONE: &'static str = "inspected";
}

/// Prints the records of one run over `inputs`, in input order, as JSON Lines or as text.
pub struct Printer<R> {
    json: bool,
    quiet: bool,
    inputs: usize,
    failed: Vec<PathBuf>,
    worst: u8,
    record: PhantomData<R>,
}

impl<R: Record> Printer<R> {
    /// `json`: JSON Lines on stdout; else text (none with `quiet`, which JSON ignores).
    pub fn new(inputs: usize, json: bool, quiet: bool) -> Self {
        Printer { json, quiet, inputs, failed: Vec::new(), worst: 0, record: PhantomData }
    }

    /// Prints one input's result. With a single input, its error is the command's error.
    pub fn result(&mut self, input: &Path, r: Result<R>) -> Result<()> {
        match r {
            Ok(rec) if self.json => outln!("{}", jsonl::ok(&rec)),
            Ok(_) if self.quiet => {}
            Ok(rec) if R::IS_OUTPUT => out!("{}", rec.human()),
            Ok(rec) => eprint!("{}", rec.human()),
            Err(e) if self.inputs == 1 => return Err(e),
            Err(e) => self.failed(input, e)?,
        }
        Ok(())
    }

    fn failed(&mut self, input: &Path, e: Error) -> Result<()> {
        if self.json {
            outln!("{}", jsonl::error::<R>(input, &e));
        }
        if !self.quiet {
            eprintln!("bumpbake: {e}");
        }
        self.worst = self.worst.max(e.exit_code());
        self.failed.push(input.to_path_buf());
        Ok(())
    }

    /// Ends the run: a summary line for a batch; returns the exit code, the worst any input
    /// earned (0 when all went well).
    pub fn finish(self) -> u8 {
        if self.inputs > 1 && !self.quiet && !(R::IS_OUTPUT && self.failed.is_empty()) {
            let which: Vec<String> = self.failed.iter().map(|p| p.display().to_string()).collect();
            let which = if which.is_empty() { String::new() } else { format!(" ({})", which.join(", ")) };
            eprintln!(
                "{} files: {} {}, {} failed{which}",
                self.inputs,
                self.inputs - self.failed.len(),
                R::DONE,
                self.failed.len()
            );
        }
        self.worst
    }
}

/// Prints every result of a batch run (`batch::run`'s, in input order); returns the exit code.
pub fn all<R: Record>(inputs: &[PathBuf], results: Vec<Result<R>>, json: bool, quiet: bool) -> Result<u8> {
    let mut p = Printer::new(inputs.len(), json, quiet);
    for (input, r) in inputs.iter().zip(results) {
        p.result(input, r)?;
    }
    Ok(p.finish())
}

/// Prints a command's one result (`preview`): pretty JSON on stdout, or its text on stderr.
pub fn document<D: serde::Serialize + Human>(d: &D, json: bool, quiet: bool) -> Result<()> {
    if json {
        outln!("{}", serde_json::to_string_pretty(d).expect("report serialises"));
    } else if !quiet {
        eprint!("{}", d.human());
    }
    Ok(())
}
