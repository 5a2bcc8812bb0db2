//! The library's [`Progress`] as an indicatif bar on stderr: one bar per run (render, fit),
//! cleared when the run ends, so one [`Bar`] serves a command's runs one after another.

use indicatif::{ProgressBar, ProgressStyle};
use std::sync::Mutex;
use xylem::progress::Progress;

/// Draws each run as `⠁ [00:00:03] ████░░ 120/256 tiles, eta 2s 2.64 Mrays/s`.
pub(crate) struct Bar {
    show: bool,
    bar: Mutex<ProgressBar>,
}

impl Bar {
    /// A bar that draws when `show` (otherwise a hidden one, for `--quiet`).
    pub(crate) fn new(show: bool) -> Self {
        Bar {
            show,
            bar: Mutex::new(ProgressBar::hidden()),
        }
    }

    fn bar(&self) -> ProgressBar {
        // A clone shares the bar; a panic elsewhere leaves the handle itself intact.
        self.bar.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }
}

impl Progress for Bar {
    fn start(&self, total: u64, unit: &str) {
        let b = if self.show {
            ProgressBar::new(total).with_style(
                ProgressStyle::with_template(&format!(
                    "{{spinner}} [{{elapsed_precise}}] {{wide_bar}} {{pos}}/{{len}} {unit}, eta {{eta}}{{msg}}"
                ))
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            )
        } else {
            ProgressBar::hidden()
        };
        *self.bar.lock().unwrap_or_else(|e| e.into_inner()) = b;
    }

    fn update(&self, done: u64, _total: u64, message: &str) {
        let b = self.bar();
        // The message first (moving the bar may draw it), spaced off only when there is one.
        if !message.is_empty() {
            b.set_message(format!(" {message}"));
        }
        // Threads report out of order: never move the bar back.
        if done > b.position() {
            b.set_position(done);
        }
    }

    fn finish(&self) {
        self.bar().finish_and_clear();
    }
}

/// The steps of a long command (`xylem validate ...`): a bar on a terminal; elsewhere (a log
/// file, CI, a pipe, where indicatif draws nothing) one line per step on stderr,
/// `validate sweep: 3/6 steps, highlight tracking (12.4 s)`, and a first line when it starts,
/// so a run of minutes never looks hung.
pub(crate) struct Steps {
    bar: ProgressBar,
    what: String,
    unit: String,
    lines: bool,
    start: std::time::Instant,
}

impl Steps {
    /// `total` steps of `unit` (e.g. "cases") for `what` (e.g. "validate bsdf").
    pub(crate) fn new(what: &str, total: u64, unit: &str) -> Self {
        use std::io::IsTerminal;
        let lines = !std::io::stderr().is_terminal();
        let bar = if lines {
            eprintln!("{what}: {total} {unit} to run");
            ProgressBar::hidden()
        } else {
            ProgressBar::new(total).with_style(
                ProgressStyle::with_template(&format!(
                    "{what} {{bar:40}} {{pos}}/{{len}} {unit}, {{elapsed}} (eta {{eta}}) {{msg}}"
                ))
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            )
        };
        bar.set_length(total);
        Steps {
            bar,
            what: what.to_string(),
            unit: unit.to_string(),
            lines,
            start: std::time::Instant::now(),
        }
    }

    /// One step done (`name` says which; may be empty).
    pub(crate) fn step(&self, name: &str) {
        self.bar.set_message(name.to_string());
        self.bar.inc(1);
        if self.lines {
            let sep = if name.is_empty() { "" } else { ", " };
            eprintln!(
                "{}: {}/{} {}{sep}{name} ({:.1} s)",
                self.what,
                self.bar.position(),
                self.bar.length().unwrap_or(0),
                self.unit,
                self.start.elapsed().as_secs_f64()
            );
        }
    }

    /// Clears the bar (the lines stay).
    pub(crate) fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
