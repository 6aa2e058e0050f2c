//! `gmwm`: command-line front end of the gmwm engine. Parses flags, validates them once into
//! the subcommand's configuration (`config.rs`), runs the subcommand, renders its result; no
//! numerics of its own.
//!
//! Exit codes: 0 success, 1 input or computation error (one line on stderr), 2 usage error.

mod args;
mod cmd;
mod config;
mod error;
mod input;
mod output;
mod panic;
mod progress;
mod recordings;
mod render;
mod spool;

use args::Cli;
use clap::Parser;
use config::{Config, PlotKind};
use error::{one_line, UsageError};
use input::InputConfig;
use std::io::{BufWriter, Write};
use std::path::Path;
use std::process::ExitCode;

/// Validates the flags into the subcommand's configuration, before any file is read, then
/// runs it.
fn run(cli: &Cli) -> anyhow::Result<()> {
    // several recordings at once (issue 16): their own path, cmd::same_model
    match &cli.command {
        args::Command::SameModel(a) => return stdout_run(|out| cmd::same_model::run(a, out)),
        args::Command::Fit(a) if a.pool => {
            return stdout_run(|out| cmd::same_model::run_pooled_fit(a, out))
        }
        args::Command::Select(a) if a.pool => {
            return stdout_run(|out| cmd::same_model::run_pooled_select(a, out))
        }
        _ => {}
    }
    let mut config = Config::try_from(&cli.command)?;
    let _spool = prepare_input(&mut config)?;
    check_outputs(&config)?;
    let levels = levels_of(&config);
    execute(&config).map_err(|e| match levels {
        // a series too short for the levels asked: the flag is the thing to change
        Some(j) if too_short(&e) => e.context(format!("--levels {j}")),
        _ => e,
    })
}

/// The files a command will write (`-` for standard output left out).
fn outputs(config: &Config) -> Vec<&Path> {
    let mut out: Vec<&Path> = Vec::new();
    match config {
        Config::Calibrate(c) => {
            out.extend(c.exports.iter().map(|(_, p)| p.as_path()));
            out.extend(c.json.as_deref());
            out.extend(c.report.as_deref());
        }
        Config::Report(r) => {
            out.extend(r.calibrate.exports.iter().map(|(_, p)| p.as_path()));
            out.extend(r.calibrate.json.as_deref());
            out.push(&r.output);
        }
        Config::Plot(p) => out.push(&p.figure.output),
        _ => {}
    }
    out.retain(|p| p.as_os_str() != "-");
    out
}

/// Before any work: every file the command writes must have a folder to go in (STYLE §9: a bad
/// path fails in milliseconds, not after the calibration).
fn check_outputs(config: &Config) -> anyhow::Result<()> {
    for path in outputs(config) {
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

/// `--levels J` when the command was given one.
fn levels_of(config: &Config) -> Option<usize> {
    match config {
        Config::Wv(c) => c.wv.levels,
        Config::Fit(c) => c.wv.levels,
        Config::Select(c) => c.wv.levels,
        Config::Calibrate(c) => c.options.wv.levels,
        Config::Report(c) => c.calibrate.options.wv.levels,
        Config::Plot(c) => match &c.kind {
            PlotKind::Wv(c) => c.wv.levels,
            PlotKind::Fit(c) => c.wv.levels,
            PlotKind::Select(c) => c.wv.levels,
            _ => None,
        },
        _ => None,
    }
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

/// Runs `f` on buffered standard output and flushes it.
fn stdout_run(
    f: impl FnOnce(&mut BufWriter<Stdout<std::io::StdoutLock<'static>>>) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    let mut out = BufWriter::new(Stdout(std::io::stdout().lock()));
    f(&mut out)?;
    out.flush()?;
    Ok(())
}

fn execute(config: &Config) -> anyhow::Result<()> {
    let stdout = std::io::stdout();
    let mut out = BufWriter::new(Stdout(stdout.lock()));
    match config {
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
        Config::Batch(c) => cmd::batch::run(c, &mut out)?,
        Config::Shared(c) => cmd::shared::run(c, &mut out)?,
        Config::Monitor(c) => cmd::monitor::run(c, &mut out)?,
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
        Config::Shared(c) => &mut c.input,
        Config::Monitor(c) => &mut c.input,
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
    if let Config::Calibrate(c) = config {
        if let Some(p) = c.pool.iter().find(|p| spool::is_stream(p)) {
            return Err(UsageError(format!(
                "{}: --pool reads several recordings from files; give standard input or a \
                 pipe to a one-recording command",
                if p.as_os_str() == "-" {
                    spool::STDIN.to_string()
                } else {
                    p.display().to_string()
                }
            ))
            .into());
        }
        if !c.pool.is_empty() {
            return Ok(None);
        }
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
    if let Some(topic) = &input.topic {
        if !spool::is_stream(&input.file)
            && gmwm::imu::ros::container_of(&input.file).is_none()
            && input.read.format == gmwm::imu::InputFormat::Auto
            && input.file.exists()
        {
            return Err(UsageError(format!(
                "invalid --topic {topic}: {} is not a ROS recording (ROS1 bag, MCAP, rosbag2 \
                 sqlite3)",
                input.file.display()
            ))
            .into());
        }
    }
    if input.file.is_dir() && !recordings::is_rosbag2_folder(&input.file) {
        anyhow::bail!(
            "{}: is a folder, not a recording (a rosbag2 folder holds metadata.yaml; gmwm wv \
             and gmwm calibrate also take a folder of recordings)",
            input.file.display()
        );
    }
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
pub(crate) fn warn_implausible(input: &InputConfig) {
    if input.read.format == gmwm::imu::InputFormat::Auto
        && (gmwm::imu::ros::container_of(&input.file).is_some() || input::is_wv(input))
    {
        return;
    }
    let layout = match gmwm::imu::binary_layout(&input.file, &input.read) {
        Ok(layout) => layout,
        // a size that is no whole number of rows (the reader says so next): the values are
        // still looked at when the format was given, as text read as f64 often has that size
        Err(_) => matches!(
            input.read.format,
            gmwm::imu::InputFormat::F64 | gmwm::imu::InputFormat::F32
        )
        .then(|| gmwm::imu::BinaryLayout {
            format: input.read.format,
            ncols: 1,
            names: Vec::new(),
        }),
    };
    if let Some(layout) = layout {
        if let Ok(Some(bad)) = gmwm::imu::plausible::raw_floats(&input.file, &layout) {
            eprintln!("gmwm: warning: {}", spool::shown(&bad.to_string()));
        }
    }
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
    panic::install();
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
