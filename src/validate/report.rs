//! The report in the formats people and CI systems read: a human summary, JSON (schema in
//! `docs/validate.md`), JUnit XML (one testcase per subject and check, which CI systems display
//! natively), GitHub workflow annotations, and SARIF 2.1.0 (`sarif.rs`).

mod sarif;

use super::{Finding, Report, Severity, Subject};
pub use sarif::sarif;
use serde_json::json;

/// The JSON schema identifier; bumped only on incompatible changes.
pub const SCHEMA: &str = "bumpbake-validate/1";

fn line(sub: &Subject, f: &Finding) -> String {
    format!("{}: {} {}: {}", sub.name, f.severity.as_str(), f.code, f.message)
}

/// The human summary (for stderr).
pub fn text(r: &Report) -> String {
    let mut out = String::new();
    for file in &r.files {
        let n = |sev| file.subjects.iter().flat_map(|s| &s.findings).filter(|f| f.severity == sev).count();
        out += &format!(
            "{}: {} error(s), {} warning(s), {} info\n",
            file.path.display(),
            n(Severity::Error),
            n(Severity::Warning),
            n(Severity::Info)
        );
        for sub in &file.subjects {
            if let Some(c) = &sub.conformance {
                if c.compared > 0 {
                    out += &format!(
                        "  {}: MikkTSpace agreement over {} corners: max {:.3}°, p99 {:.3}°, {} sign mismatches\n",
                        sub.name, c.compared, c.max_angle_deg, c.p99_angle_deg, c.sign_mismatches
                    );
                }
            }
            if let Some(d) = &sub.convention {
                let verdict = if d.confidence >= super::normal_image::REPORT_CONFIDENCE {
                    format!("looks {}", d.convention.describe())
                } else {
                    "undetermined".into()
                };
                out += &format!("  {}: green channel {verdict} (confidence {:.2})\n", sub.name, d.confidence);
            }
            let mut findings: Vec<&Finding> = sub.findings.iter().collect();
            findings.sort_by_key(|f| std::cmp::Reverse(f.severity));
            for f in findings {
                out += &format!("  {}\n", line(sub, f));
                for e in &f.examples {
                    match e.at {
                        Some([x, y]) => out += &format!("      {} ({x}, {y}): {}\n", e.kind, e.detail),
                        None => out += &format!("      {} {}: {}\n", e.kind, e.index, e.detail),
                    }
                }
                out += &format!("      fix: {}\n", f.hint);
            }
        }
    }
    let s = r.summary();
    let code = r.exit_code();
    out += &format!(
        "bumpbake validate: {} file(s), {} checks, {} error(s), {} warning(s), {} info{}: {}\n",
        r.files.len(),
        s.checks,
        s.errors,
        s.warnings,
        s.infos,
        if r.strict { " (--strict: warnings fail)" } else { "" },
        if code == 0 { "PASS" } else { "FAIL" }
    );
    out
}

/// The JSON report (for stdout).
pub fn json(r: &Report) -> String {
    let v = json!({
        "schema": SCHEMA,
        "tool": concat!("bumpbake ", env!("CARGO_PKG_VERSION")),
        "exit_code": r.exit_code(),
        "strict": r.strict,
        "max_angle_deg": r.max_angle_deg,
        "summary": r.summary(),
        "files": r.files,
    });
    serde_json::to_string_pretty(&v).unwrap_or_else(|_| "{}".to_string())
}

fn xml(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' => o += "&amp;",
            '<' => o += "&lt;",
            '>' => o += "&gt;",
            '"' => o += "&quot;",
            '\'' => o += "&apos;",
            c if (c as u32) < 0x20 && c != '\n' && c != '\t' && c != '\r' => o.push(' '),
            c => o.push(c),
        }
    }
    o
}

fn details(f: &Finding) -> String {
    let mut d = format!("{}\n", f.message);
    for e in &f.examples {
        d += &format!("{} {}: {}\n", e.kind, e.index, e.detail);
    }
    d += &format!("fix: {}\n", f.hint);
    d
}

/// JUnit XML (for stdout): a testsuite per file, a testcase per subject and check. Findings that
/// fail the run are `<failure>`s; the others pass with their message in `<system-out>`.
pub fn junit(r: &Report) -> String {
    let mut suites = String::new();
    let (mut all_tests, mut all_fail) = (0, 0);
    for file in &r.files {
        let path = file.path.display().to_string();
        let (mut tests, mut failures) = (0, 0);
        let mut cases = String::new();
        for sub in &file.subjects {
            for code in &sub.checks {
                tests += 1;
                cases +=
                    &format!("    <testcase classname=\"{}\" name=\"{}: {}\">\n", xml(&path), xml(&sub.name), code);
                for f in sub.findings.iter().filter(|f| f.code == *code) {
                    if r.fails(f.severity) {
                        failures += 1;
                        cases += &format!(
                            "      <failure type=\"{}\" message=\"{}\">{}</failure>\n",
                            code,
                            xml(&format!("{}: {}", f.severity.as_str(), f.message)),
                            xml(&details(f))
                        );
                    } else {
                        cases += &format!(
                            "      <system-out>{}</system-out>\n",
                            xml(&format!("{}: {}", f.severity.as_str(), details(f)))
                        );
                    }
                }
                cases += "    </testcase>\n";
            }
        }
        all_tests += tests;
        all_fail += failures;
        suites += &format!(
            "  <testsuite name=\"{}\" tests=\"{tests}\" failures=\"{failures}\" errors=\"0\">\n{cases}  </testsuite>\n",
            xml(&path)
        );
    }
    format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites name=\"bumpbake validate\" tests=\"{all_tests}\" failures=\"{all_fail}\" errors=\"0\">\n{suites}</testsuites>\n"
    )
}

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
