//! `gmwm report`: `gmwm calibrate` with the HTML report as its output.

use crate::config::ReportConfig;
use anyhow::Result;
use std::io::Write;

/// Runs the subcommand.
pub fn run(config: &ReportConfig, out: &mut impl Write) -> Result<()> {
    crate::cmd::calibrate::execute(&config.calibrate, Some(&config.output), false, out)
}
