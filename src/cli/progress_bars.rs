//! The one place progress is drawn: the library's [`Progress`] calls as indicatif bars on stderr,
//! only where a person watches (a terminal, not `CI=true`, not quiet; `--progress` forces them),
//! and only once a stage has run for a second, so quick work never flickers a bar.

use bumpbake::progress::{Progress, Reporter};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::Duration;

/// A stage shorter than this draws nothing.
const SHOW_AFTER: Duration = Duration::from_secs(1);

thread_local! {
    static FRONT_END: std::cell::RefCell<Option<Reporter>> = const { std::cell::RefCell::new(None) };
}

/// Sends the progress of commands run on this thread to `r` instead of bars, until called with
/// `None`: for a front end that runs the command line in-process and shows progress its own way
/// (the Python package's `progress=` callable).
#[allow(dead_code, reason = "the Python binding (python/) compiles this module and calls it")]
pub fn report_to(r: Option<Reporter>) {
    FRONT_END.with(|f| *f.borrow_mut() = r);
}

fn front_end() -> Option<Reporter> {
    FRONT_END.with(|f| f.borrow().clone())
}

/// True when a bar should be drawn: forced, or a terminal outside CI; never when quiet. A front
/// end's reporter wants every stage.
pub fn wanted(force: bool, quiet: bool) -> bool {
    if front_end().is_some() {
        return true;
    }
    if quiet {
        return false;
    }
    force
        || (std::io::stderr().is_terminal()
            && std::env::var_os("CI").map(|v| v.is_empty() || v == "false").unwrap_or(true))
}

/// Bars for the library's progress when `wanted`, else a reporter that reports nothing.
pub fn reporter(wanted: bool) -> Reporter {
    if let Some(r) = front_end() {
        r
    } else if wanted {
        Reporter::new(Bars::default())
    } else {
        Reporter::none()
    }
}

/// One bar per stage, replaced when the next stage starts.
#[derive(Default)]
struct Bars {
    bar: Mutex<Option<ProgressBar>>,
}

impl Bars {
    fn with_bar(&self, f: impl FnOnce(&ProgressBar)) {
        let guard = self.bar.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(b) = guard.as_ref() {
            if b.is_hidden() && b.elapsed() >= SHOW_AFTER {
                b.set_draw_target(ProgressDrawTarget::stderr());
            }
            f(b);
        }
    }
}

impl Progress for Bars {
    fn start(&self, stage: &str, total: u64, unit: &str) {
        let template = match unit {
            "files" => "{bar:30} {pos}/{len} files {elapsed} {wide_msg}",
            "bytes" => "{prefix} [{bar:40}] {bytes}/{total_bytes} ({elapsed})",
            _ => "{prefix} [{bar:40}] {pos}/{len} {msg} ({elapsed})",
        };
        let b = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::hidden());
        b.set_style(ProgressStyle::with_template(template).expect("valid template").progress_chars("=> "));
        b.set_prefix(super::wording::stage(stage).to_string());
        if unit != "files" {
            b.set_message(unit.to_string());
        }
        let mut guard = self.bar.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(old) = guard.replace(b) {
            old.finish_and_clear();
        }
    }

    fn tick(&self, n: u64) {
        self.with_bar(|b| b.inc(n));
    }

    fn message(&self, msg: &str) {
        self.with_bar(|b| b.set_message(msg.to_string()));
    }

    fn finish(&self) {
        let mut guard = self.bar.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(b) = guard.take() {
            b.finish_and_clear();
        }
    }
}
