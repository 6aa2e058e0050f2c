//! The recordings figure (one place per figure: its builder and what only it draws).

use super::*;

/// A pooled calibration (docs/methods.md §5.12): per column, the pooled WV with its band (grey)
/// and every recording's own WV (points joined, one colour each, labelled by `labels`), so
/// that a recording that differs from the others shows.
pub fn recordings_figure(
    columns: &[Column<'_, (WaveletVariance, Vec<WaveletVariance>)>],
    labels: &[String],
) -> Figure {
    let panels = columns
        .iter()
        .map(|c| {
            let (pooled, parts) = c.data;
            let [band, points] = estimate_series(
                pooled.tau_s(),
                pooled.wv(),
                pooled.ci_low(),
                pooled.ci_high(),
                None,
            );
            let mut series = vec![band, points.labelled("pooled WV")];
            for (k, wv) in parts.iter().enumerate() {
                let label = labels
                    .get(k)
                    .cloned()
                    .unwrap_or_else(|| format!("recording {}", k + 1));
                // palette colour 0 is black, too close to the pooled WV's grey: recordings start at 1
                series.push(
                    Series::new(Mark::LinePoints, wv.tau_s(), wv.wv())
                        .coloured(k + 1)
                        .labelled(label),
                );
            }
            Panel {
                title: format!("{}: {} recordings and their pooled WV", c.name, parts.len()),
                x_label: WV_SCALE.to_string(),
                y_label: wv_label(c.unit),
                kind: PanelKind::LogLog(series),
            }
        })
        .collect();
    stacked(panels, 2, (800, 560))
}
