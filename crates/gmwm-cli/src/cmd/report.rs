//! `gmwm report`: `gmwm calibrate` with the HTML report as its output.

use super::calibrate::{execute_in, Mode};
use super::Command;
use crate::config::ReportConfig;
use crate::prepare::Inputs;
use crate::style::OutputStyle;
use anyhow::Result;
use std::io::Write;
use std::path::Path;

impl Command for ReportConfig {
    fn inputs(&mut self) -> Inputs<'_> {
        Inputs::Recording(&mut self.calibrate.input)
    }

    fn outputs(&self) -> Vec<&Path> {
        let c = &self.calibrate;
        let mut out: Vec<&Path> = c.exports.iter().map(|(_, p)| p.as_path()).collect();
        out.extend(c.json.as_deref());
        out.push(&self.output);
        out
    }

    fn levels(&self) -> Option<usize> {
        self.calibrate.options.wv.levels
    }

    fn run(&self, style: OutputStyle, mut out: &mut dyn Write) -> Result<()> {
        let mode = Mode {
            print_summary: false,
            style,
        };
        execute_in(&self.calibrate, Some(&self.output), mode, &mut out).map(|_| ())
    }
}
