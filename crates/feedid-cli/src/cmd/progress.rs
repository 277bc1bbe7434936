//! Progress bars for long runs: shown on standard error when it is a
//! terminal, nothing in pipes and CI. The library reports progress through
//! plain callbacks `(done, total)`; this turns them into an indicatif bar.

use std::io::IsTerminal;

use indicatif::{ProgressDrawTarget, ProgressStyle};

/// A bar labelled `label`, counting `unit`s (hidden when standard error is not a terminal).
pub struct ProgressBar {
    bar: indicatif::ProgressBar,
}

impl ProgressBar {
    /// A new bar, e.g. `ProgressBar::new("identify", "samples")`.
    pub fn new(label: &str, unit: &str) -> Self {
        if !std::io::stderr().is_terminal() {
            return Self {
                bar: indicatif::ProgressBar::hidden(),
            };
        }
        let bar = indicatif::ProgressBar::with_draw_target(Some(0), ProgressDrawTarget::stderr());
        if let Ok(style) = ProgressStyle::with_template(&format!(
            "{label} [{{bar:40.cyan/blue}}] {{pos}}/{{len}} {unit}, {{elapsed}} (eta {{eta}})"
        )) {
            bar.set_style(style.progress_chars("=> "));
        }
        Self { bar }
    }

    /// Report `done` of `total` (the library's callback).
    pub fn update(&self, done: u64, total: u64) {
        self.bar.set_length(total);
        self.bar.set_position(done);
    }

    /// Remove the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl Drop for ProgressBar {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}
