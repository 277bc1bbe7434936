//! Progress bars for long runs: shown on standard error when it is a
//! terminal, nothing in pipes and CI. The library reports progress through
//! plain callbacks `(done, total)`; this turns them into an indicatif bar.

use std::io::IsTerminal;

use indicatif::{ProgressDrawTarget, ProgressStyle};

/// A bar labelled `label`, counting `unit`s (hidden when standard error is not a terminal).
pub struct ProgressBar {
    bar: indicatif::ProgressBar,
    /// False when standard error is not a terminal.
    shown: bool,
}

impl ProgressBar {
    /// A new bar, e.g. `ProgressBar::new("identify", "samples")`.
    pub fn new(label: &str, unit: &str) -> Self {
        if !std::io::stderr().is_terminal() {
            return Self::hidden();
        }
        // styled before it is drawn: no frame in the default style
        let this = Self {
            bar: indicatif::ProgressBar::with_draw_target(Some(0), ProgressDrawTarget::hidden()),
            shown: true,
        };
        this.phase(label, unit);
        this.bar.set_draw_target(ProgressDrawTarget::stderr());
        this
    }

    /// A bar that never shows (e.g. for runs in parallel).
    pub fn hidden() -> Self {
        Self {
            bar: indicatif::ProgressBar::hidden(),
            shown: false,
        }
    }

    /// Start a new phase `label` counting `unit`s from zero (`"bytes"`
    /// shows sizes: `1.2 GiB/2.0 GiB`).
    pub fn phase(&self, label: &str, unit: &str) {
        if !self.shown {
            return;
        }
        self.bar.disable_steady_tick();
        self.bar.reset();
        let counts = if unit == "bytes" {
            "{bytes}/{total_bytes}".to_string()
        } else {
            format!("{{pos}}/{{len}} {unit}")
        };
        if let Ok(style) = ProgressStyle::with_template(&format!(
            "{label} [{{bar:40.cyan/blue}}] {counts}, {{elapsed}} (eta {{eta}})"
        )) {
            self.bar.set_style(style.progress_chars("=> "));
        }
    }

    /// Start a phase `label` whose length is not known: a spinner with the
    /// elapsed time (and the bytes so far, see [`ProgressBar::set_bytes`]).
    pub fn spin(&self, label: &str, bytes: bool) {
        if !self.shown {
            return;
        }
        self.bar.reset();
        let counts = if bytes { " {bytes}," } else { "" };
        if let Ok(style) =
            ProgressStyle::with_template(&format!("{label} {{spinner}}{counts} {{elapsed}}"))
        {
            self.bar.set_style(style);
        }
        self.bar
            .enable_steady_tick(std::time::Duration::from_millis(120));
    }

    /// The bytes written so far in a [`ProgressBar::spin`] phase.
    pub fn set_bytes(&self, bytes: u64) {
        self.bar.set_position(bytes);
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
