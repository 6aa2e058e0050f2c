//! Writing series: a [`SeriesWriter`] whose format follows the file's extension (CSV, gzip CSV,
//! TSV, raw little-endian f64/f32), streamed row by row, and the JSON sidecar that tells
//! readers the sampling rate and, for raw binary, the layout.
//!
//! Every file is written atomically ([`AtomicFile`]): under a temporary name beside it, then
//! renamed over it once complete, so an interrupted run leaves the previous file or none,
//! never a partial one.

use super::{InputFormat, ReadError, Sidecar};
use crate::error::ParamError;
use flate2::write::GzEncoder;
use flate2::Compression;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Write buffer: large enough that system calls are rare.
const BUF_CAPACITY: usize = 1 << 20;

/// The file names [`OutputFormat::from_path`] accepts, for messages.
pub(crate) const OUTPUT_EXTENSIONS: &str = ".csv, .txt, .tsv (each optionally .gz), .f64, .f64le, \
                                     .f64.bin, .f64le.bin, .f32, .f32le, .f32.bin, .f32le.bin";

/// Format of a series file, from its name ([`OutputFormat::from_path`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputFormat {
    /// Delimited text with a header line; `gzip` for names ending in `.gz`.
    Text {
        /// `b','` (`.csv`, `.txt`) or `b'\t'` (`.tsv`).
        delimiter: u8,
        /// gzip-compressed.
        gzip: bool,
    },
    /// Raw little-endian f64, columns interleaved row by row, no header.
    F64,
    /// Raw little-endian f32, columns interleaved row by row, no header.
    F32,
}

impl OutputFormat {
    /// The format of a file name: `.csv`/`.txt` → comma-separated text, `.tsv` → tab-separated,
    /// either followed by `.gz` → gzip-compressed; `.f64`, `.f64le`, `.f64.bin`, `.f64le.bin` →
    /// raw f64; the same with `f32` → raw f32 (case-insensitive).
    ///
    /// # Errors
    /// [`ParamError`] `output` for any other name, listing `OUTPUT_EXTENSIONS`.
    pub fn from_path(path: &Path) -> Result<Self, ParamError> {
        let name = path
            .file_name()
            .and_then(|f| f.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        let (stem, gzip) = match name.strip_suffix(".gz") {
            Some(s) => (s, true),
            None => (name.as_str(), false),
        };
        let text = |delimiter| Ok(Self::Text { delimiter, gzip });
        if stem.ends_with(".csv") || stem.ends_with(".txt") {
            return text(b',');
        }
        if stem.ends_with(".tsv") {
            return text(b'\t');
        }
        if !gzip {
            match InputFormat::Auto.resolve(path) {
                InputFormat::F64 => return Ok(Self::F64),
                InputFormat::F32 => return Ok(Self::F32),
                _ => {}
            }
        }
        Err(ParamError::new(
            "output",
            path.display(),
            format!("a file name ending in {OUTPUT_EXTENSIONS}"),
        ))
    }

    /// The name of the format as a sidecar's `format` records it (`csv`, `tsv`, `f64`, `f32`).
    pub fn sidecar_name(self) -> &'static str {
        match self {
            Self::Text {
                delimiter: b'\t', ..
            } => "tsv",
            Self::Text { .. } => "csv",
            Self::F64 => "f64",
            Self::F32 => "f32",
        }
    }
}

/// A file written under a temporary name in its destination's folder
/// (`.NAME.PID.K.tmp`) and renamed over the destination by [`AtomicFile::commit`]. A rename
/// within one folder is atomic, so readers of the destination, and whatever is left after the
/// process is interrupted or killed, see the previous file (or none), never a partial one.
/// Dropped without a commit (an error on the way), the temporary file is removed; a process
/// killed outright leaves it behind, under its hidden name.
///
/// # Examples
/// ```
/// use gmwm::AtomicFile;
/// use std::io::Write;
/// let dir = std::env::temp_dir().join(format!("gmwm-doc-atomic-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("calib.json");
/// let mut f = AtomicFile::create(&path).unwrap();
/// f.write_all(b"{}\n").unwrap();
/// assert!(!path.exists()); // not there until committed
/// f.commit().unwrap();
/// assert_eq!(std::fs::read(&path).unwrap(), b"{}\n");
/// # std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub struct AtomicFile {
    path: PathBuf,
    /// The temporary file renamed over `path` on commit; `None` when `path` is written in
    /// place (a FIFO, a device: not a regular file, which a rename would replace).
    tmp: Option<PathBuf>,
    file: Option<BufWriter<File>>,
}

impl AtomicFile {
    /// Creates the temporary file for `path`: in `path`'s folder, under a name no other
    /// process can predict, created exclusively (a file or symlink planted at that name
    /// makes the creation fail, never redirects the write). A symlink at `path` is followed:
    /// its target is the destination. An existing `path` that is not a regular file (a FIFO,
    /// `/dev/null`, a terminal) is opened and written in place.
    ///
    /// # Errors
    /// [`ReadError::Io`] naming `path` when its folder cannot be written (or `path` has no
    /// file name).
    pub fn create(path: &Path) -> Result<Self, ReadError> {
        // what the path names, links followed by the system (`>(cmd)` is a link to a pipe)
        if let Ok(meta) = std::fs::metadata(path) {
            if !meta.is_file() && !meta.is_dir() {
                let file = std::fs::OpenOptions::new()
                    .write(true)
                    .open(path)
                    .map_err(|e| io_error(path, e))?;
                return Ok(Self {
                    path: path.to_path_buf(),
                    tmp: None,
                    file: Some(BufWriter::with_capacity(BUF_CAPACITY, file)),
                });
            }
        }
        let target = followed(path);
        let name = target.file_name().ok_or_else(|| {
            io_error(
                path,
                io::Error::new(io::ErrorKind::InvalidInput, "not a file name"),
            )
        })?;
        let mut last = None;
        for _ in 0..8 {
            let tmp = target.with_file_name(format!(
                ".{}.{:016x}.tmp",
                name.to_string_lossy(),
                unpredictable()
            ));
            match std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&tmp)
            {
                Ok(file) => {
                    super::temporary::track_temporary(&tmp);
                    return Ok(Self {
                        path: target,
                        tmp: Some(tmp),
                        file: Some(BufWriter::with_capacity(BUF_CAPACITY, file)),
                    });
                }
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last = Some(e),
                Err(e) => return Err(io_error(path, e)),
            }
        }
        Err(io_error(
            path,
            last.unwrap_or_else(|| io::Error::other("no temporary name")),
        ))
    }
    /// The destination.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Flushes the file and renames it over the destination.
    ///
    /// # Errors
    /// [`ReadError::Io`] naming the destination when the last writes or the rename fail (the
    /// temporary file is then removed).
    pub fn commit(mut self) -> Result<(), ReadError> {
        let tmp = self.tmp.clone();
        if let Some(tmp) = &tmp {
            super::temporary::untrack_temporary(tmp);
        }
        let result = match self.file.take() {
            Some(w) => w
                .into_inner()
                .map_err(io::IntoInnerError::into_error)
                .and_then(|f| match &tmp {
                    // on disk before it takes the destination's name
                    Some(tmp) => f.sync_all().and_then(|()| {
                        drop(f);
                        std::fs::rename(tmp, &self.path)
                    }),
                    None => Ok(()),
                }),
            None => Ok(()),
        };
        result.map_err(|e| {
            if let Some(tmp) = &tmp {
                let _ = std::fs::remove_file(tmp);
            }
            io_error(&self.path, e)
        })
    }

    fn writer(&mut self) -> io::Result<&mut BufWriter<File>> {
        self.file
            .as_mut()
            .ok_or_else(|| io::Error::other("the file was committed"))
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.writer()?.write(buf)
    }

    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        self.writer()?.write_all(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.writer()?.flush()
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.file.take().is_some() {
            if let Some(tmp) = &self.tmp {
                super::temporary::untrack_temporary(tmp);
                let _ = std::fs::remove_file(tmp);
            }
        }
    }
}

/// `path`, or the file a symlink there points to (a relative target read from the link's
/// folder; chains followed up to 16 links).
fn followed(path: &Path) -> PathBuf {
    let mut p = path.to_path_buf();
    for _ in 0..16 {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => match std::fs::read_link(&p) {
                Ok(t) if t.is_absolute() => p = t,
                Ok(t) => p = p.parent().map_or(t.clone(), |d| d.join(&t)),
                Err(_) => break,
            },
            _ => break,
        }
    }
    p
}

/// 64 bits no other process can predict: std's per-process random hash keys, the clock, the
/// process and a counter, hashed.
fn unpredictable() -> u64 {
    use std::hash::{BuildHasher, Hasher};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u64(COUNTER.fetch_add(1, Ordering::Relaxed));
    h.write_u32(super::temporary::process_tag());
    h.write_u128(
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos()),
    );
    h.finish()
}

/// Writes `bytes` to `path` atomically ([`AtomicFile`]).
///
/// # Errors
/// [`ReadError::Io`] naming `path` when it cannot be written.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), ReadError> {
    let mut f = AtomicFile::create(path)?;
    f.write_all(bytes).map_err(|e| io_error(path, e))?;
    f.commit()
}

enum Sink {
    Plain(AtomicFile),
    Gzip(Box<GzEncoder<AtomicFile>>),
}

impl Sink {
    fn writer(&mut self) -> &mut dyn Write {
        match self {
            Self::Plain(w) => w,
            Self::Gzip(w) => w,
        }
    }
}

/// Writes equal-length columns to a file in the format of its name ([`OutputFormat`]), a
/// block of rows at a time: text with a header line and shortest round-tripping numbers (the
/// file reads back to the same bits), raw binary interleaved little-endian.
pub struct SeriesWriter {
    path: PathBuf,
    format: OutputFormat,
    sink: Sink,
    ncols: usize,
    rows: u64,
    line: String,
}

impl SeriesWriter {
    /// Creates `path` and, for text, writes the header line (names are quoted when they hold
    /// the delimiter or a quote).
    ///
    /// # Errors
    /// [`ReadError::InvalidOption`] for a name of no known format ([`OutputFormat::from_path`])
    /// or no columns; [`ReadError::Io`] naming the path when it cannot be created.
    pub fn create(path: &Path, names: &[&str]) -> Result<Self, ReadError> {
        let format = OutputFormat::from_path(path)?;
        if names.is_empty() {
            return Err(ParamError::new("columns", 0, "at least one column to write").into());
        }
        let buffered = AtomicFile::create(path)?;
        let sink = match format {
            OutputFormat::Text { gzip: true, .. } => {
                Sink::Gzip(Box::new(GzEncoder::new(buffered, Compression::default())))
            }
            _ => Sink::Plain(buffered),
        };
        let mut w = Self {
            path: path.to_path_buf(),
            format,
            sink,
            ncols: names.len(),
            rows: 0,
            line: String::new(),
        };
        if let OutputFormat::Text { delimiter, .. } = format {
            let d = char::from(delimiter);
            let quoted: Vec<String> = names.iter().map(|n| quote_field(n, d)).collect();
            let header = quoted.join(&d.to_string()) + "\n";
            w.sink
                .writer()
                .write_all(header.as_bytes())
                .map_err(|e| io_error(path, e))?;
        }
        Ok(w)
    }

    /// The format written.
    pub fn format(&self) -> OutputFormat {
        self.format
    }

    /// Rows written so far.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// Appends rows: `columns[k][t]` is row `t` of column `k`.
    ///
    /// # Errors
    /// [`ReadError::InvalidOption`] if the number of columns differs from the header's or the
    /// columns differ in length; [`ReadError::Io`] when the write fails.
    pub fn write_rows(&mut self, columns: &[&[f64]]) -> Result<(), ReadError> {
        let n = columns.first().map_or(0, |c| c.len());
        if columns.len() != self.ncols || columns.iter().any(|c| c.len() != n) {
            return Err(ParamError::new(
                "columns",
                columns.len(),
                format!("{} columns of equal length", self.ncols),
            )
            .into());
        }
        let path = &self.path;
        let out = self.sink.writer();
        let result = match self.format {
            OutputFormat::Text { delimiter, .. } => {
                let d = char::from(delimiter);
                let line = &mut self.line;
                (0..n).try_for_each(|t| {
                    line.clear();
                    for (k, c) in columns.iter().enumerate() {
                        if k > 0 {
                            line.push(d);
                        }
                        use std::fmt::Write as _;
                        let _ = write!(line, "{}", c[t]);
                    }
                    line.push('\n');
                    out.write_all(line.as_bytes())
                })
            }
            OutputFormat::F64 => (0..n).try_for_each(|t| {
                columns
                    .iter()
                    .try_for_each(|c| out.write_all(&c[t].to_le_bytes()))
            }),
            OutputFormat::F32 => (0..n).try_for_each(|t| {
                columns
                    .iter()
                    .try_for_each(|c| out.write_all(&(c[t] as f32).to_le_bytes()))
            }),
        };
        result.map_err(|e| io_error(path, e))?;
        self.rows += n as u64;
        Ok(())
    }

    /// Ends the gzip stream and puts the complete file in place ([`AtomicFile::commit`]): a
    /// writer dropped without `finish` leaves no file.
    ///
    /// # Errors
    /// [`ReadError::Io`] when the final writes fail.
    pub fn finish(self) -> Result<(), ReadError> {
        match self.sink {
            Sink::Plain(w) => w.commit(),
            Sink::Gzip(w) => w.finish().map_err(|e| io_error(&self.path, e))?.commit(),
        }
    }
}

fn quote_field(s: &str, delimiter: char) -> String {
    if s.contains([delimiter, '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

#[cold]
fn io_error(path: &Path, source: io::Error) -> ReadError {
    ReadError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Writes rows of equal-length columns as CSV (shortest round-tripping floats, so reading the
/// file back gives the same bits). The header is written by [`write_csv_header`].
///
/// # Errors
/// [`io::ErrorKind::InvalidInput`] when the columns have different lengths (nothing is
/// written); errors of `out`.
pub fn write_csv_rows(out: &mut dyn Write, columns: &[&[f64]]) -> io::Result<()> {
    let n = columns.first().map_or(0, |c| c.len());
    if let Some(c) = columns.iter().find(|c| c.len() != n) {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "CSV columns must have equal lengths ({n} and {} samples)",
                c.len()
            ),
        ));
    }
    let mut line = String::with_capacity(32 * columns.len());
    for t in 0..n {
        line.clear();
        for (k, c) in columns.iter().enumerate() {
            if k > 0 {
                line.push(',');
            }
            use std::fmt::Write as _;
            let _ = write!(line, "{}", c[t]);
        }
        line.push('\n');
        out.write_all(line.as_bytes())?;
    }
    Ok(())
}

/// Writes a CSV header line.
pub fn write_csv_header(out: &mut dyn Write, names: &[&str]) -> io::Result<()> {
    writeln!(out, "{}", names.join(","))
}

/// The sidecar path of a data file: its whole name with `.json` appended (`x.f64.json`,
/// `x.csv.gz.json`), the first name the readers look for, so that `x.txt` and `x.f64` never
/// share a sidecar.
pub(crate) fn sidecar_path(data: &Path) -> PathBuf {
    let mut name = data.file_name().unwrap_or_default().to_os_string();
    name.push(".json");
    data.with_file_name(name)
}

/// Writes the JSON sidecar of a data file at `sidecar_path` and returns that path.
///
/// # Errors
/// [`ReadError::Io`] when it cannot be written.
pub fn write_sidecar(data: &Path, sidecar: &Sidecar) -> Result<PathBuf, ReadError> {
    let path = sidecar_path(data);
    let text = serde_json::to_string_pretty(sidecar).expect("a sidecar serialises");
    write_atomic(&path, (text + "\n").as_bytes())?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A FIFO is written through (a rename would replace it), a symlinked output writes its
    /// target and stays a link, and the temporary names differ from call to call and are
    /// created exclusively.
    #[cfg(unix)]
    #[test]
    fn outputs_that_are_not_plain_files_are_written_through() {
        use std::io::Read;
        use std::os::unix::fs::FileTypeExt;
        let d = tempfile::tempdir().unwrap();
        // a FIFO, read by a thread while the write goes through it
        let fifo = d.path().join("out.fifo");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            let reader = {
                let fifo = fifo.clone();
                std::thread::spawn(move || {
                    let mut text = String::new();
                    File::open(&fifo)
                        .unwrap()
                        .read_to_string(&mut text)
                        .unwrap();
                    text
                })
            };
            write_atomic(&fifo, b"through the pipe\n").unwrap();
            assert_eq!(reader.join().unwrap(), "through the pipe\n");
            assert!(std::fs::symlink_metadata(&fifo)
                .unwrap()
                .file_type()
                .is_fifo());
        }
        // a symlinked output
        let target = d.path().join("real.json");
        let link = d.path().join("link.json");
        std::os::unix::fs::symlink("real.json", &link).unwrap();
        write_atomic(&link, b"{}").unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read(&target).unwrap(), b"{}");
        // unpredictable temporary names; nothing left behind
        let a = AtomicFile::create(&target).unwrap();
        let b = AtomicFile::create(&target).unwrap();
        assert_ne!(a.tmp, b.tmp);
        drop((a, b));
        let left: Vec<_> = std::fs::read_dir(d.path()).unwrap().collect();
        assert_eq!(left.len(), 3, "{left:?}");
        // /dev/null is written to, not replaced
        write_atomic(Path::new("/dev/null"), b"x").unwrap();
        assert!(!std::fs::metadata("/dev/null").unwrap().is_file());
    }

    #[test]
    fn unequal_csv_columns_are_an_error() {
        let mut out = Vec::new();
        let e = write_csv_rows(&mut out, &[&[1.0, 2.0], &[3.0]]).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::InvalidInput);
        assert!(out.is_empty());
        write_csv_rows(&mut out, &[&[1.0, 2.0], &[3.0, 4.5]]).unwrap();
        assert_eq!(String::from_utf8(out).unwrap(), "1,3\n2,4.5\n");
    }

    #[test]
    fn output_format_from_path() {
        let f = |p: &str| OutputFormat::from_path(Path::new(p));
        let csv = OutputFormat::Text {
            delimiter: b',',
            gzip: false,
        };
        assert_eq!(f("x.csv").unwrap(), csv);
        assert_eq!(f("x.TXT").unwrap(), csv);
        assert_eq!(
            f("x.csv.gz").unwrap(),
            OutputFormat::Text {
                delimiter: b',',
                gzip: true
            }
        );
        assert_eq!(
            f("x.tsv").unwrap(),
            OutputFormat::Text {
                delimiter: b'\t',
                gzip: false
            }
        );
        for p in ["x.f64", "x.f64le", "x.f64.bin", "x.F64LE.BIN"] {
            assert_eq!(f(p).unwrap(), OutputFormat::F64, "{p}");
        }
        assert_eq!(f("x.f32.bin").unwrap(), OutputFormat::F32);
        for p in ["x.xyz", "x", "x.bin", "x.f64.gz", "x.json"] {
            let e = f(p).unwrap_err().to_string();
            assert!(e.starts_with(&format!("invalid output = {p}: a file name ending in .csv")));
        }
    }

    #[test]
    fn sidecar_path_appends_json() {
        assert_eq!(
            sidecar_path(Path::new("d/x.f64")),
            Path::new("d/x.f64.json")
        );
        assert_eq!(
            sidecar_path(Path::new("x.csv.gz")),
            Path::new("x.csv.gz.json")
        );
    }
}
