//! The command-line manners people expect: completions, a man page, examples in every --help.

mod common;
use common::*;

fn subcommands() -> Vec<String> {
    let help = String::from_utf8(run_ok(&["--help"]).stdout).unwrap();
    let mut in_list = false;
    let mut out = Vec::new();
    for line in help.lines() {
        if line.starts_with("Commands:") {
            in_list = true;
            continue;
        }
        if in_list {
            match line.split_whitespace().next() {
                Some(name) if line.starts_with("  ") => {
                    if name != "help" {
                        out.push(name.to_string())
                    }
                }
                _ => break,
            }
        }
    }
    out
}

#[test]
fn every_subcommand_help_ends_with_real_examples() {
    let subs = subcommands();
    assert!(subs.contains(&"tangents".to_string()), "{subs:?}");
    for sub in subs {
        let help = String::from_utf8(run_ok(&[&sub, "--help"]).stdout).unwrap();
        let examples = help.split("Examples:").nth(1).unwrap_or_else(|| panic!("`{sub} --help` has no examples"));
        let lines: Vec<&str> = examples.lines().filter(|l| l.trim_start().starts_with("bumpbake ")).collect();
        assert!(!lines.is_empty(), "`{sub} --help` examples: {examples}");
        for l in lines {
            assert!(l.contains(&format!("bumpbake {sub}")), "`{sub}` example runs `{sub}`: {l}");
        }
    }
}

#[test]
fn bash_completions_are_valid_shell() {
    let out = run_ok(&["completions", "bash"]).stdout;
    let d = scratch_dir("completions");
    let f = d.join("bumpbake.bash");
    std::fs::write(&f, &out).unwrap();
    let check = std::process::Command::new("bash").arg("-n").arg(&f).output().unwrap();
    assert!(check.status.success(), "{}", String::from_utf8_lossy(&check.stderr));
    let text = String::from_utf8(out).unwrap();
    assert!(text.contains("tangents") && text.contains("--bitangents"));
    for shell in ["zsh", "fish", "powershell"] {
        let t = String::from_utf8(run_ok(&["completions", shell]).stdout).unwrap();
        assert!(t.contains("bumpbake") && t.contains("overwrite"), "{shell}");
    }
}

#[test]
fn man_page_is_roff_with_every_subcommand() {
    let text = String::from_utf8(run_ok(&["man"]).stdout).unwrap();
    assert!(text.contains(".TH bumpbake 1"), "has a title header");
    for sub in subcommands() {
        assert!(text.contains(&format!(".SH \"BUMPBAKE {}\"", sub.to_uppercase())), "section for {sub}");
    }
    assert!(text.contains("\\-\\-overwrite"), "options are rendered");
    // Every roff request line is a known macro.
    for l in text.lines().filter(|l| l.starts_with('.')) {
        let m = l.split_whitespace().next().unwrap();
        assert!(
            [
                ".TH", ".SH", ".TP", ".PP", ".ie", ".el", ".RS", ".RE", ".br", ".IP", ".B", ".I", ".sp", ".nf", ".fi",
                ".SS"
            ]
            .contains(&m),
            "unknown macro {m}"
        );
    }
}

/// A reader that closes the pipe early (`| head -c 10`) ends the output quietly: no panic, no
/// "Broken pipe" message, and the exit code the run earned (0: every file was read).
#[test]
fn a_closed_pipe_ends_the_output_quietly() {
    use std::io::Read;
    let file = fixture("khronos/NormalTangentTest.glb");
    let mut args = vec!["inspect".to_string(), "--json".to_string()];
    args.extend(std::iter::repeat_n(s(&file).to_string(), 300));
    let mut child =
        bin().args(&args).stdout(std::process::Stdio::piped()).stderr(std::process::Stdio::piped()).spawn().unwrap();
    let mut first = [0u8; 10];
    child.stdout.take().unwrap().read_exact(&mut first).unwrap();
    // The pipe is closed here, with hundreds of records still to come.
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(err.is_empty(), "nothing on stderr: {err}");
}
