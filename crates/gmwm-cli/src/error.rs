//! The CLI's errors: a usage error (exit code 2) and the one line every error is printed as.

/// A flag combination the command refuses (e.g. `gmwm fit --filter la8`): reported in one line
/// like every error, with the usage-error exit code 2.
#[derive(Debug)]
pub struct UsageError(pub String);

impl std::fmt::Display for UsageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UsageError {}

/// The error and its causes in one line, `: `-separated, leaving out a cause whose text the
/// message before it already holds (an engine error that names its I/O cause, say).
pub fn one_line(e: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if !out.contains(&text) {
            if !out.is_empty() {
                out.push_str(": ");
            }
            out.push_str(&text);
        }
    }
    out
}
