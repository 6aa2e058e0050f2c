//! The selection figure (one place per figure: its builder and what only it draws).

use super::*;

/// Model selection (paper Fig. 4): per column, the empirical WV against the selected model's
/// implied WV, beside the candidates' WIC with objective and optimism stacked (the best `rows`
/// canonical models, 0 for all, always with the selected one, marked ▶); the column's datasheet
/// lines dashed grey on the WV panel.
pub fn selection_figure(columns: &[Column<'_, ModelSelection>], rows: usize) -> Figure {
    let mut panels = Vec::new();
    for c in columns {
        let s = c.data;
        let selected = s.selected_canonical().model.to_string();
        panels.push(Panel {
            title: format!("{}: selected {}", c.name, short_model(&selected)),
            x_label: WV_SCALE.to_string(),
            y_label: wv_label(c.unit),
            kind: PanelKind::LogLog({
                let mut series = empirical_and_model(s.fit(), "selected model (implied WV)");
                let tau_s = &s.fit().implied_wv().tau_s;
                series.extend(datasheet_series(&c.datasheet, tau_s, Quantity::Wv));
                series
            }),
        });
        let selected_row = s
            .rows()
            .iter()
            .position(|r| r.status == gmwm::RowStatus::Selected);
        let limit = if rows == 0 { s.rows().len() } else { rows };
        let mut shown: Vec<usize> = (0..s.rows().len().min(limit)).collect();
        if let Some(i) = selected_row {
            if !shown.contains(&i) {
                shown.pop();
                shown.push(i);
            }
        }
        let rows = shown
            .iter()
            .map(|&i| {
                let r = &s.rows()[i];
                BarRow {
                    label: short_model(&r.score.canonical_model.to_string()),
                    first: r.score.objective,
                    second: r.score.optimism,
                    emphasised: Some(i) == selected_row,
                }
            })
            .collect();
        panels.push(Panel {
            title: format!("{}: WIC of the best canonical models", c.name),
            x_label: "WIC = objective + optimism".to_string(),
            y_label: String::new(),
            kind: PanelKind::Bars(Bars {
                rows,
                segment_labels: [
                    "objective (fit)".to_string(),
                    "optimism (penalty)".to_string(),
                ],
            }),
        });
    }
    let n = columns.len().max(1);
    Figure::new(panels, (n, 2), (1500, 560 * n as u32))
}
