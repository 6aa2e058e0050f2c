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
mod progress;
mod render;
mod spool;

use args::Cli;
use clap::Parser;
use config::{Config, InputConfig, PlotKind};
use std::io::{BufWriter, Write};
use std::process::ExitCode;

/// Validates the flags into the subcommand's configuration, before any file is read, then
/// runs it.
fn run(cli: &Cli) -> anyhow::Result<()> {
    let mut config = Config::try_from(&cli.command)?;
    let _spool = prepare_input(&mut config)?;
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

/// The recording of a one-recording command.
fn input_mut(config: &mut Config) -> Option<&mut InputConfig> {
    Some(match config {
        Config::Wv(c) => &mut c.input,
        Config::Avar(c) => &mut c.input,
        Config::Fit(c) => &mut c.input,
        Config::Select(c) => &mut c.input,
        Config::Calibrate(c) => &mut c.input,
        Config::Report(c) => &mut c.calibrate.input,
        Config::Plot(c) => match &mut c.kind {
            PlotKind::Wv(c) => &mut c.input,
            PlotKind::Avar(c) | PlotKind::Ieee(c) => &mut c.input,
            PlotKind::Compare(c) => &mut c.input,
            PlotKind::Fit(c) => &mut c.input,
            PlotKind::Select(c) => &mut c.input,
        },
        _ => return None,
    })
}

/// Before anything is read: standard input (`-`) or a pipe as FILE is copied to a temporary
/// file ([`spool`]; the guard removes it), and raw floats that are no sensor's samples (f64
/// read as f32, ...) are warned about, naming the other format.
fn prepare_input(config: &mut Config) -> anyhow::Result<Option<spool::Spool>> {
    if let Config::Batch(b) = config {
        if let Some(p) = b.inputs.iter().find(|p| spool::is_stream(p)) {
            return Err(UsageError(format!(
                "{}: batch mode (several FILEs, a folder, --out-dir, --force) reads files; \
                 give standard input or a pipe alone, without --out-dir/--force",
                if p.as_os_str() == "-" {
                    spool::STDIN.to_string()
                } else {
                    p.display().to_string()
                }
            ))
            .into());
        }
        return Ok(None);
    }
    let mut guard = None;
    if let Config::Topics(t) = config {
        if spool::is_stream(&t.file) {
            let (copy, g) = spool::spool(&t.file)?;
            t.file = copy;
            guard = Some(g);
        }
        return Ok(guard);
    }
    let Some(input) = input_mut(config) else {
        return Ok(None);
    };
    if spool::is_stream(&input.file) {
        let (copy, g) = spool::spool(&input.file)?;
        input.file = copy;
        guard = Some(g);
    }
    warn_implausible(input);
    Ok(guard)
}

/// A warning when FILE is raw f64/f32 whose first values no sensor gives
/// ([`gmwm::imu::plausible::raw_floats`]); silent when it is not raw floats or cannot be read
/// (the reader then says why).
fn warn_implausible(input: &InputConfig) {
    if input.read.format == gmwm::imu::InputFormat::Auto
        && (gmwm::imu::ros::container_of(&input.file).is_some() || input::is_wv(input))
    {
        return;
    }
    if let Ok(Some(layout)) = gmwm::imu::binary_layout(&input.file, &input.read) {
        if let Ok(Some(bad)) = gmwm::imu::plausible::raw_floats(&input.file, &layout) {
            eprintln!("gmwm: warning: {}", spool::shown(&bad.to_string()));
        }
    }
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
            eprintln!("gmwm: error: {}", spool::shown(&one_line(&e)));
            if e.downcast_ref::<UsageError>().is_some() {
                ExitCode::from(2)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}
