//! What to read ([`InputConfig`]) and reading it into loaded columns, printing what the reader
//! found (time column, skipped columns, warnings) once per file on stderr.

use crate::style::OutputStyle;
use anyhow::{Context, Result};
use gmwm::{
    is_wv_json, quote, read_table, read_wv_json, select_series, InputFormat, ReadWarning, Table,
    WaveletVariance,
};
use std::path::{Path, PathBuf};

/// Where the data come from and how to read them: FILE and the engine's read options
/// (`--columns`, `--freq`, `--format`, `--ncols`, `--header`, `--time-column`, `--time-unit`),
/// and the ROS topic (`--topic`).
#[derive(Debug, Clone, PartialEq)]
pub struct InputConfig {
    /// The data file (or rosbag2 folder).
    pub file: PathBuf,
    /// The engine's read options; `read.freq_hz` is `--freq`, `read.columns` is `--columns`.
    pub read: gmwm::ReadOptions,
    /// `--topic`: the IMU topic of a ROS recording.
    pub topic: Option<String>,
    /// `--stream-from`: rows from which a text or IMU-record recording is streamed
    /// ([`gmwm::STREAM_FROM`] by default).
    pub stream_from: u64,
    /// `--gaps`: how gaps in the time stamps enter the WV.
    pub gaps: gmwm::GapPolicy,
    /// What FILE is, probed once ([`InputConfig::probe`]).
    pub probe: std::sync::OnceLock<gmwm::Probe>,
}

impl InputConfig {
    /// What FILE is ([`gmwm::Probe`]: a ROS container, a folder, a file), probed the
    /// first time it is asked and kept: every reader and the calibration's choice between
    /// memory and streaming take it from here.
    pub fn probe(&self) -> &gmwm::Probe {
        self.probe
            .get_or_init(|| gmwm::Probe::of(&self.file, &self.read))
    }

    /// The same reading of another FILE (its own probe).
    pub fn with_file(&self, file: &Path) -> InputConfig {
        InputConfig {
            file: file.to_path_buf(),
            probe: std::sync::OnceLock::new(),
            ..self.clone()
        }
    }

    /// Puts `file` in place of FILE (a stream's copy), to be probed afresh.
    pub fn set_file(&mut self, file: PathBuf) {
        self.file = file;
        self.probe = std::sync::OnceLock::new();
    }
}

/// A path as the user named it (`<stdin>` for the copy of standard input, [`crate::spool`]).
pub fn shown_path(path: &Path) -> std::path::PathBuf {
    crate::spool::shown(&path.display().to_string()).into()
}

/// A loaded input: the table and the sampling rate to use.
pub struct Loaded {
    /// Columns read.
    pub table: Table,
    /// Sampling rate in Hz.
    pub freq_hz: f64,
}

/// Whether FILE is a wavelet variance saved by `gmwm wv --json` (by name or content) rather
/// than a recording; never with an explicit recording `--format`.
pub fn is_wv(input: &InputConfig) -> bool {
    input.read.format == InputFormat::Auto && is_wv_json(&input.file)
}

/// A rate for messages: 6 significant digits, trailing zeros dropped (`200`, `62.5`).
fn hz(x: f64) -> String {
    let s = format!(
        "{:.*}",
        5usize.saturating_sub(x.abs().log10().floor().max(0.0) as usize),
        x
    );
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Notes the columns a reader left out (none: nothing).
pub fn note_not_analysed(style: OutputStyle, file: &Path, skipped: &[String]) {
    if !skipped.is_empty() {
        let names: Vec<String> = skipped.iter().map(|n| quote(n)).collect();
        style.note(
            file,
            &format!(
                "not analysed: {} (not a gyroscope or accelerometer axis, or another time \
                 column; --columns selects any column)",
                names.join(", ")
            ),
        );
    }
}

/// Prints what the reader found: the time column and its rate, the columns left out, then
/// every warning, each once.
fn report(style: OutputStyle, table: &Table) {
    report_parts(
        style,
        &table.facts.path,
        table.facts.timing.as_ref(),
        &table.facts.skipped,
        &table.facts.samples,
        &table.facts.warnings,
    );
}

/// [`report`] of a table's parts (a streamed table's too).
pub(crate) fn report_parts(
    style: OutputStyle,
    file: &std::path::Path,
    timing: Option<&gmwm::TimingReport>,
    skipped: &[String],
    samples: &gmwm::SampleAccount,
    warnings: &[ReadWarning],
) {
    if let Some(t) = timing {
        style.note(file, &t.to_string());
    }
    note_not_analysed(style, file, skipped);
    style.note(file, &samples.to_string());
    for w in warnings {
        match w {
            ReadWarning::FreqDisagrees {
                given_hz,
                column,
                time_hz,
                ..
            } => eprintln!(
                "gmwm: warning: {}: --freq {} Hz differs by {:.0}% from time column \"{}\" \
                 ({} Hz); --freq is used",
                crate::spool::shown(&file.display().to_string()),
                hz(*given_hz),
                100.0 * (given_hz - time_hz).abs() / time_hz,
                quote(column),
                hz(*time_hz),
            ),
            w => warn_all(std::slice::from_ref(w)),
        }
    }
}

/// Prints each reader warning on stderr (shown with `--quiet` too).
pub(crate) fn warn_all(warnings: &[ReadWarning]) {
    for w in warnings {
        eprintln!("gmwm: warning: {}", crate::spool::shown(&w.to_string()));
    }
}

/// Reads the file named by `input`; the rate comes from `--freq`, else the file (time column
/// or sidecar), else 1 Hz with a warning on stderr (scales in seconds are then scales in
/// samples). The reader's notes (as `style` says) and warnings are printed on stderr.
pub fn load(input: &InputConfig, style: OutputStyle) -> Result<Loaded> {
    if input.probe().is_ros() {
        return load_ros(input, style);
    }
    if let Some(topic) = &input.topic {
        return Err(crate::error::UsageError(format!(
            "invalid --topic {topic}: {} is not a ROS recording (ROS1 bag, MCAP, rosbag2 sqlite3)",
            input.file.display()
        ))
        .into());
    }
    let table = read_table(&input.file, &input.read)?;
    report(style, &table);
    let freq_hz = match input.read.freq_hz.or(table.facts.freq_hz) {
        Some(f) => f,
        None if crate::spool::is_stdin(&input.file) => {
            return Err(crate::error::UsageError(format!(
                "{}: no sampling rate: standard input has no JSON sidecar and no time column \
                 was found; give --freq",
                crate::spool::STDIN
            ))
            .into())
        }
        None => {
            eprintln!(
                "gmwm: warning: {}: no sampling rate (no --freq, time column or JSON sidecar); using 1 Hz, so tau_s is in samples",
                crate::spool::shown(&input.file.display().to_string())
            );
            1.0
        }
    };
    Ok(Loaded { table, freq_hz })
}

/// Reads a saved wavelet variance: the series `--columns` selects (names or 1-based indices),
/// the rate from `--freq` or the file, the first `levels` levels.
pub fn load_wv(
    input: &InputConfig,
    levels: Option<usize>,
) -> Result<Vec<(String, WaveletVariance)>> {
    let file = &input.file;
    let series = select_series(
        file,
        read_wv_json(file, input.read.freq_hz)?,
        &input.read.columns,
    )?;
    let Some(j) = levels else {
        return Ok(series);
    };
    series
        .into_iter()
        .map(|(name, wv)| {
            let total = wv.levels();
            let cut = wv.truncated(j).map_err(|_| {
                anyhow::anyhow!(
                    "{}: series {}: --levels {j} is outside 1..={total}",
                    file.display(),
                    quote(&name)
                )
            })?;
            Ok((name, cut))
        })
        .collect()
}

/// Adds "FILE: column NAME" to a per-column engine error (the name cut to 40 characters).
pub fn column_context<T>(
    r: Result<T, gmwm::Error>,
    file: &std::path::Path,
    column: &str,
) -> Result<T> {
    r.with_context(|| format!("{}: column {}", file.display(), quote(column)))
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
    let results = gmwm::per_column(&columns, f);
    loaded
        .table
        .columns
        .iter()
        .zip(results)
        .map(|(col, r)| Ok((col.name.clone(), column_context(r, file, &col.name)?)))
        .collect()
}

/// The gaps in the loaded recording's time stamps when `--gaps aware` (empty otherwise, with
/// a note for `--gaps contiguous` over gaps).
pub fn gaps_of(loaded: &Loaded, input: &InputConfig, style: OutputStyle) -> Vec<gmwm::Gap> {
    let Some(t) = &loaded.table.facts.timing else {
        return Vec::new();
    };
    if t.gaps.is_empty() {
        return Vec::new();
    }
    match input.gaps {
        gmwm::GapPolicy::Aware => t.gaps.clone(),
        gmwm::GapPolicy::Contiguous => {
            style.note(&input.file, &contiguous_gaps_note(t.gaps.len(), false));
            Vec::new()
        }
    }
}

/// The note of `count` gaps analysed as one contiguous series: asked for (`--gaps
/// contiguous`), or because the recording was streamed.
pub fn contiguous_gaps_note(count: usize, streamed: bool) -> String {
    format!(
        "{count} {} in the time stamps analysed as one contiguous series ({})",
        if count == 1 { "gap" } else { "gaps" },
        if streamed {
            "a streamed recording is not gap-aware; a larger --stream-from reads it in memory"
        } else {
            "--gaps contiguous"
        }
    )
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
    /// Its columns and what each measures.
    pub columns: Vec<(String, gmwm::SensorInfo)>,
    /// Its samples; `None` for a recording the calibration streams from the file.
    pub imu: Option<gmwm::Imu>,
    /// The ROS topic read, if any.
    pub topic: Option<String>,
    /// What it was read from.
    pub source: gmwm::RecordingSource,
    /// What the time stamps say, when there are stamps (a time column or ROS header stamps).
    pub timing: Option<gmwm::TimingReport>,
    /// How many samples were read and used per axis (row accounting).
    pub samples: gmwm::SampleAccount,
    /// What the reader noticed, one line each.
    pub notes: Vec<String>,
}

/// Opens the recording named by `input` as an IMU (the engine's `Recording`: text, raw
/// binary, binary IMU records or a ROS recording).
pub fn load_recording(input: &InputConfig) -> Result<LoadedRecording> {
    let opts = gmwm::RecordingOptions {
        read: input.read.clone(),
        topic: input.topic.clone(),
    };
    let rec = gmwm::Recording::open_probed(input.probe(), &opts)?;
    let mut loaded = memory_recording(&rec);
    loaded.imu = Some(rec.imu);
    Ok(loaded)
}

/// What a recording read into memory is, as shown (its samples stay with `rec`).
pub fn memory_recording(rec: &gmwm::Recording) -> LoadedRecording {
    LoadedRecording {
        path: shown_path(&rec.path),
        columns: rec
            .imu
            .axes()
            .iter()
            .map(|a| (a.column.name.clone(), a.info.clone()))
            .collect(),
        imu: None,
        topic: rec.topic.clone(),
        source: rec.source.clone(),
        timing: rec.timing.clone(),
        samples: rec.samples.clone(),
        notes: rec.notes.clone(),
    }
}

/// A raw binary recording the calibration streams ([`gmwm::Calibration::streams`]):
/// its columns and what each measures from the sidecar, no samples read.
pub fn streamed_recording(input: &InputConfig) -> Result<LoadedRecording> {
    let columns = gmwm::binary_file_columns(&input.file, &input.read)?;
    // the columns left out, as the in-memory reader notes them
    let skipped = match gmwm::binary_layout(&input.file, &input.read)? {
        Some(layout) => {
            warn_all(&gmwm::binary_warnings(&input.file, &layout));
            let sidecar = gmwm::find_sidecar(&input.file)?;
            layout
                .selection(&input.file, &input.read, sidecar.as_ref())?
                .1
        }
        None => Vec::new(),
    };
    let samples = streamed_samples(input, &columns)?;
    Ok(LoadedRecording {
        path: shown_path(&input.file),
        imu: None,
        topic: None,
        source: gmwm::RecordingSource::Table,
        timing: None,
        notes: gmwm::left_out_note(&skipped)
            .into_iter()
            .chain([samples.to_string()])
            .collect(),
        samples,
        columns,
    })
}

/// The account of a raw binary file streamed whole: every row read and used in `columns`.
fn streamed_samples(
    input: &InputConfig,
    columns: &[(String, gmwm::SensorInfo)],
) -> Result<gmwm::SampleAccount> {
    let names = columns.iter().map(|(n, _)| n.clone()).collect();
    let rows = match gmwm::binary_layout(&input.file, &input.read)? {
        Some(layout) => {
            let width = layout.format.value_width().unwrap_or(8) * layout.ncols;
            let bytes = std::fs::metadata(&input.file)
                .with_context(|| input.file.display().to_string())?
                .len();
            bytes / width.max(1) as u64
        }
        None => 0,
    };
    Ok(gmwm::SampleAccount::all_used(names, "row", rows))
}

/// A text or IMU-record recording the calibration streams, read once into its spool
/// ([`gmwm::StreamedTable`]): its columns, what each measures, and what the
/// reader noticed, as [`load_recording`] gives them.
pub fn streamed_table_recording(t: &gmwm::StreamedTable) -> LoadedRecording {
    // a ROS topic's notes are all of them, as the in-memory reader gives them
    let mut notes = match t.topic {
        Some(_) => Vec::new(),
        None => gmwm::table_notes(
            t.facts.record_type,
            t.facts.timing.as_ref(),
            &t.facts.skipped,
            &t.facts.samples,
            &t.facts.warnings,
        ),
    };
    notes.extend(t.notes.iter().cloned());
    LoadedRecording {
        path: shown_path(&t.facts.path),
        columns: t.names.iter().cloned().zip(t.sensor_infos()).collect(),
        imu: None,
        topic: t.topic.clone(),
        source: match (t.facts.record_type, &t.topic, t.container) {
            (_, Some(topic), Some(container)) => gmwm::RecordingSource::Ros {
                container: container.to_string(),
                topic: topic.clone(),
            },
            (Some(r), _, _) => gmwm::RecordingSource::Records {
                record_type: r.name().to_string(),
            },
            _ => gmwm::RecordingSource::Table,
        },
        timing: t.facts.timing.clone(),
        samples: t.facts.samples.clone(),
        notes,
    }
}

/// A ROS recording read as a table: the IMU topic's six axes at the header stamps' rate.
fn load_ros(input: &InputConfig, style: OutputStyle) -> Result<Loaded> {
    let rec = gmwm::Recording::open(
        &input.file,
        &gmwm::RecordingOptions {
            read: input.read.clone(),
            topic: input.topic.clone(),
        },
    )?;
    for n in &rec.notes {
        style.note(&input.file, n);
    }
    let freq_hz = rec.imu.freq_hz();
    let table = Table {
        facts: gmwm::TableFacts {
            path: rec.path,
            freq_hz: Some(freq_hz),
            sidecar: None,
            timing: rec.timing,
            warnings: Vec::new(),
            skipped: Vec::new(),
            record_type: None,
            samples: rec.samples,
        },
        columns: rec.imu.into_axes().into_iter().map(|a| a.column).collect(),
        time: None,
    };
    Ok(Loaded { table, freq_hz })
}
