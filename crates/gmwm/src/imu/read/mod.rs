//! Readers: delimited text (CSV/TSV, optionally gzip-compressed) and raw little-endian binary.
//!
//! [`read_table`] is the entry point: it picks the format ([`InputFormat::Auto`] looks at the
//! file name and the gzip magic bytes), materialises only the selected columns, reads the JSON
//! sidecar if there is one and resolves the sampling frequency (see [`read_table`]).

pub(crate) mod binary;
pub(crate) mod text;

pub use binary::{for_each_chunk, read_imu_record_file, BinaryChunks, ImuRecordType};

use super::sidecar::{find_sidecar, Sidecar};
use super::ReadError;
use crate::error::{check_freq, ParamError};
use serde::{Deserialize, Serialize};
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
    /// From the file name (default): `*.f64`, `*.f64le`, `*.f64.bin`, `*.f64le.bin` → [`F64`],
    /// the same with `f32` → [`F32`], anything else is delimited text whose delimiter is sniffed
    /// from the first line (`.tsv` prefers tab, other names prefer comma).
    ///
    /// [`F64`]: InputFormat::F64
    /// [`F32`]: InputFormat::F32
    #[default]
    Auto,
    /// Comma separated (no sniffing).
    Csv,
    /// Tab separated (no sniffing).
    Tsv,
    /// Raw little-endian f64, `ncols` interleaved columns.
    F64,
    /// Raw little-endian f32, `ncols` interleaved columns.
    F32,
}

impl FromStr for InputFormat {
    type Err = ParamError;

    /// `auto`, `csv`, `tsv`, `f64`, `f32` (case-insensitive).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "auto" => Ok(Self::Auto),
            "csv" => Ok(Self::Csv),
            "tsv" => Ok(Self::Tsv),
            "f64" => Ok(Self::F64),
            "f32" => Ok(Self::F32),
            _ => Err(ParamError::new(
                "format",
                s,
                "one of auto, csv, tsv, f64, f32",
            )),
        }
    }
}

impl InputFormat {
    /// Bytes per value of a binary format, `None` for text formats.
    pub fn value_width(self) -> Option<usize> {
        match self {
            Self::F64 => Some(8),
            Self::F32 => Some(4),
            _ => None,
        }
    }

    /// Resolves [`InputFormat::Auto`] from the file name (see the variant's doc).
    pub fn resolve(self, path: &Path) -> Self {
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

/// Options of [`read_table`]. The default reads every column of any supported file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ReadOptions {
    /// Format (default [`InputFormat::Auto`]).
    pub format: InputFormat,
    /// Header handling of text files (default [`HeaderMode::Auto`]); ignored for binary.
    pub header: HeaderMode,
    /// Time column, if any (default none: rows are equally spaced at `freq_hz`). Must be finite
    /// and strictly increasing; it is returned in [`Table::time`], not among the columns.
    pub time_column: Option<ColumnSelector>,
    /// Columns to read, in this order (default empty: all but the time column).
    pub columns: Vec<ColumnSelector>,
    /// Interleaved columns in a binary file (default `None` = 1); ignored for text.
    pub ncols: Option<usize>,
    /// Sampling rate override in Hz (default `None`: from the time column, else the sidecar).
    pub freq_hz: Option<f64>,
}

/// One column.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Column {
    /// Name (header name, or `col1`, `col2`, ... 1-based, when there is none).
    pub name: String,
    /// Values, all finite.
    pub values: Vec<f64>,
}

/// A table read from a file.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// File, as given by the caller.
    pub path: PathBuf,
    /// Selected columns, in the requested order, all of the same length (≥ 1).
    pub columns: Vec<Column>,
    /// Sampling rate in Hz, resolved as documented on [`read_table`].
    pub freq_hz: Option<f64>,
    /// The JSON sidecar beside the file, if any.
    pub sidecar: Option<Sidecar>,
    /// The time column (finite, strictly increasing), if one was selected.
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

/// Reads a text or binary file into a [`Table`].
///
/// Sampling frequency, first match wins: `opts.freq_hz`; the time column, as
/// `1 / mean(diff(t)) = (n - 1) / (t_last - t_first)` — unlike METHODS §9.2 (binary IMU records)
/// it is not rounded, so non-integer rates such as 62.5 Hz survive; the sidecar's
/// `sampling_frequency_hz`; otherwise `None` and the caller decides.
///
/// Cost: one pass over the file; only the selected columns are stored.
///
/// # Errors
/// Any [`ReadError`]: I/O, empty or header-only file, ragged row, non-numeric or non-finite cell
/// (with its line and column), unknown column, binary size not a multiple of the record size,
/// corrupt gzip, unreadable sidecar, non-increasing time, invalid options.
pub fn read_table(path: &Path, opts: &ReadOptions) -> Result<Table, ReadError> {
    if let Some(f) = opts.freq_hz {
        check_freq(f)?;
    }
    let raw = match opts.format.resolve(path) {
        f @ (InputFormat::F64 | InputFormat::F32) => binary::read_binary_table(path, f, opts)?,
        f => text::read_text_table(path, f, opts)?,
    };
    let sidecar = find_sidecar(path)?;
    let freq_from_time = raw.time.as_ref().and_then(|t| freq_from_times(&t.values));
    let freq_hz = opts
        .freq_hz
        .or(freq_from_time)
        .or_else(|| sidecar.as_ref().and_then(|s| s.sampling_frequency_hz));
    if let Some(f) = freq_hz {
        // a rate from the options, the time column or the sidecar must be usable: never
        // silently replaced by a default
        check_freq(f)?;
    }
    Ok(Table {
        path: path.to_path_buf(),
        columns: raw.columns,
        freq_hz,
        sidecar,
        time: raw.time,
    })
}

/// Columns and time as decoded by a format reader, before sidecar and frequency resolution.
pub(crate) struct RawTable {
    pub(crate) columns: Vec<Column>,
    pub(crate) time: Option<Column>,
}

/// `1 / mean(diff(t))`, `None` with fewer than two times or a non-positive span.
pub(crate) fn freq_from_times(t: &[f64]) -> Option<f64> {
    let (first, last) = (t.first()?, t.last()?);
    let span = last - first;
    let f = (t.len() - 1) as f64 / span;
    (t.len() >= 2 && span > 0.0 && f.is_finite()).then_some(f)
}

/// Resolved column selection: 0-based indices of the time column and the data columns.
pub(crate) struct Selection {
    pub(crate) time: Option<usize>,
    pub(crate) columns: Vec<usize>,
}

/// Resolves selectors against the column names of a file (`names.len()` = number of columns).
pub(crate) fn resolve_selection(
    path: &Path,
    names: &[String],
    opts: &ReadOptions,
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
    let time = opts.time_column.as_ref().map(resolve).transpose()?;
    let columns = if opts.columns.is_empty() {
        (0..names.len()).filter(|&k| Some(k) != time).collect()
    } else {
        opts.columns.iter().map(resolve).collect::<Result<_, _>>()?
    };
    Ok(Selection { time, columns })
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
    fn freq_from_times_is_inverse_mean_step() {
        assert_eq!(freq_from_times(&[0.0, 0.016, 0.032]), Some(62.5));
        assert_eq!(freq_from_times(&[1.0]), None);
        assert_eq!(freq_from_times(&[]), None);
        assert!(check_freq(0.0).is_err() && check_freq(f64::NAN).is_err());
        assert!(check_freq(100.0).is_ok());
    }
}
