//! The library's [`Progress`] as an indicatif bar on stderr: one bar per run (render, fit),
//! cleared when the run ends, so one [`Bar`] serves a command's runs one after another.

use crate::progress::Progress;
use indicatif::{ProgressBar, ProgressStyle};
use std::sync::Mutex;

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
