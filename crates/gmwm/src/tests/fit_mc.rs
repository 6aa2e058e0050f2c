//! Issue 4 "must show": seeded Monte Carlo recovery of known truths (sized for CI, able to
//! fail) and the robust fit's resistance to outliers.

use gmwm::fit::Gmwm;
use gmwm::model::Model;
use gmwm::sim::{replicate_seed, simulate_model, DemoSensor};
use gmwm::{RobustOptions, WvOptions};
use rayon::prelude::*;

/// Per-parameter mean and standard error of the mean over replicates.
fn mean_se(rows: &[Vec<f64>], k: usize) -> (f64, f64) {
    let r = rows.len() as f64;
    let m = rows.iter().map(|t| t[k]).sum::<f64>() / r;
    let v = rows.iter().map(|t| (t[k] - m).powi(2)).sum::<f64>() / (r - 1.0);
    (m, (v / r).sqrt())
}

/// Fits `R` replicates in guess mode and returns the estimates (every fit must converge).
fn replicate_fits(
    truth: &Model,
    fit_model: &str,
    n: usize,
    freq: f64,
    r: usize,
    seed: u64,
    draws: usize,
) -> Vec<Vec<f64>> {
    (0..r as u64)
        .into_par_iter()
        .map(|i| {
            let x = simulate_model(truth, n, freq, replicate_seed(seed, i)).unwrap();
            let fit = Gmwm::parse(fit_model)
                .unwrap()
                .with_draws(draws)
                .fit(&x, freq, &WvOptions::default())
                .unwrap_or_else(|e| panic!("replicate {i}: {e}"));
            assert!(fit.convergence().converged, "replicate {i}: {fit}");
            fit.theta().to_vec()
        })
        .collect()
}

/// Bias check: |mean - truth| <= 4 SE(mean) + `allow` * truth. The 4 SE is the replicate
/// noise (a 6e-5 two-sided false alarm per parameter under normality); `allow` is the
/// finite-sample bias GMWM may have in a nonlinear parameter at this N, stated per parameter.
fn assert_recovered(rows: &[Vec<f64>], truth: &[f64], names: &[&str], allow: &[f64]) {
    for k in 0..truth.len() {
        let (m, se) = mean_se(rows, k);
        let tol = 4.0 * se + allow[k] * truth[k].abs();
        assert!(
            (m - truth[k]).abs() <= tol,
            "{}: mean {m:e} vs truth {:e} (SE {se:e}, tol {tol:e})",
            names[k],
            truth[k]
        );
    }
}

/// AR1 + WN + RW (the R reference truth of `sim_ar1_wn_rw.json`) at N = 1e5, 24 replicates.
#[test]
fn recovers_ar1_wn_rw() {
    let truth = Model::parse("AR1(phi=0.99, sigma2=0.01)+WN(sigma2=1)+RW(gamma2=1e-4)").unwrap();
    let rows = replicate_fits(&truth, "AR1()+WN()+RW()", 100_000, 1.0, 24, 4100, 5000);
    assert_recovered(
        &rows,
        &[0.99, 0.01, 1.0, 1e-4],
        &["phi", "sigma2", "WN", "RW"],
        // phi: estimates near 1 are skewed; 0.2% of phi is a quarter of 1 - phi
        &[0.002, 0.1, 0.01, 0.1],
    );
}

/// The §5.10 NavChip truth (3 GM + WN + QN + RW at 250 Hz) at N = 2^22 (4.7 hours, the paper's
/// 3.1e6 order; at 2^20 the 160 s GM and the RW trade places in some replicates), 8
/// replicates: every fit converges; the parameters the WV identifies at this length (WN, QN,
/// the fast and middle GMs) are recovered; the slowest GM and the RW, whose signature lies in
/// the last few levels with eta < 10, are only checked for order of magnitude.
#[test]
fn recovers_the_navchip_model() {
    let sensor = DemoSensor::default();
    let truth: Vec<f64> = sensor.model.values().into_iter().flatten().collect();
    let truth = gmwm::fit::Parametrisation::canonical_order(&sensor.model, &truth).unwrap();
    let rows = replicate_fits(
        &sensor.model,
        "3*GM()+WN()+QN()+RW()",
        1 << 22,
        250.0,
        8,
        5100,
        20_000,
    );
    // canonical order: GM(6.28e-3), GM(0.25), GM(8.48), WN, QN, RW
    let identified: Vec<Vec<f64>> = rows.iter().map(|t| t[2..8].to_vec()).collect();
    assert_recovered(
        &identified,
        &truth[2..8],
        &[
            "GM[1].beta",
            "GM[1].sigma2_gm",
            "GM[2].beta",
            "GM[2].sigma2_gm",
            "WN",
            "QN",
        ],
        &[0.1, 0.1, 0.1, 0.1, 0.01, 0.01],
    );
    // slow GM: within a factor 5 in every replicate
    for t in &rows {
        assert!(
            t[0] / truth[0] > 0.2 && t[0] / truth[0] < 5.0,
            "slow GM beta {t:?}"
        );
        assert!(
            t[1] / truth[1] > 0.2 && t[1] / truth[1] < 5.0,
            "slow GM sigma2 {t:?}"
        );
    }
}

/// Robust GMWM (eff 0.6) on AR1 + WN data with 1% gross outliers (+-20, eight times the
/// series' SD) stays near the truth; the classical fit of the same data is far off. (Isolated
/// spikes are outliers only at the first levels: a filter of width 2^j dilutes them into a
/// white-noise-like excess `eps A^2 / tau` at coarse scales, where no WV estimator can tell
/// them from signal; the truth is chosen so that this excess is 8% of the AR1 there.)
#[test]
fn robust_fit_resists_outliers() {
    let truth = Model::parse("AR1(phi=0.9, sigma2=0.5)+WN(sigma2=1)").unwrap();
    let robust = WvOptions {
        robust: Some(RobustOptions::default()),
        ..WvOptions::default()
    };
    let results: Vec<(Vec<f64>, Vec<f64>)> = (0..8u64)
        .into_par_iter()
        .map(|i| {
            let mut x = simulate_model(&truth, 1 << 15, 1.0, replicate_seed(6100, i)).unwrap();
            // 1% of the samples replaced by spikes of +-20 (the series' SD is ~2.5)
            let mut s = replicate_seed(6200, i);
            for k in 0..x.len() {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                if (s >> 33) % 100 == 0 {
                    x[k] = if (s >> 20) & 1 == 0 { 20.0 } else { -20.0 };
                }
            }
            let est = Gmwm::parse("AR1()+WN()").unwrap().with_draws(5000);
            let r = est.fit(&x, 1.0, &robust).unwrap();
            let c = est.fit(&x, 1.0, &WvOptions::default()).unwrap();
            assert!(r.convergence().converged, "{r}");
            (r.theta().to_vec(), c.theta().to_vec())
        })
        .collect();
    for (r, c) in &results {
        // robust: WN within 25%, phi within 0.05 (eff 0.6 costs variance, not bias)
        assert!((r[2] - 1.0).abs() < 0.25, "robust WN {r:?}");
        assert!((r[0] - 0.9).abs() < 0.05, "robust phi {r:?}");
        // classical: the spikes (variance 0.01 * 400 = 4) swamp the WN of 1
        assert!(c[2] > 3.0, "classical WN {c:?}");
    }
}

/// The vibration truth of the SIN recovery tests: a 7.3 Hz sinusoid of amplitude 1 (power 0.5)
/// over white noise of variance 1 and a slow random walk, at 100 Hz.
const SIN_TRUTH: &str = "SIN(amplitude=1, omega=0.073)+WN(sigma2=1)+RW(gamma2=1e-6)";
/// The SIN recovery's sampling rate, Hz.
const SIN_FREQ_HZ: f64 = 100.0;

/// Fits `SIN()+WN()+RW()` to `r` replicates of [`SIN_TRUTH`] at N = 2^18 and returns per
/// replicate `(frequency in Hz, amplitude, WN sigma2, RW gamma2)` from the fit's canonical
/// physical read-off and its parameters.
fn sin_replicates(r: usize, seed: u64) -> Vec<Vec<f64>> {
    vibration_replicates(SIN_TRUTH, "SIN()+WN()+RW()", r, seed, |fit| {
        let canonical = fit.canonical().unwrap();
        let kind = gmwm::model::ProcessKind::Sin;
        let t = fit.theta();
        vec![
            canonical.physical(kind, "frequency").unwrap(),
            canonical.physical(kind, "amplitude").unwrap(),
            t[2],
            t[3],
        ]
    })
}

/// Fits `model` to `r` replicates of `truth` at N = 2^18 and [`SIN_FREQ_HZ`] (every fit must
/// converge) and returns `read` of each fit.
fn vibration_replicates(
    truth: &str,
    model: &str,
    r: usize,
    seed: u64,
    read: impl Fn(&gmwm::GmwmFit) -> Vec<f64> + Sync,
) -> Vec<Vec<f64>> {
    let truth = Model::parse(truth).unwrap();
    (0..r as u64)
        .into_par_iter()
        .map(|i| {
            let x = simulate_model(&truth, 1 << 18, SIN_FREQ_HZ, replicate_seed(seed, i)).unwrap();
            let fit = Gmwm::parse(model)
                .unwrap()
                .fit(&x, SIN_FREQ_HZ, &WvOptions::default())
                .unwrap_or_else(|e| panic!("replicate {i}: {e}"));
            assert!(fit.convergence().converged, "replicate {i}: {fit}");
            read(&fit)
        })
        .collect()
}

/// Relative errors of the replicate means against `[7.3 Hz, 1, 1, 1e-6]`, with their SEs.
fn sin_report(rows: &[Vec<f64>]) -> Vec<(f64, f64)> {
    let truth = [0.073 * SIN_FREQ_HZ, 1.0, 1.0, 1e-6];
    (0..4)
        .map(|k| {
            let (m, se) = mean_se(rows, k);
            ((m - truth[k]) / truth[k], se / truth[k])
        })
        .collect()
}

/// Vibration recovery (Voirol et al., arXiv 2303.18167): `SIN()+WN()+RW()` fitted to 4
/// replicates of [`SIN_TRUTH`] (2^18 samples at 100 Hz, 43 minutes) recovers, on the replicate
/// mean, the frequency within 2%, the amplitude within 15% and the WN variance within 3%, and
/// every replicate's frequency within 5% (no replicate locks onto another hump).
#[test]
fn recovers_a_sinusoid_over_wn_and_rw() {
    let rows = sin_replicates(4, 7300);
    for (i, r) in rows.iter().enumerate() {
        assert!(
            (r[0] / 7.3 - 1.0).abs() < 0.05,
            "replicate {i}: frequency {} Hz",
            r[0]
        );
    }
    let rel = sin_report(&rows);
    for (k, (name, allow)) in [("frequency", 0.02), ("amplitude", 0.15), ("WN", 0.03)]
        .into_iter()
        .enumerate()
    {
        assert!(
            rel[k].0.abs() <= allow,
            "{name}: mean relative error {:e} (SE {:e}), allowed {allow}",
            rel[k].0,
            rel[k].1
        );
    }
}

/// The larger study behind [`recovers_a_sinusoid_over_wn_and_rw`]: 32 replicates, relative bias
/// and SE of each parameter printed.
#[test]
#[ignore = "a 32-replicate study that prints figures; run with --ignored --nocapture"]
fn sin_recovery_study() {
    let rows = sin_replicates(32, 7301);
    for (k, name) in ["frequency", "amplitude", "WN sigma2", "RW gamma2"]
        .iter()
        .enumerate()
    {
        let (bias, se) = sin_report(&rows)[k];
        let worst = rows
            .iter()
            .map(|r| (r[k] / [7.3, 1.0, 1.0, 1e-6][k] - 1.0).abs())
            .fold(0.0, f64::max);
        println!("{name}: relative bias {bias:+.4} (SE {se:.4}), worst replicate {worst:.4}");
    }
}

/// Two vibration lines (issue 28: one `SIN()` per line): 0.55 Hz of amplitude 0.4 and 7.3 Hz of
/// amplitude 1 over [`SIN_TRUTH`]'s white noise and random walk, at 100 Hz.
const TWO_LINES_TRUTH: &str =
    "SIN(amplitude=1, omega=0.073)+SIN(amplitude=0.4, omega=0.0055)+WN(sigma2=1)+RW(gamma2=1e-6)";

/// Fits `2*SIN()+WN()+RW()` to `r` replicates of [`TWO_LINES_TRUTH`] at N = 2^18; per replicate
/// the canonical model's `(frequency, amplitude)` of each line in its order, then WN sigma2.
fn two_line_replicates(r: usize, seed: u64) -> Vec<Vec<f64>> {
    vibration_replicates(TWO_LINES_TRUTH, "2*SIN()+WN()+RW()", r, seed, |fit| {
        let canonical = fit.canonical().unwrap();
        let mut row: Vec<f64> = canonical
            .terms
            .iter()
            .filter(|t| t.kind == gmwm::model::ProcessKind::Sin)
            .flat_map(|t| {
                ["frequency", "amplitude"]
                    .map(|name| t.physical.iter().find(|p| p.name == name).unwrap().value)
            })
            .collect();
        assert_eq!(row.len(), 4, "{canonical}");
        let n = canonical.physical(gmwm::model::ProcessKind::Wn, "white_noise_density");
        row.push(n.unwrap().powi(2) * SIN_FREQ_HZ);
        row
    })
}

/// The truth of [`two_line_replicates`]' rows: the canonical model lists the lines by
/// frequency.
const TWO_LINES_ROW: [f64; 5] = [0.55, 0.4, 7.3, 1.0, 1.0];

/// `2*SIN()+WN()+RW()` on 4 replicates of [`TWO_LINES_TRUTH`] (43 minutes each) separates the
/// two lines: the canonical model lists them by frequency, every replicate's frequencies are
/// within 5%, and on the replicate mean the frequencies are within 2%, the amplitudes within 15%
/// and the WN variance within 3% (the one-line test's bar).
#[test]
fn recovers_two_vibration_lines_in_frequency_order() {
    let rows = two_line_replicates(4, 5500);
    for (i, r) in rows.iter().enumerate() {
        for k in [0, 2] {
            assert!(
                (r[k] / TWO_LINES_ROW[k] - 1.0).abs() < 0.05,
                "replicate {i}: line {k} at {} Hz: {r:?}",
                r[k]
            );
        }
    }
    for (k, allow) in [(0, 0.02), (1, 0.15), (2, 0.02), (3, 0.15), (4, 0.03)] {
        let (m, se) = mean_se(&rows, k);
        let rel = m / TWO_LINES_ROW[k] - 1.0;
        assert!(
            rel.abs() <= allow,
            "column {k}: mean {m} (SE {se}) against {}, allowed {allow}",
            TWO_LINES_ROW[k]
        );
    }
}

/// The larger study behind [`recovers_two_vibration_lines_in_frequency_order`]: 32 replicates,
/// relative bias and SE of each read-off printed.
#[test]
#[ignore = "a 32-replicate study that prints figures; run with --ignored --nocapture"]
fn two_line_recovery_study() {
    let rows = two_line_replicates(32, 5501);
    for (k, name) in ["f1", "A1", "f2", "A2", "WN sigma2"].iter().enumerate() {
        let (m, se) = mean_se(&rows, k);
        let worst = rows
            .iter()
            .map(|r| (r[k] / TWO_LINES_ROW[k] - 1.0).abs())
            .fold(0.0, f64::max);
        println!(
            "{name}: relative bias {:+.4} (SE {:.4}), worst replicate {worst:.4}",
            m / TWO_LINES_ROW[k] - 1.0,
            se / TWO_LINES_ROW[k]
        );
    }
}
