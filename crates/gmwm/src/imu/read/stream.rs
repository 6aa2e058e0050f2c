//! Streamed readers of text (CSV/TSV, plain or gzip), binary IMU records and ROS recordings'
//! IMU topics ([`StreamedTable::open_recording`]; the ROS reader in `read::ros_stream`, its
//! messages put in log-time order by a bounded reorder buffer): one pass over the
//! file through the in-memory readers' own parser (`text::for_each_text_row`, the
//! record decoding of `binary`), the selected columns written as raw little-endian
//! f64 to a spool file (deleted when the [`StreamedTable`] is dropped) that the streamed
//! wavelet variance reads like any raw binary recording
//! (`variance::binary_columns_wv`), and the time column checked as it goes by.
//!
//! Why a spool: the Haar wavelet variance at level j needs the samples `2^j` back, and the
//! levels above 20 of the streamed pass read them back from the file (the rings would
//! otherwise be `8 · 2^J` bytes a column: 64 MB at 10^7 rows); a text or gzip stream cannot be
//! read back, its raw f64 copy can, by several threads at once. The spool takes
//! `8 · columns · rows` bytes of disk in [`std::env::temp_dir`] (`TMPDIR`), none of memory.
//!
//! The time column: `timing::StepStats` gives the report of `check_times` bit for bit without
//! holding the stamps, from the distinct steps and the largest ones. When its bounds are
//! passed (more than `STREAM_DISTINCT_STEPS`
//! distinct steps, or more gaps than it holds), or when the unit of the stamps must be
//! inferred from their steps (not stated by the name, `--time-unit` or an epoch-sized first
//! stamp), the stamps, spooled too, are read back and checked in memory (8 bytes a row), and
//! [`StreamedTable::notes`] says so.
//!
//! The values, the selection, the errors (with file and line), the time report and the rate
//! are those of [`read_table`](super::read_table) on the same file (tests:
//! `crates/gmwm/src/tests/streamed.rs`); the WVs equal the in-memory ones within 1e-12 (the same
//! values, the squares summed in another grouping).
//!
//! Cost (measured on a busy 2-core machine, indicative, `gmwm wv FILE --json` on a CSV of a
//! `time [s]` column and six columns at 200 Hz, streamed with `--stream-from 1` against the
//! in-memory reader, back to back): 10^6 rows, 35 MB peak RSS against 79 MB, 0.70 s against
//! 0.73 s (plain), 1.05 s against 1.01 s (gzip); 10^7 rows, 77 MB against 711 MB, 9.3 s
//! against 6.7 s (plain, 690 MB), 13.1 s against 10.1 s (gzip, 270 MB). The RSS grows from
//! 10^6 to 10^7 rows mostly by the rings of levels 19 and 20 of the WV (8 MiB a column at
//! most, `variance::binary_wavelet_variance`); at 3·10^7
//! rows (gzip, 806 MB) it is 98 MB (44 s), where the in-memory reader would hold 1.4 GB of
//! columns. The time is the one parse of the in-memory reader, plus writing and reading the
//! spool.

use super::binary::{
    decode, decode_i32, for_each_record_run, non_finite, open_records, record_selection,
    RECORD_COLUMNS,
};
use super::text::for_each_text_row;
use super::{
    resolve_format, resolve_rate, timing_warnings, BinaryLayout, InputFormat, ReadOptions,
    TableFacts,
};
use crate::error::ParamError;
use crate::imu::sidecar::{find_sidecar, Sidecar};
use crate::imu::timing::{check_times, infer_unit, StepStats, TimeUnit, TimingReport, UnitSource};
use crate::imu::{ImuRecordType, Probe, ReadError, SampleAccount};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// A text or IMU-record recording read in one pass and spooled (module docs): what
/// [`read_table`](super::read_table) says of it, and its columns for the streamed wavelet
/// variance, in memory bounded whatever its length.
///
/// ```no_run
/// use gmwm::StreamedTable;
/// let table = StreamedTable::open("imu.csv.gz".as_ref(), &Default::default())?;
/// let wvs = table.wavelet_variance(table.facts.freq_hz.unwrap_or(1.0), &Default::default())?;
/// println!("{} rows, {:?}", table.rows, wvs[0].wv());
/// # Ok::<(), gmwm::ReadError>(())
/// ```
#[derive(Debug)]
pub struct StreamedTable {
    /// What the reader found out besides the samples, as [`read_table`](super::read_table)
    /// finds it.
    pub facts: TableFacts,
    /// Names of the selected columns, in order (as [`Table::columns`](super::Table)).
    pub names: Vec<String>,
    /// Rows (samples per column).
    pub rows: u64,
    /// What the streamed reader did that the in-memory one does not (the stamps checked in
    /// memory beyond the bounds of the streamed check), one line each. For a ROS recording,
    /// every note of [`Recording::notes`](crate::imu::Recording) (the topic, the timing, the
    /// samples' account), then the streamed reader's own.
    pub notes: Vec<String>,
    /// The `sensor_msgs/Imu` topic, for a ROS recording.
    pub topic: Option<String>,
    /// The container, for a ROS recording.
    pub container: Option<crate::imu::ros::RosContainer>,
    spool: Spool,
}

/// Whether `path` is read by [`StreamedTable::open_recording`]: text or binary IMU records (by
/// `opts.format`, the name, the sidecar or the content) or a ROS recording (format `auto`);
/// `Ok(None)` for other files (raw binary, which streams as it is), else the file's size in
/// bytes (0 for a rosbag2 folder).
///
/// # Errors
/// As [`resolve_format`].
pub(crate) fn streamed_size(probe: &Probe, opts: &ReadOptions) -> Result<Option<u64>, ReadError> {
    let path = probe.path();
    if probe.is_ros() {
        return Ok(Some(std::fs::metadata(path).map_or(0, |m| m.len())));
    }
    if probe.is_container_or_folder() {
        return Ok(None);
    }
    let sidecar = find_sidecar(path)?;
    let format = resolve_format(path, opts.format, sidecar.as_ref())?;
    if format.value_width().is_some() {
        return Ok(None);
    }
    let size = std::fs::metadata(path)
        .map_err(|source| ReadError::Io {
            path: path.to_path_buf(),
            source,
        })?
        .len();
    Ok(Some(size))
}

/// Rows of a file at least `stream_from` rows long when the file is streamed: for binary IMU
/// records the exact count (the size over the record's), for text, whose rows are known only
/// once read, the file's size in bytes over 8 (a text row of numbers takes more than 8 bytes
/// a column, so this is never below what the rule means for raw f64: a text file of
/// `stream_from` rows streams), and for a gzip file its lines counted as they decompress, up
/// to `stream_from`; for a ROS recording, the messages of its largest IMU topic
/// (`imu_messages_count`, from the index or the
/// statistics).
///
/// # Errors
/// As `streamed_size`; for a ROS recording, as
/// [`list_topics`](crate::imu::ros::list_topics).
pub fn streams_from(
    probe: &Probe,
    opts: &ReadOptions,
    stream_from: u64,
) -> Result<bool, ReadError> {
    let path = probe.path();
    if probe.is_ros() {
        let rows = crate::imu::ros::imu_messages_count(path)?;
        return Ok(rows > 0 && rows >= stream_from.max(1));
    }
    let Some(size) = streamed_size(probe, opts)? else {
        return Ok(false);
    };
    let sidecar = find_sidecar(path)?;
    let rows = match resolve_format(path, opts.format, sidecar.as_ref())? {
        InputFormat::ImuRecord(t) => size / t.record_size() as u64,
        // a gzip's size says nothing of its rows (a 0.5 MB file can hold 2^28): its lines
        // are counted as they decompress, up to the switch
        _ if super::text::is_gzip(path)? => {
            super::text::count_lines_up_to(path, stream_from.max(1))?
        }
        _ => size / 8,
    };
    Ok(rows >= stream_from.max(1))
}

impl StreamedTable {
    /// Reads the recording `path` as [`Recording::open`](crate::imu::Recording) would with
    /// `opts`: a ROS recording's IMU topic (streamed into a bounded reorder buffer, then
    /// spooled: `imu::read::ros_stream`), else as
    /// [`open`](Self::open).
    ///
    /// # Errors
    /// Those of [`Recording::open`](crate::imu::Recording) on the same file; [`ReadError::Io`]
    /// for the spool; [`ParamError`] `topic` for a topic given with a file that is not a ROS
    /// recording.
    pub fn open_recording(
        probe: &Probe,
        opts: &crate::imu::RecordingOptions,
    ) -> Result<Self, ReadError> {
        let path = probe.path();
        if probe.is_ros() {
            return super::ros_stream::open(path, opts);
        }
        if let Some(topic) = &opts.topic {
            return Err(ParamError::new(
                "topic",
                topic,
                format!(
                    "a topic of a ROS recording; {} is not one (ROS1 bag, MCAP, rosbag2 sqlite3)",
                    path.display()
                ),
            )
            .into());
        }
        Self::open(path, &opts.read)
    }

    /// Reads `path` (text or binary IMU records, see `streamed_size`) in one pass, as
    /// [`read_table`](super::read_table) would with `opts`, spooling the selected columns.
    ///
    /// # Errors
    /// Those of [`read_table`](super::read_table) on the same file; [`ReadError::Io`] for the
    /// spool; [`ParamError`] `format` for a file that is neither text nor IMU records.
    pub fn open(path: &Path, opts: &ReadOptions) -> Result<Self, ReadError> {
        if let Some(f) = opts.freq_hz {
            crate::error::check_freq(f)?;
        }
        let sidecar = find_sidecar(path)?;
        let format = resolve_format(path, opts.format, sidecar.as_ref())?;
        if let Some(k) = opts.ncols {
            return Err(ParamError::new(
                "ncols",
                k,
                format!(
                    "only for raw binary f64/f32 files; {} is read as {format}, whose columns it states itself",
                    path.display()
                ),
            )
            .into());
        }
        match format {
            InputFormat::ImuRecord(t) => open_records_stream(path, t, opts, sidecar),
            InputFormat::F64 | InputFormat::F32 => Err(ParamError::new(
                "format",
                format.to_string(),
                "text or binary IMU records for a streamed read (raw binary streams as it is)",
            )
            .into()),
            f => open_text_stream(path, f, opts, sidecar),
        }
    }

    /// The spool's path and layout: the selected columns as raw little-endian f64, which the
    /// streamed wavelet variance reads like any raw binary recording.
    pub(crate) fn spool(&self) -> (&Path, BinaryLayout) {
        (&self.spool.path, self.layout())
    }

    /// A ROS topic's streamed table (`imu::read::ros_stream`).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn ros(
        path: &Path,
        names: Vec<String>,
        (rows, freq_hz): (u64, f64),
        timing: TimingReport,
        samples: SampleAccount,
        notes: Vec<String>,
        (topic, container): (String, crate::imu::ros::RosContainer),
        spool: Spool,
    ) -> Self {
        Self {
            facts: TableFacts {
                path: path.to_path_buf(),
                freq_hz: Some(freq_hz),
                sidecar: None,
                timing: Some(timing),
                warnings: Vec::new(),
                skipped: Vec::new(),
                record_type: None,
                samples,
            },
            names,
            rows,
            notes,
            topic: Some(topic),
            container: Some(container),
            spool,
        }
    }

    /// What each selected column measures: by its name, the sidecar, and for binary IMU
    /// records and ROS topics their units (rad/s, m/s^2).
    pub fn sensor_infos(&self) -> Vec<crate::imu::SensorInfo> {
        let known = self.facts.record_type.is_some() || self.topic.is_some();
        self.names
            .iter()
            .map(|n| crate::imu::SensorInfo::of_column(n, self.facts.sidecar.as_ref(), known))
            .collect()
    }

    /// The spool as a raw binary recording: its path and layout (the selected columns, then
    /// the relative stamps and their lines when there is a time column).
    pub(crate) fn spooled(&self) -> (&Path, BinaryLayout) {
        (&self.spool.path, self.layout())
    }

    fn layout(&self) -> BinaryLayout {
        let mut names = self.names.clone();
        names.extend((names.len()..self.spool.ncols).map(|k| format!("spooled{}", k + 1)));
        BinaryLayout {
            format: InputFormat::F64,
            ncols: self.spool.ncols,
            names,
        }
    }

    /// An error about a column of the spool, about the recording's column instead.
    pub(crate) fn rename(&self, e: ReadError) -> ReadError {
        match e {
            ReadError::Series { column, source, .. } => ReadError::Series {
                path: self.facts.path.clone(),
                column,
                source,
            },
            e => e,
        }
    }
}

/// A raw f64 file in the temporary directory, removed when dropped.
#[derive(Debug)]
pub(super) struct Spool {
    pub(super) path: PathBuf,
    pub(super) ncols: usize,
}

impl Spool {
    pub(super) fn create(ncols: usize) -> Result<(Self, BufWriter<File>), ReadError> {
        use std::sync::atomic::{AtomicU64, Ordering};
        static NEXT: AtomicU64 = AtomicU64::new(0);
        let dir = crate::imu::temporary::temporary_dir();
        let io = |path: &Path, source| ReadError::Io {
            path: path.to_path_buf(),
            source,
        };
        loop {
            let path = dir.join(format!(
                "gmwm-spool-{}-{}.f64",
                crate::imu::temporary::process_tag(),
                NEXT.fetch_add(1, Ordering::Relaxed)
            ));
            match std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&path)
            {
                Ok(f) => {
                    crate::imu::track_temporary(&path);
                    return Ok((Self { path, ncols }, BufWriter::with_capacity(1 << 20, f)));
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(io(&path, e)),
            }
        }
    }

    /// Reads column `k` (0-based) back.
    pub(super) fn column(&self, k: usize) -> Result<Vec<f64>, ReadError> {
        let mut out = Vec::new();
        let mut chunks =
            super::BinaryChunks::open(&self.path, InputFormat::F64, self.ncols, k + 1, 1 << 16)?;
        while let Some(c) = chunks.next_chunk()? {
            out.extend_from_slice(c);
        }
        Ok(out)
    }
}

impl Drop for Spool {
    fn drop(&mut self) {
        crate::imu::untrack_temporary(&self.path);
        let _ = std::fs::remove_file(&self.path);
    }
}

pub(super) fn write_row(
    out: &mut BufWriter<File>,
    spool: &Path,
    row: &[f64],
) -> Result<(), ReadError> {
    for v in row {
        out.write_all(&v.to_le_bytes())
            .map_err(|source| ReadError::Io {
                path: spool.to_path_buf(),
                source,
            })?;
    }
    Ok(())
}

/// The time column's check while streaming: stamps converted to seconds and checked strictly
/// increasing (as [`read_table`](super::read_table) checks them after the conversion), then
/// pushed to `StepStats` when the unit is known.
struct TimeCheck {
    column: String,
    unit: Option<(TimeUnit, UnitSource)>,
    /// The unit an epoch-sized first stamp names.
    inferred: Option<(TimeUnit, UnitSource)>,
    /// The first stamp as read.
    origin: f64,
    stats: StepStats,
    previous: Option<f64>,
    row: u64,
}

impl TimeCheck {
    #[inline]
    fn push(
        &mut self,
        path: &Path,
        rel: f64,
        line: Option<u64>,
        origin: f64,
    ) -> Result<(), ReadError> {
        let Some((unit, _)) = self.unit else {
            self.row += 1;
            return Ok(());
        };
        let s = if unit == TimeUnit::Seconds {
            rel
        } else {
            rel * unit.to_seconds()
        };
        if !s.is_finite() || self.previous.is_some_and(|p| s <= p) {
            return Err(ReadError::TimeResolution {
                path: path.to_path_buf(),
                line,
                row: self.row,
                column: self.column.clone(),
                first: origin * unit.to_seconds(),
                previous: self.previous.unwrap_or(f64::NAN),
                value: s,
            });
        }
        self.previous = Some(s);
        self.stats.push(s, line);
        self.row += 1;
        Ok(())
    }
}

fn open_text_stream(
    path: &Path,
    format: InputFormat,
    opts: &ReadOptions,
    sidecar: Option<Sidecar>,
) -> Result<StreamedTable, ReadError> {
    // set by `head`, used by the rows
    let spool: std::cell::RefCell<Option<(Spool, BufWriter<File>)>> = Default::default();
    let check: std::cell::RefCell<Option<TimeCheck>> = Default::default();
    let mut buf = Vec::new();
    let head = |names: &[String], sel: &super::Selection| {
        *check.borrow_mut() = sel.time.map(|k| TimeCheck {
            column: names[k].clone(),
            unit: match (opts.time_unit, sel.time_unit) {
                (Some(u), _) => Some((u, UnitSource::Flag)),
                (None, Some(u)) => Some((u, UnitSource::Stated)),
                (None, None) => None,
            },
            inferred: None,
            origin: 0.0,
            stats: StepStats::default(),
            previous: None,
            row: 0,
        });
        let ncols = sel.columns.len() + if sel.time.is_some() { 2 } else { 0 };
        *spool.borrow_mut() = Some(Spool::create(ncols)?);
        Ok(())
    };
    let pass = for_each_text_row(path, format, opts, sidecar.as_ref(), head, |row, stamp| {
        let mut spool = spool.borrow_mut();
        let (s, out) = spool.as_mut().expect("created by head");
        buf.clear();
        buf.extend_from_slice(row);
        if let Some((rel, line, origin)) = stamp {
            let mut check = check.borrow_mut();
            // the stamp and its line, to check the column in memory beyond the streamed bounds
            buf.extend([rel, line as f64]);
            let check = check.as_mut().expect("a time column");
            if check.row == 0 && check.unit.is_none() {
                // an epoch-sized first stamp names the unit (infer_time_unit's first rule);
                // otherwise it is inferred from the steps, in memory after the pass
                check.inferred = infer_unit(origin, &[0.0]).map(|u| (u, UnitSource::Inferred));
                check.unit = check.inferred;
            }
            check.origin = origin;
            check.push(path, rel, Some(line), origin)?;
        }
        write_row(out, &s.path, &buf)
    })
    .map_err(|e| match e {
        ReadError::HeaderOnly { .. } | ReadError::Empty { .. } if super::cr_line_ends(path) => {
            ReadError::CrLineEnds {
                path: path.to_path_buf(),
            }
        }
        e => e,
    })?;
    let (spool, mut out) = spool.into_inner().expect("created by head");
    let check = check.into_inner();
    out.flush().map_err(|source| ReadError::Io {
        path: spool.path.clone(),
        source,
    })?;
    drop(out);
    let names: Vec<String> = pass
        .sel
        .columns
        .iter()
        .map(|&k| pass.names[k].clone())
        .collect();
    if names.is_empty() {
        return Err(ReadError::NoDataColumn {
            path: path.to_path_buf(),
            columns: pass
                .sel
                .time
                .iter()
                .map(|&k| pass.names[k].clone())
                .chain(pass.sel.skipped.iter().cloned())
                .collect(),
        });
    }
    if pass.unsorted {
        return Err(crate::error::ParamError::new(
            "time-policy",
            "sort",
            format!(
                "a recording read in memory ({} is streamed through a spool, in file order: --time-policy drop-duplicates drops the rows out of order, or sort the file, or raise --stream-from)",
                path.display()
            ),
        )
        .into());
    }
    let mut notes = Vec::new();
    let timing = match check {
        None => None,
        Some(check) => Some(finish_check(path, check, &spool, names.len(), &mut notes)?),
    };
    let mut table = finish(
        path,
        opts,
        (names, pass.rows as u64, pass.dropped, None),
        timing,
        sidecar,
        pass.sel.skipped,
        notes,
        spool,
    )?;
    table.facts.samples = table
        .facts
        .samples
        .without(pass.header_lines, "header line")
        .without(pass.blank_lines, "blank line");
    Ok(table)
}

/// The time report of a streamed check, or (beyond its bounds, or with a unit to infer from
/// the steps) of the stamps read back from the spool (column `at`, their lines after them)
/// and checked in memory as [`read_table`](super::read_table) checks them.
fn finish_check(
    path: &Path,
    check: TimeCheck,
    spool: &Spool,
    at: usize,
    notes: &mut Vec<String>,
) -> Result<TimingReport, ReadError> {
    let origin = check.origin;
    if let Some((unit, source)) = check.unit {
        if let Some(mut report) = check.stats.clone().finish(&check.column, unit, source) {
            report.start_s = origin * unit.to_seconds();
            return Ok(report);
        }
        notes.push(format!(
            "time column {}: more than {} distinct steps or {} gaps; its stamps were checked in memory (8 bytes a row)",
            crate::imu::quote(&check.column),
            crate::imu::timing::STREAM_DISTINCT_STEPS,
            crate::imu::timing::STREAM_LARGEST_STEPS
        ));
    }
    if check.unit.is_none() {
        notes.push(format!(
            "time column {}: its unit is inferred from its steps; its stamps were checked in memory (8 bytes a row)",
            crate::imu::quote(&check.column)
        ));
    }
    let mut values = spool.column(at)?;
    let lines = spool.column(at + 1)?;
    let (unit, source) = check.unit.unwrap_or_else(|| {
        (
            infer_unit(origin, &values).unwrap_or(TimeUnit::Seconds),
            UnitSource::Inferred,
        )
    });
    if unit != TimeUnit::Seconds {
        let k = unit.to_seconds();
        values.iter_mut().for_each(|t| *t *= k);
    }
    if let Some(row) =
        (0..values.len()).find(|&i| !values[i].is_finite() || (i > 0 && values[i] <= values[i - 1]))
    {
        return Err(ReadError::TimeResolution {
            path: path.to_path_buf(),
            line: Some(lines[row] as u64),
            row: row as u64,
            column: check.column.clone(),
            first: origin * unit.to_seconds(),
            previous: row.checked_sub(1).map_or(f64::NAN, |p| values[p]),
            value: values[row],
        });
    }
    let mut report = check_times(&check.column, &values, unit, source);
    report.start_s = origin * unit.to_seconds();
    for g in &mut report.gaps {
        g.line = Some(lines[g.row] as u64);
    }
    Ok(report)
}

/// The rate and warnings of a streamed table, as [`read_table`](super::read_table) resolves
/// them.
#[allow(clippy::too_many_arguments)]
fn finish(
    path: &Path,
    opts: &ReadOptions,
    (names, rows, dropped, format_hz): (Vec<String>, u64, super::DroppedRows, Option<f64>),
    timing: Option<TimingReport>,
    sidecar: Option<Sidecar>,
    skipped: Vec<String>,
    notes: Vec<String>,
    spool: Spool,
) -> Result<StreamedTable, ReadError> {
    let mut warnings = timing
        .as_ref()
        .map(|r| timing_warnings(path, r))
        .unwrap_or_default();
    let freq_hz = resolve_rate(
        path,
        opts,
        format_hz,
        timing.as_ref(),
        sidecar.as_ref(),
        &mut warnings,
    )?;
    warnings.extend(super::sidecar_warnings(path));
    warnings.extend(super::sidecar_rows_disagree(
        path,
        sidecar.as_ref(),
        rows + dropped.total(),
    ));
    warnings.extend(super::time_policy_warning(path, opts.time_policy, dropped));
    let samples = SampleAccount {
        missing: timing.as_ref().map_or(0, |t| t.missing_samples() as u64),
        read: rows + dropped.total(),
        ..SampleAccount::all_used(names.clone(), "row", rows)
    };
    Ok(StreamedTable {
        facts: TableFacts {
            samples,
            path: path.to_path_buf(),
            freq_hz,
            sidecar,
            timing,
            warnings,
            skipped,
            record_type: None,
        },
        names,
        rows,
        notes,
        topic: None,
        container: None,
        spool,
    })
}

/// Binary IMU records (docs/methods.md §9.2–9.3) in two passes over the file, which is read
/// by positioned reads: the times (checked and their steps counted: the rate that scales every
/// increment needs them all) and the checks of [`read_record_table`](super::binary), then the
/// scaled increments to the spool.
fn open_records_stream(
    path: &Path,
    record_type: ImuRecordType,
    opts: &ReadOptions,
    sidecar: Option<Sidecar>,
) -> Result<StreamedTable, ReadError> {
    let record = record_type.record_size();
    let names: Vec<String> = RECORD_COLUMNS.iter().map(|n| n.to_string()).collect();
    let sel = record_selection(path, opts)?;
    let (file, rows) = open_records(path, record)?;
    let raw = |r: &[u8], k: usize| {
        if record_type.is_double() {
            decode(&r[8 + 8 * k..], 8)
        } else {
            decode_i32(&r[8 + 4 * k..])
        }
    };
    // pass 1: the times, as read (for the rate) and relative to the first (for the report),
    // and the largest increment of each column (for the overflow check)
    let mut absolute = StepStats::default();
    let mut relative = StepStats::default();
    let mut previous: Option<f64> = None;
    let mut origin = 0.0;
    let mut largest = vec![0.0f64; sel.columns.len()];
    for_each_record_run(path, &file, (rows, record), |first, bytes| {
        for (j, r) in bytes.chunks_exact(record).enumerate() {
            let i = first + j;
            let t = decode(r, 8);
            if !t.is_finite() {
                return Err(non_finite(path, i, 1, t));
            }
            if let Some(p) = previous {
                if t <= p {
                    return Err(ReadError::RecordTimeNotIncreasing {
                        path: path.to_path_buf(),
                        index: i as u64,
                        previous: p,
                        value: t,
                    });
                }
            } else {
                origin = t;
            }
            previous = Some(t);
            absolute.push(t, None);
            relative.push(t - origin, None);
            for (c, &k) in sel.columns.iter().enumerate() {
                let v = raw(r, k);
                if !v.is_finite() {
                    return Err(non_finite(path, i, k + 2, v));
                }
                largest[c] = largest[c].max(v.abs());
            }
        }
        Ok(())
    })?;
    let mut notes = Vec::new();
    let in_memory = |notes: &mut Vec<String>| -> Result<Vec<f64>, ReadError> {
        notes.push(format!(
            "the record times have more than {} distinct steps or {} gaps; they were checked in memory (8 bytes a record)",
            crate::imu::timing::STREAM_DISTINCT_STEPS,
            crate::imu::timing::STREAM_LARGEST_STEPS
        ));
        let mut t = Vec::new();
        for_each_record_run(path, &file, (rows, record), |_, bytes| {
            t.extend(bytes.chunks_exact(record).map(|r| decode(r, 8)));
            Ok(())
        })?;
        Ok(t)
    };
    if rows < 2 {
        return Err(ReadError::FreqNotDerivable {
            path: path.to_path_buf(),
            reason: "fewer than 2 epochs",
        });
    }
    let (rate, mut report) = match (
        absolute.finish("time", TimeUnit::Seconds, UnitSource::Format),
        relative.finish("time", TimeUnit::Seconds, UnitSource::Format),
    ) {
        (Some(a), Some(r)) => (a.rate_hz, r),
        _ => {
            let mut t = in_memory(&mut notes)?;
            let rate = check_times("time", &t, TimeUnit::Seconds, UnitSource::Format).rate_hz;
            t.iter_mut().for_each(|v| *v -= origin);
            (
                rate,
                check_times("time", &t, TimeUnit::Seconds, UnitSource::Format),
            )
        }
    };
    let freq = rate.round();
    if !(freq.is_finite() && freq > 0.0) {
        return Err(ReadError::FreqNotDerivable {
            path: path.to_path_buf(),
            reason: "round(1 / mean time step) is not a positive finite rate",
        });
    }
    report.start_s = origin;
    let factors: Vec<f64> = sel
        .columns
        .iter()
        .map(|&k| {
            freq * if k < 3 {
                record_type.scale_gyro()
            } else {
                record_type.scale_accel()
            }
        })
        .collect();
    // an increment whose rate overflows: the first, column by column as the in-memory reader
    // finds it (|v| · factor overflows exactly when the largest does)
    for (c, &k) in sel.columns.iter().enumerate() {
        if !(largest[c] * factors[c]).is_finite() {
            let mut found = None;
            for_each_record_run(path, &file, (rows, record), |first, bytes| {
                if found.is_none() {
                    found = bytes
                        .chunks_exact(record)
                        .position(|r| !(raw(r, k) * factors[c]).is_finite())
                        .map(|j| (first + j, raw(&bytes[j * record..], k)));
                }
                Ok(())
            })?;
            let (i, v) = found.unwrap_or((0, largest[c]));
            return Err(ReadError::RecordRateOverflow {
                path: path.to_path_buf(),
                index: i as u64,
                column: names[k].clone(),
                raw: v,
                freq_hz: freq,
            });
        }
    }
    // pass 2: the rates to the spool
    let (spool, mut out) = Spool::create(sel.columns.len())?;
    let mut buf = Vec::with_capacity(sel.columns.len());
    for_each_record_run(path, &file, (rows, record), |_, bytes| {
        for r in bytes.chunks_exact(record) {
            buf.clear();
            buf.extend(
                sel.columns
                    .iter()
                    .zip(&factors)
                    .map(|(&k, &f)| raw(r, k) * f),
            );
            write_row(&mut out, &spool.path, &buf)?;
        }
        Ok(())
    })?;
    out.flush().map_err(|source| ReadError::Io {
        path: spool.path.clone(),
        source,
    })?;
    drop(out);
    let selected = sel.columns.iter().map(|&k| names[k].clone()).collect();
    let mut table = finish(
        path,
        opts,
        (selected, rows, super::DroppedRows::default(), Some(freq)),
        Some(report),
        sidecar,
        Vec::new(),
        notes,
        spool,
    )?;
    table.facts.record_type = Some(record_type);
    table.facts.samples.unit = "record";
    Ok(table)
}
