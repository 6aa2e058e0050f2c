//! Rendering results: human table (default), JSON (`--json`) and CSV (`--csv`).
//! Machine formats carry full precision and seconds; CSV and JSON come from the same fields.

use anyhow::Result;
use gmwm::{AllanVariance, WaveletVariance};
use serde::Serialize;
use std::io::Write;

/// Output style selected by the flags (`--json`, `--csv`; see [`crate::config::OutputConfig`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// Aligned human table.
    Table,
    /// JSON document.
    Json,
    /// CSV rows.
    Csv,
}

/// A result tagged with the series (column) it belongs to.
#[derive(Debug)]
pub struct Named<'a, T> {
    /// Series name.
    pub name: &'a str,
    /// The result.
    pub result: &'a T,
}

/// A result with a CSV form: one header, then one row per scale.
pub trait CsvRows {
    /// Header line (without the newline), first column `series`.
    fn header(&self) -> String;
    /// Writes the rows of the series `name`.
    fn write_rows(&self, name: &str, out: &mut dyn Write) -> std::io::Result<()>;
}

impl CsvRows for WaveletVariance {
    fn header(&self) -> String {
        "series,level,tau,tau_s,wv,ci_low,ci_high".to_string()
    }
    fn write_rows(&self, name: &str, out: &mut dyn Write) -> std::io::Result<()> {
        for j in 0..self.wv().len() {
            writeln!(
                out,
                "{},{},{},{:e},{:e},{:e},{:e}",
                csv_field(name),
                j + 1,
                self.tau()[j],
                self.tau_s()[j],
                self.wv()[j],
                self.ci_low()[j],
                self.ci_high()[j]
            )?;
        }
        Ok(())
    }
}

impl CsvRows for AllanVariance {
    /// The variance's own names: `avar,adev`, `mavar,mdev` or `hvar,hdev`
    /// ([`gmwm::AllanKind::columns`]).
    fn header(&self) -> String {
        let (var, dev) = self.kind().columns();
        format!("series,tau,tau_s,{var},{dev},ci_low,ci_high,{dev}_ci_low,{dev}_ci_high")
    }
    fn write_rows(&self, name: &str, out: &mut dyn Write) -> std::io::Result<()> {
        for k in 0..self.avar().len() {
            writeln!(
                out,
                "{},{},{:e},{:e},{:e},{:e},{:e},{:e},{:e}",
                csv_field(name),
                self.tau()[k],
                self.tau_s()[k],
                self.avar()[k],
                self.adev()[k],
                self.ci_low()[k],
                self.ci_high()[k],
                self.ci_low()[k].sqrt(),
                self.ci_high()[k].sqrt()
            )?;
        }
        Ok(())
    }
}

/// Writes per-series results as a table (their `Display`), JSON (`{"series": [...]}`) or CSV.
pub fn series<T: Serialize + std::fmt::Display + CsvRows>(
    out: &mut impl Write,
    items: &[Named<T>],
    style: Style,
) -> Result<()> {
    match style {
        Style::Json => json(out, items)?,
        Style::Table => {
            for (i, it) in items.iter().enumerate() {
                if i > 0 {
                    writeln!(out)?;
                }
                writeln!(out, "{}", it.name)?;
                write!(out, "{}", it.result)?;
            }
        }
        Style::Csv => {
            // one kind per command: the first result's header is every result's
            if let Some(first) = items.first() {
                writeln!(out, "{}", first.result.header())?;
            }
            for it in items {
                it.result.write_rows(it.name, out)?;
            }
        }
    }
    Ok(())
}

fn json<T: Serialize>(out: &mut impl Write, items: &[Named<T>]) -> Result<()> {
    let pairs: Vec<(String, &T)> = items
        .iter()
        .map(|it| (it.name.to_string(), it.result))
        .collect();
    serde_json::to_writer_pretty(&mut *out, &gmwm::document::series(&pairs))?;
    writeln!(out)?;
    Ok(())
}

/// Writes `fig` to `path` (SVG or PNG by the name); a drawing error names the file (a write
/// error names it already).
pub fn save_figure(fig: &gmwm_plot::Figure, path: &std::path::Path) -> Result<()> {
    fig.save(path).map_err(|e| match e {
        gmwm_plot::PlotError::Io { .. } => anyhow::Error::from(e),
        other => anyhow::anyhow!("{}: {other}", path.display()),
    })
}

/// The unit a figure labels a column with: the sensor unit a sidecar's text names
/// (`deg/s (inferred ...)` -> `deg/s`), else `u`.
pub fn figure_unit(unit: Option<&str>) -> String {
    unit.and_then(|u| u.parse::<gmwm::SignalUnit>().ok())
        .map_or_else(|| "u".to_string(), |u| u.symbol().to_string())
}

/// Quotes a CSV field when needed.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}
