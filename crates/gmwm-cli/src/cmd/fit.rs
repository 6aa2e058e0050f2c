//! `gmwm fit`: GMWM estimation of a latent error model on each selected column (METHODS §5).

use crate::args::{FitArgs, WeightsArg};
use crate::cmd::wv::options;
use crate::input::{analyse_columns, load};
use crate::render::Style;
use anyhow::Result;
use gmwm::model::Model;
use gmwm::{Gmwm, GmwmFit, Weighting};
use serde::Serialize;
use std::io::Write;

/// One estimated parameter in the JSON output, in model order.
#[derive(Serialize)]
struct Parameter {
    /// Process kind of the component (`GM`, `WN`, ...).
    process: String,
    /// 0-based position of the component in the model.
    index: usize,
    /// Parameter name (METHODS §0.2).
    name: String,
    /// Estimate.
    value: f64,
}

/// One column's fit in the JSON output.
#[derive(Serialize)]
struct FitReport<'a> {
    column: &'a str,
    model: String,
    objective: f64,
    converged: bool,
    parameters: Vec<Parameter>,
    fit: &'a GmwmFit,
}

#[derive(Serialize)]
struct FitsDoc<'a> {
    fits: Vec<FitReport<'a>>,
}

fn parameters(model: &Model, theta: &[f64]) -> Vec<Parameter> {
    let mut out = Vec::with_capacity(theta.len());
    let mut k = 0;
    for (index, c) in model.components().iter().enumerate() {
        for name in c.kind.param_names() {
            out.push(Parameter {
                process: c.kind.name(),
                index,
                name,
                value: theta[k],
            });
            k += 1;
        }
    }
    out
}

/// Runs the subcommand.
pub fn run(args: &FitArgs, out: &mut impl Write) -> Result<()> {
    let model: Model = args.model.parse()?;
    let wv_opts = options(&args.estimator)?;
    let mut gmwm = Gmwm::new(model).with_weighting(match args.weights {
        WeightsArg::Fast => Weighting::Fast,
        WeightsArg::Diag => Weighting::Diag,
    });
    gmwm = gmwm.with_seed(args.seed);
    if let Some(g) = args.draws {
        anyhow::ensure!(g >= 1, "invalid --G 0: at least one starting-value draw");
        gmwm = gmwm.with_draws(g);
    }
    let loaded = load(&args.input)?;
    let fits = analyse_columns(&loaded, &args.input.file, |x| {
        gmwm.fit(x, loaded.freq_hz, &wv_opts)
            .map_err(gmwm::Error::from)
    })?;
    for (name, fit) in &fits {
        if !fit.convergence.converged {
            eprintln!(
                "gmwm: warning: {}: column {name}: the optimiser did not converge ({})",
                args.input.file.display(),
                fit.convergence
            );
        }
    }
    match Style::from(&args.output) {
        Style::Json => {
            let doc = FitsDoc {
                fits: fits
                    .iter()
                    .map(|(column, fit)| FitReport {
                        column,
                        model: fit.model.to_string(),
                        objective: fit.objective,
                        converged: fit.convergence.converged,
                        parameters: parameters(&fit.model, &fit.theta),
                        fit,
                    })
                    .collect(),
            };
            serde_json::to_writer_pretty(&mut *out, &doc)?;
            writeln!(out)?;
        }
        Style::Csv => {
            writeln!(out, "column,process,index,name,value")?;
            for (column, fit) in &fits {
                for p in parameters(&fit.model, &fit.theta) {
                    writeln!(
                        out,
                        "{column},{},{},{},{:e}",
                        p.process, p.index, p.name, p.value
                    )?;
                }
            }
        }
        Style::Table => {
            for (i, (column, fit)) in fits.iter().enumerate() {
                if i > 0 {
                    writeln!(out)?;
                }
                writeln!(out, "{column}")?;
                writeln!(out, "{fit}")?;
            }
        }
    }
    Ok(())
}
