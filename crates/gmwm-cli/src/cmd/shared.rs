//! `gmwm shared`: a latent process shared by several axes of one recording (paper §IV-A,
//! docs/methods.md §15): `x_i = V + U_i`, fitted from the axes' wavelet variances and
//! cross-covariances, with intervals and the test of "no shared process".

use super::Command;
use crate::config::SharedConfig;
use crate::input::load;
use crate::prepare::Inputs;
use crate::render::Style;
use crate::style::OutputStyle;
use anyhow::Result;
use gmwm::{fit_shared, Model, SharedFit};
use std::io::Write;
use std::path::Path;

impl Command for SharedConfig {
    fn inputs(&mut self) -> Inputs<'_> {
        Inputs::Recording(&mut self.input)
    }

    fn outputs(&self) -> Vec<&Path> {
        // --plot: written after the fit, its error naming it (as before)
        Vec::new()
    }

    fn levels(&self) -> Option<usize> {
        // a series too short for --levels: the engine's error, without the flag (as before)
        None
    }

    fn run(&self, style: OutputStyle, mut out: &mut dyn Write) -> Result<()> {
        let (fit, unit) = compute(self, style)?;
        if let Some(path) = &self.plot {
            let unit = crate::render::figure_unit(unit.as_deref());
            crate::render::save_figure(&gmwm_plot::shared_figure(&fit, &unit), path)?;
            style.wrote(path);
        }
        render(&fit, self.output, &mut out)
    }
}

/// Reads the columns, checks they are one sensor in one unit, fits; the fit and that unit.
pub fn compute(config: &SharedConfig, style: OutputStyle) -> Result<(SharedFit, Option<String>)> {
    let file = config.input.file.display().to_string();
    let loaded = load(&config.input, style)?;
    let table = &loaded.table;
    anyhow::ensure!(
        table.columns.len() >= 2,
        "{file}: a shared process needs at least 2 columns, got {} ({}); give --columns, e.g. \
         --columns gyro_x,gyro_y,gyro_z",
        table.columns.len(),
        table
            .columns
            .iter()
            .map(|c| c.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let infos = gmwm::SensorInfo::of_table(table);
    if let Some((i, info)) = infos
        .iter()
        .enumerate()
        .find(|(_, s)| s.sensor != infos[0].sensor || s.unit != infos[0].unit)
    {
        let what = |s: &gmwm::SensorInfo| {
            format!(
                "{} in {}",
                s.sensor.tag(),
                s.unit.as_deref().unwrap_or("an unknown unit")
            )
        };
        anyhow::bail!(
            "{file}: --columns: {} is {} but {} is {}: a shared process needs axes of one sensor \
             and unit",
            table.columns[i].name,
            what(info),
            table.columns[0].name,
            what(&infos[0])
        );
    }
    let axes: Vec<(&str, &[f64])> = table
        .columns
        .iter()
        .map(|c| (c.name.as_str(), c.values.as_slice()))
        .collect();
    let fit = fit_shared(
        &axes,
        loaded.freq_hz,
        &config.shared,
        &config.specific,
        &config.options,
    )
    .map_err(|e| short_context(e, &file, &config.shared, &config.specific))?;
    Ok((fit, infos[0].unit.clone()))
}

/// The engine's error with the file and, for a recording too short for the model, the fix.
fn short_context(e: gmwm::FitError, file: &str, shared: &Model, specific: &Model) -> anyhow::Error {
    if let gmwm::FitError::TooFewLevels { params, levels } = &e {
        return anyhow::anyhow!(
            "{file}: too short for --shared {shared} --model {specific}: {params} parameters \
             but {levels} wavelet levels; give a longer recording or a smaller model"
        );
    }
    anyhow::Error::new(e).context(file.to_string())
}

/// Table, JSON or CSV.
pub fn render(fit: &SharedFit, style: Style, out: &mut impl Write) -> Result<()> {
    match style {
        Style::Json => {
            serde_json::to_writer_pretty(&mut *out, fit)?;
            writeln!(out)?;
        }
        Style::Csv => {
            writeln!(out, "block,parameter,estimate,se,ci_low,ci_high")?;
            let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:e}"));
            for p in &fit.parameters {
                writeln!(
                    out,
                    "{},{},{:e},{},{},{}",
                    p.block,
                    p.parameter.name,
                    p.parameter.estimate,
                    opt(p.parameter.se),
                    opt(p.parameter.ci_low),
                    opt(p.parameter.ci_high)
                )?;
            }
        }
        _ => writeln!(out, "{fit}")?,
    }
    Ok(())
}
