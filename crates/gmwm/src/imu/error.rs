//! [`ReadError`]: everything that can go wrong while reading an input file.
//!
//! Every variant carries the facts (path, 1-based physical line, column, offending text) as
//! fields; the messages follow STYLE §5: `path:line: column name: what is wrong`, lowercase, no
//! final period, the path exactly as the caller gave it.

use crate::error::ParamError;
use crate::imu::ros::RosError;
use std::path::PathBuf;
use thiserror::Error;

/// Longest text from a file quoted in a message, in characters (a cell, a header name).
pub(crate) const QUOTE_MAX: usize = 40;

/// Text from a file made safe for a one-line message: control and other non-printable
/// characters escaped (`\n`, `\u{0}`), cut to `QUOTE_MAX` characters with `...` appended.
pub fn quote(text: &str) -> String {
    escaped(text, QUOTE_MAX)
}

/// [`quote`] cut at `max` characters instead: for a table that shows names whole up to a
/// bound (a ROS topic).
///
/// ```
/// assert_eq!(gmwm::quote_up_to("/imu\n0", 3), "/im...");
/// assert_eq!(gmwm::quote_up_to("/imu\n0", 10), "/imu\\n0");
/// ```
pub fn quote_up_to(text: &str, max: usize) -> String {
    escaped(text, max)
}

/// `text` with control characters (and U+FFFD) escaped, whole: for a message of the engine's
/// own that may hold text from a file.
pub(crate) fn escape_control(text: &str) -> String {
    escaped(text, usize::MAX)
}

/// `text` with control characters (and U+FFFD) escaped, cut to `max` characters with `...`
/// appended.
fn escaped(text: &str, max: usize) -> String {
    let mut out = String::new();
    for (count, c) in text.chars().enumerate() {
        if count == max {
            out.push_str("...");
            break;
        }
        if c.is_control() || c == '\u{fffd}' {
            out.extend(c.escape_debug());
        } else {
            out.push(c);
        }
    }
    out
}

/// `text` with its control characters escaped (`\u{8}` for a backspace, `\n`, `\t`): a column
/// name from a file's header as every output shows it, so that no terminal, CSV or YAML file
/// receives raw control bytes.
pub(crate) fn printable(text: &str) -> String {
    escaped(text, usize::MAX)
}

/// Longest message of another library (e.g. SQLite's, which may quote SQL from the file)
/// kept in an error, in characters.
pub(crate) const CAUSE_MAX: usize = 200;

/// A message of another library made one line: runs of whitespace (newlines included) become
/// one space, other control characters are escaped, cut to [`CAUSE_MAX`] characters with
/// `...` appended.
#[cfg_attr(not(any(feature = "sqlite", test)), allow(dead_code))]
pub(crate) fn one_line(text: &str) -> String {
    let mut out = String::new();
    for (count, c) in text
        .split_whitespace()
        .flat_map(|w| std::iter::once(' ').chain(w.chars()))
        .skip(1)
        .enumerate()
    {
        if count == CAUSE_MAX {
            out.push_str("...");
            break;
        }
        if c.is_control() {
            out.extend(c.escape_debug());
        } else {
            out.push(c);
        }
    }
    out
}

/// A name taken from a file (a ROS topic or message type), or another library's message that
/// quotes the file (serde's unknown variant), made safe for a one-line message:
/// control characters escaped, cut to [`CAUSE_MAX`] characters with `...` appended (longer
/// than [`quote`]'s cut, so that real names are shown whole).
pub(crate) fn escape_name(text: &str) -> String {
    escaped(text, CAUSE_MAX)
}

/// At most this many column names are listed in an error (the rest are counted).
const LIST_MAX: usize = 20;

/// Column names for a message: each [`quote`]d, at most 20, then `... (N more)`.
pub(crate) fn name_list(names: &[String]) -> String {
    let mut parts: Vec<String> = names.iter().take(LIST_MAX).map(|n| quote(n)).collect();
    if names.len() > LIST_MAX {
        parts.push(format!("... ({} more)", names.len() - LIST_MAX));
    }
    parts.join(", ")
}

/// Reading or decoding an input file failed.
///
/// Line numbers are 1-based physical lines of the (decompressed) file, the header being line 1;
/// column indices are 1-based; sample indices in binary files are 0-based rows. Text taken
/// from a file (cells, header names) is cut to `QUOTE_MAX` characters with non-printable
/// characters escaped ([`quote`]), so no message can dump a file.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ReadError {
    /// The operating system refused to open or read the file.
    #[error("{}: {source}", .path.display())]
    Io {
        /// File as given by the caller.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
    /// The file holds no data at all (zero bytes or blank lines only).
    #[error("{}: file is empty (no data rows)", .path.display())]
    Empty {
        /// File.
        path: PathBuf,
    },
    /// The file holds a header row and nothing else.
    #[error("{}: file has a header (line 1) but no data rows", .path.display())]
    HeaderOnly {
        /// File.
        path: PathBuf,
    },
    /// A row has a different number of fields than the first row.
    #[error(
        "{}:{line}: row has {found} fields; expected {expected} like line {first_line}",
        .path.display()
    )]
    Ragged {
        /// File.
        path: PathBuf,
        /// 1-based physical line of the bad row.
        line: u64,
        /// 1-based line of the first row, which set the expected count.
        first_line: u64,
        /// Number of fields of the first row.
        expected: usize,
        /// Number of fields found.
        found: usize,
    },
    /// A cell of a selected column is not a number.
    #[error("{}:{line}: column {column}: \"{text}\" is not a number", .path.display())]
    NotANumber {
        /// File.
        path: PathBuf,
        /// 1-based physical line.
        line: u64,
        /// Column name (header name, or `colK` without a header).
        column: String,
        /// The offending text.
        text: String,
    },
    /// A cell of a selected column is NaN or infinite.
    #[error("{}:{line}: column {column}: \"{text}\" is not a finite number", .path.display())]
    NonFinite {
        /// File.
        path: PathBuf,
        /// 1-based physical line.
        line: u64,
        /// Column name (header name, or `colK` without a header).
        column: String,
        /// The offending text.
        text: String,
    },
    /// A value of a binary file is NaN or infinite.
    #[error(
        "{}: sample {index} (0-based) of column {column}: {value} is not a finite number",
        .path.display()
    )]
    BinaryNonFinite {
        /// File.
        path: PathBuf,
        /// 0-based row (sample) index.
        index: u64,
        /// 1-based column.
        column: usize,
        /// The value read.
        value: f64,
    },
    /// A column was selected by a name the file does not have.
    #[error(
        "{}: no column named \"{}\"; available: {}",
        .path.display(),
        quote(.name),
        name_list(.available)
    )]
    UnknownColumn {
        /// File.
        path: PathBuf,
        /// The requested name.
        name: String,
        /// The names the file has (header names, or `col1`, `col2`, ... without a header).
        available: Vec<String>,
    },
    /// A series of a wavelet-variance JSON was selected by a name the file does not have.
    #[error(
        "{}: no series named \"{}\"; available: {}",
        .path.display(),
        quote(.name),
        name_list(.available)
    )]
    UnknownSeries {
        /// File.
        path: PathBuf,
        /// The requested name.
        name: String,
        /// The series names of the file.
        available: Vec<String>,
    },
    /// A series of a wavelet-variance JSON was selected by an index outside `1..=count`.
    #[error(
        "{}: series {index} is out of range; the file has {count} series (1-based: 1..={count})",
        .path.display()
    )]
    SeriesOutOfRange {
        /// File.
        path: PathBuf,
        /// The requested 1-based index.
        index: usize,
        /// Number of series in the file.
        count: usize,
    },
    /// A column was selected by an index outside `1..=ncols`.
    #[error(
        "{}: column {index} is out of range; the file has {ncols} columns (1-based: 1..={ncols})",
        .path.display()
    )]
    ColumnOutOfRange {
        /// File.
        path: PathBuf,
        /// The requested 1-based index.
        index: usize,
        /// Number of columns of the file.
        ncols: usize,
    },
    /// A file read as text (no binary `format` given, none known from its name or sidecar)
    /// holds bytes that no text file has (NUL or invalid UTF-8 in its first 4 KiB).
    #[error(
        "{}: looks like binary data, not text; give --format \
         f64|f32|imar|ln200|ln200ig|ixsea|navchip-int|navchip-flt",
        .path.display()
    )]
    LooksBinary {
        /// File.
        path: PathBuf,
    },
    /// A text file in UTF-16 (by its byte-order mark): refused with what it is instead of as
    /// binary data.
    #[error(
        "{}: text is UTF-16 {} (byte-order mark {}), not UTF-8; save it as UTF-8",
        .path.display(),
        if *.big_endian { "big-endian" } else { "little-endian" },
        if *.big_endian { "FE FF" } else { "FF FE" }
    )]
    Utf16 {
        /// File.
        path: PathBuf,
        /// Byte order: FE FF (big-endian) or FF FE.
        big_endian: bool,
    },
    /// 8-bit text (Latin-1, Windows-1252, ...): printable but for bytes that are not UTF-8.
    #[error(
        "{}:{line}: byte 0x{byte:02x} is not UTF-8 (8-bit text such as Latin-1 or \
         Windows-1252?); save the file as UTF-8",
        .path.display()
    )]
    NotUtf8 {
        /// File.
        path: PathBuf,
        /// 1-based line of the first such byte.
        line: u64,
        /// The byte.
        byte: u8,
    },
    /// A text file whose lines end in a carriage return alone (classic Mac OS): read as one
    /// line, it would have a header and no data.
    #[error(
        "{}: lines end in a carriage return alone (CR, classic Mac OS); save it with LF or \
         CRLF line ends",
        .path.display()
    )]
    CrLineEnds {
        /// File.
        path: PathBuf,
    },
    /// A JSON document was given where a table of samples is read.
    #[error(
        "{}: is JSON, not a table of samples (a wavelet variance saved by `gmwm wv --json` is \
         read as such by fit, select, wv and avar)",
        .path.display()
    )]
    NotATable {
        /// File.
        path: PathBuf,
    },
    /// The epochs of a binary IMU record file (docs/methods.md §9.2) are not in increasing time
    /// order.
    #[error(
        "{}: record {index} (0-based): time {value} is not greater than the previous time \
         {previous}; the epochs must be in strictly increasing time order",
        .path.display()
    )]
    RecordTimeNotIncreasing {
        /// File.
        path: PathBuf,
        /// 0-based index of the offending record.
        index: u64,
        /// Time of the record before it, in seconds.
        previous: f64,
        /// Its time, in seconds.
        value: f64,
    },
    /// An increment of a binary IMU record file times the rate and the scale (docs/methods.md §9.3)
    /// is not a finite rate: the epochs' times (hence the rate) are implausible.
    #[error(
        "{}: record {index} (0-based): {column} increment {raw} times the rate {freq_hz} Hz \
         and the scale is not a finite number; the epochs' times give an implausible rate",
        .path.display()
    )]
    RecordRateOverflow {
        /// File.
        path: PathBuf,
        /// 0-based index of the record.
        index: u64,
        /// Column (`gyro_x` ... `accel_z`).
        column: String,
        /// The raw increment.
        raw: f64,
        /// The rate derived from the epochs, in Hz.
        freq_hz: f64,
    },
    /// A raw binary file does not hold a whole number of records.
    #[error(
        "{}: size {size} bytes is not a multiple of the record size {record_size} bytes \
         ({remainder} bytes left over)",
        .path.display()
    )]
    BinarySize {
        /// File.
        path: PathBuf,
        /// File size in bytes.
        size: u64,
        /// Bytes per record (row).
        record_size: u64,
        /// `size % record_size`.
        remainder: u64,
    },
    /// The gzip stream is corrupt or truncated.
    #[error("{}: corrupt or truncated gzip stream: {source}", .path.display())]
    Gzip {
        /// File.
        path: PathBuf,
        /// Cause reported by the decoder.
        source: std::io::Error,
    },
    /// The recording's rows do not fit in the memory this process can allocate (a command
    /// that holds the recording; `wv` and `calibrate` stream long recordings).
    #[error(
        "{}: holding more than {rows} rows of {columns} column(s) in memory failed (the \
         recording decompresses to more than this process may allocate); `wv` and \
         `calibrate` stream recordings this long",
        .path.display()
    )]
    TooLarge {
        /// File.
        path: PathBuf,
        /// Rows held when the allocation failed.
        rows: u64,
        /// Columns per row.
        columns: usize,
    },
    /// The JSON sidecar exists but cannot be parsed.
    #[error("{}: sidecar JSON is unreadable: {source}", .path.display())]
    Sidecar {
        /// The sidecar file.
        path: PathBuf,
        /// Cause.
        source: serde_json::Error,
    },
    /// The time column is not strictly increasing.
    #[error(
        "{}:{line}: column {column}: time {value} is not greater than the previous time \
         {previous}; the time column must be strictly increasing (--time-policy \
         drop-duplicates drops such rows, --time-policy sort sorts them)",
        .path.display()
    )]
    TimeNotIncreasing {
        /// File.
        path: PathBuf,
        /// 1-based physical line (text) or 1-based row (binary).
        line: u64,
        /// Name of the time column.
        column: String,
        /// Previous time.
        previous: f64,
        /// This time.
        value: f64,
    },
    /// Two consecutive time stamps, strictly increasing as read, can no longer be told apart
    /// (or one is not finite) once converted to seconds after the first stamp: the stamps span
    /// too wide a range for the resolution of f64 (a corrupt stamp, usually).
    #[error(
        "{}: {}: column {}: time {value} s after the first stamp ({first} s) does not follow          the previous one ({previous} s after it) once taken relative to the first stamp: the          stamps span too wide a range for their resolution",
        .path.display(),
        .line.map_or_else(|| format!("sample {row} (0-based)"), |l| format!("line {l}")),
        quote(.column)
    )]
    TimeResolution {
        /// File.
        path: PathBuf,
        /// 1-based physical line (text files).
        line: Option<u64>,
        /// 0-based row.
        row: u64,
        /// Name of the time column.
        column: String,
        /// The first stamp, in seconds.
        first: f64,
        /// The previous stamp, in seconds after the first.
        previous: f64,
        /// This stamp, in seconds after the first.
        value: f64,
    },
    /// Every column of the file is a time column: there is nothing to analyse.
    #[error(
        "{}: no column to analyse: every column is a time column ({}); --columns selects a \
         column anyway",
        .path.display(),
        name_list(.columns)
    )]
    NoDataColumn {
        /// File.
        path: PathBuf,
        /// The time columns.
        columns: Vec<String>,
    },
    /// The sampling frequency cannot be derived from the file.
    #[error("{}: sampling frequency cannot be derived: {reason}", .path.display())]
    FreqNotDerivable {
        /// File.
        path: PathBuf,
        /// Why (e.g. "fewer than 2 epochs"); a fixed phrase, not formatted data.
        reason: &'static str,
    },
    /// A wavelet-variance JSON file is not usable (what is wrong, naming the series and field).
    #[error("{}: not a usable wavelet-variance JSON: {reason}", .path.display())]
    WvJson {
        /// File.
        path: PathBuf,
        /// What is wrong, e.g. `series[0] (gyro_x): tau[2] = 12, expected 8`.
        reason: String,
    },
    /// A column read from the file cannot be analysed (constant, or too short for the levels
    /// asked): the error of a computation that streams the file instead of loading it.
    #[error("{}: column {}: {source}", .path.display(), quote(.column))]
    Series {
        /// File.
        path: PathBuf,
        /// Column name.
        column: String,
        /// Why.
        source: crate::error::SeriesError,
    },
    /// An option has an impossible value (e.g. `ncols = 0`, `freq_hz = -1`).
    #[error(transparent)]
    InvalidOption(#[from] ParamError),
    /// A ROS recording (bag, MCAP, rosbag2 sqlite3) cannot be read (see [`RosError`]).
    #[error(transparent)]
    Ros(#[from] RosError),
}
