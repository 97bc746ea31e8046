//! `validate`'s report as people read it (text, for stderr) and as its JSON document (schema in
//! `docs/validate.md`). Its CI formats are printers beside these: `junit.rs`, `github.rs`,
//! `sarif.rs`.

use bumpbake::validate::{normal_image, Finding, Report, Severity, Subject};
use serde_json::json;

/// The JSON schema identifier; bumped only on incompatible changes.
pub const SCHEMA: &str = "bumpbake-validate/1";

fn line(sub: &Subject, f: &Finding) -> String {
    format!("{}: {} {}: {}", sub.name, f.severity.as_str(), f.code, f.message)
}

/// The human summary (for stderr).
impl super::Human for Report {
    fn human(&self) -> String {
        text(self)
    }
}

fn text(r: &Report) -> String {
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
                let verdict = if d.confidence >= normal_image::REPORT_CONFIDENCE {
                    format!("looks {}", normal_image::describe_convention(d.convention))
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
