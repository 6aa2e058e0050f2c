//! Batch mode of `gmwm calibrate` and `gmwm wv`: many recordings in one command.
//!
//! The FILE arguments (recordings, folders, quoted globs) are expanded into recordings; each
//! gets its outputs under its stem (the file name without its data extensions) in `--out-dir`
//! or beside it; recordings run in parallel, each with the single-file code path, and one
//! summary (a table, or JSON) follows. A recording whose every output exists and is newer than
//! it and its sidecar is skipped as up to date (`--force` redoes it); outputs are written
//! atomically (a temporary file renamed), so an interrupted run leaves no partial output that
//! a later run would take as up to date. A failure is reported by name with the one-line
//! message a single run prints, after all the others completed; the exit code is then 1.

use super::calibrate::{execute_in, per_axis_path, Calibrated, Mode};
use super::Command;
use crate::config::{BatchConfig, BatchJob, CalibrateConfig, WvConfig};
use crate::error::UsageError;
use crate::prepare::{warn_implausible, Inputs};
use crate::recordings::{expand, key, sidecar_of, Found};
use crate::render::Style;
use crate::style::OutputStyle;
use anyhow::{Context, Result};
use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::SystemTime;

/// Data extensions stripped from a file name to give its stem (`imu1.csv.gz` → `imu1`).
const DATA_EXTENSIONS: &[&str] = &[
    "gz", "csv", "tsv", "txt", "dat", "bin", "raw", "f64", "f32", "f64le", "f32le", "bag", "mcap",
    "db3",
];

/// The stem of a recording: its file (or rosbag2 folder) name without its data extensions,
/// stripped from the right (`imu1.csv.gz` → `imu1`, `log.f64le.bin` → `log`, `run` → `run`).
pub fn stem(path: &Path) -> String {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "recording".to_string());
    let mut stem = name.as_str();
    while let Some((head, ext)) = stem.rsplit_once('.') {
        if head.is_empty() || !DATA_EXTENSIONS.contains(&ext.to_ascii_lowercase().as_str()) {
            break;
        }
        stem = head;
    }
    stem.to_string()
}

/// One recording of the batch and where its outputs go.
#[derive(Debug, Clone)]
struct Planned {
    /// The recording.
    recording: PathBuf,
    /// Its outputs' folder.
    dir: PathBuf,
    /// Its stem.
    stem: String,
}

impl Planned {
    /// `DIR/STEM.suffix`.
    fn output(&self, suffix: &str) -> PathBuf {
        self.dir.join(format!("{}.{suffix}", self.stem))
    }
}

/// The files a recording writes, known before it runs (a per-axis export adds its axis
/// letters to these names).
fn declared_outputs(job: &BatchJob, p: &Planned) -> Vec<PathBuf> {
    match job {
        BatchJob::Calibrate { config, .. } => {
            let mut out: Vec<PathBuf> = config
                .exports
                .iter()
                .map(|(_, f)| p.output(&f.to_string_lossy()))
                .collect();
            if let Some(r) = &config.report {
                out.push(p.output(&r.to_string_lossy()));
            }
            out.push(p.output("calibration.json"));
            out
        }
        BatchJob::Wv { .. } => vec![p.output("wv.json")],
    }
}

/// The recordings with their output folders; a recording a folder or glob found that is
/// another's output is dropped; two recordings writing the same file, or a named recording
/// that another would overwrite, are refused in one line.
fn plan(config: &BatchConfig, found: Vec<Found>) -> Result<Vec<Planned>> {
    let planned: Vec<(Planned, bool)> = found
        .into_iter()
        .map(|f| {
            let dir = match &config.out_dir {
                Some(d) => d.clone(),
                None => match f.path.parent() {
                    Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
                    _ => PathBuf::from("."),
                },
            };
            let p = Planned {
                stem: stem(&f.path),
                recording: f.path,
                dir,
            };
            (p, f.named)
        })
        .collect();
    let mut writers: HashMap<PathBuf, usize> = HashMap::new();
    for (i, (p, _)) in planned.iter().enumerate() {
        for o in declared_outputs(&config.job, p) {
            if let Some(&j) = writers.get(&key(&o)) {
                if j != i {
                    return Err(UsageError(format!(
                        "{} and {} both write {}: rename one or give them separate --out-dir",
                        planned[j].0.recording.display(),
                        p.recording.display(),
                        o.display()
                    ))
                    .into());
                }
            }
            writers.insert(key(&o), i);
        }
    }
    let mut kept = Vec::new();
    for (i, (p, named)) in planned.iter().enumerate() {
        match writers.get(&key(&p.recording)) {
            Some(&j) if j != i && *named => {
                return Err(UsageError(format!(
                    "{} is an output of {}: it would be overwritten",
                    p.recording.display(),
                    planned[j].0.recording.display()
                ))
                .into())
            }
            // gmwm's own output found by a folder or glob
            Some(&j) if j != i => {}
            _ => kept.push(p.clone()),
        }
    }
    Ok(kept)
}

/// The modification time that outputs must be newer than: the recording's (the newest file
/// of a rosbag2 folder) and its sidecar's.
fn input_time(path: &Path) -> Option<SystemTime> {
    let mtime = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    let own = if path.is_dir() {
        std::fs::read_dir(path)
            .ok()?
            .filter_map(|e| e.ok())
            .filter_map(|e| mtime(&e.path()))
            .max()
    } else {
        mtime(path)
    }?;
    Some(match sidecar_of(path).and_then(|s| mtime(&s)) {
        Some(t) => own.max(t),
        None => own,
    })
}

/// Every output exists and is newer than the recording and its sidecar.
fn all_newer(outputs: &[PathBuf], since: Option<SystemTime>) -> bool {
    let Some(since) = since else {
        return false;
    };
    outputs.iter().all(|o| {
        std::fs::metadata(o)
            .and_then(|m| m.modified())
            .is_ok_and(|t| t > since)
    })
}

/// Reads a JSON output, `None` when it is missing or unreadable.
fn read_json(path: &Path) -> Option<serde_json::Value> {
    serde_json::from_slice(&std::fs::read(path).ok()?).ok()
}

/// How a recording ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Status {
    /// Computed now.
    Done,
    /// Skipped: its outputs are newer than it.
    UpToDate,
    /// Failed, with its message.
    Failed,
}

/// What the summary shows of a recording beyond its status.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
struct Detail {
    /// calibrate: axes calibrated; wv: series.
    count: Option<usize>,
    /// calibrate: axes whose model explains the WV; wv: the most levels of a series.
    second: Option<usize>,
    /// calibrate with `--datasheet`: the datasheet values by verdict over the axes.
    datasheet: Option<DatasheetCounts>,
}

/// A calibration's datasheet values by verdict (`axes[].datasheet.*.verdict`): as specified
/// (inside the measured interval), better, worse, and without a verdict.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
struct DatasheetCounts {
    inside: usize,
    better: usize,
    worse: usize,
    no_verdict: usize,
}

impl DatasheetCounts {
    /// The counts of a calibration document; `None` when no axis was compared.
    fn of(doc: &serde_json::Value) -> Option<Self> {
        let mut c = Self::default();
        let mut any = false;
        for axis in doc["axes"].as_array()? {
            let Some(terms) = axis["datasheet"].as_object() else {
                continue;
            };
            for term in terms.values() {
                any = true;
                match term["verdict"].as_str() {
                    Some("inside") => c.inside += 1,
                    Some("above") => c.better += 1,
                    Some("below") => c.worse += 1,
                    _ => c.no_verdict += 1,
                }
            }
        }
        any.then_some(c)
    }

    fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "as_specified": self.inside,
            "better": self.better,
            "worse": self.worse,
            "no_verdict": self.no_verdict,
        })
    }
}

impl std::fmt::Display for DatasheetCounts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} as specified, {} better, {} worse",
            self.inside, self.better, self.worse
        )?;
        if self.no_verdict > 0 {
            write!(f, ", {} no verdict", self.no_verdict)?;
        }
        Ok(())
    }
}

/// A recording's outcome.
#[derive(Debug, Clone)]
struct Outcome {
    file: PathBuf,
    status: Status,
    outputs: Vec<PathBuf>,
    error: Option<String>,
    detail: Detail,
}

/// The calibration of one recording of the batch, or `Ok` of an up-to-date one.
fn calibrate_one(
    config: &CalibrateConfig,
    p: &Planned,
    force: bool,
    style: OutputStyle,
) -> Result<(Status, Vec<PathBuf>, Detail)> {
    let json = p.output("calibration.json");
    let report = config
        .report
        .as_ref()
        .map(|r| p.output(&r.to_string_lossy()));
    let exports: Vec<_> = config
        .exports
        .iter()
        .map(|(f, name)| (*f, p.output(&name.to_string_lossy())))
        .collect();
    if !force {
        // the JSON, written last, names the export sets (per-axis letters) and the verdicts
        if let Some(doc) = read_json(&json) {
            let labels: Vec<String> = doc["exported"]
                .as_array()
                .map(|sets| {
                    sets.iter()
                        .map(|s| s["label"].as_str().unwrap_or_default().to_string())
                        .collect()
                })
                .unwrap_or_default();
            let mut outputs: Vec<PathBuf> = exports
                .iter()
                .flat_map(|(_, path)| labels.iter().map(|l| per_axis_path(path, l)))
                .collect();
            outputs.extend(report.clone());
            outputs.push(json.clone());
            let axes = doc["axes"].as_array();
            let known = exports.is_empty() || !labels.is_empty();
            // a document without the datasheet now given (or with one no longer given) is
            // redone, so that the row's counts are the flags'
            let sheet = config.options.datasheet.is_some() == DatasheetCounts::of(&doc).is_some();
            if known && sheet && all_newer(&outputs, input_time(&p.recording)) {
                let detail = Detail {
                    count: axes.map(Vec::len),
                    second: axes.map(|a| {
                        a.iter()
                            .filter(|x| x["verdict"]["explains_wv"].as_bool() == Some(true))
                            .count()
                    }),
                    datasheet: DatasheetCounts::of(&doc),
                };
                return Ok((Status::UpToDate, outputs, detail));
            }
        }
    }
    let mut one = config.clone();
    one.input.file = p.recording.clone();
    // the single-file command's warning on raw floats no sensor gives, per recording
    warn_implausible(&one.input);
    one.exports = exports;
    one.json = Some(json);
    let mode = Mode {
        print_summary: false,
        style,
    };
    let Calibrated {
        axes,
        explained,
        written,
    } = execute_in(&one, report.as_deref(), mode, &mut std::io::sink())?;
    let detail = Detail {
        count: Some(axes),
        second: Some(explained),
        // the document just written carries the comparison
        datasheet: one
            .json
            .as_deref()
            .and_then(read_json)
            .and_then(|doc| DatasheetCounts::of(&doc)),
    };
    Ok((Status::Done, written, detail))
}

/// Series count and the most levels of a `gmwm wv --json` document.
fn wv_detail(doc: &serde_json::Value) -> Option<Detail> {
    let series = doc["series"].as_array()?;
    Some(Detail {
        count: Some(series.len()),
        second: series
            .iter()
            .filter_map(|s| s["wv"].as_array().map(Vec::len))
            .max(),
        datasheet: None,
    })
}

/// The wavelet variance of one recording of the batch, or `Ok` of an up-to-date one.
fn wv_one(
    config: &WvConfig,
    p: &Planned,
    force: bool,
    style: OutputStyle,
) -> Result<(Status, Vec<PathBuf>, Detail)> {
    let out = p.output("wv.json");
    let outputs = vec![out.clone()];
    if !force && all_newer(&outputs, input_time(&p.recording)) {
        if let Some(detail) = read_json(&out).as_ref().and_then(wv_detail) {
            return Ok((Status::UpToDate, outputs, detail));
        }
    }
    let mut one = config.clone();
    one.input.file = p.recording.clone();
    warn_implausible(&one.input);
    one.output = Style::Json;
    let items = super::wv::compute(&one, style)?;
    let mut doc = Vec::new();
    crate::render::series(&mut doc, &crate::input::named(&items), Style::Json)?;
    crate::output::write(&out, &doc)?;
    let detail = Detail {
        count: Some(items.len()),
        second: items.iter().map(|(_, wv)| wv.wv().len()).max(),
        datasheet: None,
    };
    Ok((Status::Done, outputs, detail))
}

/// Runs one recording; a failure (or a panic) becomes its outcome, never the batch's.
/// `style` has no progress bar: the batch's is the one.
fn run_one(config: &BatchConfig, p: &Planned, style: OutputStyle) -> Outcome {
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| match &config.job {
        BatchJob::Calibrate { config: c, .. } => calibrate_one(c, p, config.force, style),
        BatchJob::Wv { config: c, .. } => wv_one(c, p, config.force, style),
    }))
    .unwrap_or_else(|payload| {
        Err(anyhow::anyhow!(
            "internal error: panicked: {} (a bug: please report it with the command and this input)",
            crate::panic::describe(payload.as_ref())
        ))
    });
    match result {
        Ok((status, outputs, detail)) => Outcome {
            file: p.recording.clone(),
            status,
            outputs,
            error: None,
            detail,
        },
        Err(e) => Outcome {
            file: p.recording.clone(),
            status: Status::Failed,
            outputs: Vec::new(),
            error: Some(crate::error::one_line(&e)),
            detail: Detail::default(),
        },
    }
}

/// The words of a job: its verb, its done status and its detail columns.
struct Words {
    verb: &'static str,
    done: &'static str,
    columns: [&'static str; 2],
    keys: [&'static str; 2],
}

fn words(job: &BatchJob) -> Words {
    match job {
        BatchJob::Calibrate { .. } => Words {
            verb: "calibrating",
            done: "calibrated",
            columns: ["axes", "fit ok"],
            keys: ["axes", "axes_fit_ok"],
        },
        BatchJob::Wv { .. } => Words {
            verb: "wavelet variance",
            done: "computed",
            columns: ["series", "levels"],
            keys: ["series", "levels"],
        },
    }
}

impl Command for BatchConfig {
    fn inputs(&mut self) -> Inputs<'_> {
        Inputs::Files {
            paths: &self.inputs,
            refusal: "batch mode (several FILEs, a folder, --out-dir, --force) reads files; \
                      give standard input or a pipe alone, without --out-dir/--force",
        }
    }

    fn outputs(&self) -> Vec<&Path> {
        // each recording's, planned once the inputs are expanded (see `plan`)
        Vec::new()
    }

    fn levels(&self) -> Option<usize> {
        // each recording's error is its row of the summary
        None
    }

    fn run(&self, style: OutputStyle, mut out: &mut dyn Write) -> Result<()> {
        run(self, style, &mut out)
    }
}

/// Runs the batch: expands the inputs, runs every recording in parallel (workers pull the
/// next recording; each one's own computation is parallel on the shared rayon pool), prints
/// the summary; an error naming the failed recordings when any failed.
fn run(config: &BatchConfig, style: OutputStyle, out: &mut impl Write) -> Result<()> {
    let format = match &config.job {
        BatchJob::Calibrate { config, .. } => config.input.read.format,
        BatchJob::Wv { config, .. } => config.input.read.format,
    };
    let planned = plan(config, expand(&config.inputs, format)?)?;
    if let Some(dir) = &config.out_dir {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create --out-dir {}", dir.display()))?;
    }
    let w = words(&config.job);
    let progress = style.bar(planned.len() as u64, w.verb, "recordings");
    let outcomes: Vec<Mutex<Option<Outcome>>> = planned.iter().map(|_| Mutex::new(None)).collect();
    let next = AtomicUsize::new(0);
    // workers that are not rayon threads: a rayon worker waiting inside a calibration would
    // steal the next recording, loading more recordings at once than there are workers
    let workers = rayon::current_num_threads().clamp(1, planned.len().max(1));
    std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(p) = planned.get(i) else {
                    break;
                };
                let outcome = run_one(config, p, style.without_progress());
                if let Some(e) = &outcome.error {
                    let file = p.recording.display().to_string();
                    progress.suspend(|| {
                        if e.contains(&file) {
                            eprintln!("gmwm: error: {e}");
                        } else {
                            eprintln!("gmwm: error: {file}: {e}");
                        }
                    });
                }
                if let Ok(mut slot) = outcomes[i].lock() {
                    *slot = Some(outcome);
                }
                progress.inc(1);
            });
        }
    });
    progress.finish_and_clear();
    let outcomes: Vec<Outcome> = outcomes
        .into_iter()
        .filter_map(|m| m.into_inner().ok().flatten())
        .collect();
    let json_to = match &config.job {
        BatchJob::Calibrate { json, .. } => json.clone(),
        BatchJob::Wv { json: true, .. } => Some(PathBuf::from("-")),
        BatchJob::Wv { json: false, .. } => None,
    };
    let spread = match &config.job {
        BatchJob::Calibrate { .. } => spread_of(&outcomes),
        BatchJob::Wv { .. } => None,
    };
    let summary = || {
        let mut v = summary_json(&outcomes, &w);
        if let Some(s) = &spread {
            v["spread"] = serde_json::to_value(s).unwrap_or_default();
        }
        v
    };
    match json_to.as_deref() {
        Some(p) if p == Path::new("-") => {
            serde_json::to_writer_pretty(&mut *out, &summary())?;
            writeln!(out)?;
        }
        Some(p) => {
            table(&outcomes, &w, out)?;
            spread_table(spread.as_ref(), out)?;
            let mut text = serde_json::to_vec_pretty(&summary())?;
            text.push(b'\n');
            crate::output::write(p, &text)?;
            writeln!(out, "wrote {} (JSON summary)", p.display())?;
        }
        None => {
            table(&outcomes, &w, out)?;
            spread_table(spread.as_ref(), out)?;
        }
    }
    out.flush()?;
    let failed: Vec<String> = outcomes
        .iter()
        .filter(|o| o.status == Status::Failed)
        .map(|o| o.file.display().to_string())
        .collect();
    if !failed.is_empty() {
        let mut names = failed
            .iter()
            .take(3)
            .cloned()
            .collect::<Vec<_>>()
            .join(", ");
        if failed.len() > 3 {
            names.push_str(", ...");
        }
        anyhow::bail!(
            "{} of {} recordings failed: {names}",
            failed.len(),
            outcomes.len()
        );
    }
    Ok(())
}

/// The spread of N, B, K across the calibrated recordings (their calibration documents),
/// `None` with fewer than two.
fn spread_of(outcomes: &[Outcome]) -> Option<gmwm::SpreadAcross> {
    let mut axes = Vec::new();
    for o in outcomes.iter().filter(|o| o.status != Status::Failed) {
        let Some(doc) = o
            .outputs
            .iter()
            .find(|p| p.to_string_lossy().ends_with("calibration.json"))
            .and_then(|p| read_json(p))
        else {
            continue;
        };
        axes.extend(gmwm::RecordedAxis::from_calibration(&stem(&o.file), &doc));
    }
    let spread = gmwm::spread_across(&axes);
    (spread.recordings >= 2).then_some(spread)
}

/// The spread across recordings, after the batch table.
fn spread_table(spread: Option<&gmwm::SpreadAcross>, out: &mut impl Write) -> Result<()> {
    let Some(s) = spread else { return Ok(()) };
    writeln!(
        out,
        "\nacross {} recordings of one sensor (median, range, relative spread):",
        s.recordings
    )?;
    for r in &s.rows {
        writeln!(
            out,
            "  {:<10}{} {:.3e} {}  [{:.3e} .. {:.3e}]  spread {:.0}%{}",
            r.column,
            r.quantity,
            r.median,
            r.unit,
            r.min,
            r.max,
            100.0 * r.spread,
            if r.bounds > 0 {
                format!(" ({} of {} upper bounds)", r.bounds, r.recordings)
            } else {
                String::new()
            }
        )?;
    }
    for w in &s.warnings {
        writeln!(out, "  warning: {w}")?;
    }
    Ok(())
}

/// `N recordings: a calibrated, b up to date, c failed`.
fn counts_line(outcomes: &[Outcome], w: &Words) -> String {
    let n = |s: Status| outcomes.iter().filter(|o| o.status == s).count();
    format!(
        "{} recording{}: {} {}, {} up to date, {} failed",
        outcomes.len(),
        if outcomes.len() == 1 { "" } else { "s" },
        n(Status::Done),
        w.done,
        n(Status::UpToDate),
        n(Status::Failed)
    )
}

/// The summary table: one row per recording (file, status, the job's two counts, the main
/// output), a failure's message in place of the counts, then the counts.
fn table(outcomes: &[Outcome], w: &Words, out: &mut impl Write) -> Result<()> {
    let status = |o: &Outcome| match o.status {
        Status::Done => w.done,
        Status::UpToDate => "up to date",
        Status::Failed => "failed",
    };
    let cell = |v: Option<usize>| v.map(|v| v.to_string()).unwrap_or_else(|| "-".into());
    let files: Vec<String> = outcomes
        .iter()
        .map(|o| o.file.display().to_string())
        .collect();
    let fw = files
        .iter()
        .map(|f| f.chars().count())
        .max()
        .unwrap_or(0)
        .max(9);
    let sw = outcomes
        .iter()
        .map(|o| status(o).len())
        .max()
        .unwrap_or(0)
        .max(6);
    let c0 = w.columns[0].len();
    let c1 = w.columns[1].len();
    // a datasheet column when a datasheet was compared
    let sheet: Vec<String> = outcomes
        .iter()
        .map(|o| {
            o.detail
                .datasheet
                .map(|d| d.to_string())
                .unwrap_or_default()
        })
        .collect();
    let dw = sheet.iter().map(String::len).max().unwrap_or(0);
    let sheet_head = if dw > 0 {
        format!("{:<dw$}  ", "datasheet")
    } else {
        String::new()
    };
    let dw = dw.max(if dw > 0 { 9 } else { 0 });
    writeln!(
        out,
        "{:<fw$}  {:<sw$}  {:>c0$}  {:>c1$}  {sheet_head}output",
        "recording", "status", w.columns[0], w.columns[1]
    )?;
    for ((o, file), d) in outcomes.iter().zip(&files).zip(&sheet) {
        let d = if dw > 0 {
            format!("{d:<dw$}  ")
        } else {
            String::new()
        };
        match &o.error {
            Some(e) => writeln!(out, "{file:<fw$}  {:<sw$}  {e}", status(o))?,
            None => writeln!(
                out,
                "{file:<fw$}  {:<sw$}  {:>c0$}  {:>c1$}  {d}{}",
                status(o),
                cell(o.detail.count),
                cell(o.detail.second),
                o.outputs
                    .last()
                    .map(|p| p.display().to_string())
                    .unwrap_or_default()
            )?,
        }
    }
    writeln!(out, "{}", counts_line(outcomes, w))?;
    Ok(())
}

/// The summary as JSON: `{"recordings": [{file, status, outputs, error, <counts>}],
/// "counts": {total, <done>, up_to_date, failed}}`.
fn summary_json(outcomes: &[Outcome], w: &Words) -> serde_json::Value {
    let rows: Vec<serde_json::Value> = outcomes
        .iter()
        .map(|o| {
            let mut row = serde_json::Map::new();
            row.insert("file".into(), o.file.display().to_string().into());
            row.insert(
                "status".into(),
                match o.status {
                    Status::Done => w.done,
                    Status::UpToDate => "up_to_date",
                    Status::Failed => "failed",
                }
                .into(),
            );
            row.insert(
                "outputs".into(),
                o.outputs
                    .iter()
                    .map(|p| serde_json::Value::from(p.display().to_string()))
                    .collect(),
            );
            row.insert("error".into(), o.error.clone().into());
            row.insert(w.keys[0].into(), o.detail.count.into());
            row.insert(w.keys[1].into(), o.detail.second.into());
            if let Some(d) = o.detail.datasheet {
                row.insert("datasheet".into(), d.json());
            }
            serde_json::Value::Object(row)
        })
        .collect();
    let n = |s: Status| outcomes.iter().filter(|o| o.status == s).count();
    serde_json::json!({
        "recordings": rows,
        "counts": {
            "total": outcomes.len(),
            w.done: n(Status::Done),
            "up_to_date": n(Status::UpToDate),
            "failed": n(Status::Failed),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stems_drop_data_extensions() {
        for (name, s) in [
            ("runs/imu1.csv.gz", "imu1"),
            ("a.b.f64le.bin", "a.b"),
            ("run.bag", "run"),
            ("rosbag2_x", "rosbag2_x"),
            ("x.TSV", "x"),
            (".csv", ".csv"),
            ("x.wv.json", "x.wv.json"),
        ] {
            assert_eq!(stem(Path::new(name)), s, "{name}");
        }
    }
}
