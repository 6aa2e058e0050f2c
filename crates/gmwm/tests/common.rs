//! Shared helpers: where the shared data and reference outputs live.
#![allow(dead_code)]

use std::path::PathBuf;

/// `../shared/data` beside the repository, or `$GMWM_DATA_DIR`.
pub fn data_dir() -> PathBuf {
    match std::env::var_os("GMWM_DATA_DIR") {
        Some(d) => PathBuf::from(d),
        None => shared_dir().join("data"),
    }
}

/// `../shared/ref` beside the repository.
pub fn ref_dir() -> PathBuf {
    shared_dir().join("ref")
}

/// `../shared` beside the repository (the crate lives in `<repo>/crates/gmwm`).
pub fn shared_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared")
}

/// Reads a reference JSON file from `../shared/ref`, failing with its path.
pub fn read_ref(name: &str) -> serde_json::Value {
    let path = ref_dir().join(name);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read reference file {}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A JSON array of numbers (nulls become NaN).
pub fn f64s(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap_or_else(|| panic!("not an array: {v}"))
        .iter()
        .map(|x| x.as_f64().unwrap_or(f64::NAN))
        .collect()
}

/// Relative difference with an absolute floor.
pub fn rel_diff(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}
