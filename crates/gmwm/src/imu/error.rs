//! [`ReadError`]: everything that can go wrong while reading an input file.
//!
//! Every variant carries the facts (path, 1-based physical line, column, offending text) as
//! fields; the messages follow STYLE §5: `path:line: column name: what is wrong`, lowercase, no
//! final period, the path exactly as the caller gave it.

use crate::error::ParamError;
use crate::imu::ros::RosError;
use std::path::PathBuf;
use thiserror::Error;

/// Reading or decoding an input file failed.
///
/// Line numbers are 1-based physical lines of the (decompressed) file, the header being line 1;
/// column indices are 1-based; sample indices in binary files are 0-based rows.
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
        "{}: no column named \"{name}\"; available: {}",
        .path.display(),
        .available.join(", ")
    )]
    UnknownColumn {
        /// File.
        path: PathBuf,
        /// The requested name.
        name: String,
        /// The names the file has (header names, or `col1`, `col2`, ... without a header).
        available: Vec<String>,
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
         {previous}; the time column must be strictly increasing",
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
    /// An option has an impossible value (e.g. `ncols = 0`, `freq_hz = -1`).
    #[error(transparent)]
    InvalidOption(#[from] ParamError),
    /// A ROS recording (bag, MCAP, rosbag2 sqlite3) cannot be read (see [`RosError`]).
    #[error(transparent)]
    Ros(#[from] RosError),
}
