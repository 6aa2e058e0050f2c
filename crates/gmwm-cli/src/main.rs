//! `gmwm`: command-line front end of the gmwm engine. Parses flags, runs one subcommand,
//! renders its result; no numerics of its own.
//!
//! Exit codes: 0 success, 1 input or computation error (one line on stderr), 2 usage error.

mod args;
mod cmd;
mod input;
mod render;

use args::{Cli, Command};
use clap::Parser;
use std::io::{BufWriter, Write};
use std::process::ExitCode;

fn run(cli: &Cli) -> anyhow::Result<()> {
    let stdout = std::io::stdout();
    let mut out = BufWriter::new(stdout.lock());
    match &cli.command {
        Command::Demo(a) => cmd::demo::run(a, &mut out)?,
        Command::Wv(a) => cmd::wv::run(a, &mut out)?,
        Command::Avar(a) => cmd::avar::run(a, &mut out)?,
        Command::Simulate(a) => cmd::simulate::run(a, &mut out)?,
        Command::Implied(a) => cmd::implied::run(a, &mut out)?,
        Command::Fit(a) => cmd::fit::run(a, &mut out)?,
        Command::Select(a) => cmd::select::run(a, &mut out)?,
    }
    out.flush()?;
    Ok(())
}

fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(&cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("gmwm: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
