//! The pooled figure (one place per figure: its builder and what only it draws).

use super::*;

/// Several recordings fitted by one model (docs/methods.md §5.11): per column, every
/// recording's empirical WV (points joined, one colour each, labelled by `labels`) and the
/// pooled model's implied WV (a thick grey line) over the deepest recording's scales.
pub fn pooled_figure(columns: &[Column<'_, PooledFit>], labels: &[String]) -> Figure {
    let panels = columns
        .iter()
        .map(|c| {
            let fit = c.data;
            let f = fit.freq_hz();
            let mut series = Vec::new();
            let mut deepest = 0;
            for (k, r) in fit.recordings().iter().enumerate() {
                let tau: Vec<f64> = (1..=r.levels).map(|j| (1u64 << j) as f64 / f).collect();
                deepest = deepest.max(r.levels);
                let label = labels
                    .get(k)
                    .cloned()
                    .unwrap_or_else(|| format!("recording {}", k + 1));
                series.push(
                    Series::new(Mark::LinePoints, &tau, &r.nu_hat)
                        .coloured(k)
                        .labelled(label),
                );
            }
            if let Some(r) = fit.recordings().iter().max_by_key(|r| r.levels) {
                let tau: Vec<f64> = (1..=deepest).map(|j| (1u64 << j) as f64 / f).collect();
                series.push(
                    Series::new(
                        Mark::Line {
                            width: 3,
                            dashed: false,
                        },
                        &tau,
                        &r.implied_wv,
                    )
                    .clipped()
                    .labelled(format!("pooled model {}", fit.model().without_values())),
                );
            }
            Panel {
                title: format!(
                    "{}: {} recordings, one model",
                    c.name,
                    fit.recordings().len()
                ),
                x_label: WV_SCALE.to_string(),
                y_label: wv_label(c.unit),
                kind: PanelKind::LogLog(series),
            }
        })
        .collect();
    stacked(panels, 1, (1100, 600))
}
