//! A ROS1 bag or MCAP storage file, read by positioned reads (not memory-mapped): the record
//! parsers ask for the bytes at a position ([`Bytes`]), which are read into one reused window.
//!
//! The size is taken when the file is opened; every stated length is checked against it before
//! anything is read or allocated, so a corrupt length is the container's error and the window
//! never outgrows the largest record. A file truncated by another process afterwards gives
//! [`ReadError::Io`] (`the file shrank while it was read`), never a signal. Memory: one window,
//! about the largest record read (a chunk), whatever the file size.

use crate::imu::read::positioned::read_at;
use crate::imu::ReadError;
use std::fs::File;
use std::io::ErrorKind;
use std::path::{Path, PathBuf};

/// Smallest read: runs of small records (index records, messages outside chunks) come from one
/// read of this many bytes.
#[cfg(not(fuzzing))]
const MIN_READ: usize = 64 << 10;
/// Under cargo-fuzz (`--cfg fuzzing`) the inputs are a few KB: a 16-byte smallest read makes
/// them move the window at almost every record, so that its refills are fuzzed too.
#[cfg(fuzzing)]
const MIN_READ: usize = 16;

/// Bytes addressed by position: a storage file read on demand, a part of one, or a decompressed
/// chunk in memory. Positions are file offsets (chunk offsets for a chunk).
pub(crate) trait Bytes {
    /// The end position: bytes lie in `[0, end)`.
    fn end(&self) -> usize;

    /// The `n` bytes at `pos`; the caller has checked `pos + n <= end()`.
    ///
    /// # Errors
    /// [`ReadError::Io`] from the read (a file truncated since it was opened included).
    fn get(&mut self, pos: usize, n: usize) -> Result<&[u8], ReadError>;
}

/// A decompressed chunk (or any bytes in memory).
pub(crate) struct Memory<'a>(pub &'a [u8]);

impl Bytes for Memory<'_> {
    fn end(&self) -> usize {
        self.0.len()
    }

    fn get(&mut self, pos: usize, n: usize) -> Result<&[u8], ReadError> {
        let bytes = self.0;
        pos.checked_add(n)
            .and_then(|end| bytes.get(pos..end))
            .ok_or_else(|| out_of_range(Path::new("<chunk>"), pos, n, bytes.len()))
    }
}

/// An open storage file and its read window.
pub(crate) struct StorageFile {
    path: PathBuf,
    file: File,
    /// Size when opened.
    len: usize,
    /// Bytes `[start, start + window.len())` of the file.
    window: Vec<u8>,
    start: usize,
    /// Smallest read ([`MIN_READ`]; smaller in tests).
    min_read: usize,
}

impl StorageFile {
    /// Opens `path` and takes its size.
    ///
    /// # Errors
    /// [`ReadError::Io`].
    pub(crate) fn open(path: &Path) -> Result<Self, ReadError> {
        let io = |source| ReadError::Io {
            path: path.to_path_buf(),
            source,
        };
        let file = File::open(path).map_err(io)?;
        let len = file.metadata().map_err(io)?.len();
        let len = usize::try_from(len).map_err(|_| {
            io(std::io::Error::new(
                ErrorKind::Unsupported,
                format!("{len} bytes do not fit this platform's address space"),
            ))
        })?;
        Ok(Self {
            path: path.to_path_buf(),
            file,
            len,
            window: Vec::new(),
            start: 0,
            min_read: MIN_READ,
        })
    }

    /// The file as given.
    pub(crate) fn path(&self) -> &Path {
        &self.path
    }

    /// Size in bytes when opened.
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// Reads `buf.len()` bytes at `pos` straight into `buf` (not through the window).
    ///
    /// # Errors
    /// [`ReadError::Io`].
    pub(crate) fn read_into(&self, pos: usize, buf: &mut [u8]) -> Result<(), ReadError> {
        read_at(&self.path, &self.file, buf, pos as u64)
    }

    /// Frees the window (after the last read of this file).
    pub(crate) fn release(&mut self) {
        self.window = Vec::new();
        self.start = 0;
    }

    /// The file up to byte `to` (at most its size) as a [`Bytes`].
    pub(crate) fn region(&mut self, to: usize) -> Region<'_> {
        let end = to.min(self.len);
        Region { file: self, end }
    }
}

impl Bytes for StorageFile {
    fn end(&self) -> usize {
        self.len
    }

    fn get(&mut self, pos: usize, n: usize) -> Result<&[u8], ReadError> {
        let end = pos
            .checked_add(n)
            .filter(|&e| e <= self.len)
            .ok_or_else(|| out_of_range(&self.path, pos, n, self.len))?;
        let have = self.start + self.window.len();
        if pos >= self.start && end <= have {
            return Ok(&self.window[pos - self.start..end - self.start]);
        }
        // read at least `min_read` bytes from `pos`, keeping the bytes already held from there
        let want = n.max(self.min_read).min(self.len - pos);
        let keep = if pos >= self.start && pos < have {
            self.window.copy_within(pos - self.start.., 0);
            have - pos
        } else {
            0
        };
        self.window.resize(want, 0);
        self.start = pos;
        if let Err(e) = read_at(
            &self.path,
            &self.file,
            &mut self.window[keep..],
            (pos + keep) as u64,
        ) {
            self.window.clear();
            return Err(e);
        }
        Ok(&self.window[..n])
    }
}

/// A storage file up to a position (ROS1: the chunks before the index).
pub(crate) struct Region<'f> {
    file: &'f mut StorageFile,
    end: usize,
}

impl Bytes for Region<'_> {
    fn end(&self) -> usize {
        self.end
    }

    fn get(&mut self, pos: usize, n: usize) -> Result<&[u8], ReadError> {
        if pos.checked_add(n).map_or(true, |e| e > self.end) {
            return Err(out_of_range(&self.file.path, pos, n, self.end));
        }
        self.file.get(pos, n)
    }
}

/// A read the parser should have refused (a length it did not check): an error, not a panic.
#[cold]
fn out_of_range(path: &Path, pos: usize, n: usize, end: usize) -> ReadError {
    ReadError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::new(
            ErrorKind::InvalidData,
            format!("internal error: a read of {n} bytes at byte {pos} passes the end ({end})"),
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn file(bytes: &[u8]) -> (tempfile::NamedTempFile, StorageFile) {
        let mut f = tempfile::NamedTempFile::new().unwrap();
        f.write_all(bytes).unwrap();
        f.flush().unwrap();
        let s = StorageFile::open(f.path()).unwrap();
        (f, s)
    }

    #[test]
    fn windows_serve_any_range_with_the_file_bytes() {
        let bytes: Vec<u8> = (0..300_000u32).map(|i| (i * 7 + i / 251) as u8).collect();
        let (_f, mut s) = file(&bytes);
        assert_eq!(s.len(), bytes.len());
        // random ranges, mostly forward and overlapping like a parser's, with small and
        // default windows
        for min_read in [1, 16, 4096, MIN_READ] {
            s.min_read = min_read;
            s.release();
            let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
            let mut pos = 0usize;
            let mut largest = 0;
            for _ in 0..20_000 {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                let n = match x % 4 {
                    0 => (x >> 8) as usize % 8,
                    1 => (x >> 8) as usize % 300,
                    2 => (x >> 8) as usize % 20_000,
                    _ => (x >> 8) as usize % 200_000,
                };
                pos = match (x >> 40) % 8 {
                    0 => (x >> 20) as usize % bytes.len(),
                    1 => pos.saturating_sub((x >> 20) as usize % 1000),
                    _ => pos + (x >> 20) as usize % 64,
                } % bytes.len();
                let n = n.min(bytes.len() - pos);
                assert_eq!(s.get(pos, n).unwrap(), &bytes[pos..pos + n], "{pos} {n}");
                // the window never outgrows the largest request
                largest = largest.max(n);
                assert!(s.window.len() <= largest.max(min_read));
            }
        }
        s.min_read = MIN_READ;
        // forward, overlapping, backward, large, at the end
        for &(pos, n) in &[
            (0, 4),
            (2, 10),
            (60_000, 10_000),
            (65_000, 200_000),
            (100, 1),
            (299_990, 10),
            (0, 300_000),
            (300_000, 0),
        ] {
            assert_eq!(s.get(pos, n).unwrap(), &bytes[pos..pos + n], "{pos} {n}");
        }
        assert!(s.get(299_999, 2).is_err());
        assert!(s.get(usize::MAX, 2).is_err());
        let mut r = s.region(1000);
        assert_eq!(r.end(), 1000);
        assert_eq!(r.get(996, 4).unwrap(), &bytes[996..1000]);
        assert!(r.get(998, 4).is_err());
    }

    #[test]
    fn a_truncated_file_is_an_error() {
        let bytes = vec![5u8; 200_000];
        let (f, mut s) = file(&bytes);
        assert_eq!(s.get(0, 10).unwrap(), &bytes[..10]);
        f.as_file().set_len(1000).unwrap();
        let e = s.get(150_000, 100).unwrap_err().to_string();
        assert!(e.ends_with("the file shrank while it was read"), "{e}");
    }
}
