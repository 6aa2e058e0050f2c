//! The covariate figure (one place per figure: its builder and what only it draws).

use super::*;

/// N, B, K against a covariate (docs/methods.md §5.14): one panel per quantity and sensor
/// (axes grouped by the unit of N), each axis a line with its pointwise band shaded; the
/// recorded range is in the abscissa's label. A quantity the chosen form does not let depend
/// on the covariate is drawn flat and dashed, labelled so.
pub fn covariate_figure(c: &gmwm::CovariateCalibration) -> Figure {
    let unit = c
        .unit
        .as_deref()
        .map(|u| format!(" [{u}]"))
        .unwrap_or_default();
    let mut groups: Vec<(&str, Vec<&gmwm::AxisCurves>)> = Vec::new();
    for a in &c.axes {
        match groups
            .iter_mut()
            .find(|(u, _)| *u == a.noise_density_unit.as_str())
        {
            Some((_, g)) => g.push(a),
            None => groups.push((a.noise_density_unit.as_str(), vec![a])),
        }
    }
    let mut panels = Vec::new();
    for (n_unit, axes) in &groups {
        let sensor = if n_unit.starts_with("rad") || n_unit.starts_with('°') {
            "gyroscope "
        } else if n_unit.starts_with('m') {
            "accelerometer "
        } else {
            ""
        };
        let names = ["noise density N", "bias instability B", "random walk K"];
        for (k, name) in names.iter().enumerate() {
            let mut series = Vec::new();
            let mut unit_of_q = String::new();
            for (i, a) in axes.iter().enumerate() {
                let pick = |p: &gmwm::CurvePoint| match k {
                    0 => p.noise_density,
                    1 => p.bias_instability,
                    _ => p.random_walk,
                };
                if a.points.iter().all(|p| pick(p).is_none()) {
                    continue;
                }
                unit_of_q = [
                    &a.noise_density_unit,
                    &a.bias_instability_unit,
                    &a.random_walk_unit,
                ][k]
                    .clone();
                let x: Vec<f64> = a.points.iter().map(|p| p.covariate).collect();
                let v = |f: &dyn Fn(&gmwm::BandValue) -> Option<f64>| -> Vec<f64> {
                    a.points
                        .iter()
                        .map(|p| pick(p).and_then(|b| f(&b)).unwrap_or(f64::NAN))
                        .collect()
                };
                let value = v(&|b| Some(b.value));
                let low = v(&|b| b.low);
                let high = v(&|b| b.high);
                // a quantity the windows do not determine (no band anywhere) is not drawn: its
                // value (a term pushed to zero) would only stretch the axis
                if !low.iter().any(|l| l.is_finite()) {
                    continue;
                }
                series.push(Series::band(&x, &low, &high).coloured(i));
                let label = if a.depends[k] {
                    a.column.clone()
                } else {
                    format!("{} (no dependence chosen)", a.column)
                };
                series.push(
                    Series::new(
                        Mark::Line {
                            width: 2,
                            dashed: !a.depends[k],
                        },
                        &x,
                        &value,
                    )
                    .coloured(i)
                    .labelled(label),
                );
            }
            if series.is_empty() {
                continue;
            }
            panels.push(Panel {
                title: format!(
                    "{sensor}{name} against {} ({:.0}% bands)",
                    c.covariate,
                    100.0 * (1.0 - c.alpha)
                ),
                x_label: format!(
                    "{}{unit} (recorded {}..{})",
                    c.covariate,
                    number(c.range[0]),
                    number(c.range[1])
                ),
                y_label: format!("{name} [{unit_of_q}]"),
                kind: PanelKind::LinLog(series),
            });
        }
    }
    stacked(panels, 2, (820, 440))
}
