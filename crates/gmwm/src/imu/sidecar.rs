//! JSON sidecar files: `<file name>.json` beside the data (`x.f64.json`, `x.csv.gz.json`, as
//! [`write_sidecar`](crate::imu::write::write_sidecar) names them), or `<name>.json` beside
//! `<name>.csv.gz` (see `shared/data/README.md`).
//!
//! Reading is tolerant: every field is optional and unknown fields are ignored, so sidecars of
//! other origins can be used. A sidecar that is not valid JSON, or whose known fields have the
//! wrong type, is an error ([`ReadError::Sidecar`]), never silently skipped.

use super::ReadError;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Extensions stripped (from the right) when looking for a sidecar: `x.csv.gz` → `x.csv.json`,
/// then `x.json`.
const DATA_EXTENSIONS: &[&str] = &[
    "gz", "csv", "tsv", "txt", "dat", "bin", "raw", "f64", "f32", "f64le", "f32le",
];

/// Metadata of a recording.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct Sidecar {
    /// Dataset name (e.g. `adis_16405_imu1`).
    pub name: Option<String>,
    /// Free-text sensor description.
    pub sensor: Option<String>,
    /// Sampling frequency in Hz.
    pub sampling_frequency_hz: Option<f64>,
    /// Units of the gyroscope and accelerometer columns (free text).
    pub units: Option<SidecarUnits>,
    /// Format of the data file, as [`InputFormat`](crate::imu::InputFormat) parses it (`f64`,
    /// `f32`: little-endian, interleaved; `csv`, `tsv`; a record type): lets a raw binary file
    /// be read without flags.
    pub format: Option<String>,
    /// Number of columns (interleaved columns of a raw binary file).
    pub n_columns: Option<usize>,
    /// Column names and meanings, in file order.
    pub columns: Vec<SidecarColumn>,
    /// Number of data rows.
    pub n_rows: Option<u64>,
    /// Per-column summary statistics, keyed by column name.
    pub summary: BTreeMap<String, ColumnSummary>,
}

/// Units given by a sidecar.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct SidecarUnits {
    /// Gyroscope unit, e.g. `"deg/s"` (may carry a comment).
    pub gyro: Option<String>,
    /// Accelerometer unit, e.g. `"g"` (may carry a comment).
    pub accel: Option<String>,
}

/// One column described by a sidecar.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct SidecarColumn {
    /// Column name as in the data file header.
    pub name: String,
    /// Free-text meaning, e.g. `"gyroscope X axis, ..."`.
    pub meaning: Option<String>,
    /// The column's unit, e.g. `"deg/s"` (read as `units.gyro`/`units.accel` are; a unit the
    /// column's name states comes first, this one before the sensor's).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unit: Option<String>,
}

/// Summary statistics of a column given by a sidecar.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct ColumnSummary {
    /// Mean.
    pub mean: Option<f64>,
    /// Variance.
    pub var: Option<f64>,
    /// Minimum.
    pub min: Option<f64>,
    /// Maximum.
    pub max: Option<f64>,
}

impl Sidecar {
    /// Parses sidecar JSON text; `path` only names the file in errors.
    ///
    /// # Errors
    /// [`ReadError::Sidecar`] if the text is not JSON or a known field has the wrong type.
    pub fn from_json(text: &str, path: &Path) -> Result<Self, ReadError> {
        serde_json::from_str(text).map_err(|source| ReadError::Sidecar {
            path: path.to_path_buf(),
            source,
        })
    }

    /// Reads a sidecar file.
    ///
    /// # Errors
    /// [`ReadError::Io`] if the file cannot be read, [`ReadError::Sidecar`] if it cannot be parsed.
    pub fn read(path: &Path) -> Result<Self, ReadError> {
        let text = std::fs::read_to_string(path).map_err(|source| ReadError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_json(&text, path)
    }

    /// The meaning of the column named `name` (as the readers show it: control characters
    /// escaped), if the sidecar gives one.
    pub fn meaning(&self, name: &str) -> Option<&str> {
        self.column(name).and_then(|c| c.meaning.as_deref())
    }

    /// The unit of the column named `name`, if the sidecar gives one (`columns[k].unit`).
    pub fn unit_of(&self, name: &str) -> Option<&str> {
        self.column(name).and_then(|c| c.unit.as_deref())
    }

    fn column(&self, name: &str) -> Option<&SidecarColumn> {
        self.columns
            .iter()
            .find(|c| c.name == name || super::printable(&c.name) == name)
    }
}

/// Candidate sidecar paths of a data file, most specific first: the whole file name with
/// `.json` appended (`x.csv.gz` → `x.csv.gz.json`, the name the writers use, so that `x.f64`
/// and `x.txt` never share one), then known data extensions stripped one at a time from the
/// right and `.json` appended (`x.csv.json`, `x.json`).
pub fn sidecar_candidates(data: &Path) -> Vec<PathBuf> {
    let Some(file_name) = data.file_name().and_then(|f| f.to_str()) else {
        return Vec::new();
    };
    let mut stem = file_name;
    let mut out = Vec::new();
    if !file_name.starts_with('.') && !file_name.to_ascii_lowercase().ends_with(".json") {
        out.push(data.with_file_name(format!("{file_name}.json")));
    }
    while let Some((head, ext)) = stem.rsplit_once('.') {
        if head.is_empty() || !DATA_EXTENSIONS.contains(&ext.to_ascii_lowercase().as_str()) {
            break;
        }
        out.push(data.with_file_name(format!("{head}.json")));
        stem = head;
    }
    out
}

/// Finds and reads the sidecar of a data file, if one exists.
///
/// A candidate that is empty, or is JSON without any of a sidecar's keys (the output of
/// `gmwm wv x.csv --json > x.json`: a WV or calibration document at the sidecar's name), is
/// not a sidecar and is passed over (the readers warn which and why).
///
/// # Errors
/// As [`Sidecar::read`], for the first candidate of [`sidecar_candidates`] that exists and is
/// not passed over.
pub fn find_sidecar(data: &Path) -> Result<Option<Sidecar>, ReadError> {
    locate_sidecar(data).map(|located| located.sidecar)
}

/// A file at a sidecar's name that is not one: its path and why.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct NotASidecar {
    /// The file.
    pub path: PathBuf,
    /// Why it is not taken as a sidecar.
    pub why: String,
}

/// The keys a sidecar may have ([`Sidecar`]'s fields).
const SIDECAR_KEYS: &[&str] = &[
    "name",
    "sensor",
    "sampling_frequency_hz",
    "units",
    "format",
    "n_columns",
    "columns",
    "n_rows",
    "summary",
];

/// Keys a sidecar may carry to describe the data, not read and not warned about (those of the
/// shared recordings' sidecars and of common dataset descriptions).
const DESCRIPTIVE_KEYS: &[&str] = &[
    "file",
    "source",
    "license",
    "authors",
    "citation",
    "url",
    "description",
    "notes",
    "comment",
    "date",
    "data_origin",
    "duration_s",
    "truncated",
    "r_object",
    "r_column",
];

/// The keys of the sidecar `text` that gmwm neither reads nor takes as a description
/// (`DESCRIPTIVE_KEYS`), as paths (`gyro_unit`, `columns[2].unit`, `units.temperature`).
fn unread_keys(text: &str) -> Vec<String> {
    let Ok(serde_json::Value::Object(top)) = serde_json::from_str::<serde_json::Value>(text) else {
        return Vec::new();
    };
    let unknown = |k: &str, known: &[&str]| !known.contains(&k) && !DESCRIPTIVE_KEYS.contains(&k);
    let mut out: Vec<String> = top
        .keys()
        .filter(|k| unknown(k, SIDECAR_KEYS))
        .map(|k| k.to_string())
        .collect();
    if let Some(serde_json::Value::Object(units)) = top.get("units") {
        out.extend(
            units
                .keys()
                .filter(|k| unknown(k, &["gyro", "accel"]))
                .map(|k| format!("units.{k}")),
        );
    }
    if let Some(serde_json::Value::Array(columns)) = top.get("columns") {
        for (i, c) in columns.iter().enumerate() {
            if let serde_json::Value::Object(c) = c {
                out.extend(
                    c.keys()
                        .filter(|k| unknown(k, &["name", "meaning", "unit"]))
                        .map(|k| format!("columns[{i}].{k}")),
                );
            }
        }
    }
    out
}

/// What [`locate_sidecar`] found beside a data file.
#[derive(Debug, Default)]
pub(crate) struct Located {
    /// The sidecar, if one is there.
    pub(crate) sidecar: Option<Sidecar>,
    /// The files at a sidecar's name passed over, in candidate order.
    pub(crate) passed: Vec<NotASidecar>,
    /// The sidecar's path and its keys gmwm does not read ([`unread_keys`]), when it has any.
    pub(crate) unread: Option<(PathBuf, Vec<String>)>,
}

/// [`find_sidecar`], with the files at a sidecar's name passed over and the sidecar's unread
/// keys, each candidate read once.
///
/// # Errors
/// As [`find_sidecar`].
pub(crate) fn locate_sidecar(data: &Path) -> Result<Located, ReadError> {
    let mut passed = Vec::new();
    for path in sidecar_candidates(data).into_iter().filter(|p| p.is_file()) {
        let text = std::fs::read_to_string(&path).map_err(|source| ReadError::Io {
            path: path.clone(),
            source,
        })?;
        if let Some(why) = not_a_sidecar(&text) {
            passed.push(NotASidecar { path, why });
            continue;
        }
        let sidecar = Sidecar::from_json(&text, &path)?;
        let keys = unread_keys(&text);
        return Ok(Located {
            sidecar: Some(sidecar),
            passed,
            unread: (!keys.is_empty()).then_some((path, keys)),
        });
    }
    Ok(Located {
        passed,
        ..Located::default()
    })
}

/// Why `text` is not a sidecar, `None` when it may be one (text that is not JSON is left to
/// [`Sidecar::from_json`] to report: a sidecar with a typo is an error, not ignored).
fn not_a_sidecar(text: &str) -> Option<String> {
    if text.trim().is_empty() {
        return Some("it is empty".to_string());
    }
    let value: serde_json::Value = serde_json::from_str(text).ok()?;
    let Some(object) = value.as_object() else {
        return Some("it is JSON but not an object".to_string());
    };
    // gmwm's own documents first: a calibration has a `name` too
    if let Some((_, what)) = DOCUMENT_KEYS.iter().find(|(k, _)| object.contains_key(*k)) {
        return Some(format!("it is {what}, not a sidecar"));
    }
    if object.keys().any(|k| SIDECAR_KEYS.contains(&k.as_str())) {
        return None;
    }
    Some("it has none of a sidecar's keys".to_string())
}

/// The top-level key of each JSON document gmwm writes, and what it is.
const DOCUMENT_KEYS: &[(&str, &str)] = &[
    (
        "series",
        "a wavelet or Allan variance document (gmwm wv/avar --json)",
    ),
    ("fits", "a fit document (gmwm fit --json)"),
    ("selections", "a selection document (gmwm select --json)"),
    ("axes", "a calibration document (gmwm calibrate --json)"),
    ("processes", "an implied-WV document (gmwm implied --json)"),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unread_keys_name_typos_not_descriptions_nor_column_units() {
        let text = r#"{"name": "x", "sampling_frequncy_hz": 100, "license": "CC",
            "units": {"gyro": "rad/s", "temperature": "C"},
            "columns": [{"name": "gyro_x", "unit": "rad/s", "r_column": "X", "units": "x"},
                        "odd"]}"#;
        assert_eq!(
            unread_keys(text),
            [
                "sampling_frequncy_hz",
                "units.temperature",
                "columns[0].units"
            ]
        );
        // the shared recordings' descriptive keys, and what is not JSON, say nothing
        assert!(
            unread_keys(r#"{"file": "a.csv.gz", "duration_s": 3, "truncated": false}"#).is_empty()
        );
        assert!(unread_keys("not json").is_empty());
    }

    #[test]
    fn sidecar_candidates_strip_data_extensions() {
        let c = sidecar_candidates(Path::new("/d/x.csv.gz"));
        assert_eq!(
            c,
            vec![
                PathBuf::from("/d/x.csv.gz.json"),
                PathBuf::from("/d/x.csv.json"),
                PathBuf::from("/d/x.json")
            ]
        );
        let c = sidecar_candidates(Path::new("a.b.f64le.bin"));
        assert_eq!(
            c,
            vec![
                PathBuf::from("a.b.f64le.bin.json"),
                PathBuf::from("a.b.f64le.json"),
                PathBuf::from("a.b.json")
            ]
        );
        assert_eq!(
            sidecar_candidates(Path::new("noext")),
            vec![PathBuf::from("noext.json")]
        );
        assert!(sidecar_candidates(Path::new(".csv")).is_empty());
        assert!(sidecar_candidates(Path::new("wv.json")).is_empty());
    }

    #[test]
    fn sidecar_is_tolerant_but_typed() {
        let s = Sidecar::from_json(
            r#"{"sampling_frequency_hz": 250.5, "extra": [1, 2], "columns": [{"name": "gyro_x"}]}"#,
            Path::new("s.json"),
        )
        .unwrap();
        assert_eq!(s.sampling_frequency_hz, Some(250.5));
        assert_eq!(s.columns[0].name, "gyro_x");
        let e = Sidecar::from_json(r#"{"sampling_frequency_hz": "fast"}"#, Path::new("s.json"))
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("s.json: sidecar JSON is unreadable: invalid type"),
            "{e}"
        );
    }
}
