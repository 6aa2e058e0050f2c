//! Raw little-endian binary: interleaved f64/f32 columns, and the IMU epoch records of
//! docs/methods.md §9.2.
//!
//! Values are decoded with `from_le_bytes` (never text parsing). Whole-file reads read the file
//! by positioned reads into one buffer (`super::positioned`); [`BinaryChunks`] reads fixed-size blocks so that series of 10^9 samples can be consumed
//! in bounded memory.

use super::positioned::read_at;
use super::{binary_names, resolve_selection, Column, InputFormat, RawTable, ReadOptions};
use crate::error::ParamError;
use crate::imu::timing::{check_times, TimeUnit, UnitSource};
#[cfg(test)]
use crate::imu::Imu;
#[cfg(test)]
use crate::imu::ReadError as Error;
use crate::imu::{ReadError, Sidecar};
use std::fmt;
use std::fs::File;
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// Read buffer of [`BinaryChunks`].
const BUF_CAPACITY: usize = 1 << 20;

/// Decodes one little-endian value of `width` (8 or 4) bytes starting at `bytes[0]`.
///
/// # Panics
/// If `bytes` is shorter than the width (an internal invariant: callers slice whole records).
#[inline]
pub(crate) fn decode(bytes: &[u8], width: usize) -> f64 {
    if width == 8 {
        let mut a = [0u8; 8];
        a.copy_from_slice(&bytes[..8]);
        f64::from_le_bytes(a)
    } else {
        let mut a = [0u8; 4];
        a.copy_from_slice(&bytes[..4]);
        f64::from(f32::from_le_bytes(a))
    }
}

#[inline]
pub(crate) fn decode_i32(bytes: &[u8]) -> f64 {
    let mut a = [0u8; 4];
    a.copy_from_slice(&bytes[..4]);
    f64::from(i32::from_le_bytes(a))
}

#[cold]
fn io_error(path: &Path, source: std::io::Error) -> ReadError {
    ReadError::Io {
        path: path.to_path_buf(),
        source,
    }
}

#[cold]
pub(crate) fn non_finite(path: &Path, index: usize, column: usize, value: f64) -> ReadError {
    ReadError::BinaryNonFinite {
        path: path.to_path_buf(),
        index: index as u64,
        column,
        value,
    }
}

/// Opens a binary file and checks its size: non-empty and a whole number of `record` bytes.
/// Returns the file and the number of records.
pub(crate) fn open_records(path: &Path, record: usize) -> Result<(File, u64), ReadError> {
    let file = File::open(path).map_err(|e| io_error(path, e))?;
    let size = file.metadata().map_err(|e| io_error(path, e))?.len();
    let record = record as u64;
    if size == 0 {
        return Err(ReadError::Empty {
            path: path.to_path_buf(),
        });
    }
    if size % record != 0 {
        return Err(ReadError::BinarySize {
            path: path.to_path_buf(),
            size,
            record_size: record,
            remainder: size % record,
        });
    }
    Ok((file, size / record))
}

/// Records read at a time by the whole-file readers.
const TABLE_CHUNK_ROWS: u64 = 1 << 16;

/// Calls `f(first, bytes)` on consecutive runs of whole records (`first` is the index of the
/// run's first record) of `rows` records of `record` bytes, read with positioned reads of
/// [`TABLE_CHUNK_ROWS`] records into one buffer. The whole-file readers read so, not through a
/// memory map: a file truncated or rewritten by another process while it is read gives an error
/// (or the bytes read), never undefined behaviour, and the resident set is the output plus one
/// buffer.
pub(crate) fn for_each_record_run(
    path: &Path,
    file: &File,
    (rows, record): (u64, usize),
    mut f: impl FnMut(usize, &[u8]) -> Result<(), ReadError>,
) -> Result<(), ReadError> {
    let mut buf = vec![0u8; TABLE_CHUNK_ROWS.min(rows) as usize * record];
    let mut row = 0u64;
    while row < rows {
        let n = (rows - row).min(TABLE_CHUNK_ROWS) as usize;
        let bytes = &mut buf[..n * record];
        read_at(path, file, bytes, row * record as u64)?;
        f(row as usize, bytes)?;
        row += n as u64;
    }
    Ok(())
}

/// The columns `wanted` (in that order) of a raw binary file of `rows` records of `record`
/// bytes, `width` bytes a value ([`for_each_record_run`]).
fn read_columns(
    path: &Path,
    file: &File,
    (rows, record, width): (u64, usize, usize),
    wanted: &[usize],
) -> Result<Vec<Vec<f64>>, ReadError> {
    let capacity = usize::try_from(rows).unwrap_or(usize::MAX);
    let mut out: Vec<Vec<f64>> = wanted
        .iter()
        .map(|_| Vec::with_capacity(capacity))
        .collect();
    for_each_record_run(path, file, (rows, record), |_, bytes| {
        for (values, &k) in out.iter_mut().zip(wanted) {
            values.extend(
                bytes
                    .chunks_exact(record)
                    .map(|r| decode(&r[k * width..], width)),
            );
        }
        Ok(())
    })?;
    Ok(out)
}

fn width_of(format: InputFormat) -> Result<usize, ParamError> {
    format.value_width().ok_or_else(|| {
        ParamError::new(
            "format",
            format!("{format:?}").to_lowercase(),
            "f64 or f32 for a raw binary file",
        )
    })
}

fn check_ncols(ncols: usize) -> Result<(), ParamError> {
    if ncols == 0 {
        Err(ParamError::new("ncols", 0, "at least 1 interleaved column"))
    } else {
        Ok(())
    }
}

/// Bytes per row of `ncols` interleaved values of `width` bytes.
pub(crate) fn record_size(width: usize, ncols: usize) -> Result<usize, ParamError> {
    check_ncols(ncols)?;
    width.checked_mul(ncols).ok_or_else(|| {
        ParamError::new(
            "ncols",
            ncols,
            format!("a column count whose rows of {width}-byte values fit in memory"),
        )
    })
}

/// Opens a raw binary file of rows of `record` bytes and checks its size (non-empty, a whole
/// number of rows).
pub(crate) fn check_records(path: &Path, record: usize) -> Result<u64, ReadError> {
    open_records(path, record).map(|(_, rows)| rows)
}

/// Reads a raw binary table with positioned reads ([`read_columns`]). `ncols` and the column
/// names come from the options, else the sidecar.
pub(crate) fn read_binary_table(
    path: &Path,
    format: InputFormat,
    opts: &ReadOptions,
    sidecar: Option<&Sidecar>,
) -> Result<RawTable, ReadError> {
    let width = width_of(format)?;
    let ncols = opts
        .ncols
        .or_else(|| sidecar.and_then(|s| s.n_columns))
        .unwrap_or(1);
    let record = record_size(width, ncols)?;
    // the size first: a column count (from a sidecar) is data, its names are only made for
    // columns the file can hold
    let (file, rows) = open_records(path, record)?;
    let names = binary_names(sidecar, ncols);
    let sel = resolve_selection(path, &names, opts, sidecar)?;
    // the time column (if any) first, then the selected ones, in one pass over the file
    let wanted: Vec<usize> = sel.time.iter().chain(&sel.columns).copied().collect();
    let mut read = read_columns(path, &file, (rows, record, width), &wanted)?.into_iter();
    let mut column = |k: usize| -> Result<Vec<f64>, ReadError> {
        let values = read.next().unwrap_or_default();
        match values.iter().position(|v| !v.is_finite()) {
            Some(i) => Err(non_finite(path, i, k + 1, values[i])),
            None => Ok(values),
        }
    };
    let time = match sel.time {
        Some(k) => {
            let values = column(k)?;
            if let Some(i) = values.windows(2).position(|w| w[1] <= w[0]) {
                return Err(ReadError::TimeNotIncreasing {
                    path: path.to_path_buf(),
                    line: i as u64 + 2,
                    column: names[k].clone(),
                    previous: values[i],
                    value: values[i + 1],
                });
            }
            Some(Column {
                name: names[k].clone(),
                values,
            })
        }
        None => None,
    };
    // stamps relative to the first, as the text reader gives them
    let time_origin = time.as_ref().map_or(0.0, |t| t.values[0]);
    let time = time.map(|mut t| {
        t.values.iter_mut().for_each(|v| *v -= time_origin);
        t
    });
    let columns = sel
        .columns
        .iter()
        .map(|&k| {
            Ok(Column {
                name: names[k].clone(),
                values: column(k)?,
            })
        })
        .collect::<Result<_, ReadError>>()?;
    Ok(RawTable {
        dropped: super::DroppedRows::default(),
        columns,
        time,
        time_origin,
        time_unit: sel.time_unit,
        freq_hz: None,
        lines: None,
        skipped: sel.skipped,
        header_lines: 0,
        blank_lines: 0,
    })
}

/// Streaming reader of one column of a raw binary file, chunk by chunk, in bounded memory
/// (`chunk_len · ncols · width` bytes plus a 1 MiB buffer); the column is never materialised.
///
/// Worked example: the test `tests::examples::example_read_binary_binarychunks`.
#[derive(Debug)]
pub(crate) struct BinaryChunks {
    path: PathBuf,
    reader: BufReader<File>,
    width: usize,
    ncols: usize,
    column: usize,
    chunk_len: usize,
    rows: u64,
    row: u64,
    bytes: Vec<u8>,
    values: Vec<f64>,
}

impl BinaryChunks {
    /// Opens `path` holding `ncols` interleaved little-endian columns of `format` (F64 or F32)
    /// and prepares to read column `column` (1-based) in chunks of `chunk_len` samples (the last
    /// one may be shorter).
    ///
    /// # Errors
    /// [`ReadError::InvalidOption`] for a text format, `ncols = 0` or `chunk_len = 0`;
    /// [`ReadError::ColumnOutOfRange`]; [`ReadError::Io`]; [`ReadError::Empty`];
    /// [`ReadError::BinarySize`] if the size is not a multiple of `width · ncols`.
    pub(crate) fn open(
        path: &Path,
        format: InputFormat,
        ncols: usize,
        column: usize,
        chunk_len: usize,
    ) -> Result<Self, ReadError> {
        let width = width_of(format)?;
        check_ncols(ncols)?;
        if chunk_len == 0 {
            return Err(ParamError::new("chunk_len", 0, "at least 1 sample").into());
        }
        if !(1..=ncols).contains(&column) {
            return Err(ReadError::ColumnOutOfRange {
                path: path.to_path_buf(),
                index: column,
                ncols,
            });
        }
        let (file, rows) = open_records(path, record_size(width, ncols)?)?;
        Ok(Self {
            path: path.to_path_buf(),
            reader: BufReader::with_capacity(BUF_CAPACITY, file),
            width,
            ncols,
            column: column - 1,
            chunk_len,
            rows,
            row: 0,
            bytes: Vec::new(),
            values: Vec::with_capacity(chunk_len),
        })
    }

    /// Number of rows (samples per column) of the file.
    pub(crate) fn rows(&self) -> u64 {
        self.rows
    }

    /// The next chunk, `None` after the last one.
    ///
    /// # Errors
    /// [`ReadError::Io`] (including a file truncated while reading) and
    /// [`ReadError::BinaryNonFinite`] with the 0-based sample index.
    pub(crate) fn next_chunk(&mut self) -> Result<Option<&[f64]>, ReadError> {
        let Some(n) = self.read_rows()? else {
            return Ok(None);
        };
        let record = self.width * self.ncols;
        self.values.clear();
        let offset = self.column * self.width;
        let width = self.width;
        self.values.extend(
            self.bytes
                .chunks_exact(record)
                .map(|r| decode(&r[offset..], width)),
        );
        if let Some(i) = self.values.iter().position(|v| !v.is_finite()) {
            let index = self.row as usize + i;
            return Err(non_finite(
                &self.path,
                index,
                self.column + 1,
                self.values[i],
            ));
        }
        self.row += n as u64;
        Ok(Some(&self.values))
    }

    /// Skips the next `rows` rows (at most those left) without reading them.
    ///
    /// # Errors
    /// [`ReadError::Io`].
    pub(crate) fn skip_rows(&mut self, rows: u64) -> Result<(), ReadError> {
        let rows = rows.min(self.rows - self.row);
        let record = (self.width * self.ncols) as u64;
        let bytes = i64::try_from(rows * record)
            .map_err(|_| ParamError::new("rows", rows, "a skip within the file"))?;
        self.reader
            .seek_relative(bytes)
            .map_err(|e| io_error(&self.path, e))?;
        self.row += rows;
        Ok(())
    }

    /// Reads the bytes of the next chunk of rows into `self.bytes`: the number of rows, `None`
    /// after the last one (`self.row` is advanced by the caller once the values are checked).
    fn read_rows(&mut self) -> Result<Option<usize>, ReadError> {
        let left = self.rows - self.row;
        if left == 0 {
            return Ok(None);
        }
        let n = usize::try_from(left).map_or(self.chunk_len, |l| l.min(self.chunk_len));
        self.bytes.resize(n * self.width * self.ncols, 0);
        self.reader
            .read_exact(&mut self.bytes)
            .map_err(|e| io_error(&self.path, e))?;
        Ok(Some(n))
    }

    /// The next chunk of several columns at once (1-based `columns`, each in range), one
    /// read of the rows for all of them: `out[k]` receives column `columns[k]`. Returns the
    /// number of rows read, `None` after the last chunk. The column given to
    /// [`open`](Self::open) is not used by this call.
    ///
    /// # Errors
    /// [`ReadError::ColumnOutOfRange`] for a column outside `1..=ncols`; as
    /// [`next_chunk`](Self::next_chunk), with the first non-finite value in file order.
    pub(crate) fn next_chunk_of(
        &mut self,
        columns: &[usize],
        out: &mut [Vec<f64>],
    ) -> Result<Option<usize>, ReadError> {
        if let Some(&bad) = columns.iter().find(|c| !(1..=self.ncols).contains(*c)) {
            return Err(ReadError::ColumnOutOfRange {
                path: self.path.clone(),
                index: bad,
                ncols: self.ncols,
            });
        }
        let Some(n) = self.read_rows()? else {
            return Ok(None);
        };
        let record = self.width * self.ncols;
        let width = self.width;
        for (&column, values) in columns.iter().zip(out.iter_mut()) {
            let offset = (column - 1) * width;
            values.clear();
            values.extend(
                self.bytes
                    .chunks_exact(record)
                    .map(|r| decode(&r[offset..], width)),
            );
        }
        if out.iter().any(|v| v.iter().any(|x| !x.is_finite())) {
            // the first one in file order: row first, then column
            let (i, column, value) = (0..n)
                .flat_map(|i| {
                    columns
                        .iter()
                        .zip(out.iter())
                        .map(move |(&c, v)| (i, c, v[i]))
                })
                .find(|(_, _, v)| !v.is_finite())
                .expect("a non-finite value exists");
            return Err(non_finite(&self.path, self.row as usize + i, column, value));
        }
        self.row += n as u64;
        Ok(Some(n))
    }
}

/// A raw binary file read by rows at any position (`pread`): several threads read it at once,
/// each into its own buffers, and no read depends on another, so the file is not memory-mapped
/// and no reader position is shared.
#[derive(Debug)]
pub(crate) struct RawRows {
    path: PathBuf,
    file: File,
    width: usize,
    ncols: usize,
    rows: u64,
}

impl RawRows {
    /// Opens `path` holding `ncols` interleaved little-endian columns of `format` (F64 or F32).
    ///
    /// # Errors
    /// As [`BinaryChunks::open`].
    pub(crate) fn open(path: &Path, format: InputFormat, ncols: usize) -> Result<Self, ReadError> {
        let width = width_of(format)?;
        check_ncols(ncols)?;
        let (file, rows) = open_records(path, record_size(width, ncols)?)?;
        Ok(Self {
            path: path.to_path_buf(),
            file,
            width,
            ncols,
            rows,
        })
    }

    /// Number of rows (samples per column).
    pub(crate) fn rows(&self) -> u64 {
        self.rows
    }

    /// Number of interleaved columns.
    pub(crate) fn ncols(&self) -> usize {
        self.ncols
    }

    /// Reads rows `[row, row + n)` (within the file) and decodes the 0-based `columns` into
    /// `out[k]` (replaced), through `bytes` (a buffer reused between calls).
    ///
    /// # Errors
    /// [`ReadError::Io`] (a file truncated since it was opened included) and
    /// [`ReadError::BinaryNonFinite`] for the first NaN or infinity in file order (row first,
    /// then column).
    pub(crate) fn read(
        &self,
        row: u64,
        n: usize,
        columns: &[usize],
        bytes: &mut Vec<u8>,
        out: &mut [Vec<f64>],
    ) -> Result<(), ReadError> {
        self.read_unchecked(row, n, columns, bytes, out)?;
        if out.iter().all(|v| all_finite(v)) {
            return Ok(());
        }
        // the first one in file order: row first, then column
        let (i, k) = (0..n)
            .flat_map(|i| (0..columns.len()).map(move |k| (i, k)))
            .find(|&(i, k)| !out[k][i].is_finite())
            .expect("a non-finite value exists");
        Err(non_finite(
            &self.path,
            row as usize + i,
            columns[k] + 1,
            out[k][i],
        ))
    }
}

/// The bytes of `values`, to read a little-endian f64 file into.
fn as_bytes(values: &mut [f64]) -> &mut [u8] {
    let len = std::mem::size_of_val(values);
    // SAFETY: the slice's `len` bytes are initialised f64 values without padding, borrowed
    // exclusively for the lifetime of the result; `u8` has alignment 1, and any bytes written
    // through the result form a valid f64 (every bit pattern is one).
    unsafe { std::slice::from_raw_parts_mut(values.as_mut_ptr().cast::<u8>(), len) }
}

/// Whether every value is finite: `0 · x` is 0 for a finite `x` and NaN otherwise, summed in
/// four lanes (a loop the compiler vectorises, unlike a search that stops early).
fn all_finite(x: &[f64]) -> bool {
    let mut acc = [0.0f64; 4];
    let mut quads = x.chunks_exact(4);
    for q in &mut quads {
        for k in 0..4 {
            acc[k] += 0.0 * q[k];
        }
    }
    let tail: f64 = quads.remainder().iter().map(|v| 0.0 * v).sum();
    acc.iter().sum::<f64>() + tail == 0.0
}

impl RawRows {
    /// [`read`](Self::read) without the check for non-finite values: for rows read again.
    ///
    /// # Errors
    /// [`ReadError::Io`].
    pub(crate) fn read_unchecked(
        &self,
        row: u64,
        n: usize,
        columns: &[usize],
        bytes: &mut Vec<u8>,
        out: &mut [Vec<f64>],
    ) -> Result<(), ReadError> {
        let record = self.width * self.ncols;
        let at = row * record as u64;
        if record == 8 && cfg!(target_endian = "little") && columns == [0] {
            // one f64 column: straight into the values, whose bytes are the file's
            let values = &mut out[0];
            values.resize(n, 0.0);
            return read_at(&self.path, &self.file, as_bytes(values), at);
        }
        bytes.resize(n * record, 0);
        read_at(&self.path, &self.file, bytes, at)?;
        let width = self.width;
        for (&column, values) in columns.iter().zip(out.iter_mut()) {
            debug_assert!(column < self.ncols);
            values.resize(n, 0.0);
            let offset = column * width;
            if record == 8 {
                for (v, r) in values.iter_mut().zip(bytes.chunks_exact(8)) {
                    *v = f64::from_le_bytes(r.try_into().expect("8 bytes"));
                }
            } else {
                for (v, r) in values.iter_mut().zip(bytes.chunks_exact(record)) {
                    *v = decode(&r[offset..], width);
                }
            }
        }
        Ok(())
    }
}

/// Calls `f` on consecutive chunks of one column of a raw binary file (see [`BinaryChunks`]);
/// stops at the first error, from the file or from `f`.
///
/// # Errors
/// As [`BinaryChunks::open`] and [`BinaryChunks::next_chunk`], or the first error of `f`.
#[cfg(test)]
pub(crate) fn for_each_chunk(
    path: &Path,
    format: InputFormat,
    ncols: usize,
    column: usize,
    chunk_len: usize,
    mut f: impl FnMut(&[f64]) -> Result<(), Error>,
) -> Result<(), Error> {
    let mut chunks = BinaryChunks::open(path, format, ncols, column, chunk_len)?;
    while let Some(chunk) = chunks.next_chunk()? {
        f(chunk)?;
    }
    Ok(())
}

/// Binary IMU record types of docs/methods.md §9.2–9.3.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ImuRecordType {
    /// iMAR: int32 counts, gyro 0.1 arcsec, accel 1.52588e-6 m/s.
    Imar,
    /// Northrop Grumman LN-200: int32 counts, gyro 2^-21 rad, accel 2^-14 m/s.
    Ln200,
    /// LN-200 IG: int32 counts, gyro 2^-19 rad, accel 2^-14 m/s.
    Ln200Ig,
    /// iXblue (IXSEA): doubles, gyro 1 arcsec, accel 0.001 m/s.
    Ixsea,
    /// NavChip, float records: doubles, gyro 1 arcsec, accel 0.001 m/s.
    NavchipFlt,
    /// NavChip, integer records: int32 counts, gyro 6.25e-6 rad, accel 3.90625e-5 m/s.
    NavchipInt,
}

/// One arcsecond in radians: pi / (180 · 3600) (docs/methods.md §9.3).
const ARCSEC_RAD: f64 = std::f64::consts::PI / (180.0 * 3600.0);

impl ImuRecordType {
    /// Every type, in the order of docs/methods.md §9.3.
    pub const ALL: [Self; 6] = [
        Self::Imar,
        Self::Ln200,
        Self::Ln200Ig,
        Self::Ixsea,
        Self::NavchipFlt,
        Self::NavchipInt,
    ];

    /// The package's type name (`IMAR`, `LN200`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Self::Imar => "IMAR",
            Self::Ln200 => "LN200",
            Self::Ln200Ig => "LN200IG",
            Self::Ixsea => "IXSEA",
            Self::NavchipFlt => "NAVCHIP_FLT",
            Self::NavchipInt => "NAVCHIP_INT",
        }
    }

    /// Whether the six values are 8-byte doubles (else 32-bit signed integers).
    pub(crate) fn is_double(self) -> bool {
        matches!(self, Self::Ixsea | Self::NavchipFlt)
    }

    /// Bytes per epoch: 8 (time) + 6 · 4 = 32 or 8 + 6 · 8 = 56 (docs/methods.md §9.2).
    pub fn record_size(self) -> usize {
        if self.is_double() {
            56
        } else {
            32
        }
    }

    /// docs/methods.md §9.3: gyroscope scale, rad per count.
    pub fn scale_gyro(self) -> f64 {
        match self {
            Self::Imar => 0.1 * ARCSEC_RAD,
            Self::Ln200 => 1.0 / 2_097_152.0,
            Self::Ln200Ig => 1.0 / 524_288.0,
            Self::Ixsea => ARCSEC_RAD,
            Self::NavchipFlt => 2.0 * std::f64::consts::PI / (3600.0 * 360.0),
            Self::NavchipInt => 6.25e-6,
        }
    }

    /// docs/methods.md §9.3: accelerometer scale, m/s per count.
    pub fn scale_accel(self) -> f64 {
        match self {
            Self::Imar => 0.001_525_88 / 1000.0,
            Self::Ln200 | Self::Ln200Ig => 1.0 / 16_384.0,
            Self::Ixsea | Self::NavchipFlt => 0.001,
            Self::NavchipInt => 3.906_25e-5,
        }
    }
}

impl fmt::Display for ImuRecordType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ImuRecordType {
    type Err = ParamError;

    /// Case-insensitive type name (docs/methods.md §9.2).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim();
        Self::ALL
            .into_iter()
            .find(|ty| ty.name().eq_ignore_ascii_case(t))
            .ok_or_else(|| {
                ParamError::new(
                    "imu type",
                    s,
                    "one of IMAR, LN200, LN200IG, IXSEA, NAVCHIP_FLT, NAVCHIP_INT",
                )
            })
    }
}

/// docs/methods.md §9.2's `round(1 / mean(diff(time)))`, the mean taken over the regular steps
/// ([`check_times`]: steps within 1.5 nominal steps), so that a gap in the epochs does not lower
/// the rate that converts every increment; identical to the package's on a file without gaps.
fn record_freq(path: &Path, t: &[f64]) -> Result<f64, ReadError> {
    let not_derivable = |reason| ReadError::FreqNotDerivable {
        path: path.to_path_buf(),
        reason,
    };
    if t.len() < 2 {
        return Err(not_derivable("fewer than 2 epochs"));
    }
    let freq = check_times("time", t, TimeUnit::Seconds, UnitSource::Format)
        .rate_hz
        .round();
    if freq.is_finite() && freq > 0.0 {
        Ok(freq)
    } else {
        Err(not_derivable(
            "round(1 / mean time step) is not a positive finite rate",
        ))
    }
}

/// Column names of the IMU records, in record order (docs/methods.md §9.2).
pub(crate) const RECORD_COLUMNS: [&str; 6] = [
    "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z",
];

/// The selected columns of IMU records (`RECORD_COLUMNS`, by `opts.columns`): the time is the
/// records' own, so a time column or unit option is refused. Shared by the in-memory and the
/// streamed record readers.
pub(crate) fn record_selection(
    path: &Path,
    opts: &ReadOptions,
) -> Result<super::Selection, ReadError> {
    if let Some(t) = &opts.time_column {
        return Err(ParamError::new(
            "time column",
            t,
            "no time column: IMU records carry their own time (docs/methods.md §9.2)",
        )
        .into());
    }
    if let Some(u) = opts.time_unit {
        return Err(ParamError::new(
            "time unit",
            u,
            "no unit: IMU record times are in seconds (docs/methods.md §9.2)",
        )
        .into());
    }
    let names: Vec<String> = RECORD_COLUMNS.iter().map(|n| n.to_string()).collect();
    let select = ReadOptions {
        time_column: None,
        ..opts.clone()
    };
    resolve_selection(path, &names, &select, None)
}

/// Reads the selected columns of a binary IMU record file (docs/methods.md §9.2–9.3),
/// read by positioned reads ([`for_each_record_run`]) in one pass: each record's time is decoded
/// (checked finite and strictly increasing) and its selected columns decoded, so no raw copy of
/// the file is held.
pub(crate) fn read_record_table(
    path: &Path,
    record_type: ImuRecordType,
    opts: &ReadOptions,
) -> Result<RawTable, ReadError> {
    let record = record_type.record_size();
    let sel = record_selection(path, opts)?;
    let (file, rows) = open_records(path, record)?;
    let capacity = usize::try_from(rows).unwrap_or(usize::MAX);
    let mut time: Vec<f64> = Vec::with_capacity(capacity);
    let mut counts: Vec<Vec<f64>> = sel
        .columns
        .iter()
        .map(|_| Vec::with_capacity(capacity))
        .collect();
    // one pass over the records
    for_each_record_run(path, &file, (rows, record), |first, bytes| {
        for (j, r) in bytes.chunks_exact(record).enumerate() {
            let i = first + j;
            let t = decode(r, 8);
            if !t.is_finite() {
                return Err(non_finite(path, i, 1, t));
            }
            if let Some(&previous) = time.last() {
                if t <= previous {
                    return Err(ReadError::RecordTimeNotIncreasing {
                        path: path.to_path_buf(),
                        index: i as u64,
                        previous,
                        value: t,
                    });
                }
            }
            time.push(t);
            for (c, &k) in sel.columns.iter().enumerate() {
                let raw = if record_type.is_double() {
                    decode(&r[8 + 8 * k..], 8)
                } else {
                    decode_i32(&r[8 + 4 * k..])
                };
                if !raw.is_finite() {
                    return Err(non_finite(path, i, k + 2, raw));
                }
                counts[c].push(raw);
            }
        }
        Ok(())
    })?;
    let freq = record_freq(path, &time)?;
    let mut columns = Vec::with_capacity(sel.columns.len());
    for (&k, mut values) in sel.columns.iter().zip(counts) {
        let scale = if k < 3 {
            record_type.scale_gyro()
        } else {
            record_type.scale_accel()
        };
        let factor = freq * scale;
        if let Some(i) = values.iter().position(|v| !(v * factor).is_finite()) {
            return Err(ReadError::RecordRateOverflow {
                path: path.to_path_buf(),
                index: i as u64,
                column: RECORD_COLUMNS[k].to_string(),
                raw: values[i],
                freq_hz: freq,
            });
        }
        values.iter_mut().for_each(|v| *v *= factor);
        columns.push(Column {
            name: RECORD_COLUMNS[k].to_string(),
            values,
        });
    }
    let time_origin = time[0];
    time.iter_mut().for_each(|t| *t -= time_origin);
    Ok(RawTable {
        dropped: super::DroppedRows::default(),
        columns,
        time: Some(Column {
            name: "time".into(),
            values: time,
        }),
        time_origin,
        time_unit: Some(TimeUnit::Seconds),
        freq_hz: Some(freq),
        lines: None,
        skipped: Vec::new(),
        header_lines: 0,
        blank_lines: 0,
    })
}

/// Reads a binary IMU record file (docs/methods.md §9.2): each epoch is a little-endian f64 time
/// then gyro X, Y, Z and accel X, Y, Z increments (int32 or f64 by type). Returns an [`Imu`] with
/// `freq = round(1 / mean time step)` (the mean over the regular steps, see `record_freq`:
/// docs/methods.md §9.2's rate on a file without gaps) and rates `raw · freq · scale`
/// (docs/methods.md §9.3), in rad/s and m/s^2, columns named `gyro_x` ... `accel_z`; its
/// [`Imu::timing`] reports the epochs' gaps. The same columns are read by
/// [`read_table`](super::read_table) with [`InputFormat::ImuRecord`].
///
/// A file truncated while it is read gives [`ReadError::Io`] (`the file shrank while it was
/// read`).
///
/// # Errors
/// [`ReadError::Io`], [`ReadError::Empty`], [`ReadError::BinarySize`] (size not a multiple of
/// 32 or 56 bytes, with the bytes left over), [`ReadError::BinaryNonFinite`] (column 1 is the
/// time), [`ReadError::RecordTimeNotIncreasing`] (with the 0-based record and both times),
/// [`ReadError::FreqNotDerivable`] (fewer than 2 epochs or a degenerate time span),
/// [`ReadError::RecordRateOverflow`] (an increment times the rate is not finite).
#[cfg(test)]
pub(crate) fn read_imu_record_file(path: &Path, record_type: ImuRecordType) -> Result<Imu, Error> {
    let opts = ReadOptions {
        format: InputFormat::ImuRecord(record_type),
        ..ReadOptions::default()
    };
    let table = super::read_table(path, &opts)?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(Imu::from_table(table)?.with_name(name))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_that_shrinks_while_it_is_read_is_an_error() {
        let dir = std::env::temp_dir().join(format!("gmwm-shrink-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("x.f64");
        let values: Vec<u8> = (0..200_000u32)
            .flat_map(|i| f64::from(i).to_le_bytes())
            .collect();
        std::fs::write(&path, &values).unwrap();
        let (file, rows) = open_records(&path, 8).unwrap();
        let all = read_columns(&path, &file, (rows, 8, 8), &[0]).unwrap();
        assert_eq!(all[0].len(), 200_000);
        assert_eq!(all[0][199_999], 199_999.0);
        // another process truncates it after its size was taken
        std::fs::OpenOptions::new()
            .write(true)
            .open(&path)
            .unwrap()
            .set_len(8 * 100_000)
            .unwrap();
        let e = read_columns(&path, &file, (rows, 8, 8), &[0]).unwrap_err();
        assert!(
            e.to_string()
                .contains("x.f64: the file shrank while it was read"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn imu_record_type_from_str_and_sizes() {
        assert_eq!(
            "ln200ig".parse::<ImuRecordType>().unwrap(),
            ImuRecordType::Ln200Ig
        );
        assert_eq!(
            "Navchip_Flt".parse::<ImuRecordType>().unwrap(),
            ImuRecordType::NavchipFlt
        );
        assert!("ln201".parse::<ImuRecordType>().is_err());
        assert_eq!(ImuRecordType::Imar.record_size(), 32);
        assert_eq!(ImuRecordType::Ixsea.record_size(), 56);
    }

    /// docs/methods.md §9.3 table values.
    #[test]
    fn imu_record_scales_match_methods_9_3() {
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-7 * b.abs();
        assert!(close(ImuRecordType::Imar.scale_gyro(), 4.8481368e-7));
        assert!(close(ImuRecordType::Ixsea.scale_gyro(), 4.8481368e-6));
        assert!(close(ImuRecordType::NavchipFlt.scale_gyro(), 4.8481368e-6));
        assert!(close(ImuRecordType::Imar.scale_accel(), 1.52588e-6));
        assert_eq!(ImuRecordType::Ln200.scale_gyro(), 2f64.powi(-21));
        assert_eq!(ImuRecordType::Ln200Ig.scale_gyro(), 2f64.powi(-19));
        assert_eq!(ImuRecordType::Ln200Ig.scale_accel(), 2f64.powi(-14));
    }
}
