//! IMU data and readers. STUB: owned by the reader helper.

use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Reading errors.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ReadError {
    /// I/O.
    #[error("{path}: {source}")]
    Io {
        /// File.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
}

/// Column selector: 1-based index or header name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ColumnSelector {
    /// 1-based index.
    Index(usize),
    /// Header name.
    Name(String),
}

/// Input format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InputFormat {
    /// From the extension.
    #[default]
    Auto,
    /// Comma separated.
    Csv,
    /// Tab separated.
    Tsv,
    /// Raw little-endian f64.
    F64,
    /// Raw little-endian f32.
    F32,
}

/// Header handling.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HeaderMode {
    /// Detect.
    #[default]
    Auto,
    /// First row is a header.
    Present,
    /// No header.
    Absent,
}

/// Options.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ReadOptions {
    /// Format.
    pub format: InputFormat,
    /// Header.
    pub header: HeaderMode,
    /// Time column, if any.
    pub time_column: Option<ColumnSelector>,
    /// Columns to read (empty: all but the time column).
    pub columns: Vec<ColumnSelector>,
    /// Interleaved columns in a binary file.
    pub ncols: Option<usize>,
    /// Sampling rate override.
    pub freq_hz: Option<f64>,
}

/// One column.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Column {
    /// Name.
    pub name: String,
    /// Values.
    pub values: Vec<f64>,
}

/// A table read from a file.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// File.
    pub path: PathBuf,
    /// Columns.
    pub columns: Vec<Column>,
    /// Rate.
    pub freq_hz: Option<f64>,
}

/// Reads a file.
pub fn read_table(_path: &Path, _opts: &ReadOptions) -> Result<Table, ReadError> {
    unimplemented!()
}
