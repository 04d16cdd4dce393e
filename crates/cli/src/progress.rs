//! The progress bar of a run: drawn only when asked for and stdout is a terminal, so
//! logs and pipes stay clean.

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A progress bar that may be hidden.
pub struct Progress {
    bar: ProgressBar,
}

impl Progress {
    /// A bar over `steps` steps, visible if `wanted` and stdout is a terminal.
    pub fn new(wanted: bool, steps: u64, name: &str) -> Self {
        let bar = if wanted && std::io::stdout().is_terminal() {
            let bar = ProgressBar::with_draw_target(Some(steps), ProgressDrawTarget::stdout());
            if let Ok(style) = ProgressStyle::with_template(
                "{msg} [{elapsed_precise}] {wide_bar} {pos}/{len} steps, eta {eta}",
            ) {
                bar.set_style(style);
            }
            bar.set_message(name.to_string());
            bar
        } else {
            ProgressBar::hidden()
        };
        Self { bar }
    }

    /// One step done.
    pub fn advance(&self) {
        self.bar.inc(1);
    }

    /// Clears the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
