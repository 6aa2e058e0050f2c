//! End-to-end tests of `gmwm shared` and `gmwm monitor`: a simulated triad with a shared GM, a
//! monitor run against a hand-written calibration, and one test per bad-input class.

mod common;

use common::{assert_one_line_error, gmwm, run_json};
use std::io::Write;
use std::path::{Path, PathBuf};

/// A CSV with columns gyro_x, gyro_y, gyro_z (a shared AR1 plus white noise) and accel_x.
fn triad(dir: &Path, n: usize) -> PathBuf {
    use gmwm::simulate_model;
    use gmwm::Model;
    let v = simulate_model(
        &Model::parse("AR1(phi=0.99, sigma2=0.02)").unwrap(),
        n,
        1.0,
        1,
    )
    .unwrap();
    let cols: Vec<Vec<f64>> = (0..4u64)
        .map(|i| {
            let u = simulate_model(&Model::parse("WN(sigma2=1)").unwrap(), n, 1.0, 10 + i).unwrap();
            if i < 3 {
                u.iter().zip(&v).map(|(a, b)| a + b).collect()
            } else {
                u
            }
        })
        .collect();
    let path = dir.join("triad.csv");
    let mut f = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    writeln!(f, "gyro_x,gyro_y,gyro_z,accel_x").unwrap();
    for row in (0..n).map(|t| cols.iter().map(|c| c[t].to_string()).collect::<Vec<_>>()) {
        writeln!(f, "{}", row.join(",")).unwrap();
    }
    path
}

fn shared(file: &Path) -> assert_cmd::Command {
    let mut c = gmwm();
    c.arg("shared")
        .arg(file)
        .args(["--freq", "1", "--shared", "AR1()", "--model", "WN()"]);
    c
}

#[test]
fn shared_detects_a_shared_process() {
    let dir = tempfile::tempdir().unwrap();
    let file = triad(dir.path(), 8192);
    let doc = run_json(shared(&file).args(["--columns", "gyro_x,gyro_y,gyro_z", "--json"]));
    assert!(doc["test"]["p_value"].as_f64().unwrap() < 0.01, "{doc}");
    assert_eq!(doc["parameters"][0]["block"], "shared");
    let table = shared(&file)
        .args(["--columns", "gyro_x,gyro_y"])
        .output()
        .unwrap();
    assert!(table.status.success());
    assert!(String::from_utf8_lossy(&table.stdout).contains("no shared process: T ="));
    // --plot draws the WVs and the cross-covariances, with the test in a title
    let svg = dir.path().join("shared.svg");
    let out = shared(&file)
        .args(["--columns", "gyro_x,gyro_y,gyro_z", "--plot"])
        .arg(&svg)
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    let text = std::fs::read_to_string(&svg).unwrap();
    for needle in [
        "gyro_x–gyro_y cross-covariance",
        "shared AR1 (implied)",
        "no shared process: T =",
    ] {
        assert!(text.contains(needle), "{needle} not in the figure");
    }
}

#[test]
fn shared_refuses_bad_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let file = triad(dir.path(), 8192);
    // one column
    assert_one_line_error(
        shared(&file).args(["--columns", "gyro_x"]),
        &["at least 2 columns"],
    );
    // a column that is not there
    assert_one_line_error(
        shared(&file).args(["--columns", "gyro_x,gyro_q"]),
        &["gyro_q"],
    );
    // two sensors
    assert_one_line_error(
        shared(&file).args(["--columns", "gyro_x,accel_x"]),
        &["accel_x", "one sensor and unit"],
    );
    // too short for the model
    let short = triad(dir.path(), 8);
    let mut c = gmwm();
    c.arg("shared")
        .arg(&short)
        .args(["--freq", "1", "--shared", "GM()", "--model", "WN()+RW()"]);
    assert_one_line_error(
        c.args(["--columns", "gyro_x,gyro_y"]),
        &["too short", "parameters"],
    );
}

/// A calibration JSON of the fields `gmwm monitor` reads.
fn calibration(dir: &Path, freq: f64, model: &str) -> PathBuf {
    let path = dir.join(format!("cal{freq}.calibration.json"));
    let doc = serde_json::json!({
        "freq_hz": freq,
        "axes": [
            {"column": "gyro_x", "data_unit": null, "unit": "", "fit": {"model": model}},
            {"column": "gyro_y", "data_unit": null, "unit": "", "fit": {"model": model}},
        ]
    });
    std::fs::write(&path, doc.to_string()).unwrap();
    path
}

fn monitor(file: &Path, cal: &Path) -> assert_cmd::Command {
    let mut c = gmwm();
    c.arg("monitor")
        .arg(file)
        .args(["--freq", "1", "--model-from"])
        .arg(cal);
    c
}

#[test]
fn monitor_runs_against_a_calibration() {
    let dir = tempfile::tempdir().unwrap();
    let file = triad(dir.path(), 8192);
    let cal = calibration(dir.path(), 1.0, "AR1(phi=0.99, sigma2=0.02)+WN(sigma2=1)");
    let doc =
        run_json(monitor(&file, &cal).args(["--columns", "gyro_x", "--window", "2048", "--json"]));
    assert_eq!(doc[0]["column"], "gyro_x");
    assert_eq!(doc[0]["windows"].as_array().unwrap().len(), 7);
    let table = monitor(&file, &cal)
        .args(["--columns", "gyro_x,gyro_y", "--window", "2048s"])
        .output()
        .unwrap();
    assert!(table.status.success(), "{table:?}");
    assert!(String::from_utf8_lossy(&table.stdout).contains("flagged"));
}

#[test]
fn monitor_refuses_mismatched_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let file = triad(dir.path(), 8192);
    let cal = calibration(dir.path(), 1.0, "WN(sigma2=1)");
    // a column the calibration does not have
    assert_one_line_error(
        monitor(&file, &cal).args(["--columns", "gyro_z", "--window", "2048"]),
        &["gyro_z", "is not in", "cal1.calibration.json"],
    );
    // another rate
    let other = calibration(dir.path(), 100.0, "WN(sigma2=1)");
    assert_one_line_error(
        monitor(&file, &other).args(["--columns", "gyro_x", "--window", "2048"]),
        &["1 Hz", "100 Hz"],
    );
    // a recording too short for one window
    assert_one_line_error(
        monitor(&file, &cal).args(["--columns", "gyro_x", "--window", "100000"]),
        &["too few for one window", "--window"],
    );
    // not a calibration
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, "{\"x\": 1}").unwrap();
    assert_one_line_error(
        monitor(&file, &bad).args(["--columns", "gyro_x"]),
        &["bad.json", "not a calibration JSON"],
    );
}

/// `--against`: a calibration JSON without the empirical WV is monitored against the model
/// (auto) and refused with `--against wv` in one line; a real calibration's JSON is monitored
/// against its WV on request, saying so in the JSON and the table.
#[test]
fn monitor_against_the_calibration_wv() {
    let dir = tempfile::tempdir().unwrap();
    let file = triad(dir.path(), 8192);
    let bare = calibration(dir.path(), 1.0, "AR1(phi=0.99, sigma2=0.02)+WN(sigma2=1)");
    let doc =
        run_json(monitor(&file, &bare).args(["--columns", "gyro_x", "--window", "2048", "--json"]));
    assert_eq!(doc[0]["reference"], "model");
    assert_one_line_error(
        monitor(&file, &bare).args(["--columns", "gyro_x", "--window", "2048", "--against", "wv"]),
        &["gyro_x", "no empirical WV", "--against model"],
    );
    let cal = dir.path().join("cal.json");
    let out = gmwm()
        .arg("calibrate")
        .arg(&file)
        .args([
            "--freq",
            "1",
            "--columns",
            "gyro_x",
            "--model",
            "AR1()+WN()",
            "--G",
            "500",
        ])
        .arg("--json")
        .arg(&cal)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc = run_json(monitor(&file, &cal).args([
        "--columns",
        "gyro_x",
        "--window",
        "2048",
        "--against",
        "wv",
        "--json",
    ]));
    assert_eq!(doc[0]["reference"], "calibration WV");
    let table = monitor(&file, &cal)
        .args(["--columns", "gyro_x", "--window", "2048", "--against", "wv"])
        .output()
        .unwrap();
    assert!(
        String::from_utf8_lossy(&table.stdout).contains("against the calibration's empirical WV")
    );
}
