//! The figures of docs/methods.md §11 (paper Figs. 1–4), the IEEE Std 952 read-off and the
//! Welch PSD, built from the engine's results. Each builder only arranges numbers the engine
//! computed.

use crate::chart::{BarRow, Bars, Mark, Panel, PanelKind, Series};
use crate::style::number;
use crate::Figure;
use gmwm::{
    si_unit, AllanKind, AllanVariance, DatasheetLine, GmwmFit, IeeeReadoff, ModelSelection,
    NoiseTerm, PooledFit, Psd, Sensor, SensorInfo, SharedFit, SignalUnit, WaveletVariance,
};

mod allan;
mod compare;
mod covariate;
mod fit;
mod ieee;
mod plan;
mod pooled;
mod psd;
mod recordings;
mod selection;
mod shared;
mod wv;

pub use allan::allan_figure;
pub use compare::compare_figure;
pub use covariate::covariate_figure;
pub use fit::fit_figure;
pub use ieee::ieee_figure;
pub use plan::plan_figure;
pub use pooled::pooled_figure;
pub use psd::{psd_figure, PSD_FREQUENCY};
pub use recordings::recordings_figure;
pub use selection::selection_figure;
pub use shared::shared_figure;
pub use wv::wv_figure;

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
    /// The datasheet's lines of the column's sensor, in its unit (dashed grey on the Allan
    /// and WV figures; none by default).
    pub datasheet: Vec<DatasheetLine>,
}

impl<'a, T> Column<'a, T> {
    /// A column whose sensor and axis are inferred from its name.
    pub fn new(name: &'a str, unit: &'a str, data: &'a T) -> Self {
        Self {
            name,
            unit,
            sensor_axis: None,
            data,
            datasheet: Vec::new(),
        }
    }

    /// With the datasheet's lines (in the column's unit: [`gmwm::Datasheet::lines`]).
    pub fn with_datasheet(mut self, lines: Vec<DatasheetLine>) -> Self {
        self.datasheet = lines;
        self
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
pub(super) fn pretty(unit: &str) -> String {
    unit.replace("^2", "²").replace("^3", "³")
}

/// The unit of a noise term for a series in `unit`: SI names when the data are in SI
/// (`rad/s`, `m/s^2`), else in terms of the data unit; the engine's one formula
/// ([`gmwm::si_unit`], docs/methods.md §14.2), so figures and report agree.
pub(super) fn term_unit(term: NoiseTerm, unit: &str) -> String {
    match unit.parse::<SignalUnit>() {
        Ok(u) if u.to_si() == 1.0 => si_unit(term, Some(u.kind()), unit),
        _ => si_unit(term, None, &pretty(unit)),
    }
}

pub(super) fn squared(unit: &str) -> String {
    let unit = pretty(unit);
    if unit.contains('/') || unit.contains('·') || unit.contains('*') {
        format!("({unit})²")
    } else {
        format!("{unit}²")
    }
}

pub(super) fn wv_label(unit: &str) -> String {
    format!("wavelet variance ν² [{}]", squared(unit))
}

/// The estimate with its band as two series (band first, so the points are drawn on top).
pub(super) fn estimate_series(
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

/// The quantity a figure shows, for its datasheet lines.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Quantity {
    /// Allan deviation against the cluster time.
    Adev,
    /// Haar wavelet variance against the scale.
    Wv,
}

/// The datasheet's lines across the span of `tau_s`, dashed grey and labelled (the engine's
/// [`DatasheetLine::adev`], [`DatasheetLine::wv`]). A line is clipped to the panel but sets
/// its vertical range at its read-off point (N at 1 s, K at 3 s of cluster time, twice that in
/// WV scale; B anywhere), clamped into the span, so that a datasheet far from the data still
/// shows where it is read.
pub(super) fn datasheet_series(lines: &[DatasheetLine], tau_s: &[f64], q: Quantity) -> Vec<Series> {
    let span = tau_s
        .iter()
        .copied()
        .filter(|t| t.is_finite() && *t > 0.0)
        .fold(None, |acc: Option<(f64, f64)>, t| match acc {
            None => Some((t, t)),
            Some((lo, hi)) => Some((lo.min(t), hi.max(t))),
        });
    let Some((lo, hi)) = span else {
        return Vec::new();
    };
    let dashed = Mark::Line {
        width: 2,
        dashed: true,
    };
    let mut series = Vec::new();
    for line in lines {
        let y = |t: f64| match q {
            Quantity::Adev => line.adev(t),
            Quantity::Wv => line.wv(t),
        };
        let scale = match q {
            Quantity::Adev => 1.0,
            Quantity::Wv => 2.0,
        };
        let at = line.at_tau_s().map_or(lo, |t| t * scale).clamp(lo, hi);
        // a straight line on log-log axes: its two ends
        series.push(
            Series::new(dashed, &[lo, hi], &[y(lo), y(hi)])
                .clipped()
                .labelled(line.label.clone()),
        );
        // the read-off point: one point, not drawn, setting the range
        series.push(Series::new(dashed, &[at], &[y(at)]));
    }
    series
}

pub(super) const SENSOR_TITLES: [&str; 3] = ["gyroscope", "accelerometer", "other"];

/// What one column of a variance figure contributes: scale, value, band, and labels.
pub(super) struct Curve<'a> {
    name: &'a str,
    /// Sensor row and axis label.
    place: (usize, String),
    unit: &'a str,
    tau_s: Vec<f64>,
    value: Vec<f64>,
    low: Vec<f64>,
    high: Vec<f64>,
    /// The datasheet's lines ([`datasheet_series`]).
    datasheet: Vec<Series>,
}

pub(super) fn variance_figure(
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
                                        .into_iter()
                                        .chain(c.datasheet.iter().cloned())
                                        .collect(),
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
            // datasheet lines bring a legend: wider panels keep the plot area
            let panel_width = if curves.iter().any(|c| !c.datasheet.is_empty()) {
                680
            } else {
                420
            };
            let size = (panel_width * cols as u32 + 80, 380 * rows.len() as u32 + 40);
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
                // the sensor's datasheet, once (its axes share the datasheet and, as read, the unit)
                series.extend(members[0].datasheet.iter().cloned());
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

/// A grid with up to three panels a row for one panel per column.
pub(super) fn stacked(panels: Vec<Panel>, cols: usize, panel_size: (u32, u32)) -> Figure {
    let n = panels.len().max(1);
    let cols = cols.min(n).max(1);
    let rows = n.div_ceil(cols);
    Figure::new(
        panels,
        (rows, cols),
        (panel_size.0 * cols as u32, panel_size.1 * rows as u32),
    )
}

/// The legend entry of one fitted component: its process and the values a filter uses, in the
/// data unit (continuous time; docs/methods.md §14.2, through the engine's read-off).
pub(super) fn component_label(fit: &GmwmFit, index: usize, unit: &str) -> String {
    let component = &fit.model().components()[index];
    let kind = component.kind.name();
    let values: Vec<String> = fit
        .navigation(Some(unit))
        .into_iter()
        .filter(|p| p.index == index && p.name != "driving_noise_density")
        .filter_map(|p| {
            let (symbol, unit) = match p.name {
                "white_noise_density" => ("N", term_unit(NoiseTerm::NoiseDensity, unit)),
                "quantization_coefficient" => ("Q", term_unit(NoiseTerm::Quantization, unit)),
                "rate_random_walk_density" => ("K", term_unit(NoiseTerm::RandomWalk, unit)),
                "drift_rate" => ("R", term_unit(NoiseTerm::RateRamp, unit)),
                "correlation_time" => ("T", term_unit(NoiseTerm::GmCorrelationTime, unit)),
                "gm_std" => ("σ", term_unit(NoiseTerm::GmSigma, unit)),
                "bias_instability" => ("B", term_unit(NoiseTerm::BiasInstability, unit)),
                // a periodic (vibration) term: its line and its amplitude
                "frequency" => ("f", "Hz".to_string()),
                "amplitude" => ("A", unit.to_string()),
                _ => return None,
            };
            Some(format!("{symbol} = {} {unit}", number(p.value)))
        })
        .collect();
    if values.is_empty() {
        component.to_string()
    } else {
        format!("{kind}: {}", values.join(", "))
    }
}

/// The legend entry of a fitted component whose implied WV lies wholly below the plotted
/// range: its process without a value (`WN: negligible`), since a term that collapsed to
/// nothing has values such as 4.7×10⁻³⁹ that mean nothing to a reader.
pub(super) fn negligible_label(fit: &GmwmFit, index: usize) -> String {
    format!(
        "{}: negligible",
        fit.model().components()[index].kind.name()
    )
}

/// The empirical WV with its band and the fitted model's implied WV (total, thick), as series.
pub(super) fn empirical_and_model(fit: &GmwmFit, model_label: &str) -> Vec<Series> {
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

/// Rows of the WIC chart in the report: the selected row and the best others.
pub const WIC_ROWS: usize = 10;

/// A model without its empty parentheses, for chart labels.
pub(super) fn short_model(text: &str) -> String {
    text.replace("()", "")
}
