//! End-to-end tests of `gmwm select` (docs/methods.md §8): the JSON shape, the table, determinism
//! and one test per bad-input class.

mod common;

use common::{gmwm, run_json, simulate};
use std::path::Path;

/// A seeded AR1 + WN + RW series (5000 samples, 100 Hz, with its sidecar) in `dir`.
fn simulated(dir: &Path) -> std::path::PathBuf {
    let model = "AR1(phi=0.95, sigma2=0.1)+WN(sigma2=1)+RW(gamma2=1e-2)";
    simulate(dir, "sim.csv", model, 5000, 100.0, 3)
}

fn select_json(file: &Path, extra: &[&str]) -> serde_json::Value {
    run_json(
        gmwm()
            .arg("select")
            .arg(file)
            .args(["--G", "500", "--bootstrap", "20", "--json"])
            .args(extra),
    )
}

#[test]
fn select_json_has_the_documented_shape() {
    let dir = tempfile::tempdir().unwrap();
    let file = simulated(dir.path());
    let doc = select_json(&file, &["--model", "AR1()+WN()+RW()"]);
    let sel = doc["selections"].as_array().unwrap();
    assert_eq!(sel.len(), 1);
    assert_eq!(sel[0]["column"], "x");
    let mut top: Vec<&str> = sel[0]
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    top.sort();
    assert_eq!(
        top,
        [
            "candidates",
            "canonical",
            "canonical_notes",
            "column",
            "reason",
            "rows",
            "rule",
            "selected",
            "selected_canonical",
            "v_method",
            "v_replicates"
        ]
    );
    let cands = sel[0]["candidates"].as_array().unwrap();
    // 2^3 - 1 sub-models of AR1 + WN + RW
    assert_eq!(cands.len(), 7);
    let mut keys: Vec<&str> = cands[0]
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    keys.sort();
    assert_eq!(
        keys,
        [
            "canonical_model",
            "gof_p_value",
            "gof_p_value_upper_bound",
            "model",
            "objective",
            "optimism",
            "wic"
        ]
    );
    let wic: Vec<f64> = cands.iter().map(|c| c["wic"].as_f64().unwrap()).collect();
    // sorted by wic (ties within 1e-6 relative go to the smaller model)
    assert!(
        wic.windows(2).all(|w| w[0] <= w[1] * (1.0 + 1e-6)),
        "sorted by wic: {wic:?}"
    );
    for c in cands {
        let (o, p, w) = (
            c["objective"].as_f64().unwrap(),
            c["optimism"].as_f64().unwrap(),
            c["wic"].as_f64().unwrap(),
        );
        // wic = objective + optimism exactly as computed (one rounding)
        assert!((o + p - w).abs() <= 1e-15 * w.abs(), "{c}");
        assert!(o >= 0.0 && p > 0.0, "{c}");
    }
    // the rows: one per canonical model, the selected one marked, its canonical model named
    let rows = sel[0]["rows"].as_array().unwrap();
    let selected: Vec<&serde_json::Value> =
        rows.iter().filter(|r| r["status"] == "selected").collect();
    assert_eq!(selected.len(), 1);
    assert_eq!(sel[0]["selected_canonical"], selected[0]["canonical_model"]);
    assert_eq!(sel[0]["selected"], selected[0]["model"]);
    // the true structure is selected on this seed, and its terms carry the read-off
    assert_eq!(sel[0]["selected_canonical"], "AR1()+WN()+RW()");
    let terms: Vec<&str> = sel[0]["canonical"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["process"].as_str().unwrap())
        .collect();
    assert_eq!(terms, ["AR1", "WN", "RW"]);
    let wn = &sel[0]["canonical"][1]["physical"][0];
    assert_eq!(wn["name"], "white_noise_density");
    assert!(wn["value"].as_f64().unwrap() > 0.0);
    // every candidate names its canonical model, and each canonical model has one row
    for c in cands {
        let cm = c["canonical_model"].as_str().unwrap();
        assert_eq!(
            rows.iter().filter(|r| r["canonical_model"] == cm).count(),
            1,
            "{cm}"
        );
    }
    // the same seed gives the same bits
    assert_eq!(select_json(&file, &["--model", "AR1()+WN()+RW()"]), doc);
}

#[test]
fn select_csv_and_top_fold_the_table() {
    let dir = tempfile::tempdir().unwrap();
    let file = simulated(dir.path());
    let args = [
        "--model",
        "2*AR1()+WN()+RW()+QN()",
        "--G",
        "300",
        "--bootstrap",
        "20",
    ];
    let csv = gmwm()
        .arg("select")
        .arg(&file)
        .args(args)
        .arg("--csv")
        .output()
        .unwrap();
    assert!(csv.status.success(), "{csv:?}");
    let text = String::from_utf8(csv.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "column,rank,canonical_model,candidate,members,objective,optimism,wic,delta_wic,\
         delta_wic_se,gof_p_value,gof_p_value_upper_bound,status"
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert!(rows.iter().all(|r| r.len() == 13), "{text}");
    assert_eq!(
        rows.iter().filter(|r| r[12] == "selected").count(),
        1,
        "{text}"
    );
    // 23 candidates fold into fewer rows, each canonical model once
    let mut models: Vec<&str> = rows.iter().map(|r| r[2]).collect();
    let n = models.len();
    models.sort();
    models.dedup();
    assert_eq!(models.len(), n, "{text}");
    let members: usize = rows.iter().map(|r| r[4].split(';').count()).sum();
    assert_eq!(members, 23, "{text}");
    assert!(n < 23);
    // --top 2: two rows (plus any selected or equivalent one) and a line saying how many more
    let out = gmwm()
        .arg("select")
        .arg(&file)
        .args(args)
        .args(["--top", "2"])
        .output()
        .unwrap();
    let table = String::from_utf8(out.stdout).unwrap();
    assert!(table.contains("more rows (--top 0 shows all)"), "{table}");
    let shown = table
        .lines()
        .filter(|l| l.contains("e-") && l.contains("()"))
        .count();
    assert!(shown >= 2 && shown < n, "{table}");
}

#[test]
fn select_candidate_list_adds_the_common_denominator() {
    let dir = tempfile::tempdir().unwrap();
    let file = simulated(dir.path());
    let doc = select_json(&file, &["--candidates", "AR1()+WN(); 2*AR1()+RW()"]);
    let mut models: Vec<String> = doc["selections"][0]["candidates"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["model"].as_str().unwrap().to_string())
        .collect();
    models.sort();
    assert_eq!(models, ["2*AR1()+RW()", "2*AR1()+WN()+RW()", "AR1()+WN()"]);
}

#[test]
fn select_table_names_the_column_and_the_selected_model() {
    let dir = tempfile::tempdir().unwrap();
    let file = simulated(dir.path());
    let out = gmwm()
        .arg("select")
        .arg(&file)
        .args(["--model", "AR1()+WN()", "--G", "300", "--bootstrap", "10"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.starts_with("x\nWIC model selection: full model AR1()+WN()"),
        "{text}"
    );
    assert!(text.contains("selected: "), "{text}");
    assert!(text.contains("GoF p"), "{text}");
    assert!(text.contains("canonical model: "), "{text}");
}

/// Exit code 1 and one error line containing every needle.
fn assert_error(file: &Path, args: &[&str], needles: &[&str]) {
    common::assert_one_line_error(gmwm().arg("select").arg(file).args(args), needles);
}

#[test]
fn select_bad_inputs_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let file = simulated(dir.path());
    assert_error(
        &file,
        &["--model", "AR1()+ARMA(1,1)"],
        &[
            "candidate AR1()+ARMA(1,1)",
            "not supported in model selection",
        ],
    );
    assert_error(
        &file,
        &["--candidates", "GM()+WN();AR1()+RW()"],
        &["candidate GM()+WN() uses GM but candidate AR1()+RW() uses AR1"],
    );
    assert_error(
        &file,
        &["--candidates", "AR1()+WN();WN()+RW()+WN()"],
        &["candidate 2", "WN()+RW()+WN()", "found WN 2 times"],
    );
    let usage = |args: &[&str], needles: &[&str]| {
        common::assert_usage_error(gmwm().arg("select").arg(&file).args(args), needles)
    };
    usage(
        &["--model", "AR1()+WN()", "--bootstrap", "1"],
        &["--bootstrap", "'1'"],
    );
    usage(&["--model", "AR1()+WN()", "--G", "0"], &["--G", "'0'"]);
    assert_error(&file, &["--candidates", " ; "], &["--candidates"]);
    usage(
        &["--model", "AR1()+WN()", "--robust", "--eff", "1.5"],
        &["'1.5'", "--eff"],
    );
    assert_error(&file, &["--model", "AR1(", "--G", "10"], &["AR1("]);
    // usage errors exit 2
    let out = gmwm().arg("select").arg(&file).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "{out:?}");
}

#[test]
fn select_help_shows_examples() {
    let out = gmwm().args(["select", "--help"]).output().unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("Examples:"), "{text}");
    assert!(text.contains("--candidates"), "{text}");
    assert!(text.contains("[default: 50]"), "{text}");
}
