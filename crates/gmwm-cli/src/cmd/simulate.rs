//! `gmwm simulate`: seeded simulation of a fully specified model, streamed to CSV on stdout or
//! to a file in the format of its name (CSV, TSV, gzip, raw f64/f32) with a sidecar.

use super::Command;
use crate::config::SimulateConfig;
use crate::prepare::Inputs;
use crate::style::OutputStyle;
use anyhow::{Context, Result};
use gmwm::{
    write_csv_header, write_csv_rows, write_sidecar, OutputFormat, SeriesWriter, Sidecar,
    SidecarColumn, Simulator,
};
use std::io::Write;
use std::path::Path;

/// Samples simulated and written per step: bounded memory for any N.
const CHUNK: usize = 1 << 16;

/// Where the rows go.
enum Sink<'a> {
    Stdout(&'a mut dyn Write),
    File(Box<SeriesWriter>),
}

impl Sink<'_> {
    fn write(&mut self, columns: &[&[f64]]) -> Result<()> {
        match self {
            Self::Stdout(out) => write_csv_rows(*out, columns)?,
            Self::File(w) => w.write_rows(columns)?,
        }
        Ok(())
    }
}

/// Samples above which `--yes` is needed.
pub const CONFIRM_SAMPLES: usize = 1_000_000_000;

/// Bytes per value written as text (`-0.7416573867739413,`: the shortest round-trip form of a
/// double is up to about 20 characters).
const TEXT_BYTES: u64 = 20;

/// About how many bytes `n` rows of `ncols` values take in the output's format (text
/// uncompressed).
fn estimated_bytes(config: &SimulateConfig, ncols: usize) -> u64 {
    let per_value = match config.output.as_deref().map(OutputFormat::from_path) {
        Some(Ok(OutputFormat::F64)) => 8,
        Some(Ok(OutputFormat::F32)) => 4,
        _ => TEXT_BYTES,
    };
    (config.n as u64)
        .saturating_mul(ncols as u64)
        .saturating_mul(per_value)
}

/// A size with its unit (`1.2 GB`, decimal units).
fn bytes(b: u64) -> String {
    let units = ["bytes", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut v = b as f64;
    let mut k = 0;
    while v >= 1000.0 && k + 1 < units.len() {
        v /= 1000.0;
        k += 1;
    }
    if k == 0 {
        format!("{b} bytes")
    } else {
        format!("{v:.1} {}", units[k])
    }
}

/// Free bytes for an unprivileged writer on the file system that will hold `path`.
#[cfg(unix)]
fn free_space(path: &Path) -> Option<u64> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let s = rustix::fs::statvfs(dir).ok()?;
    Some(s.f_bavail.saturating_mul(s.f_frsize))
}

#[cfg(not(unix))]
fn free_space(_: &Path) -> Option<u64> {
    None
}

/// Refuses, without `--yes`, more than [`CONFIRM_SAMPLES`] samples, or a file larger than the
/// free space of its file system: one line with the size it would write and the flag.
fn check_size(config: &SimulateConfig, ncols: usize) -> Result<()> {
    size_check(config, ncols, config.output.as_deref().and_then(free_space))
}

/// [`check_size`] with the free bytes of the output's file system given.
fn size_check(config: &SimulateConfig, ncols: usize, free: Option<u64>) -> Result<()> {
    if config.yes {
        return Ok(());
    }
    let size = estimated_bytes(config, ncols);
    let gz = config.output.as_deref().is_some_and(|p| {
        matches!(
            OutputFormat::from_path(p),
            Ok(OutputFormat::Text { gzip: true, .. })
        )
    });
    let target = match &config.output {
        Some(p) => p.display().to_string(),
        None => "standard output".to_string(),
    };
    let what = format!(
        "about {}{} ({} samples x {ncols} column{})",
        bytes(size),
        if gz { " before compression" } else { "" },
        config.n,
        if ncols == 1 { "" } else { "s" }
    );
    if config.n > CONFIRM_SAMPLES {
        return Err(crate::error::UsageError(format!(
            "--n {}: gmwm simulate would write {what} to {target}, more than {CONFIRM_SAMPLES} \
             samples; give --yes to write it",
            config.n
        ))
        .into());
    }
    if let Some(p) = &config.output {
        if let Some(free) = free {
            if size > free && !gz {
                return Err(crate::error::UsageError(format!(
                    "{}: gmwm simulate would write {what}, and its file system has {} free; \
                     give --yes to write it anyway",
                    p.display(),
                    bytes(free)
                ))
                .into());
            }
        }
    }
    Ok(())
}

/// Runs the subcommand.
pub fn run(config: &SimulateConfig, stdout: &mut impl Write) -> Result<()> {
    let model = &config.model;
    let mut sim = Simulator::for_model(model, config.freq_hz, config.seed)?;
    let k = model.components().len();
    let mut names = vec!["x".to_string()];
    if config.components {
        names.extend(model.components().iter().map(|c| c.to_string()));
    }
    check_size(config, names.len())?;
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    // Create the file first so a bad path or an unknown extension fails before any work.
    let mut sink = match &config.output {
        Some(p) => Sink::File(Box::new(
            SeriesWriter::create(p, &refs)
                .with_context(|| "cannot create the output file".to_string())?,
        )),
        None => {
            let quoted: Vec<String> = names.iter().map(|n| csv_quote(n)).collect();
            let refs: Vec<&str> = quoted.iter().map(String::as_str).collect();
            write_csv_header(stdout, &refs)?;
            Sink::Stdout(stdout)
        }
    };
    let mut parts: Vec<Vec<f64>> = vec![Vec::new(); k];
    let mut total = Vec::new();
    let mut left = config.n;
    while left > 0 {
        let len = left.min(CHUNK);
        total.resize(len, 0.0);
        if config.components {
            for p in parts.iter_mut() {
                p.resize(len, 0.0);
            }
            sim.fill_components(&mut parts)?;
            for (t, v) in total.iter_mut().enumerate() {
                *v = parts.iter().map(|p| p[t]).sum();
            }
            let mut cols: Vec<&[f64]> = vec![&total];
            cols.extend(parts.iter().map(Vec::as_slice));
            sink.write(&cols)?;
        } else {
            sim.fill(&mut total);
            sink.write(&[&total])?;
        }
        left -= len;
    }
    match sink {
        Sink::Stdout(out) => out.flush()?,
        Sink::File(w) => {
            let format = w.format();
            w.finish()?;
            let path = config.output.as_deref().unwrap_or(std::path::Path::new(""));
            let sidecar = Sidecar {
                name: path.file_name().map(|f| f.to_string_lossy().into_owned()),
                sensor: Some(format!(
                    "simulated by gmwm: {} (seed {})",
                    model, config.seed
                )),
                sampling_frequency_hz: Some(config.freq_hz),
                format: Some(format.sidecar_name().to_string()),
                n_columns: Some(names.len()),
                n_rows: Some(config.n as u64),
                columns: names
                    .iter()
                    .map(|n| SidecarColumn {
                        name: n.clone(),
                        meaning: None,
                        unit: None,
                    })
                    .collect(),
                ..Sidecar::default()
            };
            write_sidecar(path, &sidecar)?;
        }
    }
    Ok(())
}

fn csv_quote(s: &str) -> String {
    if s.contains([',', '"']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

impl Command for SimulateConfig {
    fn inputs(&mut self) -> Inputs<'_> {
        Inputs::None
    }

    fn outputs(&self) -> Vec<&Path> {
        // -o: refused by the writer when it cannot be created, naming it (as before)
        Vec::new()
    }

    fn levels(&self) -> Option<usize> {
        None
    }

    fn run(&self, _: OutputStyle, mut out: &mut dyn Write) -> Result<()> {
        run(self, &mut out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config(n: usize, output: Option<&str>, yes: bool) -> SimulateConfig {
        SimulateConfig {
            model: "WN(sigma2=1)".parse().unwrap(),
            n,
            freq_hz: 1.0,
            seed: 0,
            output: output.map(Into::into),
            components: false,
            yes,
        }
    }

    #[test]
    fn a_file_larger_than_the_free_space_needs_yes() {
        // 1e8 f64 samples: 800 MB, on a file system with 100 MB free
        let c = config(100_000_000, Some("big.f64"), false);
        let e = size_check(&c, 1, Some(100_000_000))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("big.f64") && e.contains("800.0 MB") && e.contains("100.0 MB free"),
            "{e}"
        );
        assert!(e.contains("--yes"), "{e}");
        assert!(size_check(&config(100_000_000, Some("big.f64"), true), 1, Some(1)).is_ok());
        assert!(size_check(&c, 1, Some(1_000_000_000)).is_ok());
        // text: about 20 bytes a value
        let csv = config(1000, Some("x.csv"), false);
        let e = size_check(&csv, 2, Some(10_000)).unwrap_err().to_string();
        assert!(e.contains("40.0 kB") && e.contains("2 columns"), "{e}");
    }

    #[test]
    fn more_than_a_billion_samples_need_yes_wherever_they_go() {
        let e = size_check(&config(CONFIRM_SAMPLES + 1, None, false), 1, None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("standard output") && e.contains("--yes"), "{e}");
        assert!(size_check(&config(CONFIRM_SAMPLES, None, false), 1, None).is_ok());
        assert!(size_check(&config(CONFIRM_SAMPLES + 1, None, true), 1, None).is_ok());
    }
}
