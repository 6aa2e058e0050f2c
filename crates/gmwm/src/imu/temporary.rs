//! The temporary files of this process (the spools of streamed recordings, the unfinished
//! files of atomic outputs, a copy of standard input), listed while they exist so that an
//! interrupted run removes them: [`remove_temporary_files`] is what a SIGINT/SIGTERM handler
//! calls before the process ends.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn live() -> MutexGuard<'static, Vec<PathBuf>> {
    // a panic elsewhere while the list was held leaves a usable list
    LIVE.lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// The folder for temporary files: the system's (`TMPDIR`, else `/tmp`). Under WASI, whose
/// standard library has none, `TMPDIR` or `/tmp` as the host maps it (the browser page's
/// in-memory file system).
pub fn temporary_dir() -> PathBuf {
    #[cfg(target_os = "wasi")]
    {
        std::env::var_os("TMPDIR").map_or_else(|| PathBuf::from("/tmp"), PathBuf::from)
    }
    #[cfg(not(target_os = "wasi"))]
    {
        std::env::temp_dir()
    }
}

/// A number that tells this process's temporary names from another's: the process id, or 0
/// under WASI (one program per sandbox, and no process ids).
pub fn process_tag() -> u32 {
    #[cfg(target_os = "wasi")]
    {
        0
    }
    #[cfg(not(target_os = "wasi"))]
    {
        std::process::id()
    }
}

/// Lists `path` (a file or a folder) as a temporary of this process, until
/// [`untrack_temporary`].
pub fn track_temporary(path: &Path) {
    live().push(path.to_path_buf());
}

/// Takes `path` off the list (removed, renamed into place, or kept on purpose).
pub fn untrack_temporary(path: &Path) {
    let mut live = live();
    if let Some(k) = live.iter().rposition(|p| p == path) {
        live.swap_remove(k);
    }
}

/// Removes every listed temporary (folders with their content) and empties the list;
/// returns how many were removed. For a signal handler: the process is about to end.
///
/// ```
/// let dir = std::env::temp_dir().join(format!("gmwm-doc-temporary-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// gmwm::track_temporary(&dir);
/// assert_eq!(gmwm::remove_temporary_files(), 1);
/// assert!(!dir.exists());
/// ```
pub fn remove_temporary_files() -> usize {
    let paths = std::mem::take(&mut *live());
    paths
        .iter()
        .filter(|p| match std::fs::symlink_metadata(p) {
            Ok(m) if m.is_dir() => std::fs::remove_dir_all(p).is_ok(),
            Ok(_) => std::fs::remove_file(p).is_ok(),
            Err(_) => false,
        })
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tracked_files_are_removed_once() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a"), dir.path().join("b"));
        std::fs::write(&a, b"x").unwrap();
        std::fs::write(&b, b"y").unwrap();
        track_temporary(&a);
        track_temporary(&b);
        untrack_temporary(&b);
        // other tests may track their own files at the same time: only ours are asserted
        remove_temporary_files();
        assert!(!a.exists());
        assert!(b.exists());
    }
}
