//! Readers: delimited text (CSV/TSV, optionally gzip-compressed) and raw little-endian binary.
//!
//! [`read_table`] is the entry point: it picks the format ([`InputFormat::Auto`] looks at the
//! file name, the JSON sidecar and the first bytes), finds the time column, materialises only
//! the selected columns and resolves the sampling frequency (see [`read_table`]).

pub(crate) mod binary;
pub(crate) mod positioned;
mod ros_stream;
pub(crate) mod stream;
pub(crate) mod text;

pub(crate) use binary::{BinaryChunks, ImuRecordType};

#[cfg(test)]
pub(crate) use binary::{for_each_chunk, read_imu_record_file};

use super::error::quote;
use super::samples::SampleAccount;
use super::sidecar::{find_sidecar, Sidecar};
use super::timing::{
    check_times, fmt_hz, infer_unit, time_column_unit, TimeUnit, TimingReport, TimingWarning,
    UnitSource,
};
use super::{ReadError, SensorInfo};
use crate::error::{check_freq, ParamError};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// Column selector: 1-based index or header name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ColumnSelector {
    /// 1-based index.
    Index(usize),
    /// Header name (without a header, the names are `col1`, `col2`, ...).
    Name(String),
}

impl FromStr for ColumnSelector {
    type Err = ParamError;

    /// All digits → [`ColumnSelector::Index`] (must be ≥ 1), anything else → a name.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.trim();
        if s.is_empty() {
            return Err(ParamError::new(
                "column",
                s,
                "a 1-based index or a column name",
            ));
        }
        if s.bytes().all(|b| b.is_ascii_digit()) {
            return match s.parse::<usize>() {
                Ok(i) if i >= 1 => Ok(Self::Index(i)),
                _ => Err(ParamError::new("column", s, "a 1-based index (1, 2, ...)")),
            };
        }
        Ok(Self::Name(s.to_string()))
    }
}

impl std::fmt::Display for ColumnSelector {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Index(i) => write!(f, "{i}"),
            Self::Name(n) => f.write_str(n),
        }
    }
}

/// Input format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InputFormat {
    /// From the file name, then the sidecar, then the content (default): `*.f64`, `*.f64le`,
    /// `*.f64.bin`, `*.f64le.bin` → [`F64`], the same with `f32` → [`F32`]; else the sidecar's
    /// `format` (`f64`, `f32`, a record type, `csv`, `tsv`); else the first bytes: a gzip
    /// stream or text is delimited text whose delimiter is sniffed from the first line (`.tsv`
    /// prefers tab, other names prefer comma), JSON is refused ([`ReadError::NotATable`]),
    /// anything else is refused as binary ([`ReadError::LooksBinary`]).
    ///
    /// [`F64`]: InputFormat::F64
    /// [`F32`]: InputFormat::F32
    #[default]
    Auto,
    /// Comma separated (no sniffing).
    Csv,
    /// Tab separated (no sniffing).
    Tsv,
    /// Binary IMU epoch records of docs/methods.md §9.2 (time, then gyro X, Y, Z and accel X, Y, Z
    /// increments), read as columns `gyro_x` ... `accel_z` in rad/s and m/s^2 and the time.
    ImuRecord(ImuRecordType),
    /// Raw little-endian f64, `ncols` interleaved columns.
    F64,
    /// Raw little-endian f32, `ncols` interleaved columns.
    F32,
}

impl FromStr for InputFormat {
    type Err = ParamError;

    /// `auto`, `csv`, `tsv`, `f64`, `f32` or a record type (`imar`, `ln200`, `ln200ig`,
    /// `ixsea`, `navchip-int`, `navchip-flt`, also with `_`), case-insensitive.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "auto" => Ok(Self::Auto),
            "csv" => Ok(Self::Csv),
            "tsv" => Ok(Self::Tsv),
            "f64" | "f64le" => Ok(Self::F64),
            "f32" | "f32le" => Ok(Self::F32),
            other => other
                .replace('-', "_")
                .parse::<ImuRecordType>()
                .map(Self::ImuRecord)
                .map_err(|_| {
                    ParamError::new(
                        "format",
                        s,
                        "one of auto, csv, tsv, f64, f32, imar, ln200, ln200ig, ixsea, \
                         navchip-int, navchip-flt",
                    )
                }),
        }
    }
}

crate::names::named_values!(InputFormat, "format", {
    Auto => "auto",
    Csv => "csv",
    Tsv => "tsv",
    ImuRecord(ImuRecordType::Imar) => "imar",
    ImuRecord(ImuRecordType::Ln200) => "ln200",
    ImuRecord(ImuRecordType::Ln200Ig) => "ln200ig",
    ImuRecord(ImuRecordType::Ixsea) => "ixsea",
    ImuRecord(ImuRecordType::NavchipInt) => "navchip-int",
    ImuRecord(ImuRecordType::NavchipFlt) => "navchip-flt",
    F64 => "f64",
    F32 => "f32",
}, derive(Display));

impl InputFormat {
    /// Bytes per value of a raw binary format, `None` for text formats and IMU records.
    pub fn value_width(self) -> Option<usize> {
        match self {
            Self::F64 => Some(8),
            Self::F32 => Some(4),
            _ => None,
        }
    }

    /// Resolves [`InputFormat::Auto`] from the file name only (see the variant's doc; the
    /// sidecar and the content are looked at by [`read_table`]).
    pub(crate) fn resolve(self, path: &Path) -> Self {
        if self != Self::Auto {
            return self;
        }
        let name = path
            .file_name()
            .and_then(|f| f.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        let name = name.strip_suffix(".bin").unwrap_or(&name);
        if name.ends_with(".f64") || name.ends_with(".f64le") {
            Self::F64
        } else if name.ends_with(".f32") || name.ends_with(".f32le") {
            Self::F32
        } else {
            Self::Auto
        }
    }
}

/// What the first bytes of a file are (`sniff`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Content {
    /// Plain text.
    Text,
    /// A gzip stream whose start decompresses to text.
    Gzip,
    /// A JSON object (first non-blank character `{`).
    Json,
    /// Neither: NUL bytes or invalid UTF-8 in the first `SNIFF_BYTES`.
    Binary,
}

/// Bytes looked at by [`sniff`]: 4 KiB.
pub(crate) const SNIFF_BYTES: usize = 4096;

/// Looks at the first [`SNIFF_BYTES`] bytes of a file (decompressed if it starts with the gzip
/// magic bytes) and says whether it is text, gzip text, JSON or binary data. Text is UTF-8
/// without NUL bytes (a UTF-8 sequence cut by the 4 KiB window counts as text).
///
/// # Errors
/// [`ReadError::Io`] if the file cannot be read; [`ReadError::Gzip`] if the gzip stream is
/// corrupt at its start.
pub(crate) fn sniff(path: &Path) -> Result<Content, ReadError> {
    use std::io::Read;
    let io = |source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut head = Vec::with_capacity(SNIFF_BYTES);
    std::fs::File::open(path)
        .map_err(io)?
        .take(SNIFF_BYTES as u64)
        .read_to_end(&mut head)
        .map_err(io)?;
    let gzip = head.starts_with(&[0x1f, 0x8b]);
    if gzip {
        let file = std::fs::File::open(path).map_err(io)?;
        let mut text = Vec::with_capacity(SNIFF_BYTES);
        flate2::read::MultiGzDecoder::new(file)
            .take(SNIFF_BYTES as u64)
            .read_to_end(&mut text)
            .map_err(|source| ReadError::Gzip {
                path: path.to_path_buf(),
                source,
            })?;
        head = text;
    }
    let is_text = !head.contains(&0)
        && match std::str::from_utf8(&head) {
            Ok(_) => true,
            // a multi-byte character cut at the end of the window
            Err(e) => e.error_len().is_none(),
        };
    let body = head.strip_prefix(&[0xef, 0xbb, 0xbf][..]).unwrap_or(&head);
    Ok(if !is_text {
        Content::Binary
    } else if body.trim_ascii_start().starts_with(b"{") {
        Content::Json
    } else if gzip {
        Content::Gzip
    } else {
        Content::Text
    })
}

/// Header handling of delimited text.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HeaderMode {
    /// The first row is a header iff one of its fields is not a number (default: data files
    /// with and without headers both work).
    #[default]
    Auto,
    /// The first row is a header.
    Present,
    /// There is no header; columns are named `col1`, `col2`, ...
    Absent,
}

crate::names::named_values!(HeaderMode, "header", {
    Auto => "auto",
    Present => "yes",
    Absent => "no",
}, derive(FromStr, Display));

/// What a text reader does with a row whose time stamp is not after the previous row's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum TimePolicy {
    /// An error naming the line (default): a repeated or reordered stamp is a logging fault
    /// the user should see before any number is computed.
    #[default]
    Strict,
    /// The rows are sorted by their stamps (stable), then a row whose stamp repeats the
    /// previous one is dropped; in-memory reads only.
    Sort,
    /// A row whose stamp is not after the last kept row's is dropped.
    DropDuplicates,
}

crate::names::named_values!(TimePolicy, "time policy", {
    Strict => "strict",
    Sort => "sort",
    DropDuplicates => "drop-duplicates",
}, derive(FromStr, Display));

/// Options of [`read_table`]. The default reads every column of any supported file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ReadOptions {
    /// Format (default [`InputFormat::Auto`]).
    pub format: InputFormat,
    /// Header handling of text files (default [`HeaderMode::Auto`]); ignored for binary.
    pub header: HeaderMode,
    /// Time column (default `None`: found by name, see [`read_table`]). Must be finite and
    /// strictly increasing; it is returned in [`Table::time`] (in seconds after its first
    /// stamp), not among the columns.
    pub time_column: Option<ColumnSelector>,
    /// Unit of the time column (default `None`: stated by its name, else inferred, see
    /// `infer_time_unit`).
    pub time_unit: Option<TimeUnit>,
    /// Columns to read, in this order (default empty: see [`read_table`]).
    pub columns: Vec<ColumnSelector>,
    /// Interleaved columns in a binary file (default `None`: the sidecar's `n_columns`, else
    /// 1); ignored for text.
    pub ncols: Option<usize>,
    /// Sampling rate override in Hz (default `None`: from the time column, else the sidecar).
    pub freq_hz: Option<f64>,
    /// What a text file's stamp that is not after the previous one does (default
    /// [`TimePolicy::Strict`]: an error).
    pub time_policy: TimePolicy,
}

/// One column.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Column {
    /// Name (header name, or `col1`, `col2`, ... 1-based, when there is none).
    pub name: String,
    /// Values, all finite.
    pub values: Vec<f64>,
}

/// What a reader found out about a recording besides its samples: where it came from, its
/// rate, sidecar, time column, soft problems, the columns it left out, its record type and its
/// row accounting. Shared by the in-memory [`Table`] and the streamed
/// [`StreamedTable`](stream::StreamedTable).
#[derive(Debug, Clone, PartialEq)]
pub struct TableFacts {
    /// File, as given by the caller.
    pub path: PathBuf,
    /// Sampling rate in Hz, resolved as documented on [`read_table`].
    pub freq_hz: Option<f64>,
    /// The JSON sidecar beside the file, if any.
    pub sidecar: Option<Sidecar>,
    /// What the time column says about the sampling (unit, rate, gaps, ...), if there is one.
    pub timing: Option<TimingReport>,
    /// Soft problems found while reading (gaps, a rate that disagrees with the time column).
    pub warnings: Vec<ReadWarning>,
    /// Columns left out of the default selection: other time columns, and the columns that
    /// are neither a gyroscope nor an accelerometer axis when the file has such axes.
    pub skipped: Vec<String>,
    /// The binary IMU record type the table was decoded from, if any (docs/methods.md §9.1
    /// `stype`).
    pub record_type: Option<ImuRecordType>,
    /// How many samples were read and used per column, and what held none (row accounting).
    pub samples: SampleAccount,
}

/// A table read from a file.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// What the reader found out besides the samples.
    pub facts: TableFacts,
    /// Selected columns, in the requested order, all of the same length (≥ 1).
    pub columns: Vec<Column>,
    /// The time column, if one was given or found: seconds after its first stamp (which is
    /// [`TimingReport::start_s`]), finite and strictly increasing; relative so that epoch
    /// stamps keep their precision (whole-number stamps are subtracted exactly).
    pub time: Option<Column>,
}

impl Table {
    /// Number of rows.
    pub fn len(&self) -> usize {
        self.columns.first().map_or(0, |c| c.values.len())
    }

    /// Whether there are no rows (never the case for a table returned by [`read_table`]).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The column named `name`.
    pub fn column(&self, name: &str) -> Option<&Column> {
        self.columns.iter().find(|c| c.name == name)
    }
}

/// A soft problem found by [`read_table`]; `Display` is one line starting with the file.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
#[non_exhaustive]
pub enum ReadWarning {
    /// A problem of the time stamps (gaps, duplicates, reordering, jitter).
    Timing {
        /// File.
        path: PathBuf,
        /// What.
        warning: TimingWarning,
    },
    /// The rate given by the caller differs by more than [`RATE_TOLERANCE`] from the time
    /// column's; the given rate is used.
    FreqDisagrees {
        /// File.
        path: PathBuf,
        /// The rate given, in Hz (used).
        given_hz: f64,
        /// Time column.
        column: String,
        /// Its rate, in Hz.
        time_hz: f64,
    },
    /// The sidecar's `sampling_frequency_hz` differs by more than [`RATE_TOLERANCE`] from the
    /// time column's; the time column's is used.
    SidecarFreqDisagrees {
        /// File.
        path: PathBuf,
        /// The sidecar's rate, in Hz.
        sidecar_hz: f64,
        /// Time column.
        column: String,
        /// Its rate, in Hz (used).
        time_hz: f64,
    },
    /// A file at a sidecar's name that is not a sidecar (empty, or a document gmwm wrote
    /// there: `gmwm wv x.csv --json > x.json`), passed over.
    NotASidecar(crate::imu::sidecar::NotASidecar),
    /// The sidecar has keys gmwm does not read (a typo, or a per-column unit).
    SidecarKeysUnread {
        /// The sidecar.
        path: PathBuf,
        /// The keys, as paths (`columns[2].unit`).
        keys: Vec<String>,
    },
    /// Rows a [`TimePolicy`] other than strict dropped or moved.
    TimePolicy {
        /// File.
        path: PathBuf,
        /// The policy.
        policy: TimePolicy,
        /// Rows whose stamp repeated the previous one, dropped.
        repeated: u64,
        /// Rows whose stamp was before the previous one: dropped (`drop-duplicates`).
        earlier: u64,
        /// Rows sorted into place (`sort`).
        moved: u64,
    },
    /// The sidecar's `n_rows` is not the number of rows read; the rows read are used.
    SidecarRowsDisagree {
        /// File.
        path: PathBuf,
        /// The sidecar's `n_rows`.
        sidecar_rows: u64,
        /// Rows read.
        rows: u64,
    },
}

/// The warning of a sidecar whose `n_rows` is not the number of rows the file holds (a
/// truncated or partial copy of the recording, or the sidecar of another one).
pub(crate) fn sidecar_rows_disagree(
    path: &Path,
    sidecar: Option<&Sidecar>,
    rows: u64,
) -> Option<ReadWarning> {
    let stated = sidecar?.n_rows?;
    (stated != rows).then(|| ReadWarning::SidecarRowsDisagree {
        path: path.to_path_buf(),
        sidecar_rows: stated,
        rows,
    })
}

/// The warning of rows a time policy dropped or moved, `None` when it did neither.
pub(crate) fn time_policy_warning(
    path: &Path,
    policy: TimePolicy,
    dropped: DroppedRows,
) -> Option<ReadWarning> {
    (dropped.total() + dropped.moved > 0).then(|| ReadWarning::TimePolicy {
        path: path.to_path_buf(),
        policy,
        repeated: dropped.repeated,
        earlier: dropped.earlier,
        moved: dropped.moved,
    })
}

/// The warnings for the files at `path`'s sidecar names passed over as not sidecars, and for
/// the keys of its sidecar that are not read.
pub(crate) fn sidecar_warnings(path: &Path) -> Vec<ReadWarning> {
    located_warnings(crate::imu::sidecar::locate_sidecar(path).unwrap_or_default()).collect()
}

fn located_warnings(located: crate::imu::sidecar::Located) -> impl Iterator<Item = ReadWarning> {
    let unread = located
        .unread
        .map(|(path, keys)| ReadWarning::SidecarKeysUnread { path, keys });
    located
        .passed
        .into_iter()
        .map(ReadWarning::NotASidecar)
        .chain(unread)
}

/// Relative difference between two rates above which they disagree: 1% (a time column and a
/// nominal rate agree far better; a factor such as 100 vs 200 Hz is a wrong rate).
pub const RATE_TOLERANCE: f64 = 0.01;

impl fmt::Display for ReadWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let pct = |a: f64, b: f64| 100.0 * (a - b).abs() / b;
        match self {
            Self::Timing { path, warning } => write!(f, "{}: {warning}", path.display()),
            Self::TimePolicy {
                path,
                policy,
                repeated,
                earlier,
                moved,
            } => {
                let rows = |k: u64| if k == 1 { "1 row".to_string() } else { format!("{k} rows") };
                let mut parts = Vec::new();
                if *moved > 0 {
                    parts.push(format!("{} out of order sorted into place", rows(*moved)));
                }
                if *repeated > 0 {
                    parts.push(format!("{} repeating the previous stamp dropped", rows(*repeated)));
                }
                if *earlier > 0 {
                    parts.push(format!("{} stamped before the previous one dropped", rows(*earlier)));
                }
                write!(f, "{}: --time-policy {policy}: {}", path.display(), parts.join(", "))
            }
            Self::SidecarRowsDisagree {
                path,
                sidecar_rows,
                rows,
            } => write!(
                f,
                "{}: its sidecar says n_rows = {sidecar_rows} but the file holds {rows} rows ({}); the {rows} rows are analysed",
                path.display(),
                if rows < sidecar_rows {
                    "a truncated or partial copy?"
                } else {
                    "the sidecar of another recording?"
                }
            ),
            Self::SidecarKeysUnread { path, keys } => {
                let units = keys
                    .iter()
                    .any(|k| k.starts_with("units.") || k.ends_with(".units"));
                write!(
                    f,
                    "{}: key{} not read: {}{}",
                    path.display(),
                    if keys.len() == 1 { "" } else { "s" },
                    crate::imu::error::name_list(keys),
                    if units {
                        " (the units read are units.gyro, units.accel and a column's \
                         unit: columns[k].unit)"
                    } else {
                        " (a typo? the keys read are name, sensor, sampling_frequency_hz, \
                         units, format, n_columns, columns, n_rows, summary)"
                    }
                )
            }
            Self::NotASidecar(n) => write!(
                f,
                "{}: not read as the recording's sidecar: {}",
                n.path.display(),
                n.why
            ),
            Self::FreqDisagrees {
                path,
                given_hz,
                column,
                time_hz,
            } => write!(
                f,
                "{}: the rate given ({} Hz) differs by {:.0}% from time column \"{}\" ({} Hz); \
                 the given rate is used",
                path.display(),
                fmt_hz(*given_hz),
                pct(*given_hz, *time_hz),
                quote(column),
                fmt_hz(*time_hz)
            ),
            Self::SidecarFreqDisagrees {
                path,
                sidecar_hz,
                column,
                time_hz,
            } => write!(
                f,
                "{}: the sidecar's sampling_frequency_hz ({} Hz) differs by {:.0}% from time \
                 column \"{}\" ({} Hz); the time column's rate is used",
                path.display(),
                fmt_hz(*sidecar_hz),
                pct(*sidecar_hz, *time_hz),
                quote(column),
                fmt_hz(*time_hz)
            ),
        }
    }
}

/// The format [`read_table`] reads `path` with: `opts.format` unless [`InputFormat::Auto`],
/// else as documented on [`InputFormat::Auto`]. Text formats are checked to be text.
///
/// # Errors
/// [`ReadError::LooksBinary`], [`ReadError::NotATable`], [`ReadError::Io`],
/// [`ReadError::Gzip`].
pub(crate) fn resolve_format(
    path: &Path,
    format: InputFormat,
    sidecar: Option<&Sidecar>,
) -> Result<InputFormat, ReadError> {
    let given = format;
    let mut format = format.resolve(path);
    // a raw layout named by the file and another by its sidecar: the values would be read
    // with the wrong width, so neither is chosen silently (a --format flag decides)
    if given == InputFormat::Auto && format.value_width().is_some() {
        if let Some(other) = sidecar
            .and_then(|s| s.format.as_deref())
            .and_then(|f| f.parse::<InputFormat>().ok())
            .filter(|f| f.value_width().is_some() && *f != format)
        {
            return Err(ParamError::new(
                "sidecar format",
                other,
                format!(
                    "the layout {}'s name says ({format}); fix the sidecar, rename the file, or say --format",
                    path.display()
                ),
            )
            .into());
        }
    }
    if format == InputFormat::Auto {
        if let Some(f) = sidecar
            .and_then(|s| s.format.as_deref())
            .and_then(|f| f.parse::<InputFormat>().ok())
        {
            format = f;
        }
    }
    if matches!(
        format,
        InputFormat::Auto | InputFormat::Csv | InputFormat::Tsv
    ) {
        match sniff(path)? {
            Content::Binary => {
                return Err(other_encoding(path).unwrap_or(ReadError::LooksBinary {
                    path: path.to_path_buf(),
                }))
            }
            Content::Json => {
                return Err(ReadError::NotATable {
                    path: path.to_path_buf(),
                })
            }
            Content::Text | Content::Gzip => {}
        }
    }
    Ok(format)
}

/// The first bytes of a plain file (not gzip), empty if it cannot be read.
fn head(path: &Path) -> Vec<u8> {
    use std::io::Read;
    let mut head = Vec::with_capacity(SNIFF_BYTES);
    if let Ok(f) = std::fs::File::open(path) {
        let _ = f.take(SNIFF_BYTES as u64).read_to_end(&mut head);
    }
    head
}

/// What a file that [`sniff`] finds binary is when it is text in another encoding: UTF-16 by
/// its byte-order mark ([`ReadError::Utf16`]), or 8-bit text ([`ReadError::NotUtf8`]: no NUL,
/// printable ASCII but for a few bytes above 0x7f, such as Latin-1's degree sign).
fn other_encoding(path: &Path) -> Option<ReadError> {
    let head = head(path);
    let path = path.to_path_buf();
    if head.starts_with(&[0xff, 0xfe]) || head.starts_with(&[0xfe, 0xff]) {
        return Some(ReadError::Utf16 {
            path,
            big_endian: head[0] == 0xfe,
        });
    }
    let printable = |b: &u8| b.is_ascii_graphic() || matches!(b, b' ' | b'\t' | b'\r' | b'\n');
    let high = head.iter().filter(|b| **b >= 0x80).count();
    let plain = head.iter().filter(|b| printable(b)).count();
    if head.is_empty() || head.contains(&0) || plain + high < head.len() || high * 20 > head.len() {
        return None;
    }
    let offset = std::str::from_utf8(&head).err()?.valid_up_to();
    let line = 1 + head[..offset].iter().filter(|&&b| b == b'\n').count() as u64;
    Some(ReadError::NotUtf8 {
        path,
        line,
        byte: head[offset],
    })
}

/// Whether the start of a plain file breaks lines with a carriage return alone.
pub(crate) fn cr_line_ends(path: &Path) -> bool {
    let head = head(path);
    !head.contains(&b'\n') && head.iter().filter(|&&b| b == b'\r').count() > 1
}

/// Layout of a raw f64/f32 file: what [`read_table`] would use for it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BinaryLayout {
    /// [`InputFormat::F64`] or [`InputFormat::F32`].
    pub format: InputFormat,
    /// Interleaved columns: `opts.ncols`, else the sidecar's `n_columns`, else 1.
    pub ncols: usize,
    /// Column names: the sidecar's when it names `ncols` columns, else `col1`, `col2`, ...
    pub names: Vec<String>,
}

impl BinaryLayout {
    /// The columns [`read_table`] would analyse in this layout (1-based indices: `--columns`,
    /// else the sensor axes, else every column but the time columns) and the names of those
    /// it leaves out, by the one rule of the in-memory readers, so that a streamed file
    /// analyses the same columns as a loaded one.
    ///
    /// # Errors
    /// [`ReadError::UnknownColumn`] / [`ReadError::ColumnOutOfRange`] for a selector that
    /// names no column.
    pub fn selection(
        &self,
        path: &Path,
        opts: &ReadOptions,
        sidecar: Option<&Sidecar>,
    ) -> Result<(Vec<usize>, Vec<String>), ReadError> {
        let sel = resolve_selection(path, &self.names, opts, sidecar)?;
        Ok((sel.columns.iter().map(|k| k + 1).collect(), sel.skipped))
    }
}

/// The raw binary layout of `path` if [`read_table`] would read it as raw f64/f32 (from
/// `opts.format`, the name or the sidecar), `None` otherwise; for readers that stream
/// (`BinaryChunks`).
///
/// # Errors
/// As `resolve_format` and [`find_sidecar`]; [`ReadError::Empty`] or
/// [`ReadError::BinarySize`] if the file does not hold a whole number of rows of `ncols`
/// values; [`ParamError`] `ncols` for 0 columns.
pub fn binary_layout(path: &Path, opts: &ReadOptions) -> Result<Option<BinaryLayout>, ReadError> {
    let sidecar = find_sidecar(path)?;
    let format = resolve_format(path, opts.format, sidecar.as_ref())?;
    let Some(width) = format.value_width() else {
        return Ok(None);
    };
    let ncols = opts
        .ncols
        .or_else(|| sidecar.as_ref().and_then(|s| s.n_columns))
        .unwrap_or(1);
    // a column count is data (a sidecar's): names are only made for columns the file can hold
    binary::check_records(path, binary::record_size(width, ncols)?)?;
    Ok(Some(BinaryLayout {
        format,
        ncols,
        names: binary_names(sidecar.as_ref(), ncols),
    }))
}

/// The warnings of a raw binary file read in `layout` without [`read_table`] (streamed): the
/// files at its sidecar's names passed over, its unread keys, and a sidecar `n_rows` the file
/// does not hold.
pub fn binary_warnings(path: &Path, layout: &BinaryLayout) -> Vec<ReadWarning> {
    let mut located = crate::imu::sidecar::locate_sidecar(path).unwrap_or_default();
    let record = layout.format.value_width().unwrap_or(8) * layout.ncols.max(1);
    let rows = std::fs::metadata(path).map_or(0, |m| m.len() / record as u64);
    let disagree = sidecar_rows_disagree(path, located.sidecar.take().as_ref(), rows);
    located_warnings(located).chain(disagree).collect()
}

/// Column names of a raw binary file: the sidecar's if it names exactly `ncols` columns.
pub(crate) fn binary_names(sidecar: Option<&Sidecar>, ncols: usize) -> Vec<String> {
    match sidecar {
        Some(s) if s.columns.len() == ncols && s.columns.iter().all(|c| !c.name.is_empty()) => s
            .columns
            .iter()
            .map(|c| crate::imu::printable(&c.name))
            .collect(),
        _ => (0..ncols).map(default_name).collect(),
    }
}

/// Reads a text or binary file into a [`Table`].
///
/// Format: `resolve_format` (name, sidecar, content).
///
/// Time column: `opts.time_column`, else found by name ([`time_column_unit`]: `time`,
/// `timestamp`, `t`, `stamp`, `%time`, `#timestamp [ns]`, `timestamp_ns`, `time_s`,
/// `time [s]`, `field.header.stamp`, ...; a header stamp is preferred, else the first in file
/// order) unless `opts.columns` selects that column explicitly. Its unit: `opts.time_unit`,
/// else the one its name states, else `infer_time_unit`
/// (seconds if nothing can be inferred). The stamps are converted to seconds and checked
/// (`check_times`, [`TableFacts::timing`]); in a text or raw binary file
/// they must strictly increase ([`ReadError::TimeNotIncreasing`] names the line).
///
/// Columns: `opts.columns` in that order; by default every column but the time columns, and
/// if some columns are gyroscope or accelerometer axes ([`SensorInfo::infer`] on the name or
/// the sidecar's meaning) only those; the others are listed in [`TableFacts::skipped`].
///
/// Sampling frequency, first match wins: `opts.freq_hz`; the time column's rate,
/// `TimingReport::rate_hz` (1 / the nominal step: the mean of the steps within 1.5 median
/// steps, so gaps do not lower it; not rounded, so 62.5 Hz survives) — for IMU records
/// docs/methods.md §9.2's rounded rate; the sidecar's `sampling_frequency_hz`; otherwise `None` and
/// the caller decides. A given rate or a sidecar rate that differs from the time column's by
/// more than [`RATE_TOLERANCE`] is a [`ReadWarning`].
///
/// Cost: one pass over the file; only the selected columns are stored.
///
/// # Errors
/// Any [`ReadError`]: I/O, empty or header-only file, ragged row, non-numeric or non-finite cell
/// (with its line and column), unknown column, binary size not a multiple of the record size,
/// binary content without a binary format, corrupt gzip, unreadable sidecar, non-increasing
/// time, stamps too far apart to stay strictly increasing relative to the first one
/// ([`ReadError::TimeResolution`]), only time columns ([`ReadError::NoDataColumn`]), IMU
/// record increments whose rate is not finite, invalid options.
pub fn read_table(path: &Path, opts: &ReadOptions) -> Result<Table, ReadError> {
    if let Some(f) = opts.freq_hz {
        check_freq(f)?;
    }
    let sidecar = find_sidecar(path)?;
    let format = resolve_format(path, opts.format, sidecar.as_ref())?;
    // a column count only describes raw interleaved values; elsewhere it would be ignored
    if let (Some(k), None) = (opts.ncols, format.value_width()) {
        return Err(ParamError::new(
            "ncols",
            k,
            format!(
                "only for raw binary f64/f32 files; {} is read as {}, whose columns it states itself",
                path.display(),
                match format {
                    InputFormat::ImuRecord(t) => format!("{} records", t.name()),
                    _ => "text".to_string(),
                }
            ),
        )
        .into());
    }
    let raw = match format {
        InputFormat::F64 | InputFormat::F32 => {
            binary::read_binary_table(path, format, opts, sidecar.as_ref())?
        }
        InputFormat::ImuRecord(t) => binary::read_record_table(path, t, opts)?,
        f => text::read_text_table(path, f, opts, sidecar.as_ref()).map_err(|e| match e {
            ReadError::HeaderOnly { .. } | ReadError::Empty { .. } if cr_line_ends(path) => {
                ReadError::CrLineEnds {
                    path: path.to_path_buf(),
                }
            }
            e => e,
        })?,
    };
    if raw.columns.is_empty() {
        // only time columns: the selection was the default one (an explicit one is never
        // empty)
        return Err(ReadError::NoDataColumn {
            path: path.to_path_buf(),
            columns: raw
                .time
                .iter()
                .map(|t| t.name.clone())
                .chain(raw.skipped)
                .collect(),
        });
    }
    let mut warnings = Vec::new();
    let (time, timing) = match raw.time {
        Some(mut col) => {
            let (unit, source) = match (opts.time_unit, raw.time_unit) {
                (Some(u), _) => (u, UnitSource::Flag),
                (None, Some(u)) if raw.freq_hz.is_some() => (u, UnitSource::Format),
                (None, Some(u)) => (u, UnitSource::Stated),
                (None, None) => (
                    infer_unit(raw.time_origin, &col.values).unwrap_or(TimeUnit::Seconds),
                    UnitSource::Inferred,
                ),
            };
            if unit != TimeUnit::Seconds {
                let k = unit.to_seconds();
                col.values.iter_mut().for_each(|t| *t *= k);
            }
            // each reader checked the stamps as read; relative to the first one and in seconds
            // they must still be finite and strictly increasing (Table::time)
            let bad = (0..col.values.len()).find(|&i| {
                !col.values[i].is_finite() || (i > 0 && col.values[i] <= col.values[i - 1])
            });
            if let Some(row) = bad {
                return Err(ReadError::TimeResolution {
                    path: path.to_path_buf(),
                    line: raw.lines.as_ref().map(|l| l.line_of(row)),
                    row: row as u64,
                    column: col.name.clone(),
                    first: raw.time_origin * unit.to_seconds(),
                    previous: row.checked_sub(1).map_or(f64::NAN, |p| col.values[p]),
                    value: col.values[row],
                });
            }
            let mut report = check_times(&col.name, &col.values, unit, source);
            report.start_s = raw.time_origin * unit.to_seconds();
            if let Some(lines) = &raw.lines {
                for g in &mut report.gaps {
                    g.line = Some(lines.line_of(g.row));
                }
            }
            warnings.extend(timing_warnings(path, &report));
            (Some(col), Some(report))
        }
        None => (None, None),
    };
    let freq_hz = resolve_rate(
        path,
        opts,
        raw.freq_hz,
        timing.as_ref(),
        sidecar.as_ref(),
        &mut warnings,
    )?;
    warnings.extend(sidecar_warnings(path));
    let kept = raw.columns.first().map_or(0, |c| c.values.len() as u64);
    let dropped = raw.dropped;
    warnings.extend(sidecar_rows_disagree(
        path,
        sidecar.as_ref(),
        kept + dropped.total(),
    ));
    warnings.extend(time_policy_warning(path, opts.time_policy, dropped));
    let samples = SampleAccount {
        missing: timing.as_ref().map_or(0, |t| t.missing_samples() as u64),
        read: kept + dropped.total(),
        ..SampleAccount::all_used(
            raw.columns.iter().map(|c| c.name.clone()).collect(),
            if matches!(format, InputFormat::ImuRecord(_)) {
                "record"
            } else {
                "row"
            },
            kept,
        )
        .without(raw.header_lines, "header line")
        .without(raw.blank_lines, "blank line")
    };
    Ok(Table {
        facts: TableFacts {
            samples,
            path: path.to_path_buf(),
            freq_hz,
            sidecar,
            timing,
            warnings,
            skipped: raw.skipped,
            record_type: match format {
                InputFormat::ImuRecord(t) => Some(t),
                _ => None,
            },
        },
        columns: raw.columns,
        time,
    })
}

/// The sampling rate of a table (first match wins, as documented on [`read_table`]) and the
/// warnings of a rate that disagrees with the time column's: shared by [`read_table`] and the
/// streamed readers ([`stream`]).
pub(crate) fn resolve_rate(
    path: &Path,
    opts: &ReadOptions,
    format_hz: Option<f64>,
    timing: Option<&TimingReport>,
    sidecar: Option<&Sidecar>,
    warnings: &mut Vec<ReadWarning>,
) -> Result<Option<f64>, ReadError> {
    let time_hz = timing
        .filter(|r| r.rate_hz.is_finite() && r.rate_hz > 0.0)
        .map(|r| (r.column.clone(), format_hz.unwrap_or(r.rate_hz)));
    let sidecar_hz = sidecar.and_then(|s| s.sampling_frequency_hz);
    let disagree = |a: f64, b: f64| (a - b).abs() > RATE_TOLERANCE * b;
    if let Some((column, time_hz)) = &time_hz {
        if let Some(given_hz) = opts.freq_hz.filter(|&g| disagree(g, *time_hz)) {
            warnings.push(ReadWarning::FreqDisagrees {
                path: path.to_path_buf(),
                given_hz,
                column: column.clone(),
                time_hz: *time_hz,
            });
        } else if let Some(sidecar_hz) = sidecar_hz.filter(|&s| disagree(s, *time_hz)) {
            if opts.freq_hz.is_none() {
                warnings.push(ReadWarning::SidecarFreqDisagrees {
                    path: path.to_path_buf(),
                    sidecar_hz,
                    column: column.clone(),
                    time_hz: *time_hz,
                });
            }
        }
    }
    let freq_hz = opts
        .freq_hz
        .or(time_hz.map(|(_, f)| f))
        .or(format_hz)
        .or(sidecar_hz);
    if let Some(f) = freq_hz {
        // a rate from the options, the time column or the sidecar must be usable: never
        // silently replaced by a default
        check_freq(f)?;
    }
    Ok(freq_hz)
}

/// The warnings of a timing report, each naming the file.
pub(crate) fn timing_warnings(path: &Path, report: &TimingReport) -> Vec<ReadWarning> {
    report
        .warnings()
        .into_iter()
        .map(|warning| ReadWarning::Timing {
            path: path.to_path_buf(),
            warning,
        })
        .collect()
}

/// Columns and time as decoded by a format reader, before unit, sidecar and frequency
/// resolution.
pub(crate) struct RawTable {
    pub(crate) columns: Vec<Column>,
    /// Stamps relative to the first one (in `time_unit` if stated, else unknown), exact for
    /// whole-number stamps.
    pub(crate) time: Option<Column>,
    /// The first stamp, in the same unit.
    pub(crate) time_origin: f64,
    /// Unit stated by the time column's name or the format.
    pub(crate) time_unit: Option<TimeUnit>,
    /// Rate fixed by the format (IMU records: docs/methods.md §9.2).
    pub(crate) freq_hz: Option<f64>,
    /// Physical lines of the data rows (text files).
    pub(crate) lines: Option<LineMap>,
    /// Columns left out of the default selection.
    pub(crate) skipped: Vec<String>,
    /// Header lines (text files: 0 or 1).
    pub(crate) header_lines: u64,
    /// Blank lines before the last data row (text files).
    pub(crate) blank_lines: u64,
    /// Rows dropped by the time policy: stamps repeating the previous one, stamps before it.
    pub(crate) dropped: DroppedRows,
}

/// Rows a [`TimePolicy`] dropped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct DroppedRows {
    /// Stamp equal to the previous kept one.
    pub(crate) repeated: u64,
    /// Stamp before the previous kept one (`drop-duplicates`).
    pub(crate) earlier: u64,
    /// Rows moved into place (`sort`).
    pub(crate) moved: u64,
}

impl DroppedRows {
    pub(crate) fn total(&self) -> u64 {
        self.repeated + self.earlier
    }
}

/// Physical line of each data row of a text file, stored as the rows where the line stops
/// following the row (blank lines): `(row, line)` pairs, the first at row 0.
#[derive(Debug, Default)]
pub(crate) struct LineMap {
    breaks: Vec<(usize, u64)>,
    rows: usize,
}

impl LineMap {
    /// Records that the next data row is on `line`.
    #[inline]
    pub(crate) fn push(&mut self, line: u64) {
        let expected = self.breaks.last().map(|&(r, l)| l + (self.rows - r) as u64);
        if expected != Some(line) {
            self.breaks.push((self.rows, line));
        }
        self.rows += 1;
    }

    /// The 1-based physical line of the 0-based data row `row`.
    pub(crate) fn line_of(&self, row: usize) -> u64 {
        let i = self.breaks.partition_point(|&(r, _)| r <= row);
        match i.checked_sub(1).map(|i| self.breaks[i]) {
            Some((r, l)) => l + (row - r) as u64,
            None => row as u64 + 1,
        }
    }
}

/// Resolved column selection: 0-based indices of the time column and the data columns.
pub(crate) struct Selection {
    pub(crate) time: Option<usize>,
    /// Unit stated by the time column's name.
    pub(crate) time_unit: Option<TimeUnit>,
    pub(crate) columns: Vec<usize>,
    pub(crate) skipped: Vec<String>,
}

/// Resolves selectors against the column names of a file (`names.len()` = number of columns),
/// finding the time column and the default columns as documented on [`read_table`].
pub(crate) fn resolve_selection(
    path: &Path,
    names: &[String],
    opts: &ReadOptions,
    sidecar: Option<&Sidecar>,
) -> Result<Selection, ReadError> {
    let resolve = |sel: &ColumnSelector| -> Result<usize, ReadError> {
        match sel {
            ColumnSelector::Index(i) if (1..=names.len()).contains(i) => Ok(i - 1),
            ColumnSelector::Index(i) => Err(ReadError::ColumnOutOfRange {
                path: path.to_path_buf(),
                index: *i,
                ncols: names.len(),
            }),
            ColumnSelector::Name(n) => {
                names
                    .iter()
                    .position(|m| m == n)
                    .ok_or_else(|| ReadError::UnknownColumn {
                        path: path.to_path_buf(),
                        name: n.clone(),
                        available: names.to_vec(),
                    })
            }
        }
    };
    let explicit: Vec<usize> = opts.columns.iter().map(resolve).collect::<Result<_, _>>()?;
    // every column named like a time column, header stamps first
    let mut times: Vec<(usize, Option<TimeUnit>)> = names
        .iter()
        .enumerate()
        .filter_map(|(k, n)| time_column_unit(n).map(|u| (k, u)))
        .collect();
    times.sort_by_key(|&(k, _)| (!names[k].to_ascii_lowercase().contains("header.stamp"), k));
    let (time, time_unit) = match &opts.time_column {
        Some(sel) => {
            let k = resolve(sel)?;
            (Some(k), time_column_unit(&names[k]).flatten())
        }
        None => match times.iter().find(|(k, _)| !explicit.contains(k)) {
            Some(&(k, u)) => (Some(k), u),
            None => (None, None),
        },
    };
    if !opts.columns.is_empty() {
        return Ok(Selection {
            time,
            time_unit,
            columns: explicit,
            skipped: Vec::new(),
        });
    }
    // masks, not searches: a header of n columns costs O(n) (a fuzzed header of thousands of
    // columns made the searches quadratic)
    let mut is_time = vec![false; names.len()];
    for &(t, _) in &times {
        is_time[t] = true;
    }
    let data: Vec<usize> = (0..names.len())
        .filter(|&k| Some(k) != time && !is_time[k])
        .collect();
    let is_axis = |k: usize| {
        SensorInfo::infer(&names[k]).is_some()
            || sidecar
                .and_then(|s| s.meaning(&names[k]))
                .and_then(SensorInfo::infer)
                .is_some()
    };
    let axes: Vec<usize> = data.iter().copied().filter(|&k| is_axis(k)).collect();
    let columns = if axes.is_empty() { data } else { axes };
    let mut selected = vec![false; names.len()];
    for &k in &columns {
        selected[k] = true;
    }
    let skipped = (0..names.len())
        .filter(|&k| Some(k) != time && !selected[k])
        .map(|k| names[k].clone())
        .collect();
    Ok(Selection {
        time,
        time_unit,
        columns,
        skipped,
    })
}

/// Default name of the 0-based column `k`: `col{k+1}`.
pub(crate) fn default_name(k: usize) -> String {
    format!("col{}", k + 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn column_selector_from_str() {
        assert_eq!(
            "3".parse::<ColumnSelector>().unwrap(),
            ColumnSelector::Index(3)
        );
        assert_eq!(
            "gyro_x".parse::<ColumnSelector>().unwrap(),
            ColumnSelector::Name("gyro_x".into())
        );
        assert_eq!(
            "0".parse::<ColumnSelector>().unwrap_err().to_string(),
            "invalid column = 0: a 1-based index (1, 2, ...)"
        );
        assert!("".parse::<ColumnSelector>().is_err());
    }

    #[test]
    fn input_format_from_str_and_resolve() {
        assert_eq!("F64".parse::<InputFormat>().unwrap(), InputFormat::F64);
        assert_eq!("tsv".parse::<InputFormat>().unwrap(), InputFormat::Tsv);
        assert!("xml".parse::<InputFormat>().is_err());
        for (text, f) in [
            ("ln200", InputFormat::ImuRecord(ImuRecordType::Ln200)),
            (
                "navchip-int",
                InputFormat::ImuRecord(ImuRecordType::NavchipInt),
            ),
            (
                "NAVCHIP_FLT",
                InputFormat::ImuRecord(ImuRecordType::NavchipFlt),
            ),
            ("f64le", InputFormat::F64),
        ] {
            assert_eq!(text.parse::<InputFormat>().unwrap(), f);
            assert_eq!(f.to_string().parse::<InputFormat>().unwrap(), f);
        }
        let r = |p: &str| InputFormat::Auto.resolve(Path::new(p));
        assert_eq!(r("gm3_N1000000.f64le.bin"), InputFormat::F64);
        assert_eq!(r("x.F32"), InputFormat::F32);
        assert_eq!(r("x.csv.gz"), InputFormat::Auto);
        assert_eq!(
            InputFormat::Tsv.resolve(Path::new("x.f64")),
            InputFormat::Tsv
        );
    }

    #[test]
    fn line_map_follows_blank_lines() {
        let mut m = LineMap::default();
        for l in [2, 3, 5, 6, 7, 10] {
            m.push(l);
        }
        let lines: Vec<u64> = (0..6).map(|r| m.line_of(r)).collect();
        assert_eq!(lines, [2, 3, 5, 6, 7, 10]);
        assert_eq!(m.breaks.len(), 3);
    }
}
