//! Delimited text (CSV/TSV/other single-byte delimiter), plain or gzip-compressed.
//!
//! One pass with the `csv` crate into a reused [`ByteRecord`]; cells are parsed straight from
//! their bytes (`str::parse::<f64>`), never copied into a `String`, and only the selected
//! columns are stored.

use super::{default_name, resolve_selection, Column, InputFormat, LineMap, RawTable, ReadOptions};
use crate::imu::error::quote;
use crate::imu::read::HeaderMode;
use crate::imu::{ReadError, Sidecar};
use csv::ByteRecord;
use flate2::read::MultiGzDecoder;
use std::fs::File;
use std::io::{self, BufRead, BufReader, Cursor, Read};
use std::path::Path;

/// Read buffer: large enough that system calls and gzip refills are rare.
const BUF_CAPACITY: usize = 1 << 20;
/// The two magic bytes that start every gzip member (RFC 1952 §2.3.1).
const GZIP_MAGIC: [u8; 2] = [0x1f, 0x8b];
/// UTF-8 byte order mark, dropped if a file starts with it.
const UTF8_BOM: [u8; 3] = [0xef, 0xbb, 0xbf];

/// The byte source of a text file, remembering whether it is gzip so that stream errors can be
/// reported as [`ReadError::Gzip`].
struct Source {
    reader: Box<dyn BufRead>,
    gzip: bool,
}

/// Opens a file, decompressing it if it starts with the gzip magic bytes (whatever its name).
fn open(path: &Path) -> Result<Source, ReadError> {
    let file = File::open(path).map_err(|e| io_error(path, e))?;
    let mut buffered = BufReader::with_capacity(BUF_CAPACITY, file);
    let head = buffered.fill_buf().map_err(|e| io_error(path, e))?;
    let gzip = head.starts_with(&GZIP_MAGIC);
    let reader: Box<dyn BufRead> = if gzip {
        Box::new(BufReader::with_capacity(
            BUF_CAPACITY,
            LineCapped::new(ReadAhead::spawn(MultiGzDecoder::new(buffered))),
        ))
    } else {
        Box::new(BufReader::with_capacity(
            BUF_CAPACITY,
            LineCapped::new(buffered),
        ))
    };
    Ok(Source { reader, gzip })
}

/// Whether the file starts with the gzip magic bytes.
pub(crate) fn is_gzip(path: &Path) -> Result<bool, ReadError> {
    let mut head = [0u8; 2];
    let mut file = File::open(path).map_err(|e| io_error(path, e))?;
    let n = io::Read::read(&mut file, &mut head).map_err(|e| io_error(path, e))?;
    Ok(n == 2 && head == GZIP_MAGIC)
}

/// Lines of a (gzip) text file, counted as they decompress and no further than `cap`: the
/// streaming switch's count for a file whose size says nothing of its rows.
pub(crate) fn count_lines_up_to(path: &Path, cap: u64) -> Result<u64, ReadError> {
    let mut source = open(path)?;
    let mut lines = 0u64;
    loop {
        let gzip = source.gzip;
        let buf = source
            .reader
            .fill_buf()
            .map_err(|e| stream_error(path, gzip, e))?;
        if buf.is_empty() {
            return Ok(lines);
        }
        lines += buf.iter().filter(|&&b| b == b'\n').count() as u64;
        let n = buf.len();
        source.reader.consume(n);
        if lines >= cap {
            return Ok(lines);
        }
    }
}

/// Longest line a text recording may hold: 1 MiB (a row of an IMU log is under a kilobyte; a
/// header of 10^5 column names fits). A longer one (a gzip bomb's single 1 GiB line) is an
/// error once this many bytes have passed without a newline, before the line is held.
pub(crate) const MAX_LINE: usize = 1 << 20;

/// Bytes per buffer of [`ReadAhead`].
const AHEAD_CHUNK: usize = 1 << 18;
/// Buffers [`ReadAhead`]'s thread may fill before the reader takes them.
const AHEAD_BUFFERS: usize = 4;

/// A byte stream read on a thread of its own, at most [`AHEAD_BUFFERS`] buffers of
/// [`AHEAD_CHUNK`] bytes ahead of the reader: a gzip file's decompression runs beside the
/// parsing of what it has already given (a third of a CSV.gz read), with the same bytes in the
/// same order, and its memory stays bounded whatever the stream. Read errors arrive in order,
/// after the bytes before them; a thread that cannot be started leaves the stream read in
/// place.
enum ReadAhead<R> {
    Thread {
        rx: std::sync::mpsc::Receiver<io::Result<Vec<u8>>>,
        /// Buffers read through, handed back to the thread to fill again.
        spent: std::sync::mpsc::Sender<Vec<u8>>,
        current: Vec<u8>,
        pos: usize,
        done: bool,
    },
    Direct(R),
}

impl<R: Read + Send + 'static> ReadAhead<R> {
    fn spawn(inner: R) -> Self {
        // under WASI a thread is another WebAssembly instance (a Web Worker in the browser)
        // that shares the memory but not the host's file descriptors: read in place
        if cfg!(target_os = "wasi") {
            return ReadAhead::Direct(inner);
        }
        let (tx, rx) = std::sync::mpsc::sync_channel(AHEAD_BUFFERS);
        let (spent, reuse) = std::sync::mpsc::channel::<Vec<u8>>();
        let slot = std::sync::Arc::new(std::sync::Mutex::new(Some(inner)));
        let theirs = std::sync::Arc::clone(&slot);
        let started = std::thread::Builder::new()
            .name("gmwm-read-ahead".into())
            .spawn(move || {
                let Some(mut inner) = theirs.lock().ok().and_then(|mut s| s.take()) else {
                    return;
                };
                loop {
                    let mut buf = reuse.try_recv().unwrap_or_default();
                    buf.resize(AHEAD_CHUNK, 0);
                    let mut filled = 0;
                    let mut failed = None;
                    while filled < buf.len() {
                        match inner.read(&mut buf[filled..]) {
                            Ok(0) => break,
                            Ok(n) => filled += n,
                            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                            Err(e) => {
                                failed = Some(e);
                                break;
                            }
                        }
                    }
                    buf.truncate(filled);
                    let end = filled == 0 || failed.is_some();
                    if filled > 0 && tx.send(Ok(buf)).is_err() {
                        return; // the reader is gone
                    }
                    if let Some(e) = failed {
                        let _ = tx.send(Err(e));
                    }
                    if end {
                        return;
                    }
                }
            });
        match started {
            Ok(_) => ReadAhead::Thread {
                rx,
                spent,
                current: Vec::new(),
                pos: 0,
                done: false,
            },
            // the closure never ran: the stream is still in its slot
            Err(_) => match slot.lock().ok().and_then(|mut s| s.take()) {
                Some(inner) => ReadAhead::Direct(inner),
                None => ReadAhead::Thread {
                    rx,
                    spent,
                    current: Vec::new(),
                    pos: 0,
                    done: false,
                },
            },
        }
    }
}

impl<R: Read> Read for ReadAhead<R> {
    fn read(&mut self, out: &mut [u8]) -> io::Result<usize> {
        match self {
            ReadAhead::Direct(inner) => inner.read(out),
            ReadAhead::Thread {
                rx,
                spent,
                current,
                pos,
                done,
            } => {
                while *pos == current.len() {
                    if *done {
                        return Ok(0);
                    }
                    match rx.recv() {
                        Ok(Ok(buf)) => {
                            // the thread may be gone already: then the buffer is dropped
                            let _ = spent.send(std::mem::replace(current, buf));
                            *pos = 0;
                        }
                        Ok(Err(e)) => {
                            *done = true;
                            return Err(e);
                        }
                        // the thread ended after the last bytes
                        Err(_) => {
                            *done = true;
                            return Ok(0);
                        }
                    }
                }
                let n = out.len().min(current.len() - *pos);
                out[..n].copy_from_slice(&current[*pos..*pos + n]);
                *pos += n;
                Ok(n)
            }
        }
    }
}

/// The error of [`LineCapped`].
#[derive(Debug)]
struct LineTooLong;

impl std::fmt::Display for LineTooLong {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "a line longer than {} MiB: not a text recording (its rows are short)",
            MAX_LINE >> 20
        )
    }
}

impl std::error::Error for LineTooLong {}

/// A byte stream that fails once a line runs past [`MAX_LINE`] bytes.
struct LineCapped<R> {
    inner: R,
    /// Bytes since the last newline.
    run: usize,
}

impl<R> LineCapped<R> {
    fn new(inner: R) -> Self {
        Self { inner, run: 0 }
    }
}

impl<R: Read> Read for LineCapped<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        match buf[..n].iter().rposition(|&b| b == b'\n') {
            Some(i) => self.run = n - 1 - i,
            None => self.run += n,
        }
        if self.run > MAX_LINE {
            return Err(io::Error::new(io::ErrorKind::InvalidData, LineTooLong));
        }
        Ok(n)
    }
}

/// Chooses the delimiter: fixed for [`InputFormat::Csv`]/[`InputFormat::Tsv`], else the most
/// frequent of `,` `\t` `;` in the first line, ties and absence resolved by the extension
/// (`.tsv` → tab, otherwise comma).
fn delimiter(format: InputFormat, path: &Path, first_line: &[u8]) -> u8 {
    match format {
        InputFormat::Csv => return b',',
        InputFormat::Tsv => return b'\t',
        _ => {}
    }
    let name = path
        .file_name()
        .and_then(|f| f.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let name = name.strip_suffix(".gz").unwrap_or(&name);
    let preferred = if name.ends_with(".tsv") { b'\t' } else { b',' };
    let count = |d: u8| first_line.iter().filter(|&&b| b == d).count();
    let mut best = (count(preferred), preferred);
    for d in [b',', b'\t', b';'] {
        let c = count(d);
        if c > best.0 {
            best = (c, d);
        }
    }
    best.1
}

/// Largest integer below which every integer is exactly representable in an f64 (2^53).
const EXACT_INT: u64 = 1 << 53;
/// Powers of ten exactly representable in an f64 (10^0 ..= 10^22: 5^22 < 2^53).
const EXACT_POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Parses one cell (surrounding ASCII whitespace, including a `\r`, ignored); `None` if it is
/// not a number (NaN and infinities are numbers here, rejected by the caller).
#[inline]
fn parse_cell(bytes: &[u8]) -> Option<f64> {
    let bytes = bytes.trim_ascii();
    match parse_simple_decimal(bytes) {
        Some(v) => Some(v),
        None => std::str::from_utf8(bytes).ok()?.parse::<f64>().ok(),
    }
}

/// A whole number that fits an i64 (optionally signed), exactly; `None` otherwise.
#[inline]
fn parse_int(bytes: &[u8]) -> Option<i64> {
    let bytes = bytes.trim_ascii();
    let digits = bytes
        .strip_prefix(b"-")
        .or(bytes.strip_prefix(b"+"))
        .unwrap_or(bytes);
    if digits.is_empty() || digits.len() > 19 || !digits.iter().all(u8::is_ascii_digit) {
        return None;
    }
    std::str::from_utf8(bytes)
        .ok()?
        .trim_start_matches('+')
        .parse()
        .ok()
}

/// Clinger's fast path for plain decimals `[+-]digits[.digits]` with at most 19 significant
/// digits: when the digit string `m < 2^53` and the number of fraction digits `k <= 22`, both
/// `m` and `10^k` are exact f64 values and one IEEE division `m / 10^k` is correctly rounded,
/// i.e. equal to `str::parse`. Anything else (exponents, long mantissas, `nan`) returns `None`
/// and goes to `str::parse`.
#[inline]
fn parse_simple_decimal(bytes: &[u8]) -> Option<f64> {
    let (negative, digits) = match bytes.first()? {
        b'-' => (true, &bytes[1..]),
        b'+' => (false, &bytes[1..]),
        _ => (false, bytes),
    };
    let mut mantissa: u64 = 0;
    let mut n_digits = 0usize;
    let mut frac_digits = 0usize;
    let mut seen_point = false;
    for &b in digits {
        match b {
            b'0'..=b'9' => {
                if n_digits >= 19 {
                    return None;
                }
                mantissa = mantissa * 10 + u64::from(b - b'0');
                n_digits += 1;
                if seen_point {
                    frac_digits += 1;
                }
            }
            b'.' if !seen_point => seen_point = true,
            _ => return None,
        }
    }
    if n_digits == 0 || mantissa >= EXACT_INT || frac_digits >= EXACT_POW10.len() {
        return None;
    }
    let v = mantissa as f64 / EXACT_POW10[frac_digits];
    Some(if negative { -v } else { v })
}

/// What a pass over a text file found besides its rows: the column names, the selection,
/// the first stamp and the number of data rows.
pub(crate) struct TextPass {
    pub(crate) names: Vec<String>,
    pub(crate) sel: super::Selection,
    /// The first stamp as read (0 without a time column).
    pub(crate) time_origin: f64,
    pub(crate) rows: usize,
    /// Header lines (0 or 1).
    pub(crate) header_lines: u64,
    /// Blank lines before the last data row.
    pub(crate) blank_lines: u64,
    /// Rows the time policy dropped, and whether a row came before the previous one (`sort`:
    /// the rows must be sorted).
    pub(crate) dropped: super::DroppedRows,
    pub(crate) unsorted: bool,
}

/// Reads a delimited text file (see [`super::read_table`] for the options) into memory: the
/// pass of [`for_each_text_row`], collected.
pub(crate) fn read_text_table(
    path: &Path,
    format: InputFormat,
    opts: &ReadOptions,
    sidecar: Option<&Sidecar>,
) -> Result<RawTable, ReadError> {
    let mut values: Vec<Vec<f64>> = Vec::new();
    let mut time = Vec::new();
    let mut lines = LineMap::default();
    let (mut held, mut room) = (0usize, 0usize);
    let pass = for_each_text_row(
        path,
        format,
        opts,
        sidecar,
        |_, _| Ok(()),
        |row, stamp| {
            if values.is_empty() {
                values = vec![Vec::new(); row.len()];
            }
            // columns grow by fallible reservations: a gzip of 10^8 rows is refused with a
            // line, not an abort, where the process may not allocate that much (a row may
            // hold no value column: a time column alone)
            if room == 0 {
                let grow = held.max(4096);
                let failed = values
                    .iter_mut()
                    .chain(stamp.is_some().then_some(&mut time))
                    .any(|v| v.try_reserve_exact(grow).is_err());
                if failed {
                    return Err(ReadError::TooLarge {
                        path: path.to_path_buf(),
                        rows: held as u64,
                        columns: row.len(),
                    });
                }
                room = grow;
            }
            room -= 1;
            held += 1;
            for (v, &x) in values.iter_mut().zip(row) {
                v.push(x);
            }
            if let Some((rel, line, _)) = stamp {
                time.push(rel);
                lines.push(line);
            }
            Ok(())
        },
    )?;
    if values.is_empty() {
        values = vec![Vec::new(); pass.sel.columns.len()];
    }
    // an in-memory WV holds a second copy of a column (the Haar pyramid's stage A): room for
    // it is asked for now (reserved, never touched), so that a decompressed recording too
    // large for this process stops here with a line instead of aborting there
    if held > 0 && Vec::<f64>::new().try_reserve_exact(held).is_err() {
        return Err(ReadError::TooLarge {
            path: path.to_path_buf(),
            rows: held as u64,
            columns: values.len(),
        });
    }
    let mut dropped = pass.dropped;
    let mut time_origin = pass.time_origin;
    let mut lines = Some(lines);
    if pass.unsorted {
        let (moved, repeated) = sort_rows(&mut time, &mut values);
        dropped.moved = moved;
        dropped.repeated += repeated;
        // stamps relative to the earliest one; the rows' lines no longer follow the file
        let first = time.first().copied().unwrap_or(0.0);
        time.iter_mut().for_each(|t| *t -= first);
        time_origin += first;
        lines = None;
    }
    let names = &pass.names;
    let columns = pass
        .sel
        .columns
        .iter()
        .zip(values)
        .map(|(&k, values)| Column {
            name: names[k].clone(),
            values,
        })
        .collect();
    let time = pass.sel.time.map(|k| Column {
        name: names[k].clone(),
        values: time,
    });
    Ok(RawTable {
        columns,
        time,
        time_origin,
        time_unit: pass.sel.time_unit,
        freq_hz: None,
        lines: pass.sel.time.and(lines),
        skipped: pass.sel.skipped,
        header_lines: pass.header_lines,
        blank_lines: pass.blank_lines,
        dropped,
    })
}

/// `--time-policy sort`: the rows put in the order of their stamps (stable: rows with one
/// stamp keep the file's order), then each row whose stamp repeats the previous one dropped.
/// Returns the rows that moved and the rows dropped.
fn sort_rows(time: &mut Vec<f64>, values: &mut [Vec<f64>]) -> (u64, u64) {
    let mut order: Vec<usize> = (0..time.len()).collect();
    order.sort_by(|&a, &b| time[a].total_cmp(&time[b]));
    let moved = order.iter().enumerate().filter(|(i, &k)| *i != k).count() as u64;
    let mut kept: Vec<usize> = Vec::with_capacity(order.len());
    for k in order {
        if kept.last().is_some_and(|&last| time[last] == time[k]) {
            continue;
        }
        kept.push(k);
    }
    let repeated = (time.len() - kept.len()) as u64;
    *time = kept.iter().map(|&k| time[k]).collect();
    for v in values.iter_mut() {
        *v = kept.iter().map(|&k| v[k]).collect();
    }
    (moved, repeated)
}

/// One pass over a delimited text file: `row` is called on each data row with the selected
/// cells (in the selection's order) and, with a time column, the stamp relative to the first
/// one (exact for whole numbers, checked strictly increasing), the row's physical line and the
/// first stamp as read. The
/// one parser of text files (`head` is called with the names and the selection before the
/// first row): [`read_text_table`] collects its rows, the streamed readers
/// ([`super::stream`]) spool them.
pub(crate) fn for_each_text_row(
    path: &Path,
    format: InputFormat,
    opts: &ReadOptions,
    sidecar: Option<&Sidecar>,
    head: impl FnOnce(&[String], &super::Selection) -> Result<(), ReadError>,
    mut row: impl FnMut(&[f64], Option<(f64, u64, f64)>) -> Result<(), ReadError>,
) -> Result<TextPass, ReadError> {
    let Source { mut reader, gzip } = open(path)?;
    let stream_error = |e: io::Error| stream_error(path, gzip, e);
    let mut first_line = Vec::new();
    reader
        .read_until(b'\n', &mut first_line)
        .map_err(stream_error)?;
    if first_line.starts_with(&UTF8_BOM) {
        first_line.drain(..UTF8_BOM.len());
    }
    let delim = delimiter(format, path, &first_line);
    // Lines end at `\n` only (a `\r` before it is trimmed with the field, see
    // [`parse_cell`]), and a final `\n` is
    // appended, so that after each record the reader has consumed exactly its terminator and
    // its physical line is `position().line() - 1` (csv's own record positions point at the
    // start of the scan, before any skipped blank line).
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .delimiter(delim)
        .terminator(csv::Terminator::Any(b'\n'))
        .buffer_capacity(BUF_CAPACITY)
        .from_reader(
            Cursor::new(first_line)
                .chain(reader)
                .chain(Cursor::new(&b"\n"[..])),
        );
    // Next non-blank record and its 1-based physical line; a record made of one empty field
    // is a blank (or whitespace-only) line and is skipped; the csv reader skips empty lines
    // itself, so the blank lines before a record are counted from the jump in line numbers.
    let mut blank_lines = 0u64;
    let mut last_line = 0u64;
    let mut next = |rec: &mut ByteRecord| -> Result<Option<u64>, ReadError> {
        loop {
            let more = rdr.read_byte_record(rec).map_err(|e| match e.into_kind() {
                csv::ErrorKind::Io(e) => stream_error(e),
                other => io_error(
                    path,
                    io::Error::new(io::ErrorKind::InvalidData, format!("{other:?}")),
                ),
            })?;
            if !more {
                return Ok(None);
            }
            if rec.len() == 1 && rec.get(0).is_some_and(|f| f.trim_ascii().is_empty()) {
                continue;
            }
            let line = rdr.position().line().saturating_sub(1);
            blank_lines += line.saturating_sub(last_line + 1);
            last_line = line;
            return Ok(Some(line));
        }
    };

    let mut rec = ByteRecord::new();
    let Some(first_line_no) = next(&mut rec)? else {
        return Err(ReadError::Empty {
            path: path.to_path_buf(),
        });
    };
    let ncols = rec.len();
    let has_header = match opts.header {
        HeaderMode::Present => true,
        HeaderMode::Absent => false,
        HeaderMode::Auto => rec.iter().any(|f| parse_cell(f).is_none()),
    };
    let names: Vec<String> = if has_header {
        rec.iter()
            .enumerate()
            .map(|(k, f)| {
                // control characters escaped once here: every output shows the name so
                let n = crate::imu::printable(String::from_utf8_lossy(f).trim());
                if n.is_empty() {
                    default_name(k)
                } else {
                    n
                }
            })
            .collect()
    } else {
        (0..ncols).map(default_name).collect()
    };
    let sel = resolve_selection(path, &names, opts, sidecar)?;
    head(&names, &sel)?;

    let mut rows = Rows {
        path,
        names: &names,
        ncols,
        first_line: first_line_no,
        columns: &sel.columns,
        time_index: sel.time,
        cells: Vec::with_capacity(sel.columns.len()),
        previous: None,
        origin: None,
        previous_abs: 0.0,
        n: 0,
        policy: opts.time_policy,
        dropped: super::DroppedRows::default(),
        unsorted: false,
    };
    if !has_header {
        rows.push(&rec, first_line_no, &mut row)?;
    }
    while let Some(line) = next(&mut rec)? {
        rows.push(&rec, line, &mut row)?;
    }
    let n = rows.n;
    if n == 0 {
        return Err(if has_header {
            ReadError::HeaderOnly {
                path: path.to_path_buf(),
            }
        } else {
            ReadError::Empty {
                path: path.to_path_buf(),
            }
        });
    }
    let time_origin = rows.origin.map_or(0.0, |o| o.0);
    Ok(TextPass {
        dropped: rows.dropped,
        unsorted: rows.unsorted,
        names,
        sel,
        time_origin,
        rows: n,
        header_lines: u64::from(has_header),
        blank_lines,
    })
}

/// Accumulates the selected cells of each data row.
struct Rows<'a> {
    path: &'a Path,
    names: &'a [String],
    ncols: usize,
    first_line: u64,
    columns: &'a [usize],
    time_index: Option<usize>,
    /// The selected cells of the row being read.
    cells: Vec<f64>,
    /// The previous stamp relative to the first one, in the column's unit.
    previous: Option<f64>,
    /// Data rows read.
    n: usize,
    /// The first stamp: its value and, if it is a whole number, its exact integer.
    origin: Option<(f64, Option<i64>)>,
    /// The previous stamp as read (for messages).
    previous_abs: f64,
    /// What a stamp not after the previous one does.
    policy: super::TimePolicy,
    /// Rows dropped by the policy.
    dropped: super::DroppedRows,
    /// A row came before the previous one (`sort`).
    unsorted: bool,
}

impl Rows<'_> {
    #[inline]
    fn push(
        &mut self,
        rec: &ByteRecord,
        line: u64,
        row: &mut impl FnMut(&[f64], Option<(f64, u64, f64)>) -> Result<(), ReadError>,
    ) -> Result<(), ReadError> {
        if rec.len() != self.ncols {
            return Err(self.ragged(line, rec.len()));
        }
        let mut cells = std::mem::take(&mut self.cells);
        cells.clear();
        for &k in self.columns {
            match self.cell(rec, k, line) {
                Ok(v) => cells.push(v),
                Err(e) => return Err(e),
            }
        }
        let mut stamp = None;
        if let Some(k) = self.time_index {
            let t = self.cell(rec, k, line)?;
            // whole-number stamps (ns since 1970 are ~1.7e18, beyond f64's 2^53) are taken
            // relative to the first one exactly, in integers
            let int = parse_int(rec.get(k).unwrap_or_default());
            let origin = *self.origin.get_or_insert((t, int));
            let rel = match (origin.1, int) {
                (Some(o), Some(v)) => v.checked_sub(o).map_or(t - origin.0, |d| d as f64),
                _ => t - origin.0,
            };
            match self.previous {
                Some(previous) if rel <= previous => match self.policy {
                    super::TimePolicy::Strict => {
                        return Err(self.not_increasing(k, line, self.previous_abs, t))
                    }
                    super::TimePolicy::DropDuplicates => {
                        if rel == previous {
                            self.dropped.repeated += 1;
                        } else {
                            self.dropped.earlier += 1;
                        }
                        self.cells = cells;
                        return Ok(());
                    }
                    // kept as read: sorted, and repeats dropped, once every row is in
                    super::TimePolicy::Sort => self.unsorted = true,
                },
                _ => {
                    self.previous_abs = t;
                    self.previous = Some(rel);
                }
            }
            stamp = Some((rel, line, origin.0));
        }
        self.n += 1;
        let result = row(&cells, stamp);
        self.cells = cells;
        result
    }

    #[inline]
    fn cell(&self, rec: &ByteRecord, k: usize, line: u64) -> Result<f64, ReadError> {
        let bytes = rec.get(k).unwrap_or_default();
        match parse_cell(bytes) {
            Some(v) if v.is_finite() => Ok(v),
            Some(_) => Err(self.bad_cell(k, line, bytes, true)),
            None => Err(self.bad_cell(k, line, bytes, false)),
        }
    }

    #[cold]
    fn ragged(&self, line: u64, found: usize) -> ReadError {
        ReadError::Ragged {
            path: self.path.to_path_buf(),
            line,
            first_line: self.first_line,
            expected: self.ncols,
            found,
        }
    }

    #[cold]
    fn bad_cell(&self, k: usize, line: u64, bytes: &[u8], numeric: bool) -> ReadError {
        let path = self.path.to_path_buf();
        let column = quote(&self.names[k]);
        let text = quote(&String::from_utf8_lossy(bytes.trim_ascii()));
        if numeric {
            ReadError::NonFinite {
                path,
                line,
                column,
                text,
            }
        } else {
            ReadError::NotANumber {
                path,
                line,
                column,
                text,
            }
        }
    }

    #[cold]
    fn not_increasing(&self, k: usize, line: u64, previous: f64, value: f64) -> ReadError {
        ReadError::TimeNotIncreasing {
            path: self.path.to_path_buf(),
            line,
            column: quote(&self.names[k]),
            previous,
            value,
        }
    }
}

#[cold]
/// A read error of the text source: a gzip stream's own as [`ReadError::Gzip`], the line
/// cap's and the file's as I/O.
fn stream_error(path: &Path, gzip: bool, e: io::Error) -> ReadError {
    let too_long = e.get_ref().is_some_and(|r| r.is::<LineTooLong>());
    if gzip && !too_long {
        ReadError::Gzip {
            path: path.to_path_buf(),
            source: e,
        }
    } else {
        io_error(path, e)
    }
}

fn io_error(path: &Path, source: io::Error) -> ReadError {
    ReadError::Io {
        path: path.to_path_buf(),
        source,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stream read ahead on its own thread gives the same bytes in the same order, then the
    /// stream's error, then the end.
    #[test]
    fn read_ahead_gives_the_bytes_then_the_error() {
        struct Uneven {
            data: Vec<u8>,
            at: usize,
            step: usize,
        }
        impl Read for Uneven {
            fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
                if self.at == self.data.len() {
                    return Err(io::Error::new(
                        io::ErrorKind::InvalidData,
                        "corrupt deflate",
                    ));
                }
                self.step = self.step * 7 % 1013 + 1;
                let n = self.step.min(buf.len()).min(self.data.len() - self.at);
                buf[..n].copy_from_slice(&self.data[self.at..self.at + n]);
                self.at += n;
                Ok(n)
            }
        }
        let data: Vec<u8> = (0..3 * AHEAD_CHUNK + 12345)
            .map(|i| (i * 31 % 251) as u8)
            .collect();
        let mut ahead = ReadAhead::spawn(Uneven {
            data: data.clone(),
            at: 0,
            step: 1,
        });
        let mut got = Vec::new();
        let mut buf = [0u8; 4097];
        let err = loop {
            match ahead.read(&mut buf) {
                Ok(0) => panic!("ended without the error"),
                Ok(n) => got.extend_from_slice(&buf[..n]),
                Err(e) => break e,
            }
        };
        assert_eq!(got, data);
        assert_eq!(err.to_string(), "corrupt deflate");
        assert_eq!(ahead.read(&mut buf).unwrap(), 0);
        // a clean end: the bytes, then 0
        let mut ahead = ReadAhead::spawn(io::Cursor::new(data.clone()));
        let mut all = Vec::new();
        ahead.read_to_end(&mut all).unwrap();
        assert_eq!(all, data);
    }

    #[test]
    fn delimiter_sniffing() {
        let p = Path::new("x.txt");
        assert_eq!(delimiter(InputFormat::Auto, p, b"a\tb\tc\n"), b'\t');
        assert_eq!(delimiter(InputFormat::Auto, p, b"a;b;c\n"), b';');
        assert_eq!(delimiter(InputFormat::Auto, p, b"a\n"), b',');
        assert_eq!(
            delimiter(InputFormat::Auto, Path::new("x.tsv.gz"), b"a\n"),
            b'\t'
        );
        assert_eq!(delimiter(InputFormat::Csv, p, b"a\tb\n"), b',');
    }

    #[test]
    fn parse_cell_accepts_numbers_only() {
        assert_eq!(parse_cell(b"-1.5e-3"), Some(-1.5e-3));
        assert!(parse_cell(b"nan").is_some_and(f64::is_nan));
        assert_eq!(parse_cell(b"gyro_x"), None);
        assert_eq!(parse_cell(b""), None);
        assert_eq!(parse_cell(&[0xff, 0x31]), None);
        assert_eq!(parse_cell(b" 2.5\r"), Some(2.5));
        assert_eq!(parse_cell(b"-"), None);
        assert_eq!(parse_cell(b"."), None);
        assert_eq!(parse_cell(b"1.2.3"), None);
        assert_eq!(parse_cell(b"+.5"), Some(0.5));
        assert_eq!(parse_cell(b"-0"), Some(-0.0));
        assert!(parse_cell(b"-0").unwrap().is_sign_negative());
    }

    #[test]
    fn parse_int_is_exact_for_epoch_nanoseconds() {
        assert_eq!(
            parse_int(b" 1403636579758555392\r"),
            Some(1_403_636_579_758_555_392)
        );
        assert_eq!(parse_int(b"-12"), Some(-12));
        assert_eq!(parse_int(b"+7"), Some(7));
        assert_eq!(parse_int(b"99999999999999999999"), None);
        assert_eq!(parse_int(b"1.5"), None);
        assert_eq!(parse_int(b""), None);
        assert_eq!(parse_int(b"-"), None);
    }

    /// The fast path is bit-identical to `str::parse` on every input it accepts.
    #[test]
    fn parse_simple_decimal_matches_std() {
        let mut state: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut accepted = 0;
        for _ in 0..200_000 {
            let r = next();
            let int_digits = (r % 12) as usize;
            let frac_digits = ((r >> 8) % 20) as usize;
            let mut s = String::new();
            if r >> 20 & 1 == 1 {
                s.push('-');
            }
            for _ in 0..int_digits {
                s.push(char::from(b'0' + (next() % 10) as u8));
            }
            if frac_digits > 0 || r >> 21 & 1 == 1 {
                s.push('.');
            }
            for _ in 0..frac_digits {
                s.push(char::from(b'0' + (next() % 10) as u8));
            }
            let std = s.parse::<f64>().ok();
            if let Some(v) = parse_simple_decimal(s.as_bytes()) {
                accepted += 1;
                assert_eq!(Some(v.to_bits()), std.map(f64::to_bits), "{s}");
            }
            assert_eq!(
                parse_cell(s.as_bytes()).map(f64::to_bits),
                std.map(f64::to_bits),
                "{s}"
            );
        }
        assert!(accepted > 100_000, "{accepted}");
    }
}
