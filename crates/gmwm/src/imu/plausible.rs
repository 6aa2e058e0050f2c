//! Whether raw little-endian floats look like sensor samples: a file of f64 values read as
//! f32 (or the reverse, or integers read as floats) decodes to numbers no sensor gives
//! (|x| near 1e38, subnormals, NaN), and its wavelet variance is then nonsense (2e45) without
//! any error. [`raw_floats`] samples the start of the file and says so.

use super::read::{BinaryLayout, InputFormat};
use super::ReadError;
use std::fmt;
use std::io::Read;
use std::path::{Path, PathBuf};

/// Values looked at: the first this many of the file.
const SAMPLE: usize = 1 << 16;

/// A magnitude no inertial sensor reports, in any unit.
pub(crate) const HUGE: f64 = 1e20;

/// A nonzero magnitude no inertial sensor reports (a subnormal f32 is below 1.2e-38).
pub(crate) const TINY: f64 = 1e-30;

/// Raw floats that do not look like sensor samples ([`raw_floats`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ImplausibleFloats {
    /// The file.
    pub path: PathBuf,
    /// The format it was read with: [`InputFormat::F64`] or [`InputFormat::F32`].
    pub format: InputFormat,
    /// Values looked at (the first of the file).
    pub(crate) looked_at: usize,
    /// Of those, finite with |x| > [`HUGE`].
    pub(crate) huge: usize,
    /// Of those, nonzero with |x| < [`TINY`] (subnormals among them).
    pub(crate) tiny: usize,
    /// Of those, NaN or infinite.
    pub(crate) non_finite: usize,
    /// The largest finite magnitude seen.
    pub largest: f64,
    /// The bytes looked at are printable ASCII text: the file is text, not raw floats.
    pub text: bool,
}

impl ImplausibleFloats {
    /// The other raw format, the likely right one.
    pub(crate) fn other_format(&self) -> InputFormat {
        match self.format {
            InputFormat::F32 => InputFormat::F64,
            _ => InputFormat::F32,
        }
    }
}

impl fmt::Display for ImplausibleFloats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts = Vec::new();
        if self.huge > 0 {
            parts.push(format!(
                "{} beyond {HUGE:e} (largest {:.1e})",
                self.huge, self.largest
            ));
        }
        if self.tiny > 0 {
            parts.push(format!("{} nonzero below {TINY:e}", self.tiny));
        }
        if self.non_finite > 0 {
            parts.push(format!("{} NaN or infinite", self.non_finite));
        }
        let hint = if self.text {
            "the file is text: drop --format".to_string()
        } else {
            format!("is it --format {}?", self.other_format())
        };
        write!(
            f,
            "{}: read as {}, the first {} values do not look like sensor samples ({}); {hint}",
            self.path.display(),
            self.format,
            self.looked_at,
            parts.join(", "),
        )
    }
}

/// Looks at the first values of a raw f64/f32 file (`layout`) and returns what is implausible
/// when any value is beyond `HUGE`, at least 1% are NaN or infinite, or at least 5% are
/// nonzero below `TINY`; `None` when they look like samples (or the file is not raw floats).
///
/// # Errors
/// [`ReadError::Io`] when the file cannot be opened or read.
pub fn raw_floats(
    path: &Path,
    layout: &BinaryLayout,
) -> Result<Option<ImplausibleFloats>, ReadError> {
    let Some(width) = layout.format.value_width() else {
        return Ok(None);
    };
    let io = |source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut bytes = Vec::with_capacity(SAMPLE * width);
    std::fs::File::open(path)
        .map_err(io)?
        .take((SAMPLE * width) as u64)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    let mut out = ImplausibleFloats {
        path: path.to_path_buf(),
        format: layout.format,
        looked_at: 0,
        huge: 0,
        tiny: 0,
        non_finite: 0,
        largest: 0.0,
        text: !bytes.is_empty()
            && bytes
                .iter()
                .all(|b| b.is_ascii_graphic() || matches!(b, b' ' | b'\t' | b'\r' | b'\n')),
    };
    for chunk in bytes.chunks_exact(width) {
        let x = match chunk {
            [a, b, c, d] => f64::from(f32::from_le_bytes([*a, *b, *c, *d])),
            _ => {
                let mut v = [0u8; 8];
                v.copy_from_slice(chunk);
                f64::from_le_bytes(v)
            }
        };
        out.looked_at += 1;
        let a = x.abs();
        if !x.is_finite() {
            out.non_finite += 1;
            continue;
        }
        out.largest = out.largest.max(a);
        if a > HUGE {
            out.huge += 1;
        } else if a != 0.0 && a < TINY {
            out.tiny += 1;
        }
    }
    let implausible = out.huge > 0
        || (out.non_finite > 0 && out.non_finite * 100 >= out.looked_at)
        || (out.tiny > 0 && out.tiny * 20 >= out.looked_at);
    Ok(implausible.then_some(out))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layout(format: InputFormat) -> BinaryLayout {
        BinaryLayout {
            format,
            ncols: 1,
            names: vec!["col1".into()],
        }
    }

    fn file(bytes: &[u8]) -> tempfile::NamedTempFile {
        let mut f = tempfile::NamedTempFile::new().unwrap();
        std::io::Write::write_all(&mut f, bytes).unwrap();
        f
    }

    /// Gyro-like samples in rad/s.
    fn samples() -> Vec<f64> {
        (0..4096u64)
            .map(|k| ((k * 7919 + 13) % 1009) as f64 * 1e-6 - 5e-4)
            .collect()
    }

    #[test]
    fn f64_read_as_f32_is_implausible_and_names_f64() {
        let bytes: Vec<u8> = samples().iter().flat_map(|v| v.to_le_bytes()).collect();
        let f = file(&bytes);
        let bad = raw_floats(f.path(), &layout(InputFormat::F32))
            .unwrap()
            .expect("implausible");
        assert_eq!(bad.looked_at, 8192);
        assert!(!bad.text);
        let text = bad.to_string();
        assert!(
            text.contains("read as f32") && text.ends_with("is it --format f64?"),
            "{text}"
        );
        // read right: plausible
        assert_eq!(
            raw_floats(f.path(), &layout(InputFormat::F64)).unwrap(),
            None
        );
    }

    #[test]
    fn f32_samples_are_plausible_and_text_is_named_text() {
        let bytes: Vec<u8> = samples()
            .iter()
            .flat_map(|v| (*v as f32).to_le_bytes())
            .collect();
        let f = file(&bytes);
        assert_eq!(
            raw_floats(f.path(), &layout(InputFormat::F32)).unwrap(),
            None
        );
        let t = file(b"gyro_x\n0.001\n-0.002\n0.003\n0.0015\n-0.0005\n0.0025\n0.001\n");
        let bad = raw_floats(t.path(), &layout(InputFormat::F64))
            .unwrap()
            .expect("text read as f64");
        assert!(bad.text && bad.to_string().ends_with("the file is text: drop --format"));
    }

    #[test]
    fn text_formats_are_not_looked_at() {
        let f = file(b"x\n1\n");
        assert_eq!(
            raw_floats(f.path(), &layout(InputFormat::Csv)).unwrap(),
            None
        );
    }
}
