//! `gmwm monitor`: the robust-WV fault monitor (paper §IV-C, docs/methods.md §16) of a long
//! recording against the models of a calibration (`gmwm calibrate FILE --out-dir DIR` writes
//! `DIR/NAME.calibration.json`).

use crate::args::{InputArgs, OutputArgs};
use crate::config::OutputConfig;
use crate::input::load;
use crate::input::InputConfig;
use crate::render::Style;
use anyhow::{Context, Result};
use clap::Args;
use gmwm::model::Model;
use gmwm::monitor::{monitor_against, MonitorOptions, MonitorReport, Reference};
use gmwm::units::SignalUnit;
use serde::Serialize;
use std::io::Write;
use std::path::PathBuf;

/// `gmwm monitor --help` examples.
pub const EXAMPLES: &str = "Each window's robust WV (docs/methods.md §2) is compared with the band the calibrated \
model predicts for a window of that length (chi-square with the model's equivalent degrees of \
freedom, Bonferroni over the levels); a window outside at some level is flagged. About --alpha \
of the windows of a recording that follows the model are flagged by chance. Where the \
calibration's verdict says the model misfits its WV, the windows are compared with that \
empirical WV and its uncertainty instead (--against auto, the default; docs/methods/multi-axis.md \
§16.6): a misfit of a few percent would otherwise flag nearly every long window.\n\n\
Examples:\n  gmwm calibrate imu.csv.gz --out-dir cal && gmwm monitor imu.csv.gz --model-from cal/imu.calibration.json\n  \
gmwm monitor long.csv.gz --model-from cal/imu.calibration.json --columns gyro_x --window 600s --step 60s\n  \
gmwm monitor long.csv.gz --model-from cal/imu.calibration.json --window 65536 --json";

/// `gmwm monitor` flags.
#[derive(Debug, Args)]
pub struct MonitorArgs {
    /// Input.
    #[command(flatten)]
    pub input: InputArgs,
    /// The calibration JSON (`gmwm calibrate FILE --out-dir DIR` writes DIR/NAME.calibration.json):
    /// per axis the model and its estimates.
    #[arg(long = "model-from", value_name = "CALIB_JSON")]
    pub model_from: PathBuf,
    /// Window length: samples (65536) or a duration with a unit (600s, 10min, 2h).
    #[arg(long, default_value = "65536")]
    pub window: String,
    /// Step between windows: samples or a duration [default: half a window].
    #[arg(long)]
    pub step: Option<String>,
    /// Probability that a window of a recording following the model is flagged, in (0, 0.5].
    #[arg(long, default_value_t = 0.01)]
    pub alpha: f64,
    /// Efficiency of the robust WV, in (0, 0.99].
    #[arg(long, default_value_t = 0.6)]
    pub eff: f64,
    /// Largest level tested [default: every level with M_j / 2^j >= 8].
    #[arg(long, value_name = "J")]
    pub levels: Option<usize>,
    /// What each window is compared with: the calibrated model's WV (model), the calibration's
    /// empirical WV with its uncertainty (wv), or the model where the calibration's verdict says it
    /// explains the WV and the empirical WV where it misfits (auto; docs/methods/multi-axis.md
    /// §16.6).
    #[arg(long, value_enum, default_value_t = Against::Auto)]
    pub against: Against,
    /// Output format.
    #[command(flatten)]
    pub output: OutputArgs,
}

/// `--against`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Against {
    /// The model where it explains the calibration's WV, else that WV.
    Auto,
    /// The calibrated model's implied WV.
    Model,
    /// The calibration's empirical WV.
    Wv,
}

/// A length given as samples or as a duration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Span {
    /// Samples.
    Samples(usize),
    /// Seconds.
    Seconds(f64),
}

impl Span {
    fn parse(flag: &str, text: &str) -> Result<Self> {
        let t = text.trim();
        if let Ok(n) = t.parse::<usize>() {
            anyhow::ensure!(n >= 1, "invalid {flag} {text}: at least 1 sample");
            return Ok(Span::Samples(n));
        }
        let (num, unit) = t
            .find(|c: char| c.is_ascii_alphabetic())
            .map(|i| t.split_at(i))
            .unwrap_or((t, ""));
        let factor = match unit {
            "s" => 1.0,
            "min" => 60.0,
            "h" => 3600.0,
            _ => anyhow::bail!(
                "invalid {flag} {text}: give samples (65536) or a duration in s, min or h (600s)"
            ),
        };
        let v: f64 = num
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite() && *v > 0.0)
            .with_context(|| format!("invalid {flag} {text}: not a positive duration"))?;
        Ok(Span::Seconds(v * factor))
    }

    fn samples(self, freq_hz: f64) -> usize {
        match self {
            Span::Samples(n) => n,
            Span::Seconds(s) => (s * freq_hz).round() as usize,
        }
    }
}

/// Validated `gmwm monitor`.
#[derive(Debug, Clone)]
pub struct MonitorConfig {
    /// The recording.
    pub input: InputConfig,
    /// `--model-from`.
    pub calibration: PathBuf,
    /// `--window`.
    pub window: Span,
    /// `--step`.
    pub step: Option<Span>,
    /// Engine settings (window and step filled in once the rate is known).
    pub options: MonitorOptions,
    /// `--against`.
    pub against: Against,
    /// Table or JSON.
    pub output: OutputConfig,
}

impl TryFrom<&MonitorArgs> for MonitorConfig {
    type Error = anyhow::Error;

    fn try_from(a: &MonitorArgs) -> Result<Self> {
        if let Some(why) = gmwm::variance::ci::significance_level_problem(a.alpha) {
            anyhow::bail!("invalid --alpha {}: {why}", a.alpha);
        }
        let robust = gmwm::RobustOptions::new(a.eff, gmwm::RobustConvention::Exact)
            .map_err(|e| anyhow::anyhow!("invalid --eff {}: {e}", a.eff))?;
        if a.levels == Some(0) {
            anyhow::bail!("invalid --levels 0: at least one level");
        }
        Ok(Self {
            input: InputConfig::try_from(&a.input)?,
            calibration: a.model_from.clone(),
            window: Span::parse("--window", &a.window)?,
            step: a
                .step
                .as_deref()
                .map(|s| Span::parse("--step", s))
                .transpose()?,
            options: MonitorOptions {
                alpha: a.alpha,
                robust,
                levels: a.levels,
                ..MonitorOptions::default()
            },
            against: a.against,
            output: OutputConfig::from(&a.output),
        })
    }
}

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

/// Runs the subcommand.
pub fn run(config: &MonitorConfig, out: &mut impl Write) -> Result<()> {
    let axes = compute(config)?;
    render(&axes, config.output, out)
}

/// Checks the recording against the calibration (columns, rate, units) and monitors each axis.
pub fn compute(config: &MonitorConfig) -> Result<Vec<AxisMonitor>> {
    let file = config.input.file.display().to_string();
    let cal_shown = config.calibration.display().to_string();
    let (cal_freq, cal_axes) = read_calibration(&config.calibration)?;
    let loaded = load(&config.input)?;
    let freq = loaded.freq_hz;
    anyhow::ensure!(
        ((freq - cal_freq) / cal_freq).abs() <= 1e-6,
        "{file}: sampled at {freq} Hz but {cal_shown} was calibrated at {cal_freq} Hz: the \
         model's scales would not match (give --freq if the file's rate is wrong)"
    );
    let infos = gmwm::imu::SensorInfo::of_table(&loaded.table);
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
