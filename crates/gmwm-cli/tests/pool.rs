//! End-to-end tests of `gmwm fit FILE... --pool` (docs/methods.md §5.11) and `gmwm same-model`
//! (§7.7): the JSON shape and one clear error per mismatched input.

mod common;

use common::{assert_one_line_error, assert_usage_error, gmwm, run_json, simulate};
use std::path::{Path, PathBuf};

const TRUTH: &str = "WN(sigma2=1)+RW(gamma2=1e-4)";

fn three(dir: &Path) -> Vec<PathBuf> {
    [(4000, 1), (8000, 2), (12000, 3)]
        .iter()
        .map(|&(n, s)| simulate(dir, &format!("r{s}.csv"), TRUTH, n, 100.0, s))
        .collect()
}

#[test]
fn pooled_fit_json_lists_the_recordings_and_the_fit() {
    let dir = tempfile::tempdir().unwrap();
    let files = three(dir.path());
    let doc = run_json(gmwm().arg("fit").args(&files).args([
        "--pool",
        "--model",
        "WN()+RW()",
        "--G",
        "500",
        "--inference",
        "--json",
    ]));
    let recs = doc["recordings"].as_array().unwrap();
    assert_eq!(recs.len(), 3);
    assert_eq!(recs[1]["n"], 8000);
    assert_eq!(recs[2]["freq_hz"], 100.0);
    assert!(recs[0]["levels"].as_u64().unwrap() >= 10);
    let fit = &doc["fits"][0];
    assert_eq!(fit["column"], "x");
    let theta = fit["theta"].as_array().unwrap();
    assert!((theta[0].as_f64().unwrap() - 1.0).abs() < 0.05);
    assert_eq!(fit["recordings"].as_array().unwrap().len(), 3);
    let inf = fit["inference"].as_array().unwrap();
    assert!(inf[0]["ci_low"].as_f64().unwrap() < 1.0 && inf[0]["ci_high"].as_f64().unwrap() > 0.9);
    assert_eq!(fit["inference_method"], "asymptotic");
}

#[test]
fn same_model_json_has_the_documented_shape() {
    let dir = tempfile::tempdir().unwrap();
    let files = three(dir.path());
    let doc = run_json(gmwm().arg("same-model").args(&files).args([
        "--model",
        "WN()+RW()",
        "--G",
        "500",
        "--bootstrap",
        "9",
        "--json",
    ]));
    assert_eq!(doc["recordings"].as_array().unwrap().len(), 3);
    let t = &doc["tests"][0];
    assert_eq!(t["column"], "x");
    assert_eq!(t["df"], 4);
    let p = t["p_value"].as_f64().unwrap();
    assert!((0.0..=1.0).contains(&p));
    let pb = t["p_value_bootstrap"].as_f64().unwrap();
    // (1 + #exceed) / (B + 1) with B = 9
    assert!(((pb * 10.0).round() - pb * 10.0).abs() < 1e-9);
    let stat = t["statistic"].as_f64().unwrap();
    let sum: f64 = t["per_scale"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["contribution"].as_f64().unwrap())
        .sum();
    assert!((sum - stat).abs() < 1e-6 * (1.0 + stat));
    assert!(t["per_scale"][0]["wv_max_abs_z"].is_number());
}

#[test]
fn mismatched_inputs_give_one_clear_error_each() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = simulate(d, "a.csv", TRUTH, 4000, 100.0, 1);
    // another rate
    let b = simulate(d, "b.csv", TRUTH, 4000, 200.0, 2);
    assert_one_line_error(
        gmwm()
            .arg("fit")
            .args([&a, &b])
            .args(["--pool", "--model", "WN()+RW()"]),
        &["b.csv", "200 Hz", "100 Hz", "one"],
    );
    assert_one_line_error(
        gmwm()
            .arg("same-model")
            .args([&a, &b])
            .args(["--model", "WN()+RW()"]),
        &["b.csv", "200 Hz"],
    );
    // a column missing from one file
    let c = d.join("c.csv");
    std::fs::write(&c, "y\n1\n2\n3\n4\n5\n6\n7\n8\n").unwrap();
    std::fs::write(d.join("c.csv.json"), r#"{"sampling_frequency_hz": 100}"#).unwrap();
    assert_one_line_error(
        gmwm()
            .arg("same-model")
            .args([&a, &c])
            .args(["--model", "WN()+RW()", "--columns", "x"]),
        &["c.csv", "x"],
    );
    // different columns without --columns
    assert_one_line_error(
        gmwm()
            .arg("same-model")
            .args([&a, &c])
            .args(["--model", "WN()+RW()"]),
        &["c.csv", "columns", "--columns"],
    );
    // too short for the model: 8 samples, 2 levels, 3 parameters
    let short = simulate(d, "short.csv", TRUTH, 8, 100.0, 3);
    assert_one_line_error(
        gmwm()
            .arg("fit")
            .args([&a, &short])
            .args(["--pool", "--model", "AR1()+WN()"]),
        &["short.csv", "too short", "3 parameters"],
    );
    // units stated differently by the sidecars
    let u1 = d.join("u1.csv");
    let u2 = d.join("u2.csv");
    let body: String = std::iter::once("gyro_x\n".to_string())
        .chain((0..512).map(|i| format!("{}\n", ((i * 7919) % 13) as f64 * 0.1)))
        .collect();
    std::fs::write(&u1, &body).unwrap();
    std::fs::write(&u2, &body).unwrap();
    std::fs::write(
        d.join("u1.csv.json"),
        r#"{"sampling_frequency_hz": 100, "units": {"gyro": "deg/s"}}"#,
    )
    .unwrap();
    std::fs::write(
        d.join("u2.csv.json"),
        r#"{"sampling_frequency_hz": 100, "units": {"gyro": "rad/s"}}"#,
    )
    .unwrap();
    assert_one_line_error(
        gmwm()
            .arg("same-model")
            .args([&u1, &u2])
            .args(["--model", "WN()"]),
        &["u2.csv", "rad/s", "deg/s", "unit"],
    );
    // one recording only
    assert_one_line_error(
        gmwm()
            .arg("same-model")
            .arg(&a)
            .args(["--model", "WN()+RW()"]),
        &["a.csv", "two recordings"],
    );
    // several FILEs without --pool: clap's usage error (exit 2) naming --pool
    let out = gmwm()
        .arg("fit")
        .args([&a, &b])
        .args(["--model", "WN()+RW()"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--pool"));
    // a flag out of its domain
    assert_usage_error(
        gmwm()
            .arg("same-model")
            .args([&a, &b])
            .args(["--model", "WN()", "--bootstrap", "0"]),
        &["--bootstrap"],
    );
}

/// A gyro recording: `gmwm simulate`'s column renamed gyro_x, with a sidecar stating the rate
/// and (when given) the unit.
fn gyro(dir: &Path, name: &str, n: usize, freq: f64, seed: u64, unit: Option<&str>) -> PathBuf {
    let path = simulate(dir, name, TRUTH, n, freq, seed);
    let text = std::fs::read_to_string(&path).unwrap();
    let body = text.split_once('\n').unwrap().1;
    std::fs::write(&path, format!("gyro_x\n{body}")).unwrap();
    let units = unit.map_or(String::new(), |u| {
        format!(r#", "units": {{"gyro": "{u}"}}"#)
    });
    std::fs::write(
        dir.join(format!("{name}.json")),
        format!(r#"{{"sampling_frequency_hz": {freq}{units}}}"#),
    )
    .unwrap();
    path
}

/// `calibrate --pool`: one calibration of three recordings (one in deg/s), its JSON listing
/// them, the table titled by the pool; a folder of recordings works as FILE too.
#[test]
fn calibrate_pool_gives_one_calibration_of_all_recordings() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let files = [
        gyro(d, "r1.csv", 20000, 100.0, 1, Some("rad/s")),
        gyro(d, "r2.csv", 40000, 100.0, 2, Some("deg/s")),
        gyro(d, "r3.csv", 60000, 100.0, 3, Some("rad/s")),
    ];
    let doc = run_json(gmwm().arg("calibrate").args(&files).args([
        "--pool",
        "--model",
        "WN()+RW()",
        "--G",
        "500",
        "--json",
        "-",
    ]));
    let recs = doc["recordings"].as_array().unwrap();
    assert_eq!(recs.len(), 3);
    assert!(recs[1]["name"].as_str().unwrap().ends_with("r2.csv"));
    assert_eq!(recs[2]["samples"], 60000);
    assert_eq!(doc["samples"], 120000);
    let axis = &doc["axes"][0];
    assert_eq!(axis["column"], "gyro_x");
    assert_eq!(axis["data_unit"], "rad/s");
    // r2 holds rad/s-scale values labelled deg/s: the pool mixes two scales and says so
    let notes: Vec<&str> = axis["notes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    let r2 = notes.iter().find(|n| n.contains("r2.csv:")).unwrap();
    assert!(r2.contains("differs from the other recordings'"), "{r2}");
    let checks = doc["checks"].as_array().unwrap();
    assert!(
        checks
            .iter()
            .any(|c| c.as_str().unwrap().contains("rad/s, deg/s")),
        "{checks:?}"
    );
    // the three in rad/s as a folder: all agree, N near sqrt(sigma2 / f) = 0.1
    std::fs::remove_file(&files[1]).unwrap();
    std::fs::remove_file(d.join("r2.csv.json")).unwrap();
    gyro(d, "r2.csv", 40000, 100.0, 2, Some("rad/s"));
    let out = gmwm()
        .arg("calibrate")
        .arg(d)
        .args(["--pool", "--model", "WN()+RW()", "--G", "500"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.starts_with("3 recordings pooled: 120000 samples per axis in all"),
        "{table}"
    );
    assert!(table.contains("samples per axis in all"), "{table}");
    assert!(!table.contains("may not share"), "{table}");
    let doc = run_json(gmwm().arg("calibrate").arg(d).args([
        "--pool",
        "--model",
        "WN()+RW()",
        "--G",
        "500",
        "--json",
        "-",
    ]));
    let n = doc["axes"][0]["noise_density"]["value"].as_f64().unwrap();
    assert!((n / 0.1 - 1.0).abs() < 0.03, "N = {n}");
    assert_eq!(doc["axes"][0]["recording_wvs"].as_array().unwrap().len(), 3);
    // the HTML report lists the recordings and draws each one's WV with the pooled one
    let html = dir.path().join("pooled.html");
    let out = gmwm()
        .arg("calibrate")
        .args(&files)
        .args(["--pool", "--model", "WN()+RW()", "--G", "500", "--report"])
        .arg(&html)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(page.contains("<th>recordings</th>"));
    assert!(page.contains("<section id=\"recordings\">"));
    assert!(
        page.contains("Each recording&#39;s wavelet variance and the pooled one")
            || page.contains("Each recording's wavelet variance and the pooled one")
    );
}

#[test]
fn calibrate_pool_refuses_mismatched_recordings_one_line_each() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let a = gyro(d, "a.csv", 4000, 100.0, 1, Some("rad/s"));
    let cal = |files: &[&PathBuf], extra: &[&str]| {
        let mut c = gmwm();
        c.arg("calibrate")
            .args(files)
            .args(["--pool", "--model", "WN()+RW()", "--G", "200"])
            .args(extra);
        c
    };
    // another rate
    let b = gyro(d, "b.csv", 4000, 200.0, 2, Some("rad/s"));
    assert_one_line_error(
        &mut cal(&[&a, &b], &[]),
        &["b.csv", "200 Hz", "100 Hz", "one rate"],
    );
    // a unit stated in one recording and not in another
    let u = gyro(d, "u.csv", 4000, 100.0, 3, None);
    assert_one_line_error(
        &mut cal(&[&a, &u], &[]),
        &["u.csv", "gyro_x", "unit unknown", "a.csv", "rad/s"],
    );
    // a column missing
    let y = d.join("y.csv");
    std::fs::write(&y, "gyro_y\n1\n2\n3\n4\n5\n6\n7\n8\n").unwrap();
    std::fs::write(
        d.join("y.csv.json"),
        r#"{"sampling_frequency_hz": 100, "units": {"gyro": "rad/s"}}"#,
    )
    .unwrap();
    assert_one_line_error(
        &mut cal(&[&a, &y], &[]),
        &["y.csv", "no column gyro_x", "a.csv"],
    );
    // a recording too short for any wavelet variance
    let short = d.join("short.csv");
    std::fs::write(&short, "gyro_x\n0.1\n").unwrap();
    std::fs::write(
        d.join("short.csv.json"),
        r#"{"sampling_frequency_hz": 100, "units": {"gyro": "rad/s"}}"#,
    )
    .unwrap();
    assert_one_line_error(&mut cal(&[&a, &short], &[]), &["short.csv", "gyro_x"]);
    // one recording
    assert_usage_error(&mut cal(&[&a], &[]), &["--pool", "1 found", "two or more"]);
    // batch flags, standard input
    assert_usage_error(
        &mut cal(&[&a, &b], &["--out-dir", "o"]),
        &["--pool", "--out-dir", "batch mode"],
    );
    let dash = PathBuf::from("-");
    assert_usage_error(&mut cal(&[&a, &dash], &[]), &["standard input", "--pool"]);
}
