//! `gmwm fit FILE... --covariate COL | --covariate-values LIST`: the parameters as functions
//! of a covariate (docs/methods.md §5.13). The engine does every computation
//! (`Gmwm::fit_covariate`, `CovariateFit::inference`, `CovariateInference::band`,
//! `gmwm::covariate_level`); this module reads the files and their levels and renders.

use super::same_model::{named, read_pool, write_recordings, RecordingInfo};
use super::Command;
use crate::config::{CovariateFitConfig, CovariateSource};
use crate::input::load;
use crate::prepare::Inputs;
use crate::render::Style;
use crate::style::OutputStyle;
use anyhow::Result;
use gmwm::{
    covariate_level, ColumnSelector, CovariateFit, CovariateInference, FitRecording,
    ParameterInference,
};
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};

impl Command for CovariateFitConfig {
    fn inputs(&mut self) -> Inputs<'_> {
        Inputs::Pool
    }

    fn outputs(&self) -> Vec<&Path> {
        Vec::new()
    }

    fn levels(&self) -> Option<usize> {
        None
    }

    fn run(&self, style: OutputStyle, mut out: &mut dyn Write) -> Result<()> {
        run(self, style, &mut out)
    }
}

/// The parameters at one covariate level with their pointwise bands.
#[derive(Debug, Serialize)]
struct Band {
    covariate: f64,
    parameters: Vec<ParameterInference>,
}

/// One column's covariate fit as reported.
#[derive(Debug, Serialize)]
struct ColumnFit<'a> {
    column: &'a str,
    #[serde(flatten)]
    fit: CovariateFit,
    inference: CovariateInference,
    bands: Vec<Band>,
}

/// The values of column `col` of `file` (read as `base` reads recordings), without notes
/// (the recording's notes come once, from the read of its sensor columns); of a ROS
/// recording, the covariate `col` one value per IMU message (a scalar topic or a magnitude,
/// `gmwm::read_ros_covariate`), with its notes. Also its unit, when the recording says it.
pub(super) fn covariate_values(
    base: &crate::input::InputConfig,
    file: &Path,
    col: &str,
    style: OutputStyle,
) -> Result<(Vec<f64>, Option<String>)> {
    let mut input = base.with_file(file);
    if input.probe().is_ros() {
        // a scalar topic interpolated to the IMU messages, or a magnitude of their fields
        let covariate = gmwm::read_ros_covariate(file, input.topic.as_deref(), col)?;
        for n in &covariate.notes {
            style.note(file, n);
        }
        return Ok((covariate.values, covariate.unit.map(str::to_owned)));
    }
    input.read.columns = vec![col
        .parse::<ColumnSelector>()
        .map_err(|e| anyhow::anyhow!("invalid --covariate {col}: {}", e.expected))?];
    let quiet = OutputStyle {
        notes: false,
        progress: false,
        ..style
    };
    // the reader's errors name the file, the line and the column
    let mut loaded = load(&input, quiet)?;
    Ok((std::mem::take(&mut loaded.table.columns[0].values), None))
}

fn covariate_column(
    config: &CovariateFitConfig,
    file: &Path,
    col: &str,
    style: OutputStyle,
) -> Result<Vec<f64>> {
    Ok(covariate_values(&config.fit.input, file, col, style)?.0)
}

/// What a covariate fit runs on: the recordings (or windows) as reported, their names in
/// errors, their covariate levels and, per column, their WVs.
struct FitInputs {
    info: Vec<RecordingInfo>,
    names: Vec<PathBuf>,
    covariates: Vec<f64>,
    columns: Vec<(String, Vec<FitRecording>)>,
}

/// Several FILEs, each at its level: given, or the mean of its column COL.
fn files_at_levels(config: &CovariateFitConfig, style: OutputStyle) -> Result<FitInputs> {
    let fit_config = &config.fit;
    let covariates = match &config.covariate {
        CovariateSource::Values(v) => v.clone(),
        CovariateSource::Column(col) => config
            .files
            .iter()
            .map(|f| {
                let values = covariate_column(config, f, col, style)?;
                covariate_level(&values).map_err(|e| {
                    anyhow::anyhow!(
                        "{}: covariate column {col}: {} is not a usable level ({})",
                        f.display(),
                        e.value,
                        e.expected
                    )
                })
            })
            .collect::<Result<_>>()?,
    };
    let pool = read_pool(
        &config.files,
        &fit_config.input,
        &fit_config.wv,
        fit_config.gmwm.weighting(),
        style,
    )?;
    Ok(FitInputs {
        info: pool.info,
        names: pool.files,
        covariates,
        columns: pool.columns,
    })
}

/// One FILE whose covariate drifts, cut into `windows` windows at their mean levels.
fn windows_of_one(
    config: &CovariateFitConfig,
    col: &str,
    windows: usize,
    style: OutputStyle,
) -> Result<FitInputs> {
    let fit_config = &config.fit;
    let file = &config.files[0];
    let covariate = covariate_column(config, file, col, style)?;
    let loaded = load(&fit_config.input, style)?;
    let mut columns = Vec::new();
    let mut levels = Vec::new();
    for c in &loaded.table.columns {
        if c.name == col {
            continue;
        }
        let (recs, l) = gmwm::covariate_windows(
            &c.values,
            &covariate,
            loaded.freq_hz,
            windows,
            &fit_config.wv,
            fit_config.gmwm.weighting(),
        )
        .map_err(|e| anyhow::anyhow!("{}: column {}: {e}", file.display(), c.name))?;
        levels = l;
        columns.push((c.name.clone(), recs));
    }
    let Some((_, first)) = columns.first() else {
        anyhow::bail!(
            "--covariate {col} is the only column selected: name the sensor columns with --columns"
        );
    };
    let names: Vec<PathBuf> = (1..=windows)
        .map(|k| PathBuf::from(format!("{} [window {k}/{windows}]", file.display())))
        .collect();
    let info = names
        .iter()
        .zip(first)
        .map(|(name, r)| RecordingInfo {
            path: name.display().to_string(),
            freq_hz: loaded.freq_hz,
            n: r.n(),
            levels: r.levels(),
        })
        .collect();
    Ok(FitInputs {
        info,
        names,
        covariates: levels,
        columns,
    })
}

fn run(config: &CovariateFitConfig, style: OutputStyle, out: &mut impl Write) -> Result<()> {
    let fit_config = &config.fit;
    let mut inputs = match (&config.covariate, config.windows) {
        (CovariateSource::Column(col), Some(k)) => windows_of_one(config, col, k, style)?,
        _ => files_at_levels(config, style)?,
    };
    // the covariate column is the regressor, not a series to fit
    if let CovariateSource::Column(col) = &config.covariate {
        inputs.columns.retain(|(name, _)| name != col);
        anyhow::ensure!(
            !inputs.columns.is_empty(),
            "--covariate {col} is the only column selected: name the sensor columns with --columns"
        );
    }
    let covariates = &inputs.covariates;
    let alpha = fit_config
        .inference
        .as_ref()
        .map_or(gmwm::InferenceOptions::default().alpha, |o| o.alpha);
    let at = if !config.at.is_empty() {
        config.at.clone()
    } else if config.windows.is_some() {
        // a ramp's windows are many: its ends and its centre
        let lo = covariates.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = covariates.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        vec![lo, 0.5 * (lo + hi), hi]
    } else {
        covariates.to_vec()
    };
    let mut fits = Vec::with_capacity(inputs.columns.len());
    for (column, recs) in &inputs.columns {
        let fit = fit_config
            .gmwm
            .fit_covariate(recs, covariates, &config.dependence)
            .map_err(|e| named(e, &inputs.names, column))?;
        if !fit.convergence().converged {
            eprintln!(
                "gmwm: warning: column {column}: the covariate fit did not converge ({})",
                fit.convergence()
            );
        }
        let inference = fit
            .inference(alpha, config.seed)
            .map_err(|e| named(e, &inputs.names, column))?;
        let bands = at
            .iter()
            .map(|&x| {
                Ok(Band {
                    covariate: x,
                    parameters: inference.band(&fit, x)?,
                })
            })
            .collect::<Result<Vec<_>, gmwm::FitError>>()
            .map_err(|e| named(e, &inputs.names, column))?;
        fits.push(ColumnFit {
            column,
            fit,
            inference,
            bands,
        });
    }
    let what = match &config.covariate {
        CovariateSource::Column(c) => c.as_str(),
        CovariateSource::Values(_) => "covariate",
    };
    if fit_config.output == Style::Json {
        #[derive(Serialize)]
        struct Recording<'a> {
            #[serde(flatten)]
            info: &'a RecordingInfo,
            covariate: f64,
        }
        #[derive(Serialize)]
        struct Doc<'a> {
            covariate: &'a str,
            recordings: Vec<Recording<'a>>,
            fits: &'a [ColumnFit<'a>],
        }
        let recordings = inputs
            .info
            .iter()
            .zip(covariates)
            .map(|(info, &covariate)| Recording { info, covariate })
            .collect();
        serde_json::to_writer_pretty(
            &mut *out,
            &Doc {
                covariate: what,
                recordings,
                fits: &fits,
            },
        )?;
        writeln!(out)?;
        return Ok(());
    }
    write_recordings(&inputs.info, out)?;
    writeln!(
        out,
        "{what} levels: {}",
        covariates
            .iter()
            .map(|&x| level_text(x))
            .collect::<Vec<_>>()
            .join(", ")
    )?;
    for f in &fits {
        write_fit(f, what, alpha, out)?;
    }
    Ok(())
}

/// One column's covariate fit as a table: the coefficients, the tests, the parameters at the
/// levels asked for.
fn write_fit(f: &ColumnFit<'_>, what: &str, alpha: f64, out: &mut impl Write) -> Result<()> {
    let fit = &f.fit;
    writeln!(out)?;
    writeln!(
        out,
        "{}: {} as functions of {what} over {} recordings (x0 = {}), Q = {:.6e} ({})",
        f.column,
        fit.model(),
        fit.recordings().len(),
        level_text(fit.centre()),
        fit.objective(),
        fit.convergence()
    )?;
    writeln!(
        out,
        "  coefficients on each parameter's transformed scale (log for variances and beta): \
         u(x) = c0 + c1 (x - x0) + c2 (x - x0)^2"
    )?;
    writeln!(
        out,
        "  {:<20} {:>10} {:>6} {:>14} {:>12} {:>14} {:>14}",
        "parameter", "dependence", "power", "estimate", "SE", "CI low", "CI high"
    )?;
    let mut i = 0;
    for (name, dep) in fit.param_names().iter().zip(fit.dependence()) {
        for _ in 0..dep.terms() {
            let c = &f.inference.coefficients[i];
            writeln!(
                out,
                "  {:<20} {:>10} {:>6} {:>14.6e} {:>12.4e} {:>14.6e} {:>14.6e}",
                name,
                dep.to_string(),
                c.power,
                c.estimate,
                c.se,
                c.ci_low,
                c.ci_high
            )?;
            i += 1;
        }
    }
    match &f.inference.no_dependence {
        Some(t) => {
            writeln!(
                out,
                "  no dependence on {what} (Wald, all slopes): W = {:.3}, df = {}, p {}",
                t.statistic,
                t.df,
                p_text(t.p_value)
            )?;
            for t in &f.inference.per_parameter {
                writeln!(
                    out,
                    "    {:<20} W = {:.3}, df = {}, p {}",
                    t.parameter,
                    t.statistic,
                    t.df,
                    p_text(t.p_value)
                )?;
            }
        }
        None => writeln!(out, "  every parameter constant: nothing depends on {what}")?,
    }
    writeln!(
        out,
        "  parameters at {what} levels, with pointwise {:.0}% bands:",
        100.0 * (1.0 - alpha)
    )?;
    writeln!(
        out,
        "  {:>10} {:<20} {:>14} {:>14} {:>14}",
        what, "parameter", "estimate", "band low", "band high"
    )?;
    for b in &f.bands {
        for p in &b.parameters {
            writeln!(
                out,
                "  {:>10.4} {:<20} {:>14.6e} {:>14.6e} {:>14.6e}",
                b.covariate,
                p.name,
                p.estimate,
                p.ci_low.unwrap_or(f64::NAN),
                p.ci_high.unwrap_or(f64::NAN)
            )?;
        }
    }
    Ok(())
}

/// A p-value as `= 0.0312` or `< 1e-16` (a chi-square tail below rounding prints as zero).
fn p_text(p: f64) -> String {
    if p < 1e-16 {
        "< 1e-16".into()
    } else if p < 1e-3 {
        format!("= {p:.2e}")
    } else {
        format!("= {p:.4}")
    }
}

/// A covariate level with at most six decimals and no trailing zeros (`5`, `20.0021`).
fn level_text(x: f64) -> String {
    let s = format!("{x:.6}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}
