//! What a figure holds, as plain data (panels of series on log-log axes, or a bar chart), and
//! its drawing with plotters on any backend. Builders in [`crate::figures`] fill these from the
//! engine's results; nothing here knows about statistics.

use crate::style::{
    colour, ensure_fonts, number, pow10_label, FONT, LABEL_SIZE, TICK_SIZE, TITLE_SIZE,
};
use crate::PlotError;
use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Mark {
    /// A polyline of the given width in pixels; dashed when `dashed`.
    Line {
        /// Stroke width, px.
        width: u32,
        /// Dashed (reference lines) or solid.
        dashed: bool,
    },
    /// Circles at the points joined by a thin line (empirical estimates).
    LinePoints,
    /// Circles only (read-off points).
    Points,
    /// A filled band between `y` (lower) and `upper`.
    Band,
    /// A bar's colour (legend swatch of a bar chart's segment).
    Bar,
}

/// One series of a log-log panel.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend entry (`None`: not in the legend).
    pub label: Option<String>,
    /// Palette index ([`crate::style::PALETTE`]); `None`: the empirical grey.
    pub colour: Option<usize>,
    /// How it is drawn.
    pub mark: Mark,
    /// Abscissae (positive; others are skipped).
    pub x: Vec<f64>,
    /// Ordinates (positive; NaN or non-positive values break the line).
    pub y: Vec<f64>,
    /// Upper edge of a [`Mark::Band`].
    pub upper: Option<Vec<f64>>,
    /// Whether the series sets the vertical range (data and bands do; model lines that fall
    /// far below the data are clipped and said to be below the plot in the legend).
    pub sets_range: bool,
    /// The legend entry instead of `label` when every value lies below the plotted range
    /// (`None`: `label` with "(below the plot)"): a fitted term that collapsed to nothing reads
    /// "WN: negligible" rather than a value such as 4.7×10⁻³⁹.
    pub label_below: Option<String>,
}

impl Series {
    /// A series of `mark` (sets the range, no label, empirical grey).
    pub fn new(mark: Mark, x: &[f64], y: &[f64]) -> Self {
        Self {
            label: None,
            colour: None,
            mark,
            x: x.to_vec(),
            y: y.to_vec(),
            upper: None,
            sets_range: true,
            label_below: None,
        }
    }

    /// A band between `low` and `high`.
    pub fn band(x: &[f64], low: &[f64], high: &[f64]) -> Self {
        Self {
            upper: Some(high.to_vec()),
            ..Self::new(Mark::Band, x, low)
        }
    }

    /// With a legend entry.
    pub fn labelled(mut self, label: impl Into<String>) -> Self {
        self.label = Some(label.into());
        self
    }

    /// With the legend entry `label` when it falls wholly below the plotted range.
    pub fn labelled_below(mut self, label: impl Into<String>) -> Self {
        self.label_below = Some(label.into());
        self
    }

    /// In palette colour `i`.
    pub fn coloured(mut self, i: usize) -> Self {
        self.colour = Some(i);
        self
    }

    /// Not setting the vertical range.
    pub fn clipped(mut self) -> Self {
        self.sets_range = false;
        self
    }

    fn rgb(&self) -> RGBColor {
        self.colour.map_or(crate::style::EMPIRICAL, colour)
    }
}

/// One row of a bar chart of WIC: objective and optimism stacked.
#[derive(Debug, Clone, PartialEq)]
pub struct BarRow {
    /// Category label (a model).
    pub label: String,
    /// First segment (the objective).
    pub first: f64,
    /// Second segment (the optimism).
    pub second: f64,
    /// Drawn emphasised (the selected row).
    pub emphasised: bool,
}

/// A horizontal stacked bar chart.
#[derive(Debug, Clone, PartialEq)]
pub struct Bars {
    /// Rows from top to bottom.
    pub rows: Vec<BarRow>,
    /// Legend entries of the two segments.
    pub segment_labels: [String; 2],
}

/// What a panel shows.
#[derive(Debug, Clone, PartialEq)]
pub enum PanelKind {
    /// Series on log-log axes.
    LogLog(Vec<Series>),
    /// Series against a linear abscissa (a covariate such as temperature, which may be zero
    /// or negative) on a log ordinate; lines and bands only.
    LinLog(Vec<Series>),
    /// A stacked bar chart.
    Bars(Bars),
}

/// One panel of a figure.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// Title above the panel.
    pub title: String,
    /// Horizontal axis description, with its unit.
    pub x_label: String,
    /// Vertical axis description, with its unit.
    pub y_label: String,
    /// Content.
    pub kind: PanelKind,
}

impl Panel {
    /// The legend entries as drawn, in drawing order (with "(below the plot)" and the like
    /// where a series has no point inside the panel's range).
    pub fn legend(&self) -> Vec<String> {
        match &self.kind {
            PanelKind::LogLog(series) | PanelKind::LinLog(series) => {
                legend_entries(series, ranges(series).1)
                    .into_iter()
                    .map(|(label, _, _)| label)
                    .collect()
            }
            PanelKind::Bars(b) => b.segment_labels.to_vec(),
        }
    }
}

/// Range of the finite positive values of `values`, or `None`.
fn positive_range<'a>(values: impl Iterator<Item = &'a f64>) -> Option<(f64, f64)> {
    values
        .filter(|v| v.is_finite() && **v > 0.0)
        .fold(None, |acc, &v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
}

/// Narrowest logarithmic range drawn, decades: any decade holds at least three of the 1-2-5
/// multiples of the powers of ten (the widest span of two, 2 to 10 excluded, is 0.7 decades),
/// so that a nearly flat series is labelled by round numbers rather than by 4, 5, ... 9.
const MIN_LOG_SPAN: f64 = 1.0;

/// A logarithmic range padded by 5% of its decades on each side, and widened evenly to
/// `MIN_LOG_SPAN` decades (so that one level, or a nearly flat series, still has labelled axes).
fn padded((lo, hi): (f64, f64)) -> (f64, f64) {
    let (a, b) = (lo.log10(), hi.log10());
    let pad = (0.05 * (b - a)).max(0.5 * (MIN_LOG_SPAN - (b - a)));
    (10f64.powf(a - pad), 10f64.powf(b + pad))
}

/// Fewest labelled ticks on a logarithmic axis: with two, a reader cannot tell the scale from
/// one reading (an accelerometer's Allan deviation spanning less than a decade showed one).
const MIN_LOG_LABELS: usize = 3;

/// Tick marks of a logarithmic axis: powers of ten (every other one beyond eight decades);
/// when fewer than [`MIN_LOG_LABELS`] powers fall in the range, the first of the multiples 1-3,
/// 1-2-5, then 1 to 9 of each power that gives that many; and the light grid lines at 2..9
/// times each power.
fn log_ticks((lo, hi): (f64, f64)) -> (Vec<f64>, Vec<f64>) {
    let (a, b) = (lo.log10().ceil() as i32, hi.log10().floor() as i32);
    let decades = (b - a).max(0);
    let step = if decades > 8 { 2 } else { 1 };
    let mut bold: Vec<f64> = (a..=b)
        .filter(|k| (k - a) % step == 0)
        .map(|k| 10f64.powi(k))
        .collect();
    let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let multiples = |ms: &[f64]| -> Vec<f64> {
        (k0..=k1)
            .flat_map(|k| ms.iter().map(move |m| m * 10f64.powi(k)))
            .filter(|v| *v >= lo * (1.0 - 1e-12) && *v <= hi * (1.0 + 1e-12))
            .collect()
    };
    for ms in [
        &[1.0, 3.0][..],
        &[1.0, 2.0, 5.0][..],
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0][..],
    ] {
        if bold.len() >= MIN_LOG_LABELS {
            break;
        }
        bold = multiples(ms);
    }
    let light = if decades <= 8 {
        multiples(&[2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
            .into_iter()
            .filter(|v| !bold.iter().any(|b| (b / v - 1.0).abs() < 1e-9))
            .collect()
    } else {
        Vec::new()
    };
    (bold, light)
}

/// Splits a polyline at missing points (NaN, non-positive) and clips it to the box in log
/// space (Liang–Barsky per segment), so lines below the range stop at its edge.
fn clip_polyline(x: &[f64], y: &[f64], xr: (f64, f64), yr: (f64, f64)) -> Vec<Vec<(f64, f64)>> {
    let ok = |v: f64| v.is_finite() && v > 0.0;
    let (x0, x1, y0, y1) = (xr.0.log10(), xr.1.log10(), yr.0.log10(), yr.1.log10());
    let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut current: Vec<(f64, f64)> = Vec::new();
    let n = x.len().min(y.len());
    for i in 1..n {
        if !(ok(x[i - 1]) && ok(y[i - 1]) && ok(x[i]) && ok(y[i])) {
            if !current.is_empty() {
                runs.push(std::mem::take(&mut current));
            }
            continue;
        }
        let (ax, ay, bx, by) = (
            x[i - 1].log10(),
            y[i - 1].log10(),
            x[i].log10(),
            y[i].log10(),
        );
        let (dx, dy) = (bx - ax, by - ay);
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        let mut inside = true;
        for (p, q) in [(-dx, ax - x0), (dx, x1 - ax), (-dy, ay - y0), (dy, y1 - ay)] {
            if p == 0.0 {
                if q < 0.0 {
                    inside = false;
                }
            } else {
                let r = q / p;
                if p < 0.0 {
                    t0 = t0.max(r);
                } else {
                    t1 = t1.min(r);
                }
            }
        }
        if !inside || t0 > t1 {
            if !current.is_empty() {
                runs.push(std::mem::take(&mut current));
            }
            continue;
        }
        let at = |t: f64| (10f64.powf(ax + t * dx), 10f64.powf(ay + t * dy));
        let (start, end) = (at(t0), at(t1));
        if current.is_empty() || t0 > 0.0 {
            if !current.is_empty() {
                runs.push(std::mem::take(&mut current));
            }
            current.push(start);
        }
        current.push(end);
        if t1 < 1.0 {
            runs.push(std::mem::take(&mut current));
        }
    }
    if !current.is_empty() {
        runs.push(current);
    }
    runs
}

/// Splits a band at missing levels and clamps it to the vertical range.
fn band_runs(s: &Series, yr: (f64, f64)) -> Vec<Vec<(f64, f64)>> {
    let upper = s.upper.as_deref().unwrap_or(&s.y);
    let ok = |v: f64| v.is_finite() && v > 0.0;
    let mut polygons = Vec::new();
    let mut run: Vec<usize> = Vec::new();
    let n = s.x.len().min(s.y.len()).min(upper.len());
    let mut flush = |run: &mut Vec<usize>| {
        if !run.is_empty() {
            let clamp = |v: f64| v.clamp(yr.0, yr.1);
            let mut pts: Vec<(f64, f64)> = run.iter().map(|&i| (s.x[i], clamp(upper[i]))).collect();
            pts.extend(run.iter().rev().map(|&i| (s.x[i], clamp(s.y[i]))));
            polygons.push(pts);
            run.clear();
        }
    };
    for (i, ((&x, &y), &hi)) in s.x.iter().zip(&s.y).zip(upper).take(n).enumerate() {
        if ok(x) && ok(y) && ok(hi) {
            run.push(i);
        } else {
            flush(&mut run);
        }
    }
    flush(&mut run);
    polygons
}

fn draw_error<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> PlotError {
    PlotError::Draw(e.to_string())
}

/// Width in pixels of `text` at `size` in the embedded font, as the backend will set it.
fn text_width<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, text: &str, size: u32) -> u32 {
    area.estimate_text_size(text, &TextStyle::from((FONT, size).into_font()))
        .map(|(w, _)| w)
        .unwrap_or_else(|_| (text.chars().count() as u32 * size) / 2)
}

/// The legend column to the right of a panel: one entry per labelled series, never over data.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, RGBColor, Mark)],
) -> Result<(), PlotError> {
    let style = (FONT, TICK_SIZE).into_font().color(&BLACK);
    let line_h = (TICK_SIZE as i32 * 3) / 2;
    let top = 40;
    for (k, (label, rgb, mark)) in entries.iter().enumerate() {
        let y = top + k as i32 * line_h;
        let (x0, x1) = (8, 36);
        match mark {
            Mark::Band => area
                .draw(&Rectangle::new(
                    [(x0, y - 6), (x1, y + 6)],
                    rgb.mix(0.25).filled(),
                ))
                .map_err(draw_error)?,
            Mark::Bar => area
                .draw(&Rectangle::new([(x0, y - 7), (x1, y + 7)], rgb.filled()))
                .map_err(draw_error)?,
            Mark::Points => area
                .draw(&Circle::new(((x0 + x1) / 2, y), 4, rgb.filled()))
                .map_err(draw_error)?,
            Mark::LinePoints => {
                area.draw(&PathElement::new(
                    vec![(x0, y), (x1, y)],
                    rgb.stroke_width(1),
                ))
                .map_err(draw_error)?;
                area.draw(&Circle::new(((x0 + x1) / 2, y), 3, rgb.filled()))
                    .map_err(draw_error)?;
            }
            Mark::Line { width, dashed } => {
                if *dashed {
                    for xa in (x0..x1).step_by(8) {
                        area.draw(&PathElement::new(
                            vec![(xa, y), ((xa + 4).min(x1), y)],
                            rgb.stroke_width(*width),
                        ))
                        .map_err(draw_error)?;
                    }
                } else {
                    area.draw(&PathElement::new(
                        vec![(x0, y), (x1, y)],
                        rgb.stroke_width(*width),
                    ))
                    .map_err(draw_error)?;
                }
            }
        }
        area.draw(&Text::new(
            label.clone(),
            (x1 + 8, y - TICK_SIZE as i32 / 2 - 1),
            style.clone(),
        ))
        .map_err(draw_error)?;
    }
    Ok(())
}

/// Width of the legend column of `entries` inside `area` (at most half of it).
fn legend_width<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, RGBColor, Mark)],
) -> u32 {
    let widest = entries
        .iter()
        .map(|(l, _, _)| text_width(area, l, TICK_SIZE))
        .max()
        .unwrap_or(0);
    (widest + 60).min(area.dim_in_pixel().0 / 2)
}

/// The horizontal and vertical ranges of a log-log panel: every series' positive abscissae,
/// the ordinates of those that set the range (all of them when none does), padded.
fn ranges(series: &[Series]) -> ((f64, f64), (f64, f64)) {
    let xr = positive_range(series.iter().flat_map(|s| s.x.iter()))
        .map(padded)
        .unwrap_or((0.1, 10.0));
    let yr = positive_range(
        series
            .iter()
            .filter(|s| s.sets_range)
            .flat_map(|s| s.y.iter().chain(s.upper.iter().flatten())),
    )
    .or_else(|| positive_range(series.iter().flat_map(|s| s.y.iter())))
    .map(padded)
    .unwrap_or((0.1, 10.0));
    (xr, yr)
}

/// The legend entries of a log-log panel whose vertical range is `yr`: a series with no point
/// inside it says so (below the plot: its `label_below` when it has one).
fn legend_entries(series: &[Series], yr: (f64, f64)) -> Vec<(String, RGBColor, Mark)> {
    // a series with no point inside the vertical range says so in the legend
    series
        .iter()
        .filter_map(|s| {
            let label = s.label.as_ref()?;
            let finite: Vec<f64> =
                s.y.iter()
                    .chain(s.upper.iter().flatten())
                    .copied()
                    .filter(|v| v.is_finite() && *v > 0.0)
                    .collect();
            let label = if finite.iter().any(|v| *v >= yr.0 && *v <= yr.1) {
                label.clone()
            } else if finite.is_empty() {
                format!("{label} (no value to draw)")
            } else if finite.iter().all(|v| *v < yr.0) {
                match &s.label_below {
                    Some(below) => format!("{below} (below the plot)"),
                    None => format!("{label} (below the plot)"),
                }
            } else {
                format!("{label} (outside the plot)")
            };
            Some((label, s.rgb(), s.mark))
        })
        .collect()
}

/// The plot area and, when there are `entries`, the legend column on its right.
fn split_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, RGBColor, Mark)],
) -> (DrawingArea<DB, Shift>, Option<DrawingArea<DB, Shift>>) {
    if entries.is_empty() {
        return (area.clone(), None);
    }
    let (w, _) = area.dim_in_pixel();
    let (p, l) = area.split_horizontally(w - legend_width(area, entries));
    (p, Some(l))
}

/// The grid, axis labels and tick labels of a panel with a log ordinate (powers of ten) and
/// abscissa ticks written by `x_label`.
fn draw_mesh<DB, X, Y>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<X, Y>>,
    panel: &Panel,
    x_label: &dyn Fn(&f64) -> String,
) -> Result<(), PlotError>
where
    DB: DrawingBackend,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .x_desc(&panel.x_label)
        .y_desc(&panel.y_label)
        .x_label_formatter(x_label)
        .y_label_formatter(&|v| pow10_label(*v))
        .label_style((FONT, TICK_SIZE))
        .axis_desc_style((FONT, LABEL_SIZE))
        .bold_line_style(RGBColor(200, 200, 200).stroke_width(1))
        .light_line_style(RGBColor(236, 236, 236).stroke_width(1))
        .draw()
        .map_err(draw_error)
}

/// Draws a log-log panel.
fn draw_loglog<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
    series: &[Series],
) -> Result<(), PlotError> {
    let (xr, yr) = ranges(series);
    let entries = legend_entries(series, yr);
    let (plot, legend) = split_legend(area, &entries);
    let (xb, xl) = log_ticks(xr);
    let (yb, yl) = log_ticks(yr);
    let mut chart = ChartBuilder::on(&plot)
        .caption(&panel.title, (FONT, TITLE_SIZE))
        .margin(12)
        .x_label_area_size(52)
        .y_label_area_size(84)
        .build_cartesian_2d(
            (xr.0..xr.1)
                .log_scale()
                .with_key_points(xb)
                .with_light_points(xl),
            (yr.0..yr.1)
                .log_scale()
                .with_key_points(yb)
                .with_light_points(yl),
        )
        .map_err(draw_error)?;
    draw_mesh(&mut chart, panel, &|v| pow10_label(*v))?;
    let inside = |&(x, y): &(f64, f64)| x >= xr.0 && x <= xr.1 && y >= yr.0 && y <= yr.1;
    for s in series {
        let rgb = s.rgb();
        match s.mark {
            Mark::Band => {
                for poly in band_runs(s, yr) {
                    if poly.len() == 2 {
                        // one level: a vertical interval bar
                        chart
                            .draw_series(std::iter::once(PathElement::new(
                                poly,
                                rgb.mix(0.5).stroke_width(3),
                            )))
                            .map_err(draw_error)?;
                    } else {
                        chart
                            .draw_series(std::iter::once(Polygon::new(poly, rgb.mix(0.2).filled())))
                            .map_err(draw_error)?;
                    }
                }
            }
            Mark::Line { width, dashed } => {
                for run in clip_polyline(&s.x, &s.y, xr, yr) {
                    if dashed {
                        chart
                            .draw_series(DashedLineSeries::new(run, 7, 5, rgb.stroke_width(width)))
                            .map_err(draw_error)?;
                    } else {
                        chart
                            .draw_series(LineSeries::new(run, rgb.stroke_width(width)))
                            .map_err(draw_error)?;
                    }
                }
            }
            Mark::Bar => {}
            Mark::LinePoints | Mark::Points => {
                if s.mark == Mark::LinePoints {
                    for run in clip_polyline(&s.x, &s.y, xr, yr) {
                        chart
                            .draw_series(LineSeries::new(run, rgb.stroke_width(1)))
                            .map_err(draw_error)?;
                    }
                }
                let pts: Vec<(f64, f64)> =
                    s.x.iter()
                        .zip(&s.y)
                        .map(|(&x, &y)| (x, y))
                        .filter(inside)
                        .collect();
                let r = if s.mark == Mark::Points { 5 } else { 3 };
                chart
                    .draw_series(pts.into_iter().map(|p| Circle::new(p, r, rgb.filled())))
                    .map_err(draw_error)?;
            }
        }
    }
    if let Some(l) = legend {
        draw_legend(&l, &entries)?;
    }
    Ok(())
}

/// Draws a panel with a linear abscissa and a log ordinate: lines (broken at missing values)
/// and bands (a polygon per run of points with both ends); the abscissa spans every series'
/// finite abscissae.
fn draw_linlog<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
    series: &[Series],
) -> Result<(), PlotError> {
    let (_, yr) = ranges(series);
    let (x0, x1) = series
        .iter()
        .flat_map(|s| s.x.iter().copied())
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    let (x0, x1) = if x0 < x1 {
        let pad = 0.02 * (x1 - x0);
        (x0 - pad, x1 + pad)
    } else if x0.is_finite() {
        (x0 - 1.0, x0 + 1.0)
    } else {
        (0.0, 1.0)
    };
    let entries = legend_entries(series, yr);
    let (plot, legend) = split_legend(area, &entries);
    let (yb, yl) = log_ticks(yr);
    let mut chart = ChartBuilder::on(&plot)
        .caption(&panel.title, (FONT, TITLE_SIZE))
        .margin(12)
        .x_label_area_size(52)
        .y_label_area_size(84)
        .build_cartesian_2d(
            x0..x1,
            (yr.0..yr.1)
                .log_scale()
                .with_key_points(yb)
                .with_light_points(yl),
        )
        .map_err(draw_error)?;
    draw_mesh(&mut chart, panel, &|v| number(*v))?;
    let ok = |y: f64| y.is_finite() && y >= yr.0 && y <= yr.1;
    for s in series {
        let rgb = s.rgb();
        let upper = s.upper.as_deref();
        // runs of consecutive drawable points
        let mut runs: Vec<Vec<usize>> = vec![Vec::new()];
        for k in 0..s.x.len() {
            // a band is drawn clamped to the range; a line only inside it
            let drawable = match (s.mark, upper) {
                (Mark::Band, Some(u)) => {
                    s.y[k].is_finite() && u[k].is_finite() && s.y[k] > 0.0 && u[k] > 0.0
                }
                _ => ok(s.y[k]),
            };
            if drawable {
                if let Some(r) = runs.last_mut() {
                    r.push(k);
                }
            } else if runs.last().is_some_and(|r| !r.is_empty()) {
                runs.push(Vec::new());
            }
        }
        for run in runs.iter().filter(|r| !r.is_empty()) {
            match (s.mark, upper) {
                (Mark::Band, Some(u)) => {
                    let clamp = |v: f64| v.clamp(yr.0, yr.1);
                    let poly: Vec<(f64, f64)> = run
                        .iter()
                        .map(|&k| (s.x[k], clamp(s.y[k])))
                        .chain(run.iter().rev().map(|&k| (s.x[k], clamp(u[k]))))
                        .collect();
                    chart
                        .draw_series(std::iter::once(Polygon::new(poly, rgb.mix(0.2).filled())))
                        .map_err(draw_error)?;
                }
                (Mark::Line { width, dashed }, _) => {
                    let pts: Vec<(f64, f64)> = run.iter().map(|&k| (s.x[k], s.y[k])).collect();
                    if dashed {
                        chart
                            .draw_series(DashedLineSeries::new(pts, 7, 5, rgb.stroke_width(width)))
                            .map_err(draw_error)?;
                    } else {
                        chart
                            .draw_series(LineSeries::new(pts, rgb.stroke_width(width)))
                            .map_err(draw_error)?;
                    }
                }
                (Mark::Points | Mark::LinePoints, _) => {
                    chart
                        .draw_series(
                            run.iter()
                                .map(|&k| Circle::new((s.x[k], s.y[k]), 4, rgb.filled())),
                        )
                        .map_err(draw_error)?;
                }
                _ => {}
            }
        }
    }
    if let Some(l) = legend {
        draw_legend(&l, &entries)?;
    }
    Ok(())
}

/// Draws a horizontal stacked bar chart on an axis up to 12.5 times the smallest total (1.25
/// times a cap at ten times it); longer bars are cut at the edge with their value written, so
/// the margin between the best rows stays visible.
fn draw_bars<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
    bars: &Bars,
) -> Result<(), PlotError> {
    let n = bars.rows.len().max(1);
    let totals: Vec<f64> = bars
        .rows
        .iter()
        .map(|r| r.first + r.second.max(0.0))
        .collect();
    let smallest = totals
        .iter()
        .copied()
        .filter(|t| t.is_finite())
        .fold(f64::INFINITY, f64::min);
    let largest = totals
        .iter()
        .copied()
        .filter(|t| t.is_finite())
        .fold(0.0, f64::max);
    let cap = if smallest.is_finite() && smallest > 0.0 {
        largest.min(10.0 * smallest)
    } else {
        largest
    };
    let xmax = if cap > 0.0 { cap * 1.25 } else { 1.0 };
    let labels: Vec<String> = bars
        .rows
        .iter()
        .map(|r| {
            if r.emphasised {
                format!("▶ {}", r.label)
            } else {
                r.label.clone()
            }
        })
        .collect();
    let label_w = labels
        .iter()
        .map(|l| text_width(area, l, TICK_SIZE))
        .max()
        .unwrap_or(40)
        + 20;
    let entries: Vec<(String, RGBColor, Mark)> = bars
        .segment_labels
        .iter()
        .enumerate()
        .map(|(k, l)| (l.clone(), colour(4 + k), Mark::Bar))
        .collect();
    let (w, _) = area.dim_in_pixel();
    let lw = legend_width(area, &entries);
    let (plot, legend) = area.split_horizontally(w - lw);
    let mut chart = ChartBuilder::on(&plot)
        .caption(&panel.title, (FONT, TITLE_SIZE))
        .margin(12)
        .x_label_area_size(52)
        .y_label_area_size(label_w.min(w / 2))
        .build_cartesian_2d(0.0..xmax, -0.6..n as f64 - 0.4)
        .map_err(draw_error)?;
    chart
        .configure_mesh()
        .x_desc(&panel.x_label)
        .y_labels(0)
        .x_label_formatter(&|v| number(*v))
        .label_style((FONT, TICK_SIZE))
        .axis_desc_style((FONT, LABEL_SIZE))
        .disable_y_mesh()
        .bold_line_style(RGBColor(200, 200, 200).stroke_width(1))
        .light_line_style(TRANSPARENT)
        .draw()
        .map_err(draw_error)?;
    // the rows' names, right-aligned against the axis, top to bottom
    let name_style =
        TextStyle::from((FONT, TICK_SIZE).into_font()).pos(Pos::new(HPos::Right, VPos::Center));
    chart
        .draw_series(labels.iter().enumerate().map(|(i, l)| {
            EmptyElement::at((0.0, (n - 1 - i) as f64))
                + Text::new(l.clone(), (-8, 0), name_style.clone())
        }))
        .map_err(draw_error)?;
    let value_style =
        TextStyle::from((FONT, TICK_SIZE).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    for (i, row) in bars.rows.iter().enumerate() {
        let y = (n - 1 - i) as f64;
        let (y0, y1) = (y - 0.32, y + 0.32);
        let first = row.first.clamp(0.0, xmax);
        let total = (row.first + row.second.max(0.0)).clamp(0.0, xmax);
        let alpha = if row.emphasised { 1.0 } else { 0.6 };
        chart
            .draw_series([
                Rectangle::new([(0.0, y0), (first, y1)], colour(4).mix(alpha).filled()),
                Rectangle::new([(first, y0), (total, y1)], colour(5).mix(alpha).filled()),
            ])
            .map_err(draw_error)?;
        let wic = row.first + row.second;
        let text = if row.first + row.second.max(0.0) > xmax {
            format!("→ {}", number(wic))
        } else {
            number(wic)
        };
        let at = (total.min(xmax * 0.82), y);
        chart
            .draw_series(std::iter::once(
                EmptyElement::at(at) + Text::new(text, (6, 0), value_style.clone()),
            ))
            .map_err(draw_error)?;
    }
    draw_legend(&legend, &entries)
}

/// Draws a whole figure: its panels on a grid of `rows` x `cols`, row-major.
pub(crate) fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    panels: &[Panel],
    (rows, cols): (usize, usize),
) -> Result<(), PlotError> {
    ensure_fonts();
    root.fill(&WHITE).map_err(draw_error)?;
    let areas = root.split_evenly((rows.max(1), cols.max(1)));
    for (panel, area) in panels.iter().zip(areas.iter()) {
        match &panel.kind {
            PanelKind::LogLog(series) => draw_loglog(area, panel, series)?,
            PanelKind::LinLog(series) => draw_linlog(area, panel, series)?,
            PanelKind::Bars(bars) => draw_bars(area, panel, bars)?,
        }
    }
    root.present().map_err(draw_error)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clip_polyline_stops_at_the_edge() {
        // from inside (y = 1) down to far below the range (y = 1e-6) over x = 1..100
        let runs = clip_polyline(&[1.0, 100.0], &[1.0, 1e-6], (1.0, 100.0), (1e-2, 10.0));
        assert_eq!(runs.len(), 1);
        let end = runs[0][1];
        assert!((end.1 / 1e-2 - 1.0).abs() < 1e-9, "{end:?}");
        // wholly below: nothing
        assert!(clip_polyline(&[1.0, 10.0], &[1e-9, 1e-8], (1.0, 10.0), (1e-2, 10.0)).is_empty());
        // a NaN splits
        let runs = clip_polyline(
            &[1.0, 2.0, 3.0, 4.0],
            &[1.0, f64::NAN, 1.0, 1.0],
            (1.0, 4.0),
            (0.1, 10.0),
        );
        assert_eq!(runs.len(), 1);
        assert_eq!(runs[0].len(), 2);
    }

    #[test]
    fn log_ticks_are_powers_of_ten_or_one_two_five() {
        let (bold, light) = log_ticks((0.5e-3, 2e2));
        assert_eq!(bold.len(), 6);
        assert!(light.contains(&2e-3));
        // two powers only: 1-3 multiples
        let (bold, _) = log_ticks((2e-4, 5e-2));
        assert_eq!(bold.len(), 5, "{bold:?}");
        // less than a decade: 1-2-5, or every multiple
        let (bold, _) = log_ticks((1.5, 9.0));
        assert_eq!(bold, vec![2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
        let (bold, _) = log_ticks((1.5, 12.0));
        assert_eq!(bold, vec![2.0, 5.0, 10.0]);
    }

    #[test]
    fn log_ticks_label_every_axis_at_least_three_times() {
        // ranges from a sliver to twelve decades, at any offset
        for lo_exp in [-40.0, -7.3, -3.01, 0.0, 0.49, 2.7] {
            for span in [0.05, 0.2, 0.45, 0.7, 0.99, 1.3, 1.9, 2.05, 3.5, 8.7, 12.0] {
                let (lo, hi) = padded((10f64.powf(lo_exp), 10f64.powf(lo_exp + span)));
                let (bold, light) = log_ticks((lo, hi));
                assert!(bold.len() >= MIN_LOG_LABELS, "{lo:e}..{hi:e}: {bold:?}");
                assert!(bold.iter().all(|v| *v >= lo * 0.999 && *v <= hi * 1.001));
                assert!(bold.windows(2).all(|w| w[0] < w[1]));
                assert!(light.iter().all(|l| !bold.contains(l)));
            }
        }
    }

    #[test]
    fn padded_opens_a_single_value() {
        let (lo, hi) = padded((1.0, 1.0));
        assert!(lo < 1.0 && hi > 1.0);
    }
}
