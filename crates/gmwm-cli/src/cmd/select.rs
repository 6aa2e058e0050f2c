//! `gmwm select`: model selection by the Wavelet Information Criterion on each selected column
//! (METHODS §8), the candidates folded by canonical model.

use crate::args::{OptimismArg, OptimismConventionArg, RuleArg, SelectArgs};
use crate::cmd::wv::options;
use crate::input::{analyse_columns, check_wv_estimator, column_context, is_wv, load, load_wv};
use crate::progress::{bar, Ticks};
use crate::render::Style;
use anyhow::Result;
use gmwm::model::Model;
use gmwm::selection::{OptimismConvention, OptimismMethod, RowStatus, SelectionRule};
use gmwm::{ModelSelection, Wic};
use std::io::Write;

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
    let wv_options = options(&args.estimator)?;
    crate::cmd::fit::check_haar_flag(&args.estimator.filter, &wv_options)?;
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
        })
        .with_rule(match args.rule {
            RuleArg::Navigation => SelectionRule::Navigation,
            RuleArg::Parsimonious => SelectionRule::Parsimonious,
            RuleArg::WicMinimum => SelectionRule::WicMinimum,
        })
        .with_wv_options(wv_options);
    if let Some(g) = args.draws {
        wic = wic.with_draws(g);
    }
    Ok(wic)
}

/// CSV: one line per row of each column's table.
const CSV_HEADER: &str = "column,rank,canonical_model,candidate,members,objective,optimism,wic,\
delta_wic,delta_wic_se,gof_p_value,gof_p_value_upper_bound,status";

fn write_csv(results: &[(String, ModelSelection)], out: &mut impl Write) -> Result<()> {
    writeln!(out, "{CSV_HEADER}")?;
    let cell = |x: Option<f64>| x.map(|x| format!("{x:e}")).unwrap_or_default();
    for (column, s) in results {
        for (r, row) in s.rows.iter().enumerate() {
            let members: Vec<String> = row.members.iter().map(Model::to_string).collect();
            let status = match row.status {
                RowStatus::Selected => "selected",
                RowStatus::Equivalent => "equivalent",
                RowStatus::Separable => "separable",
            };
            writeln!(
                out,
                "{column},{},{},{},{},{:e},{:e},{:e},{:e},{:e},{},{},{status}",
                r + 1,
                row.score.canonical_model,
                row.score.model,
                members.join(";"),
                row.score.objective,
                row.score.optimism,
                row.score.wic,
                row.delta_wic,
                row.delta_wic_se,
                cell(row.score.gof_p_value),
                row.score.gof_p_value_upper_bound
            )?;
        }
    }
    Ok(())
}

/// Runs the subcommand.
pub fn run(args: &SelectArgs, out: &mut impl Write) -> Result<()> {
    let results = compute(args)?;
    render_selections(args, &results, out)
}

/// The WIC selection on every selected column (convergence warnings printed).
pub fn compute(args: &SelectArgs) -> Result<Vec<(String, ModelSelection)>> {
    let wic = wic(args)?;
    let file = &args.input.file;
    let results: Result<Vec<(String, ModelSelection)>> = if is_wv(&args.input) {
        // a saved wavelet variance: selected as it is, the bootstrap V simulated at its n
        check_wv_estimator(file, &args.estimator)?;
        let series = load_wv(&args.input, args.estimator.levels)?;
        let progress = bar(
            (series.len() * wic.candidates().len()) as u64,
            "WIC selection",
            "candidates",
        );
        let ticks = Ticks(&progress);
        let results = series
            .iter()
            .map(|(name, wv)| {
                let s = wic
                    .select_wv_with_progress(wv, &ticks)
                    .map_err(gmwm::Error::from);
                Ok((name.clone(), column_context(s, file, name)?))
            })
            .collect();
        progress.finish_and_clear();
        results
    } else {
        let loaded = load(&args.input)?;
        let columns = loaded.table.columns.len();
        let progress = bar(
            (columns * wic.candidates().len()) as u64,
            "WIC selection",
            "candidates",
        );
        let ticks = Ticks(&progress);
        let results = analyse_columns(&loaded, file, |x| {
            wic.select_with_progress(x, loaded.freq_hz, &ticks)
                .map_err(gmwm::Error::from)
        });
        progress.finish_and_clear();
        results
    };
    let results = results?;
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
    Ok(results)
}

fn render_selections(
    args: &SelectArgs,
    results: &[(String, ModelSelection)],
    out: &mut impl Write,
) -> Result<()> {
    match Style::from(&args.output) {
        Style::Json => {
            serde_json::to_writer_pretty(&mut *out, &gmwm::document::selections(results))?;
            writeln!(out)?;
        }
        Style::Csv => write_csv(results, out)?,
        Style::Table => {
            for (i, (column, s)) in results.iter().enumerate() {
                if i > 0 {
                    writeln!(out)?;
                }
                writeln!(out, "{column}")?;
                writeln!(out, "{}", s.table(args.top))?;
            }
        }
    }
    Ok(())
}
