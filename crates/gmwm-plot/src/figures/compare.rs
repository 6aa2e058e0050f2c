//! The compare figure (one place per figure: its builder and what only it draws).

use super::*;

/// The classical against the robust WV of each column (paper Fig. 2): where outliers inflate
/// the classical estimate, its points leave the robust band; the column's datasheet lines
/// dashed grey.
pub fn compare_figure(columns: &[Column<'_, (WaveletVariance, WaveletVariance)>]) -> Figure {
    let panels = columns
        .iter()
        .map(|c| {
            let (classical, robust) = c.data;
            let eff = robust.robust().map_or(0.6, |r| r.eff());
            let level = 100.0 * (1.0 - classical.alpha());
            let [cb, cp] = estimate_series(
                classical.tau_s(),
                classical.wv(),
                classical.ci_low(),
                classical.ci_high(),
                Some(4),
            );
            let [rb, rp] = estimate_series(
                robust.tau_s(),
                robust.wv(),
                robust.ci_low(),
                robust.ci_high(),
                Some(5),
            );
            Panel {
                title: format!("{}: classical and robust WV", c.name),
                x_label: WV_SCALE.to_string(),
                y_label: wv_label(c.unit),
                kind: PanelKind::LogLog(
                    [
                        cb.labelled(format!("classical {level:.0}% interval")),
                        rb.labelled(format!("robust {level:.0}% interval")),
                        cp.labelled("classical WV"),
                        rp.labelled(format!("robust WV (efficiency {eff})")),
                    ]
                    .into_iter()
                    .chain(datasheet_series(
                        &c.datasheet,
                        classical.tau_s(),
                        Quantity::Wv,
                    ))
                    .collect(),
                ),
            }
        })
        .collect();
    stacked(panels, 1, (1000, 560))
}
