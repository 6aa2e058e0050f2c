//! `gmwm plan`: how long to record (docs/methods.md §18), from a model, a datasheet or a
//! calibration's identified models.

use super::Command;
use crate::args::PlanArgs;
use crate::error::UsageError;
use crate::prepare::Inputs;
use crate::style::OutputStyle;
use anyhow::{Context, Result};
use gmwm::{Model, Plan, SignalKind, PLAN_LENGTHS_S};
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};

/// One model to plan for, named.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanSubject {
    /// The axis or sensor it stands for.
    pub name: String,
    /// The unit of its values (`u` when unknown).
    pub unit: String,
    /// The model, every value given.
    pub model: Model,
    /// Its rate, Hz.
    pub freq_hz: f64,
    /// Where it comes from, in words.
    pub from: String,
}

/// `gmwm plan`, validated.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanConfig {
    /// The models.
    pub subjects: Vec<PlanSubject>,
    /// `--lengths`, s.
    pub lengths_s: Vec<f64>,
    /// `--target`: (quantity, relative half-width).
    pub targets: Vec<(String, f64)>,
    /// `--alpha`.
    pub alpha: f64,
    /// `--json`.
    pub json: bool,
    /// FILE, when given.
    pub file: Option<PathBuf>,
}

/// `30min`, `2h`, `1d`, `600` (s) in seconds.
fn length(text: &str) -> Result<f64> {
    let t = text.trim();
    let split = t.find(|c: char| c.is_ascii_alphabetic()).unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let factor = match unit.trim() {
        "" | "s" => 1.0,
        "min" | "m" => 60.0,
        "h" => 3600.0,
        "d" => 86400.0,
        _ => f64::NAN,
    };
    match number.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && factor.is_finite() => Ok(v * factor),
        _ => Err(UsageError(format!(
            "invalid --lengths item {t:?}: a length with s, min, h or d, e.g. 30min, 3h, 1d"
        ))
        .into()),
    }
}

/// `K=20%` or `K=0.2`.
fn target(text: &str) -> Result<(String, f64)> {
    let bad = || {
        UsageError(format!(
            "invalid --target item {text:?}: QUANTITY=PERCENT, e.g. K=20% (N, B, K, T1, ...)"
        ))
    };
    let (name, value) = text.split_once('=').ok_or_else(bad)?;
    let value = value.trim();
    let v = match value.strip_suffix('%') {
        Some(p) => p.trim().parse::<f64>().map(|x| x / 100.0),
        None => value.parse::<f64>(),
    }
    .map_err(|_| bad())?;
    if !(v.is_finite() && v > 0.0) {
        return Err(bad().into());
    }
    Ok((name.trim().to_string(), v))
}

/// Each axis of a calibration document: its identified model with its values.
fn subjects_of_calibration(path: &Path, columns: Option<&str>) -> Result<Vec<PlanSubject>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    let doc: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))?;
    let axes = doc["axes"].as_array().ok_or_else(|| {
        UsageError(format!(
            "{}: not a calibration (no axes[]; write one with gmwm calibrate --json)",
            path.display()
        ))
    })?;
    let wanted: Option<Vec<&str>> = columns.map(|c| c.split(',').map(str::trim).collect());
    let mut out = Vec::new();
    for (i, a) in axes.iter().enumerate() {
        let column = a["column"].as_str().unwrap_or("?").to_string();
        if wanted
            .as_ref()
            .is_some_and(|w| !w.contains(&column.as_str()))
        {
            continue;
        }
        let field = |what: &str| {
            UsageError(format!(
                "{}: axes[{i}] ({column}) has no {what}",
                path.display()
            ))
        };
        let text = a["fit"]["model"]
            .as_str()
            .ok_or_else(|| field("fit.model"))?;
        let freq_hz = a["fit"]["freq_hz"]
            .as_f64()
            .ok_or_else(|| field("fit.freq_hz"))?;
        let model: Model = text
            .parse()
            .with_context(|| format!("{}: axes[{i}] ({column}) fit.model", path.display()))?;
        out.push(PlanSubject {
            name: column,
            unit: a["unit"].as_str().unwrap_or("u").to_string(),
            model,
            freq_hz,
            from: format!("identified model of {}", path.display()),
        });
    }
    if out.is_empty() {
        return Err(UsageError(format!(
            "{}: no axis {}",
            path.display(),
            columns.unwrap_or("")
        ))
        .into());
    }
    Ok(out)
}

impl TryFrom<&PlanArgs> for PlanConfig {
    type Error = anyhow::Error;

    fn try_from(a: &PlanArgs) -> Result<Self> {
        let need_freq = || {
            a.freq.ok_or_else(|| {
                UsageError("--freq HZ: the sampling rate the model or datasheet is at".into())
            })
        };
        let subjects = match (&a.file, &a.model, &a.datasheet) {
            (Some(f), ..) => subjects_of_calibration(f, a.columns.as_deref())?,
            (None, Some(m), _) => vec![PlanSubject {
                name: "model".into(),
                unit: "u".into(),
                model: m.parse()?,
                freq_hz: need_freq()?,
                from: "--model".into(),
            }],
            (None, None, Some(d)) => {
                let f = need_freq()?;
                [SignalKind::Gyroscope, SignalKind::Accelerometer]
                    .into_iter()
                    .filter_map(|kind| {
                        d.model_for(kind, f).map(|(model, from)| PlanSubject {
                            name: match kind {
                                SignalKind::Gyroscope => "gyro".into(),
                                SignalKind::Accelerometer => "accel".into(),
                            },
                            unit: match kind {
                                SignalKind::Gyroscope => "rad/s".into(),
                                SignalKind::Accelerometer => "m/s^2".into(),
                            },
                            model,
                            freq_hz: f,
                            from,
                        })
                    })
                    .collect()
            }
            (None, None, None) => {
                return Err(UsageError(
                    "give a calibration FILE, --model or --datasheet (see gmwm plan --help)".into(),
                )
                .into())
            }
        };
        let lengths_s = match &a.lengths {
            Some(l) => l.split(',').map(length).collect::<Result<Vec<_>>>()?,
            None => PLAN_LENGTHS_S.to_vec(),
        };
        let targets = match &a.target {
            Some(t) => t.split(',').map(target).collect::<Result<Vec<_>>>()?,
            None => Vec::new(),
        };
        Ok(Self {
            subjects,
            lengths_s,
            targets,
            alpha: a.alpha,
            json: a.json,
            file: a.file.clone(),
        })
    }
}

/// One plan with its subject, as JSON.
#[derive(Serialize)]
struct Named<'a> {
    name: &'a str,
    unit: &'a str,
    from: &'a str,
    #[serde(flatten)]
    plan: &'a Plan,
}

/// `600` -> `10 min`, `86400` -> `1 d`.
fn human(s: f64) -> String {
    let (v, u) = if s >= 86400.0 {
        (s / 86400.0, "d")
    } else if s >= 3600.0 {
        (s / 3600.0, "h")
    } else if s >= 60.0 {
        (s / 60.0, "min")
    } else {
        (s, "s")
    };
    if (v - v.round()).abs() < 0.05 {
        format!("{v:.0} {u}")
    } else {
        format!("{v:.1} {u}")
    }
}

fn cell(w: Option<f64>) -> String {
    match w {
        None => "-".into(),
        Some(w) if w > 1.0 => "undet.".into(),
        Some(w) if w >= 0.1 => format!("±{:.0}%", 100.0 * w),
        Some(w) if w >= 0.01 => format!("±{:.1}%", 100.0 * w),
        Some(w) => format!("±{:.2}%", 100.0 * w),
    }
}

fn table(subject: &PlanSubject, plan: &Plan, out: &mut dyn Write) -> Result<()> {
    writeln!(
        out,
        "{} ({}): {} at {} Hz",
        subject.name, subject.from, plan.model, plan.freq_hz
    )?;
    write!(out, "  {:<6}{:>12}", "", "value")?;
    for l in &plan.lengths_s {
        write!(out, "{:>9}", human(*l))?;
    }
    writeln!(out)?;
    for q in &plan.quantities {
        let unit = q.unit.replace('u', &subject.unit);
        write!(out, "  {:<6}{:>12}", q.name, format!("{:.3e}", q.value))?;
        for w in &q.half_width {
            write!(out, "{:>9}", cell(*w))?;
        }
        writeln!(out, "   {unit}; {}", q.source)?;
    }
    for t in &plan.targets {
        match t.length_s {
            Some(l) => writeln!(
                out,
                "  target {} within ±{:.0}%: record at least {} ({:.0} s)",
                t.quantity,
                100.0 * t.half_width,
                human(l),
                l
            )?,
            None => writeln!(
                out,
                "  target {} within ±{:.0}%: not reached within 30 days",
                t.quantity,
                100.0 * t.half_width
            )?,
        }
    }
    for n in &plan.notes {
        writeln!(out, "  note: {n}")?;
    }
    writeln!(
        out,
        "  half-widths of {:.0}% intervals; 'undet.' beyond ±100% (the data cannot fix the value)",
        100.0 * (1.0 - plan.alpha)
    )?;
    Ok(())
}

impl Command for PlanConfig {
    fn inputs(&mut self) -> Inputs<'_> {
        Inputs::None
    }

    fn outputs(&self) -> Vec<&Path> {
        Vec::new()
    }

    fn levels(&self) -> Option<usize> {
        None
    }

    fn run(&self, _: OutputStyle, out: &mut dyn Write) -> Result<()> {
        let mut plans = Vec::new();
        for s in &self.subjects {
            let plan = Plan::new(
                &s.model,
                s.freq_hz,
                &self.lengths_s,
                self.alpha,
                &self.targets,
            )
            .with_context(|| format!("{}: {}", s.name, s.model))?;
            plans.push(plan);
        }
        if self.json {
            let named: Vec<Named<'_>> = self
                .subjects
                .iter()
                .zip(&plans)
                .map(|(s, plan)| Named {
                    name: &s.name,
                    unit: &s.unit,
                    from: &s.from,
                    plan,
                })
                .collect();
            serde_json::to_writer_pretty(&mut *out, &named)?;
            writeln!(out)?;
        } else {
            for (i, (s, p)) in self.subjects.iter().zip(&plans).enumerate() {
                if i > 0 {
                    writeln!(out)?;
                }
                table(s, p, out)?;
            }
        }
        Ok(())
    }
}
