//! The plan figure (one place per figure: its builder and what only it draws).

use super::*;

/// How long to record (docs/methods/planning.md §18): per model, the predicted half-width of
/// the interval (the plan's level) of each quantity (N, B, K, correlation times) against the recording
/// length, log-log, with each target as a dashed horizontal line. `plans` are (name, plan).
pub fn plan_figure(plans: &[(&str, &gmwm::Plan)]) -> Figure {
    let panels = plans
        .iter()
        .map(|(name, plan)| {
            let hours: Vec<f64> = plan.lengths_s.iter().map(|s| s / 3600.0).collect();
            let mut series = Vec::new();
            for (k, q) in plan.quantities.iter().enumerate() {
                // beyond ±100% the value is not determined: not drawn
                let percent: Vec<f64> = q
                    .half_width
                    .iter()
                    .map(|w| match w {
                        Some(w) if *w <= 1.0 => 100.0 * w,
                        _ => f64::NAN,
                    })
                    .collect();
                series.push(
                    Series::new(Mark::LinePoints, &hours, &percent)
                        .coloured(k)
                        .labelled(format!("{} ({})", q.name, short_source(&q.source))),
                );
            }
            for t in &plan.targets {
                let x = [hours[0], hours[hours.len() - 1]];
                let y = [100.0 * t.half_width; 2];
                let when = t.length_s.map_or("not within 30 days".to_string(), |l| {
                    format!("{} h", number(l / 3600.0))
                });
                series.push(
                    Series::new(
                        Mark::Line {
                            width: 1,
                            dashed: true,
                        },
                        &x,
                        &y,
                    )
                    .labelled(format!(
                        "target {} ±{}%: {when}",
                        t.quantity,
                        number(100.0 * t.half_width)
                    )),
                );
            }
            Panel {
                title: format!("{name}: precision against recording length"),
                x_label: "recording length [h]".to_string(),
                y_label: format!("{:.0}% interval half-width [%]", 100.0 * (1.0 - plan.alpha)),
                kind: PanelKind::LogLog(series),
            }
        })
        .collect();
    stacked(panels, 2, (900, 520))
}

/// A quantity's source in a few words for the legend.
fn short_source(source: &str) -> &str {
    if source.starts_with("IEEE") {
        "IEEE read-off"
    } else {
        source.trim_start_matches("correlation time of ")
    }
}
