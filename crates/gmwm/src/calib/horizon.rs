//! A white-noise + random-walk pair that bounds a fitted model over a mission (docs/methods.md
//! §17.2): what a Kalibr / OpenVINS / VINS-Fusion / ORB-SLAM3 filter, which knows only `N`
//! and `K`, should be given so that it never trusts the sensor more than the model allows up
//! to a horizon `T`.
//!
//! # The bound
//! With the pair's per-sample variances `a = N'^2 f` and `b = K'^2 / f`, its Allan variance
//! and integrated-error mean square (`crate::variance::growth`) are linear in `(a, b)`:
//! `AV(m) = a / m + b (2 m^2 + 1) / (6 m)` and `E S_n^2 = a n + b n (n + 1) (2n + 1) / 6`.
//! The pair must be at least the model's (a) Allan variance at every cluster time from `1/f`
//! to `T` and (b) integrated-error mean square at every time up to `T` (the error of a filter
//! holding its bias, `crate::variance::growth`), and no smaller than the plain estimates
//! (`a >= a0`, `b >= b0`).
//!
//! Among those pairs the one taken has the **least common inflation**: the smallest `kappa`
//! with `a <= kappa a0` and `b <= kappa b0` (the plain values; where the random walk was not
//! detected, its exported upper bound, else the random walk whose Allan variance at `T` is the
//! model's), each then lowered as far as the rows allow, under one more row: (c) the pair's
//! integrated-error variance at `T` is at most 3x the model's, so that the filter is not
//! pessimistic where the mission ends (dropped, and said, when no pair meets it). A white
//! noise and a random walk cannot follow a term that grows like `n^2` (flicker, a
//! Gauss–Markov term near its correlation time) over many decades of time within a constant
//! factor — the best factor over `R` decades of samples is about `sqrt(10^R)` — so the pair
//! is pessimistic somewhere; the rule spreads that evenly between `N` and `K` and keeps it off
//! the horizon. For a given `kappa` the feasible pairs form a convex polygon: with the least
//! feasible `a` given `b` (convex in `b`), feasibility is the sign of a convex function of `b`
//! (a ternary search), and `kappa` is bisected.
//!
//! The constraints are taken at every count `n <= 64` and on a 0.1% geometric grid beyond, up
//! to `T f`: both sides are smooth there, and the gaps between grid points are far below the
//! Monte Carlo error with which the bound is checked (`tests::horizon`).

use super::pipeline::{AxisCalibration, Estimate, EstimateStatus};
use crate::error::{InputError, ParamError};
use crate::process::Process;
use crate::variance::growth::ErrorGrowth;
use serde::Serialize;

/// Counts of samples up to which every one is a constraint.
const EVERY_COUNT_UP_TO: usize = 64;
/// Ratio of the geometric grid beyond.
const GRID_RATIO: f64 = 1.001;
/// The pair's integrated-error variance at the horizon is kept below this multiple of the
/// model's whenever the rows allow it.
const HORIZON_EXCESS_CAP: f64 = 3.0;
/// Longest horizon, in samples: an ARMA(p, q)'s autocovariance is summed over it.
const MAX_HORIZON_SAMPLES: f64 = 1e9;

/// The white-noise + random-walk pair bounding a model up to a horizon.
///
/// Wire format: `horizon_s`, `noise_density`, `random_walk` (continuous-time, the axis' unit),
/// `noise_inflation`, `random_walk_inflation` (over the plain estimates; null where the plain
/// value is 0 or missing), `excess_at_horizon` (the pair's integrated-error variance at `T`
/// over the model's), `binding` (which constraints hold with equality, in words).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HorizonBound {
    /// The horizon `T`, s.
    pub horizon_s: f64,
    /// `N'`, continuous time (unit/sqrt(Hz)).
    pub noise_density: f64,
    /// `K'`, continuous time (unit·sqrt(Hz)).
    pub random_walk: f64,
    /// `N' / N`, the plain noise density's inflation.
    pub noise_inflation: Option<f64>,
    /// `K' / K`, the plain random walk's inflation.
    pub random_walk_inflation: Option<f64>,
    /// The pair's integrated-error variance at `T` over the model's (>= 1).
    pub excess_at_horizon: f64,
    /// Where the pair touches the model, in words.
    pub binding: String,
}

/// The constraint rows `a u + b v >= r` with where each comes from.
struct Rows {
    u: Vec<f64>,
    v: Vec<f64>,
    r: Vec<f64>,
    /// (is the Allan variance, count of samples).
    what: Vec<(bool, usize)>,
}

/// Counts `1..=64` then a 0.1% geometric grid up to `last` (included).
fn grid(last: usize) -> Vec<usize> {
    let mut counts: Vec<usize> = (1..=last.min(EVERY_COUNT_UP_TO)).collect();
    let mut x = EVERY_COUNT_UP_TO as f64;
    while (x as usize) < last {
        x *= GRID_RATIO;
        let c = (x.round() as usize).min(last);
        if c > *counts.last().unwrap_or(&0) {
            counts.push(c);
        }
    }
    counts
}

/// The least-inflated pair bounding `processes` (the fitted model at `freq_hz`) up to
/// `horizon_s` (module doc), never below the plain `noise_density` and `random_walk`
/// (continuous time; `None` for a missing value, taken as 0); `scale_of_random_walk` is what
/// a unit of the random walk's inflation is (the exported value, an upper bound included).
///
/// # Errors
/// [`ParamError`] naming `horizon` unless it is finite and spans at least one sample and at
/// most 1e9.
pub(crate) fn horizon_bound(
    processes: &[Process],
    freq_hz: f64,
    horizon_s: f64,
    noise_density: Option<f64>,
    random_walk: Option<f64>,
    scale_of_random_walk: Option<f64>,
) -> Result<HorizonBound, ParamError> {
    let samples = horizon_s * freq_hz;
    if !horizon_s.is_finite() || !(1.0..=MAX_HORIZON_SAMPLES).contains(&samples) {
        return Err(ParamError::new(
            "horizon",
            horizon_s,
            format!(
                "a horizon in seconds of at least one sample (1/f = {:.3e} s) and at most 1e9 samples",
                1.0 / freq_hz
            ),
        ));
    }
    let last = samples.floor() as usize;
    let counts = grid(last);
    let model = ErrorGrowth::of(processes, &counts);
    let mut rows = Rows {
        u: Vec::new(),
        v: Vec::new(),
        r: Vec::new(),
        what: Vec::new(),
    };
    for (i, &c) in counts.iter().enumerate() {
        let m = c as f64;
        rows.u.push(1.0 / m);
        rows.v.push((2.0 * m * m + 1.0) / (6.0 * m));
        rows.r.push(model.allan[i]);
        rows.what.push((true, c));
        rows.u.push(m);
        rows.v.push(m * (m + 1.0) * (2.0 * m + 1.0) / 6.0);
        rows.r.push(model.integrated[i]);
        rows.what.push((false, c));
    }
    let a0 = noise_density.map_or(0.0, |n| n * n * freq_hz);
    let b0 = random_walk.map_or(0.0, |k| k * k / freq_hz);
    let n_t = last as f64;
    let (p, q) = (n_t, n_t * (n_t + 1.0) * (2.0 * n_t + 1.0) / 6.0);
    let at_horizon = *model.integrated.last().unwrap_or(&0.0);
    // a unit of inflation: the plain values, else the white noise whose Allan variance at one
    // sample is the model's and the random walk whose Allan variance at T is
    let scale_a = if a0 > 0.0 { a0 } else { model.allan[0] };
    let scale_b = match scale_of_random_walk {
        Some(k) if k > 0.0 => k * k / freq_hz,
        _ => 3.0 * model.allan.last().copied().unwrap_or(0.0) / n_t,
    };
    let goal = Goal {
        floor: (a0, b0),
        scale: (scale_a, scale_b.max(f64::MIN_POSITIVE)),
        at_horizon: (p, q),
        cap: HORIZON_EXCESS_CAP * at_horizon,
    };
    let (a, b) = solve(&rows, &goal);
    let n_prime = (a / freq_hz).sqrt();
    let k_prime = (b * freq_hz).sqrt();
    let ratio = |new: f64, old: Option<f64>| old.filter(|o| *o > 0.0).map(|o| new / o);
    Ok(HorizonBound {
        horizon_s,
        noise_density: n_prime,
        random_walk: k_prime,
        noise_inflation: ratio(n_prime, noise_density),
        random_walk_inflation: ratio(k_prime, random_walk),
        excess_at_horizon: (a * p + b * q) / at_horizon,
        binding: binding(&rows, a, b, a0, b0, freq_hz),
    })
}

impl Rows {
    /// The least `b` feasible with `a` (at least `floor`).
    fn least_b(&self, a: f64, floor: f64) -> f64 {
        let mut b = floor;
        for i in 0..self.r.len() {
            b = b.max((self.r[i] - a * self.u[i]) / self.v[i]);
        }
        b
    }

    /// The least `a` feasible with `b` (at least `floor`).
    fn least_a(&self, b: f64, floor: f64) -> f64 {
        let mut a = floor;
        for i in 0..self.r.len() {
            a = a.max((self.r[i] - b * self.v[i]) / self.u[i]);
        }
        a
    }
}

/// What the pair is chosen by (module doc).
struct Goal {
    /// The least `a`, `b`.
    floor: (f64, f64),
    /// What one unit of inflation is for `a`, `b` (the plain values).
    scale: (f64, f64),
    /// The pair's integrated-error variance at `T` per unit of `a` and `b`.
    at_horizon: (f64, f64),
    /// Its largest value allowed.
    cap: f64,
}

/// The pair of the least common inflation `kappa` (`a <= kappa a_s`, `b <= kappa b_s`) that
/// satisfies every row and the cap, each then lowered as far as the rows allow; without a
/// feasible pair under the cap, the least inflation without it.
fn solve(rows: &Rows, goal: &Goal) -> (f64, f64) {
    let feasible = |kappa: f64, cap: f64| -> Option<(f64, f64)> {
        let (a_hi, b_hi) = (kappa * goal.scale.0, kappa * goal.scale.1);
        if a_hi < goal.floor.0 || b_hi < goal.floor.1 {
            return None;
        }
        let (p, q) = goal.at_horizon;
        // the shortfall of the best a at this b: convex in b
        let shortfall = |b: f64| rows.least_a(b, goal.floor.0) - a_hi.min((cap - q * b) / p);
        let (mut lo, mut hi) = (goal.floor.1, b_hi);
        for _ in 0..100 {
            let m1 = lo + (hi - lo) / 3.0;
            let m2 = hi - (hi - lo) / 3.0;
            if shortfall(m1) <= shortfall(m2) {
                hi = m2;
            } else {
                lo = m1;
            }
        }
        let b = hi;
        (shortfall(b) <= 1e-12 * a_hi).then(|| (rows.least_a(b, goal.floor.0), b))
    };
    let search = |cap: f64| -> Option<(f64, f64)> {
        let mut hi = 1.0;
        while feasible(hi, cap).is_none() {
            hi *= 2.0;
            if hi > 1e30 {
                return None;
            }
        }
        let mut lo = 0.0;
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if feasible(mid, cap).is_some() {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        feasible(hi, cap)
    };
    let (a, _) = search(goal.cap)
        .or_else(|| search(f64::INFINITY))
        .unwrap_or((goal.floor.0, rows.least_b(goal.floor.0, goal.floor.1)));
    // each as low as the other allows: a is already the least for b
    (a, rows.least_b(a, goal.floor.1))
}

/// The constraints that hold with equality at `(a, b)`, in words.
fn binding(rows: &Rows, a: f64, b: f64, a0: f64, b0: f64, freq_hz: f64) -> String {
    let mut parts = Vec::new();
    if a <= a0 * (1.0 + 1e-9) && a0 > 0.0 {
        parts.push("the noise density estimate".to_string());
    }
    if b <= b0 * (1.0 + 1e-9) && b0 > 0.0 {
        parts.push("the random walk estimate".to_string());
    }
    let mut tight: Vec<(bool, usize)> = (0..rows.r.len())
        .filter(|&i| {
            let lhs = a * rows.u[i] + b * rows.v[i];
            rows.r[i] > 0.0 && lhs <= rows.r[i] * (1.0 + 1e-6)
        })
        .map(|i| rows.what[i])
        .collect();
    tight.dedup_by_key(|t| (t.0, t.1 / 2));
    for (allan, c) in tight.into_iter().take(3) {
        parts.push(format!(
            "{} at {:.3e} s",
            if allan {
                "the Allan variance"
            } else {
                "the integrated error"
            },
            c as f64 / freq_hz
        ));
    }
    parts.join(", ")
}

impl AxisCalibration {
    /// The white-noise + random-walk pair bounding this axis' identified model (its fit with
    /// the estimates) up to `horizon_s` (module doc), never below the plain noise density and
    /// random walk (an upper bound of an undetected term does not count as a floor).
    ///
    /// # Errors
    /// [`InputError`] for a horizon outside one sample .. 1e9 samples.
    pub fn horizon_bound(&self, horizon_s: f64) -> Result<HorizonBound, InputError> {
        let freq_hz = self.fit.freq_hz();
        let processes = self.fit.model().processes(freq_hz)?;
        let floor = |e: &Option<Estimate>| {
            e.as_ref()
                .filter(|e| e.status != EstimateStatus::UpperBound)
                .map(|e| e.value)
        };
        let mut bound = horizon_bound(
            &processes,
            freq_hz,
            horizon_s,
            floor(&self.noise_density),
            floor(&self.random_walk),
            self.random_walk.as_ref().map(|e| e.value),
        )?;
        // the inflation is over the values a plain export writes, upper bounds included
        let ratio = |new: f64, old: &Option<Estimate>| {
            old.as_ref()
                .filter(|o| o.value > 0.0)
                .map(|o| new / o.value)
        };
        bound.noise_inflation = ratio(bound.noise_density, &self.noise_density);
        bound.random_walk_inflation = ratio(bound.random_walk, &self.random_walk);
        Ok(bound)
    }
}
