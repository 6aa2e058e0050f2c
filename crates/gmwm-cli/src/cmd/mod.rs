//! One module per subcommand, each behind [`Command`]: what it reads, what it writes, its
//! `--levels`, and how it runs. `main` runs every subcommand through the same path (prepare its
//! inputs, check its outputs' folders, run, name `--levels` in a too-short error), so a
//! subcommand cannot skip a step: it declares each, and [`of`] lists every configuration.

pub mod avar;
pub mod batch;
pub mod calibrate;
pub mod covariate;
pub mod demo;
pub mod dynamic;
pub mod fit;
pub mod implied;
pub mod monitor;
pub mod plan;
pub mod plot;
pub mod report;
pub mod same_model;
pub mod select;
pub mod shared;
pub mod simulate;
pub mod topics;
pub mod wv;

use crate::config::Config;
use crate::prepare::Inputs;
use crate::style::OutputStyle;
use anyhow::Result;
use std::io::Write;
use std::path::Path;

/// A subcommand, configured: every method is required, so a new one declares each step.
pub trait Command {
    /// What it reads, prepared before it runs ([`crate::prepare::prepare`]).
    fn inputs(&mut self) -> Inputs<'_>;
    /// The files it writes (`-` is standard output), whose folders must exist before any work.
    fn outputs(&self) -> Vec<&Path>;
    /// `--levels J`, named in the error of a series too short for it.
    fn levels(&self) -> Option<usize>;
    /// Runs it: results on `out`, progress and notes on stderr as `style` says.
    fn run(&self, style: OutputStyle, out: &mut dyn Write) -> Result<()>;
}

/// The subcommand a configuration runs.
pub fn of(config: &mut Config) -> &mut dyn Command {
    match config {
        Config::Demo(c) => c,
        Config::Wv(c) => c,
        Config::Avar(c) => c,
        Config::Simulate(c) => c,
        Config::Implied(c) => c,
        Config::Plan(c) => c,
        Config::Fit(c) => c,
        Config::Select(c) => c,
        Config::Calibrate(c) => c,
        Config::Topics(c) => c,
        Config::Plot(c) => c,
        Config::Report(c) => c,
        Config::Batch(c) => c,
        Config::Shared(c) => c,
        Config::Monitor(c) => c,
        Config::SameModel(c) => c,
        Config::PooledFit(c) => c,
        Config::CovariateFit(c) => c,
        Config::DynamicFit(c) => c,
        Config::PooledSelect(c) => c,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::args::Cli;
    use clap::Parser;

    fn config(argv: &[&str]) -> Config {
        let cli = Cli::try_parse_from(std::iter::once("gmwm").chain(argv.iter().copied()))
            .unwrap_or_else(|e| panic!("clap refuses {argv:?}: {e}"));
        Config::try_from(&cli.command).unwrap_or_else(|e| panic!("{argv:?}: {e:#}"))
    }

    /// What a command declares it reads, by kind.
    fn reads(argv: &[&str]) -> &'static str {
        match of(&mut config(argv)).inputs() {
            Inputs::None => "none",
            Inputs::Recording(_) => "recording",
            Inputs::RosFile(_) => "ros file",
            Inputs::Files { .. } => "files",
            Inputs::Pool => "pool",
        }
    }

    #[test]
    fn every_subcommand_declares_what_it_reads() {
        for (argv, kind) in [
            (&["demo"][..], "none"),
            (
                &["simulate", "--model", "WN(sigma2=1)", "--n", "10"],
                "none",
            ),
            (
                &["implied", "--model", "WN(sigma2=1)", "--levels", "3"],
                "none",
            ),
            (&["wv", "x.csv"], "recording"),
            (&["avar", "x.csv"], "recording"),
            (&["fit", "x.csv", "--model", "WN()"], "recording"),
            (&["select", "x.csv", "--model", "WN()"], "recording"),
            (&["calibrate", "x.csv"], "recording"),
            (&["report", "x.csv"], "recording"),
            (&["plot", "ieee", "x.csv", "-o", "f.svg"], "recording"),
            (
                &["shared", "x.csv", "--shared", "GM()", "--model", "WN()"],
                "recording",
            ),
            (&["monitor", "x.csv", "--model-from", "c.json"], "recording"),
            (&["topics", "x.bag"], "ros file"),
            (&["wv", "a.csv", "b.csv"], "files"),
            (&["calibrate", "a.csv", "b.csv", "--pool"], "files"),
            (
                &["fit", "a.csv", "b.csv", "--pool", "--model", "WN()"],
                "pool",
            ),
            (
                &["select", "a.csv", "b.csv", "--pool", "--model", "WN()"],
                "pool",
            ),
            (&["same-model", "a.csv", "b.csv", "--model", "WN()"], "pool"),
        ] {
            assert_eq!(reads(argv), kind, "{argv:?}");
        }
    }

    #[test]
    fn outputs_and_levels_are_declared() {
        let mut c = config(&[
            "calibrate",
            "x.csv",
            "--kalibr",
            "k.yaml",
            "--json",
            "-",
            "--report",
            "r.html",
            "--levels",
            "9",
        ]);
        let command = of(&mut c);
        let outputs: Vec<&Path> = command.outputs();
        assert_eq!(
            outputs,
            [Path::new("k.yaml"), Path::new("-"), Path::new("r.html")]
        );
        assert_eq!(command.levels(), Some(9));
        let mut c = config(&["plot", "wv", "x.csv", "--levels", "4", "-o", "d/f.svg"]);
        let command = of(&mut c);
        assert_eq!(command.outputs(), [Path::new("d/f.svg")]);
        assert_eq!(command.levels(), Some(4));
        assert_eq!(of(&mut config(&["wv", "x.csv"])).levels(), None);
    }
}
