//! The mission-horizon bound (docs/methods.md §17) against Monte Carlo: a truth with a
//! Gauss–Markov term, flicker noise and a sinusoid is simulated in its stationary law; the
//! error a filter holding its bias makes (the bias terms relative to their value before the
//! first sample, the noise terms as they are) is summed, its mean square estimated over 1000
//! replicates, and the white-noise + random-walk pair bounding the truth must stay above it at
//! every time up to the horizon.

use crate::calib::horizon::horizon_bound;
use crate::model::Model;
use crate::process::sampler::stream;
use crate::process::{Process, StartMode};
use crate::variance::growth::ErrorGrowth;
use rayon::prelude::*;

/// Gyroscope-like at 100 Hz, per-sample units: white noise, a 10 s Gauss–Markov term, a
/// flicker floor, a 1 Hz vibration line and a random walk, each visible before 60 s.
const TRUTH: &str = "WN(sigma2=1)+GM(beta=0.1, sigma2_gm=1e-3)+FN(b2=1e-3)+SIN(amplitude=0.2, omega=0.01)+RW(gamma2=1e-8)";
const FREQ: f64 = 100.0;

fn truth() -> Vec<Process> {
    Model::parse(TRUTH).unwrap().processes(FREQ).unwrap()
}

/// The mean square of `sum_{t=1}^{n} e_t` at every `n <= samples` over `replicates`
/// simulations, `e_t = x_t - x_0` for the `held` terms and `x_t` for the others.
fn simulated_mean_square(
    processes: &[Process],
    held: &[bool],
    samples: usize,
    replicates: usize,
) -> Vec<f64> {
    let sums = (0..replicates)
        .into_par_iter()
        .map(|r| {
            let mut x = vec![0.0; samples];
            let mut one = vec![0.0; samples + 1];
            for (i, p) in processes.iter().enumerate() {
                let mut s = p
                    .sampler(stream(9000 + r as u64, i), StartMode::Stationary)
                    .unwrap();
                s.store(&mut one);
                let start = if held[i] { one[0] } else { 0.0 };
                for (a, v) in x.iter_mut().zip(&one[1..]) {
                    *a += v - start;
                }
            }
            let mut acc = 0.0;
            x.iter()
                .map(|v| {
                    acc += v;
                    acc * acc
                })
                .collect::<Vec<f64>>()
        })
        .reduce(
            || vec![0.0; samples],
            |mut a, b| {
                for (x, y) in a.iter_mut().zip(&b) {
                    *x += y;
                }
                a
            },
        );
    sums.into_iter().map(|s| s / replicates as f64).collect()
}

fn check_bound(horizon_s: f64, replicates: usize) {
    let processes = truth();
    let samples = (horizon_s * FREQ) as usize;
    let bound = horizon_bound(
        &processes,
        FREQ,
        horizon_s,
        Some(0.1),
        Some(1e-3),
        Some(1e-3),
    )
    .unwrap();
    let a = bound.noise_density.powi(2) * FREQ;
    let b = bound.random_walk.powi(2) / FREQ;
    let counts: Vec<usize> = (1..=samples).collect();
    let model = ErrorGrowth::of(&processes, &counts);
    // (a) and (b) at every count, not only the solver's grid: the gaps between its points
    // cost at most a part in 1e4
    for (i, &n) in counts.iter().enumerate() {
        let m = n as f64;
        let av = a / m + b * (2.0 * m * m + 1.0) / (6.0 * m);
        let ms = a * m + b * m * (m + 1.0) * (2.0 * m + 1.0) / 6.0;
        assert!(
            av >= model.allan[i] * (1.0 - 1e-4),
            "AV at n = {n}: {av} < {}",
            model.allan[i]
        );
        assert!(ms >= model.integrated[i] * (1.0 - 1e-4), "E S^2 at n = {n}");
    }
    // the truth, simulated: its mean square is the closed form's, and under the pair's
    let simulated = simulated_mean_square(&processes, &model.held, samples, replicates);
    // relative standard error of a mean of squares of Gaussian sums: sqrt(2 / R)
    let se = (2.0 / replicates as f64).sqrt();
    let mut worst_excess: f64 = 0.0;
    for (k, n) in (1..=samples).step_by(7).enumerate() {
        let i = n - 1;
        let closed = model.integrated[i];
        let rel = simulated[i] / closed - 1.0;
        assert!(
            rel.abs() < 5.0 * se,
            "n = {n}: simulated {} vs closed form {closed}",
            simulated[i]
        );
        let m = n as f64;
        let pair = a * m + b * m * (m + 1.0) * (2.0 * m + 1.0) / 6.0;
        worst_excess = worst_excess.max(simulated[i] / pair);
        let _ = k;
    }
    assert!(
        worst_excess < 1.0 + 3.0 * se,
        "truth above the pair by {worst_excess}"
    );
    // the pair at T is at most 3x the truth's
    assert!(
        bound.excess_at_horizon >= 1.0 - 1e-9 && bound.excess_at_horizon <= 3.0,
        "excess at T: {}",
        bound.excess_at_horizon
    );
    let sim_excess = (a * samples as f64
        + b * (samples * (samples + 1) * (2 * samples + 1)) as f64 / 6.0)
        / simulated[samples - 1];
    assert!(
        sim_excess <= 3.0 * (1.0 + 3.0 * se),
        "simulated excess at T: {sim_excess}"
    );
    eprintln!(
        "T = {horizon_s} s: N x {:.3}, K x {:.3}, excess at T {:.3} (simulated {:.3}), max truth / pair {:.3}; binding: {}",
        bound.noise_inflation.unwrap(),
        bound.random_walk_inflation.unwrap(),
        bound.excess_at_horizon,
        sim_excess,
        worst_excess,
        bound.binding
    );
}

#[test]
fn pair_bounds_the_simulated_truth_up_to_60_s() {
    check_bound(60.0, 1000);
}

/// The ten-minute horizon at the same size (6e7 samples, about a minute on two cores).
#[test]
#[ignore]
fn pair_bounds_the_simulated_truth_up_to_600_s() {
    check_bound(600.0, 1000);
}

#[test]
fn plain_pair_that_already_bounds_is_kept() {
    // white noise + random walk bounds itself: no inflation
    let p = Model::parse("WN(sigma2=4e-4)+RW(gamma2=1e-10)")
        .unwrap()
        .processes(200.0)
        .unwrap();
    let n = (4e-4f64 / 200.0).sqrt();
    let k = (1e-10f64 * 200.0).sqrt();
    let b = horizon_bound(&p, 200.0, 600.0, Some(n), Some(k), Some(k)).unwrap();
    assert!((b.noise_inflation.unwrap() - 1.0).abs() < 1e-9, "{b:?}");
    assert!(
        (b.random_walk_inflation.unwrap() - 1.0).abs() < 1e-9,
        "{b:?}"
    );
    assert!((b.excess_at_horizon - 1.0).abs() < 1e-9);
}

#[test]
fn horizon_is_checked() {
    let p = truth();
    for t in [0.0, -1.0, f64::NAN, 0.001, 1e12] {
        let e = horizon_bound(&p, FREQ, t, None, None, None).unwrap_err();
        assert!(e.to_string().contains("horizon"), "{e}");
    }
}
