//! `gmwm fit FILE... --covariate COL | --covariate-values LIST` (issue 31 items 2 and 4,
//! docs/methods.md §5.13): the JSON's shape and values on a simulated temperature-dependent
//! sensor, and one clear line per input that cannot carry a dependence.

mod common;

use common::{assert_one_line_error, gmwm, run_json, simulate};
use std::path::{Path, PathBuf};

const TEMPS: [f64; 4] = [5.0, 15.0, 25.0, 35.0];

/// `log sigma2_wn(T) = ln 1e-4 + 0.03 (T - 20)`, `log sigma2_gm(T) = ln 1e-5 - 0.02 (T - 20)`.
fn truth_at(t: f64) -> (f64, f64) {
    (
        1e-4 * (0.03 * (t - 20.0)).exp(),
        1e-5 * (-0.02 * (t - 20.0)).exp(),
    )
}

/// Four recordings at [`TEMPS`] (100 Hz, 2^15 samples each) with a `time`, a `gyro_x` and a
/// `temperature` column: the temperature wanders by 0.1 °C around its level. With
/// `constant_temperature`, every file says 20 °C.
fn recordings(dir: &Path, constant_temperature: bool) -> Vec<PathBuf> {
    TEMPS
        .iter()
        .enumerate()
        .map(|(k, &t)| {
            let (s2, g2) = truth_at(t);
            let raw = simulate(
                dir,
                &format!("raw{k}.csv"),
                &format!("WN(sigma2={s2})+GM(beta=0.5, sigma2_gm={g2})"),
                1 << 15,
                100.0,
                k as u64 + 1,
            );
            let text = std::fs::read_to_string(&raw).unwrap();
            let level = if constant_temperature { 20.0 } else { t };
            let mut out = String::from("time,gyro_x,temperature\n");
            for (i, line) in text.lines().skip(1).enumerate() {
                let wander = 0.1 * (i as f64 / 3000.0).sin();
                out.push_str(&format!(
                    "{:.2},{line},{:.3}\n",
                    i as f64 / 100.0,
                    level + wander
                ));
            }
            let path = dir.join(format!("t{k}.csv"));
            std::fs::write(&path, out).unwrap();
            path
        })
        .collect()
}

#[test]
fn covariate_column_fit_recovers_the_dependence_with_bands() {
    let dir = tempfile::tempdir().unwrap();
    let files = recordings(dir.path(), false);
    let doc = run_json(gmwm().arg("fit").args(&files).args([
        "--covariate",
        "temperature",
        "--model",
        "WN()+GM()",
        "--at",
        "0,40",
        "--json",
    ]));
    assert_eq!(doc["covariate"], "temperature");
    let recs = doc["recordings"].as_array().unwrap();
    assert_eq!(recs.len(), 4);
    for (r, t) in recs.iter().zip(TEMPS) {
        // the mean of a 0.1 °C wander over 3.4 of its periods
        assert!((r["covariate"].as_f64().unwrap() - t).abs() < 0.05, "{r}");
    }
    let fits = doc["fits"].as_array().unwrap();
    assert_eq!(
        fits.len(),
        1,
        "the temperature column is the regressor, not fitted"
    );
    let fit = &fits[0];
    assert_eq!(fit["column"], "gyro_x");
    assert_eq!(
        fit["dependence"],
        serde_json::json!(["affine", "constant", "affine"])
    );
    let inf = &fit["inference"];
    assert_eq!(inf["coefficients"].as_array().unwrap().len(), 5);
    assert_eq!(inf["covariance"].as_array().unwrap().len(), 5);
    let test = &inf["no_dependence"];
    assert_eq!(test["df"], 2);
    assert!(test["p_value"].as_f64().unwrap() < 1e-6, "{test}");
    // the white-noise slope on the log scale: 0.03 per °C, within 4 SE
    let slope = &inf["coefficients"][1];
    assert_eq!(slope["power"], 1);
    let (est, se) = (
        slope["estimate"].as_f64().unwrap(),
        slope["se"].as_f64().unwrap(),
    );
    assert!((est - 0.03).abs() < 4.0 * se, "{slope}");
    // the bands at 0 and 40 °C, outside the recordings' range, hold the truth
    let bands = fit["bands"].as_array().unwrap();
    assert_eq!(bands.len(), 2);
    for b in bands {
        let t = b["covariate"].as_f64().unwrap();
        let wn = &b["parameters"][0];
        assert_eq!(wn["name"], "WN[0].sigma2");
        let (lo, hi) = (
            wn["ci_low"].as_f64().unwrap(),
            wn["ci_high"].as_f64().unwrap(),
        );
        assert!(lo < truth_at(t).0 && truth_at(t).0 < hi, "{t} °C: {wn}");
    }
}

#[test]
fn covariate_values_and_the_table() {
    let dir = tempfile::tempdir().unwrap();
    let files = recordings(dir.path(), false);
    let out = gmwm()
        .arg("fit")
        .args(&files)
        .args(["--covariate-values", "5,15,25,35", "--columns", "gyro_x"])
        .args([
            "--model",
            "WN()+GM()",
            "--depends",
            "all=constant,WN[0].sigma2=affine",
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("covariate levels: 5, 15, 25, 35"), "{text}");
    assert!(
        text.contains("no dependence on covariate (Wald, all slopes)"),
        "{text}"
    );
    assert!(
        text.contains("WN[0].sigma2             affine      1"),
        "{text}"
    );
    assert!(
        text.contains("GM[1].sigma2_gm        constant      0"),
        "{text}"
    );
    // two coefficients, one test, bands at the four levels
    let rows = text.lines().filter(|l| l.contains("WN[0].sigma2")).count();
    assert_eq!(rows, 2 + 1 + 4, "{text}");
}

#[test]
fn covariates_that_cannot_carry_a_dependence_are_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let files = recordings(dir.path(), true);
    let fit = |extra: &[&str]| {
        let mut cmd = gmwm();
        cmd.arg("fit").args(&files).args(["--model", "WN()+GM()"]);
        cmd.args(extra);
        cmd
    };
    // every file at 20 °C: nothing to regress on
    assert_one_line_error(
        &mut fit(&["--covariate", "temperature"]),
        &["distinct", "WN[0].sigma2", "does not vary"],
    );
    assert_one_line_error(
        &mut fit(&["--covariate-values", "5,15,25"]),
        &["--covariate-values", "3 value(s) for 4 FILEs"],
    );
    assert_one_line_error(
        &mut fit(&[
            "--covariate-values",
            "5,15,25,35",
            "--depends",
            "GM.beta=affine",
        ]),
        &[
            "--depends GM.beta=affine",
            "WN[0].sigma2, GM[1].beta, GM[1].sigma2_gm",
        ],
    );
    assert_one_line_error(&mut fit(&["--covariate", "pressure"]), &["pressure"]);
    assert_one_line_error(
        gmwm().args(["fit", "a.csv", "--model", "WN()", "--depends", "all=affine"]),
        &["--depends", "--covariate"],
    );
    // a NaN in the covariate column names the file
    let text = std::fs::read_to_string(&files[1]).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let cells: Vec<&str> = lines[100].split(',').collect();
    lines[100] = format!("{},{},nan", cells[0], cells[1]);
    std::fs::write(&files[1], lines.join("\n") + "\n").unwrap();
    let mut cmd = gmwm();
    cmd.arg("fit")
        .args(&files)
        .args(["--model", "WN()+GM()", "--covariate", "temperature"]);
    assert_one_line_error(&mut cmd, &["t1.csv"]);
}

#[test]
fn one_recording_on_a_ramp_is_cut_into_windows() {
    let dir = tempfile::tempdir().unwrap();
    let n = 1 << 16;
    let raw = simulate(dir.path(), "unit.csv", "WN(sigma2=1)", n, 100.0, 9);
    let text = std::fs::read_to_string(&raw).unwrap();
    let mut out = String::from("time,gyro_x,temperature\n");
    for (i, line) in text.lines().skip(1).enumerate() {
        let t = 40.0 * i as f64 / n as f64;
        let z: f64 = line.parse().unwrap();
        let x = z * truth_at(t).0.sqrt();
        out.push_str(&format!("{:.2},{x:.9e},{t:.4}\n", i as f64 / 100.0));
    }
    let ramp = dir.path().join("ramp.csv");
    std::fs::write(&ramp, out).unwrap();
    let doc = run_json(gmwm().arg("fit").arg(&ramp).args([
        "--covariate",
        "temperature",
        "--windows",
        "8",
        "--model",
        "WN()",
        "--json",
    ]));
    let recs = doc["recordings"].as_array().unwrap();
    assert_eq!(recs.len(), 8);
    assert!(recs[2]["path"]
        .as_str()
        .unwrap()
        .ends_with("ramp.csv [window 3/8]"));
    assert_eq!(recs[2]["n"], n / 8);
    assert!((recs[2]["covariate"].as_f64().unwrap() - 12.5).abs() < 1e-3);
    // a ramp's bands at its ends and its centre
    let bands = doc["fits"][0]["bands"].as_array().unwrap();
    assert_eq!(bands.len(), 3);
    let slope = &doc["fits"][0]["inference"]["coefficients"][1];
    let (est, se) = (
        slope["estimate"].as_f64().unwrap(),
        slope["se"].as_f64().unwrap(),
    );
    assert!((est - 0.03).abs() < 4.0 * se, "{slope}");
    // --windows cuts one FILE; --covariate-values needs a FILE per level
    let mut cmd = gmwm();
    cmd.arg("fit").arg(&ramp).arg(&ramp);
    cmd.args([
        "--covariate",
        "temperature",
        "--windows",
        "4",
        "--model",
        "WN()",
    ]);
    assert_one_line_error(&mut cmd, &["--windows 4", "2 FILEs"]);
    let mut cmd = gmwm();
    cmd.arg("fit").arg(&ramp);
    cmd.args(["--covariate-values", "5", "--model", "WN()"]);
    assert_one_line_error(&mut cmd, &["one FILE", "--covariate COL"]);
    let mut cmd = gmwm();
    cmd.arg("fit").arg(&ramp);
    cmd.args([
        "--covariate",
        "temperature",
        "--windows",
        "400",
        "--model",
        "WN()",
    ]);
    assert_one_line_error(&mut cmd, &["--windows 400", "at most 64"]);
    // 64 windows of 1024 samples: each still fits
    let mut cmd = gmwm();
    cmd.arg("fit").arg(&ramp);
    cmd.args([
        "--covariate",
        "temperature",
        "--windows",
        "64",
        "--model",
        "WN()",
        "--json",
    ]);
    assert_eq!(
        run_json(&mut cmd)["recordings"].as_array().unwrap().len(),
        64
    );
}
