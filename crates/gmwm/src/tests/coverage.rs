//! Intervals after selection (docs/methods.md §20) against Monte Carlo: realistic truths are
//! simulated at a realistic length and rate, the whole calibration (selection, refinement,
//! identification, read-off) is run on each replicate, and every exported number's 95%
//! interval must hold its target in at least 90% of the replicates.
//!
//! Targets: N and K are the truth's white noise and random walk; B the truth's flicker
//! coefficient, else the IEEE read-off of the truth's implied Allan deviation over the scales
//! the read-off uses (`audit::model_b`); the Gauss–Markov correlation time (what the PX4 file
//! exports) the truth's, over the replicates whose model keeps one.

use crate::calib::audit::{model_b, SimulatedAxis};
use crate::calib::effective::{unresolved_slow_terms, with_random_walk_for};
use crate::calib::Plan;
use crate::calib::{AxisCalibration, Calibration, CalibrationOptions, Estimate, EstimateStatus};
use crate::fit::weights::Weights;
use crate::fit::Gmwm;
use crate::model::Model;
use crate::process::{LatentProcess, Process};
use crate::units::SignalKind;
use crate::variance::default_levels;
use crate::variance::implied_cov::exact_wv_covariance;
use crate::wavelet::{Transform, WaveletFilter};
use rayon::prelude::*;

/// A MEMS gyroscope at 200 Hz in rad/s (the held-back truth, our values): N = 1.7e-4
/// rad/s/sqrt(Hz) (0.6 deg/sqrt(h)), a Gauss–Markov bias of correlation time 200 s and sd 5e-5
/// rad/s (10 deg/h), K = 2e-5 rad/s/sqrt(s), quantization.
const GM_TRUTH: &str =
    "GM(beta=0.005, sigma2_gm=4e-8)+WN(sigma2=6e-6)+RW(gamma2=2e-12)+QN(q2=2e-8)";
/// The same white noise and random walk with a flicker floor, B = 3e-5 rad/s (6 deg/h).
const FLICKER_TRUTH: &str = "FN(b2=2.3e-9)+WN(sigma2=6e-6)+RW(gamma2=2e-14)";
const FREQ: f64 = 200.0;
/// 2.9 h at 200 Hz.
const SAMPLES: usize = 2_088_000;

/// One exported number of one replicate: its value and interval (`None` where the
/// calibration gave none or only a bound).
type Reading = Option<(f64, Option<(f64, f64)>)>;

/// An upper bound is the interval `[0, value]`: what it claims is that the truth is below.
fn reading(e: &Option<Estimate>) -> Reading {
    e.as_ref().map(|e| match e.status {
        EstimateStatus::UpperBound => (e.value, Some((0.0, e.value))),
        _ => (e.value, e.ci_low.zip(e.ci_high)),
    })
}

fn readings(a: &AxisCalibration) -> [Reading; 4] {
    [
        reading(&a.noise_density),
        reading(&a.bias_instability),
        reading(&a.random_walk),
        a.gauss_markov_bias
            .as_ref()
            .and_then(|g| reading(&Some(g.correlation_time.clone()))),
    ]
}

/// The truth's N, B, K and correlation time, and whether K is the effective random walk.
///
/// K's target is the truth's random walk, or, when the planner leaves a slow Gauss–Markov
/// term of the truth undetermined at this length (`effective::unresolved_slow_terms`), the
/// truth's effective random walk: the K of the truth without that term, with a random walk,
/// fitted to the truth's implied WV with the weights of the truth's exact WV variances (the
/// pseudo-true value of the calibration's refit).
fn targets(truth: &Model) -> ([Option<f64>; 4], bool) {
    let processes = truth.processes(FREQ).unwrap();
    let mut t = [None; 4];
    let text = truth.to_string();
    let param = |name: &str| -> Option<f64> {
        let at = text.find(&format!("{name}="))? + name.len() + 1;
        let rest = &text[at..];
        let end = rest.find([',', ')']).unwrap_or(rest.len());
        rest[..end].trim().parse().ok()
    };
    t[0] = param("WN(sigma2").map(|s| (s / FREQ).sqrt());
    t[1] = model_b(&processes, SAMPLES, 0.05);
    t[2] = param("RW(gamma2").map(|g| (g * FREQ).sqrt());
    t[3] = param("GM(beta").map(|b| 1.0 / b);
    let plan = Plan::new(truth, FREQ, &[SAMPLES as f64 / FREQ], 0.05, &[]).unwrap();
    let terms = unresolved_slow_terms(&plan, 0.0);
    if terms.is_empty() {
        return (t, false);
    }
    let dropped: Vec<usize> = terms.iter().map(|t| t.0).collect();
    let effective = with_random_walk_for(truth, &dropped, FREQ).unwrap();
    let levels = default_levels(SAMPLES, Transform::Modwt, WaveletFilter::Haar);
    let nu = truth.implied_wv(levels, FREQ).unwrap();
    let v = exact_wv_covariance(truth, SAMPLES, FREQ, levels).unwrap();
    let weights = Weights::from_v((0..levels).map(|j| v[(j, j)]).collect(), "exact").unwrap();
    // the truth's own values of the kept terms as the start
    let start: Vec<f64> = processes
        .iter()
        .enumerate()
        .filter(|(i, _)| !dropped.contains(i))
        .flat_map(|(_, p)| p.params())
        .collect();
    let fit = Gmwm::new(effective.clone())
        .fit_weighted(&nu.wv, weights, FREQ, &start)
        .unwrap();
    let rw = fit
        .model()
        .processes(FREQ)
        .unwrap()
        .into_iter()
        .find_map(|p| match p {
            Process::Rw(r) => Some(r.gamma2()),
            _ => None,
        })
        .unwrap();
    t[2] = Some((rw * FREQ).sqrt());
    eprintln!(
        "  K target: effective random walk {:.4e} ({} fitted to the truth's WV; truth's K {:.4e})",
        t[2].unwrap(),
        effective,
        param("RW(gamma2").map_or(f64::NAN, |g| (g * FREQ).sqrt())
    );
    (t, true)
}

/// Per number: replicates whose interval held the target, replicates with an interval, and
/// every value relative to the target.
type Tally = (usize, usize, Vec<f64>);

/// Coverage of each number over `replicates` calibrations of `truth`: `(covered, with an
/// interval, values)` per number, and the canonical models selected.
fn study(truth: &str, replicates: usize, seed: u64) -> ([Tally; 4], Vec<String>) {
    let truth: Model = truth.parse().unwrap();
    let (targets, _) = targets(&truth);
    let options = CalibrationOptions {
        robust_check: None,
        ..CalibrationOptions::default()
    };
    let inner = Calibration::new(options);
    let axis = SimulatedAxis {
        column: "gyro_x",
        axis: "X",
        kind: SignalKind::Gyroscope,
        unit: Some("rad/s"),
    };
    let rows: Vec<AxisCalibration> = (0..replicates as u64)
        .into_par_iter()
        .filter_map(|r| {
            axis.calibrate(&inner, &truth, SAMPLES, FREQ, seed + r)
                .unwrap()
        })
        .collect();
    assert!(
        rows.len() >= replicates * 9 / 10,
        "{} calibrations failed",
        replicates - rows.len()
    );
    let mut out: [Tally; 4] = Default::default();
    if std::env::var("GMWM_COVERAGE_ROWS").is_ok() {
        for a in rows.iter().take(8) {
            eprintln!(
                "replicate: selected {} K {:?}",
                a.canonical_model,
                a.random_walk.as_ref().map(|e| (
                    e.value / targets[2].unwrap_or(1.0),
                    e.ci_low,
                    e.ci_high
                ))
            );
            for row in a.selection.rows().iter().take(6) {
                eprintln!(
                    "   {:30} dwic {:8.2} se {:8.2} {:?} k={}",
                    row.score.canonical_model.to_string(),
                    row.delta_wic,
                    row.delta_wic_se,
                    row.status,
                    row.score.model.without_values()
                );
            }
        }
    }
    if std::env::var("GMWM_COVERAGE_MISSES").is_ok() {
        for a in &rows {
            if let (Some((v, Some((lo, hi)))), Some(t)) = (readings(a)[2], targets[2]) {
                if !(lo <= t && t <= hi) {
                    eprintln!(
                        "  K missed: {} K/target {:.3} [{:.3}, {:.3}] {}",
                        a.canonical_model,
                        v / t,
                        lo / t,
                        hi / t,
                        a.random_walk.as_ref().unwrap().source
                    );
                }
            }
        }
    }
    for a in &rows {
        for (k, r) in readings(a).into_iter().enumerate() {
            let (Some((v, ci)), Some(t)) = (r, targets[k]) else {
                continue;
            };
            out[k].2.push(v / t);
            if let Some((lo, hi)) = ci {
                out[k].1 += 1;
                out[k].0 += usize::from(lo <= t && t <= hi);
            }
        }
    }
    (
        out,
        rows.iter().map(|a| a.canonical_model.clone()).collect(),
    )
}

fn report(truth: &str, replicates: usize, seed: u64) -> Vec<(&'static str, f64)> {
    let (numbers, models) = study(truth, replicates, seed);
    let mut counts: Vec<(String, usize)> = Vec::new();
    for m in models {
        match counts.iter_mut().find(|c| c.0 == m) {
            Some(c) => c.1 += 1,
            None => counts.push((m, 1)),
        }
    }
    eprintln!("{truth}: models {counts:?}");
    let mut coverage = Vec::new();
    for (name, (covered, with, values)) in ["N", "B", "K", "T"].into_iter().zip(numbers) {
        if values.is_empty() {
            continue;
        }
        let mut v = values.clone();
        v.sort_by(f64::total_cmp);
        let c = covered as f64 / with.max(1) as f64;
        let logs: Vec<f64> = v.iter().map(|x| x.ln()).collect();
        let m = logs.iter().sum::<f64>() / logs.len() as f64;
        let sd = (logs.iter().map(|l| (l - m).powi(2)).sum::<f64>()
            / (logs.len().max(2) - 1) as f64)
            .sqrt();
        eprintln!(
            "  {name}: {} values, median ratio {:.3}, spread ±{:.1}% (1.96 sd of the log), {with} intervals, coverage {c:.3}",
            v.len(),
            v[v.len() / 2],
            100.0 * (1.959964 * sd).sinh(),
        );
        // a coverage over fewer than 10 intervals says little (the correlation time has one
        // only where the recording determines it): printed, not judged
        if with >= 10 {
            coverage.push((name, c));
        }
    }
    coverage
}

/// The CI version: 40 replicates of each truth, every number's coverage at least 0.8 (with a
/// true coverage of 0.93 a binomial count of 40 falls below 32 with probability about 1%;
/// before the effective random walk, K of the Gauss–Markov truth covered 15%).
#[test]
fn intervals_hold_after_selection() {
    let mut low = Vec::new();
    for truth in [GM_TRUTH, FLICKER_TRUTH] {
        for (name, c) in report(truth, 40, 77_000) {
            if c < 0.8 {
                low.push(format!("{truth} {name}: coverage {c}"));
            }
        }
    }
    assert!(low.is_empty(), "{low:?}");
}

#[test]
#[ignore = "Monte Carlo study: cargo test --release -- --ignored coverage_study"]
fn coverage_study() {
    let r = std::env::var("GMWM_COVERAGE_REPS").map_or(200, |v| v.parse().unwrap());
    let truths = std::env::var("GMWM_COVERAGE_TRUTHS")
        .map_or(vec![GM_TRUTH.to_string(), FLICKER_TRUTH.to_string()], |v| {
            v.split(';').map(str::to_string).collect()
        });
    let mut low = Vec::new();
    for truth in &truths {
        for (name, c) in report(truth, r, 4000) {
            if c < 0.9 {
                low.push(format!("{truth} {name}: coverage {c}"));
            }
        }
    }
    assert!(low.is_empty(), "{low:?}");
}
