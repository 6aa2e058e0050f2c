//! The PSD figure (one place per figure: its builder and what only it draws).

use super::*;

/// Horizontal axis of a PSD figure.
pub const PSD_FREQUENCY: &str = "frequency f (Hz)";

/// The amplitude spectral density of a column: `√PSD`, one-sided, in the data unit per √Hz.
fn asd(psd: &Psd) -> Vec<f64> {
    psd.density().iter().map(|d| d.sqrt()).collect()
}

/// The white-noise reference of a fitted density `n` (unit/√Hz): the one-sided `√PSD` of that
/// white noise is `√2 · N` (`σ² = N² f_s`, one-sided level `2 N²`), drawn flat over `f` and
/// labelled `label`.
fn white_noise_line(f: &[f64], n: f64, label: String, colour: usize) -> Option<Series> {
    let (lo, hi) = (f.first()?, f.last()?);
    let level = std::f64::consts::SQRT_2 * n;
    Some(
        Series::new(
            Mark::Line {
                width: 2,
                dashed: true,
            },
            &[*lo, *hi],
            &[level, level],
        )
        .coloured(colour)
        .clipped()
        .labelled(label),
    )
}

/// A white-noise density with its unit: `N = 0.04043 deg/s/√Hz`.
fn density_text(n: f64, unit: &str) -> String {
    format!(
        "N = {} {}",
        number(n),
        term_unit(NoiseTerm::NoiseDensity, unit)
    )
}

fn psd_y_label(unit: &str) -> String {
    format!(
        "√PSD, one-sided [{}]",
        term_unit(NoiseTerm::NoiseDensity, unit)
    )
}

/// Welch power spectral densities drawn as the one-sided amplitude spectral density `√PSD`
/// (data unit/√Hz, the unit of a datasheet's noise density) against frequency, one panel per
/// column (`Layout::Grid`) or one per sensor type with the axes overlaid; with a fitted
/// white-noise density `N` (the pair's second member), its level `√2·N` as a dashed line (`N`
/// in the panel's title, or the line's legend when axes are overlaid), so that vibration humps
/// above it and the sensor's filter roll-off below it read at a glance.
pub fn psd_figure(columns: &[Column<'_, (Psd, Option<f64>)>], layout: Layout) -> Figure {
    if columns.is_empty() {
        let empty = Panel {
            title: "no column".to_string(),
            x_label: PSD_FREQUENCY.to_string(),
            y_label: String::new(),
            kind: PanelKind::LogLog(Vec::new()),
        };
        return Figure::new(vec![empty], (1, 1), (500, 420));
    }
    let panel_of = |c: &Column<'_, (Psd, Option<f64>)>| {
        let (psd, n) = c.data;
        let f = psd.frequency_hz();
        let line = Series::new(
            Mark::Line {
                width: 2,
                dashed: false,
            },
            f,
            &asd(psd),
        );
        // a legend only beside a reference line (short: the panels of a grid are narrow;
        // the density's value is in the title)
        match n.and_then(|n| Some((n, white_noise_line(f, n, "√2·N".to_string(), 5)?))) {
            Some((n, reference)) => Panel {
                title: format!("{}: {}", c.name, density_text(n, c.unit)),
                x_label: PSD_FREQUENCY.to_string(),
                y_label: psd_y_label(c.unit),
                kind: PanelKind::LogLog(vec![line.labelled("√PSD"), reference]),
            },
            None => Panel {
                title: format!("{} (√PSD, Welch)", c.name),
                x_label: PSD_FREQUENCY.to_string(),
                y_label: psd_y_label(c.unit),
                kind: PanelKind::LogLog(vec![line]),
            },
        }
    };
    match layout {
        Layout::Grid => {
            let placed: Vec<usize> = columns.iter().map(|c| c.place().0).collect();
            let mut rows = placed.clone();
            rows.sort_unstable();
            rows.dedup();
            let cols = rows
                .iter()
                .map(|r| placed.iter().filter(|p| *p == r).count())
                .max()
                .unwrap_or(1);
            let mut panels = Vec::new();
            for r in &rows {
                let members: Vec<&Column<'_, _>> = columns
                    .iter()
                    .zip(&placed)
                    .filter(|(_, p)| *p == r)
                    .map(|(c, _)| c)
                    .collect();
                for k in 0..cols {
                    panels.push(match members.get(k) {
                        Some(c) => panel_of(c),
                        None => Panel {
                            title: String::new(),
                            x_label: String::new(),
                            y_label: String::new(),
                            kind: PanelKind::LogLog(Vec::new()),
                        },
                    });
                }
            }
            let size = (540 * cols as u32 + 80, 400 * rows.len() as u32 + 40);
            Figure::new(panels, (rows.len(), cols), size)
        }
        Layout::Overlay => {
            let mut panels = Vec::new();
            for (row, title) in SENSOR_TITLES.iter().enumerate() {
                let members: Vec<&Column<'_, _>> =
                    columns.iter().filter(|c| c.place().0 == row).collect();
                if members.is_empty() {
                    continue;
                }
                let mut series = Vec::new();
                for (k, c) in members.iter().enumerate() {
                    let (psd, n) = c.data;
                    let f = psd.frequency_hz();
                    series.push(
                        Series::new(
                            Mark::Line {
                                width: 2,
                                dashed: false,
                            },
                            f,
                            &asd(psd),
                        )
                        .coloured(k + 1)
                        .labelled(format!("axis {}", c.place().1)),
                    );
                    let axis = c.place().1;
                    series.extend(n.and_then(|n| {
                        let label = format!("{axis}: √2·N, {}", density_text(n, c.unit));
                        white_noise_line(f, n, label, k + 1)
                    }));
                }
                panels.push(Panel {
                    title: format!("{title} (√PSD, Welch)"),
                    x_label: PSD_FREQUENCY.to_string(),
                    y_label: psd_y_label(members[0].unit),
                    kind: PanelKind::LogLog(series),
                });
            }
            let n = panels.len().max(1);
            Figure::new(panels, (n, 1), (1000, 520 * n as u32))
        }
    }
}
