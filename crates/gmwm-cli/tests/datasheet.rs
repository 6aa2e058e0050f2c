//! End-to-end tests of `--datasheet` (issue 28, item 6) and of the unit flags of `gmwm plot`:
//! the datasheet in calibrate's JSON in SI beside the measured values, a bad datasheet as one
//! usage line, the datasheet's lines on the figures, `--gyro-unit`/`--accel-unit` on a plot.

mod common;

use common::{assert_usage_error, gmwm, run_json};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

/// One or two multiplications, printed by serde_json at full precision: a few ulps.
const TOL_EXACT: f64 = 1e-12;

/// The ADIS16405 datasheet: ARW 2 °/√h, in-run bias stability 25.2 °/h (0.007 °/s), VRW
/// 0.2 m/s/√h, accelerometer bias stability 0.2 mg.
const ADIS: &str = "N=2 deg/sqrt(h), B=25.2 deg/h, N=0.2 m/s/sqrt(h), B=0.2 mg";

fn data_dir() -> PathBuf {
    std::env::var_os("GMWM_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"))
}

fn adis() -> PathBuf {
    let file = data_dir().join("adis_16405_imu1.csv.gz");
    assert!(file.exists(), "{} missing (GMWM_DATA_DIR)", file.display());
    file
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// A recording without sidecar (units unknown): `gyro_x` and `accel_x`, 4096 samples of a
/// fixed pseudo-random sequence.
fn unitless(dir: &Path) -> PathBuf {
    let path = dir.join("imu.csv");
    let mut state: u64 = 12345;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut text = String::from("gyro_x,accel_x\n");
    for _ in 0..4096 {
        text.push_str(&format!("{},{}\n", next(), next()));
    }
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn calibrate_json_carries_the_datasheet_in_si() {
    let doc = run_json(
        gmwm()
            .arg("calibrate")
            .arg(adis())
            .args(["--columns", "gyro_x,accel_y", "--datasheet", ADIS])
            .args(["--json", "-", "-q"]),
    );
    let axes = doc["axes"].as_array().unwrap();
    assert_eq!(axes.len(), 2);
    let f = |v: &serde_json::Value| v.as_f64().unwrap();
    let gyro = &axes[0]["datasheet"];
    let accel = &axes[1]["datasheet"];
    // 2 deg/sqrt(h) = 2 (pi/180) / 60 rad/s/sqrt(Hz); 25.2 deg/h = 25.2 (pi/180) / 3600 rad/s
    assert!(rel(f(&gyro["N"]["value_si"]), 2.0 * (PI / 180.0) / 60.0) < TOL_EXACT);
    assert!(rel(f(&gyro["B"]["value_si"]), 25.2 * (PI / 180.0) / 3600.0) < TOL_EXACT);
    assert_eq!(gyro["N"]["unit"], "deg/sqrt(h)");
    assert_eq!(gyro["N"]["unit_si"], "rad/s/√Hz");
    assert!(gyro.get("K").is_none(), "no K in the datasheet");
    // 0.2 m/s/sqrt(h) = 0.2 / 60 m/s^2/sqrt(Hz); 0.2 mg = 0.2e-3 x 9.80665 m/s^2
    assert!(rel(f(&accel["N"]["value_si"]), 0.2 / 60.0) < TOL_EXACT);
    assert!(rel(f(&accel["B"]["value_si"]), 0.2e-3 * 9.80665) < TOL_EXACT);
    // the measured values are the axis' estimates; the ratio is measured / datasheet
    for (axis, sheet) in [(&axes[0], gyro), (&axes[1], accel)] {
        for (key, estimate) in [("N", "noise_density"), ("B", "bias_instability")] {
            let t = &sheet[key];
            let measured = f(&axis[estimate]["value"]);
            assert_eq!(f(&t["measured_si"]), measured, "{key}");
            assert!(rel(f(&t["ratio"]), measured / f(&t["value_si"])) < TOL_EXACT);
            let verdict = t["verdict"].as_str().unwrap();
            assert!(
                ["inside", "above", "below", "no-interval"].contains(&verdict),
                "{verdict}"
            );
        }
    }
    // the measured value in the datasheet's unit: 2 deg/sqrt(h) per value_si
    let n = &gyro["N"];
    assert!(
        rel(
            f(&n["measured"]),
            f(&n["measured_si"]) * 2.0 / f(&n["value_si"])
        ) < TOL_EXACT
    );
}

#[test]
fn calibrate_summary_shows_the_datasheet_beside_the_measured_values() {
    let out = gmwm()
        .arg("calibrate")
        .arg(adis())
        .args([
            "--columns",
            "gyro_x",
            "--datasheet",
            "N=2 deg/sqrt(h), B=25.2 deg/h",
        ])
        .arg("-q")
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    let text = String::from_utf8_lossy(&out.stdout);
    let line = |key: &str| {
        text.lines()
            .find(|l| l.trim_start().starts_with(&format!("datasheet {key}")))
            .unwrap_or_else(|| panic!("no datasheet {key} line in {text}"))
            .to_string()
    };
    let n = line("N");
    assert!(n.contains("2 deg/sqrt(h) = 5.818e-4 rad/s/√Hz"), "{n}");
    assert!(n.contains("ratio") && n.contains("datasheet "), "{n}");
    assert!(line("B").contains("25.2 deg/h = 1.222e-4 rad/s"));
}

#[test]
fn bad_datasheet_is_one_usage_line_naming_the_flag_and_the_item() {
    for (spec, needles) in [
        (
            "X=2 deg/sqrt(h)",
            &["--datasheet", "\"X=2 deg/sqrt(h)\"", "unknown key"][..],
        ),
        (
            "N=25 deg/h",
            &["--datasheet", "\"N=25 deg/h\"", "bias instability"][..],
        ),
        ("N=deg/sqrt(h)", &["--datasheet", "no number"][..]),
        ("N=2 furlong", &["--datasheet", "furlong"][..]),
        (
            "N=2 deg/sqrt(h), N=3 deg/sqrt(h)",
            &["--datasheet", "\"N=3 deg/sqrt(h)\"", "twice"][..],
        ),
        ("", &["--datasheet", "no item"][..]),
    ] {
        assert_usage_error(
            gmwm()
                .arg("calibrate")
                .arg(adis())
                .args(["--datasheet", spec]),
            needles,
        );
        assert_usage_error(
            gmwm().args(["plot", "ieee"]).arg(adis()).args([
                "--datasheet",
                spec,
                "-o",
                "never.svg",
            ]),
            needles,
        );
    }
    // the Allan slope laws only: not on a Hadamard deviation
    assert_usage_error(
        gmwm().args(["plot", "avar"]).arg(adis()).args([
            "--kind",
            "hadamard",
            "--datasheet",
            ADIS,
            "-o",
            "never.svg",
        ]),
        &["--datasheet", "hadamard"],
    );
}

#[test]
fn plot_with_datasheet_is_written_with_its_lines() {
    let dir = tempfile::tempdir().unwrap();
    for (figure, extra) in [
        ("ieee", &["--columns", "gyro_x"][..]),
        ("avar", &["--columns", "gyro_x,accel_x"][..]),
        ("wv", &["--columns", "gyro_x,accel_x", "--overlay"][..]),
        (
            "fit",
            &["--columns", "gyro_x", "--model", "AR1()+WN()", "--G", "200"][..],
        ),
        ("compare", &["--columns", "gyro_x,accel_x"][..]),
        (
            "select",
            &[
                "--columns",
                "gyro_x",
                "--model",
                "AR1()+WN()+RW()",
                "--G",
                "200",
            ][..],
        ),
    ] {
        let svg = dir.path().join(format!("{figure}.svg"));
        let out = gmwm()
            .args(["plot", figure])
            .arg(adis())
            .args(extra)
            .args(["--datasheet", ADIS, "-q", "-o"])
            .arg(&svg)
            .output()
            .unwrap();
        assert!(out.status.success(), "{figure}: {out:?}");
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.contains("datasheet N = 2 deg/sqrt(h)"), "{figure}");
        assert!(text.contains("datasheet B = 25.2 deg/h"), "{figure}");
        if extra.contains(&"gyro_x,accel_x") {
            assert!(text.contains("datasheet B = 0.2 mg"), "{figure}");
        }
        let png = dir.path().join(format!("{figure}.png"));
        gmwm()
            .args(["plot", figure])
            .arg(adis())
            .args(extra)
            .args(["--datasheet", ADIS, "-q", "-o"])
            .arg(&png)
            .assert()
            .success();
        assert!(std::fs::metadata(&png).unwrap().len() > 1000, "{figure}");
    }
}

#[test]
fn plot_takes_the_unit_flags_of_calibrate() {
    let dir = tempfile::tempdir().unwrap();
    let file = unitless(dir.path());
    let svg = dir.path().join("avar.svg");
    let out = gmwm()
        .args(["plot", "avar"])
        .arg(&file)
        .args(["--gyro-unit", "deg/s", "--datasheet", ADIS, "-o"])
        .arg(&svg)
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    let text = std::fs::read_to_string(&svg).unwrap();
    // the gyroscope in the unit given, with its datasheet lines; the accelerometer unknown
    assert!(text.contains("σ(τ) [deg/s]"), "gyroscope axis label");
    assert!(text.contains("datasheet N = 2 deg/sqrt(h)"));
    assert!(!text.contains("datasheet B = 0.2 mg"));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr
            .contains("column accel_x: unit unknown, no datasheet line drawn (give --accel-unit)"),
        "{stderr}"
    );
    // with both units, both sensors' lines
    gmwm()
        .args(["plot", "ieee"])
        .arg(&file)
        .args([
            "--columns",
            "accel_x",
            "--accel-unit",
            "g",
            "--datasheet",
            ADIS,
            "-o",
        ])
        .arg(&svg)
        .assert()
        .success();
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("[g]") && text.contains("datasheet B = 0.2 mg"));
    assert_usage_error(
        gmwm().args(["plot", "wv"]).arg(&file).args([
            "--gyro-unit",
            "furlong/s",
            "-o",
            "never.svg",
        ]),
        &["--gyro-unit"],
    );
}
