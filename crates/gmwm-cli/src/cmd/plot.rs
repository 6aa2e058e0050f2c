//! `gmwm plot`: one figure of the matching command's results (gmwm-plot renders; the numbers
//! are those `gmwm wv|avar|fit|select --json` gives).

use crate::args::{FigureArgs, InputArgs, KindArg, OutputArgs, PlotArgs, PlotCommand};
use crate::input::is_wv;
use crate::UsageError;
use anyhow::{Context, Result};
use gmwm::calib::ieee::ieee_readoff;
use gmwm::imu::{Sensor, SensorInfo};
use gmwm::units::SignalUnit;
use gmwm::{RobustOptions, WvOptions};
use gmwm_plot::{Column, Figure, ImageFormat, Layout};
use std::io::Write;

/// The unit of each column for axis labels and legends: the one its name or the sidecar
/// states (SI for ROS recordings and binary IMU records), as its symbol; `u` when unknown.
fn column_units(input: &InputArgs, names: &[String]) -> Vec<String> {
    let ros = gmwm::imu::ros::container_of(&input.file).is_some();
    let sidecar = if ros || is_wv(input) {
        None
    } else {
        gmwm::imu::find_sidecar(&input.file).ok().flatten()
    };
    // binary IMU records by --format or by the sidecar's format, as the reader resolves it
    let record = matches!(
        crate::input::format(input.format),
        gmwm::imu::InputFormat::ImuRecord(_)
    ) || sidecar
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

/// `--json`/`--csv` belong to the tables; a figure refuses them instead of ignoring them.
fn no_table_output(output: &OutputArgs) -> Result<()> {
    if output.json || output.csv {
        return Err(UsageError(
            "gmwm plot draws a figure: --json and --csv belong to gmwm wv|avar|fit|select".into(),
        )
        .into());
    }
    Ok(())
}

fn columns<'a, T>(items: &'a [(String, T)], units: &'a [String]) -> Vec<Column<'a, T>> {
    items
        .iter()
        .zip(units)
        .map(|((name, data), unit)| Column::new(name, unit, data))
        .collect()
}

fn layout(figure: &FigureArgs) -> Layout {
    if figure.overlay {
        Layout::Overlay
    } else {
        Layout::Grid
    }
}

/// A figure file name the renderer can write, checked before any computation.
fn check_output(figure: &FigureArgs) -> Result<()> {
    ImageFormat::of(&figure.output)
        .map(|_| ())
        .map_err(|e| UsageError(format!("invalid --output {e}")).into())
}

/// Writes `fig` at the requested size and says where.
fn save(fig: Figure, args: &FigureArgs, out: &mut impl Write) -> Result<()> {
    let (w, h) = fig.size;
    let size = (
        args.width
            .map_or(w, |v| u32::try_from(v).unwrap_or(u32::MAX)),
        args.height
            .map_or(h, |v| u32::try_from(v).unwrap_or(u32::MAX)),
    );
    let fig = fig.with_size(size);
    fig.save(&args.output).map_err(|e| match e {
        // a write error names the file already
        gmwm_plot::PlotError::Io { .. } => anyhow::Error::from(e),
        other => anyhow::anyhow!("{}: {other}", args.output.display()),
    })?;
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
    input: &InputArgs,
    items: &[(String, T)],
    build: impl Fn(&[Column<'_, T>]) -> Figure,
    figure: &FigureArgs,
    out: &mut impl Write,
) -> Result<()> {
    let units = column_units(input, &names(items));
    save(build(&columns(items, &units)), figure, out)
}

/// Flags the figure cannot honour, refused before any computation.
fn check_flags(command: &PlotCommand) -> Result<()> {
    let (output, figure) = match command {
        PlotCommand::Wv { args, figure } | PlotCommand::Compare { args, figure } => {
            (&args.output, figure)
        }
        PlotCommand::Avar { args, figure } => (&args.output, figure),
        PlotCommand::Ieee { args, figure } => {
            if args.kind != KindArg::Overlapping {
                return Err(UsageError(
                    "gmwm plot ieee reads the overlapping Allan variance (IEEE Std 952): drop --kind"
                        .into(),
                )
                .into());
            }
            (&args.output, figure)
        }
        PlotCommand::Fit { args, figure } => {
            if args.inference {
                return Err(UsageError(
                    "gmwm plot fit draws the fit: --inference belongs to gmwm fit".into(),
                )
                .into());
            }
            (&args.output, figure)
        }
        PlotCommand::Select { args, figure } => (&args.output, figure),
    };
    no_table_output(output)?;
    let layered = matches!(command, PlotCommand::Wv { .. } | PlotCommand::Avar { .. });
    if figure.overlay && !layered {
        return Err(UsageError(
            "--overlay lays out the axes of gmwm plot wv and avar; this figure has one panel per column"
                .into(),
        )
        .into());
    }
    let too_large = |v: Option<usize>| v.is_some_and(|v| v > gmwm_plot::MAX_SIDE as usize);
    if too_large(figure.width) || too_large(figure.height) {
        return Err(UsageError(format!(
            "invalid --width/--height: at most {} px a side",
            gmwm_plot::MAX_SIDE
        ))
        .into());
    }
    if let (Some(w), Some(h)) = (figure.width, figure.height) {
        if (w as u64) * (h as u64) > gmwm_plot::MAX_PIXELS {
            return Err(UsageError(format!(
                "invalid --width {w} --height {h}: at most {} megapixels",
                gmwm_plot::MAX_PIXELS / 1_000_000
            ))
            .into());
        }
    }
    check_output(figure)
}

/// Runs the subcommand.
pub fn run(args: &PlotArgs, out: &mut impl Write) -> Result<()> {
    check_flags(&args.figure)?;
    match &args.figure {
        PlotCommand::Wv { args, figure } => {
            let items = crate::cmd::wv::compute(args)?;
            let layout = layout(figure);
            draw(
                &args.input,
                &items,
                |c| gmwm_plot::wv_figure(c, layout),
                figure,
                out,
            )
        }
        PlotCommand::Avar { args, figure } => {
            let items = crate::cmd::avar::compute(args)?;
            let layout = layout(figure);
            draw(
                &args.input,
                &items,
                |c| gmwm_plot::allan_figure(c, layout),
                figure,
                out,
            )
        }
        PlotCommand::Compare { args, figure } => {
            anyhow::ensure!(
                !is_wv(&args.input),
                "{}: classical against robust needs the samples, not a saved wavelet variance",
                args.input.file.display()
            );
            let classical_opts = WvOptions {
                robust: None,
                ..crate::cmd::wv::options(&args.estimator)?
            };
            let robust_opts = WvOptions {
                robust: Some(RobustOptions::new(
                    args.estimator.eff,
                    crate::cmd::wv::robust_convention(args.estimator.robust_convention),
                )?),
                ..classical_opts
            };
            let loaded = crate::input::load(&args.input)?;
            let items = crate::input::analyse_columns(&loaded, &args.input.file, |x| {
                Ok((
                    gmwm::wavelet_variance(x, loaded.freq_hz, &classical_opts)?,
                    gmwm::wavelet_variance(x, loaded.freq_hz, &robust_opts)?,
                ))
            })?;
            draw(&args.input, &items, gmwm_plot::compare_figure, figure, out)
        }
        PlotCommand::Fit { args, figure } => {
            let (_, fits) = crate::cmd::fit::compute(args)?;
            draw(&args.input, &fits, gmwm_plot::fit_figure, figure, out)
        }
        PlotCommand::Select { args, figure } => {
            let selections = crate::cmd::select::compute(args)?;
            let top = args.top;
            let build = |c: &[Column<'_, _>]| gmwm_plot::selection_figure(c, top);
            draw(&args.input, &selections, build, figure, out)
        }
        PlotCommand::Ieee { args, figure } => {
            let items = crate::cmd::avar::compute(args)?;
            let mut pairs = Vec::with_capacity(items.len());
            for (name, av) in items {
                let readoff = ieee_readoff(&av)
                    .map_err(gmwm::Error::from)
                    .with_context(|| format!("{}: column {name}", args.input.file.display()))?;
                pairs.push((name, (av, readoff)));
            }
            draw(&args.input, &pairs, gmwm_plot::ieee_figure, figure, out)
        }
    }
}
