//! The FILE arguments of the commands that take many recordings (batch mode of `gmwm calibrate`
//! and `gmwm wv`, `gmwm calibrate --pool`): recordings, folders of recordings, quoted globs,
//! expanded into the recordings gmwm reads.

use crate::error::UsageError;
use anyhow::{Context, Result};
use gmwm::InputFormat;
use std::path::{Path, PathBuf};

/// A FILE argument that gmwm expands itself: it does not exist as written and holds a glob
/// metacharacter (`*`, `?`, `[`).
pub fn is_glob(path: &Path) -> bool {
    !path.exists() && path.to_str().is_some_and(|s| s.contains(['*', '?', '[']))
}

/// A folder that is one ROS recording: a rosbag2 folder (it holds metadata.yaml).
pub fn is_rosbag2_folder(path: &Path) -> bool {
    path.is_dir() && path.join("metadata.yaml").is_file()
}

/// Extensions of files a folder or glob contributes as recordings, whatever else they hold.
const RECORDING_EXTENSIONS: &[&str] = &[
    "csv", "tsv", "txt", "bag", "mcap", "db3", "f64", "f32", "f64le", "f32le",
];

/// Raw binary extensions: a recording when a JSON sidecar (or `--format`) says how to read it.
const RAW_EXTENSIONS: &[&str] = &["bin", "dat", "raw"];

/// Whether a folder entry (or glob match) is a recording gmwm reads: by its name (see
/// [`RECORDING_EXTENSIONS`], also `.gz` text; raw `.bin`/`.dat`/`.raw` with a sidecar or an
/// explicit `--format`), or a rosbag2 folder. Hidden files, sidecars and other JSON (gmwm's own
/// `.calibration.json` and `.wv.json` among them) are not.
fn is_recording(path: &Path, format: InputFormat) -> bool {
    let Some(name) = path
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
    else {
        return false;
    };
    if name.starts_with('.') {
        return false;
    }
    if path.is_dir() {
        return is_rosbag2_folder(path);
    }
    let ext = |n: &str| n.rsplit_once('.').map(|(_, e)| e.to_string());
    if let Some(text) = name.strip_suffix(".gz") {
        return ext(text).is_some_and(|e| ["csv", "tsv", "txt"].contains(&e.as_str()));
    }
    match ext(&name) {
        Some(e) if RECORDING_EXTENSIONS.contains(&e.as_str()) => true,
        Some(e) if RAW_EXTENSIONS.contains(&e.as_str()) => {
            format != InputFormat::Auto || sidecar_of(path).is_some()
        }
        _ => false,
    }
}

/// The JSON sidecar a reader would use for `path`, if one exists.
pub fn sidecar_of(path: &Path) -> Option<PathBuf> {
    gmwm::sidecar_candidates(path)
        .into_iter()
        .find(|p| p.is_file())
}

/// A recording to run, and whether it was named on the command line (else a folder or a glob
/// found it).
#[derive(Debug, Clone)]
pub struct Found {
    /// The recording.
    pub path: PathBuf,
    /// Named on the command line (else found by a folder or a glob).
    pub named: bool,
}

/// The recordings of a folder (not recursing), sorted by name.
fn scan_folder(dir: &Path, format: InputFormat) -> Result<Vec<PathBuf>> {
    let mut found: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read folder {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| is_recording(p, format))
        .collect();
    found.sort();
    found.retain(|p| readable_entry(p));
    anyhow::ensure!(
        !found.is_empty(),
        "{}: no recording in this folder (.csv, .tsv, .txt, .gz, .bag, .mcap, .db3, .f64, .f32, \
         raw binary with a sidecar, rosbag2 folders)",
        dir.display()
    );
    Ok(found)
}

/// Whether a folder's or glob's entry is a regular file (links followed) or a folder: a FIFO,
/// socket or device named like a recording would block or never end the batch, and is
/// skipped with a warning.
fn readable_entry(path: &Path) -> bool {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() || m.is_dir() => true,
        Ok(_) => {
            eprintln!(
                "gmwm: warning: {}: not a regular file (a FIFO, socket or device): skipped; \
                 name it alone to read it as a stream",
                path.display()
            );
            false
        }
        // a broken link: left to the reader, which names it
        Err(_) => true,
    }
}

/// The recordings among a glob's matches, sorted.
fn expand_glob(pattern: &Path, format: InputFormat) -> Result<Vec<PathBuf>> {
    let text = pattern.to_string_lossy();
    let paths = glob::glob(&text)
        .map_err(|e| UsageError(format!("invalid glob {text:?}: {e}")))?
        .filter_map(|p| p.ok())
        .filter(|p| is_recording(p, format));
    let mut found: Vec<PathBuf> = paths.collect();
    found.sort();
    found.retain(|p| readable_entry(p));
    anyhow::ensure!(!found.is_empty(), "no recording matches {text:?}");
    Ok(found)
}

/// A path to compare outputs and inputs by: the canonical folder and the file name.
pub fn key(path: &Path) -> PathBuf {
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let folder = parent
        .canonicalize()
        .or_else(|_| std::path::absolute(parent))
        .unwrap_or_else(|_| parent.to_path_buf());
    match path.file_name() {
        Some(name) => folder.join(name),
        None => folder,
    }
}

/// Every FILE argument expanded: a named file (or rosbag2 folder) as it is, a folder into its
/// recordings, a glob into the recordings among its matches; the same recording once.
pub fn expand(inputs: &[PathBuf], format: InputFormat) -> Result<Vec<Found>> {
    let mut out: Vec<Found> = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for input in inputs {
        let (paths, named) = if is_glob(input) {
            (expand_glob(input, format)?, false)
        } else if input.is_dir() && !is_rosbag2_folder(input) {
            (scan_folder(input, format)?, false)
        } else {
            (vec![input.clone()], true)
        };
        for path in paths {
            // by folder and name: two links to one file are two recordings with two stems
            if seen.insert(key(&path)) {
                out.push(Found { path, named });
            }
        }
    }
    Ok(out)
}

/// The recordings that the FILE arguments `inputs` name, expanded as in batch mode (folders,
/// globs), in order, each once: the inputs of `calibrate --pool`.
pub fn recordings(inputs: &[PathBuf], format: InputFormat) -> Result<Vec<PathBuf>> {
    Ok(expand(inputs, format)?
        .into_iter()
        .map(|f| f.path)
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recordings_are_chosen_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let touch = |n: &str| {
            let p = dir.path().join(n);
            std::fs::write(&p, b"").unwrap();
            p
        };
        for (name, yes) in [
            ("a.csv", true),
            ("a.csv.gz", true),
            ("a.txt", true),
            ("a.bag", true),
            ("a.f64", true),
            ("a.json", false),
            ("a.csv.json", false),
            ("a.calibration.json", false),
            ("a.report.html", false),
            ("a.yaml", false),
            ("a.gz", false),
            (".a.csv", false),
            ("raw.bin", false),
        ] {
            assert_eq!(is_recording(&touch(name), InputFormat::Auto), yes, "{name}");
        }
        let raw = dir.path().join("raw.bin");
        assert!(is_recording(&raw, InputFormat::F64));
        touch("raw.bin.json");
        assert!(is_recording(&raw, InputFormat::Auto));
        let bag = dir.path().join("bag2");
        std::fs::create_dir(&bag).unwrap();
        assert!(!is_recording(&bag, InputFormat::Auto));
        std::fs::write(bag.join("metadata.yaml"), b"").unwrap();
        assert!(is_recording(&bag, InputFormat::Auto));
    }
}
