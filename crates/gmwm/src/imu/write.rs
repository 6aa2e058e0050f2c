//! Writing series: CSV text (gzip-compressed when the path ends in `.gz`) streamed row by row,
//! and the JSON sidecar that tells readers the sampling rate.

use super::{ReadError, Sidecar};
use flate2::write::GzEncoder;
use flate2::Compression;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// Opens `path` for writing, gzip-compressed when it ends in `.gz`.
///
/// # Errors
/// [`ReadError::Io`] naming the path when it cannot be created.
pub fn create(path: &Path) -> Result<Box<dyn Write>, ReadError> {
    let file = File::create(path).map_err(|source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let buffered = BufWriter::with_capacity(1 << 20, file);
    let gz = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gz"));
    Ok(if gz {
        Box::new(GzEncoder::new(buffered, Compression::default()))
    } else {
        Box::new(buffered)
    })
}

/// Writes rows of equal-length columns as CSV (shortest round-tripping floats, so reading the
/// file back gives the same bits). The header is written by [`write_csv_header`].
///
/// # Panics
/// If the columns have different lengths (an internal invariant of the callers).
pub fn write_csv_rows(out: &mut dyn Write, columns: &[&[f64]]) -> io::Result<()> {
    let n = columns.first().map_or(0, |c| c.len());
    assert!(
        columns.iter().all(|c| c.len() == n),
        "columns of equal length"
    );
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

/// Writes the JSON sidecar of a data file: `<file without .csv/.gz/...>.json`, the name the
/// readers look for first.
///
/// # Errors
/// [`ReadError::Io`] when it cannot be written.
pub fn write_sidecar(data: &Path, sidecar: &Sidecar) -> Result<std::path::PathBuf, ReadError> {
    let path = super::sidecar::sidecar_candidates(data)
        .into_iter()
        .last()
        .unwrap_or_else(|| data.with_extension("json"));
    let text = serde_json::to_string_pretty(sidecar).expect("a sidecar serialises");
    std::fs::write(&path, text + "\n").map_err(|source| ReadError::Io {
        path: path.clone(),
        source,
    })?;
    Ok(path)
}
