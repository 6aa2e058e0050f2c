//! `gmwm plan` end to end (issue 29, item 2): from a model, a datasheet and a calibration, the
//! half-widths shrink with the length, a target's length meets it, bad flags are one line.

mod common;

use common::{assert_usage_error, gmwm, run_json};

const MODEL: &str = "GM(beta=0.2, sigma2_gm=1e-6)+WN(sigma2=1e-4)+RW(gamma2=1e-10)";

#[test]
fn plan_from_a_model_with_a_target() {
    let v = run_json(gmwm().args([
        "plan",
        "--model",
        MODEL,
        "--freq",
        "100",
        "--lengths",
        "1h,3h,12h",
        "--target",
        "K=20%",
        "--json",
    ]));
    let plan = &v[0];
    assert_eq!(
        plan["lengths_s"],
        serde_json::json!([3600.0, 10800.0, 43200.0])
    );
    let names: Vec<&str> = plan["quantities"]
        .as_array()
        .unwrap()
        .iter()
        .map(|q| q["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["N", "B", "K", "T1"]);
    for q in plan["quantities"].as_array().unwrap() {
        let w: Vec<f64> = q["half_width"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        assert!(w[0] > w[1] && w[1] > w[2], "{}: {w:?}", q["name"]);
    }
    // the Monte Carlo of crate::tests::plan measured K at ±19% at 3 h
    let k = &plan["quantities"][2]["half_width"];
    assert!((k[1].as_f64().unwrap() - 0.18).abs() < 0.02, "{k}");
    let t = &plan["targets"][0];
    assert_eq!(t["quantity"], "K");
    let length = t["length_s"].as_f64().unwrap();
    assert!(length > 3600.0 && length < 10800.0, "{length}");
}

#[test]
fn plan_from_a_datasheet_states_the_conversion() {
    let v = run_json(gmwm().args([
        "plan",
        "--datasheet",
        "N=0.15 deg/sqrt(h), B=2 deg/h, K=0.5 deg/h/sqrt(h)",
        "--freq",
        "200",
        "--json",
    ]));
    assert_eq!(v.as_array().unwrap().len(), 1, "a gyroscope only");
    let g = &v[0];
    assert_eq!(g["name"], "gyro");
    assert!(
        g["from"].as_str().unwrap().contains("b2 = B^2"),
        "{}",
        g["from"]
    );
    assert!(
        g["model"].as_str().unwrap().starts_with("FN("),
        "{}",
        g["model"]
    );
    // B is the datasheet's, in rad/s
    let b = g["quantities"][1]["value"].as_f64().unwrap();
    assert!((b - 2.0 / 3600.0 * std::f64::consts::PI / 180.0).abs() < 1e-12 * b.max(1.0));
}

#[test]
fn plan_refuses_bad_flags() {
    assert_usage_error(gmwm().args(["plan", "--model", MODEL]), &["--freq"]);
    assert_usage_error(
        gmwm().args([
            "plan", "--model", MODEL, "--freq", "100", "--target", "K=abc",
        ]),
        &["--target", "K=abc"],
    );
    assert_usage_error(
        gmwm().args([
            "plan",
            "--model",
            MODEL,
            "--freq",
            "100",
            "--lengths",
            "3 weeks",
        ]),
        &["--lengths", "3 weeks"],
    );
    assert_usage_error(gmwm().args(["plan"]), &["--model"]);
}

#[test]
fn plan_draws_its_figure() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("plan.png");
    let out = gmwm()
        .args([
            "plan", "--model", MODEL, "--freq", "100", "--target", "K=20%", "--plot",
        ])
        .arg(&png)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(&png).unwrap();
    assert!(bytes.starts_with(b"\x89PNG"), "a PNG");
    assert!(bytes.len() > 10_000, "a drawn figure, not an empty canvas");
}
