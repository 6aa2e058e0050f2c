//! The figures of docs/methods.md §11 (paper Figs. 1–4) and the IEEE Std 952 read-off, built from
//! the engine's results. Each builder only arranges numbers the engine computed.

use crate::chart::{BarRow, Bars, Mark, Panel, PanelKind, Series};
use crate::style::number;
use crate::Figure;
use gmwm::calib::ieee::IeeeReadoff;
use gmwm::fit::PooledFit;
use gmwm::imu::{Sensor, SensorInfo};
use gmwm::shared::SharedFit;
use gmwm::units::{si_unit, NoiseTerm, SignalUnit};
use gmwm::{AllanKind, AllanVariance, GmwmFit, ModelSelection, WaveletVariance};

/// A named series of a recording with the unit of its samples (`"u"` when unknown).
#[derive(Debug, Clone)]
pub struct Column<'a, T> {
    /// Column name (`gyro_x`, ...).
    pub name: &'a str,
    /// Unit of the samples.
    pub unit: &'a str,
    /// The sensor and axis the column measures (`None`: inferred from its name).
    pub sensor_axis: Option<(Sensor, String)>,
    /// What is drawn.
    pub data: &'a T,
}

impl<'a, T> Column<'a, T> {
    /// A column whose sensor and axis are inferred from its name.
    pub fn new(name: &'a str, unit: &'a str, data: &'a T) -> Self {
        Self {
            name,
            unit,
            sensor_axis: None,
            data,
        }
    }

    /// With the sensor and axis the reader recognised (e.g. from a sidecar's meaning).
    pub fn with_sensor(mut self, sensor: Sensor, axis: impl Into<String>) -> Self {
        self.sensor_axis = Some((sensor, axis.into()));
        self
    }

    /// Sensor row (gyroscope, accelerometer, other) and axis label.
    fn place(&self) -> (usize, String) {
        let known = self
            .sensor_axis
            .clone()
            .or_else(|| SensorInfo::infer(self.name));
        match known {
            Some((Sensor::Gyroscope, axis)) => (0, axis),
            Some((Sensor::Accelerometer, axis)) => (1, axis),
            _ => (2, self.name.to_string()),
        }
    }
}

/// How several columns' variances share a figure (paper Fig. 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// One panel per column: rows gyroscope / accelerometer / other, columns the axes (Fig. 1a).
    Grid,
    /// One panel per sensor type with its axes overlaid (Fig. 1b).
    Overlay,
}

/// Horizontal axis of a WV figure: the Haar WV scale (docs/methods.md §14.1).
pub const WV_SCALE: &str = "scale τ = 2^j/f (s)";
/// Horizontal axis of an Allan-type figure: the cluster time (docs/methods.md §14.1).
pub const AV_SCALE: &str = "cluster time τ = m/f (s)";

/// A unit as set in figures: `m/s^2` as `m/s²`.
fn pretty(unit: &str) -> String {
    unit.replace("^2", "²").replace("^3", "³")
}

/// The unit of a noise term for a series in `unit`: SI names when the data are in SI
/// (`rad/s`, `m/s^2`), else in terms of the data unit; the engine's one formula
/// ([`gmwm::units::si_unit`], docs/methods.md §14.2), so figures and report agree.
fn term_unit(term: NoiseTerm, unit: &str) -> String {
    match unit.parse::<SignalUnit>() {
        Ok(u) if u.to_si() == 1.0 => si_unit(term, Some(u.kind()), unit),
        _ => si_unit(term, None, &pretty(unit)),
    }
}

fn squared(unit: &str) -> String {
    let unit = pretty(unit);
    if unit.contains('/') || unit.contains('·') || unit.contains('*') {
        format!("({unit})²")
    } else {
        format!("{unit}²")
    }
}

fn wv_label(unit: &str) -> String {
    format!("wavelet variance ν² [{}]", squared(unit))
}

/// The estimate with its band as two series (band first, so the points are drawn on top).
fn estimate_series(
    tau_s: &[f64],
    value: &[f64],
    low: &[f64],
    high: &[f64],
    colour: Option<usize>,
) -> [Series; 2] {
    let mut band = Series::band(tau_s, low, high);
    let mut points = Series::new(Mark::LinePoints, tau_s, value);
    band.colour = colour;
    points.colour = colour;
    [band, points]
}

const SENSOR_TITLES: [&str; 3] = ["gyroscope", "accelerometer", "other"];

/// What one column of a variance figure contributes: scale, value, band, and labels.
struct Curve<'a> {
    name: &'a str,
    /// Sensor row and axis label.
    place: (usize, String),
    unit: &'a str,
    tau_s: Vec<f64>,
    value: Vec<f64>,
    low: Vec<f64>,
    high: Vec<f64>,
}

fn variance_figure(
    curves: &[Curve<'_>],
    layout: Layout,
    x_label: &str,
    y_label: &dyn Fn(&str) -> String,
    what: &str,
) -> Figure {
    if curves.is_empty() {
        let empty = Panel {
            title: "no column".to_string(),
            x_label: x_label.to_string(),
            y_label: String::new(),
            kind: PanelKind::LogLog(Vec::new()),
        };
        return Figure::new(vec![empty], (1, 1), (500, 420));
    }
    match layout {
        Layout::Grid => {
            let placed: Vec<(usize, String)> = curves.iter().map(|c| c.place.clone()).collect();
            let mut rows: Vec<usize> = placed.iter().map(|p| p.0).collect();
            rows.sort_unstable();
            rows.dedup();
            let cols = rows
                .iter()
                .map(|r| placed.iter().filter(|p| p.0 == *r).count())
                .max()
                .unwrap_or(1);
            let mut panels = Vec::new();
            for r in &rows {
                let members: Vec<usize> =
                    (0..curves.len()).filter(|&i| placed[i].0 == *r).collect();
                for k in 0..cols {
                    panels.push(match members.get(k) {
                        Some(&i) => {
                            let c = &curves[i];
                            Panel {
                                title: format!("{} ({what})", c.name),
                                x_label: x_label.to_string(),
                                y_label: y_label(c.unit),
                                kind: PanelKind::LogLog(
                                    estimate_series(&c.tau_s, &c.value, &c.low, &c.high, None)
                                        .to_vec(),
                                ),
                            }
                        }
                        // a short sensor row keeps the grid: an empty panel
                        None => Panel {
                            title: String::new(),
                            x_label: String::new(),
                            y_label: String::new(),
                            kind: PanelKind::LogLog(Vec::new()),
                        },
                    });
                }
            }
            let panels: Vec<Panel> = panels;
            let size = (420 * cols as u32 + 80, 380 * rows.len() as u32 + 40);
            Figure::new(panels, (rows.len(), cols), size)
        }
        Layout::Overlay => {
            let mut panels = Vec::new();
            for (row, title) in SENSOR_TITLES.iter().enumerate() {
                let members: Vec<&Curve<'_>> = curves.iter().filter(|c| c.place.0 == row).collect();
                if members.is_empty() {
                    continue;
                }
                let mut series = Vec::new();
                for (k, c) in members.iter().enumerate() {
                    let [band, points] =
                        estimate_series(&c.tau_s, &c.value, &c.low, &c.high, Some(k + 1));
                    let axis = &c.place.1;
                    series.push(band);
                    series.push(points.labelled(format!("axis {axis}")));
                }
                panels.push(Panel {
                    title: format!("{title} ({what})"),
                    x_label: x_label.to_string(),
                    y_label: y_label(members[0].unit),
                    kind: PanelKind::LogLog(series),
                });
            }
            let n = panels.len().max(1);
            Figure::new(panels, (n, 1), (1000, 520 * n as u32))
        }
    }
}

/// Wavelet variances with their confidence bands, one panel per column (`Layout::Grid`, paper
/// Fig. 1a) or one per sensor type with the axes overlaid (Fig. 1b).
pub fn wv_figure(columns: &[Column<'_, WaveletVariance>], layout: Layout) -> Figure {
    let curves: Vec<Curve<'_>> = columns
        .iter()
        .map(|c| Curve {
            name: c.name,
            place: c.place(),
            unit: c.unit,
            tau_s: c.data.tau_s().to_vec(),
            value: c.data.wv().to_vec(),
            low: c.data.ci_low().to_vec(),
            high: c.data.ci_high().to_vec(),
        })
        .collect();
    let what = match columns.first().map(|c| c.data.robust().is_some()) {
        Some(true) => "robust WV",
        _ => "WV",
    };
    variance_figure(&curves, layout, WV_SCALE, &wv_label, what)
}

/// Allan, modified Allan or Hadamard deviations with their bands (square roots of the
/// variance's interval), laid out as [`wv_figure`].
pub fn allan_figure(columns: &[Column<'_, AllanVariance>], layout: Layout) -> Figure {
    let curves: Vec<Curve<'_>> = columns
        .iter()
        .map(|c| Curve {
            name: c.name,
            place: c.place(),
            unit: c.unit,
            tau_s: c.data.tau_s().to_vec(),
            value: c.data.adev().to_vec(),
            low: c.data.ci_low().iter().map(|v| v.sqrt()).collect(),
            high: c.data.ci_high().iter().map(|v| v.sqrt()).collect(),
        })
        .collect();
    let (what, quantity) = match columns.first().map(|c| c.data.kind()) {
        Some(AllanKind::Modified) => ("modified Allan deviation", "modified Allan deviation"),
        Some(AllanKind::Hadamard | AllanKind::HadamardNonOverlapping) => {
            ("Hadamard deviation", "Hadamard deviation")
        }
        _ => ("Allan deviation", "Allan deviation σ(τ)"),
    };
    let label = move |unit: &str| format!("{quantity} [{}]", pretty(unit));
    variance_figure(&curves, layout, AV_SCALE, &label, what)
}

/// A grid with up to three panels a row for one panel per column.
fn stacked(panels: Vec<Panel>, cols: usize, panel_size: (u32, u32)) -> Figure {
    let n = panels.len().max(1);
    let cols = cols.min(n).max(1);
    let rows = n.div_ceil(cols);
    Figure::new(
        panels,
        (rows, cols),
        (panel_size.0 * cols as u32, panel_size.1 * rows as u32),
    )
}

/// The classical against the robust WV of each column (paper Fig. 2): where outliers inflate
/// the classical estimate, its points leave the robust band.
pub fn compare_figure(columns: &[Column<'_, (WaveletVariance, WaveletVariance)>]) -> Figure {
    let panels = columns
        .iter()
        .map(|c| {
            let (classical, robust) = c.data;
            let eff = robust.robust().map_or(0.6, |r| r.eff);
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
                kind: PanelKind::LogLog(vec![
                    cb.labelled(format!("classical {level:.0}% interval")),
                    rb.labelled(format!("robust {level:.0}% interval")),
                    cp.labelled("classical WV"),
                    rp.labelled(format!("robust WV (efficiency {eff})")),
                ]),
            }
        })
        .collect();
    stacked(panels, 1, (1000, 560))
}

/// The legend entry of one fitted component: its process and the values a filter uses, in the
/// data unit (continuous time; docs/methods.md §14.2, through the engine's read-off).
fn component_label(fit: &GmwmFit, index: usize, unit: &str) -> String {
    let component = &fit.model().components()[index];
    let kind = component.kind.name();
    let values: Vec<String> = fit
        .navigation(Some(unit))
        .into_iter()
        .filter(|p| p.index == index && p.name != "driving_noise_density")
        .filter_map(|p| {
            let (symbol, term) = match p.name {
                "white_noise_density" => ("N", NoiseTerm::NoiseDensity),
                "quantization_coefficient" => ("Q", NoiseTerm::Quantization),
                "rate_random_walk_density" => ("K", NoiseTerm::RandomWalk),
                "drift_rate" => ("R", NoiseTerm::RateRamp),
                "correlation_time" => ("T", NoiseTerm::GmCorrelationTime),
                "gm_std" => ("σ", NoiseTerm::GmSigma),
                _ => return None,
            };
            Some(format!(
                "{symbol} = {} {}",
                number(p.value),
                term_unit(term, unit)
            ))
        })
        .collect();
    if values.is_empty() {
        component.to_string()
    } else {
        format!("{kind}: {}", values.join(", "))
    }
}

/// The empirical WV with its band and the fitted model's implied WV (total, thick), as series.
fn empirical_and_model(fit: &GmwmFit, model_label: &str) -> Vec<Series> {
    let implied = &fit.implied_wv();
    let mut series = Vec::new();
    if let Some(wv) = &fit.empirical() {
        let level = 100.0 * (1.0 - wv.alpha());
        let [band, points] = estimate_series(wv.tau_s(), wv.wv(), wv.ci_low(), wv.ci_high(), None);
        series.push(band.labelled(format!("{level:.0}% interval")));
        series.push(points.labelled("empirical WV"));
    } else {
        series.push(
            Series::new(Mark::LinePoints, &implied.tau_s, fit.nu_hat()).labelled("empirical WV"),
        );
    }
    series.push(
        Series::new(
            Mark::Line {
                width: 3,
                dashed: false,
            },
            &implied.tau_s,
            &implied.wv,
        )
        .coloured(0)
        .clipped()
        .labelled(model_label),
    );
    series
}

/// A fit (paper Figs. 3a, 3b): the empirical WV with its band, the model's implied WV and,
/// with more than one component, each component's implied WV as its own line, the legend
/// naming each process with its values in the data unit.
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
                        .labelled(component_label(fit, k, c.unit)),
                    );
                }
            }
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
        fit.shared_model.parse::<gmwm::model::Model>().map_or_else(
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

/// Rows of the WIC chart in the report: the selected row and the best others.
pub const WIC_ROWS: usize = 10;

/// A model without its empty parentheses, for chart labels.
fn short_model(text: &str) -> String {
    text.replace("()", "")
}

/// Model selection (paper Fig. 4): per column, the empirical WV against the selected model's
/// implied WV, beside the candidates' WIC with objective and optimism stacked (the best `rows`
/// canonical models, 0 for all, always with the selected one, marked ▶).
pub fn selection_figure(columns: &[Column<'_, ModelSelection>], rows: usize) -> Figure {
    let mut panels = Vec::new();
    for c in columns {
        let s = c.data;
        let selected = s.selected_canonical().model.to_string();
        panels.push(Panel {
            title: format!("{}: selected {}", c.name, short_model(&selected)),
            x_label: WV_SCALE.to_string(),
            y_label: wv_label(c.unit),
            kind: PanelKind::LogLog(empirical_and_model(s.fit(), "selected model (implied WV)")),
        });
        let selected_row = s
            .rows()
            .iter()
            .position(|r| r.status == gmwm::selection::RowStatus::Selected);
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

/// One IEEE 952 term on the Allan deviation: its line `sigma(value, tau)` and where it is
/// read (docs/methods.md §14.3).
struct SlopeLine {
    symbol: &'static str,
    value: Option<f64>,
    sigma: fn(f64, f64) -> f64,
    at_tau_s: f64,
    colour: usize,
    legend: String,
}

/// The IEEE Std 952 read-off (docs/methods.md §14.3) on the Allan deviation: the −1/2 slope line
/// through N at 1 s, the flat line at the minimum (B × 0.664) and the +1/2 slope line through
/// K at 3 s, each with its read-off point; a term without a value is left out and named in
/// the title.
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
                    sigma: |n, t| n / t.sqrt(),
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
                    sigma: |b, _| b * gmwm::calib::ieee::FLICKER_FACTOR,
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
                    sigma: |k, t| k * (t / 3.0).sqrt(),
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
                    sigma: line,
                    at_tau_s: at,
                    colour,
                    legend: unit_text,
                } = term;
                let Some(v) = value else {
                    missing.push(symbol);
                    continue;
                };
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
