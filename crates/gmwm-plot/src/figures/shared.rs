//! The shared figure (one place per figure: its builder and what only it draws).

use super::*;

/// A process shared by several axes (docs/methods/multi-axis.md §15): the axes' WVs with
/// their fitted implied WVs and the shared process's implied WV with its band (left), and the
/// pairwise wavelet cross-covariances against that shared WV (right; a negative
/// cross-covariance, which no shared process gives, is drawn as its magnitude with open
/// marks and said so in the legend). `unit` is the samples' unit.
pub fn shared_figure(fit: &SharedFit, unit: &str) -> Figure {
    let tau = &fit.tau_s;
    let mut wv = Vec::new();
    for (k, axis) in fit.axes.iter().enumerate() {
        wv.push(
            Series::new(Mark::LinePoints, tau, &fit.wv[k])
                .coloured(k)
                .labelled(format!("{axis} WV")),
        );
        wv.push(
            Series::new(
                Mark::Line {
                    width: 1,
                    dashed: true,
                },
                tau,
                &fit.implied_wv[k],
            )
            .coloured(k)
            .clipped(),
        );
    }
    let shared_line = |label: &str| {
        Series::new(
            Mark::Line {
                width: 3,
                dashed: false,
            },
            tau,
            &fit.shared_wv,
        )
        .clipped()
        .labelled(label.to_string())
    };
    let band =
        |side: &[Option<f64>]| -> Vec<f64> { side.iter().map(|v| v.unwrap_or(f64::NAN)).collect() };
    let low = band(&fit.shared_wv_low);
    let high = band(&fit.shared_wv_high);
    let with_band = low.iter().any(|v| v.is_finite());
    // the model without its values: the estimates are in the table
    let shared_label = format!(
        "shared {}",
        fit.shared_model.parse::<gmwm::Model>().map_or_else(
            |_| fit.shared_model.clone(),
            |m| short_model(&m.without_values().to_string())
        )
    );
    if with_band {
        wv.push(Series::band(tau, &low, &high).clipped());
    }
    wv.push(shared_line(&shared_label));
    let mut cross = Vec::new();
    for (k, c) in fit.cross.iter().enumerate() {
        let colour = fit.axes.len() + k;
        let positive: Vec<f64> = c
            .values
            .iter()
            .map(|&v| if v > 0.0 { v } else { f64::NAN })
            .collect();
        let negative: Vec<f64> = c
            .values
            .iter()
            .map(|&v| if v < 0.0 { -v } else { f64::NAN })
            .collect();
        cross.push(
            Series::new(Mark::LinePoints, tau, &positive)
                .coloured(colour)
                .labelled(format!("{}–{} cross-covariance", c.a, c.b)),
        );
        if negative.iter().any(|v| v.is_finite()) {
            cross.push(
                Series::new(Mark::Points, tau, &negative)
                    .coloured(colour)
                    .labelled(format!("{}–{} negative (|c|)", c.a, c.b)),
            );
        }
    }
    if with_band {
        cross.push(Series::band(tau, &low, &high).clipped());
    }
    cross.push(shared_line(&format!("{shared_label} (implied)")));
    let test = &fit.test;
    let panels = vec![
        Panel {
            title: format!("{}: WVs (dashed: fitted)", fit.axes.join(", ")),
            x_label: WV_SCALE.to_string(),
            y_label: wv_label(unit),
            kind: PanelKind::LogLog(wv),
        },
        Panel {
            title: format!(
                "cross-covariances; no shared process: T = {}, df {}, p = {}",
                number(test.statistic),
                test.df,
                number(test.p_value)
            ),
            x_label: WV_SCALE.to_string(),
            y_label: format!("wavelet cross-covariance [{}]", squared(unit)),
            kind: PanelKind::LogLog(cross),
        },
    ];
    stacked(panels, 1, (1100, 600))
}
