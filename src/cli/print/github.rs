//! `validate --format github`: GitHub Actions workflow commands, which annotate the files in a
//! workflow run.

use bumpbake::validate::{Report, Severity};

fn gh_data(s: &str) -> String {
    s.replace('%', "%25").replace('\r', "%0D").replace('\n', "%0A")
}

fn gh_prop(s: &str) -> String {
    gh_data(s).replace(':', "%3A").replace(',', "%2C")
}

/// GitHub Actions workflow commands (for stdout): `::error file=...,title=CODE::message`.
/// Failing findings are errors, other warnings are warnings, infos are notices.
pub fn github(r: &Report) -> String {
    let mut out = String::new();
    for (file, sub, f) in r.findings() {
        let level = if r.fails(f.severity) {
            "error"
        } else if f.severity == Severity::Warning {
            "warning"
        } else {
            "notice"
        };
        let mut msg = format!("{}: {}", sub.name, f.message);
        if let Some(e) = f.examples.first() {
            msg += &format!(" (e.g. {} {}: {})", e.kind, e.index, e.detail);
        }
        msg += &format!("\nfix: {}", f.hint);
        out += &format!(
            "::{level} file={},title={}::{}\n",
            gh_prop(&file.path.display().to_string()),
            gh_prop(f.code.as_str()),
            gh_data(&msg)
        );
    }
    out
}
