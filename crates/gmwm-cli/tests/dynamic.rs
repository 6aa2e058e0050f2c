//! `gmwm fit FILE --covariate COL --dynamic` (the non-stationary AR1 of the paper's §IV-B,
//! docs/methods.md §5.16): the dependence recovered from a CSV with a dynamics column, and one
//! clear line for each input that cannot carry it.

mod common;

use common::{assert_one_line_error, assert_usage_error, gmwm, run_json};
use std::path::{Path, PathBuf};

/// A CSV `gyro,speed` at 100 Hz: `speed` three slow cycles of a unit sinusoid, `gyro` the
/// non-stationary AR1 + WN along it (`beta1`), `speed` replaced by `bad(t, speed)`.
fn recording(dir: &Path, name: &str, beta1: f64, bad: impl Fn(usize, f64) -> f64) -> PathBuf {
    let n = 1 << 15;
    let z: Vec<f64> = (0..n)
        .map(|t| (6.0 * std::f64::consts::PI * t as f64 / n as f64).sin())
        .collect();
    let model = gmwm::NsAr1 {
        beta: [2.0, beta1],
        alpha: [-9.0, 0.0],
        gamma: Some([-9.0, 0.0]),
    };
    let x = model.simulate(&z, 21).unwrap();
    let mut text = String::from("gyro,speed\n");
    for (t, (x, z)) in x.iter().zip(&z).enumerate() {
        text.push_str(&format!("{x:e},{}\n", bad(t, *z)));
    }
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn dynamic_fit_recovers_rho_following_the_covariate() {
    let dir = tempfile::tempdir().unwrap();
    let csv = recording(dir.path(), "drive.csv", 0.6, |_, z| z);
    let doc = run_json(gmwm().arg("fit").arg(&csv).args([
        "--freq",
        "100",
        "--covariate",
        "speed",
        "--dynamic",
        "--model",
        "AR1()+WN()",
        "--json",
    ]));
    let fits = doc["dynamic_fits"].as_array().unwrap();
    assert_eq!(fits.len(), 1, "the covariate column is not fitted");
    let f = &fits[0];
    assert_eq!(f["column"], "gyro");
    assert_eq!(f["names"][1], "beta1");
    let (b1, se) = (
        f["theta"][1].as_f64().unwrap(),
        f["se"][1].as_f64().unwrap(),
    );
    assert!((b1 - 0.6).abs() < 4.0 * se, "beta1 {b1} +- {se}");
    assert!(f["stationary_objective"].as_f64().unwrap() > 5.0 * f["objective"].as_f64().unwrap());
    let out = gmwm()
        .arg("fit")
        .arg(&csv)
        .args([
            "--freq",
            "100",
            "--covariate",
            "speed",
            "--dynamic",
            "--model",
            "AR1()+WN()",
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    let table = String::from_utf8_lossy(&out.stdout);
    for needle in [
        "non-stationary AR1 along speed",
        "beta1",
        "rejected at 5%",
        "ignoring speed",
    ] {
        assert!(table.contains(needle), "{needle} not in {table}");
    }
}

#[test]
fn dynamic_fit_bad_inputs_are_one_line_each() {
    let dir = tempfile::tempdir().unwrap();
    let base = ["--freq", "100", "--covariate", "speed", "--dynamic"];
    let nan = recording(dir.path(), "nan.csv", 0.6, |t, z| {
        if t == 70 {
            f64::NAN
        } else {
            z
        }
    });
    assert_one_line_error(
        gmwm()
            .arg("fit")
            .arg(&nan)
            .args(base)
            .args(["--model", "AR1()+WN()"]),
        &["speed"],
    );
    let constant = recording(dir.path(), "const.csv", 0.6, |_, _| 1.0);
    assert_one_line_error(
        gmwm()
            .arg("fit")
            .arg(&constant)
            .args(base)
            .args(["--model", "AR1()+WN()"]),
        &["column gyro", "constant"],
    );
    let fine = recording(dir.path(), "fine.csv", 0.6, |_, z| z);
    assert_usage_error(
        gmwm()
            .arg("fit")
            .arg(&fine)
            .args(base)
            .args(["--model", "WN()+RW()"]),
        &["--dynamic", "AR1()+WN()"],
    );
    assert_usage_error(
        gmwm()
            .arg("fit")
            .arg(&fine)
            .args(["--freq", "100", "--dynamic", "--model", "AR1()"]),
        &["--covariate"],
    );
}
