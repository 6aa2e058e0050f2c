//! The IEEE Std 952 read-off figure: the Allan deviation with the slope lines of each term.

use super::*;

/// One IEEE 952 term on the Allan deviation: its line `sigma(value, tau)` and where it is
/// read (docs/methods.md §14.3).
struct SlopeLine {
    symbol: &'static str,
    value: Option<f64>,
    /// The term: its line is the engine's ([`gmwm::term_avar`]).
    term: NoiseTerm,
    at_tau_s: f64,
    colour: usize,
    legend: String,
}

/// The IEEE Std 952 read-off (docs/methods.md §14.3) on the Allan deviation: the −1/2 slope line
/// through N at 1 s, the flat line at the minimum (B × 0.664) and the +1/2 slope line through
/// K at 3 s, each with its read-off point; a term without a value is left out and named in
/// the title. The column's datasheet lines are drawn dashed grey beside them.
pub fn ieee_figure(columns: &[Column<'_, (AllanVariance, IeeeReadoff)>]) -> Figure {
    let panels = columns
        .iter()
        .map(|c| {
            let (av, readoff) = c.data;
            let level = 100.0 * (1.0 - av.alpha());
            let low: Vec<f64> = av.ci_low().iter().map(|v| v.sqrt()).collect();
            let high: Vec<f64> = av.ci_high().iter().map(|v| v.sqrt()).collect();
            let [band, points] = estimate_series(av.tau_s(), av.adev(), &low, &high, None);
            let mut series = vec![
                band.labelled(format!("{level:.0}% interval")),
                points.labelled("Allan deviation"),
            ];
            // each line spans the observed cluster times and the read-off time
            let xs = [
                av.tau_s().first().copied().unwrap_or(1.0).min(1.0) / 2.0,
                av.tau_s().last().copied().unwrap_or(1.0).max(3.0) * 2.0,
            ];
            let u = pretty(c.unit);
            let terms = [
                SlopeLine {
                    symbol: "N",
                    value: readoff.n.value,
                    term: NoiseTerm::NoiseDensity,
                    at_tau_s: readoff.n.at_tau_s,
                    colour: 4,
                    legend: format!(
                        "{} (slope −1/2, at {} s)",
                        term_unit(NoiseTerm::NoiseDensity, c.unit),
                        number(readoff.n.at_tau_s)
                    ),
                },
                SlopeLine {
                    symbol: "B",
                    value: readoff.b.value,
                    term: NoiseTerm::BiasInstability,
                    at_tau_s: readoff.b.at_tau_s,
                    colour: 3,
                    legend: format!(
                        "{} (slope 0: min σ / 0.664, at {} s)",
                        term_unit(NoiseTerm::BiasInstability, c.unit),
                        number(readoff.b.at_tau_s)
                    ),
                },
                SlopeLine {
                    symbol: "K",
                    value: readoff.k.value,
                    term: NoiseTerm::RandomWalk,
                    at_tau_s: readoff.k.at_tau_s,
                    colour: 5,
                    legend: format!(
                        "{} (slope +1/2, at {} s)",
                        term_unit(NoiseTerm::RandomWalk, c.unit),
                        number(readoff.k.at_tau_s)
                    ),
                },
            ];
            let mut missing = Vec::new();
            for term in terms {
                let SlopeLine {
                    symbol,
                    value,
                    term,
                    at_tau_s: at,
                    colour,
                    legend: unit_text,
                } = term;
                let Some(v) = value else {
                    missing.push(symbol);
                    continue;
                };
                let line = |v: f64, t: f64| gmwm::term_avar(term, v, t).map_or(f64::NAN, f64::sqrt);
                let ys: Vec<f64> = xs.iter().map(|&t| line(v, t)).collect();
                let dashed = Mark::Line {
                    width: 2,
                    dashed: true,
                };
                series.push(Series::new(dashed, &xs, &ys).coloured(colour).clipped());
                series.push(
                    // the read-off point sets the range: K at 3 s often lies below the data
                    Series::new(Mark::Points, &[at], &[line(v, at)])
                        .coloured(colour)
                        .labelled(format!("{symbol} = {} {unit_text}", number(v))),
                );
            }
            series.extend(datasheet_series(&c.datasheet, av.tau_s(), Quantity::Adev));
            let mut title = format!("{}: IEEE 952 read-off", c.name);
            if !missing.is_empty() {
                title.push_str(&format!(" ({}: region too short)", missing.join(", ")));
            }
            Panel {
                title,
                x_label: AV_SCALE.to_string(),
                y_label: format!("Allan deviation σ(τ) [{u}]"),
                kind: PanelKind::LogLog(series),
            }
        })
        .collect();
    stacked(panels, 1, (1100, 600))
}
