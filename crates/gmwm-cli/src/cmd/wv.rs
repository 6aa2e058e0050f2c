//! `gmwm wv`: wavelet variance of each selected column.

use super::Command;
use crate::config::WvConfig;
use crate::input::InputConfig;
use crate::input::{analyse_columns, gaps_of, is_wv, load, load_wv, named, Loaded};
use crate::prepare::Inputs;
use crate::render;
use crate::style::OutputStyle;
use anyhow::Result;
use gmwm::{
    binary_columns_wv, binary_layout, wavelet_variance, BinaryLayout, StreamedColumn, Transform,
    WaveletFilter, WaveletVariance, WvOptions,
};
use std::io::Write;
use std::path::Path;

/// Raw binary input (from `--format`, the name or the sidecar) with the classical Haar MODWT
/// estimator and no time column streams ([`gmwm::binary_wavelet_variance`]): the
/// columns are never loaded, and memory does not grow with the file.
pub(crate) fn streamable(input: &InputConfig, opts: &WvOptions) -> Result<Option<BinaryLayout>> {
    if input.read.time_column.is_some()
        || input.probe().container().is_some()
        || opts.robust.is_some()
        || opts.transform != Transform::Modwt
        || opts.filter != WaveletFilter::Haar
    {
        return Ok(None);
    }
    let layout = binary_layout(&input.file, &input.read)?;
    // a column named like a time column is a time column: the in-memory reader handles it
    Ok(layout.filter(|l| l.names.iter().all(|n| gmwm::time_column_unit(n).is_none())))
}

fn run_streaming(
    input: &InputConfig,
    layout: &BinaryLayout,
    opts: &WvOptions,
    style: OutputStyle,
) -> Result<Vec<(String, WaveletVariance)>> {
    let columns = stream_columns(input, layout, opts, style)?;
    Ok(columns.into_iter().map(|(name, c)| (name, c.wv)).collect())
}

/// The selected columns of a raw binary file (`--columns`, else the sensor axes, else all, as
/// the in-memory reader selects them), streamed in one pass: each one's name, WV and range.
pub(crate) fn stream_columns(
    input: &InputConfig,
    layout: &BinaryLayout,
    opts: &WvOptions,
    style: OutputStyle,
) -> Result<Vec<(String, StreamedColumn)>> {
    let sidecar = gmwm::find_sidecar(&input.file)?;
    let (columns, skipped) = layout.selection(&input.file, &input.read, sidecar.as_ref())?;
    crate::input::note_not_analysed(style, &input.file, &skipped);
    crate::input::warn_all(&gmwm::binary_warnings(&input.file, layout));
    let freq_hz = match input.read.freq_hz {
        Some(f) => f,
        None => stream_freq(&input.file)?,
    };
    // the errors name the file (and the column, or the row of a bad value)
    let streamed = binary_columns_wv(&input.file, layout, &columns, freq_hz, opts)?;
    let named: Vec<(String, StreamedColumn)> = columns
        .iter()
        .map(|&c| layout.names[c - 1].clone())
        .zip(streamed)
        .collect();
    if let Some((_, first)) = named.first() {
        let account = gmwm::SampleAccount::all_used(
            named.iter().map(|(n, _)| n.clone()).collect(),
            "row",
            first.wv.n() as u64,
        );
        style.note(&input.file, &account.to_string());
    }
    Ok(named)
}

fn stream_freq(path: &std::path::Path) -> Result<f64> {
    let sidecar = gmwm::find_sidecar(path)?;
    Ok(match sidecar.and_then(|s| s.sampling_frequency_hz) {
        Some(f) => f,
        None if crate::spool::is_stdin(path) => {
            return Err(crate::error::UsageError(format!(
                "{}: no sampling rate: raw binary on standard input has no JSON sidecar; give \
                 --freq",
                crate::spool::STDIN
            ))
            .into())
        }
        None => {
            eprintln!(
                "gmwm: warning: {}: no sampling rate (no --freq or JSON sidecar); using 1 Hz, so tau_s is in samples",
                path.display()
            );
            1.0
        }
    })
}

/// Text, binary IMU records or a ROS recording of at least `--stream-from` rows (a text file:
/// 8 bytes a row; a ROS recording: the messages of its largest IMU topic), with the classical
/// Haar MODWT estimator, stream
/// ([`gmwm::StreamedTable`]): one pass over the file, memory bounded.
pub(crate) fn streams_text(input: &InputConfig, opts: &WvOptions) -> Result<bool> {
    if crate::spool::is_stdin(&input.file)
        || opts.robust.is_some()
        || opts.transform != Transform::Modwt
        || opts.filter != WaveletFilter::Haar
    {
        return Ok(false);
    }
    Ok(gmwm::streams_from(
        input.probe(),
        &input.read,
        input.stream_from,
    )?)
}

/// The selected columns of a text or IMU-record recording, streamed: as the in-memory path
/// reads them (columns, rate, notes and timing warnings), the WV of each.
fn run_streamed_table(
    input: &InputConfig,
    opts: &WvOptions,
    style: OutputStyle,
) -> Result<Vec<(String, WaveletVariance)>> {
    let table = gmwm::StreamedTable::open_recording(
        input.probe(),
        &gmwm::RecordingOptions {
            read: input.read.clone(),
            topic: input.topic.clone(),
        },
    )?;
    if table.topic.is_none() {
        // a ROS topic's notes say all of it, as the in-memory path prints them
        crate::input::report_parts(
            style,
            &table.facts.path,
            table.facts.timing.as_ref(),
            &table.facts.skipped,
            &table.facts.samples,
            &table.facts.warnings,
        );
    }
    for n in &table.notes {
        style.note(&input.file, n);
    }
    // the streamed pass sums the windows as the rows come: every scale spliced across gaps
    if let Some(t) = table.facts.timing.as_ref().filter(|t| !t.gaps.is_empty()) {
        let streamed = input.gaps == gmwm::GapPolicy::Aware;
        style.note(
            &input.file,
            &crate::input::contiguous_gaps_note(t.gaps.len(), streamed),
        );
    }
    let freq_hz = match table.facts.freq_hz {
        Some(f) => f,
        None => {
            eprintln!(
                "gmwm: warning: {}: no sampling rate (no --freq, time column or JSON sidecar); using 1 Hz, so tau_s is in samples",
                input.file.display()
            );
            1.0
        }
    };
    let wvs = table.wavelet_variance(freq_hz, opts)?;
    Ok(table.names.iter().cloned().zip(wvs).collect())
}

/// The gap-aware WV of every loaded column (docs/methods.md §1.11), the gaps' cost noted
/// once (it is the same for every column).
pub(crate) fn gap_aware(
    loaded: &Loaded,
    file: &Path,
    gaps: &[gmwm::Gap],
    opts: &WvOptions,
    style: OutputStyle,
) -> Result<Vec<(String, WaveletVariance)>> {
    let items = analyse_columns(loaded, file, |x| {
        Ok(gmwm::gap_aware_wavelet_variance(
            x,
            gaps,
            loaded.freq_hz,
            opts,
        )?)
    })?;
    if let Some((_, (_, account))) = items.first() {
        style.note(file, &account.to_string());
    }
    Ok(items.into_iter().map(|(n, (wv, _))| (n, wv)).collect())
}

/// A saved wavelet variance as it is (no recomputation).
fn run_saved(config: &WvConfig, style: OutputStyle) -> Result<Vec<(String, WaveletVariance)>> {
    let file = &config.input.file;
    config.saved_wv.check(file)?;
    let alpha = config.wv.alpha;
    let series = load_wv(&config.input, config.wv.levels)?;
    if let Some((name, wv)) = series
        .iter()
        .find(|(_, wv)| (wv.alpha() - alpha).abs() > 1e-12)
    {
        anyhow::ensure!(
            alpha == 0.05,
            "{}: series {}: --alpha {} needs the series; the file's intervals are at alpha {}",
            file.display(),
            gmwm::quote(name),
            alpha,
            wv.alpha()
        );
    }
    style.note(
        file,
        "a wavelet variance saved by gmwm wv --json: shown as read, not recomputed",
    );
    Ok(series)
}

impl Command for WvConfig {
    fn inputs(&mut self) -> Inputs<'_> {
        Inputs::Recording(&mut self.input)
    }

    fn outputs(&self) -> Vec<&Path> {
        Vec::new()
    }

    fn levels(&self) -> Option<usize> {
        self.wv.levels
    }

    fn run(&self, style: OutputStyle, mut out: &mut dyn Write) -> Result<()> {
        let items = compute(self, style)?;
        render::series(&mut out, &named(&items), self.output)
    }
}

/// The wavelet variance of every selected column: read from a saved WV, streamed from raw
/// binary, or computed from the loaded columns (warnings printed).
pub fn compute(config: &WvConfig, style: OutputStyle) -> Result<Vec<(String, WaveletVariance)>> {
    let (input, opts) = (&config.input, &config.wv);
    if is_wv(input) {
        return run_saved(config, style);
    }
    if let Some(layout) = streamable(input, opts)? {
        return run_streaming(input, &layout, opts, style);
    }
    if streams_text(input, opts)? {
        return run_streamed_table(input, opts, style);
    }
    let loaded = load(input, style)?;
    let gaps = gaps_of(&loaded, input, style);
    let items = if gaps.is_empty() {
        analyse_columns(&loaded, &input.file, |x| {
            Ok(wavelet_variance(x, loaded.freq_hz, opts)?)
        })?
    } else {
        gap_aware(&loaded, &input.file, &gaps, opts, style)?
    };
    for (name, wv) in &items {
        for w in wv.warnings() {
            eprintln!(
                "gmwm: warning: {}: column {name}: {w}",
                input.file.display()
            );
        }
    }
    Ok(items)
}
