//! `gmwm plot`: one figure of the matching command's results (gmwm-plot renders; the numbers
//! are those `gmwm wv|avar|fit|select --json` gives, and the engine's Welch PSD for `psd`).

use super::Command;
use crate::config::{FigureConfig, PlotConfig, PlotKind};
use crate::error::UsageError;
use crate::input::{is_wv, InputConfig};
use crate::prepare::Inputs;
use crate::style::OutputStyle;
use anyhow::{Context, Result};
use gmwm::{
    ieee_readoff, welch_psd, DatasheetLine, Sensor, SensorInfo, SignalKind, SignalUnit,
    BINNED_POINTS,
};
use gmwm_plot::{Column, Figure};
use std::io::Write;
use std::path::Path;

/// The sensor and the unit of each column for axis labels, legends and datasheet lines: the
/// unit `--gyro-unit`/`--accel-unit` give for its sensor, else the one its name or the sidecar
/// states (SI for ROS recordings and binary IMU records); `None` when unknown.
fn column_units(
    config: &PlotConfig,
    input: &InputConfig,
    names: &[String],
) -> Result<Vec<(Sensor, Option<SignalUnit>)>> {
    let ros = input.probe().container().is_some();
    if ros && (config.gyro_unit.is_some() || config.accel_unit.is_some()) {
        return Err(UsageError(format!(
            "{}: a ROS recording (sensor_msgs/Imu) is SI by definition: drop --gyro-unit/--accel-unit",
            input.file.display()
        ))
        .into());
    }
    let sidecar = if ros || is_wv(input) {
        None
    } else {
        gmwm::find_sidecar(&input.file).ok().flatten()
    };
    // binary IMU records by --format or by the sidecar's format, as the reader resolves it
    let record = matches!(input.read.format, gmwm::InputFormat::ImuRecord(_))
        || sidecar
            .as_ref()
            .and_then(|s| s.format.as_deref())
            .and_then(|f| f.parse::<gmwm::InputFormat>().ok())
            .is_some_and(|f| matches!(f, gmwm::InputFormat::ImuRecord(_)));
    Ok(names
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
            let given = match sensor {
                Sensor::Gyroscope => config.gyro_unit,
                Sensor::Accelerometer => config.accel_unit,
                Sensor::Other => None,
            };
            let text = if ros {
                match sensor {
                    Sensor::Gyroscope => Some("rad/s".to_string()),
                    Sensor::Accelerometer => Some("m/s^2".to_string()),
                    Sensor::Other => None,
                }
            } else {
                SensorInfo::column_unit(name, sensor, sidecar.as_ref(), record)
            };
            let unit = given.or_else(|| text.and_then(|t| t.parse::<SignalUnit>().ok()));
            (sensor, unit)
        })
        .collect())
}

/// The figure's columns: each in its unit (`u` when unknown) with the datasheet's lines of its
/// sensor in that unit.
fn columns<'a, T>(
    items: &'a [(String, T)],
    units: &'a [String],
    lines: &[Vec<DatasheetLine>],
) -> Vec<Column<'a, T>> {
    items
        .iter()
        .zip(units)
        .zip(lines)
        .map(|(((name, data), unit), lines)| {
            Column::new(name, unit, data).with_datasheet(lines.clone())
        })
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

/// Draws `items` with `build` in the columns' units, with the datasheet's lines on the
/// columns of its sensors, and writes the figure; a note for a datasheet that finds no column
/// to draw on, or a column of its sensor whose unit is unknown.
fn draw<T>(
    config: &PlotConfig,
    input: &InputConfig,
    items: &[(String, T)],
    build: impl Fn(&[Column<'_, T>]) -> Figure,
    style: OutputStyle,
    out: &mut impl Write,
) -> Result<()> {
    let placed = column_units(config, input, &names(items))?;
    let units: Vec<String> = placed
        .iter()
        .map(|(_, u)| u.map_or_else(|| "u".to_string(), |u| u.symbol().to_string()))
        .collect();
    let lines: Vec<Vec<DatasheetLine>> = placed
        .iter()
        .map(|(_, u)| match (&config.datasheet, u) {
            (Some(sheet), Some(u)) => sheet.lines(*u),
            _ => Vec::new(),
        })
        .collect();
    if let Some(sheet) = &config.datasheet {
        for ((name, _), (sensor, unit)) in items.iter().zip(&placed) {
            let kind = match sensor {
                Sensor::Gyroscope => SignalKind::Gyroscope,
                Sensor::Accelerometer => SignalKind::Accelerometer,
                Sensor::Other => continue,
            };
            if unit.is_none() && sheet.has(kind) {
                let flag = match kind {
                    SignalKind::Gyroscope => "--gyro-unit",
                    SignalKind::Accelerometer => "--accel-unit",
                };
                style.note(
                    &input.file,
                    &format!("column {name}: unit unknown, no datasheet line drawn (give {flag})"),
                );
            }
        }
        if lines.iter().all(Vec::is_empty) {
            style.note(
                &input.file,
                "--datasheet: no column of the datasheet's sensors with a known unit: no line drawn",
            );
        }
    }
    save(build(&columns(items, &units, &lines)), &config.figure, out)
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
    let layout = config.figure.layout;
    match &config.kind {
        PlotKind::Wv(c) => {
            let items = super::wv::compute(c, style)?;
            draw(
                config,
                &c.input,
                &items,
                |cols| gmwm_plot::wv_figure(cols, layout),
                style,
                out,
            )
        }
        PlotKind::Avar(c) => {
            let items = super::avar::compute(c, style)?;
            draw(
                config,
                &c.input,
                &items,
                |cols| gmwm_plot::allan_figure(cols, layout),
                style,
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
            draw(config, input, &items, gmwm_plot::compare_figure, style, out)
        }
        PlotKind::Fit(c) => {
            let fits = super::fit::compute(c, style)?;
            draw(config, &c.input, &fits, gmwm_plot::fit_figure, style, out)
        }
        PlotKind::Select(c) => {
            let selections = super::select::compute(c, style)?;
            let top = c.top;
            let build = |cols: &[Column<'_, _>]| gmwm_plot::selection_figure(cols, top);
            draw(config, &c.input, &selections, build, style, out)
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
            draw(config, &c.input, &pairs, gmwm_plot::ieee_figure, style, out)
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
                config,
                input,
                &items,
                |cols| gmwm_plot::psd_figure(cols, layout),
                style,
                out,
            )
        }
    }
}
