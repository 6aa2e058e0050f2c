//! `gmwm implied`: the implied wavelet variance of a fully specified model.

use super::Command;
use crate::config::ImpliedConfig;
use crate::prepare::Inputs;
use crate::style::OutputStyle;
use anyhow::Result;
use std::io::Write;
use std::path::Path;

/// Runs the subcommand.
pub fn run(config: &ImpliedConfig, out: &mut impl Write) -> Result<()> {
    let implied = config.model.implied_wv(config.levels, config.freq_hz)?;
    if config.json {
        serde_json::to_writer_pretty(&mut *out, &implied)?;
        writeln!(out)?;
    } else {
        write!(out, "{implied}")?;
    }
    Ok(())
}

impl Command for ImpliedConfig {
    fn inputs(&mut self) -> Inputs<'_> {
        Inputs::None
    }

    fn outputs(&self) -> Vec<&Path> {
        Vec::new()
    }

    fn levels(&self) -> Option<usize> {
        // the levels of a model, not of a series
        None
    }

    fn run(&self, _: OutputStyle, mut out: &mut dyn Write) -> Result<()> {
        run(self, &mut out)
    }
}
