//! `gmwm simulate`: seeded simulation of a fully specified model, streamed to CSV on stdout or
//! to a file in the format of its name (CSV, TSV, gzip, raw f64/f32) with a sidecar.

use crate::config::SimulateConfig;
use anyhow::{Context, Result};
use gmwm::imu::write::{write_csv_header, write_csv_rows, write_sidecar};
use gmwm::imu::{SeriesWriter, Sidecar, SidecarColumn};
use gmwm::sim::Simulator;
use std::io::Write;

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

/// Runs the subcommand.
pub fn run(config: &SimulateConfig, stdout: &mut impl Write) -> Result<()> {
    let model = &config.model;
    let mut sim = Simulator::for_model(model, config.freq_hz, config.seed)?;
    let k = model.components().len();
    let mut names = vec!["x".to_string()];
    if config.components {
        names.extend(model.components().iter().map(|c| c.to_string()));
    }
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
