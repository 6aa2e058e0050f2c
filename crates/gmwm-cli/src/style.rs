//! How the CLI talks on standard error, decided once in `main` ([`OutputStyle::detect`]) and
//! passed down: progress bars (indicatif, behind the engine's `Progress` trait) only on a
//! terminal, without `--quiet` and not on a `TERM=dumb` one; notes (what the reader found, the
//! files written) unless `--quiet`; colour (clap's messages) unless `NO_COLOR` or `TERM=dumb`.
//! Warnings and errors are always printed; standard output carries the results alone, the same
//! whatever the style. `GMWM_PROGRESS=lines` draws the bars as plain lines on standard error,
//! `gmwm: progress: calibrating: 12/60 candidate fits`, at most four a second and whether or not
//! it is a terminal: for a program that runs gmwm and shows its progress (the browser page's
//! worker, web/).

use gmwm::Progress;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle, TermLike};
use std::io::IsTerminal;
use std::path::Path;

/// What goes to standard error besides warnings and errors.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OutputStyle {
    /// Progress bars with an ETA.
    pub progress: bool,
    /// `gmwm: note: ...` lines and `gmwm: wrote FILE`.
    pub notes: bool,
    /// Colour in clap's help and usage errors (when its stream is a terminal).
    pub colour: bool,
}

impl OutputStyle {
    /// The style of this run: `--quiet`, the environment (`NO_COLOR`, `TERM`) and whether
    /// standard error is a terminal.
    pub fn detect(quiet: bool) -> Self {
        let mut style = Self::of(quiet, std::io::stderr().is_terminal(), no_color(), dumb());
        style.progress |= progress_lines() && !quiet;
        style
    }

    /// The style for `--quiet`, a terminal on stderr, `NO_COLOR` set (non-empty, as
    /// no-color.org says) and `TERM=dumb`.
    pub fn of(quiet: bool, terminal: bool, no_color: bool, dumb: bool) -> Self {
        Self {
            progress: terminal && !quiet && !dumb,
            notes: !quiet,
            colour: !no_color && !dumb,
        }
    }

    /// The same style without progress bars (one recording of a batch, whose bar is the
    /// batch's).
    pub fn without_progress(self) -> Self {
        Self {
            progress: false,
            ..self
        }
    }

    /// A bar of `total` steps named `message`, counting `unit`; hidden without progress.
    pub fn bar(&self, total: u64, message: &str, unit: &str) -> ProgressBar {
        if !self.progress {
            return ProgressBar::hidden();
        }
        if progress_lines() {
            let bar = ProgressBar::with_draw_target(
                Some(total),
                ProgressDrawTarget::term_like_with_hz(Box::new(ProgressLines), 4),
            );
            let template = format!("{{msg}}: {{pos}}/{{len}} {unit}");
            bar.set_style(
                ProgressStyle::with_template(&template)
                    .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            bar.set_message(message.to_string());
            return bar;
        }
        let bar = ProgressBar::new(total);
        let template =
            format!("{{msg}} [{{bar:30}}] {{pos}}/{{len}} {unit}, {{elapsed}} (eta {{eta}})");
        bar.set_style(
            ProgressStyle::with_template(&template)
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar.set_message(message.to_string());
        bar
    }

    /// `gmwm: note: FILE: text` (FILE as the user named it), unless quiet.
    pub fn note(&self, file: &Path, text: &str) {
        if self.notes {
            eprintln!(
                "gmwm: note: {}",
                crate::spool::shown(&format!("{}: {text}", file.display()))
            );
        }
    }

    /// `gmwm: wrote FILE` for a file written beside the results, unless quiet.
    pub fn wrote(&self, path: &Path) {
        if self.notes {
            eprintln!("gmwm: wrote {}", path.display());
        }
    }
}

/// Whether the environment allows colour (the style's `colour`, known before the flags are
/// parsed: clap colours its help and usage errors).
pub fn colour() -> bool {
    OutputStyle::of(false, false, no_color(), dumb()).colour
}

/// `NO_COLOR` set and not empty (no-color.org).
fn no_color() -> bool {
    std::env::var_os("NO_COLOR").is_some_and(|v| !v.is_empty())
}

/// `TERM=dumb`: a terminal that cannot redraw a line or show colour.
fn dumb() -> bool {
    std::env::var_os("TERM").is_some_and(|t| t == "dumb")
}

/// `GMWM_PROGRESS=lines` in the environment.
fn progress_lines() -> bool {
    static LINES: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *LINES.get_or_init(|| std::env::var_os("GMWM_PROGRESS").is_some_and(|v| v == "lines"))
}

/// A bar's draw target that writes each drawn state as one line on standard error, with no
/// cursor movement: `gmwm: progress: MESSAGE: POS/LEN UNIT`.
#[derive(Debug)]
struct ProgressLines;

impl TermLike for ProgressLines {
    fn width(&self) -> u16 {
        200
    }
    fn move_cursor_up(&self, _: usize) -> std::io::Result<()> {
        Ok(())
    }
    fn move_cursor_down(&self, _: usize) -> std::io::Result<()> {
        Ok(())
    }
    fn move_cursor_right(&self, _: usize) -> std::io::Result<()> {
        Ok(())
    }
    fn move_cursor_left(&self, _: usize) -> std::io::Result<()> {
        Ok(())
    }
    fn write_line(&self, s: &str) -> std::io::Result<()> {
        self.write_str(s)
    }
    fn write_str(&self, s: &str) -> std::io::Result<()> {
        if !s.trim().is_empty() {
            use std::io::Write;
            writeln!(std::io::stderr().lock(), "gmwm: progress: {}", s.trim_end())?;
        }
        Ok(())
    }
    fn clear_line(&self) -> std::io::Result<()> {
        Ok(())
    }
    fn flush(&self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Advances a bar by one step per engine report, whichever computation (or thread) reports.
pub struct Ticks<'a>(pub &'a ProgressBar);

impl Progress for Ticks<'_> {
    fn advance(&self, _done: usize) {
        self.0.inc(1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_style_is_decided_from_quiet_the_terminal_and_the_environment() {
        let all = OutputStyle {
            progress: true,
            notes: true,
            colour: true,
        };
        assert_eq!(OutputStyle::of(false, true, false, false), all);
        // a pipe or a log: no bar, notes and colour as asked
        assert_eq!(
            OutputStyle::of(false, false, false, false),
            OutputStyle {
                progress: false,
                ..all
            }
        );
        // --quiet: no bar and no notes
        assert_eq!(
            OutputStyle::of(true, true, false, false),
            OutputStyle {
                progress: false,
                notes: false,
                colour: true,
            }
        );
        assert!(!OutputStyle::of(false, true, true, false).colour);
        // TERM=dumb: no colour and no animated bar
        let dumb = OutputStyle::of(false, true, false, true);
        assert!(!dumb.colour && !dumb.progress && dumb.notes);
        assert!(!all.without_progress().progress);
    }
}
