//! Issue 4 "must show": parity with the R package's `gmwm_imu` fits on real data, the bootstrap
//! weighting, `update`, fits of a WV read from JSON, and the §5.7 refusals.

use crate::tests::common::{data_dir, read_column, read_ref};
use gmwm::fit::{FitError, Gmwm, StartInputs, Weighting};
use gmwm::model::Model;
use gmwm::{wavelet_variance, RobustConvention, RobustOptions, WvOptions};

fn robust_package() -> WvOptions {
    WvOptions {
        robust: Some(RobustOptions::new(0.6, RobustConvention::Package).unwrap()),
        ..WvOptions::default()
    }
}

/// `../shared/ref/gmwm_adis_16405_imu1_{gyro_x,accel_x}.json`: for each of the three models,
/// classical and robust (eff 0.6, the package's robust convention so that the WV, its CI and
/// hence the fast weights are the package's to ~1e-11), our guess-mode fit with the default
/// G and seed reaches an objective no higher than the package's, to 1e-6 relative (the
/// issue's tolerance), and converges.
#[test]
fn objective_never_above_the_r_package_on_adis_imu1() {
    for column in ["gyro_x", "accel_x"] {
        let r = read_ref(&format!("gmwm_adis_16405_imu1_{column}.json"));
        let x = read_column("adis_16405_imu1", column);
        let freq = r["freq_hz"].as_f64().unwrap();
        let classical = wavelet_variance(&x, freq, &WvOptions::default()).unwrap();
        let robust = wavelet_variance(&x, freq, &robust_package()).unwrap();
        let fits = r["fits"].as_object().unwrap();
        assert_eq!(fits.len(), 6);
        for (key, f) in fits {
            let model = Model::parse(f["model"].as_str().unwrap()).unwrap();
            let is_robust = f["robust"].as_bool().unwrap();
            let wv = if is_robust { &robust } else { &classical };
            let ours = Gmwm::new(model)
                .fit_from_wv(wv, StartInputs::from_series(&x))
                .unwrap();
            let r_obj = f["gm"]["obj_fun"].as_f64().unwrap();
            assert!(ours.convergence().converged, "{column} {key}: {ours}");
            assert!(
                ours.objective() <= r_obj * (1.0 + 1e-6),
                "{column} {key}: ours Q = {} > R's {r_obj}\n{ours}",
                ours.objective()
            );
            // the same weights as the package (its omega_diag), to the WV parity (1e-9)
            let omega = crate::tests::common::f64s(&f["gm"]["omega_diag"]);
            for (j, (a, b)) in ours.weights().omega.iter().zip(&omega).enumerate() {
                assert!(
                    crate::tests::common::rel_diff(*a, *b) < 1e-8,
                    "{column} {key}: omega level {}: {a} vs {b}",
                    j + 1
                );
            }
        }
    }
}

/// The bootstrap weighting refits with `V_jj` from the parametric bootstrap of the first fit
/// and keeps the fast V as `org_v`; the refit sits near the fast one on well-specified data,
/// and the bootstrap V is close to the implied-model variance of the WV (for white noise
/// known in closed form at level 1: Var = 2 nu2^2 / edf with edf ~ 2M/3).
#[test]
fn bootstrap_weighting_refits_with_bootstrap_variances() {
    let truth = Model::parse("AR1(phi=0.95, sigma2=0.1)+WN(sigma2=1)").unwrap();
    let x = gmwm::sim::simulate_model(&truth, 20_000, 1.0, 21).unwrap();
    let opts = WvOptions::default();
    let start = [0.9, 0.05, 0.8];
    let fast = Gmwm::parse("AR1()+WN()")
        .unwrap()
        .fit_series(&x, 1.0, &opts, &start)
        .unwrap();
    let bootstrap_fit = || {
        Gmwm::parse("AR1()+WN()")
            .unwrap()
            .with_weighting(Weighting::Bootstrap)
            .with_bootstrap(60, 1)
            .unwrap()
            .fit_series(&x, 1.0, &opts, &start)
            .unwrap()
    };
    let boot = bootstrap_fit();
    assert!(boot.convergence().converged, "{boot}");
    assert_eq!(boot.weighting(), Weighting::Bootstrap);
    assert_eq!(boot.bootstrap_replicates(), Some(60));
    assert_eq!(boot.org_v(), Some(&fast.weights().v[..]));
    assert_ne!(boot.weights().v, fast.weights().v);
    // both estimators are consistent: estimates within a few of the fast fit's sampling spread
    assert!(
        (boot.theta()[0] - fast.theta()[0]).abs() < 0.02,
        "{boot}\n{fast}"
    );
    assert!(
        (boot.theta()[2] / fast.theta()[2] - 1.0).abs() < 0.05,
        "{boot}\n{fast}"
    );
    // the squared fast CI width overstates Var(nu2_hat) by (2 z)^2 ~ 15 at large eta: the
    // bootstrap variances are ~15x smaller (a factor, not an error; only Omega's shape matters)
    let ratio = fast.weights().v[0] / boot.weights().v[0];
    assert!(
        ratio > 5.0 && ratio < 40.0,
        "fast / bootstrap V at level 1: {ratio}"
    );
    // same seed, same answer
    let again = bootstrap_fit();
    assert_eq!(again.theta(), boot.theta());
    assert!(Gmwm::parse("WN()").unwrap().with_bootstrap(1, 1).is_err());
    assert!(Gmwm::parse("WN()").unwrap().with_bootstrap(10, 0).is_err());
}

/// `update` refits another model on the stored WV and original weights, equal to a fresh fit
/// of that model on the same WV with the same settings.
#[test]
fn update_refits_on_the_stored_wv() {
    let truth = Model::parse("AR1(phi=0.99, sigma2=0.01)+WN(sigma2=1)+RW(gamma2=1e-5)").unwrap();
    let x = gmwm::sim::simulate_model(&truth, 30_000, 1.0, 4).unwrap();
    let full = Gmwm::parse("AR1()+WN()+RW()")
        .unwrap()
        .with_draws(3000)
        .fit(&x, 1.0, &WvOptions::default())
        .unwrap();
    let small = Gmwm::parse("AR1()+WN()").unwrap().with_draws(3000);
    let updated = small.update(&full).unwrap();
    let direct = small.fit(&x, 1.0, &WvOptions::default()).unwrap();
    assert_eq!(updated.theta(), direct.theta());
    assert_eq!(updated.objective(), direct.objective());
    assert_eq!(updated.empirical(), full.empirical());
    // dropping RW from the truth cannot fit better
    assert!(updated.objective() >= full.objective());
    // a bare fit_weighted result has no stored WV
    let nu = full.nu_hat().to_vec();
    let bare = small
        .fit_weighted(&nu, full.weights().clone(), 1.0, &[0.99, 0.01, 1.0])
        .unwrap();
    assert!(matches!(
        small.update(&bare).unwrap_err(),
        FitError::Length {
            what: "stored WV",
            ..
        }
    ));
}

/// A WV written as `gmwm wv --json` writes it (or by hand, minimal fields) fits exactly as the
/// WV computed in memory; malformed files are refused naming the series and field.
#[test]
fn wv_json_round_trip_and_refusals() {
    let truth = Model::parse("AR1(phi=0.9, sigma2=0.5)+WN(sigma2=1)").unwrap();
    let x = gmwm::sim::simulate_model(&truth, 8000, 10.0, 9).unwrap();
    let wv = wavelet_variance(&x, 10.0, &WvOptions::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let full = dir.path().join("full.json");
    let doc = serde_json::json!({ "series": [ { "name": "x", "n": wv.n(), "freq_hz": 10.0,
        "tau": wv.tau(), "wv": wv.wv(), "ci_low": wv.ci_low(), "ci_high": wv.ci_high(),
        "n_coefficients": wv.n_coefficients(), "eta": wv.eta() } ] });
    std::fs::write(&full, doc.to_string()).unwrap();
    let read = gmwm::variance::read_wv_json(&full, None).unwrap();
    assert_eq!(read[0].0, "x");
    assert_eq!(read[0].1.wv(), wv.wv());
    assert_eq!(read[0].1.eta(), wv.eta());
    let minimal = dir.path().join("min.json");
    let doc = serde_json::json!({ "freq_hz": 10.0, "series": [ { "name": "x", "n": wv.n(),
        "tau": wv.tau(), "wv": wv.wv(), "ci_low": wv.ci_low(), "ci_high": wv.ci_high() } ] });
    std::fs::write(&minimal, doc.to_string()).unwrap();
    let min = gmwm::variance::read_wv_json(&minimal, None).unwrap();
    // counts and eta3 are recomputed from n exactly as the estimator does
    assert_eq!(min[0].1.n_coefficients(), wv.n_coefficients());
    assert_eq!(min[0].1.eta(), wv.eta());
    let est = Gmwm::parse("AR1()+WN()").unwrap().with_draws(2000);
    let a = est
        .fit_from_wv(&min[0].1, StartInputs::from_wv(&wv))
        .unwrap();
    let b = est.fit_from_wv(&wv, StartInputs::from_wv(&wv)).unwrap();
    assert_eq!(a.theta(), b.theta());
    let bad = |doc: serde_json::Value, needle: &str| {
        let p = dir.path().join("bad.json");
        std::fs::write(&p, doc.to_string()).unwrap();
        let e = gmwm::variance::read_wv_json(&p, None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("bad.json") && e.contains(needle), "{e}");
    };
    bad(serde_json::json!({"series": []}), "empty");
    bad(
        serde_json::json!({"freq_hz": 1.0, "series": [{"name": "a", "n": 100, "tau": [2.0, 4.0],
        "wv": [1.0], "ci_low": [0.5, 0.5], "ci_high": [2.0, 2.0]}]}),
        "\"wv\" has 1 values",
    );
    bad(
        serde_json::json!({"freq_hz": 1.0, "series": [{"name": "a", "n": 100, "tau": [2.0, 8.0],
        "wv": [1.0, 1.0], "ci_low": [0.5, 0.5], "ci_high": [2.0, 2.0]}]}),
        "tau[1] = 8",
    );
    bad(
        serde_json::json!({"series": [{"name": "a", "n": 100, "tau": [2.0],
        "wv": [1.0], "ci_low": [0.5], "ci_high": [2.0]}]}),
        "no sampling rate",
    );
    bad(
        serde_json::json!({"freq_hz": 1.0, "series": [{"name": "a", "n": 10.5, "tau": [2.0],
        "wv": [1.0], "ci_low": [0.5], "ci_high": [2.0]}]}),
        "n = 10.5",
    );
    bad(
        serde_json::json!({"freq_hz": 1.0, "series": [{"name": "a", "n": 100, "tau": [2.0],
        "ci_low": [0.5], "ci_high": [2.0]}]}),
        "missing \"wv\"",
    );
    bad(
        serde_json::json!({"freq_hz": 1.0, "series": [{"name": "a", "n": 4,
        "tau": [2.0, 4.0, 8.0], "wv": [1.0, 1.0, 1.0], "ci_low": [0.5, 0.5, 0.5],
        "ci_high": [2.0, 2.0, 2.0]}]}),
        "does not fit in n = 4",
    );
    let _ = data_dir();
}

/// docs/methods.md §5.7 refusals, each a clear error; a power-of-two length works (its last,
/// coefficient-less level is not produced by the default J, §1.6).
#[test]
fn section_5_7_refusals_and_power_of_two() {
    let x = gmwm::sim::simulate_model(
        &Model::parse("AR1(phi=0.9, sigma2=1)+WN(sigma2=1)").unwrap(),
        1 << 12,
        1.0,
        2,
    )
    .unwrap();
    let opts = WvOptions::default();
    // repeated WN, GM mixed with AR1: refused when the model is built
    for bad in [
        "WN()+WN()",
        "GM()+AR1()",
        "RW()+RW()",
        "QN()+QN()",
        "DR()+DR()",
    ] {
        let e = Model::parse(bad).unwrap_err().to_string();
        assert!(!e.is_empty(), "{bad}");
    }
    // too many parameters for the levels
    let e = Gmwm::parse("5*AR1()+WN()+RW()")
        .unwrap()
        .fit(&x[..64], 1.0, &opts)
        .unwrap_err();
    assert!(matches!(e, FitError::TooFewLevels { .. }), "{e}");
    assert!(e.to_string().contains("parameters"), "{e}");
    // robust: parameters + 1 <= J
    let e = Gmwm::parse("2*AR1()+WN()")
        .unwrap()
        .fit(
            &x[..64],
            1.0,
            &WvOptions {
                robust: Some(RobustOptions::default()),
                ..opts
            },
        )
        .unwrap_err();
    assert!(
        matches!(
            e,
            FitError::TooFewLevels {
                params: 6,
                levels: 5
            }
        ),
        "{e}"
    );
    // eff > 0.99
    assert!(RobustOptions::new(0.995, RobustConvention::Exact).is_err());
    // too short, non-finite
    let e = Gmwm::parse("WN()")
        .unwrap()
        .fit(&x[..1], 1.0, &opts)
        .unwrap_err();
    assert!(e.to_string().contains("sample"), "{e}");
    let mut y = x.clone();
    y[100] = f64::NAN;
    let e = Gmwm::parse("WN()")
        .unwrap()
        .fit(&y, 1.0, &opts)
        .unwrap_err();
    assert!(e.to_string().contains("100"), "{e}");
    // power of two: 4096 samples, J = 11 (not 12), fits and converges
    let fit = Gmwm::parse("AR1()+WN()")
        .unwrap()
        .with_draws(2000)
        .fit(&x, 1.0, &opts)
        .unwrap();
    assert_eq!(fit.nu_hat().len(), 11);
    assert!(fit.convergence().converged, "{fit}");
}
