//! Standard input (`-`) and pipes as FILE. The readers look at a file more than once (its
//! first bytes, then the data; raw binary is read at positions), which a pipe cannot give: the
//! stream is copied once to a private temporary folder, read from there, and removed at the
//! end. Messages name it as the user did (`<stdin>`, or the FIFO's path), not the copy.

use anyhow::{Context, Result};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// How standard input is named in messages.
pub const STDIN: &str = "<stdin>";

/// The copy and the name the user gave it, once per run.
static SPOOLED: OnceLock<(PathBuf, String)> = OnceLock::new();

/// The temporary folder of the copy, removed when dropped.
pub struct Spool {
    dir: PathBuf,
}

impl Drop for Spool {
    fn drop(&mut self) {
        gmwm::untrack_temporary(&self.dir);
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// Whether `path` is a stream to copy first: `-` (standard input), or a FIFO, character device
/// or socket (`<(zcat x.gz)`, a named pipe).
pub fn is_stream(path: &Path) -> bool {
    if path == Path::new("-") {
        return true;
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if let Ok(m) = std::fs::metadata(path) {
            let t = m.file_type();
            return t.is_fifo() || t.is_char_device() || t.is_socket();
        }
    }
    false
}

/// Whether `path` is the copy of standard input (no sidecar, no name: `--freq` is needed unless
/// a time column gives the rate).
pub fn is_stdin(path: &Path) -> bool {
    SPOOLED
        .get()
        .is_some_and(|(copy, shown)| copy == path && shown == STDIN)
}

/// `text` with the copy's path replaced by the name the user gave (`<stdin>`, the FIFO's path).
pub fn shown(text: &str) -> String {
    match SPOOLED.get() {
        Some((copy, name)) => text.replace(&copy.display().to_string(), name),
        None => text.to_string(),
    }
}

/// Copies the stream `path` (`-` or a pipe) to a temporary file and returns its path with the
/// guard that removes it. The copy keeps a pipe's file name (so `data.f64` is still raw f64)
/// and its sidecar, when one is beside it.
pub fn spool(path: &Path) -> Result<(PathBuf, Spool)> {
    let stdin = path == Path::new("-");
    let shown_name = if stdin {
        STDIN.to_string()
    } else {
        path.display().to_string()
    };
    // a character device (/dev/zero, /dev/urandom, a terminal) never ends: refused before a
    // byte is copied, where the copy would fill the disk
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let probe = if stdin { Path::new("/dev/stdin") } else { path };
        if std::fs::metadata(probe).is_ok_and(|m| m.file_type().is_char_device()) {
            anyhow::bail!(
                "{shown_name}: is a character device (a terminal, /dev/zero), not a recording: \
                 give a file, or pipe the data in (cmd | gmwm ... -)"
            );
        }
    }
    let dir = gmwm::temporary_dir().join(format!("gmwm-input-{}", gmwm::process_tag()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir)
        .with_context(|| format!("{shown_name}: cannot create a temporary folder to read it"))?;
    gmwm::track_temporary(&dir);
    let guard = Spool { dir: dir.clone() };
    let name = match path.file_name() {
        Some(n) if !stdin => n.to_os_string(),
        _ => "stdin".into(),
    };
    let copy = dir.join(name);
    let mut file = std::fs::File::create(&copy)
        .with_context(|| format!("{shown_name}: cannot create its temporary copy"))?;
    let mut source: Box<dyn std::io::Read> = if stdin {
        Box::new(std::io::stdin().lock())
    } else {
        Box::new(
            std::fs::File::open(path).with_context(|| format!("{shown_name}: cannot read it"))?,
        )
    };
    // a failed read is the input's; a failed write (a full disk) is the temporary folder's
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = match source.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e).with_context(|| format!("{shown_name}: cannot read it")),
        };
        file.write_all(&buf[..n]).with_context(|| {
            format!(
                "{shown_name}: cannot write its temporary copy in {} (free space there or set TMPDIR)",
                dir.display()
            )
        })?;
    }
    file.flush().with_context(|| {
        format!(
            "{shown_name}: cannot write its temporary copy in {} (free space there or set TMPDIR)",
            dir.display()
        )
    })?;
    if !stdin {
        for candidate in gmwm::sidecar_candidates(path) {
            if candidate.is_file() {
                if let Some(n) = candidate.file_name() {
                    let _ = std::fs::copy(&candidate, dir.join(n));
                }
            }
        }
    }
    let _ = SPOOLED.set((copy.clone(), shown_name));
    Ok((copy, guard))
}
