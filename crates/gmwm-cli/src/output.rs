//! The files the commands write: atomically (a temporary file beside the destination,
//! renamed over it once complete, [`gmwm::AtomicFile`]), so an interrupted run
//! leaves the previous file or none, and never over one of the command's inputs.

use anyhow::{bail, Result};
use gmwm::{write_atomic, AtomicFile, ReadError};
use std::path::Path;

/// Writes `bytes` to `path` atomically; the error reads `cannot write PATH: cause`.
pub fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic(path, bytes).map_err(|e| cannot_write(path, e))
}

/// Writes `bytes` to `path` atomically; the error is the operating system's cause alone, for
/// callers that name the file themselves.
pub fn write_io(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_atomic(path, bytes).map_err(|e| match e {
        ReadError::Io { source, .. } => source,
        other => std::io::Error::other(other.to_string()),
    })
}

/// Writes `value` as pretty JSON (with a final newline) to `path` atomically.
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<()> {
    let mut file = AtomicFile::create(path).map_err(|e| cannot_write(path, e))?;
    serde_json::to_writer_pretty(&mut file, value)
        .map_err(std::io::Error::from)
        .and_then(|()| std::io::Write::write_all(&mut file, b"\n"))
        .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
    file.commit().map_err(|e| cannot_write(path, e))
}

/// `cannot write PATH: cause`, the cause once.
fn cannot_write(path: &Path, e: ReadError) -> anyhow::Error {
    match e {
        ReadError::Io { source, .. } => {
            anyhow::anyhow!("cannot write {}: {source}", path.display())
        }
        other => anyhow::anyhow!("cannot write {}: {other}", path.display()),
    }
}

/// Refuses an output that is one of the inputs (the same file, by any path to it): `flag`
/// names the option that gave it.
pub fn check_not_input(flag: &str, output: &Path, inputs: &[&Path]) -> Result<()> {
    let Ok(out) = std::fs::canonicalize(output) else {
        // not there yet: it cannot be an input
        return Ok(());
    };
    for input in inputs {
        if std::fs::canonicalize(input).is_ok_and(|i| i == out) {
            bail!(
                "{flag} {}: this is an input of the command ({}); write the output elsewhere",
                output.display(),
                input.display()
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_replace_and_leave_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.json");
        write(&p, b"one").unwrap();
        write(&p, b"two").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two");
        write_json(&p, &serde_json::json!({"a": 1})).unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "{\n  \"a\": 1\n}\n");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        let e = write(&dir.path().join("no/such/dir/x"), b"x").unwrap_err();
        let text = e.to_string();
        assert!(text.starts_with("cannot write "), "{text}");
        assert_eq!(text.matches("No such file").count(), 1, "{text}");
    }

    #[test]
    fn an_input_is_never_an_output() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("imu.csv");
        std::fs::write(&input, "x\n1\n").unwrap();
        let other = dir.path().join("calib.json");
        assert!(check_not_input("--json", &other, &[&input]).is_ok());
        let same = dir.path().join(".").join("imu.csv");
        let e = check_not_input("--json", &same, &[&input]).unwrap_err();
        assert!(e.to_string().starts_with("--json "), "{e}");
        assert!(e.to_string().contains("is an input"), "{e}");
    }
}
