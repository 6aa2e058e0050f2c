//! `gmwm plot`: one figure of the matching command's results (gmwm-plot renders; the numbers
//! are those `gmwm wv|avar|fit|select --json` gives, and the engine's Welch PSD for `psd`).

use super::Command;
use crate::config::{FigureConfig, PlotConfig, PlotKind};
use crate::input::{is_wv, InputConfig};
use crate::prepare::Inputs;
use crate::style::OutputStyle;
use anyhow::{Context, Result};
use gmwm::calib::ieee::ieee_readoff;
use gmwm::imu::{Sensor, SensorInfo};
use gmwm::units::SignalUnit;
use gmwm::variance::psd::{welch_psd, BINNED_POINTS};
use gmwm_plot::{Column, Figure};
use std::io::Write;
use std::path::Path;

/// The unit of each column for axis labels and legends: the one its name or the sidecar
/// states (SI for ROS recordings and binary IMU records), as its symbol; `u` when unknown.
fn column_units(input: &InputConfig, names: &[String]) -> Vec<String> {
    let ros = input.probe().container().is_some();
    let sidecar = if ros || is_wv(input) {
        None
    } else {
        gmwm::imu::find_sidecar(&input.file).ok().flatten()
    };
    // binary IMU records by --format or by the sidecar's format, as the reader resolves it
    let record = matches!(input.read.format, gmwm::imu::InputFormat::ImuRecord(_))
        || sidecar
            .as_ref()
            .and_then(|s| s.format.as_deref())
            .and_then(|f| f.parse::<gmwm::imu::InputFormat>().ok())
            .is_some_and(|f| matches!(f, gmwm::imu::InputFormat::ImuRecord(_)));
    names
        .iter()
        .map(|name| {
            // the sensor from the name, else the sidecar's meaning (as SensorInfo::of_table)
            let sensor = SensorInfo::infer(name)
                .or_else(|| {
                    sidecar
                        .as_ref()
                        .and_then(|s| s.meaning(name))
                        .and_then(SensorInfo::infer)
                })
                .map_or(Sensor::Other, |(s, _)| s);
            let text = if ros {
                match sensor {
                    Sensor::Gyroscope => Some("rad/s".to_string()),
                    Sensor::Accelerometer => Some("m/s^2".to_string()),
                    Sensor::Other => None,
                }
            } else {
                SensorInfo::column_unit(name, sensor, sidecar.as_ref(), record)
            };
            text.and_then(|t| t.parse::<SignalUnit>().ok())
                .map_or_else(|| "u".to_string(), |u| u.symbol().to_string())
        })
        .collect()
}

fn columns<'a, T>(items: &'a [(String, T)], units: &'a [String]) -> Vec<Column<'a, T>> {
    items
        .iter()
        .zip(units)
        .map(|((name, data), unit)| Column::new(name, unit, data))
        .collect()
}

/// Writes `fig` at the requested size and says where.
fn save(fig: Figure, args: &FigureConfig, out: &mut impl Write) -> Result<()> {
    let (w, h) = fig.size;
    let size = (args.width.unwrap_or(w), args.height.unwrap_or(h));
    let fig = fig.with_size(size);
    crate::render::save_figure(&fig, &args.output)?;
    writeln!(
        out,
        "wrote {} ({}x{} px, {} panel(s))",
        args.output.display(),
        size.0,
        size.1,
        fig.panels.len()
    )?;
    Ok(())
}

fn names<T>(items: &[(String, T)]) -> Vec<String> {
    items.iter().map(|(n, _)| n.clone()).collect()
}

/// Draws `items` with `build` in the columns' units and writes the figure.
fn draw<T>(
    input: &InputConfig,
    items: &[(String, T)],
    build: impl Fn(&[Column<'_, T>]) -> Figure,
    figure: &FigureConfig,
    out: &mut impl Write,
) -> Result<()> {
    let units = column_units(input, &names(items));
    save(build(&columns(items, &units)), figure, out)
}

impl Command for PlotConfig {
    fn inputs(&mut self) -> Inputs<'_> {
        Inputs::Recording(match &mut self.kind {
            PlotKind::Wv(c) => &mut c.input,
            PlotKind::Avar(c) | PlotKind::Ieee(c) => &mut c.input,
            PlotKind::Compare(c) => &mut c.input,
            PlotKind::Fit(c) => &mut c.input,
            PlotKind::Select(c) => &mut c.input,
            PlotKind::Psd(c) => &mut c.input,
        })
    }

    fn outputs(&self) -> Vec<&Path> {
        vec![&self.figure.output]
    }

    fn levels(&self) -> Option<usize> {
        match &self.kind {
            PlotKind::Wv(c) => c.wv.levels,
            PlotKind::Fit(c) => c.wv.levels,
            PlotKind::Select(c) => c.wv.levels,
            // compare's --levels: the engine's error without the flag, as before
            PlotKind::Avar(_) | PlotKind::Ieee(_) | PlotKind::Compare(_) | PlotKind::Psd(_) => None,
        }
    }

    fn run(&self, style: OutputStyle, mut out: &mut dyn Write) -> Result<()> {
        run(self, style, &mut out)
    }
}

/// Computes the figure's data and draws it.
fn run(config: &PlotConfig, style: OutputStyle, out: &mut impl Write) -> Result<()> {
    let figure = &config.figure;
    let layout = figure.layout;
    match &config.kind {
        PlotKind::Wv(c) => {
            let items = super::wv::compute(c, style)?;
            draw(
                &c.input,
                &items,
                |cols| gmwm_plot::wv_figure(cols, layout),
                figure,
                out,
            )
        }
        PlotKind::Avar(c) => {
            let items = super::avar::compute(c, style)?;
            draw(
                &c.input,
                &items,
                |cols| gmwm_plot::allan_figure(cols, layout),
                figure,
                out,
            )
        }
        PlotKind::Compare(c) => {
            let input = &c.input;
            anyhow::ensure!(
                !is_wv(input),
                "{}: classical against robust needs the samples, not a saved wavelet variance",
                input.file.display()
            );
            let loaded = crate::input::load(input, style)?;
            let items = crate::input::analyse_columns(&loaded, &input.file, |x| {
                Ok((
                    gmwm::wavelet_variance(x, loaded.freq_hz, &c.classical)?,
                    gmwm::wavelet_variance(x, loaded.freq_hz, &c.robust)?,
                ))
            })?;
            draw(input, &items, gmwm_plot::compare_figure, figure, out)
        }
        PlotKind::Fit(c) => {
            let fits = super::fit::compute(c, style)?;
            draw(&c.input, &fits, gmwm_plot::fit_figure, figure, out)
        }
        PlotKind::Select(c) => {
            let selections = super::select::compute(c, style)?;
            let top = c.top;
            let build = |cols: &[Column<'_, _>]| gmwm_plot::selection_figure(cols, top);
            draw(&c.input, &selections, build, figure, out)
        }
        PlotKind::Ieee(c) => {
            let items = super::avar::compute(c, style)?;
            let mut pairs = Vec::with_capacity(items.len());
            for (name, av) in items {
                let readoff = ieee_readoff(&av)
                    .map_err(gmwm::Error::from)
                    .with_context(|| format!("{}: column {name}", c.input.file.display()))?;
                pairs.push((name, (av, readoff)));
            }
            draw(&c.input, &pairs, gmwm_plot::ieee_figure, figure, out)
        }
        PlotKind::Psd(c) => {
            let input = &c.input;
            anyhow::ensure!(
                !is_wv(input),
                "{}: a PSD needs the samples, not a saved wavelet variance",
                input.file.display()
            );
            let loaded = crate::input::load(input, style)?;
            // the column is borrowed, never copied: Welch keeps one segment (at most 2^16)
            let items = crate::input::analyse_columns(&loaded, &input.file, |x| {
                let psd = welch_psd(x, loaded.freq_hz)?;
                Ok((psd.binned(BINNED_POINTS), None))
            })?;
            draw(
                input,
                &items,
                |cols| gmwm_plot::psd_figure(cols, layout),
                figure,
                out,
            )
        }
    }
}
