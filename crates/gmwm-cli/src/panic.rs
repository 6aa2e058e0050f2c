//! A panic as one line. A panic is a bug, never a verdict on the input; Rust's default report
//! spreads it over two lines and a backtrace hint. The hook prints it where it happens (so no
//! panic goes unsaid, whichever thread it is on) as one line, control characters escaped, and
//! the process still ends with Rust's exit code for a panic, 101. With `RUST_BACKTRACE` set
//! the default report follows, backtrace and all.

use std::any::Any;

/// A caught panic's message on one line (for a batch's outcome; the hook has printed it).
pub(crate) fn describe(payload: &(dyn Any + Send)) -> String {
    one_line(message(payload))
}

/// A panic's message (its payload when that is text).
fn message(payload: &(dyn Any + Send)) -> &str {
    payload
        .downcast_ref::<&str>()
        .copied()
        .or_else(|| payload.downcast_ref::<String>().map(String::as_str))
        .unwrap_or("no message")
}

/// `message` on one line: runs of white space as one space, other control characters escaped.
fn one_line(message: &str) -> String {
    let mut text = String::new();
    for c in message
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .chars()
    {
        if c.is_control() {
            text.extend(c.escape_default());
        } else {
            text.push(c);
        }
    }
    text
}

/// The line the hook prints for a panic with `message` at `place` (`FILE:LINE`).
fn line(place: Option<String>, message: &str) -> String {
    let place = place.map(|p| format!(" at {p}")).unwrap_or_default();
    format!(
        "gmwm: internal error: panicked{place}: {} (a bug: please report it with the command \
         and its input)",
        one_line(message)
    )
}

/// Installs the hook (first thing in `main`).
pub(crate) fn install() {
    let default = std::panic::take_hook();
    let backtrace = std::env::var_os("RUST_BACKTRACE").is_some_and(|v| v != "0");
    std::panic::set_hook(Box::new(move |info| {
        let place = info
            .location()
            .map(|l| format!("{}:{}", l.file(), l.line()));
        eprintln!("{}", line(place, message(info.payload())));
        if backtrace {
            default(info);
        }
    }));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_reads_as_one_line_with_its_place() {
        let text = line(
            Some("src/x.rs:7".into()),
            "index 9 out of range\n  for slice\u{1b}[31m of length 3",
        );
        assert_eq!(
            text,
            "gmwm: internal error: panicked at src/x.rs:7: index 9 out of range for \
             slice\\u{1b}[31m of length 3 (a bug: please report it with the command and its input)"
        );
        let payload: Box<dyn Any + Send> = Box::new(String::from("owned"));
        assert_eq!(message(payload.as_ref()), "owned");
        let payload: Box<dyn Any + Send> = Box::new(7_u8);
        assert_eq!(message(payload.as_ref()), "no message");
    }
}
