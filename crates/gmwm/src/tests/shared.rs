//! The shared-process estimator (`gmwm::shared`, docs/methods.md §15): Monte Carlo with a known
//! shared Gauss–Markov process, the size of the test of no shared process, bad inputs.

use gmwm::model::Model;
use gmwm::shared::{fit_shared, SharedFit, SharedOptions};
use gmwm::sim::{replicate_seed, simulate_model};

/// Rate of the simulated triad (Hz).
const FREQ: f64 = 100.0;
/// The shared process: correlation time 2 s (200 samples), well inside the observed scales.
const SHARED: &str = "GM(beta=0.5, sigma2_gm=0.05)";
/// Each axis's own noise (one model for the three axes, different values).
const SPECIFIC: [&str; 3] = [
    "WN(sigma2=1)+RW(gamma2=1e-6)",
    "WN(sigma2=1.5)+RW(gamma2=2e-6)",
    "WN(sigma2=0.8)+RW(gamma2=5e-7)",
];

/// One simulated triad of `n` samples (with or without the shared GM), fitted.
fn replicate(n: usize, seed: u64, with_shared: bool) -> SharedFit {
    let v = simulate_model(
        &Model::parse(SHARED).unwrap(),
        n,
        FREQ,
        replicate_seed(seed, 0),
    )
    .unwrap();
    let axes: Vec<Vec<f64>> = SPECIFIC
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let u = simulate_model(
                &Model::parse(m).unwrap(),
                n,
                FREQ,
                replicate_seed(seed, 1 + i as u64),
            )
            .unwrap();
            if with_shared {
                u.iter().zip(&v).map(|(a, b)| a + b).collect()
            } else {
                u
            }
        })
        .collect();
    let named: Vec<(&str, &[f64])> = vec![("x", &axes[0]), ("y", &axes[1]), ("z", &axes[2])];
    let opts = SharedOptions {
        draws: 500,
        ..SharedOptions::default()
    };
    fit_shared(
        &named,
        FREQ,
        &"GM()".parse().unwrap(),
        &"WN()+RW()".parse().unwrap(),
        &opts,
    )
    .unwrap()
}

/// (replicates, beta covered, sigma2_gm covered, both covered, test rejections at 5%)
fn study(n: usize, reps: u64, seed: u64, with_shared: bool) -> (u64, u64, u64, u64, u64) {
    use rayon::prelude::*;
    let out: Vec<(bool, bool, bool)> = (0..reps)
        .into_par_iter()
        .map(|r| {
            let fit = replicate(n, replicate_seed(seed, r), with_shared);
            let sp: Vec<_> = fit.shared_parameters().collect();
            let inside =
                |k: usize, truth: f64| match (sp[k].parameter.ci_low, sp[k].parameter.ci_high) {
                    (Some(lo), Some(hi)) => lo <= truth && truth <= hi,
                    _ => false,
                };
            (inside(0, 0.5), inside(1, 0.05), fit.test.p_value < 0.05)
        })
        .collect();
    let count =
        |f: &dyn Fn(&(bool, bool, bool)) -> bool| out.iter().filter(|o| f(o)).count() as u64;
    (
        reps,
        count(&|o| o.0),
        count(&|o| o.1),
        count(&|o| o.0 && o.1),
        count(&|o| o.2),
    )
}

/// The quick Monte Carlo: N = 2^15 samples at 100 Hz (J = 14), 200 triads with the shared GM
/// and 200 without. Each shared GM parameter must be inside its 95% interval in at least 93% of
/// the triads (the bar; the nominal 95% has a binomial SE of 1.5% here), and the test of
/// no shared process at 5% must reject within 3 binomial SE (1.5%) of 5% of the triads without.
#[test]
fn shared_gm_is_recovered_and_the_test_holds_its_size() {
    let (reps, beta, s2, _, rejected) = study(1 << 15, 200, 11, true);
    assert!(
        beta as f64 >= 0.93 * reps as f64,
        "beta covered {beta}/{reps}"
    );
    assert!(
        s2 as f64 >= 0.93 * reps as f64,
        "sigma2_gm covered {s2}/{reps}"
    );
    // with the shared GM the test has power: it rejects in (nearly) every triad
    assert!(
        rejected as f64 >= 0.99 * reps as f64,
        "power {rejected}/{reps}"
    );
    let (reps, _, _, _, rejected) = study(1 << 15, 200, 12, false);
    let se = (0.05f64 * 0.95 / reps as f64).sqrt();
    let rate = rejected as f64 / reps as f64;
    assert!((rate - 0.05).abs() <= 3.0 * se, "size {rejected}/{reps}");
}

/// The full study (figures in the closing note): 1000 triads of N = 2^16 with and without the
/// shared GM. `cargo test --release -p gmwm --lib shared_study -- --ignored
/// --nocapture`.
#[test]
#[ignore = "full study, ~27 min: N = 2^16, 1000 triads each way; figures in docs/methods/multi-axis.md §15"]
fn shared_study() {
    let (reps, beta, s2, both, rejected) = study(1 << 16, 1000, 21, true);
    println!("with shared GM: {reps} triads, beta covered {beta}, sigma2_gm covered {s2}, both {both}, test rejected {rejected}");
    let (reps, _, _, _, rejected) = study(1 << 16, 1000, 22, false);
    println!("without: {reps} triads, test rejected at 5%: {rejected}");
    assert!(beta as f64 >= 0.93 * reps as f64 && s2 as f64 >= 0.93 * reps as f64);
}

/// The exact covariance of the stacked moments (`gmwm::variance::cross`) against the Monte
/// Carlo covariance of 400 simulated triads (N = 4096, 6 levels): the variance of every moment
/// within 30% (4 SE of a variance estimated from 400 draws, `sqrt(2/400) = 7%`), their mean
/// log ratio within 0.1 (the 18 rows are correlated across neighbouring levels, about 6
/// independent ones: 3 SE of their mean is 0.09).
#[test]
fn stacked_moment_covariance_matches_monte_carlo() {
    use gmwm::variance::cross::{stacked_moment_covariance, wavelet_cross_covariance};
    use gmwm::{wavelet_variance, WvOptions};
    use rayon::prelude::*;
    let (n, j, reps) = (4096, 6, 400u64);
    let moments: Vec<Vec<f64>> = (0..reps)
        .into_par_iter()
        .map(|r| {
            let v = simulate_model(
                &Model::parse("AR1(phi=0.9, sigma2=0.2)").unwrap(),
                n,
                1.0,
                replicate_seed(5, 3 * r),
            )
            .unwrap();
            let axes: Vec<Vec<f64>> = ["WN(sigma2=1)", "WN(sigma2=2)+RW(gamma2=1e-3)"]
                .iter()
                .enumerate()
                .map(|(i, m)| {
                    let u = simulate_model(
                        &Model::parse(m).unwrap(),
                        n,
                        1.0,
                        replicate_seed(5, 3 * r + 1 + i as u64),
                    )
                    .unwrap();
                    u.iter().zip(&v).map(|(a, b)| a + b).collect()
                })
                .collect();
            let o = WvOptions {
                levels: Some(j),
                ..WvOptions::default()
            };
            let mut m = Vec::new();
            for x in &axes {
                m.extend(wavelet_variance(x, 1.0, &o).unwrap().wv().iter().copied());
            }
            m.extend(wavelet_cross_covariance(&axes[0], &axes[1], j).unwrap());
            m
        })
        .collect();
    let procs = |t: &str| Model::parse(t).unwrap().processes(1.0).unwrap();
    let v = stacked_moment_covariance(
        &procs("AR1(phi=0.9, sigma2=0.2)"),
        &[procs("WN(sigma2=1)"), procs("WN(sigma2=2)+RW(gamma2=1e-3)")],
        n,
        j,
    )
    .unwrap();
    let k = moments[0].len();
    let mut log_sum = 0.0;
    for i in 0..k {
        let mean = moments.iter().map(|m| m[i]).sum::<f64>() / reps as f64;
        let var = moments.iter().map(|m| (m[i] - mean).powi(2)).sum::<f64>() / (reps - 1) as f64;
        let ratio = var / v[(i, i)];
        assert!(
            (ratio - 1.0).abs() < 0.3,
            "moment {i}: Monte Carlo {var:e}, exact {:e}",
            v[(i, i)]
        );
        log_sum += ratio.ln();
    }
    assert!(
        (log_sum / k as f64).abs() < 0.1,
        "mean log ratio {}",
        log_sum / k as f64
    );
}

/// Bad inputs: one clear error each, never a panic.
#[test]
fn shared_refuses_bad_inputs() {
    let x = simulate_model(&Model::parse("WN(sigma2=1)").unwrap(), 4096, 1.0, 1).unwrap();
    let shared: Model = "GM()".parse().unwrap();
    let spec: Model = "WN()+RW()".parse().unwrap();
    let o = SharedOptions::default();
    let one = fit_shared(&[("x", &x)], 1.0, &shared, &spec, &o).unwrap_err();
    assert!(one.to_string().contains("at least 2 series"), "{one}");
    let short = &x[..4000];
    let diff = fit_shared(&[("x", &x), ("y", short)], 1.0, &shared, &spec, &o).unwrap_err();
    assert!(diff.to_string().contains("as many samples"), "{diff}");
    let dr = fit_shared(
        &[("x", &x), ("y", &x)],
        1.0,
        &shared,
        &"WN()+DR()".parse().unwrap(),
        &o,
    )
    .unwrap_err();
    assert!(dr.to_string().contains("DR"), "{dr}");
    let tiny = &x[..8];
    let e = fit_shared(&[("x", tiny), ("y", tiny)], 1.0, &shared, &spec, &o).unwrap_err();
    assert!(matches!(e, gmwm::FitError::TooFewLevels { .. }), "{e:?}");
    let mut bad = x.clone();
    bad[7] = f64::NAN;
    assert!(fit_shared(&[("x", &x), ("y", &bad)], 1.0, &shared, &spec, &o).is_err());
}
