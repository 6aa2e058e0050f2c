//! Rendering results: human table (default), JSON (`--json`) and CSV (`--csv`).
//! Machine formats carry full precision and seconds; CSV and JSON come from the same fields.

use crate::args::OutputArgs;
use anyhow::Result;
use gmwm::{AllanVariance, WaveletVariance};
use serde::Serialize;
use std::io::Write;

/// Output style selected by the flags.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// Aligned human table.
    Table,
    /// JSON document.
    Json,
    /// CSV rows.
    Csv,
}

impl From<&OutputArgs> for Style {
    fn from(o: &OutputArgs) -> Self {
        if o.json {
            Style::Json
        } else if o.csv {
            Style::Csv
        } else {
            Style::Table
        }
    }
}

/// A result tagged with the series (column) it belongs to; JSON flattens the result into it.
#[derive(Debug, Serialize)]
pub struct Named<'a, T> {
    /// Series name.
    pub name: &'a str,
    /// The result.
    #[serde(flatten)]
    pub result: &'a T,
}

#[derive(Serialize)]
struct SeriesDoc<'a, T> {
    series: &'a [Named<'a, T>],
}

/// Writes wavelet variances.
pub fn wavelet_variances(
    out: &mut impl Write,
    items: &[Named<WaveletVariance>],
    style: Style,
) -> Result<()> {
    match style {
        Style::Json => json(out, items),
        Style::Table => {
            for (i, it) in items.iter().enumerate() {
                if i > 0 {
                    writeln!(out)?;
                }
                writeln!(out, "{}", it.name)?;
                write!(out, "{}", it.result)?;
            }
            Ok(())
        }
        Style::Csv => {
            writeln!(out, "series,level,tau,tau_s,wv,ci_low,ci_high")?;
            for it in items {
                let r = it.result;
                for j in 0..r.wv.len() {
                    writeln!(
                        out,
                        "{},{},{},{:e},{:e},{:e},{:e}",
                        csv_field(it.name),
                        j + 1,
                        r.tau[j],
                        r.tau_s[j],
                        r.wv[j],
                        r.ci_low[j],
                        r.ci_high[j]
                    )?;
                }
            }
            Ok(())
        }
    }
}

/// Writes Allan/Hadamard variances.
pub fn allan_variances(
    out: &mut impl Write,
    items: &[Named<AllanVariance>],
    style: Style,
) -> Result<()> {
    match style {
        Style::Json => json(out, items),
        Style::Table => {
            for (i, it) in items.iter().enumerate() {
                if i > 0 {
                    writeln!(out)?;
                }
                writeln!(out, "{}", it.name)?;
                write!(out, "{}", it.result)?;
            }
            Ok(())
        }
        Style::Csv => {
            writeln!(out, "series,tau,tau_s,avar,adev,ci_low,ci_high")?;
            for it in items {
                let r = it.result;
                for k in 0..r.avar.len() {
                    writeln!(
                        out,
                        "{},{},{:e},{:e},{:e},{:e},{:e}",
                        csv_field(it.name),
                        r.tau[k],
                        r.tau_s[k],
                        r.avar[k],
                        r.adev[k],
                        r.ci_low[k],
                        r.ci_high[k]
                    )?;
                }
            }
            Ok(())
        }
    }
}

fn json<T: Serialize>(out: &mut impl Write, items: &[Named<T>]) -> Result<()> {
    serde_json::to_writer_pretty(&mut *out, &SeriesDoc { series: items })?;
    writeln!(out)?;
    Ok(())
}

/// Quotes a CSV field when needed.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}
