//! `gmwm fit`: GMWM estimation of a latent error model on each selected column (METHODS §5).

use crate::args::{FitArgs, WeightsArg};
use crate::cmd::wv::options;
use crate::input::{analyse_columns, check_wv_estimator, column_context, is_wv, load, load_wv};
use crate::progress::bar;
use crate::render::Style;
use crate::UsageError;
use anyhow::Result;
use gmwm::fit::{CanonicalModel, StartInputs};
use gmwm::inference::{infer_with_progress, Inference, InferenceOptions};
use gmwm::model::Model;
use gmwm::{Gmwm, GmwmFit, WaveletFilter, WaveletVariance, Weighting, WvOptions};
use rayon::prelude::*;
use std::io::Write;

/// Fits every series of a WV JSON file (`gmwm wv --json`) selected by `--columns` (names or
/// 1-based indices).
fn fit_wv_file(args: &FitArgs, gmwm: &Gmwm) -> Result<Vec<(String, GmwmFit)>> {
    let file = &args.input.file;
    check_wv_estimator(file, &args.estimator)?;
    anyhow::ensure!(
        args.weights != WeightsArg::Diag,
        "{}: --weights diag needs the series; use fast or bootstrap with a wavelet-variance file",
        file.display()
    );
    let series = load_wv(&args.input, args.estimator.levels)?;
    let wvs: Vec<&WaveletVariance> = series.iter().map(|(_, w)| w).collect();
    let fits: Vec<_> = wvs
        .par_iter()
        .map(|wv| gmwm.fit_from_wv(wv, StartInputs::from_wv(wv)))
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

/// The series length and WV settings behind a fit (for the bootstrap replicates).
fn wv_options_of(fit: &GmwmFit) -> Result<(usize, WvOptions)> {
    let wv = fit
        .empirical
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("the fit carries no wavelet variance"))?;
    Ok((wv.n, wv.options()))
}

/// METHODS §7 on one column's fit, with a progress bar on a terminal.
fn inference(args: &FitArgs, gmwm: &Gmwm, column: &str, fit: &GmwmFit) -> Result<Inference> {
    if let Some(b) = args.bootstrap {
        anyhow::ensure!(b >= 2, "invalid --bootstrap {b}: at least 2 replicates");
    }
    let (n, wv_opts) = wv_options_of(fit)?;
    let opts = InferenceOptions {
        alpha: args.estimator.alpha,
        bootstrap: args.bootstrap,
        ..InferenceOptions::default()
    };
    let total = args.bootstrap.unwrap_or(opts.v_replicates) as u64;
    let bar = bar(total, &format!("inference on {column}"), "replicates");
    let progress = |done: usize| bar.set_position(done as u64);
    let result = infer_with_progress(gmwm, fit, n, &wv_opts, &opts, &progress);
    bar.finish_and_clear();
    column_context(result.map_err(gmwm::Error::from), &args.input.file, column)
}

/// Refuses a non-Haar `--filter` for the estimation commands (fit, select): every model's
/// implied WV is the Haar one (METHODS §1.8, §4); the engine refuses it too.
pub fn check_haar_flag(name: &str, opts: &WvOptions) -> Result<()> {
    if opts.filter != WaveletFilter::Haar {
        return Err(UsageError(format!(
            "invalid --filter {name}: every model's implied wavelet variance is the Haar one \
             (METHODS §1.8, §4), so fits and selections use --filter haar (the default); other \
             filters are for gmwm wv"
        ))
        .into());
    }
    Ok(())
}

/// Runs the subcommand.
pub fn run(args: &FitArgs, out: &mut impl Write) -> Result<()> {
    let (gmwm, fits) = compute(args)?;
    render_fits(args, &gmwm, &fits, out)
}

/// The estimator from the flags and its fit on every selected column (convergence warnings
/// printed).
pub fn compute(args: &FitArgs) -> Result<(Gmwm, Vec<(String, GmwmFit)>)> {
    let model: Model = args.model.parse()?;
    let wv_opts = options(&args.estimator)?;
    check_haar_flag(&args.estimator.filter, &wv_opts)?;
    let mut gmwm = Gmwm::new(model).with_weighting(match args.weights {
        WeightsArg::Fast => Weighting::Fast,
        WeightsArg::Diag => Weighting::Diag,
        WeightsArg::Bootstrap => Weighting::Bootstrap,
    });
    gmwm = gmwm.with_seed(args.seed);
    if let Some(g) = args.draws {
        anyhow::ensure!(g >= 1, "invalid --G 0: at least one starting-value draw");
        gmwm = gmwm.with_draws(g);
    }
    let fits = if is_wv(&args.input) {
        fit_wv_file(args, &gmwm)?
    } else {
        let loaded = load(&args.input)?;
        analyse_columns(&loaded, &args.input.file, |x| {
            gmwm.fit(x, loaded.freq_hz, &wv_opts)
                .map_err(gmwm::Error::from)
        })?
    };
    for (name, fit) in &fits {
        if !fit.convergence.converged {
            eprintln!(
                "gmwm: warning: {}: column {name}: the optimiser did not converge ({})",
                args.input.file.display(),
                fit.convergence
            );
        }
    }
    Ok((gmwm, fits))
}

fn render_fits(
    args: &FitArgs,
    gmwm: &Gmwm,
    fits: &[(String, GmwmFit)],
    out: &mut impl Write,
) -> Result<()> {
    let canonicals: Vec<CanonicalModel> = fits
        .par_iter()
        .map(|(column, fit)| {
            column_context(
                fit.canonical().map_err(gmwm::Error::from),
                &args.input.file,
                column,
            )
        })
        .collect::<Result<_>>()?;
    let inferences: Vec<Option<Inference>> = if args.inference {
        fits.iter()
            .map(|(column, fit)| inference(args, gmwm, column, fit).map(Some))
            .collect::<Result<_>>()?
    } else {
        fits.iter().map(|_| None).collect()
    };
    match Style::from(&args.output) {
        Style::Json => {
            let items: Vec<gmwm::document::FitItem<'_>> = fits
                .iter()
                .zip(&inferences)
                .zip(&canonicals)
                .map(
                    |(((column, fit), inf), canonical)| gmwm::document::FitItem {
                        column,
                        fit,
                        canonical,
                        inference: inf.as_ref(),
                    },
                )
                .collect();
            serde_json::to_writer_pretty(&mut *out, &gmwm::document::fits(&items))?;
            writeln!(out)?;
        }
        Style::Csv => {
            writeln!(out, "column,process,index,name,value,se,ci_low,ci_high")?;
            for ((column, fit), inf) in fits.iter().zip(&inferences) {
                for (k, p) in fit.parameters().into_iter().enumerate() {
                    let (se, lo, hi) = match inf {
                        Some(i) => {
                            let q = &i.parameters[k];
                            let cell =
                                |x: Option<f64>| x.map(|x| format!("{x:e}")).unwrap_or_default();
                            (cell(q.se), cell(q.ci_low), cell(q.ci_high))
                        }
                        None => Default::default(),
                    };
                    writeln!(
                        out,
                        "{column},{},{},{},{:e},{se},{lo},{hi}",
                        p.process, p.index, p.name, p.value
                    )?;
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
                if canonical.reduced != fit.model.without_values() {
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
