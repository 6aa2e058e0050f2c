//! `gmwm fit`: GMWM estimation of a latent error model on each selected column (docs/methods.md
//! §5).

use super::wv::{stream_columns, streamable};
use super::Command;
use crate::config::FitConfig;
use crate::input::{analyse_columns, column_context, is_wv, load, load_wv};
use crate::prepare::Inputs;
use crate::render::Style;
use crate::style::OutputStyle;
use anyhow::Result;
use gmwm::{
    fit_augmented, infer_with_progress, AugmentedFit, CanonicalModel, GmwmFit, Inference,
    InferenceOptions, StartInputs, WaveletVariance, Weighting,
};
use rayon::prelude::*;
use std::io::Write;
use std::path::Path;

/// Fits every series of a WV JSON file (`gmwm wv --json`) selected by `--columns` (names or
/// 1-based indices).
fn fit_wv_file(config: &FitConfig) -> Result<Vec<(String, GmwmFit)>> {
    let file = &config.input.file;
    config.saved_wv.check(file)?;
    let series = load_wv(&config.input, config.wv.levels)?;
    let wvs: Vec<&WaveletVariance> = series.iter().map(|(_, w)| w).collect();
    let fits: Vec<_> = wvs
        .par_iter()
        .map(|wv| config.gmwm.fit_from_wv(wv, StartInputs::from_wv(wv)))
        .collect();
    series
        .iter()
        .zip(fits)
        .map(|((name, _), r)| {
            Ok((
                name.clone(),
                column_context(r.map_err(gmwm::Error::from), file, name)?,
            ))
        })
        .collect()
}

/// Fits the columns of a raw binary file that `gmwm wv` would stream, when the weighting needs
/// only the WV: each column's WV and range (all the fit takes from the series: N and
/// `R = (max - min) / N`, as [`StartInputs::from_series`] gives them) come from one streamed
/// pass instead of loading the file. Only for the columns the loader would take too: the
/// file's single column, or `--columns`. `None` when the file is not such a case.
fn fit_streamed(config: &FitConfig, style: OutputStyle) -> Result<Option<Vec<(String, GmwmFit)>>> {
    let input = &config.input;
    if config.gmwm.weighting() == Weighting::Diag {
        return Ok(None);
    }
    let Some(layout) = streamable(input, &config.wv)? else {
        return Ok(None);
    };
    if layout.ncols > 1 && input.read.columns.is_empty() {
        return Ok(None);
    }
    let columns = stream_columns(input, &layout, &config.wv, style)?;
    let fits: Vec<_> = columns
        .par_iter()
        .map(|(_, c)| {
            let n = c.wv.n();
            let range = if n == 0 || c.max < c.min {
                0.0
            } else {
                (c.max - c.min) / n as f64
            };
            config
                .gmwm
                .fit_from_wv(&c.wv, StartInputs { n, range })
                .map_err(gmwm::Error::from)
        })
        .collect();
    columns
        .iter()
        .zip(fits)
        .map(|((name, _), r)| Ok((name.clone(), column_context(r, &input.file, name)?)))
        .collect::<Result<_>>()
        .map(Some)
}

/// docs/methods.md §7 on one column's fit, at the series length and WV settings the fit carries,
/// with a progress bar as `style` says.
fn inference(
    config: &FitConfig,
    style: OutputStyle,
    opts: &InferenceOptions,
    column: &str,
    fit: &GmwmFit,
) -> Result<Inference> {
    let wv = fit
        .empirical()
        .ok_or_else(|| anyhow::anyhow!("the fit carries no wavelet variance"))?;
    let total = opts.bootstrap.unwrap_or(opts.v_replicates) as u64;
    let bar = style.bar(total, &format!("inference on {column}"), "replicates");
    let progress = |done: usize| bar.set_position(done as u64);
    let result = infer_with_progress(&config.gmwm, fit, wv.n(), &wv.options(), opts, &progress);
    bar.finish_and_clear();
    column_context(
        result.map_err(gmwm::Error::from),
        &config.input.file,
        column,
    )
}

impl Command for FitConfig {
    fn inputs(&mut self) -> Inputs<'_> {
        Inputs::Recording(&mut self.input)
    }

    fn outputs(&self) -> Vec<&Path> {
        Vec::new()
    }

    fn levels(&self) -> Option<usize> {
        self.wv.levels
    }

    fn run(&self, style: OutputStyle, mut out: &mut dyn Write) -> Result<()> {
        if self.augment.is_some() {
            let augmented = compute_augmented(self, style)?;
            let fits: Vec<(String, GmwmFit)> = augmented
                .iter()
                .map(|(c, a)| (c.clone(), a.gmwm().clone()))
                .collect();
            let plus: Vec<&AugmentedFit> = augmented.iter().map(|(_, a)| a).collect();
            return render_fits(self, style, &fits, Some(&plus), &mut out);
        }
        let fits = compute(self, style)?;
        render_fits(self, style, &fits, None, &mut out)
    }
}

/// The fit of the configured estimator on every selected column (convergence warnings
/// printed).
pub fn compute(config: &FitConfig, style: OutputStyle) -> Result<Vec<(String, GmwmFit)>> {
    let file = &config.input.file;
    let fits = if is_wv(&config.input) {
        fit_wv_file(config)?
    } else if let Some(fits) = fit_streamed(config, style)? {
        fits
    } else {
        let loaded = load(&config.input, style)?;
        analyse_columns(&loaded, file, |x| {
            config
                .gmwm
                .fit(x, loaded.freq_hz, &config.wv)
                .map_err(gmwm::Error::from)
        })?
    };
    for (name, fit) in &fits {
        if !fit.convergence().converged {
            eprintln!(
                "gmwm: warning: {}: column {name}: the optimiser did not converge ({})",
                file.display(),
                fit.convergence()
            );
        }
    }
    Ok(fits)
}

/// GMWM+ (`--augment`, docs/methods.md §5.15) on every selected column of a recording: the
/// series are needed (the extra moments and the bootstrap), so a saved WV is refused.
fn compute_augmented(
    config: &FitConfig,
    style: OutputStyle,
) -> Result<Vec<(String, AugmentedFit)>> {
    let file = &config.input.file;
    let Some(opts) = &config.augment else {
        anyhow::bail!("no --augment given");
    };
    anyhow::ensure!(
        !is_wv(&config.input),
        "{}: --augment needs the series (its differences' moments and the bootstrap), and this \
         file is a saved wavelet variance: give the recording instead",
        file.display()
    );
    let loaded = load(&config.input, style)?;
    let bar = style.bar(loaded.table.columns.len() as u64, "GMWM+ fits", "columns");
    let fits = analyse_columns(&loaded, file, |x| {
        let r = fit_augmented(&config.gmwm, x, loaded.freq_hz, &config.wv, opts)
            .map_err(gmwm::Error::from);
        bar.inc(1);
        r
    })?;
    bar.finish_and_clear();
    for (name, fit) in &fits {
        for (what, c) in [
            ("GMWM", fit.gmwm().convergence()),
            ("GMWM+", fit.estimates().convergence()),
        ] {
            if !c.converged {
                eprintln!(
                    "gmwm: warning: {}: column {name}: the {what} optimiser did not converge ({c})",
                    file.display()
                );
            }
        }
    }
    Ok(fits)
}

fn render_fits(
    config: &FitConfig,
    style: OutputStyle,
    fits: &[(String, GmwmFit)],
    augmented: Option<&[&AugmentedFit]>,
    out: &mut impl Write,
) -> Result<()> {
    let plus = |i: usize| augmented.map(|a| a[i]);
    let canonicals: Vec<CanonicalModel> = fits
        .par_iter()
        .map(|(column, fit)| {
            column_context(
                fit.canonical().map_err(gmwm::Error::from),
                &config.input.file,
                column,
            )
        })
        .collect::<Result<_>>()?;
    let inferences: Vec<Option<Inference>> = match &config.inference {
        Some(opts) => fits
            .iter()
            .map(|(column, fit)| inference(config, style, opts, column, fit).map(Some))
            .collect::<Result<_>>()?,
        None => fits.iter().map(|_| None).collect(),
    };
    match config.output {
        Style::Json => {
            let items: Vec<gmwm::document::FitItem<'_>> = fits
                .iter()
                .zip(&inferences)
                .zip(&canonicals)
                .enumerate()
                .map(
                    |(i, (((column, fit), inf), canonical))| gmwm::document::FitItem {
                        column,
                        fit,
                        canonical,
                        inference: inf.as_ref(),
                        augmented: plus(i),
                    },
                )
                .collect();
            serde_json::to_writer_pretty(&mut *out, &gmwm::document::fits(&items))?;
            writeln!(out)?;
        }
        Style::Csv => {
            // as --json: the parameters (`parameters`), then the physical quantities
            // (`navigation`), each with its unit in terms of u, the data unit, and the
            // column's objective
            writeln!(
                out,
                "column,process,index,name,value,se,ci_low,ci_high,unit,objective"
            )?;
            for ((column, fit), inf) in fits.iter().zip(&inferences) {
                let objective = fit.objective();
                for (k, p) in fit.parameters().into_iter().enumerate() {
                    let (se, lo, hi) = match inf {
                        Some(i) => {
                            let q = &i.parameters()[k];
                            let cell =
                                |x: Option<f64>| x.map(|x| format!("{x:e}")).unwrap_or_default();
                            (cell(q.se), cell(q.ci_low), cell(q.ci_high))
                        }
                        None => Default::default(),
                    };
                    writeln!(
                        out,
                        "{column},{},{},{},{:e},{se},{lo},{hi},{},{objective:e}",
                        p.process,
                        p.index,
                        p.name,
                        p.value,
                        parameter_unit(&p.name)
                    )?;
                }
                for q in fit.navigation(None) {
                    writeln!(
                        out,
                        "{column},{},{},{},{:e},,,,{},{objective:e}",
                        q.process, q.index, q.name, q.value, q.unit
                    )?;
                }
            }
            if let Some(augmented) = augmented {
                // GMWM+ rows: process `GMWM+`, the label as name, its own objective
                for ((column, _), a) in fits.iter().zip(augmented) {
                    let objective = a.estimates().objective();
                    for p in a.parameters() {
                        let cell = |x: Option<f64>| x.map(|x| format!("{x:e}")).unwrap_or_default();
                        let short = p.name.rsplit('.').next().unwrap_or(&p.name);
                        writeln!(
                            out,
                            "{column},GMWM+,,{},{:e},{},{},{},{},{objective:e}",
                            p.name,
                            p.value,
                            cell(p.se),
                            cell(p.ci_low),
                            cell(p.ci_high),
                            parameter_unit(short)
                        )?;
                    }
                }
            }
        }
        Style::Table => {
            for (i, (((column, fit), inf), canonical)) in
                fits.iter().zip(&inferences).zip(&canonicals).enumerate()
            {
                if i > 0 {
                    writeln!(out)?;
                }
                writeln!(out, "{column}")?;
                writeln!(out, "{fit}")?;
                if let Some(inf) = inf {
                    writeln!(out, "{inf}")?;
                }
                writeln!(out, "{canonical}")?;
                if let Some(a) = plus(i) {
                    writeln!(out, "{a}")?;
                }
                if !canonical.reduced.same_terms(fit.model()) {
                    writeln!(
                        out,
                        "  (the data cannot tell this fit from one of {}: fit that model for \
                         identified estimates and intervals)",
                        canonical.reduced
                    )?;
                }
            }
        }
    }
    Ok(())
}

/// The unit of a model parameter in terms of u, the data unit (per-sample parameters, as the
/// model is written): `beta` 1/s, the coefficients (`phi`, `theta`, `arK`, `maK`) none, the drift `omega` u per
/// sample, every variance (`sigma2`, `sigma2_gm`, `gamma2`, `q2`) u^2.
fn parameter_unit(name: &str) -> &'static str {
    if name == "beta" {
        "1/s"
    } else if ["phi", "theta", "ar", "ma"]
        .iter()
        .any(|p| name.starts_with(p))
    {
        "1"
    } else if name == "omega" {
        "u/sample"
    } else {
        "u^2"
    }
}
