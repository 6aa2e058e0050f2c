//! `gmwm select`: model selection by the Wavelet Information Criterion on each selected column
//! (docs/methods.md §8), the candidates folded by canonical model.

use super::Command;
use crate::config::SelectConfig;
use crate::input::{analyse_columns, column_context, is_wv, load, load_wv};
use crate::prepare::Inputs;
use crate::render::Style;
use crate::style::{OutputStyle, Ticks};
use anyhow::Result;
use gmwm::{Model, ModelSelection, RowStatus};
use std::io::Write;
use std::path::Path;

/// CSV: one line per row of each column's table.
const CSV_HEADER: &str = "column,rank,canonical_model,candidate,members,objective,optimism,wic,\
delta_wic,delta_wic_se,gof_p_value,gof_p_value_upper_bound,status";

fn write_csv(results: &[(String, ModelSelection)], out: &mut impl Write) -> Result<()> {
    writeln!(out, "{CSV_HEADER}")?;
    let cell = |x: Option<f64>| x.map(|x| format!("{x:e}")).unwrap_or_default();
    for (column, s) in results {
        for (r, row) in s.rows().iter().enumerate() {
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

impl Command for SelectConfig {
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
        let results = compute(self, style)?;
        render_selections(self, &results, &mut out)
    }
}

/// The WIC selection on every selected column (convergence warnings printed).
pub fn compute(config: &SelectConfig, style: OutputStyle) -> Result<Vec<(String, ModelSelection)>> {
    let wic = &config.wic;
    let file = &config.input.file;
    let results: Result<Vec<(String, ModelSelection)>> = if is_wv(&config.input) {
        // a saved wavelet variance: selected as it is, the bootstrap V simulated at its n
        config.saved_wv.check(file)?;
        let series = load_wv(&config.input, config.wv.levels)?;
        let progress = style.bar(
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
        let loaded = load(&config.input, style)?;
        let columns = loaded.table.columns.len();
        let progress = style.bar(
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
        if !s.fit().convergence().converged {
            eprintln!(
                "gmwm: warning: {}: column {name}: the optimiser did not converge for the selected model {} ({})",
                file.display(),
                s.selected(),
                s.fit().convergence()
            );
        }
    }
    Ok(results)
}

fn render_selections(
    config: &SelectConfig,
    results: &[(String, ModelSelection)],
    out: &mut impl Write,
) -> Result<()> {
    match config.output {
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
                writeln!(out, "{}", s.table(config.top))?;
            }
        }
    }
    Ok(())
}
