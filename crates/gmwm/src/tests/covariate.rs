//! Issue 31 item 2 "must show": parameters as functions of a covariate (docs/methods.md
//! §5.13) against known truths, and one clear error per input that cannot carry a dependence.
//!
//! Truth of the studies, a temperature-dependent sensor at 100 Hz over 0–40 °C:
//! `WN(sigma2(T)) + GM(beta, sigma2_gm(T))` with `log sigma2(T)` and `log sigma2_gm(T)` affine
//! in `T` ([`truth_at`]), `beta` constant; four recordings at 5, 15, 25 and 35 °C. Replicate
//! `i` of a study with master seed `s` simulates recording `k` with
//! `replicate_seed(replicate_seed(s, i), k)`. The CI-run tests are sized to seconds in
//! release; the `#[ignore]` study gives the figures of docs/methods.md §5.13.

use gmwm::fit::{Dependence, FitError, FitRecording, Gmwm};
use gmwm::model::Model;
use gmwm::sim::{replicate_seed, simulate_model};
use gmwm::{Weighting, WvOptions};
use rayon::prelude::*;

const FREQ: f64 = 100.0;
const TEMPS: [f64; 4] = [5.0, 15.0, 25.0, 35.0];
/// `log sigma2_wn(T) = ln(1e-4) + WN_SLOPE (T - 20)`: x1.57 from 20 to 35 °C.
const WN_SLOPE: f64 = 0.03;
/// `log sigma2_gm(T) = ln(1e-5) + GM_SLOPE (T - 20)`.
const GM_SLOPE: f64 = -0.02;
const BETA: f64 = 0.5;

fn truth_at(t: f64, wn_slope: f64, gm_slope: f64) -> Model {
    let s2 = 1e-4 * (wn_slope * (t - 20.0)).exp();
    let g2 = 1e-5 * (gm_slope * (t - 20.0)).exp();
    Model::parse(&format!("WN(sigma2={s2})+GM(beta={BETA}, sigma2_gm={g2})")).unwrap()
}

fn recordings(n: usize, temps: &[f64], slopes: (f64, f64), seed: u64) -> Vec<FitRecording> {
    temps
        .iter()
        .enumerate()
        .map(|(k, &t)| {
            let truth = truth_at(t, slopes.0, slopes.1);
            let x = simulate_model(&truth, n, FREQ, replicate_seed(seed, k as u64)).unwrap();
            FitRecording::from_series(&x, FREQ, &WvOptions::default(), Weighting::Fast).unwrap()
        })
        .collect()
}

/// The estimator: the separate fits start from the values at 20 °C without the slopes (a user
/// giving a datasheet's values), stage 2 only.
fn estimator() -> Gmwm {
    let m = truth_at(20.0, 0.0, 0.0);
    Gmwm::parse(&m.to_string()).unwrap()
}

const AFFINE: [Dependence; 3] = [Dependence::Affine, Dependence::Constant, Dependence::Affine];

#[test]
fn every_parameter_constant_is_the_pooled_fit() {
    let recs = recordings(1 << 14, &TEMPS, (WN_SLOPE, GM_SLOPE), 3);
    let gmwm = estimator();
    let pooled = gmwm.fit_pooled(&recs).unwrap();
    let cov = gmwm
        .fit_covariate(&recs, &TEMPS, &[Dependence::Constant; 3])
        .unwrap();
    assert!(cov.convergence().converged);
    let theta = cov.theta_at(0.0).unwrap();
    for (a, b) in theta.iter().zip(pooled.theta()) {
        // two minimisers of one objective from different starts: the optimiser's tolerance
        assert!((a / b - 1.0).abs() < 1e-6, "{a} vs pooled {b}");
    }
    assert!((cov.objective() / pooled.objective() - 1.0).abs() < 1e-8);
    // a constant is the same at every temperature
    assert_eq!(cov.theta_at(-40.0).unwrap(), cov.theta_at(85.0).unwrap());
}

#[test]
fn a_log_affine_sensor_is_recovered_with_its_bands() {
    let recs = recordings(1 << 17, &TEMPS, (WN_SLOPE, GM_SLOPE), 7);
    let fit = estimator().fit_covariate(&recs, &TEMPS, &AFFINE).unwrap();
    assert!(fit.convergence().converged && fit.reweighted());
    assert_eq!(fit.centre(), 20.0);
    let inf = fit.inference(0.05, 1).unwrap();
    let truth = [
        (1e-4f64.ln(), 0),
        (WN_SLOPE, 1),
        (BETA.ln(), 0),
        (1e-5f64.ln(), 0),
        (GM_SLOPE, 1),
    ];
    assert_eq!(inf.coefficients.len(), truth.len());
    for (c, (t, power)) in inf.coefficients.iter().zip(truth) {
        assert_eq!(c.power, power);
        // 4.5 standard errors: a failure is a bias, not bad luck (p ~ 1e-5 per coefficient)
        assert!(
            (c.estimate - t).abs() < 4.5 * c.se,
            "{} power {}: {} vs truth {t} (se {})",
            c.parameter,
            c.power,
            c.estimate,
            c.se
        );
    }
    let test = inf.no_dependence.as_ref().unwrap();
    assert_eq!(test.df, 2);
    assert!(test.p_value < 1e-6, "{test:?}");
    // per-temperature white noise within 5% of the truth, and inside its band
    for t in [5.0, 20.0, 35.0] {
        let band = inf.band(&fit, t).unwrap();
        let s2 = truth_at(t, WN_SLOPE, GM_SLOPE).values()[0].unwrap();
        let wn = &band[0];
        assert!(
            (wn.estimate / s2 - 1.0).abs() < 0.05,
            "{t} °C: {} vs {s2}",
            wn.estimate
        );
        assert!(wn.ci_low.unwrap() < s2 && s2 < wn.ci_high.unwrap());
        // N = sqrt(sigma2 / f) within 2.5% is the same statement on N
        assert!(((wn.estimate / s2).sqrt() - 1.0).abs() < 0.025);
    }
}

#[test]
fn a_constant_covariate_or_a_bad_value_is_one_clear_error() {
    let recs = recordings(1 << 12, &TEMPS, (0.0, 0.0), 1);
    let gmwm = estimator();
    let same = [20.0; 4];
    let e = gmwm.fit_covariate(&recs, &same, &AFFINE).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, FitError::Input(_)), "{e:?}");
    assert!(
        msg.contains("1 distinct value") && msg.contains("WN[0].sigma2"),
        "{msg}"
    );
    assert!(msg.contains("does not vary"), "{msg}");
    let e = gmwm
        .fit_covariate(&recs, &[5.0, f64::NAN, 25.0, 35.0], &AFFINE)
        .unwrap_err();
    assert!(e.to_string().contains("NaN"), "{e}");
    let e = gmwm.fit_covariate(&recs, &TEMPS[..3], &AFFINE).unwrap_err();
    assert!(e.to_string().contains("covariate values"), "{e}");
    let e = gmwm.fit_covariate(&recs, &TEMPS, &AFFINE[..2]).unwrap_err();
    assert!(e.to_string().contains("dependences"), "{e}");
    // a quadratic needs three distinct values
    let e = gmwm
        .fit_covariate(
            &recs,
            &[5.0, 5.0, 35.0, 35.0],
            &[
                Dependence::Quadratic,
                Dependence::Constant,
                Dependence::Constant,
            ],
        )
        .unwrap_err();
    assert!(e.to_string().contains("at least 3 distinct"), "{e}");
    assert!(e.to_string().contains("lower degree"), "{e}");
    assert_eq!("Affine".parse::<Dependence>().unwrap(), Dependence::Affine);
    assert!("cubic".parse::<Dependence>().is_err());
}

/// One recording whose temperature ramps from 0 to 40 °C, the sensor following it sample by
/// sample: white noise `sigma(T_t) z_t`, a GM whose innovation variance is
/// `sigma2_gm(T_t) (1 - phi^2)`.
fn ramp(n: usize, seed: u64) -> (Vec<f64>, Vec<f64>) {
    use rand::SeedableRng;
    use rand_distr::Distribution;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let phi = (-BETA / FREQ).exp();
    let temps: Vec<f64> = (0..n).map(|i| 40.0 * i as f64 / n as f64).collect();
    let z0: f64 = rand_distr::StandardNormal.sample(&mut rng);
    let mut gm = 1e-5f64.sqrt() * z0;
    let x = temps
        .iter()
        .map(|&t| {
            let (s2, g2) = {
                let m = truth_at(t, WN_SLOPE, GM_SLOPE).values();
                (m[0].unwrap(), m[2].unwrap())
            };
            let z: f64 = rand_distr::StandardNormal.sample(&mut rng);
            let e: f64 = rand_distr::StandardNormal.sample(&mut rng);
            gm = phi * gm + (g2 * (1.0 - phi * phi)).sqrt() * e;
            s2.sqrt() * z + gm
        })
        .collect();
    (x, temps)
}

#[test]
fn one_recording_on_a_temperature_ramp_cut_into_windows() {
    let (x, temps) = ramp(1 << 19, 17);
    let (recs, levels) =
        gmwm::fit::covariate_windows(&x, &temps, FREQ, 8, &WvOptions::default(), Weighting::Fast)
            .unwrap();
    assert_eq!(recs.len(), 8);
    // window k covers 5k to 5(k + 1) °C
    for (k, l) in levels.iter().enumerate() {
        assert!((l - (5.0 * k as f64 + 2.5)).abs() < 1e-3, "window {k}: {l}");
        assert_eq!(recs[k].n(), 1 << 16);
    }
    let fit = estimator().fit_covariate(&recs, &levels, &AFFINE).unwrap();
    let inf = fit.inference(0.05, 1).unwrap();
    for (c, t) in [
        (&inf.coefficients[1], WN_SLOPE),
        (&inf.coefficients[4], GM_SLOPE),
    ] {
        assert!(
            (c.estimate - t).abs() < 4.5 * c.se,
            "{}: {} vs {t} (se {})",
            c.parameter,
            c.estimate,
            c.se
        );
    }
    for t in [5.0, 35.0] {
        let wn = &inf.band(&fit, t).unwrap()[0];
        let s2 = truth_at(t, WN_SLOPE, GM_SLOPE).values()[0].unwrap();
        assert!(
            (wn.estimate / s2 - 1.0).abs() < 0.05,
            "{t} °C: {} vs {s2}",
            wn.estimate
        );
    }
    // bad windows: one line each
    let e = gmwm::fit::covariate_windows(
        &x,
        &temps[1..],
        FREQ,
        8,
        &WvOptions::default(),
        Weighting::Fast,
    )
    .unwrap_err();
    assert!(e.to_string().contains("covariate samples"), "{e}");
    let e = gmwm::fit::covariate_windows(
        &x[..10],
        &temps[..10],
        FREQ,
        6,
        &WvOptions::default(),
        Weighting::Fast,
    )
    .unwrap_err();
    assert!(e.to_string().contains("at most 5 for 10 samples"), "{e}");
    let mut bad = temps.clone();
    bad[1 << 17] = f64::NAN;
    let e = gmwm::fit::covariate_windows(&x, &bad, FREQ, 8, &WvOptions::default(), Weighting::Fast)
        .unwrap_err();
    assert!(e.to_string().contains("window 3"), "{e}");
}

/// One replicate: (slope estimates, their 95% interval covers the truth, no-dependence p).
fn replicate(n: usize, slopes: (f64, f64), seed: u64) -> ([f64; 2], [bool; 2], f64) {
    let recs = recordings(n, &TEMPS, slopes, seed);
    let fit = estimator().fit_covariate(&recs, &TEMPS, &AFFINE).unwrap();
    let inf = fit.inference(0.05, seed).unwrap();
    let wn = &inf.coefficients[1];
    let gm = &inf.coefficients[4];
    let cover = |c: &gmwm::CoefficientInference, t: f64| c.ci_low <= t && t <= c.ci_high;
    (
        [wn.estimate, gm.estimate],
        [cover(wn, slopes.0), cover(gm, slopes.1)],
        inf.no_dependence.unwrap().p_value,
    )
}

/// Monte Carlo sized for CI (release, seconds): the slopes' intervals cover, the test of no
/// dependence holds its size when nothing depends on temperature and rejects when it does.
#[test]
fn slopes_cover_and_the_no_dependence_test_holds_its_size() {
    const R: u64 = 60;
    let n = 1 << 14;
    let with: Vec<_> = (0..R)
        .into_par_iter()
        .map(|i| replicate(n, (WN_SLOPE, GM_SLOPE), replicate_seed(101, i)))
        .collect();
    let without: Vec<_> = (0..R)
        .into_par_iter()
        .map(|i| replicate(n, (0.0, 0.0), replicate_seed(202, i)))
        .collect();
    for s in 0..2 {
        let covered = with.iter().filter(|r| r.1[s]).count();
        // 95% nominal: below 49 of 60 is p < 0.002 under binomial(60, 0.95)
        assert!(covered >= 49, "slope {s}: {covered}/{R} covered");
    }
    let power = with.iter().filter(|r| r.2 < 0.05).count();
    let size = without.iter().filter(|r| r.2 < 0.05).count();
    // size 5%: more than 9 of 60 rejections is p < 0.01 under binomial(60, 0.05)
    assert!(size <= 9, "size: {size}/{R} rejected without a dependence");
    assert!(
        power >= 54,
        "power: {power}/{R} rejected with the dependence"
    );
}

/// The study of docs/methods.md §5.13 (200 replicates at each of two lengths).
#[test]
#[ignore = "study: minutes in release; figures in docs/methods.md §5.13"]
fn covariate_study() {
    for n in [1usize << 14, 1 << 16] {
        for (label, slopes, seed) in [
            ("dependence", (WN_SLOPE, GM_SLOPE), 303),
            ("none", (0.0, 0.0), 404),
        ] {
            let r: Vec<_> = (0..200u64)
                .into_par_iter()
                .map(|i| replicate(n, slopes, replicate_seed(seed, i)))
                .collect();
            let k = r.len() as f64;
            let mean = |s: usize| r.iter().map(|x| x.0[s]).sum::<f64>() / k;
            let rmse =
                |s: usize, t: f64| (r.iter().map(|x| (x.0[s] - t).powi(2)).sum::<f64>() / k).sqrt();
            let cov = |s: usize| r.iter().filter(|x| x.1[s]).count() as f64 / k;
            let rej = r.iter().filter(|x| x.2 < 0.05).count() as f64 / k;
            println!(
                "N={n} {label}: WN slope mean {:.5} rmse {:.5} cover {:.3}; GM slope mean {:.5} \
                 rmse {:.5} cover {:.3}; rejected at 5%: {rej:.3}",
                mean(0),
                rmse(0, slopes.0),
                cov(0),
                mean(1),
                rmse(1, slopes.1),
                cov(1)
            );
        }
    }
}

/// docs/methods.md §5.14: a calibration against the temperature of one drifting recording
/// (two gyroscope axes on the 0–40 °C ramp of [`ramp`]) gives N within 5% of the truth along
/// the range, with bands that contain it; `--at` and `--over` put the curve's values into the
/// report; a constant covariate is one clear error.
#[test]
fn calibration_against_temperature_gives_n_curves_and_exports() {
    use gmwm::imu::{Column, Sensor, SensorInfo};
    let n = 1 << 18;
    let (x0, temps) = ramp(n, 23);
    let (x1, _) = ramp(n, 24);
    let info = |axis: &str| SensorInfo {
        sensor: Sensor::Gyroscope,
        axis: axis.into(),
        unit: Some("rad/s".into()),
    };
    let imu = gmwm::Imu::new(
        vec![
            Column {
                name: "gyro_x".into(),
                values: x0,
            },
            Column {
                name: "gyro_y".into(),
                values: x1,
            },
        ],
        vec![info("X"), info("Y")],
        FREQ,
    )
    .unwrap();
    let options = gmwm::CalibrationOptions {
        full_model: "AR1()+WN()+RW()".parse().unwrap(),
        robust_check: None,
        ..gmwm::CalibrationOptions::default()
    };
    let calibration = gmwm::Calibration::new(options);
    let report = calibration.run(&imu).unwrap();
    let mut opts = gmwm::CovariateCalibrationOptions::new("temperature");
    opts.unit = Some("degC".into());
    opts.at = vec![5.0];
    let curves = calibration
        .covariate_curves(&imu, &report, &temps, &opts)
        .unwrap();
    assert_eq!(curves.axes.len(), 2);
    assert!((curves.range[0] - 2.5).abs() < 1e-3 && (curves.range[1] - 37.5).abs() < 1e-3);
    let n_truth = |t: f64| (truth_at(t, WN_SLOPE, GM_SLOPE).values()[0].unwrap() / FREQ).sqrt();
    for a in &curves.axes {
        assert!(a.depends[0], "{}: {:?}", a.column, a.notes);
        assert!(a.points.iter().any(|p| p.covariate == 5.0));
        for t in [5.0, 20.0, 35.0] {
            let p = a.at(t).unwrap();
            let nd = p.noise_density.unwrap();
            let truth = n_truth(t);
            assert!(
                (nd.value / truth - 1.0).abs() < 0.05,
                "{} at {t}: N {} vs {truth}",
                a.column,
                nd.value
            );
            let (lo, hi) = (nd.low.unwrap(), nd.high.unwrap());
            assert!(lo < nd.value && nd.value < hi, "{lo} {} {hi}", nd.value);
            // B only where the model's Allan deviation reaches a floor inside the scales
            // (the unit tests of calib::covariate); when given, positive with its band
            if let Some(b) = p.bias_instability {
                assert!(b.value > 0.0 && b.value.is_finite());
            }
        }
    }
    // --at 5: the report's N is the curve's at 5 °C, said so
    let mut at5 = report.clone();
    at5.at_covariate(&curves, 5.0).unwrap();
    for (axis, a) in at5.axes.iter().zip(&curves.axes) {
        let nd = axis.noise_density.as_ref().unwrap();
        let want = a.at(5.0).unwrap().noise_density.unwrap();
        assert_eq!(nd.value, want.value);
        assert_eq!((nd.ci_low, nd.ci_high), (want.low, want.high));
        assert!(
            nd.source.starts_with("at temperature 5 degC"),
            "{}",
            nd.source
        );
        assert!(axis
            .notes
            .iter()
            .any(|n| n.contains("N, B, K at temperature 5 degC")));
    }
    // --over 0:40: N grows with T here, so its worst case is at 40 °C (extrapolated, said so)
    let mut worst = report.clone();
    worst.worst_over(&curves, 0.0, 40.0).unwrap();
    for (axis, a) in worst.axes.iter().zip(&curves.axes) {
        let nd = axis.noise_density.as_ref().unwrap();
        assert_eq!(nd.value, a.at(40.0).unwrap().noise_density.unwrap().value);
        assert!(nd.source.contains("at 40 degC"), "{}", nd.source);
        assert!(axis.notes.iter().any(|n| n.contains("extrapolated")));
    }
    assert!(worst.worst_over(&curves, 40.0, 0.0).is_err());
    // a constant covariate cannot explain a dependence: one line naming it
    let flat = vec![21.0; n];
    let e = calibration
        .covariate_curves(&imu, &report, &flat, &opts)
        .unwrap_err()
        .to_string();
    assert!(!e.contains('\n'), "{e}");
    assert!(e.contains("cannot explain a dependence"), "{e}");
}

/// docs/methods.md §5.14's figures: over replicates of one gyroscope axis on the 0–40 °C ramp
/// of [`ramp`] (2^17 samples at 100 Hz, 8 windows), the relative error of N at 5, 20 and
/// 35 °C and how often its 95% band covers the truth. (This truth, WN + one GM, has no Allan
/// floor inside the scales: no B to read off.)
/// `cargo test --release --workspace --lib covariate_calibration_study -- --ignored --nocapture`
#[test]
#[ignore]
fn covariate_calibration_study() {
    use gmwm::imu::{Column, Sensor, SensorInfo};
    const REPLICATES: u64 = 100;
    let n = 1 << 17;
    let temps = [5.0, 20.0, 35.0];
    let rows: Vec<Option<[(f64, bool); 3]>> = (0..REPLICATES)
        .into_par_iter()
        .map(|i| {
            let (x, covariate) = ramp(n, 1000 + i);
            let imu = gmwm::Imu::new(
                vec![Column {
                    name: "gyro_x".into(),
                    values: x,
                }],
                vec![SensorInfo {
                    sensor: Sensor::Gyroscope,
                    axis: "X".into(),
                    unit: Some("rad/s".into()),
                }],
                FREQ,
            )
            .unwrap();
            let options = gmwm::CalibrationOptions {
                full_model: "AR1()+WN()".parse().unwrap(),
                robust_check: None,
                seed: i,
                ..gmwm::CalibrationOptions::default()
            };
            let calibration = gmwm::Calibration::new(options);
            let report = calibration.run(&imu).ok()?;
            let curves = calibration
                .covariate_curves(
                    &imu,
                    &report,
                    &covariate,
                    &gmwm::CovariateCalibrationOptions::new("temperature"),
                )
                .ok()?;
            let a = &curves.axes[0];
            let mut out = [(0.0, false); 3];
            for (k, &t) in temps.iter().enumerate() {
                let truth = (truth_at(t, WN_SLOPE, GM_SLOPE).values()[0].unwrap() / FREQ).sqrt();
                let v = a.at(t).ok()?.noise_density?;
                let covered =
                    v.low.is_some_and(|l| l <= truth) && v.high.is_some_and(|h| truth <= h);
                out[k] = (v.value / truth - 1.0, covered);
            }
            Some(out)
        })
        .collect();
    let ok: Vec<_> = rows.iter().flatten().collect();
    println!("{} of {REPLICATES} replicates calibrated", ok.len());
    println!("| T (°C) | N: mean rel. error | RMSE rel. | max abs rel. | 95% band covers |");
    println!("|---:|---:|---:|---:|---:|");
    for (k, t) in temps.iter().enumerate() {
        let e: Vec<f64> = ok.iter().map(|r| r[k].0).collect();
        let mean = e.iter().sum::<f64>() / e.len() as f64;
        let rmse = (e.iter().map(|v| v * v).sum::<f64>() / e.len() as f64).sqrt();
        let max = e.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let cover = ok.iter().filter(|r| r[k].1).count() as f64 / ok.len() as f64;
        println!("| {t} | {mean:+.4} | {rmse:.4} | {max:.4} | {cover:.3} |");
    }
    assert!(ok.len() as u64 >= REPLICATES * 9 / 10);
}
