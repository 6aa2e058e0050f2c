//! Progress bars on a terminal (indicatif) behind the engine's `Progress` trait; hidden when
//! stderr is not a terminal, so pipes and logs stay clean.

use gmwm::inference::Progress;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;

/// A bar of `total` steps named `message`, counting `unit`; hidden off a terminal.
pub fn bar(total: u64, message: &str, unit: &str) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(total);
    let template =
        format!("{{msg}} [{{bar:30}}] {{pos}}/{{len}} {unit}, {{elapsed}} (eta {{eta}})");
    bar.set_style(
        ProgressStyle::with_template(&template).unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_message(message.to_string());
    bar
}

/// Advances a bar by one step per engine report, whichever computation (or thread) reports.
pub struct Ticks<'a>(pub &'a ProgressBar);

impl Progress for Ticks<'_> {
    fn advance(&self, _done: usize) {
        self.0.inc(1);
    }
}
