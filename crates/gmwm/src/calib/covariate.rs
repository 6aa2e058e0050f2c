//! A calibration against a covariate (docs/methods.md §5.14): each axis' identified model
//! fitted with its parameters as functions of the covariate (§5.13) over windows of one
//! drifting recording, and N, B, K as curves against it with pointwise bands; the report's
//! N, B, K replaced by their values at one covariate value ([`CalibrationReport::at_covariate`])
//! or by the worst case over a range ([`CalibrationReport::worst_over`]), for the exports.
//!
//! At a covariate value `x` the model is `theta(x)`; there
//! - N = `sqrt(sum of the WN variances / f)`, K = `sqrt(sum of the RW increment variances * f)`
//!   (the forms of the WN and RW read-offs, §14.1);
//! - B = the minimum over the scales of the model's Allan deviation `sqrt(2 nu_j(theta(x)))`,
//!   divided by 0.664: the IEEE 952 read-off applied to the model rather than to the data;
//! - the bands are the `alpha/2` and `1 - alpha/2` quantiles of each quantity over draws of the
//!   coefficients from their asymptotic normal law (the sandwich covariance of §5.13), seeded.

use super::pipeline::{AxisCalibration, CalibError, Calibration, CalibrationReport, Estimate};
use crate::fit::covariate::{dependences, CovariateFit, Dependence};
use crate::fit::{FitError, FitRecording, Gmwm, Weighting};
use crate::imu::Imu;
use crate::inference::covariate::CovariateInference;
use crate::math::elementary;
use crate::model::Model;
use crate::process::sampler::{normal, SimRng};
use crate::process::{spec, Role};
use crate::units::{forms, NoiseTerm};
use nalgebra::DMatrix;
use rand::SeedableRng;
use rayon::prelude::*;
use serde::Serialize;

/// The IEEE 952 ratio of the flicker floor to the bias instability.
const FLICKER_FLOOR: f64 = 0.664;

/// Points of each curve over the recorded range (the `at` values are added).
const CURVE_POINTS: usize = 21;

/// Points of the search for the worst case over a range.
const WORST_POINTS: usize = 201;

/// How [`Calibration::covariate_curves`] runs.
#[derive(Debug, Clone, PartialEq)]
pub struct CovariateCalibrationOptions {
    /// The covariate's name (`temperature`).
    pub name: String,
    /// Its unit (`degC`), when known.
    pub unit: Option<String>,
    /// Windows the recording is cut into (at least 2).
    pub windows: usize,
    /// Covariate values added to the curves (those exported at).
    pub at: Vec<f64>,
    /// Draws of the coefficients for the bands.
    pub draws: usize,
}

impl CovariateCalibrationOptions {
    /// `name` over 8 windows, 1000 draws.
    pub fn new(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            unit: None,
            windows: 8,
            at: Vec::new(),
            draws: 1000,
        }
    }
}

/// A value with its pointwise `1 - alpha` band.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BandValue {
    /// The value at the estimate.
    pub value: f64,
    /// Lower end of the band (`None` when the coefficients have no covariance).
    pub low: Option<f64>,
    /// Upper end.
    pub high: Option<f64>,
}

/// N, B, K of one axis at one covariate value (SI, continuous time; `None` for a quantity the
/// model has no term for: K without a random walk).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CurvePoint {
    /// The covariate value.
    pub covariate: f64,
    /// White-noise density N.
    pub noise_density: Option<BandValue>,
    /// Bias instability B (the model's Allan-deviation floor / 0.664).
    pub bias_instability: Option<BandValue>,
    /// Random-walk density K.
    pub random_walk: Option<BandValue>,
}

/// One axis' parameters as functions of the covariate, and its N, B, K curves.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisCurves {
    /// Column name.
    pub column: String,
    /// Unit of N (B is in the axis' unit, K in unit*sqrt(Hz)).
    pub noise_density_unit: String,
    /// Unit of B.
    pub bias_instability_unit: String,
    /// Unit of K.
    pub random_walk_unit: String,
    /// The fit (the identified model's parameters as functions of the covariate).
    pub fit: CovariateFit,
    /// Its inference (`None`, with a note, when the sandwich failed).
    pub inference: Option<CovariateInference>,
    /// The curves, in ascending covariate.
    pub points: Vec<CurvePoint>,
    /// Whether N, B, K depend on the covariate in the chosen form (a quantity that does not
    /// keeps the whole recording's estimate, which also uses the scales the windows lose).
    pub depends: [bool; 3],
    /// What a user should know, one line each.
    pub notes: Vec<String>,
    #[serde(skip)]
    freq_hz: f64,
    #[serde(skip)]
    levels: usize,
    #[serde(skip)]
    alpha: f64,
    #[serde(skip)]
    draws: usize,
    #[serde(skip)]
    seed: u64,
}

/// A calibration's N, B, K against a covariate ([`Calibration::covariate_curves`]).
///
/// Wire format: `covariate`, `unit`, `windows`, `levels` (each window's mean covariate),
/// `range` ([lowest, highest] level), `alpha`, `axes[]` (`column`, the three units, `fit`,
/// `inference`, `points[]` of `covariate`, `noise_density`, `bias_instability`, `random_walk`
/// each `{value, low, high}` or null, `notes`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CovariateCalibration {
    /// The covariate's name.
    pub covariate: String,
    /// Its unit, when known.
    pub unit: Option<String>,
    /// Windows the recording was cut into.
    pub windows: usize,
    /// Each window's mean covariate.
    pub levels: Vec<f64>,
    /// The lowest and highest window level: where the curves are interpolated, not
    /// extrapolated.
    pub range: [f64; 2],
    /// Bands are `1 - alpha` pointwise.
    pub alpha: f64,
    /// One entry per calibrated axis of known kind.
    pub axes: Vec<AxisCurves>,
}

/// N, B, K of `model` (with values) at `freq_hz` over `levels` scales.
fn quantities(model: &Model, freq_hz: f64, levels: usize) -> [Option<f64>; 3] {
    let theta: Vec<f64> = model
        .components()
        .iter()
        .flat_map(|c| c.values.iter().map(|v| v.unwrap_or(f64::NAN)))
        .collect();
    quantities_at(model, &theta, freq_hz, levels)
}

/// N, B, K of `model`'s structure with parameters `theta`: N and K from the white-noise and
/// random-walk variances alone (so a draw whose other parameters are out of range still
/// gives them), B from the implied WV, and only when the model has a term that makes an
/// Allan-deviation floor (a Gauss–Markov or flicker term: without one the minimum is where
/// the white noise meets the random walk) and the minimum lies inside the scales (a floor
/// reached; at the longest scale the deviation is still falling).
fn quantities_at(model: &Model, theta: &[f64], freq_hz: f64, levels: usize) -> [Option<f64>; 3] {
    let (mut wn, mut rw, mut floor) = (None::<f64>, None::<f64>, false);
    let mut at = 0;
    for c in model.components() {
        let v = theta.get(at).copied().filter(|v| v.is_finite());
        at += c.kind.n_params();
        let role = spec(c.kind).role;
        floor |= matches!(role, Role::Correlated | Role::Flicker);
        match role {
            Role::WhiteNoise => *wn.get_or_insert(0.0) += v.unwrap_or(f64::NAN),
            Role::RandomWalk => *rw.get_or_insert(0.0) += v.unwrap_or(f64::NAN),
            _ => {}
        }
    }
    let implied = || {
        let m = model.with_values(theta).ok()?;
        m.implied_wv(levels, freq_hz).ok()
    };
    // a floor: the minimum inside the scales, not at the longest (where an Allan deviation
    // still falling would put it: no floor reached, no bias instability to read off)
    let b = floor.then(implied).flatten().and_then(|w| {
        let ad: Vec<f64> = w.wv.iter().map(|&nu| (2.0 * nu).sqrt()).collect();
        if ad.iter().any(|a| !(a.is_finite() && *a > 0.0)) {
            return None;
        }
        let (at, min) = ad
            .iter()
            .copied()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        (at + 1 < ad.len()).then_some(min / FLICKER_FLOOR)
    });
    let finite = |v: f64| v.is_finite().then_some(v);
    [
        wn.and_then(|s| finite((s / freq_hz).sqrt())),
        b,
        rw.and_then(|g| finite((g * freq_hz).sqrt())),
    ]
}

/// The `p`-quantile of sorted finite values (linear interpolation).
fn quantile(sorted: &[f64], p: f64) -> Option<f64> {
    let n = sorted.len();
    if n == 0 {
        return None;
    }
    let h = p * (n - 1) as f64;
    let (lo, hi) = (h.floor() as usize, h.ceil() as usize);
    Some(sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo]))
}

impl AxisCurves {
    /// N, B, K at `x` with their bands.
    pub fn at(&self, x: f64) -> Result<CurvePoint, FitError> {
        let model = self.fit.model_at(x)?;
        let centre = quantities(&model, self.freq_hz, self.levels);
        let draws = self.coefficient_draws();
        let mut samples: [Vec<f64>; 3] = Default::default();
        for c in &draws {
            let Ok(theta) = self.fit.theta_with(c, x) else {
                continue;
            };
            let q = quantities_at(&self.fit.model, &theta, self.freq_hz, self.levels);
            for (s, q) in samples.iter_mut().zip(q) {
                if let Some(q) = q.filter(|q| q.is_finite()) {
                    s.push(q);
                }
            }
        }
        // N and K are monotone in one parameter each (WN and RW occur once in a model): their
        // bands are that parameter's band mapped, exactly; B's come from the draws
        let bands = self
            .inference
            .as_ref()
            .and_then(|i| i.band(&self.fit, x).ok());
        let mapped = |role: Role, f: &dyn Fn(f64) -> f64| -> Option<(f64, f64)> {
            let bands = bands.as_ref()?;
            let mut at = 0;
            for c in self.fit.model.components() {
                if spec(c.kind).role == role {
                    let b = bands.get(at)?;
                    return Some((f(b.ci_low?), f(b.ci_high?)));
                }
                at += c.kind.n_params();
            }
            None
        };
        let f = self.freq_hz;
        let exact = [
            mapped(Role::WhiteNoise, &|s| (s / f).sqrt()),
            None,
            mapped(Role::RandomWalk, &|g| (g * f).sqrt()),
        ];
        let band = |k: usize| -> Option<BandValue> {
            let value = centre[k]?;
            if let Some((low, high)) = exact[k].filter(|(l, h)| l.is_finite() && h.is_finite()) {
                return Some(BandValue {
                    value,
                    low: Some(low),
                    high: Some(high),
                });
            }
            let mut s = samples[k].clone();
            s.sort_by(f64::total_cmp);
            // a band needs most draws to give the quantity
            let enough = !draws.is_empty() && s.len() * 10 >= draws.len() * 9;
            let (low, high) = if enough {
                (
                    quantile(&s, self.alpha / 2.0),
                    quantile(&s, 1.0 - self.alpha / 2.0),
                )
            } else {
                (None, None)
            };
            Some(BandValue { value, low, high })
        };
        Ok(CurvePoint {
            covariate: x,
            noise_density: band(0),
            bias_instability: band(1),
            random_walk: band(2),
        })
    }

    /// Draws of the coefficients from their asymptotic normal law (seeded: the same draws at
    /// every `x`, so the bands are smooth in `x`); empty without an inference.
    fn coefficient_draws(&self) -> Vec<Vec<f64>> {
        let Some(inf) = &self.inference else {
            return Vec::new();
        };
        let c = self.fit.flat_coefficients();
        let q = c.len();
        let psi: &DMatrix<f64> = &inf.psi;
        if psi.nrows() != q || psi.iter().any(|v| !v.is_finite()) {
            return Vec::new();
        }
        // a square root of the (symmetric, possibly semi-definite) covariance
        let eig = psi.clone().symmetric_eigen();
        let mut root = eig.eigenvectors.clone();
        for (j, &l) in eig.eigenvalues.iter().enumerate() {
            let s = l.max(0.0).sqrt();
            for i in 0..q {
                root[(i, j)] *= s;
            }
        }
        let mut rng = SimRng::seed_from_u64(self.seed);
        (0..self.draws)
            .map(|_| {
                let z: Vec<f64> = (0..q).map(|_| normal(&mut rng)).collect();
                (0..q)
                    .map(|i| c[i] + (0..q).map(|j| root[(i, j)] * z[j]).sum::<f64>())
                    .collect()
            })
            .collect()
    }
}

impl Calibration {
    /// N, B, K of every axis of `report` against `covariate` (one value per sample of `imu`,
    /// the recording `report` calibrated): module docs. Each axis' identified model is fitted
    /// with its variances affine in the covariate on the log scale (§5.13's default) over
    /// `options.windows` windows of equal length; the curves run over the windows' levels
    /// plus `options.at`.
    ///
    /// # Errors
    /// [`CalibError::Fit`], naming the column, when the covariate's length differs from the
    /// recording's, a window is too short for the model, a covariate value is not finite, the
    /// covariate is the same in every window (it cannot explain a dependence), or the fit
    /// fails.
    pub fn covariate_curves(
        &self,
        imu: &Imu,
        report: &CalibrationReport,
        covariate: &[f64],
        options: &CovariateCalibrationOptions,
    ) -> Result<CovariateCalibration, CalibError> {
        let alpha = report.alpha;
        let freq_hz = imu.freq_hz();
        let work: Vec<(&AxisCalibration, &[f64])> = report
            .axes
            .iter()
            .filter(|a| a.kind.is_some())
            .filter_map(|a| {
                let axis = imu.axes().iter().find(|x| x.column.name == a.column)?;
                Some((a, axis.column.values.as_slice()))
            })
            .collect();
        let results: Vec<Result<(AxisCurves, Vec<f64>), CalibError>> = work
            .par_iter()
            .map(|(axis, values)| self.axis_curves(axis, values, covariate, freq_hz, options))
            .collect();
        let mut axes = Vec::with_capacity(results.len());
        let mut levels = Vec::new();
        for r in results {
            let (a, l) = r?;
            levels = l;
            axes.push(a);
        }
        let lo = levels.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = levels.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Ok(CovariateCalibration {
            covariate: options.name.clone(),
            unit: options.unit.clone(),
            windows: options.windows,
            levels,
            range: [lo, hi],
            alpha,
            axes,
        })
    }

    fn axis_curves(
        &self,
        axis: &AxisCalibration,
        values: &[f64],
        covariate: &[f64],
        freq_hz: f64,
        options: &CovariateCalibrationOptions,
    ) -> Result<(AxisCurves, Vec<f64>), CalibError> {
        let mut notes = Vec::new();
        let fit_error = |source: FitError| CalibError::Fit {
            column: axis.column.clone(),
            source,
        };
        let si = self.samples_in_si(axis, values)?;
        let (recs, levels): (Vec<FitRecording>, Vec<f64>) = crate::fit::covariate_windows(
            &si,
            covariate,
            freq_hz,
            options.windows,
            &self.options().wv,
            Weighting::default(),
        )
        .map_err(fit_error)?;
        let spread = levels.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            - levels.iter().copied().fold(f64::INFINITY, f64::min);
        let scale = levels.iter().map(|l| l.abs()).fold(1.0, f64::max);
        if spread.is_nan() || spread <= 1e-9 * scale {
            return Err(fit_error(FitError::from(crate::error::ParamError::new(
                "covariate",
                levels[0],
                format!(
                    "a covariate that varies over the recording; {} is the same in all {} windows, so it cannot explain a dependence",
                    options.name,
                    levels.len()
                ),
            ))));
        }
        let model = axis.fit.model.clone();
        let mut gmwm = Gmwm::new(model.clone()).with_seed(self.options().seed);
        if let Some(d) = self.options().draws {
            gmwm = gmwm.with_draws(d);
        }
        let (fit, inference, chosen) = self
            .chosen_dependence(&gmwm, &model, &recs, &levels, &mut notes)
            .map_err(fit_error)?;
        notes.push(chosen);
        if !fit.convergence().converged {
            notes.push(format!(
                "the fit against {} did not converge ({})",
                options.name,
                fit.convergence()
            ));
        }
        let kind = axis.kind;
        let u = axis.unit.as_str();
        let unit_of = |term: NoiseTerm| crate::units::si_unit(term, kind, u);
        let depends = quantity_dependence(&fit);
        let mut curves = AxisCurves {
            column: axis.column.clone(),
            noise_density_unit: unit_of(NoiseTerm::NoiseDensity),
            bias_instability_unit: unit_of(NoiseTerm::BiasInstability),
            random_walk_unit: unit_of(NoiseTerm::RandomWalk),
            fit,
            inference,
            points: Vec::new(),
            depends,
            notes,
            freq_hz,
            levels: axis.wv.levels(),
            alpha: self.options().wv.alpha,
            draws: options.draws,
            seed: self.options().seed,
        };
        let lo = levels.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = levels.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let mut xs: Vec<f64> = (0..CURVE_POINTS)
            .map(|k| lo + (hi - lo) * k as f64 / (CURVE_POINTS - 1) as f64)
            .chain(options.at.iter().copied())
            .collect();
        xs.sort_by(f64::total_cmp);
        xs.dedup();
        curves.points = xs
            .iter()
            .map(|&x| curves.at(x))
            .collect::<Result<_, FitError>>()
            .map_err(fit_error)?;
        Ok((curves, levels))
    }
}

impl Calibration {
    /// The dependence form with the smallest WIC (docs/methods.md §5.14): each variance either
    /// constant or affine in the covariate (log scale), the other parameters constant; every
    /// combination when the model has at most [`MAX_EXHAUSTIVE`] variances, else all affine
    /// and each one constant in turn. Returns the fit, its inference and a note naming the
    /// choice.
    fn chosen_dependence(
        &self,
        gmwm: &Gmwm,
        model: &Model,
        recs: &[FitRecording],
        levels: &[f64],
        notes: &mut Vec<String>,
    ) -> Result<(CovariateFit, Option<CovariateInference>, String), FitError> {
        let all = dependences(model, &[])?;
        let variances: Vec<usize> = all
            .iter()
            .enumerate()
            .filter(|(_, d)| **d != Dependence::Constant)
            .map(|(i, _)| i)
            .collect();
        let m = variances.len();
        let masks: Vec<u64> = if m <= MAX_EXHAUSTIVE {
            (0..1u64 << m).collect()
        } else {
            let full = (1u64 << m) - 1;
            std::iter::once(full)
                .chain((0..m).map(|k| full & !(1 << k)))
                .collect()
        };
        let alpha = self.options().wv.alpha;
        let seed = self.options().seed;
        let candidates: Vec<(u64, Vec<Dependence>)> = masks
            .into_iter()
            .map(|mask| {
                let mut d = vec![Dependence::Constant; all.len()];
                for (k, &i) in variances.iter().enumerate() {
                    if mask & (1 << k) != 0 {
                        d[i] = all[i];
                    }
                }
                (mask, d)
            })
            .collect();
        let fits: Vec<(u64, FitAndInference)> = candidates
            .par_iter()
            .map(|(mask, d)| {
                let r = gmwm
                    .fit_covariate(recs, levels, d)
                    .and_then(|f| Ok((f.inference(alpha, seed)?, f)))
                    .map(|(i, f)| (f, i));
                (*mask, r)
            })
            .collect();
        let lo = levels.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = levels.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        // a variance changing by more than MAX_CHANGE over the recorded range is the windows'
        // identification failing (a term the short windows cannot see pushed to zero at one
        // end), not the covariate's effect: such forms are not chosen
        let plausible = |f: &CovariateFit| {
            f.coefficients.iter().all(|c| {
                c.get(1)
                    .is_none_or_compat(|s| s.abs() * (hi - lo) <= elementary::log(MAX_CHANGE))
            })
        };
        let mut implausible = 0;
        let best = fits
            .iter()
            .filter_map(|(mask, r)| {
                let (f, i) = r.as_ref().ok()?;
                if !plausible(f) {
                    implausible += 1;
                    return None;
                }
                let w = i.wic(f);
                w.is_finite().then_some((*mask, w))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if implausible > 0 {
            notes.push(format!(
                "{implausible} dependence form(s) left out: a variance changing more than {MAX_CHANGE}x over the recorded range (the windows cannot tell such a term)"
            ));
        }
        let labels: Vec<String> = fits
            .iter()
            .find_map(|(_, r)| r.as_ref().ok())
            .map(|(f, _)| f.param_names().to_vec())
            .unwrap_or_default();
        let names = |mask: u64| -> String {
            let on: Vec<&str> = variances
                .iter()
                .enumerate()
                .filter(|(k, _)| mask & (1 << k) != 0)
                .filter_map(|(_, &i)| labels.get(i).map(String::as_str))
                .collect();
            if on.is_empty() {
                "none".into()
            } else {
                on.join(", ")
            }
        };
        match best {
            Some((mask, wic)) => {
                let (_, r) = fits
                    .into_iter()
                    .find(|(m, _)| *m == mask)
                    .expect("the best is one");
                let (fit, inference) = r?;
                let note = format!(
                    "depends on the covariate (log-affine), chosen by WIC among {} forms: {} (WIC {:.2})",
                    candidates.len(),
                    names(mask),
                    wic
                );
                Ok((fit, Some(inference), note))
            }
            None => {
                // no form has an inference: the default form without bands
                let fit = gmwm.fit_covariate(recs, levels, &all)?;
                notes.push(
                    "no bands: the covariance of the coefficients failed for every dependence form"
                        .into(),
                );
                let note = format!(
                    "depends on the covariate (log-affine): {}",
                    names((1 << m) - 1)
                );
                Ok((fit, None, note))
            }
        }
    }
}

/// A candidate form's fit with its inference.
type FitAndInference = Result<(CovariateFit, CovariateInference), FitError>;

/// `Option::is_none_or` (Rust 1.82) for the crate's MSRV.
trait IsNoneOr<T> {
    fn is_none_or_compat(&self, f: impl FnOnce(&T) -> bool) -> bool;
}

impl<T> IsNoneOr<T> for Option<T> {
    fn is_none_or_compat(&self, f: impl FnOnce(&T) -> bool) -> bool {
        self.as_ref().map_or(true, f)
    }
}

/// The largest change of a variance over the recorded range a chosen form may show.
const MAX_CHANGE: f64 = 100.0;

/// Variances whose every constant/affine combination is fitted (2^3 = 8 fits); beyond, all
/// affine and each one constant in turn.
const MAX_EXHAUSTIVE: usize = 3;

/// Whether N, B, K depend on the covariate in `fit`'s form: N through a white-noise
/// variance, K through a random-walk one, B through any parameter.
fn quantity_dependence(fit: &CovariateFit) -> [bool; 3] {
    let mut out = [false; 3];
    let mut at = 0;
    for c in fit.model.components() {
        let n = c.kind.n_params();
        let varies = fit.dependence[at..at + n]
            .iter()
            .any(|d| *d != Dependence::Constant);
        match spec(c.kind).role {
            Role::WhiteNoise => out[0] |= varies,
            Role::RandomWalk => out[2] |= varies,
            _ => {}
        }
        out[1] |= varies;
        at += n;
    }
    out
}

/// Which of N, B, K a replacement takes.
const TERMS: [NoiseTerm; 3] = [
    NoiseTerm::NoiseDensity,
    NoiseTerm::BiasInstability,
    NoiseTerm::RandomWalk,
];

impl CalibrationReport {
    /// Replaces each axis' N, B, K by their values at covariate value `x` (with their bands
    /// as intervals), for the exports; a note on each axis says so, and whether `x` lies
    /// outside the recorded range (extrapolated).
    ///
    /// # Errors
    /// [`CalibError::Fit`] for a non-finite `x`.
    pub fn at_covariate(
        &mut self,
        curves: &CovariateCalibration,
        x: f64,
    ) -> Result<(), CalibError> {
        self.for_each_curve(curves, x, x, |axis, c, r, freq_hz| {
            let p = c.at(x).map_err(|e| axis_error(axis, e))?;
            let (name, unit, outside) = (r.name, &r.unit, &r.outside);
            let at = format!("at {name} {}{unit}", fmt_level(x));
            let kept = replace(axis, &p, c.depends, [&at, &at, &at], freq_hz);
            axis.notes.push(format!(
                "N, B, K {at}, from the fit of its parameters against {name} (docs/methods.md §5.14){outside}{}",
                kept_note(&kept, name)
            ));
            Ok(())
        })
    }

    /// Calls `f` with each axis that has a curve in `curves`, the curve, how the covariate
    /// reads (over `[lo, hi]`) and the rate: the walk [`Self::at_covariate`] and
    /// [`Self::worst_over`] share.
    fn for_each_curve(
        &mut self,
        curves: &CovariateCalibration,
        lo: f64,
        hi: f64,
        mut f: impl FnMut(
            &mut AxisCalibration,
            &AxisCurves,
            &CovariateReading<'_>,
            f64,
        ) -> Result<(), CalibError>,
    ) -> Result<(), CalibError> {
        let reading = CovariateReading {
            name: &curves.covariate,
            unit: curves
                .unit
                .as_deref()
                .map(|u| format!(" {u}"))
                .unwrap_or_default(),
            outside: outside_note(curves, lo, hi),
        };
        let freq_hz = self.freq_hz;
        for axis in &mut self.axes {
            let Some(c) = curves.axes.iter().find(|c| c.column == axis.column) else {
                continue;
            };
            f(axis, c, &reading, freq_hz)?;
        }
        Ok(())
    }

    /// Replaces each axis' N, B, K by their largest values over covariate values in
    /// `[lo, hi]` (each at its own worst value, with its band there), for a filter that must
    /// hold over the whole range; a note on each axis says where each maximum is.
    ///
    /// # Errors
    /// [`CalibError::Input`] for a non-finite or empty range; [`CalibError::Fit`] when a curve
    /// cannot be evaluated.
    pub fn worst_over(
        &mut self,
        curves: &CovariateCalibration,
        lo: f64,
        hi: f64,
    ) -> Result<(), CalibError> {
        if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            return Err(crate::InputError::from(crate::error::ParamError::new(
                "over",
                format!("{lo}:{hi}"),
                "a range LO:HI of finite values with LO <= HI",
            ))
            .into());
        }
        self.for_each_curve(curves, lo, hi, |axis, c, r, freq_hz| {
            let (name, unit, outside) = (r.name, &r.unit, &r.outside);
            // the point estimates on a fine grid: the worst x of each quantity
            let mut worst: [Option<(f64, f64)>; 3] = [None; 3];
            for k in 0..WORST_POINTS {
                let x = lo + (hi - lo) * k as f64 / (WORST_POINTS - 1) as f64;
                let m = c.fit.model_at(x).map_err(|e| axis_error(axis, e))?;
                let q = quantities(&m, c.freq_hz, c.levels);
                for (w, v) in worst.iter_mut().zip(q) {
                    if let Some(v) = v.filter(|v| v.is_finite()) {
                        if w.is_none_or_compat(|&(_, best)| v > best) {
                            *w = Some((x, v));
                        }
                    }
                }
            }
            let mut point = CurvePoint {
                covariate: f64::NAN,
                noise_density: None,
                bias_instability: None,
                random_walk: None,
            };
            let mut sources = [String::new(), String::new(), String::new()];
            for (k, w) in worst.iter().enumerate() {
                let Some((x, _)) = *w else { continue };
                let p = c.at(x).map_err(|e| axis_error(axis, e))?;
                let value = [p.noise_density, p.bias_instability, p.random_walk][k];
                match k {
                    0 => point.noise_density = value,
                    1 => point.bias_instability = value,
                    _ => point.random_walk = value,
                }
                sources[k] = format!(
                    "worst case over {name} {}..{}{unit}, at {}{unit}",
                    fmt_level(lo),
                    fmt_level(hi),
                    fmt_level(x)
                );
            }
            let kept = replace(
                axis,
                &point,
                c.depends,
                [&sources[0], &sources[1], &sources[2]],
                freq_hz,
            );
            axis.notes.push(format!(
                "N, B, K are the largest over {name} {}..{}{unit}, from the fit of its parameters against {name} (docs/methods.md §5.14){outside}{}",
                fmt_level(lo),
                fmt_level(hi),
                kept_note(&kept, name)
            ));
            Ok(())
        })
    }
}

fn axis_error(axis: &AxisCalibration, source: FitError) -> CalibError {
    CalibError::Fit {
        column: axis.column.clone(),
        source,
    }
}

/// How a covariate reads in the notes: its name, its unit as a suffix (` degC`, or empty) and
/// the note on covariate values outside the recorded range.
struct CovariateReading<'a> {
    name: &'a str,
    unit: String,
    outside: String,
}

/// `; X is outside the recorded range A..B: extrapolated` when `[lo, hi]` leaves it.
fn outside_note(curves: &CovariateCalibration, lo: f64, hi: f64) -> String {
    let [a, b] = curves.range;
    if lo < a || hi > b {
        let unit = curves
            .unit
            .as_deref()
            .map(|u| format!(" {u}"))
            .unwrap_or_default();
        format!(
            "; outside the recorded range {}..{}{unit} the curves are extrapolated",
            fmt_level(a),
            fmt_level(b)
        )
    } else {
        String::new()
    }
}

/// A covariate level with at most 3 decimals and no trailing zeros.
pub(crate) fn fmt_level(x: f64) -> String {
    let s = format!("{x:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.to_owned()
    }
}

/// Puts N, B, K of `p` into the axis: each that depends on the covariate (`depends`) and has
/// a band at `p`; the others keep the whole recording's estimate. Returns the names kept.
fn replace(
    axis: &mut AxisCalibration,
    p: &CurvePoint,
    depends: [bool; 3],
    sources: [&str; 3],
    freq_hz: f64,
) -> Vec<&'static str> {
    let mut kept = Vec::new();
    let values: Vec<Option<BandValue>> = [p.noise_density, p.bias_instability, p.random_walk]
        .into_iter()
        .zip(depends)
        .zip(["N", "B", "K"])
        .map(|((v, d), name)| {
            let usable = d && v.is_some_and(|b| b.low.is_some() && b.high.is_some());
            if !usable {
                kept.push(name);
            }
            v.filter(|_| usable)
        })
        .collect();
    let kind = axis.kind;
    let unit = axis.unit.clone();
    let slots: [&mut Option<Estimate>; 3] = [
        &mut axis.noise_density,
        &mut axis.bias_instability,
        &mut axis.random_walk,
    ];
    for (((slot, v), term), source) in slots.into_iter().zip(values).zip(TERMS).zip(sources) {
        let (Some(v), Some(old)) = (v, slot.as_mut()) else {
            continue;
        };
        old.value = v.value;
        old.ci_low = v.low;
        old.ci_high = v.high;
        old.source = format!("{source}: {}", old.source);
        old.forms = Some(forms(term, kind, &unit, v.value, freq_hz));
    }
    kept
}

/// `; B, K are the whole recording's (they do not depend on T in the chosen form, or the
/// windows do not determine them)`, or nothing.
fn kept_note(kept: &[&str], name: &str) -> String {
    if kept.is_empty() {
        String::new()
    } else {
        format!(
            "; {} kept from the whole recording (not dependent on {name} in the chosen form, or not determined by the windows)",
            kept.join(", ")
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantities_of_wn_and_rw() {
        let m: Model = "WN(sigma2=4e-4)+RW(gamma2=1e-10)".parse().unwrap();
        let [n, b, k] = quantities(&m, 100.0, 12);
        assert!((n.unwrap() - (4e-4f64 / 100.0).sqrt()).abs() < 1e-15);
        assert!((k.unwrap() - (1e-10f64 * 100.0).sqrt()).abs() < 1e-15);
        // no Gauss–Markov or flicker term: no floor, no B
        assert!(b.is_none());
        // the Allan deviation's minimum over the dyadic scales, / 0.664
        // (the random walk meets the white noise at 3.5 s: a floor inside the 41 s of scales)
        let m: Model = "GM(beta=0.5, sigma2_gm=1e-6)+WN(sigma2=4e-4)+RW(gamma2=1e-8)"
            .parse()
            .unwrap();
        let [_, b, _] = quantities(&m, 100.0, 12);
        let w = m.implied_wv(12, 100.0).unwrap();
        let min =
            w.wv.iter()
                .map(|v| (2.0 * v).sqrt())
                .fold(f64::INFINITY, f64::min);
        assert!((b.unwrap() - min / 0.664).abs() < 1e-15);
        // an AR1 alone: its Allan deviation still falls at the longest scale, no floor
        let only: Model = "AR1(phi=0.9, sigma2=1e-4)".parse().unwrap();
        let [n, b, k] = quantities(&only, 100.0, 12);
        assert!(n.is_none() && k.is_none() && b.is_none());
    }

    #[test]
    fn quantile_interpolates() {
        let s = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(quantile(&s, 0.5), Some(3.0));
        assert_eq!(quantile(&s, 0.125), Some(1.5));
        assert_eq!(quantile(&[], 0.5), None);
        assert_eq!(fmt_level(5.0), "5");
        assert_eq!(fmt_level(-0.0001), "0");
        assert_eq!(fmt_level(20.12345), "20.123");
    }
}
