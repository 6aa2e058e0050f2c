//! `gmwm implied`: the implied wavelet variance of a fully specified model.

use crate::config::ImpliedConfig;
use anyhow::Result;
use std::io::Write;

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
