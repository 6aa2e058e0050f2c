//! Shared helpers: where the shared data and reference outputs live.
#![allow(dead_code)]

use std::path::PathBuf;

/// Neumaier-compensated sum (the engine's own `math::sum` is crate-internal).
pub(super) fn neumaier_sum(values: impl IntoIterator<Item = f64>) -> f64 {
    let (mut sum, mut comp) = (0.0f64, 0.0f64);
    for v in values {
        let t = sum + v;
        comp += if sum.abs() >= v.abs() {
            (sum - t) + v
        } else {
            (v - t) + sum
        };
        sum = t;
    }
    sum + comp
}

/// `../shared/data` beside the repository, or `$GMWM_DATA_DIR`.
pub(super) fn data_dir() -> PathBuf {
    match std::env::var_os("GMWM_DATA_DIR") {
        Some(d) => PathBuf::from(d),
        None => shared_dir().join("data"),
    }
}

/// `../shared/ref` beside the repository.
pub(super) fn ref_dir() -> PathBuf {
    shared_dir().join("ref")
}

/// `../shared` beside the repository (the crate lives in `<repo>/crates/gmwm`).
pub(super) fn shared_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared")
}

/// Reads a reference JSON file from `../shared/ref`, failing with its path.
pub(super) fn read_ref(name: &str) -> serde_json::Value {
    let path = ref_dir().join(name);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read reference file {}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A JSON array of numbers (nulls become NaN).
pub(super) fn f64s(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap_or_else(|| panic!("not an array: {v}"))
        .iter()
        .map(|x| x.as_f64().unwrap_or(f64::NAN))
        .collect()
}

/// Relative difference with an absolute floor.
pub(super) fn rel_diff(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// Reads a whole dataset `<name>.csv.gz` of `../shared/data` with the library's reader.
pub(super) fn read_dataset(name: &str) -> gmwm::imu::Table {
    let path = data_dir().join(format!("{name}.csv.gz"));
    gmwm::imu::read_table(&path, &gmwm::imu::ReadOptions::default())
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
}

/// One column of a dataset.
pub(super) fn read_column(name: &str, column: &str) -> Vec<f64> {
    let table = read_dataset(name);
    table
        .columns
        .into_iter()
        .find(|c| c.name == column)
        .unwrap_or_else(|| panic!("{name} has no column {column}"))
        .values
}

/// Seeded white noise N(0, sigma2).
pub(super) fn white_noise(n: usize, sigma2: f64, seed: u64) -> Vec<f64> {
    use rand::SeedableRng;
    use rand_distr::Distribution;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let sd = sigma2.sqrt();
    (0..n)
        .map(|_| {
            let z: f64 = rand_distr::StandardNormal.sample(&mut rng);
            sd * z
        })
        .collect()
}

/// `wv` edited as its JSON document (`gmwm wv --json`: `null` for an undefined value) and read
/// back by the engine's WV file reader: the public way to a wavelet variance computed elsewhere,
/// used here to fabricate edge cases (an undefined level, exact values, more degrees of freedom).
pub(super) fn edited_wv(
    wv: &gmwm::WaveletVariance,
    edit: impl FnOnce(&mut serde_json::Value),
) -> gmwm::WaveletVariance {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static CALLS: AtomicUsize = AtomicUsize::new(0);
    let mut series = serde_json::to_value(wv).unwrap();
    series["name"] = "edited".into();
    edit(&mut series);
    let doc = serde_json::json!({ "freq_hz": wv.freq_hz(), "series": [series] });
    let path = std::env::temp_dir().join(format!(
        "gmwm_edited_wv_{}_{}.json",
        std::process::id(),
        CALLS.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::write(&path, doc.to_string()).unwrap();
    let read = gmwm::variance::read_wv_json(&path, None);
    std::fs::remove_file(&path).ok();
    read.unwrap().remove(0).1
}
