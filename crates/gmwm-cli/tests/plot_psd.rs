//! `gmwm plot psd` and the PSD of `gmwm calibrate`: the figure is written from a real
//! recording with its unit on the axis, a series too short for one Welch segment or a saved
//! wavelet variance is one clear error line (and no figure), and the calibration's JSON and
//! report carry the binned PSD.

mod common;

use common::{assert_one_line_error, gmwm};
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    std::env::var_os("GMWM_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"))
        .join(name)
}

#[test]
fn plot_psd_writes_the_figure_of_a_recording() {
    let dir = tempfile::tempdir().unwrap();
    let adis = data("adis_16405_imu1.csv.gz");
    let png = dir.path().join("psd.png");
    let out = gmwm()
        .args(["plot", "psd"])
        .arg(&adis)
        .args(["--columns", "gyro_z,accel_x", "-o"])
        .arg(&png)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("wrote "));
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "a PNG file");

    let svg_path = dir.path().join("psd.svg");
    let out = gmwm()
        .args(["plot", "psd"])
        .arg(&adis)
        .args(["--overlay", "-o"])
        .arg(&svg_path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let svg = std::fs::read_to_string(&svg_path).unwrap();
    assert!(svg.contains("frequency f (Hz)"), "the frequency axis");
    // the sidecar's units, as amplitude spectral densities
    assert!(
        svg.contains("√PSD, one-sided [deg/s/√Hz]"),
        "gyroscope axis label"
    );
    assert!(
        svg.contains("√PSD, one-sided [g/√Hz]"),
        "accelerometer axis label"
    );
}

#[test]
fn plot_psd_refuses_a_short_series_and_a_saved_wv_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    // 100 samples: fewer than one Welch segment (256)
    let short = dir.path().join("short.csv");
    let rows: String = (0..100)
        .map(|i| format!("{}\n", (i * 7 % 13) as f64))
        .collect();
    std::fs::write(&short, format!("gyro_x\n{rows}")).unwrap();
    let fig = dir.path().join("short.png");
    assert_one_line_error(
        gmwm()
            .args(["plot", "psd"])
            .arg(&short)
            .args(["--freq", "100", "-o"])
            .arg(&fig),
        &["gyro_x", "100 samples", "Welch PSD", "256"],
    );
    assert!(!fig.exists(), "no figure after an error");

    let saved = data("precomputed/adis_wv.json");
    assert_one_line_error(
        gmwm()
            .args(["plot", "psd"])
            .arg(&saved)
            .arg("-o")
            .arg(dir.path().join("wv.png")),
        &["needs the samples"],
    );
}

#[test]
fn calibrate_reports_the_binned_psd_in_its_json_and_report() {
    let dir = tempfile::tempdir().unwrap();
    let adis = data("adis_16405_imu1.csv.gz");
    let (json, html) = (dir.path().join("c.json"), dir.path().join("r.html"));
    let out = gmwm()
        .arg("calibrate")
        .arg(&adis)
        .args(["--columns", "gyro_x", "--model", "WN()+RW()", "--json"])
        .arg(&json)
        .arg("--report")
        .arg(&html)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let psd = &doc["axes"][0]["psd"];
    let f = psd["frequency_hz"].as_array().expect("frequency_hz");
    let d = psd["density"].as_array().expect("density");
    assert!(
        !f.is_empty() && f.len() == d.len() && f.len() <= 100,
        "{psd}"
    );
    assert_eq!(psd["unit"], "(rad/s)^2/Hz");
    // the white-noise floor (middle frequencies) is 2 N² of the fitted N, within the
    // scatter of a binned Welch estimate and the model's other terms (a factor 1.5)
    let n = doc["axes"][0]["noise_density"]["value"].as_f64().unwrap();
    let mid: Vec<f64> = f
        .iter()
        .zip(d)
        .filter(|(f, _)| (1.0..10.0).contains(&f.as_f64().unwrap()))
        .map(|(_, d)| d.as_f64().unwrap())
        .collect();
    let floor = mid.iter().sum::<f64>() / mid.len() as f64;
    let ratio = floor / (2.0 * n * n);
    assert!((1.0 / 1.5..1.5).contains(&ratio), "floor / 2N² = {ratio}");
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(
        page.contains("Power spectral density of every axis"),
        "the PSD figure's caption"
    );
}
