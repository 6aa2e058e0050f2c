//! The fit figure (one place per figure: its builder and what only it draws).

use super::*;

/// A fit (paper Figs. 3a, 3b): the empirical WV with its band, the model's implied WV and,
/// with more than one component, each component's implied WV as its own line, the legend
/// naming each process with its values in the data unit; the column's datasheet lines dashed
/// grey.
pub fn fit_figure(columns: &[Column<'_, GmwmFit>]) -> Figure {
    let panels = columns
        .iter()
        .map(|c| {
            let fit = c.data;
            let mut series = empirical_and_model(fit, "model (implied WV)");
            if fit.implied_wv().processes.len() > 1 {
                for (k, p) in fit.implied_wv().processes.iter().enumerate() {
                    series.push(
                        Series::new(
                            Mark::Line {
                                width: 2,
                                dashed: false,
                            },
                            &fit.implied_wv().tau_s,
                            &p.wv,
                        )
                        .coloured(k + 1)
                        .clipped()
                        .labelled(component_label(fit, k, c.unit))
                        .labelled_below(negligible_label(fit, k)),
                    );
                }
            }
            series.extend(datasheet_series(
                &c.datasheet,
                &fit.implied_wv().tau_s,
                Quantity::Wv,
            ));
            Panel {
                title: format!("{}: {}", c.name, fit.model().without_values()),
                x_label: WV_SCALE.to_string(),
                y_label: wv_label(c.unit),
                kind: PanelKind::LogLog(series),
            }
        })
        .collect();
    stacked(panels, 1, (1100, 600))
}
