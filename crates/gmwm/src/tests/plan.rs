//! The planner (docs/methods.md §18) against Monte Carlo: the predicted 95% half-widths of
//! N, B, K and the correlation time against the spread of the estimates over simulated
//! recordings of the truth, each fitted (its model in guess mode, as a calibration fits the
//! identified model) and read off (B: the IEEE 952 read-off of the recording's Allan variance).

use crate::calib::ieee::ieee_readoff;
use crate::calib::plan::Plan;
use crate::fit::Gmwm;
use crate::model::Model;
use crate::sim::simulate_model;
use crate::variance::allan::{allan_variance, AllanOptions};
use crate::variance::wv::WvOptions;
use rayon::prelude::*;

/// `sinh(1.96 sd(ln q))` over the replicates, the Monte Carlo relative half-width, leaving out
/// the replicates more than 5 robust standard deviations (1.4826 x the median absolute
/// deviation) from the median: one whose fit lets the Gauss–Markov term absorb the random
/// walk (K -> 0, a log of -30) would otherwise be the whole spread; how many is printed.
fn spread(values: &[f64]) -> f64 {
    let mut logs: Vec<f64> = values.iter().map(|v| v.ln()).collect();
    logs.sort_by(f64::total_cmp);
    let median = logs[logs.len() / 2];
    let mut dev: Vec<f64> = logs.iter().map(|l| (l - median).abs()).collect();
    dev.sort_by(f64::total_cmp);
    let robust = 1.4826 * dev[dev.len() / 2];
    let kept: Vec<f64> = logs
        .iter()
        .copied()
        .filter(|l| (l - median).abs() <= 5.0 * robust)
        .collect();
    if kept.len() < logs.len() {
        eprintln!(
            "  {} of {} replicates beyond 5 sd",
            logs.len() - kept.len(),
            logs.len()
        );
    }
    let r = kept.len() as f64;
    let m = kept.iter().sum::<f64>() / r;
    let sd = (kept.iter().map(|l| (l - m).powi(2)).sum::<f64>() / (r - 1.0)).sqrt();
    (1.959964 * sd).sinh()
}

/// MEMS-like gyroscope at 100 Hz: N = 1e-3 u/sqrt(Hz), a 5 s Gauss–Markov term of sd 1e-3 u,
/// K = 1e-4 u sqrt(Hz).
const MEMS: &str = "GM(beta=0.2, sigma2_gm=1e-6)+WN(sigma2=1e-4)+RW(gamma2=1e-10)";
/// The same white noise and random walk with a flicker floor, B = 2.6e-4 u.
const FLICKER: &str = "FN(b2=7e-8)+WN(sigma2=1e-4)+RW(gamma2=1e-10)";

/// `(name, value)` of each quantity of one replicate.
type Row = Vec<(&'static str, f64)>;

/// The quantities of each replicate of `truth`, fitted as `fit_model`.
fn replicates(truth: &str, fit_model: &str, length_s: f64, r: usize, seed: u64) -> Vec<Row> {
    let truth: Model = truth.parse().unwrap();
    let freq = 100.0;
    let n = (length_s * freq) as usize;
    (0..r as u64)
        .into_par_iter()
        .map(|i| {
            let x = simulate_model(&truth, n, freq, seed + i).unwrap();
            let fit = Gmwm::parse(fit_model)
                .unwrap()
                .with_draws(2000)
                .fit(&x, freq, &WvOptions::default())
                .unwrap();
            let t = fit.theta();
            if fit_model.starts_with("FN") {
                vec![
                    ("N", (t[1] / freq).sqrt()),
                    ("B", t[0].sqrt()),
                    ("K", (t[2] * freq).sqrt()),
                ]
            } else {
                let av = allan_variance(&x, freq, &AllanOptions::default()).unwrap();
                let b = ieee_readoff(&av).unwrap().b.value.unwrap_or(f64::NAN);
                vec![
                    ("N", (t[2] / freq).sqrt()),
                    ("B", b),
                    ("K", (t[3] * freq).sqrt()),
                    ("T1", 1.0 / t[0]),
                ]
            }
        })
        .collect()
}

fn check(truth: &str, fit_model: &str, length_s: f64, r: usize, tolerance: f64) {
    let model: Model = truth.parse().unwrap();
    let plan = Plan::new(&model, 100.0, &[length_s], 0.05, &[]).unwrap();
    let rows = replicates(truth, fit_model, length_s, r, 2024);
    for (k, (name, _)) in rows[0].iter().enumerate() {
        let q = plan.quantities.iter().find(|q| &q.name == name).unwrap();
        let predicted = q.half_width[0].unwrap();
        let values: Vec<f64> = rows
            .iter()
            .map(|row| row[k].1)
            .filter(|v| v.is_finite())
            .collect();
        assert!(
            values.len() * 10 >= r * 9,
            "{name}: {} of {r} replicates read off",
            values.len()
        );
        let observed = spread(&values);
        eprintln!(
            "{fit_model} {length_s} s {name}: predicted ±{:.2}%, Monte Carlo ±{:.2}% ({} replicates)",
            100.0 * predicted,
            100.0 * observed,
            values.len()
        );
        assert!(
            (predicted / observed - 1.0).abs() <= tolerance,
            "{name} at {length_s} s: predicted {predicted}, Monte Carlo {observed}"
        );
    }
}

/// CI size: one hour, 60 replicates (the spread's own sampling error is about 9%: the 30%
/// allowance is 20% plus that).
#[test]
fn plan_matches_monte_carlo_at_one_hour() {
    check(MEMS, "GM()+WN()+RW()", 3600.0, 60, 0.3);
    check(FLICKER, "FN()+WN()+RW()", 3600.0, 60, 0.3);
}

/// The study: three lengths, 200 replicates each, within 20%.
#[test]
#[ignore]
fn plan_matches_monte_carlo_study() {
    for l in [3600.0, 10800.0, 43200.0] {
        check(MEMS, "GM()+WN()+RW()", l, 200, 0.2);
        check(FLICKER, "FN()+WN()+RW()", l, 200, 0.2);
    }
}
