//! `gmwm plan`: how long to record (docs/methods.md §18), from a model, a datasheet or a
//! calibration's identified models.

use super::Command;
use crate::config::{PlanConfig, PlanSubject};
use crate::prepare::Inputs;
use crate::style::OutputStyle;
use anyhow::{Context, Result};
use gmwm::Plan;
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};

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
        self.plot.iter().map(PathBuf::as_path).collect()
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
        if let Some(path) = &self.plot {
            let named: Vec<(&str, &Plan)> = self
                .subjects
                .iter()
                .map(|s| s.name.as_str())
                .zip(&plans)
                .collect();
            gmwm_plot::plan_figure(&named)
                .save(path)
                .with_context(|| path.display().to_string())?;
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
