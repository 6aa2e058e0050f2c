//! Positioned reads (`pread`): how the binary and ROS readers read files, instead of
//! memory-mapping them. A file truncated by another process while it is read gives
//! [`ReadError::Io`] saying `the file shrank while it was read` (never undefined behaviour or
//! a signal), and the resident set holds the caller's buffers, not the file.

use crate::imu::ReadError;
use std::fs::File;
use std::io::ErrorKind;
use std::path::Path;

/// The sentence of a read that found the end of the file before the size it had when opened.
pub(crate) const SHRANK: &str = "the file shrank while it was read";

/// Reads `buf.len()` bytes of `file` at `offset`; a read past the end of the file is
/// [`ReadError::Io`] with [`SHRANK`] (the callers only read below the size the file had when
/// they opened it).
pub(crate) fn read_at(
    path: &Path,
    file: &File,
    buf: &mut [u8],
    offset: u64,
) -> Result<(), ReadError> {
    read_exact_at(file, buf, offset).map_err(|e| ReadError::Io {
        path: path.to_path_buf(),
        source: if e.kind() == ErrorKind::UnexpectedEof {
            std::io::Error::new(ErrorKind::UnexpectedEof, SHRANK)
        } else {
            e
        },
    })
}

/// `pread` of the whole buffer at `offset`.
#[cfg(unix)]
pub(crate) fn read_exact_at(file: &File, buf: &mut [u8], offset: u64) -> std::io::Result<()> {
    std::os::unix::fs::FileExt::read_exact_at(file, buf, offset)
}

/// A seek and a read under WASI (the WebAssembly build, web/), whose positioned reads are not
/// in stable std: a WASI program has one thread, so nothing moves the file's cursor between
/// the two.
#[cfg(target_os = "wasi")]
pub(crate) fn read_exact_at(file: &File, buf: &mut [u8], offset: u64) -> std::io::Result<()> {
    use std::io::{Read, Seek, SeekFrom};
    let mut cursor = file;
    cursor.seek(SeekFrom::Start(offset))?;
    cursor.read_exact(buf)
}

/// Positioned reads are not available on this platform.
#[cfg(not(any(unix, windows, target_os = "wasi")))]
pub(crate) fn read_exact_at(_: &File, _: &mut [u8], _: u64) -> std::io::Result<()> {
    Err(std::io::Error::new(
        ErrorKind::Unsupported,
        "positioned reads are not supported on this platform",
    ))
}

/// `pread` of the whole buffer at `offset`.
#[cfg(windows)]
pub(crate) fn read_exact_at(
    file: &File,
    mut buf: &mut [u8],
    mut offset: u64,
) -> std::io::Result<()> {
    use std::os::windows::fs::FileExt;
    while !buf.is_empty() {
        match file.seek_read(buf, offset) {
            Ok(0) => return Err(ErrorKind::UnexpectedEof.into()),
            Ok(k) => {
                buf = &mut buf[k..];
                offset += k as u64;
            }
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    #[test]
    fn a_read_past_the_end_says_the_file_shrank() {
        let mut f = tempfile::NamedTempFile::new().unwrap();
        f.write_all(b"0123456789").unwrap();
        let path = f.path().to_path_buf();
        let file = File::open(&path).unwrap();
        let mut buf = [0u8; 4];
        read_at(&path, &file, &mut buf, 6).unwrap();
        assert_eq!(&buf, b"6789");
        let e = read_at(&path, &file, &mut buf, 7).unwrap_err().to_string();
        assert_eq!(e, format!("{}: {SHRANK}", path.display()));
    }
}
