//! `gmwm fit FILE --covariate COL --dynamic`: the non-stationary AR1 of the paper's §IV-B
//! (docs/methods.md §5.16) on each sensor column. The engine does every computation
//! (`gmwm::fit_ns_ar1`); this module reads the recording and its covariate and renders.

use super::covariate::covariate_values;
use super::Command;
use crate::config::DynamicFitConfig;
use crate::input::load;
use crate::prepare::Inputs;
use crate::render::Style;
use crate::style::OutputStyle;
use anyhow::Result;
use gmwm::NsAr1Fit;
use rayon::prelude::*;
use serde::Serialize;
use std::io::Write;
use std::path::Path;

impl Command for DynamicFitConfig {
    fn inputs(&mut self) -> Inputs<'_> {
        Inputs::Recording(&mut self.fit.input)
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

/// One column's fit as reported.
#[derive(Serialize)]
struct ColumnFit<'a> {
    column: &'a str,
    covariate: &'a str,
    #[serde(flatten)]
    fit: &'a NsAr1Fit,
    stationary_model: String,
}

fn run(config: &DynamicFitConfig, style: OutputStyle, out: &mut impl Write) -> Result<()> {
    let file = &config.fit.input.file;
    let col = &config.covariate;
    let (z, _) = covariate_values(&config.fit.input, file, col, style)?;
    let loaded = load(&config.fit.input, style)?;
    let columns: Vec<_> = loaded
        .table
        .columns
        .iter()
        .filter(|c| &c.name != col)
        .collect();
    anyhow::ensure!(
        !columns.is_empty(),
        "--covariate {col} is the only column selected: name the sensor columns with --columns"
    );
    let bar = style.bar(columns.len() as u64, "non-stationary AR1 fits", "columns");
    let fits: Vec<Result<NsAr1Fit>> = columns
        .par_iter()
        .map(|c| {
            let r = gmwm::fit_ns_ar1(&c.values, &z, loaded.freq_hz, &config.options).map_err(|e| {
                anyhow::anyhow!(
                    "{}: column {}: --dynamic along {col}: {e}",
                    file.display(),
                    c.name
                )
            });
            bar.inc(1);
            r
        })
        .collect();
    bar.finish_and_clear();
    let fits: Vec<NsAr1Fit> = fits.into_iter().collect::<Result<_>>()?;
    let items: Vec<ColumnFit<'_>> = columns
        .iter()
        .zip(&fits)
        .map(|(c, fit)| ColumnFit {
            column: &c.name,
            covariate: col,
            fit,
            stationary_model: fit.stationary.model().to_string(),
        })
        .collect();
    match config.fit.output {
        Style::Json => {
            serde_json::to_writer_pretty(&mut *out, &serde_json::json!({ "dynamic_fits": items }))?;
            writeln!(out)?;
        }
        Style::Csv => {
            writeln!(
                out,
                "column,covariate,name,value,se,covariate_mean,objective"
            )?;
            for it in &items {
                for ((name, v), se) in it.fit.names.iter().zip(&it.fit.theta).zip(&it.fit.se) {
                    writeln!(
                        out,
                        "{},{col},{name},{v:e},{},{:e},{:e}",
                        it.column,
                        se.map(|s| format!("{s:e}")).unwrap_or_default(),
                        it.fit.covariate_mean,
                        it.fit.objective
                    )?;
                }
            }
        }
        Style::Table => {
            for (i, it) in items.iter().enumerate() {
                if i > 0 {
                    writeln!(out)?;
                }
                table(it, col, out)?;
            }
        }
    }
    Ok(())
}

fn table(it: &ColumnFit<'_>, col: &str, out: &mut impl Write) -> Result<()> {
    let f = it.fit;
    writeln!(
        out,
        "{}: non-stationary AR1 along {col} (z = {col} - {:.6}), {} windows of {} levels",
        it.column, f.covariate_mean, f.windows, f.levels
    )?;
    writeln!(out, "  {}", f.model)?;
    writeln!(
        out,
        "  {:<8} {:>13} {:>11} {:>8}",
        "param", "estimate", "SE", "z"
    )?;
    for ((name, v), se) in f.names.iter().zip(&f.theta).zip(&f.se) {
        match se {
            Some(s) => writeln!(out, "  {name:<8} {v:>13.6} {s:>11.4e} {:>8.2}", v / s)?,
            None => writeln!(out, "  {name:<8} {v:>13.6} {:>11} {:>8}", "fixed", "")?,
        }
    }
    let rho = |zv: f64| (f.model.beta[0] + f.model.beta[1] * zv).tanh();
    let [lo, hi] = f.covariate_range;
    writeln!(
        out,
        "  rho at the lowest, mean and highest {col} ({:.4}, {:.4}, {:.4}): {:.6}, {:.6}, {:.6} \
         (correlation times {} s)",
        lo + f.covariate_mean,
        f.covariate_mean,
        hi + f.covariate_mean,
        rho(lo),
        rho(0.0),
        rho(hi),
        [lo, 0.0, hi]
            .iter()
            .map(|&zv| format!(
                "{:.4}",
                -1.0 / (rho(zv).abs().ln() * f.stationary.freq_hz())
            ))
            .collect::<Vec<_>>()
            .join(", ")
    )?;
    writeln!(
        out,
        "  ignoring {col}: {} (windowed objective {:.4e}, {:.1}x the dynamic model's {:.4e})",
        it.stationary_model,
        f.stationary_objective,
        f.stationary_objective / f.objective,
        f.objective
    )?;
    if let Some(s) = f.se[1] {
        writeln!(
            out,
            "  no-dependence test of rho on {col} (beta1 = 0): z = {:.2}{}",
            f.theta[1] / s,
            if (f.theta[1] / s).abs() > 1.96 {
                ", rejected at 5%"
            } else {
                ", not rejected at 5%"
            }
        )?;
    }
    if !f.converged {
        writeln!(out, "  the optimiser did not converge")?;
    }
    Ok(())
}
