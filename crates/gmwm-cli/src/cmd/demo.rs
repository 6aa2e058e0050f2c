//! `gmwm demo`: the main job on a built-in default — simulate a sensor with known truth and
//! show its wavelet variance.

use crate::args::DemoArgs;
use crate::cmd::wv::options;
use crate::render::{self, Named, Style};
use anyhow::Result;
use gmwm::sim::DemoSensor;
use gmwm::wavelet_variance;
use std::io::Write;

/// Runs the subcommand.
pub fn run(args: &DemoArgs, out: &mut impl Write) -> Result<()> {
    let opts = options(&args.estimator)?;
    let sensor = DemoSensor::default();
    let x = sensor.simulate(args.n, args.seed)?;
    let wv = wavelet_variance(&x, sensor.freq_hz, &opts)?;
    let style = Style::from(&args.output);
    if style == Style::Table {
        writeln!(
            out,
            "demo sensor: {} at {} Hz, N = {}, seed {}",
            sensor.model_text(),
            sensor.freq_hz,
            args.n,
            args.seed
        )?;
    }
    let name = "demo";
    render::series(out, &[Named { name, result: &wv }], style)
}
