//! How long to record (docs/methods.md §18): the predicted interval half-widths of N, B, K
//! and each correlation time of a model for recording lengths from minutes to days, and the
//! length a target needs.
//!
//! # The prediction
//! At a length of `n` samples (levels `J = default_levels(n)`, as a calibration takes):
//! `theta_hat ~ N(theta, Psi)`, `Psi = H V H'`, `H = (A' Omega A)^{-1} A' Omega` (the sandwich of
//! docs/methods.md §7.1) with
//! - `A` the Jacobian of the implied WV at the model's values,
//! - `Omega` the fit's weights at their expected value: `1 / (hi_j - lo_j)^2` of the
//!   chi-square interval of the implied WV `nu_j` with `eta_j = max(M_j / 2^j, 1)`,
//! - `V` the exact covariance of the WV at length `n` (`crate::variance::implied_cov`), for
//!   a model of WN, QN, RW, DR, AR1/GM, MA1 and ARMA11 terms. The other terms enter `V`
//!   through a stand-in (stated in the plan's notes): flicker as the Gauss–Markov terms, one
//!   per three octaves, whose summed WV matches flicker's over the levels (non-negative least
//!   squares on the relative error, below 1% in practice); the sensor filter `MAF(L)` as the
//!   white noise it is beyond its `L` samples; a sinusoid is left out (its WV sits at its own
//!   levels and leaves the others' variance alone).
//!
//! A quantity `q(theta)` (N from the white-noise terms, K from the random walk, B from the
//! flicker term, each correlation time from its Gauss–Markov / AR1 term) gets the
//! delta-method log-scale standard error `s = |grad ln q| Psi`, and the relative half-width
//! `sinh(z s)` of its interval `q exp(+- z s)`. B of a model without flicker is the IEEE 952
//! read-off of the Allan deviation's minimum over the levels: with `AV(2^(j-1)) = 2 nu2_j`,
//! `s` is half the spread of `ln min_j nu2_hat_j` over 4000 seeded log-normal draws of the WV
//! with covariance `V` (near a flat floor the minimum of several levels varies less than any one
//! level; one level's `sqrt(V_jj) / (2 nu_j)` predicted ±39% there). (The read-off's own chi-square
//! interval, with the conservative `eta_j`, is wider: at one hour of the MEMS truth of
//! `crate::tests::plan`, ±70% against the ±27% spread of the read-off.)
//!
//! The prediction holds for the model given; what selecting a model adds to the spread is the
//! self-audit's business (docs/methods.md §19).

use super::ieee::RELIABLE_SPAN;
use super::pipeline::CalibError;
use crate::error::{InputError, ParamError};
use crate::inference::asymptotic::{sandwich, z_value, ZConvention};
use crate::math::elementary;
use crate::model::Model;
use crate::process::{Gm, LatentProcess, Process};
use crate::variance::ci::{eta3, interval_unchecked};
use crate::variance::default_levels;
use crate::variance::implied_cov::exact_covariance_of;
use crate::wavelet::{Transform, WaveletFilter};
use nalgebra::DMatrix;
use rayon::prelude::*;
use serde::Serialize;

/// The default recording lengths of a plan, s: 10 min, 30 min, 1, 3, 6, 12, 24, 48 h, 7 days.
pub const PLAN_LENGTHS_S: [f64; 9] = [
    600.0, 1800.0, 3600.0, 10800.0, 21600.0, 43200.0, 86400.0, 172800.0, 604800.0,
];

/// Longest length a target is searched to, s (30 days).
const LONGEST_TARGET_S: f64 = 30.0 * 86400.0;

/// A quantity and its predicted precision at each length.
///
/// Wire format: `name` (`N`, `B`, `K`, `T1`, ...), `value`, `unit` (per second: `N` in
/// unit/sqrt(Hz), `K` in unit·sqrt(Hz), `B` in the data unit, `T` in s), `source` (which term,
/// and how its interval is formed), `half_width` (the relative half-width of the `1 - alpha`
/// interval at each of the plan's lengths, 0.1 = ±10%; null where the length is too short to
/// estimate it).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlannedQuantity {
    /// `N`, `B`, `K`, `T1`, `T2`, ...
    pub name: String,
    /// Its value in the model.
    pub value: f64,
    /// Its unit (`u` the data unit).
    pub unit: String,
    /// Which term, and how its interval is formed.
    pub source: String,
    /// Relative half-width at each length.
    pub half_width: Vec<Option<f64>>,
    /// The index of the process (in `Model::processes` order) a correlation time belongs to.
    #[serde(skip)]
    pub(crate) process: Option<usize>,
}

/// The shortest length meeting a target.
///
/// Wire format: `quantity`, `half_width` (the target, relative), `length_s` (null when not
/// met within 30 days).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlanTarget {
    /// The quantity's name.
    pub quantity: String,
    /// The target relative half-width.
    pub half_width: f64,
    /// The shortest length meeting it, s.
    pub length_s: Option<f64>,
}

/// A plan: the model's quantities' precision against the recording length.
///
/// Wire format: `model`, `freq_hz`, `alpha`, `lengths_s`, `quantities`
/// ([`PlannedQuantity`]), `targets` ([`PlanTarget`]), `notes`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Plan {
    /// The model planned for, with its values.
    pub model: String,
    /// Sampling rate, Hz.
    pub freq_hz: f64,
    /// Every interval is at `1 - alpha`.
    pub alpha: f64,
    /// The recording lengths, s.
    pub lengths_s: Vec<f64>,
    /// N, B, K and the correlation times.
    pub quantities: Vec<PlannedQuantity>,
    /// The lengths the targets need.
    pub targets: Vec<PlanTarget>,
    /// How the prediction was made where it is not exact, one line each.
    pub notes: Vec<String>,
}

impl Plan {
    /// The predicted precision of `model` (every value given) at `freq_hz` for recordings of
    /// `lengths_s`, and the shortest length meeting each of `targets` (quantity name,
    /// relative half-width).
    ///
    /// # Errors
    /// [`CalibError::Input`] for a model with a missing value or a term the prediction does
    /// not cover (a generic ARMA), a bad rate, length, alpha or target.
    pub fn new(
        model: &Model,
        freq_hz: f64,
        lengths_s: &[f64],
        alpha: f64,
        targets: &[(String, f64)],
    ) -> Result<Self, CalibError> {
        if !model.is_fully_specified() {
            return Err(InputError::from(ParamError::new(
                "model",
                model.to_string(),
                "every value given, e.g. WN(sigma2=1e-6)+RW(gamma2=1e-12)",
            ))
            .into());
        }
        let planner = Planner::new(model, freq_hz, alpha)?;
        for &l in lengths_s {
            if !(l.is_finite() && l * freq_hz >= 16.0) {
                return Err(InputError::from(ParamError::new(
                    "length",
                    l,
                    "a recording length in seconds of at least 16 samples",
                ))
                .into());
            }
        }
        let columns: Vec<Vec<Option<f64>>> = lengths_s
            .par_iter()
            .map(|&l| planner.half_widths(l))
            .collect::<Result<_, _>>()?;
        let quantities = planner
            .quantities
            .iter()
            .enumerate()
            .map(|(i, q)| PlannedQuantity {
                name: q.name.clone(),
                value: q.value,
                unit: q.unit.clone(),
                source: q.source.clone(),
                half_width: columns.iter().map(|c| c[i]).collect(),
                process: q.process,
            })
            .collect();
        let mut out_targets = Vec::new();
        let mut notes = planner.notes.clone();
        for (name, goal) in targets {
            let Some(index) = planner.quantities.iter().position(|q| &q.name == name) else {
                let names: Vec<&str> = planner.quantities.iter().map(|q| q.name.as_str()).collect();
                notes.push(format!(
                    "target {name}: not a quantity of this model (it has {})",
                    names.join(", ")
                ));
                continue;
            };
            if !(goal.is_finite() && *goal > 0.0) {
                return Err(InputError::from(ParamError::new(
                    "target",
                    goal,
                    "a relative half-width > 0, e.g. K=20%",
                ))
                .into());
            }
            out_targets.push(PlanTarget {
                quantity: name.clone(),
                half_width: *goal,
                length_s: planner.length_for(index, *goal)?,
            });
        }
        Ok(Self {
            model: model.to_string(),
            freq_hz,
            alpha,
            lengths_s: lengths_s.to_vec(),
            quantities,
            targets: out_targets,
            notes,
        })
    }
}

/// What a quantity is a function of.
#[derive(Debug, Clone, PartialEq)]
enum Of {
    /// `sqrt(sum of the long-run variances / f)` over these terms: WN and MAF (the variance
    /// at this offset), and AR1 terms faster than a sample (`phi` at the offset, `sigma2`
    /// after it; long-run variance `sigma2 / (1 - phi)^2`), which a calibration reports as
    /// white noise.
    WhiteDensity(Vec<(usize, bool)>),
    /// `sqrt(gamma2 f)` of the parameter.
    RandomWalk(usize),
    /// `sqrt(b2)` of the parameter.
    Flicker(usize),
    /// The IEEE read-off of B (no parameter).
    AllanMinimum,
    /// The correlation time of the AR1 (`phi`, index) or GM (`beta`, index) parameter.
    CorrelationTime { index: usize, gm: bool },
}

#[derive(Debug, Clone)]
struct Quantity {
    name: String,
    value: f64,
    unit: String,
    source: String,
    of: Of,
    /// The process a correlation time belongs to.
    process: Option<usize>,
}

/// The model prepared once for every length.
struct Planner {
    model: Model,
    theta: Vec<f64>,
    freq_hz: f64,
    alpha: f64,
    z: f64,
    /// The processes `V` is computed for (the model's, or their stand-ins).
    quantities: Vec<Quantity>,
    notes: Vec<String>,
}

impl Planner {
    fn new(model: &Model, freq_hz: f64, alpha: f64) -> Result<Self, CalibError> {
        let z = z_value(alpha, ZConvention::TwoSided).map_err(InputError::from)?;
        let processes = model.processes(freq_hz)?;
        let theta: Vec<f64> = model
            .values()
            .into_iter()
            .map(|v| v.unwrap_or(0.0))
            .collect();
        let mut quantities = Vec::new();
        let mut notes = Vec::new();
        let mut white = Vec::new();
        let mut offset = 0;
        let mut correlated = 0;
        for (component, p) in processes.iter().enumerate() {
            let np = p.params().len();
            match p {
                Process::Wn(_) | Process::Maf(_) => white.push((offset, false)),
                // faster than a sample: white noise to a calibration (its canonical model)
                Process::Ar1(a) if correlation_time(p, freq_hz) < 1.0 / freq_hz && a.phi() > 0.0 => {
                    white.push((offset, true))
                }
                Process::Rw(r) => quantities.push(Quantity {
                    name: "K".into(),
                    value: (r.gamma2() * freq_hz).sqrt(),
                    unit: "u*sqrt(Hz)".into(),
                    source: "RW term".into(),
                    of: Of::RandomWalk(offset),
                    process: None,
                }),
                Process::Flicker(f) => quantities.push(Quantity {
                    name: "B".into(),
                    value: f.bias_instability(),
                    unit: "u".into(),
                    source: "FN term".into(),
                    of: Of::Flicker(offset),
                    process: None,
                }),
                Process::Ar1(_) | Process::Gm(_) => {
                    correlated += 1;
                    let gm = matches!(p, Process::Gm(_));
                    let t = correlation_time(p, freq_hz);
                    quantities.push(Quantity {
                        name: format!("T{correlated}"),
                        value: t,
                        unit: "s".into(),
                        source: format!("correlation time of {}[{component}]", p.name()),
                        of: Of::CorrelationTime { index: offset, gm },
                        process: Some(component),
                    });
                }
                Process::Arma(_) => {
                    return Err(InputError::from(ParamError::new(
                        "model",
                        model.to_string(),
                        "WN, QN, RW, DR, FN, MAF, SIN, AR1/GM, MA1 and ARMA11 terms (a generic ARMA has no exact WV covariance)",
                    ))
                    .into())
                }
                _ => {}
            }
            offset += np;
        }
        if !white.is_empty() {
            let s2: f64 = white.iter().map(|&w| long_run_variance(&theta, w)).sum();
            quantities.insert(
                0,
                Quantity {
                    name: "N".into(),
                    value: (s2 / freq_hz).sqrt(),
                    unit: "u/sqrt(Hz)".into(),
                    source: "white-noise terms".into(),
                    of: Of::WhiteDensity(white),
                    process: None,
                },
            );
        }
        if !quantities.iter().any(|q| q.name == "B") {
            if let Some(b) = allan_minimum_b(&processes) {
                quantities.push(Quantity {
                    name: "B".into(),
                    value: b,
                    unit: "u".into(),
                    source: "IEEE 952 read-off: min Allan deviation / 0.664 (its spread)".into(),
                    of: Of::AllanMinimum,
                    process: None,
                });
            }
        }
        // name order: N, B, K, then the correlation times
        quantities.sort_by_key(|q| match q.name.as_str() {
            "N" => 0,
            "B" => 1,
            "K" => 2,
            _ => 3,
        });
        if processes.iter().any(|p| matches!(p, Process::Flicker(_))) {
            notes.push("V (the WV covariance) of the flicker term from its stand-in: Gauss–Markov terms one per three octaves whose summed WV matches flicker's at the levels".into());
        }
        if processes.iter().any(|p| matches!(p, Process::Maf(_))) {
            notes.push(
                "V of the sensor filter MAF(L) from the white noise it is beyond its L samples"
                    .into(),
            );
        }
        if processes.iter().any(|p| matches!(p, Process::Sin(_))) {
            notes.push("V without the sinusoid (its WV sits at its own levels)".into());
        }
        Ok(Self {
            model: model.clone(),
            theta,
            freq_hz,
            alpha,
            z,
            quantities,
            notes,
        })
    }

    /// The relative half-width of every quantity at a length, s.
    fn half_widths(&self, length_s: f64) -> Result<Vec<Option<f64>>, CalibError> {
        let n = (length_s * self.freq_hz).round() as usize;
        let levels = default_levels(n, Transform::Modwt, WaveletFilter::Haar);
        if levels < 2 {
            return Ok(vec![None; self.quantities.len()]);
        }
        let f = self.freq_hz;
        let nu = self.model.implied_wv(levels, f)?.wv;
        let a_rows = self.model.jacobian(levels, f)?;
        let p = self.theta.len();
        let a = DMatrix::from_fn(levels, p, |j, k| a_rows[j][k]);
        let eta: Vec<f64> = (1..=levels).map(|j| eta3(n + 1 - (1 << j), j)).collect();
        let omega = DMatrix::from_fn(levels, levels, |j, k| {
            if j == k {
                let (lo, hi) = interval_unchecked(nu[j], eta[j], self.alpha);
                1.0 / ((hi - lo) * (hi - lo))
            } else {
                0.0
            }
        });
        let stand_in = stand_in(&self.model.processes(f)?, levels, f)?;
        let v = exact_covariance_of(&stand_in, n, levels).map_err(InputError::from)?;
        let s = sandwich(&a, &omega, &v).map_err(|e| {
            InputError::from(ParamError::new(
                "model",
                e,
                "a model whose terms the WV identifies",
            ))
        })?;
        Ok(self
            .quantities
            .iter()
            .map(|q| {
                let se_log = match &q.of {
                    Of::AllanMinimum => {
                        allan_minimum_level(&nu)?;
                        minimum_spread(&nu, &v, &readoff_levels(n, levels, self.alpha))
                    }
                    of => {
                        let g = self.log_gradient(of);
                        let var: f64 = (0..p)
                            .flat_map(|i| (0..p).map(move |k| (i, k)))
                            .map(|(i, k)| g[i] * s.psi[(i, k)] * g[k])
                            .sum();
                        Some(var.max(0.0).sqrt())
                    }
                };
                se_log.map(|s| elementary::sinh(self.z * s))
            })
            .collect())
    }

    /// The gradient of `ln q(theta)`.
    fn log_gradient(&self, of: &Of) -> Vec<f64> {
        let mut g = vec![0.0; self.theta.len()];
        match of {
            Of::WhiteDensity(terms) => {
                let sum: f64 = terms
                    .iter()
                    .map(|&w| long_run_variance(&self.theta, w))
                    .sum();
                for &(i, ar1) in terms {
                    if ar1 {
                        let (phi, s2) = (self.theta[i], self.theta[i + 1]);
                        let e = 1.0 - phi;
                        g[i] = 0.5 * 2.0 * s2 / (e * e * e) / sum;
                        g[i + 1] = 0.5 / (e * e) / sum;
                    } else {
                        g[i] = 0.5 / sum;
                    }
                }
            }
            Of::RandomWalk(i) | Of::Flicker(i) => g[*i] = 0.5 / self.theta[*i],
            Of::CorrelationTime { index, gm } => {
                if *gm {
                    // T = 1 / beta
                    g[*index] = -1.0 / self.theta[*index];
                } else {
                    // T = -1 / (f ln phi): d ln T / d phi = -1 / (phi ln phi)
                    let phi = self.theta[*index];
                    g[*index] = -1.0 / (phi * elementary::log(phi));
                }
            }
            Of::AllanMinimum => {}
        }
        g
    }

    /// The shortest length (s) whose half-width of quantity `index` is at most `goal`:
    /// a 1.25x geometric search from one minute to 30 days, then log-log interpolation.
    fn length_for(&self, index: usize, goal: f64) -> Result<Option<f64>, CalibError> {
        let mut lengths = Vec::new();
        let mut l = 60.0_f64.max(16.0 / self.freq_hz);
        while l <= LONGEST_TARGET_S {
            lengths.push(l);
            l *= 1.25;
        }
        let widths: Vec<Option<f64>> = lengths
            .par_iter()
            .map(|&l| self.half_widths(l).map(|w| w[index]))
            .collect::<Result<_, _>>()?;
        let mut previous: Option<(f64, f64)> = None;
        for (&l, w) in lengths.iter().zip(&widths) {
            let Some(w) = *w else { continue };
            if w <= goal {
                return Ok(Some(match previous {
                    Some((l0, w0)) if w0 > goal => {
                        let t = (elementary::log(w0) - elementary::log(goal))
                            / (elementary::log(w0) - elementary::log(w));
                        elementary::exp(
                            elementary::log(l0) + t * (elementary::log(l) - elementary::log(l0)),
                        )
                    }
                    _ => l,
                }));
            }
            previous = Some((l, w));
        }
        Ok(None)
    }
}

/// The long-run variance of a white term (`Of::WhiteDensity`).
fn long_run_variance(theta: &[f64], (i, ar1): (usize, bool)) -> f64 {
    if ar1 {
        theta[i + 1] / ((1.0 - theta[i]) * (1.0 - theta[i]))
    } else {
        theta[i]
    }
}

/// The correlation time of an AR1 or GM, s.
fn correlation_time(p: &Process, freq_hz: f64) -> f64 {
    match p {
        Process::Gm(g) => 1.0 / g.beta(),
        Process::Ar1(a) => -1.0 / (freq_hz * elementary::log(a.phi())),
        _ => f64::NAN,
    }
}

/// The level (index) of the Allan variance's minimum over the dyadic cluster times
/// (`AV(m) = 2 nu2(2m)`, so the implied WV's minimum), `None` at either end (no floor).
fn allan_minimum_level(nu: &[f64]) -> Option<usize> {
    let (j, _) = nu.iter().enumerate().min_by(|a, b| a.1.total_cmp(b.1))?;
    (j > 0 && j + 1 < nu.len()).then_some(j)
}

/// Which of the `levels` Haar levels of a recording of `samples` the IEEE read-off of B
/// looks at: those whose chi-square interval (`eta_j = max(M_j / 2^j, 1)`, the Allan
/// variance's at `tau = 2^(j-1)`) spans at most `RELIABLE_SPAN` (`crate::calib::ieee`).
pub(crate) fn readoff_levels(samples: usize, levels: usize, alpha: f64) -> Vec<bool> {
    (1..=levels)
        .map(|j| {
            let eta = eta3(samples + 1 - (1 << j), j);
            let (lo, hi) = interval_unchecked(1.0, eta, alpha);
            hi <= RELIABLE_SPAN * lo
        })
        .collect()
}

/// Draws of the WV from its normal law behind [`minimum_spread`].
const MINIMUM_DRAWS: usize = 4000;

/// The log-scale spread of B read off at the minimum of the Allan variance (`AV(2^(j-1)) =
/// 2 nu2_j` exactly): the minimum over the read-off's levels of WVs drawn log-normal with the
/// covariance `V` (seeded), whose
/// spread is below any one level's where neighbouring levels are near the floor;
/// `sd(ln min nu2_hat) / 2`.
fn minimum_spread(nu: &[f64], v: &DMatrix<f64>, reliable: &[bool]) -> Option<f64> {
    // on the log scale: a WV estimate is a sum of squares, right-skewed like a chi-square,
    // which a log-normal follows and a normal (reaching 0 at the coarse levels) does not
    let log_v = DMatrix::from_fn(v.nrows(), v.ncols(), |r, c| v[(r, c)] / (nu[r] * nu[c]));
    let chol = nalgebra::Cholesky::new(log_v)?;
    let l = chol.l();
    let mut rng = crate::process::sampler::stream(0x9E37_79B9, 0);
    let j = nu.len();
    let mut z = vec![0.0; j];
    let logs: Vec<f64> = (0..MINIMUM_DRAWS)
        .filter_map(|_| {
            for zi in z.iter_mut() {
                *zi = crate::process::sampler::normal(&mut rng);
            }
            let min = (0..j)
                .filter(|&r| reliable[r])
                .map(|r| elementary::log(nu[r]) + (0..=r).map(|c| l[(r, c)] * z[c]).sum::<f64>())
                .fold(f64::INFINITY, f64::min);
            min.is_finite().then_some(min)
        })
        .collect();
    let r = logs.len() as f64;
    let m = logs.iter().sum::<f64>() / r;
    let var = logs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (r - 1.0);
    Some(0.5 * var.sqrt())
}

/// B of the IEEE read-off of a model without flicker: `sqrt(min AV) / 0.664` over the
/// dyadic cluster times of a long recording (2^26 samples); `None` without an interior minimum.
fn allan_minimum_b(processes: &[Process]) -> Option<f64> {
    let levels = 26;
    let mut nu = vec![0.0; levels];
    for p in processes {
        p.add_wv(&mut nu);
    }
    let j = allan_minimum_level(&nu)?;
    Some((2.0 * nu[j]).sqrt() / 0.664)
}

/// The processes `V` is computed for (module doc).
fn stand_in(
    processes: &[Process],
    levels: usize,
    freq_hz: f64,
) -> Result<Vec<Process>, InputError> {
    let mut out = Vec::new();
    for p in processes {
        match p {
            Process::Flicker(f) => out.extend(flicker_stand_in(f.b2(), levels, freq_hz)?),
            Process::Maf(m) => out.push(crate::process::Wn::new(m.sigma2())?.into()),
            Process::Sin(_) => {}
            other => out.push(other.clone()),
        }
    }
    Ok(out)
}

/// Ratio of the correlation times of flicker's stand-in terms: three octaves (the exact
/// covariance's cost grows with the number of terms; two octaves gave the same half-widths
/// to a few percent at three times the cost).
const STAND_IN_SPACING: f64 = 8.0;

/// Gauss–Markov terms, correlation times `8^i / 2` samples, whose summed WV matches that of
/// `FN(b2)` at levels `1..=levels` (non-negative least squares on the relative error,
/// coordinate descent).
fn flicker_stand_in(b2: f64, levels: usize, freq_hz: f64) -> Result<Vec<Process>, InputError> {
    let target: Vec<f64> = (1..=levels)
        .map(|j| b2 * crate::process::flicker::unit_wv((1u64 << (j - 1)) as f64))
        .collect();
    let mut basis: Vec<(f64, Vec<f64>)> = Vec::new();
    let mut t = 0.5;
    while t < (1u64 << levels) as f64 * 4.0 {
        let beta = freq_hz / t;
        let g = Gm::new(beta, 1.0, freq_hz)?;
        let wv = g.wv(levels);
        basis.push((beta, wv.iter().zip(&target).map(|(w, y)| w / y).collect()));
        t *= STAND_IN_SPACING;
    }
    // minimise sum_j (sum_i c_i B_ij - 1)^2, c >= 0
    let k = basis.len();
    let mut c = vec![0.0; k];
    let mut resid = vec![-1.0; levels];
    for _ in 0..500 {
        for i in 0..k {
            let b = &basis[i].1;
            let bb: f64 = b.iter().map(|x| x * x).sum();
            let br: f64 = b.iter().zip(&resid).map(|(x, r)| x * r).sum();
            let new = (c[i] - br / bb).max(0.0);
            let d = new - c[i];
            if d != 0.0 {
                for (r, x) in resid.iter_mut().zip(b) {
                    *r += d * x;
                }
                c[i] = new;
            }
        }
    }
    let mut out = Vec::new();
    for (i, &ci) in c.iter().enumerate() {
        if ci > 0.0 {
            out.push(Gm::new(basis[i].0, ci, freq_hz)?.into());
        }
    }
    Ok(out)
}

/// The planning line of a calibration (docs/methods.md §18): the precision of K, B and the
/// correlation times from this recording's length `samples`, and from two and four times it,
/// under the identified `model`; `None` when the model has none of them or is not covered.
pub(crate) fn longer_recording(
    model: &Model,
    freq_hz: f64,
    samples: usize,
) -> Option<(Plan, String)> {
    let length = samples as f64 / freq_hz;
    let plan = Plan::new(
        model,
        freq_hz,
        &[length, 2.0 * length, 4.0 * length],
        0.05,
        &[],
    )
    .ok()?;
    let shown: Vec<&PlannedQuantity> = plan.quantities.iter().filter(|q| q.name != "N").collect();
    if shown.is_empty() {
        return None;
    }
    let at = |i: usize| {
        shown
            .iter()
            .map(|q| match q.half_width[i] {
                Some(w) if w <= 1.0 => format!("{} within ±{:.0}%", q.name, 100.0 * w),
                _ => format!("{} not determined", q.name),
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    let hours = |k: f64| format!("{:.1} h", k * length / 3600.0);
    let line = format!(
        "planning (gmwm plan, under the identified model): this recording gives {}; one of {} would give {}; one of {}: {}",
        at(0),
        hours(2.0),
        at(1),
        hours(4.0),
        at(2)
    );
    Some((plan, line))
}
