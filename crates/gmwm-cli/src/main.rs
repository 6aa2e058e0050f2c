//! `gmwm`: command-line front end of the gmwm engine. Parses flags, validates them once into
//! the subcommand's configuration (`config.rs`), runs the subcommand, renders its result; no
//! numerics of its own.
//!
//! Exit codes: 0 success, 1 input or computation error (one line on stderr), 2 usage error.

mod args;
mod batch;
mod cmd;
mod config;
mod input;
mod output;
mod progress;
mod render;

use args::Cli;
use clap::Parser;
use config::Config;
use std::io::{BufWriter, Write};
use std::process::ExitCode;

/// Validates the flags into the subcommand's configuration, before any file is read, then
/// runs it.
fn run(cli: &Cli) -> anyhow::Result<()> {
    let config = Config::try_from(&cli.command)?;
    let stdout = std::io::stdout();
    let mut out = BufWriter::new(stdout.lock());
    match &config {
        Config::Demo(c) => cmd::demo::run(c, &mut out)?,
        Config::Wv(c) => cmd::wv::run(c, &mut out)?,
        Config::Avar(c) => cmd::avar::run(c, &mut out)?,
        Config::Simulate(c) => cmd::simulate::run(c, &mut out)?,
        Config::Implied(c) => cmd::implied::run(c, &mut out)?,
        Config::Fit(c) => cmd::fit::run(c, &mut out)?,
        Config::Select(c) => cmd::select::run(c, &mut out)?,
        Config::Calibrate(c) => cmd::calibrate::run(c, &mut out)?,
        Config::Topics(c) => cmd::topics::run(c, &mut out)?,
        Config::Plot(c) => cmd::plot::run(c, &mut out)?,
        Config::Report(c) => cmd::report::run(c, &mut out)?,
        Config::Batch(c) => batch::run(c, &mut out)?,
    }
    out.flush()?;
    Ok(())
}

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
fn one_line(e: &anyhow::Error) -> String {
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

fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// A flag value outside its domain (`--freq -5`, `--G 0`, `--rule foo`): one line naming the
/// flag and what would be valid, exit code 2; other usage errors keep clap's message with the
/// usage.
fn parse() -> Result<Cli, ExitCode> {
    match Cli::try_parse() {
        Ok(cli) => Ok(cli),
        Err(e)
            if matches!(
                e.kind(),
                clap::error::ErrorKind::ValueValidation | clap::error::ErrorKind::InvalidValue
            ) =>
        {
            // clap's first line names the flag and the value; an invalid choice lists the
            // possible values on the next one
            let text = e.to_string();
            let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
            let first = lines.next().unwrap_or_default();
            match lines.next().filter(|l| l.starts_with("[possible values")) {
                Some(values) => eprintln!("gmwm: {first} {values}"),
                None => eprintln!("gmwm: {first}"),
            }
            Err(ExitCode::from(2))
        }
        Err(e) => e.exit(),
    }
}

fn main() -> ExitCode {
    let cli = match parse() {
        Ok(cli) => cli,
        Err(code) => return code,
    };
    match run(&cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("gmwm: error: {}", one_line(&e));
            if e.downcast_ref::<UsageError>().is_some() {
                ExitCode::from(2)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}
