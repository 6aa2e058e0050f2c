//! SIGINT, SIGTERM and SIGHUP: the run's temporary files (spools of streamed recordings,
//! unfinished outputs, the copy of standard input: [`gmwm::track_temporary`]) are removed
//! before the process ends, which then ends as the signal asks (status 128 + signal).

/// Starts the thread that waits for the signals.
pub fn install() {
    #[cfg(unix)]
    {
        use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
        let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
            return;
        };
        std::thread::spawn(move || {
            if let Some(signal) = signals.forever().next() {
                gmwm::remove_temporary_files();
                // the default action (the process ends by the signal), else the usual status
                let _ = signal_hook::low_level::emulate_default_handler(signal);
                std::process::exit(128 + signal);
            }
        });
    }
}
