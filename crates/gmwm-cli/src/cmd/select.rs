//! `gmwm select`: model selection by the Wavelet Information Criterion on each selected column
//! (METHODS §8).

use crate::args::{OptimismArg, OptimismConventionArg, SelectArgs};
use crate::input::{analyse_columns, load};
use anyhow::Result;
use gmwm::model::Model;
use gmwm::selection::{OptimismConvention, OptimismMethod};
use gmwm::{ModelSelection, RobustConvention, RobustOptions, Wic, WvOptions};
use serde::Serialize;
use std::io::Write;

/// One candidate in the JSON output.
#[derive(Serialize)]
struct CandidateRow {
    model: String,
    objective: f64,
    optimism: f64,
    wic: f64,
    gof_p_value: Option<f64>,
}

/// One column's selection in the JSON output; candidates sorted by `wic`.
#[derive(Serialize)]
struct SelectionReport<'a> {
    column: &'a str,
    selected: String,
    candidates: Vec<CandidateRow>,
}

#[derive(Serialize)]
struct SelectionsDoc<'a> {
    selections: Vec<SelectionReport<'a>>,
}

/// The validated selection settings from the flags.
fn wic(args: &SelectArgs) -> Result<Wic> {
    let mut wic = match &args.candidates {
        Some(list) => {
            let mut texts: Vec<String> = list
                .split(';')
                .map(str::trim)
                .filter(|t| !t.is_empty())
                .map(String::from)
                .collect();
            if let Some(m) = &args.model {
                texts.push(m.clone());
            }
            anyhow::ensure!(
                !texts.is_empty(),
                "invalid --candidates {list:?}: give models separated by ';', e.g. \"AR1()+WN();2*AR1()+WN()\""
            );
            Wic::parse_list(&texts)?
        }
        None => {
            let text = args
                .model
                .as_deref()
                .ok_or_else(|| anyhow::anyhow!("give --model or --candidates"))?;
            let model: Model = text.parse()?;
            Wic::nested(model)?
        }
    };
    anyhow::ensure!(
        args.bootstrap >= 2,
        "invalid --bootstrap {}: at least 2 replicates (a covariance needs two)",
        args.bootstrap
    );
    wic = wic
        .with_bootstrap(args.bootstrap)
        .with_seed(args.seed)
        .with_optimism(match args.optimism {
            OptimismArg::Asymptotic => OptimismMethod::Asymptotic,
            OptimismArg::Bootstrap => OptimismMethod::Bootstrap,
        })
        .with_convention(match args.convention {
            OptimismConventionArg::Corrected => OptimismConvention::Corrected,
            OptimismConventionArg::Package => OptimismConvention::Package,
        });
    if let Some(g) = args.draws {
        anyhow::ensure!(g >= 1, "invalid --G 0: at least one starting-value draw");
        wic = wic.with_draws(g);
    }
    let robust = if args.robust {
        Some(RobustOptions::new(args.eff, RobustConvention::Exact)?)
    } else {
        None
    };
    Ok(wic.with_wv_options(WvOptions {
        robust,
        ..WvOptions::default()
    }))
}

/// Runs the subcommand.
pub fn run(args: &SelectArgs, out: &mut impl Write) -> Result<()> {
    let wic = wic(args)?;
    let loaded = load(&args.input)?;
    let results: Vec<(String, ModelSelection)> = analyse_columns(&loaded, &args.input.file, |x| {
        wic.select(x, loaded.freq_hz).map_err(gmwm::Error::from)
    })?;
    for (name, s) in &results {
        if !s.fit.convergence.converged {
            eprintln!(
                "gmwm: warning: {}: column {name}: the optimiser did not converge for the selected model {} ({})",
                args.input.file.display(),
                s.selected,
                s.fit.convergence
            );
        }
    }
    if args.json {
        let doc = SelectionsDoc {
            selections: results
                .iter()
                .map(|(column, s)| SelectionReport {
                    column,
                    selected: s.selected.to_string(),
                    candidates: s
                        .candidates
                        .iter()
                        .map(|c| CandidateRow {
                            model: c.model.to_string(),
                            objective: c.objective,
                            optimism: c.optimism,
                            wic: c.wic,
                            gof_p_value: c.gof_p_value,
                        })
                        .collect(),
                })
                .collect(),
        };
        serde_json::to_writer_pretty(&mut *out, &doc)?;
        writeln!(out)?;
    } else {
        for (i, (column, s)) in results.iter().enumerate() {
            if i > 0 {
                writeln!(out)?;
            }
            writeln!(out, "{column}")?;
            writeln!(out, "{s}")?;
        }
    }
    Ok(())
}
