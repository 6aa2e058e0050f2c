//! Panics as one line. A panic is a bug, never a verdict on the input, but its default report
//! (two lines and a backtrace hint, printed where it happens) would also appear for the panics
//! the engine catches and turns into errors (the MCAP reader's guard around the `mcap` crate).
//! The hook only keeps the message and place; [`report`] gives them to whoever catches the
//! panic at the top (`main`, a batch's recording), which prints one line. With `RUST_BACKTRACE`
//! set the default report is printed as well.

use std::any::Any;
use std::sync::Mutex;

/// The last panic's message and place, kept by the hook.
static LAST: Mutex<Option<String>> = Mutex::new(None);

fn message(payload: &(dyn Any + Send)) -> &str {
    payload
        .downcast_ref::<&str>()
        .copied()
        .or_else(|| payload.downcast_ref::<String>().map(String::as_str))
        .unwrap_or("no message")
}

/// Installs the hook (once, first thing in `main`).
pub(crate) fn install() {
    let default = std::panic::take_hook();
    let backtrace = std::env::var_os("RUST_BACKTRACE").is_some_and(|v| v != "0");
    std::panic::set_hook(Box::new(move |info| {
        let place = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        let line = format!("panicked{place}: {}", message(info.payload()));
        *LAST.lock().unwrap_or_else(|e| e.into_inner()) = Some(line);
        if backtrace {
            default(info);
        }
    }));
}

/// What a caught panic says, on one line, with its place when the hook kept it: "panicked at
/// FILE:LINE: MESSAGE".
pub(crate) fn report(payload: &(dyn Any + Send)) -> String {
    let text = LAST
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .take()
        .unwrap_or_else(|| format!("panicked: {}", message(payload)));
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_caught_panic_reads_as_one_line_with_its_place() {
        install();
        let line = line!() + 1;
        let caught = std::panic::catch_unwind(|| panic!("boom\n  on a second line"));
        // back to the default hook, for the other tests of this binary
        drop(std::panic::take_hook());
        let text = report(caught.unwrap_err().as_ref());
        assert_eq!(
            text,
            format!("panicked at crates/gmwm-cli/src/panic.rs:{line}: boom on a second line")
        );
        // taken: a later report without a hook falls back on the payload
        let payload: Box<dyn Any + Send> = Box::new("plain");
        assert_eq!(report(payload.as_ref()), "panicked: plain");
    }
}
