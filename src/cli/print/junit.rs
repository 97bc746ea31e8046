//! `validate --format junit`: JUnit XML, one testcase per subject and check, which CI systems
//! display natively.

use bumpbake::validate::{Finding, Report};

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
