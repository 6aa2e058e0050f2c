//! `gmwm calibrate`: the engine's calibration pipeline on a recording, a readable summary, and
//! the files a navigation filter reads.

use super::Command;
use crate::config::CalibrateConfig;
use crate::error::UsageError;
use crate::prepare::Inputs;
use crate::style::{OutputStyle, Ticks};
use anyhow::{Context, Result};
use gmwm::{
    render_export, AxisCalibration, Calibration, CalibrationReport, CalibrationSource,
    DatasheetComparison, Estimate, EstimateStatus, ExportFormat, NavSet, SelectionRule,
};
use std::io::Write;
use std::path::{Path, PathBuf};

impl Command for CalibrateConfig {
    fn inputs(&mut self) -> Inputs<'_> {
        if self.pool.is_empty() {
            return Inputs::Recording(&mut self.input);
        }
        Inputs::Files {
            paths: &self.pool,
            refusal: "--pool reads several recordings from files; give standard input or a \
                      pipe to a one-recording command",
        }
    }

    fn outputs(&self) -> Vec<&Path> {
        let mut out: Vec<&Path> = self.exports.iter().map(|(_, p)| p.as_path()).collect();
        out.extend(self.json.as_deref());
        out.extend(self.report.as_deref());
        out
    }

    fn levels(&self) -> Option<usize> {
        self.options.wv.levels
    }

    fn run(&self, style: OutputStyle, mut out: &mut dyn Write) -> Result<()> {
        let mode = Mode {
            print_summary: true,
            style,
        };
        execute_in(self, self.report.as_deref(), mode, &mut out).map(|_| ())
    }
}

/// How [`execute_in`] runs.
#[derive(Debug, Clone, Copy)]
pub struct Mode {
    /// Print the summary (else only what was written).
    pub print_summary: bool,
    /// Progress and notes (one recording of a batch: no progress bar of its own).
    pub style: OutputStyle,
}

/// What a calibration gave.
#[derive(Debug, Clone, PartialEq)]
pub struct Calibrated {
    /// Axes calibrated.
    pub axes: usize,
    /// Axes whose selected model explains the wavelet variance within its band.
    pub explained: usize,
    /// The files written, in order (the JSON last).
    pub written: Vec<PathBuf>,
}

/// Refuses, before any work, an output file that is the recording or its sidecar.
fn check_outputs(config: &CalibrateConfig, report_path: Option<&Path>) -> Result<()> {
    let file = config.input.file.as_path();
    let sidecars = gmwm::sidecar_candidates(file);
    let inputs: Vec<&Path> = std::iter::once(file)
        .chain(sidecars.iter().map(PathBuf::as_path))
        .collect();
    for (format, path) in &config.exports {
        crate::output::check_not_input(&format!("--export {format}"), path, &inputs)?;
    }
    if let Some(json) = config.json.as_deref().filter(|p| *p != Path::new("-")) {
        crate::output::check_not_input("--json", json, &inputs)?;
    }
    if let Some(report) = report_path {
        crate::output::check_not_input("--report", report, &inputs)?;
    }
    Ok(())
}

/// [`execute`] with its mode; returns what was calibrated and written.
pub fn execute_in(
    config: &CalibrateConfig,
    report_path: Option<&Path>,
    mode: Mode,
    out: &mut impl Write,
) -> Result<Calibrated> {
    let print_summary = mode.print_summary;
    let exports = &config.exports;
    let (recording, mut report, samples) = if config.pool.is_empty() {
        check_outputs(config, report_path)?;
        calibrate_one(config, mode)?
    } else {
        let (recording, report) = calibrate_pooled(config, report_path, mode)?;
        (recording, report, None)
    };
    let samples = if config.covariate.is_some() || config.augment.is_some() {
        Some(samples_of(config, &recording, samples)?)
    } else {
        None
    };
    let curves = match (&config.covariate, &samples) {
        (Some(c), Some(imu)) => Some(against_covariate(config, c, imu, &mut report, mode)?),
        _ => None,
    };
    let augmented = match (&config.augment, &samples) {
        (Some(opts), Some(imu)) => Some(augmented(config, opts, imu, &report, mode)?),
        _ => None,
    };
    let audited = audit(config, &mut report, mode)?;
    // unknown for a file that is not a ROS recording: the exporter writes its placeholder and
    // says so in a comment
    let rostopic = config.rostopic.clone().or_else(|| recording.topic.clone());
    let sets = report.nav_sets(config.policy, config.adjustment, rostopic.as_deref());
    // every file that can be written is, then the failures are reported together
    let mut written = Vec::new();
    let mut paths = Vec::new();
    let mut failed = Vec::new();
    for (format, path) in exports {
        for set in &sets {
            let target = per_axis_path(path, &set.label);
            let result = render_export(*format, &set.noise)
                .map_err(anyhow::Error::from)
                // the file is named below
                .and_then(|text| Ok(crate::output::write_io(&target, text.as_bytes())?));
            match result {
                Ok(()) => {
                    written.push(format!("{} ({format})", target.display()));
                    paths.push(target);
                }
                Err(e) => failed.push(format!("{} ({format}): {e}", target.display())),
            }
        }
    }
    let json_to_stdout = config.json.as_deref() == Some(Path::new("-"));
    let mut doc = gmwm::document::calibration(
        &recording.path,
        &recording.notes,
        // a pooled calibration's accounts are its recordings' (their notes)
        config.pool.is_empty().then_some(&recording.samples),
        &report,
        &sets,
    );
    if let Some(c) = &curves {
        doc["covariate"] = serde_json::to_value(c)?;
    }
    if let Some(a) = &augmented {
        doc["augmented"] = serde_json::to_value(a)?;
    }
    if let Some(path) = report_path {
        match write_report(
            config,
            path,
            &recording,
            &report,
            &sets,
            &doc,
            Extra {
                curves: curves.as_ref(),
                augmented: augmented.as_deref(),
            },
        ) {
            Ok(figures) => {
                written.push(format!(
                    "{} (HTML report, {figures} figures)",
                    path.display()
                ));
                paths.push(path.to_path_buf());
            }
            Err(e) => failed.push(format!("{} (HTML report): {e:#}", path.display())),
        }
    }
    if let Some(path) = &config.json {
        if json_to_stdout {
            serde_json::to_writer_pretty(&mut *out, &doc)?;
            writeln!(out)?;
        } else {
            crate::output::write_json(path, &doc)?;
            written.push(format!("{} (JSON)", path.display()));
            paths.push(path.clone());
        }
    }
    if !json_to_stdout {
        if print_summary {
            summary(&recording, &report, out)?;
            if let Some(c) = &curves {
                covariate_summary(c, out)?;
            }
            if let Some(a) = &augmented {
                augmented_summary(a, out)?;
            }
            if let Some(seconds) = audited {
                writeln!(
                    out,
                    "\nself-audit: {} simulated recordings per axis, each recalibrated, in {seconds:.1} s",
                    config.audit
                )?;
            }
        }
        for w in &written {
            writeln!(out, "wrote {w}")?;
        }
    }
    out.flush()?;
    if !failed.is_empty() {
        anyhow::bail!("not written: {}", failed.join("; "));
    }
    Ok(Calibrated {
        axes: report.axes.len(),
        explained: report.axes.iter().filter(|a| a.verdict.explains_wv).count(),
        written: paths,
    })
}

/// `--audit R`: the self-audit of every axis, attached to it; its wall time, s (`None` when
/// not run: R = 0, or a pooled calibration, which has no one length to simulate).
fn audit(
    config: &CalibrateConfig,
    report: &mut CalibrationReport,
    mode: Mode,
) -> Result<Option<f64>> {
    if config.audit == 0 || !config.pool.is_empty() {
        return Ok(None);
    }
    let started = std::time::Instant::now();
    let calibration = Calibration::new(config.options.clone());
    let axes = report.axes.iter().filter(|a| a.kind.is_some()).count();
    let bar = mode
        .style
        .bar((axes * config.audit) as u64, "self-audit", "recalibrations");
    let audits = calibration.audit(report, config.audit, config.options.seed, &Ticks(&bar))?;
    bar.finish_and_clear();
    for (axis, audit) in report.axes.iter_mut().zip(audits) {
        axis.audit = audit;
    }
    Ok(Some(started.elapsed().as_secs_f64()))
}

/// `--covariate`: N, B, K of every axis against the covariate (the engine's
/// `Calibration::covariate_curves` over the recording's samples, `samples` when the
/// calibration held them, else read again), and the report's N, B, K replaced for `--at` or
/// `--over`.
fn against_covariate(
    config: &CalibrateConfig,
    c: &crate::config::CovariateCalibrationConfig,
    imu: &gmwm::Imu,
    report: &mut CalibrationReport,
    mode: Mode,
) -> Result<gmwm::CovariateCalibration> {
    use crate::config::CovariateExport;
    let file = &config.input.file;
    let (values, unit) =
        super::covariate::covariate_values(&config.input, file, &c.column, mode.style)?;
    let options = gmwm::CovariateCalibrationOptions {
        unit,
        windows: c.windows,
        at: match c.export {
            CovariateExport::At(x) => vec![x],
            _ => Vec::new(),
        },
        ..gmwm::CovariateCalibrationOptions::new(c.column.clone())
    };
    let calibration = Calibration::new(config.options.clone());
    let spinner = mode.style.bar(
        1,
        &format!("fitting against {} over {} windows", c.column, c.windows),
        "steps",
    );
    spinner.enable_steady_tick(std::time::Duration::from_millis(250));
    let curves = calibration
        .covariate_curves(imu, report, &values, &options)
        .with_context(|| format!("{}: --covariate {}", file.display(), c.column))?;
    spinner.finish_and_clear();
    match c.export {
        CovariateExport::At(x) => report.at_covariate(&curves, x)?,
        CovariateExport::Over(lo, hi) => report.worst_over(&curves, lo, hi)?,
        CovariateExport::Whole => {}
    }
    Ok(curves)
}

/// The samples `--covariate` and `--augment` work on: those the calibration held, else the
/// recording read again (a streamed one); refused for a pooled calibration and a saved WV.
fn samples_of(
    config: &CalibrateConfig,
    recording: &crate::input::LoadedRecording,
    samples: Option<gmwm::Imu>,
) -> Result<gmwm::Imu> {
    let flag = if config.covariate.is_some() {
        "--covariate"
    } else {
        "--augment"
    };
    if !config.pool.is_empty() {
        return Err(UsageError(if config.covariate.is_some() {
            "--covariate calibrates one recording cut into windows; for several recordings at \
             different levels use gmwm fit FILE... --covariate COL"
                .to_string()
        } else {
            "--augment works on one recording's samples; calibrate the recordings one by one"
                .to_string()
        })
        .into());
    }
    if matches!(recording.source, gmwm::RecordingSource::SavedWv) {
        return Err(UsageError(format!(
            "{}: {flag} needs the samples; a saved wavelet variance has none",
            config.input.file.display()
        ))
        .into());
    }
    match samples {
        Some(imu) => Ok(imu),
        None => crate::input::load_recording(&config.input)?
            .imu
            .context("the recording's samples"),
    }
}

/// `--augment`: GMWM+ of every axis' identified model (the engine's `Calibration::augmented`).
fn augmented(
    config: &CalibrateConfig,
    opts: &gmwm::AugmentOptions,
    imu: &gmwm::Imu,
    report: &CalibrationReport,
    mode: Mode,
) -> Result<Vec<gmwm::AxisAugmented>> {
    let spinner = mode.style.bar(
        1,
        &format!(
            "GMWM+ ({}) with {} bootstrap series per axis",
            opts.augment, opts.replicates
        ),
        "steps",
    );
    spinner.enable_steady_tick(std::time::Duration::from_millis(250));
    let out = Calibration::new(config.options.clone())
        .augmented(imu, report, opts)
        .with_context(|| {
            format!(
                "{}: --augment {}",
                config.input.file.display(),
                opts.augment
            )
        })?;
    spinner.finish_and_clear();
    Ok(out)
}

/// The `--augment` table: per axis the physical quantities of GMWM and GMWM+ and the J-test.
fn augmented_summary(axes: &[gmwm::AxisAugmented], out: &mut impl Write) -> Result<()> {
    let Some(first) = axes.iter().find_map(|a| a.fit.as_ref()) else {
        writeln!(out, "\nGMWM+:")?;
        for a in axes {
            if let Some(n) = &a.note {
                writeln!(out, "  {n}")?;
            }
        }
        return Ok(());
    };
    writeln!(
        out,
        "\nGMWM+ (augment {}; the exports above stay GMWM's)",
        first.augment()
    )?;
    writeln!(
        out,
        "  {:<9} {:<34} {:>12} {:>12} {:>27}  unit",
        "axis", "quantity", "GMWM", "GMWM+", "95% interval"
    )?;
    for a in axes {
        let Some(fit) = &a.fit else {
            if let Some(n) = &a.note {
                writeln!(out, "  {:<9} {n}", a.column)?;
            }
            continue;
        };
        for q in &a.physical {
            let ci = match (q.ci_low, q.ci_high) {
                // an interval from 0 to infinity: the stacked moments cannot place it
                (Some(lo), Some(hi)) if lo > 0.0 && hi.is_finite() => {
                    format!("[{lo:.4e}, {hi:.4e}]")
                }
                (Some(_), Some(_)) => "not determined".to_string(),
                _ => "-".to_string(),
            };
            writeln!(
                out,
                "  {:<9} {:<34} {:>12.4e} {:>12.4e} {:>27}  {}",
                a.column,
                format!("{}[{}].{}", q.process, q.index, q.name),
                q.gmwm,
                q.value,
                ci,
                q.unit
            )?;
        }
        let j = fit.j_test();
        let p = match j.p_value {
            Some(p) if p < 1e-16 => "p < 1e-16".to_string(),
            Some(p) => format!("p = {p:.3}"),
            None => "no degrees of freedom".to_string(),
        };
        writeln!(
            out,
            "  {:<9} J-test of the stacked moments: Q = {:.1} on {} df, {p}",
            a.column, j.statistic, j.df
        )?;
        if j.p_value.is_some_and(|p| p < 0.001) {
            writeln!(
                out,
                "  {:<9} the model does not reproduce the differences' first autocovariances \
                 (observed against implied: {}): the sensor's own filter shapes them; read \
                 GMWM+ here as a check of the model, not as better estimates",
                a.column,
                fit.moments()[fit.moments().len() - fit.augment().len()..]
                    .iter()
                    .map(|m| format!("{} {:.3e} vs {:.3e}", m.name, m.observed, m.implied))
                    .collect::<Vec<_>>()
                    .join(", ")
            )?;
        }
    }
    Ok(())
}

/// One recording read (streamed when long) and calibrated; its samples too when they were
/// read into memory.
fn calibrate_one(
    config: &CalibrateConfig,
    mode: Mode,
) -> Result<(
    crate::input::LoadedRecording,
    CalibrationReport,
    Option<gmwm::Imu>,
)> {
    let exports = &config.exports;
    let calibration = Calibration::new(config.options.clone());
    if crate::input::is_wv(&config.input) {
        let (recording, report) = calibrate_saved_wv(config, &calibration, exports, mode)?;
        return Ok((recording, report, None));
    }
    // the engine reads the recording the way its kind and length ask (memory, one spooled
    // pass, or a raw binary file streamed), from the probe the configuration carries
    let source = calibration.open(
        config.input.probe(),
        &gmwm::RecordingOptions {
            read: config.input.read.clone(),
            topic: config.input.topic.clone(),
        },
    )?;
    let recording = match &source {
        CalibrationSource::Memory(r) => crate::input::memory_recording(r),
        CalibrationSource::Spooled(t) => crate::input::streamed_table_recording(t),
        CalibrationSource::Raw { .. } => crate::input::streamed_recording(&config.input)?,
        // `open` reads one recording; several, or saved WVs, are sources the caller builds
        CalibrationSource::Pooled(_) | CalibrationSource::SavedWv { .. } => {
            anyhow::bail!("{}: not one recording", config.input.file.display())
        }
    };
    if !exports.is_empty() {
        check_units_known(config, &recording)?;
    }
    let per_axis = calibration.candidates_per_axis()?;
    let axes = recording.columns.len();
    let progress = mode
        .style
        .bar((axes * per_axis) as u64, "calibrating", "candidate fits");
    let report = calibration
        .run_source(&source, &Ticks(&progress))
        .with_context(|| recording.path.display().to_string())?;
    progress.finish_and_clear();
    let samples = match source {
        CalibrationSource::Memory(r) => Some(r.imu),
        _ => None,
    };
    Ok((recording, report, samples))
}

/// A wavelet variance saved by `gmwm wv --json` (or computed elsewhere in that shape, such as
/// the precomputed WVs of recordings not at hand), calibrated as a streamed recording is
/// ([`Calibration::run_wv`]); `--columns` picks series, `--freq` overrides the file's rate.
fn calibrate_saved_wv(
    config: &CalibrateConfig,
    calibration: &Calibration,
    exports: &[(ExportFormat, PathBuf)],
    mode: Mode,
) -> Result<(crate::input::LoadedRecording, CalibrationReport)> {
    let input = &config.input;
    let series = crate::input::load_wv(input, config.options.wv.levels)?;
    let columns = gmwm::wv_columns(&series);
    let (samples, note) = gmwm::wv_account(&series);
    let recording = crate::input::LoadedRecording {
        path: crate::input::shown_path(&input.file),
        columns,
        imu: None,
        topic: None,
        source: gmwm::RecordingSource::SavedWv,
        timing: None,
        notes: vec![note],
        samples,
    };
    if !exports.is_empty() {
        check_units_known(config, &recording)?;
    }
    let per_axis = calibration.candidates_per_axis()?;
    let progress = mode.style.bar(
        (recording.columns.len() * per_axis) as u64,
        "calibrating",
        "candidate fits",
    );
    let name = input
        .file
        .file_name()
        .map(|f| f.to_string_lossy().into_owned());
    let report = calibration
        .run_source(
            &CalibrationSource::SavedWv { name, series },
            &Ticks(&progress),
        )
        .with_context(|| recording.path.display().to_string())?;
    progress.finish_and_clear();
    Ok((recording, report))
}

/// `--pool`: every recording the FILE arguments name, read into memory and calibrated as one
/// sensor (docs/methods.md §5.12). The recording returned stands for them all: the first's
/// path, source and topic, every recording's notes.
fn calibrate_pooled(
    config: &CalibrateConfig,
    report_path: Option<&Path>,
    mode: Mode,
) -> Result<(crate::input::LoadedRecording, CalibrationReport)> {
    let files = crate::recordings::recordings(&config.pool, config.input.read.format)?;
    if files.len() < 2 {
        return Err(UsageError(format!(
            "--pool calibrates several recordings as one sensor: {} found in {}; give two or more",
            files.len(),
            config
                .pool
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(" ")
        ))
        .into());
    }
    let mut loaded = Vec::with_capacity(files.len());
    for f in &files {
        let one = CalibrateConfig {
            input: config.input.with_file(f),
            ..config.clone()
        };
        check_outputs(&one, report_path)?;
        let recording = crate::input::load_recording(&one.input)?;
        if !config.exports.is_empty() {
            check_units_known(config, &recording)?;
        }
        loaded.push(recording);
    }
    let calibration = Calibration::new(config.options.clone());
    let names: Vec<String> = loaded
        .iter()
        .map(|r| crate::spool::shown(&r.path.display().to_string()))
        .collect();
    // the recordings move into the source; what stays behind is each one's path and notes
    let pooled = CalibrationSource::Pooled(
        names
            .iter()
            .zip(&mut loaded)
            .filter_map(|(n, r)| Some((n.clone(), r.imu.take()?)))
            .collect(),
    );
    let per_axis = calibration.candidates_per_axis()?;
    let axes = loaded[0].columns.len();
    let progress = mode
        .style
        .bar((axes * per_axis) as u64, "calibrating", "candidate fits");
    let report = calibration
        .run_source(&pooled, &Ticks(&progress))
        .map_err(gmwm::Error::from)?;
    progress.finish_and_clear();
    // each recording's notes, named by it
    let notes = names
        .iter()
        .zip(&loaded)
        .flat_map(|(name, r)| r.notes.iter().map(move |n| format!("{name}: {n}")))
        .collect();
    let mut first = loaded.swap_remove(0);
    first.notes = notes;
    first.timing = None;
    Ok((first, report))
}

/// The HTML report: the calibration rendered by gmwm-plot with the filter files as exported
/// (Kalibr's always, for the page, and every one asked for) and the JSON of `--json`; returns
/// the number of figures.
fn write_report(
    config: &CalibrateConfig,
    path: &Path,
    recording: &crate::input::LoadedRecording,
    report: &CalibrationReport,
    sets: &[NavSet],
    doc: &serde_json::Value,
    extra: Extra<'_>,
) -> Result<usize> {
    let mut formats: Vec<(ExportFormat, Option<&Path>)> = config
        .exports
        .iter()
        .map(|(f, p)| (*f, Some(p.as_path())))
        .collect();
    if !formats.iter().any(|(f, _)| *f == ExportFormat::KALIBR) {
        formats.insert(0, (ExportFormat::KALIBR, None));
    }
    let mut files = Vec::new();
    for (format, target) in &formats {
        for set in sets {
            let name = match target {
                Some(p) => per_axis_path(p, &set.label).display().to_string(),
                // one set (no per-axis split) has no label to name
                None if set.label.is_empty() => "not written: add --kalibr FILE".to_string(),
                None => format!("{}: not written, add --kalibr FILE", set.label),
            };
            let content = match render_export(*format, &set.noise) {
                Ok(text) => text,
                Err(e) => format!("# cannot be exported: {e}"),
            };
            files.push((format.to_string(), name, content));
        }
    }
    let ctx = gmwm_plot::report::ReportContext {
        file: match report.recordings.len() {
            0 => crate::spool::shown(&config.input.file.display().to_string()),
            _ => report
                .recordings
                .iter()
                .map(|r| r.name.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        },
        source: match &recording.source {
            gmwm::RecordingSource::Records { record_type } => {
                format!("binary IMU records ({record_type})")
            }
            gmwm::RecordingSource::Ros { container, topic } => {
                format!("{container}, topic {topic}")
            }
            gmwm::RecordingSource::SavedWv => "saved wavelet variances (no samples)".to_string(),
            _ => "delimited text or raw binary columns".to_string(),
        },
        reader_notes: recording.notes.clone(),
        timing: match recording.source {
            gmwm::RecordingSource::SavedWv => {
                Some("no samples: the rate the saved WV gives (or --freq)".to_string())
            }
            _ => recording.timing.as_ref().map(ToString::to_string),
        },
        command: command_line(),
        exports: files,
        json: serde_json::to_string(doc)?,
        generator: format!("gmwm {}", env!("CARGO_PKG_VERSION")),
        covariate: extra.curves.cloned(),
        augmented: extra.augmented.map(<[_]>::to_vec).unwrap_or_default(),
    };
    let html = gmwm_plot::report::render(report, &ctx)?;
    let figures = html.matches("<figure>").count();
    // the caller names the file
    crate::output::write_io(path, html.as_bytes())?;
    Ok(figures)
}

/// The analyses beyond the calibration that the report shows when they were asked for.
struct Extra<'a> {
    /// `--covariate`: N, B, K against the covariate.
    curves: Option<&'a gmwm::CovariateCalibration>,
    /// `--augment`: GMWM+ per axis.
    augmented: Option<&'a [gmwm::AxisAugmented]>,
}

/// The command as typed, to paste back into a shell: `gmwm` and the arguments, each quoted
/// when it holds anything but letters, digits and `-_./:=,+@%` (non-UTF-8 bytes shown as �).
fn command_line() -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "-_./:=,+@%".contains(c);
    std::iter::once("gmwm".to_string())
        .chain(std::env::args_os().skip(1).map(|a| {
            let a = a.to_string_lossy().into_owned();
            if !a.is_empty() && a.chars().all(plain) {
                a
            } else {
                format!("'{}'", a.replace('\'', "'\\''"))
            }
        }))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Exported files are SI: every gyroscope and accelerometer axis needs a unit the engine
/// understands, from the recording or the flags; said before any computation.
fn check_units_known(
    config: &CalibrateConfig,
    recording: &crate::input::LoadedRecording,
) -> Result<()> {
    use gmwm::Sensor;
    let options = &config.options;
    for (name, info) in &recording.columns {
        let (given, flag) = match info.sensor {
            Sensor::Gyroscope => (options.gyro_unit.is_some(), "--gyro-unit rad/s|deg/s|deg/h"),
            Sensor::Accelerometer => (options.accel_unit.is_some(), "--accel-unit m/s^2|g|mg"),
            _ => continue,
        };
        let known = info
            .unit
            .as_deref()
            .is_some_and(|u| u.parse::<gmwm::SignalUnit>().is_ok());
        if !given && !known {
            return Err(UsageError(format!(
                "{}: the unit of column {} is unknown{} and the exported files are SI: give {flag}",
                recording.path.display(),
                name,
                info.unit
                    .as_deref()
                    .map(|u| format!(" ({})", gmwm::quote(u)))
                    .unwrap_or_default()
            ))
            .into());
        }
    }
    Ok(())
}

/// `FILE` for one set, `FILE` with `.x` before its extension for a per-axis set.
pub fn per_axis_path(path: &Path, label: &str) -> PathBuf {
    if label.is_empty() {
        return path.to_path_buf();
    }
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let name = match path.extension() {
        Some(ext) => format!("{stem}.{label}.{}", ext.to_string_lossy()),
        None => format!("{stem}.{label}"),
    };
    path.with_file_name(name)
}

/// Four significant digits.
/// N, B, K against the covariate: per axis the no-dependence test and the three at five
/// levels across the recorded range (and `--at`), with their bands.
fn covariate_summary(c: &gmwm::CovariateCalibration, out: &mut impl Write) -> Result<()> {
    let unit = c
        .unit
        .as_deref()
        .map(|u| format!(" {u}"))
        .unwrap_or_default();
    writeln!(
        out,
        "\nN, B, K against {} ({} windows at {}..{}{unit}; {:.0}% pointwise bands; docs/methods.md §5.14):",
        c.covariate,
        c.windows,
        num(c.range[0]),
        num(c.range[1]),
        100.0 * (1.0 - c.alpha)
    )?;
    for a in &c.axes {
        let test = a
            .inference
            .as_ref()
            .and_then(|i| i.no_dependence.as_ref())
            .map_or_else(
                || "no test".to_string(),
                |t| {
                    format!(
                        "no dependence: W = {:.1}, df = {}, p {}",
                        t.statistic,
                        t.df,
                        if t.p_value < 1e-16 {
                            "< 1e-16".to_string()
                        } else {
                            format!("= {:.3}", t.p_value)
                        }
                    )
                },
            );
        writeln!(
            out,
            "  {}: {}; {test}",
            a.column,
            a.fit.model().without_values()
        )?;
        writeln!(
            out,
            "    {:>10}  {:<36} {:<36} {:<36}",
            c.covariate,
            format!("N ({})", a.noise_density_unit),
            format!("B ({})", a.bias_instability_unit),
            format!("K ({})", a.random_walk_unit)
        )?;
        let n = a.points.len();
        let picks: Vec<usize> = (0..n)
            .filter(|&k| {
                let x = a.points[k].covariate;
                [0, n / 4, n / 2, (3 * n) / 4, n.saturating_sub(1)].contains(&k)
                    || !(c.range[0]..=c.range[1]).contains(&x)
            })
            .collect();
        for k in picks {
            let p = &a.points[k];
            let cell = |k: usize, v: &Option<gmwm::BandValue>| match v {
                // a quantity that does not depend on the covariate: the calibration's own
                _ if !a.depends[k] && v.is_some() => "as the whole recording".to_string(),
                Some(b) => match (b.low, b.high) {
                    (Some(l), Some(h)) => format!("{:.3e} [{:.3e}, {:.3e}]", b.value, l, h),
                    _ => format!("{:.3e}", b.value),
                },
                None => "-".to_string(),
            };
            writeln!(
                out,
                "    {:>10}  {:<36} {:<36} {:<36}",
                num(p.covariate),
                cell(0, &p.noise_density),
                cell(1, &p.bias_instability),
                cell(2, &p.random_walk)
            )?;
        }
        for note in &a.notes {
            writeln!(out, "    note: {note}")?;
        }
    }
    Ok(())
}

fn num(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        format!("{v:.3e}")
    } else {
        let digits = if a == 0.0 {
            0
        } else {
            (3 - a.log10().floor() as i32).max(0) as usize
        };
        format!("{v:.digits$}")
    }
}

/// `value unit [lo, hi] = datasheet`; `<= bound` for a term not detected.
fn estimate_line(e: &Estimate) -> String {
    let sheet = e
        .forms
        .as_ref()
        .and_then(|f| f.datasheet.as_ref())
        .map(|d| format!(" = {} {}", num(d.value), d.unit))
        .unwrap_or_default();
    let ci = match (e.status, e.ci_low, e.ci_high) {
        (EstimateStatus::UpperBound, ..) => {
            return format!(
                "<= {} {}{sheet} (not detected: an upper bound)",
                num(e.value),
                e.unit
            )
        }
        (_, Some(lo), Some(hi)) => format!(" [{}, {}]", num(lo), num(hi)),
        (EstimateStatus::Undetermined, ..) => " [not determined by the data]".to_string(),
        _ => " [no interval]".to_string(),
    };
    format!("{} {}{ci}{sheet}", num(e.value), e.unit)
}

fn summary(
    recording: &crate::input::LoadedRecording,
    report: &CalibrationReport,
    out: &mut impl Write,
) -> Result<()> {
    let hours = report.duration_s / 3600.0;
    let title = match &report.name {
        Some(name) if !report.recordings.is_empty() => name.clone(),
        _ => recording.path.display().to_string(),
    };
    writeln!(
        out,
        "{title}: {} samples per axis{} at {} Hz ({}), {}",
        report.samples,
        if report.recordings.is_empty() {
            ""
        } else {
            " in all"
        },
        num(report.freq_hz),
        if hours >= 1.0 {
            format!("{hours:.2} h")
        } else {
            format!("{:.0} s", report.duration_s)
        },
        match report.axes.len() {
            1 => "1 axis".to_string(),
            n => format!("{n} axes"),
        }
    )?;
    for n in &recording.notes {
        writeln!(out, "  {n}")?;
    }
    for c in &report.checks {
        writeln!(out, "  check: {c}")?;
    }
    writeln!(
        out,
        "model: selected by WIC among the sub-models of {} ({} rule); intervals {:.0}%",
        report.full_model,
        match report.rule {
            SelectionRule::Navigation => "navigation",
            SelectionRule::Parsimonious => "parsimonious",
            SelectionRule::WicMinimum => "WIC-minimum",
        },
        100.0 * (1.0 - report.alpha)
    )?;
    for a in &report.axes {
        axis_block(a, out)?;
    }
    // the conversions behind the datasheet and discrete forms, once per quantity and sensor
    let mut conversions: Vec<String> = Vec::new();
    for a in &report.axes {
        for (what, e) in [
            ("noise density", &a.noise_density),
            ("random walk", &a.random_walk),
            ("bias instability", &a.bias_instability),
        ] {
            let Some(c) = e
                .as_ref()
                .and_then(|e| e.forms.as_ref())
                .map(|f| &f.conversion)
            else {
                continue;
            };
            let kind = match a.kind {
                Some(gmwm::SignalKind::Gyroscope) => "gyro",
                Some(gmwm::SignalKind::Accelerometer) => "accel",
                None => "other",
            };
            let line = format!("{kind} {what}: {c}");
            if !c.is_empty() && !conversions.contains(&line) {
                conversions.push(line);
            }
        }
    }
    if !conversions.is_empty() {
        writeln!(out, "\nconversions (f = {} Hz):", num(report.freq_hz))?;
        for c in &conversions {
            writeln!(out, "  {c}")?;
        }
    }
    Ok(())
}

/// The axis against its datasheet, one line per term: the datasheet value (as given and SI),
/// the measured one in the datasheet's unit with its interval, the ratio and the verdict.
fn datasheet_lines(d: &DatasheetComparison, out: &mut impl Write) -> Result<()> {
    for t in d.terms() {
        // the datasheet's number as given
        let sheet = format!("{} {} = {} {}", t.value, t.unit, num(t.value_si), t.unit_si);
        let measured = match (t.measured_si, t.ci_low_si, t.ci_high_si) {
            (None, ..) => "not measured".to_string(),
            (Some(m), ..) if t.upper_bound => format!(
                "measured <= {} {} (upper bound), ratio <= {}",
                num(t.in_datasheet_unit(m)),
                t.unit,
                t.ratio.map_or_else(|| "-".to_string(), num)
            ),
            (Some(m), Some(lo), Some(hi)) => format!(
                "measured {} [{}, {}] {}, ratio {}",
                num(t.in_datasheet_unit(m)),
                num(t.in_datasheet_unit(lo)),
                num(t.in_datasheet_unit(hi)),
                t.unit,
                t.ratio.map_or_else(|| "-".to_string(), num)
            ),
            (Some(m), ..) => format!(
                "measured {} {}, ratio {}",
                num(t.in_datasheet_unit(m)),
                t.unit,
                t.ratio.map_or_else(|| "-".to_string(), num)
            ),
        };
        writeln!(
            out,
            "  {:<18}{sheet}; {measured}; {}",
            format!("datasheet {}", t.key),
            t.verdict_text()
        )?;
    }
    Ok(())
}

/// The self-audit of an axis: per number, the calibration's and the IEEE read-off's bias and
/// spread, and the coverage of the calibration's intervals.
fn audit_lines(au: &gmwm::Audit, out: &mut impl Write) -> Result<()> {
    let pct = |x: f64| {
        if x.is_finite() {
            format!("{:+.1}%", 100.0 * x)
        } else {
            "-".into()
        }
    };
    writeln!(
        out,
        "  {:<18}{} simulated recordings of the identified model: same canonical model in {:.0}%{}",
        "self-audit",
        au.replicates,
        100.0 * au.same_model,
        if au.failed > 0 {
            format!(", {} failed", au.failed)
        } else {
            String::new()
        }
    )?;
    for q in &au.quantities {
        let coverage = match q.gmwm.coverage {
            Some(c) => format!(
                "interval covers {:.0}% ({} of {})",
                100.0 * c,
                (c * q.gmwm.intervals as f64).round(),
                q.gmwm.intervals
            ),
            None => "no intervals".into(),
        };
        let ieee = match &q.ieee {
            Some(i) => format!(
                "IEEE bias {}, spread {}",
                pct(i.bias),
                pct(i.spread).trim_start_matches('+')
            ),
            None => "IEEE -".into(),
        };
        writeln!(
            out,
            "    {} {}: GMWM bias {}, spread {}, {coverage} | {ieee}",
            q.name,
            num(q.target),
            pct(q.gmwm.bias),
            pct(q.gmwm.spread).trim_start_matches('+'),
        )?;
    }
    Ok(())
}

fn axis_block(a: &AxisCalibration, out: &mut impl Write) -> Result<()> {
    writeln!(out)?;
    let unit_note = match (&a.data_unit, a.unit.as_str()) {
        (_, "u") => ", unit not known: results in the data unit u".to_string(),
        (Some(d), u) if d != u => format!(", data in {d} converted to {u}"),
        _ => String::new(),
    };
    let fitted = if a.model == a.canonical_model {
        String::new()
    } else if a.identified_model == a.model {
        format!(" (fitted as {})", a.model)
    } else {
        format!(
            " (selected {}; estimates from its reduced model {})",
            a.model, a.identified_model
        )
    };
    writeln!(
        out,
        "{}: {}{fitted}{unit_note}",
        a.column, a.canonical_model
    )?;
    let line = |label: &str, e: &Option<Estimate>| match e {
        Some(e) => format!("  {label:<18}{}", estimate_line(e)),
        None => format!("  {label:<18}- (no such term)"),
    };
    writeln!(out, "{}", line("noise density", &a.noise_density))?;
    match &a.bias_instability {
        Some(_) => writeln!(out, "{}", line("bias instability", &a.bias_instability))?,
        None => writeln!(
            out,
            "  {:<18}- ({})",
            "bias instability",
            a.ieee
                .b
                .note
                .as_deref()
                .unwrap_or("no minimum of the Allan deviation observed")
        )?,
    }
    writeln!(out, "{}", line("random walk", &a.random_walk))?;
    if let Some(h) = &a.horizon {
        let times = |f: Option<f64>| f.map_or_else(|| "-".to_string(), |f| format!("x{}", num(f)));
        writeln!(
            out,
            "  {:<18}N {} {}/sqrt(Hz) ({}), K {} {}*sqrt(Hz) ({}): bounds the model up to {} s; at {} s its integrated-error variance is {}x the model's",
            format!("horizon {} s", num(h.horizon_s)),
            num(h.noise_density),
            a.unit,
            times(h.noise_inflation),
            num(h.random_walk),
            a.unit,
            times(h.random_walk_inflation),
            num(h.horizon_s),
            num(h.horizon_s),
            num(h.excess_at_horizon)
        )?;
    }
    if let Some(au) = &a.audit {
        audit_lines(au, out)?;
    }
    if let Some(g) = &a.gauss_markov_bias {
        writeln!(
            out,
            "  {:<18}T = {} s [{}], sigma = {}",
            "Gauss-Markov bias",
            num(g.correlation_time.value),
            match (g.correlation_time.ci_low, g.correlation_time.ci_high) {
                (Some(lo), Some(hi)) => format!("{}, {}", num(lo), num(hi)),
                _ => "no interval".into(),
            },
            estimate_line(&g.sigma)
        )?;
    }
    let discrete = |e: &Option<Estimate>| {
        e.as_ref()
            .and_then(|e| e.forms.as_ref())
            .and_then(|f| f.discrete.as_ref())
            .map(|d| format!("{} {}", num(d.value), d.unit))
    };
    if let (Some(n), k) = (discrete(&a.noise_density), discrete(&a.random_walk)) {
        writeln!(
            out,
            "  {:<18}white-noise sd {n} per sample{}",
            "discrete",
            k.map(|k| format!(", random-walk step sd {k}"))
                .unwrap_or_default()
        )?;
    }
    if let Some(q) = &a.quantization {
        writeln!(out, "  {:<18}{}", "quantization", estimate_line(q))?;
    }
    if let Some(r) = &a.rate_ramp {
        writeln!(out, "  {:<18}{}", "rate ramp", estimate_line(r))?;
    }
    // a periodic (vibration) term: its frequency and amplitude, as the canonical model reads them
    for t in &a.canonical.terms {
        let value = |name: &str| t.physical.iter().find(|p| p.name == name).map(|p| p.value);
        if let (Some(f), Some(amp)) = (value("frequency"), value("amplitude")) {
            writeln!(
                out,
                "  {:<18}{} Hz, amplitude {} {} ({} term)",
                "vibration",
                num(f),
                num(amp),
                a.unit,
                t.process.split('(').next().unwrap_or_default()
            )?;
        }
    }
    let ieee: Vec<String> = a
        .ieee
        .rows()
        .iter()
        .map(|(sym, term, r)| match r.value {
            Some(v) => format!(
                "{sym} = {} {}",
                num(v),
                gmwm::si_unit(*term, a.kind.filter(|_| a.unit != "u"), &a.unit)
            ),
            None => format!("{sym} = -"),
        })
        .collect();
    writeln!(out, "  {:<18}{}", "IEEE 952", ieee.join(", "))?;
    if let Some(d) = &a.datasheet {
        datasheet_lines(d, out)?;
    }
    writeln!(out, "  {:<18}{}", "fit", a.verdict.summary)?;
    if let Some(c) = a.contamination.as_ref().filter(|c| c.matters) {
        writeln!(out, "  {:<18}{}", "contamination", c.summary)?;
    }
    for n in &a.notes {
        writeln!(out, "  note: {n}")?;
    }
    Ok(())
}
