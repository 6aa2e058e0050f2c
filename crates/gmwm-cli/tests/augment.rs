//! `gmwm fit --augment` (GMWM+, docs/methods.md §5.15): the fit beside GMWM's in the table, the
//! JSON and the CSV, and one clear line for what it cannot do.

mod common;

use common::{assert_one_line_error, assert_usage_error, gmwm, run_json, simulate};

const TRUTH: &str = "AR1(phi=0.9, sigma2=1e-6)+WN(sigma2=1e-4)";

#[test]
fn fit_augment_reports_gmwm_plus_beside_gmwm() {
    let dir = tempfile::tempdir().unwrap();
    let csv = simulate(dir.path(), "sim.csv", TRUTH, 1 << 14, 100.0, 3);
    let doc = run_json(gmwm().arg("fit").arg(&csv).args([
        "--model",
        "AR1()+WN()",
        "--augment",
        "acf:3",
        "--json",
    ]));
    let a = &doc["fits"][0]["augmented"];
    assert_eq!(a["augment"], "acf:3");
    assert_eq!(a["replicates"], 200);
    let truth = [0.9, 1e-6, 1e-4];
    for (p, t) in a["parameters"].as_array().unwrap().iter().zip(truth) {
        let (v, se) = (p["value"].as_f64().unwrap(), p["se"].as_f64().unwrap());
        // 2^14 samples: within 4 standard errors of the truth
        assert!((v - t).abs() < 4.0 * se, "{p} vs {t}");
        assert!(p["ci_low"].as_f64().unwrap() < v && v < p["ci_high"].as_f64().unwrap());
    }
    assert_eq!(a["moments"].as_array().unwrap().len(), 13 + 3);
    assert!(
        a["j_test"]["p_value"].as_f64().unwrap() > 1e-4,
        "{}",
        a["j_test"]
    );
    // without --augment the document has no such field
    let plain = run_json(
        gmwm()
            .arg("fit")
            .arg(&csv)
            .args(["--model", "AR1()+WN()", "--json"]),
    );
    assert!(plain["fits"][0].get("augmented").is_none());
    let out = gmwm()
        .arg("fit")
        .arg(&csv)
        .args(["--model", "AR1()+WN()", "--augment", "acf:2"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let table = String::from_utf8_lossy(&out.stdout);
    for needle in ["GMWM+ (augment acf:2", "acf_diff[2]", "J-test"] {
        assert!(table.contains(needle), "{needle} not in {table}");
    }
    let out = gmwm()
        .arg("fit")
        .arg(&csv)
        .args(["--model", "AR1()+WN()", "--augment", "acf:2", "--csv"])
        .output()
        .unwrap();
    let csv_text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        csv_text.lines().filter(|l| l.contains(",GMWM+,")).count(),
        3
    );
}

#[test]
fn fit_augment_bad_inputs_are_one_line_each() {
    let dir = tempfile::tempdir().unwrap();
    let csv = simulate(dir.path(), "sim.csv", TRUTH, 1 << 12, 100.0, 4);
    // a mean needs a DR term
    assert_one_line_error(
        gmwm()
            .arg("fit")
            .arg(&csv)
            .args(["--model", "AR1()+WN()", "--augment", "mean"]),
        &["augment", "DR()"],
    );
    // the flag's own values
    for bad in ["acf:0", "acf:17", "var", "mean,mean"] {
        assert_usage_error(
            gmwm()
                .arg("fit")
                .arg(&csv)
                .args(["--model", "AR1()+WN()", "--augment", bad]),
            &["--augment", "mean, acf:K"],
        );
    }
    // a saved WV has no series
    let wv = dir.path().join("wv.json");
    let out = gmwm()
        .arg("wv")
        .arg(&csv)
        .args(["--json"])
        .output()
        .unwrap();
    std::fs::write(&wv, &out.stdout).unwrap();
    assert_one_line_error(
        gmwm()
            .arg("fit")
            .arg(&wv)
            .args(["--model", "AR1()+WN()", "--augment", "acf:2"]),
        &["--augment needs the series", "saved wavelet variance"],
    );
}
