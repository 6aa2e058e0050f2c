//! `gmwm`: command-line front end of the gmwm engine. Parses flags, validates them once into
//! the subcommand's configuration (`config.rs`), decides the output style once (`style.rs`),
//! then runs every subcommand through the same steps ([`cmd::Command`]): prepare what it reads,
//! check that its output files can be written, run it; no numerics of its own.
//!
//! Exit codes: 0 success, 1 input or computation error (one line on stderr), 2 usage error.

mod args;
mod cmd;
mod config;
mod error;
mod input;
mod output;
mod panic;
mod prepare;
mod recordings;
mod render;
mod signals;
mod spool;
mod style;

use args::Cli;
use clap::{CommandFactory, FromArgMatches};
use config::Config;
use error::{one_line, UsageError};
use std::io::{BufWriter, Write};
use std::path::Path;
use std::process::ExitCode;
use style::OutputStyle;

/// Validates the flags into the subcommand's configuration, before any file is read, prepares
/// its inputs, checks its outputs' folders, then runs it.
fn run(cli: &Cli, style: OutputStyle) -> anyhow::Result<()> {
    let mut config = Config::try_from(&cli.command)?;
    let command = cmd::of(&mut config);
    let _spool = prepare::prepare(command.inputs())?;
    check_outputs(&command.outputs())?;
    let levels = command.levels();
    let mut out = BufWriter::new(Stdout(std::io::stdout().lock()));
    let ran = command.run(style, &mut out).and_then(|()| Ok(out.flush()?));
    ran.map_err(|e| match levels {
        // a series too short for the levels asked: the flag is the thing to change
        Some(j) if too_short(&e) => e.context(format!("--levels {j}")),
        _ => e,
    })
}

/// Before any work: every file the command writes (`-`, standard output, aside) must have a
/// folder to go in (STYLE §9: a bad path fails in milliseconds, not after the calibration).
fn check_outputs(outputs: &[&Path]) -> anyhow::Result<()> {
    for path in outputs.iter().filter(|p| p.as_os_str() != "-") {
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        if !dir.is_dir() {
            let why = if dir.exists() {
                "is not a folder"
            } else {
                "does not exist"
            };
            anyhow::bail!(
                "{}: cannot be written: {} {why}",
                path.display(),
                dir.display()
            );
        }
    }
    Ok(())
}

/// Whether a series was too short for the computation (the engine's
/// [`gmwm::SeriesError::TooShort`], however wrapped).
fn too_short(e: &anyhow::Error) -> bool {
    use gmwm::{Error, FitError, InputError, SelectionError, SeriesError};
    let short = |s: &SeriesError| matches!(s, SeriesError::TooShort { .. });
    let input = |i: &InputError| matches!(i, InputError::Series(s) if short(s));
    e.chain().any(|c| {
        c.downcast_ref::<SeriesError>().is_some_and(short)
            || c.downcast_ref::<InputError>().is_some_and(input)
            || c.downcast_ref::<FitError>()
                .is_some_and(|f| matches!(f, FitError::Input(i) if input(i)))
            || c.downcast_ref::<SelectionError>()
                .is_some_and(|f| matches!(f, SelectionError::Input(i) if input(i)))
            || c.downcast_ref::<Error>().is_some_and(|g| match g {
                Error::Series(s) => short(s),
                Error::Fit(FitError::Input(i)) | Error::Selection(SelectionError::Input(i)) => {
                    input(i)
                }
                _ => false,
            })
    })
}

/// Standard output with its write errors naming it (`standard output: No space left on
/// device`); the kind is kept (a closed pipe is still [`std::io::ErrorKind::BrokenPipe`]).
struct Stdout<W>(W);

impl<W: Write> Write for Stdout<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.write(buf).map_err(named_stdout)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.0.flush().map_err(named_stdout)
    }
}

fn named_stdout(e: std::io::Error) -> std::io::Error {
    std::io::Error::new(e.kind(), format!("standard output: {e}"))
}

fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// The flags, parsed with colour as [`style::colour`] allows. A flag value outside its domain
/// (`--freq -5`, `--G 0`, `--rule foo`): one line naming the flag and what would be valid, exit
/// code 2; other usage errors keep clap's message with the usage.
fn parse() -> Result<Cli, ExitCode> {
    let colour = match style::colour() {
        true => clap::ColorChoice::Auto,
        false => clap::ColorChoice::Never,
    };
    let mut command = Cli::command().color(colour);
    let parsed = command
        .try_get_matches_from_mut(std::env::args_os())
        .and_then(|mut m| Cli::from_arg_matches_mut(&mut m))
        .map_err(|e| e.format(&mut command));
    match parsed {
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
    panic::install();
    signals::install();
    let cli = match parse() {
        Ok(cli) => cli,
        Err(code) => return code,
    };
    match run(&cli, OutputStyle::detect(cli.quiet)) {
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
