//! `gmwm monitor`: the robust-WV fault monitor (paper §IV-C, docs/methods.md §16) of a long
//! recording against the models of a calibration (`gmwm calibrate FILE --out-dir DIR` writes
//! `DIR/NAME.calibration.json`).

use super::Command;
use crate::config::Against;
use crate::config::MonitorConfig;
use crate::input::load;
use crate::prepare::Inputs;
use crate::render::Style;
use crate::style::OutputStyle;
use anyhow::{Context, Result};
use gmwm::{monitor_against, Model, MonitorReport, Reference, SignalUnit};
use serde::Serialize;
use std::io::Write;
use std::path::Path;

/// One axis of a calibration JSON.
struct CalibratedAxis {
    column: String,
    data_unit: Option<String>,
    unit: String,
    model: Model,
    /// Its empirical WV (`wv`), in `unit`.
    wv: Option<gmwm::WaveletVariance>,
    /// Its robust WV (`contamination.robust`), when the calibration computed one.
    robust_wv: Option<gmwm::WaveletVariance>,
    /// Its verdict's `explains_wv`.
    explains_wv: Option<bool>,
}

/// The rate and the per-axis models of a calibration JSON.
fn read_calibration(path: &std::path::Path) -> Result<(f64, Vec<CalibratedAxis>)> {
    let shown = path.display();
    let text = std::fs::read_to_string(path).with_context(|| format!("{shown}"))?;
    let doc: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("{shown}: not JSON (expected a gmwm calibration JSON)"))?;
    let freq = doc["freq_hz"].as_f64().with_context(|| {
        format!("{shown}: no freq_hz: not a calibration JSON of `gmwm calibrate`")
    })?;
    let axes = doc["axes"]
        .as_array()
        .with_context(|| format!("{shown}: no axes: not a calibration JSON of `gmwm calibrate`"))?;
    let mut out = Vec::with_capacity(axes.len());
    for a in axes {
        let column = a["column"]
            .as_str()
            .with_context(|| format!("{shown}: an axis without a column name"))?
            .to_string();
        let model_text = a["fit"]["model"]
            .as_str()
            .with_context(|| format!("{shown}: axis {column}: no fitted model (fit.model)"))?;
        let model = Model::parse(model_text)
            .with_context(|| format!("{shown}: axis {column}: fit.model {model_text:?}"))?;
        let wv_at = |value: &serde_json::Value, what: &str| -> Result<_> {
            match value {
                serde_json::Value::Null => Ok(None),
                w => Ok(Some(
                    serde_json::from_value::<gmwm::WaveletVariance>(w.clone()).with_context(
                        || format!("{shown}: axis {column}: {what} is not a wavelet variance"),
                    )?,
                )),
            }
        };
        let wv = wv_at(&a["wv"], "wv")?;
        let robust_wv = wv_at(&a["contamination"]["robust"], "contamination.robust")?;
        out.push(CalibratedAxis {
            column,
            data_unit: a["data_unit"].as_str().map(str::to_string),
            unit: a["unit"].as_str().unwrap_or_default().to_string(),
            model,
            wv,
            robust_wv,
            explains_wv: a["verdict"]["explains_wv"].as_bool(),
        });
    }
    Ok((freq, out))
}

/// One axis's monitor with the recording's time stamps of its events.
#[derive(Debug, Serialize)]
pub struct AxisMonitor {
    /// Column.
    pub column: String,
    /// Unit of the model and of the WVs.
    pub unit: String,
    /// The report.
    #[serde(flatten)]
    pub report: MonitorReport,
    /// Time-column stamps (s) of each event's first and last sample, when the file has a time
    /// column.
    pub event_stamps: Option<Vec<(f64, f64)>>,
}

impl Command for MonitorConfig {
    fn inputs(&mut self) -> Inputs<'_> {
        Inputs::Recording(&mut self.input)
    }

    fn outputs(&self) -> Vec<&Path> {
        Vec::new()
    }

    fn levels(&self) -> Option<usize> {
        // --levels: the largest level tested, not the WV's J
        None
    }

    fn run(&self, style: OutputStyle, mut out: &mut dyn Write) -> Result<()> {
        let axes = compute(self, style)?;
        render(&axes, self.output, &mut out)
    }
}

/// Checks the recording against the calibration (columns, rate, units) and monitors each axis.
pub fn compute(config: &MonitorConfig, style: OutputStyle) -> Result<Vec<AxisMonitor>> {
    let file = config.input.file.display().to_string();
    let cal_shown = config.calibration.display().to_string();
    let (cal_freq, cal_axes) = read_calibration(&config.calibration)?;
    let loaded = load(&config.input, style)?;
    let freq = loaded.freq_hz;
    anyhow::ensure!(
        ((freq - cal_freq) / cal_freq).abs() <= 1e-6,
        "{file}: sampled at {freq} Hz but {cal_shown} was calibrated at {cal_freq} Hz: the \
         model's scales would not match (give --freq if the file's rate is wrong)"
    );
    let infos = gmwm::SensorInfo::of_table(&loaded.table);
    let mut items = Vec::new();
    for (col, info) in loaded.table.columns.iter().zip(&infos) {
        let cal = cal_axes
            .iter()
            .find(|a| a.column == col.name)
            .with_context(|| {
                format!(
                "{file}: column {} is not in {cal_shown} (it has {}); choose --columns among them",
                col.name,
                cal_axes
                    .iter()
                    .map(|a| a.column.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            )
            })?;
        let file_unit = info.unit.as_deref();
        if let (Some(f), Some(c)) = (file_unit, cal.data_unit.as_deref()) {
            let same = match (f.parse::<SignalUnit>(), c.parse::<SignalUnit>()) {
                (Ok(a), Ok(b)) => a == b,
                _ => f == c,
            };
            anyhow::ensure!(
                same,
                "{file}: column {} is in {f} but {cal_shown} was calibrated on data in {c}",
                col.name
            );
        }
        // the calibration's model is in its `unit` (SI when the data unit is known): convert
        let factor = match cal.data_unit.as_deref().map(str::parse::<SignalUnit>) {
            Some(Ok(u)) if cal.unit != cal.data_unit.clone().unwrap_or_default() => u.to_si(),
            _ => 1.0,
        };
        let x: Vec<f64> = col.values.iter().map(|v| v * factor).collect();
        let mut opts = config.options;
        opts.window = config.window.samples(freq);
        opts.step = config.step.map(|s| s.samples(freq));
        if opts.window > x.len() {
            anyhow::bail!(
                "{file}: column {}: {} samples are too few for one window of {} samples \
                 (--window)",
                col.name,
                x.len(),
                opts.window
            );
        }
        let use_wv = match config.against {
            Against::Model => false,
            Against::Wv => true,
            Against::Auto => cal.explains_wv == Some(false) && cal.wv.is_some(),
        };
        let reference = match (use_wv, &cal.wv) {
            (false, _) => Reference::Model,
            (true, Some(w)) => Reference::Wv {
                classical: w,
                robust: cal.robust_wv.as_ref(),
            },
            (true, None) => anyhow::bail!(
                "{cal_shown}: axis {}: no empirical WV (wv) to monitor against: use --against model",
                col.name
            ),
        };
        let report = monitor_against(&x, freq, &cal.model, reference, &opts)
            .map_err(|e| anyhow::Error::new(e).context(format!("{file}: column {}", col.name)))?;
        let event_stamps = loaded.table.time.as_ref().map(|t| {
            let start = loaded
                .table
                .facts
                .timing
                .as_ref()
                .map_or(0.0, |timing| timing.start_s);
            report
                .events
                .iter()
                .map(|e| {
                    (
                        start + t.values[e.start],
                        start + t.values[(e.end - 1).min(t.values.len() - 1)],
                    )
                })
                .collect()
        });
        items.push(AxisMonitor {
            column: col.name.clone(),
            unit: cal.unit.clone(),
            report,
            event_stamps,
        });
    }
    Ok(items)
}

/// Table or JSON.
pub fn render(axes: &[AxisMonitor], style: Style, out: &mut impl Write) -> Result<()> {
    if style == Style::Json {
        serde_json::to_writer_pretty(&mut *out, axes)?;
        writeln!(out)?;
        return Ok(());
    }
    for a in axes {
        let r = &a.report;
        writeln!(
            out,
            "{}: {} windows of {} samples ({:.0} s) every {} samples, levels 1..{} (tau up to \
             {:.3} s), alpha {} per window ({:.2e} per level), model {}",
            a.column,
            r.windows.len(),
            r.window,
            r.window as f64 / r.freq_hz,
            r.step,
            r.tau_s.len(),
            r.tau_s.last().copied().unwrap_or(0.0),
            r.alpha,
            r.alpha_level,
            r.model
        )?;
        writeln!(
            out,
            "  against {}",
            match r.reference {
                "model" => "the model's WV",
                _ => "the calibration's empirical WV and its interval (--against model: the model's WV)",
            }
        )?;
        writeln!(
            out,
            "  flagged {} of {} windows (expected by chance: at most {:.1})",
            r.flagged,
            r.windows.len(),
            r.alpha * r.windows.len() as f64
        )?;
        for (k, e) in r.events.iter().enumerate() {
            let stamps = a
                .event_stamps
                .as_ref()
                .map(|s| format!(", stamps {:.3} .. {:.3}", s[k].0, s[k].1))
                .unwrap_or_default();
            let levels: Vec<String> = r
                .windows
                .iter()
                .filter(|w| w.flagged && w.start >= e.start && w.end <= e.end)
                .flat_map(|w| {
                    w.out
                        .iter()
                        .map(|o| format!("{}{}({})", o.level, &o.side[..1], o.estimator))
                })
                .collect::<std::collections::BTreeSet<_>>()
                .into_iter()
                .collect();
            writeln!(
                out,
                "  event {}: {:.1} s .. {:.1} s ({} windows{stamps}), levels out: {}",
                k + 1,
                e.start_s,
                e.end_s,
                e.windows,
                levels.join(" ")
            )?;
        }
    }
    Ok(())
}
