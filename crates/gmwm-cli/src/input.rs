//! Turning `InputArgs` into engine read options and loaded columns.

use crate::args::{FormatArg, HeaderArg, InputArgs};
use anyhow::{Context, Result};
use gmwm::imu::{read_table, ColumnSelector, HeaderMode, InputFormat, ReadOptions, Table};

/// A loaded input: the table and the sampling rate to use.
pub struct Loaded {
    /// Columns read.
    pub table: Table,
    /// Sampling rate in Hz.
    pub freq_hz: f64,
}

fn selector(text: &str) -> ColumnSelector {
    match text.trim().parse::<usize>() {
        Ok(i) => ColumnSelector::Index(i),
        Err(_) => ColumnSelector::Name(text.trim().to_string()),
    }
}

/// The engine's read options from the flags.
fn read_options(args: &InputArgs) -> ReadOptions {
    ReadOptions {
        format: match args.format {
            FormatArg::Auto => InputFormat::Auto,
            FormatArg::Csv => InputFormat::Csv,
            FormatArg::Tsv => InputFormat::Tsv,
            FormatArg::F64 => InputFormat::F64,
            FormatArg::F32 => InputFormat::F32,
        },
        header: match args.header {
            HeaderArg::Auto => HeaderMode::Auto,
            HeaderArg::Yes => HeaderMode::Present,
            HeaderArg::No => HeaderMode::Absent,
        },
        time_column: args.time_column.as_deref().map(selector),
        columns: args.columns.iter().map(|c| selector(c)).collect(),
        ncols: args.ncols,
        freq_hz: args.freq,
        time_unit: None,
    }
}

/// Reads the file named by `args`; the rate comes from `--freq`, else the file (time column or
/// sidecar), else 1 Hz with a warning on stderr (scales in seconds are then scales in samples).
pub fn load(args: &InputArgs) -> Result<Loaded> {
    if let Some(f) = args.freq {
        anyhow::ensure!(
            f.is_finite() && f > 0.0,
            "invalid --freq {f}: must be a positive number of hertz"
        );
    }
    if let Some(k) = args.ncols {
        anyhow::ensure!(
            k >= 1,
            "invalid --ncols 0: a binary file has at least one column"
        );
    }
    let opts = read_options(args);
    let table = read_table(&args.file, &opts)?;
    let freq_hz = match args.freq.or(table.freq_hz) {
        Some(f) => f,
        None => {
            eprintln!(
                "gmwm: warning: {}: no sampling rate (no --freq, time column or JSON sidecar); using 1 Hz, so tau_s is in samples",
                args.file.display()
            );
            1.0
        }
    };
    Ok(Loaded { table, freq_hz })
}

/// Adds "FILE: column NAME" to a per-column engine error.
pub fn column_context<T>(
    r: Result<T, gmwm::Error>,
    file: &std::path::Path,
    column: &str,
) -> Result<T> {
    r.with_context(|| format!("{}: column {column}", file.display()))
}

/// Runs a per-series computation over every loaded column in parallel (the engine's
/// `per_column`), naming any failure by file and column.
pub fn analyse_columns<T: Send>(
    loaded: &Loaded,
    file: &std::path::Path,
    f: impl Fn(&[f64]) -> Result<T, gmwm::Error> + Sync + Send,
) -> Result<Vec<(String, T)>> {
    let columns: Vec<&[f64]> = loaded
        .table
        .columns
        .iter()
        .map(|c| c.values.as_slice())
        .collect();
    let results = gmwm::variance::per_column(&columns, f);
    loaded
        .table
        .columns
        .iter()
        .zip(results)
        .map(|(col, r)| Ok((col.name.clone(), column_context(r, file, &col.name)?)))
        .collect()
}

/// Borrows `(name, result)` pairs as [`Named`](crate::render::Named) items.
pub fn named<T>(items: &[(String, T)]) -> Vec<crate::render::Named<'_, T>> {
    items
        .iter()
        .map(|(name, result)| crate::render::Named { name, result })
        .collect()
}

/// A recording loaded for calibration.
pub struct LoadedRecording {
    /// The file.
    pub path: std::path::PathBuf,
    /// Its axes.
    pub imu: gmwm::imu::Imu,
    /// The ROS topic read, if any.
    pub topic: Option<String>,
    /// What the reader noticed, one line each.
    pub notes: Vec<String>,
}

/// Opens the recording named by `args` as an IMU (the engine's `Recording`).
pub fn load_recording(args: &InputArgs) -> Result<LoadedRecording> {
    let opts = gmwm::imu::RecordingOptions {
        read: read_options(args),
        topic: None,
    };
    let rec = gmwm::imu::Recording::open(&args.file, &opts)?;
    Ok(LoadedRecording {
        path: rec.path,
        imu: rec.imu,
        topic: rec.topic,
        notes: rec.notes,
    })
}
