//! GMWM with parameters that are functions of a covariate (docs/methods.md §5.13): one model
//! fitted to K recordings made at covariate levels `x_1..x_K` (a sensor at four temperatures,
//! or one long recording cut into windows whose temperature drifts), each parameter a smooth
//! function of the covariate.
//!
//! # Estimator
//! Every parameter is a polynomial in the centred covariate on its §5.3 transformed scale
//! (log for variances and GM `beta`, logit-type for AR1 `phi`):
//!
//! ```text
//! u_i(x) = c_i0 + c_i1 (x - x0) [+ c_i2 (x - x0)^2],  theta_i(x) = g_i^{-1}(u_i(x))
//! ```
//!
//! with `x0` the mean of the recordings' covariate values and the degree of each parameter its
//! [`Dependence`] (a constant is degree 0). "The white-noise variance is affine in temperature
//! on the log scale" is `log sigma2(x) = c0 + c1 (x - x0)`: sigma2 changes by the factor
//! `exp(c1)` per unit of the covariate and stays positive at every x. The coefficients minimise
//! the stacked objective of the recordings, each at its own parameters:
//!
//! ```text
//! Q(c) = sum_k (nu2_hat_k - nu2(theta(x_k)))' Omega_k (nu2_hat_k - nu2(theta(x_k)))
//! ```
//!
//! (the objective of SMAC-Group's `ns-gmwm`, there divided by K) by the crate's
//! Levenberg–Marquardt on `c`. With every parameter constant it is the pooled objective of
//! §5.11, and the estimate is the pooled one.
//!
//! Each parameter's `g_i` is its own (the AR1/GM `phi`s are not ordered jointly,
//! [`super::PhiOrder::Free`]), so `theta_i(x)` depends on the covariate through `u_i(x)` alone.
//!
//! **Starts.** Each recording is fitted alone; per parameter, the separate estimates'
//! transformed values are regressed on the covariate (least squares, the parameter's degree):
//! one start. The median of the separate values as a constant is a second; the lower `Q` wins.
//!
//! **Weights, two steps** (as §5.11): step 1 uses each recording's own weights, step 2
//! `omega_kj = 1 / V_k,jj(theta_1(x_k))`, the model's variance of recording k's WV at its
//! step-1 parameters and length, and minimises again from step 1.
//!
//! # Inference (`crate::inference::covariate`)
//! The sandwich of §7.1 on the stacked problem in `c`: the Jacobian of recording k's implied
//! WV in `c` is `A_k G_k D_k`, `A_k` the model's Jacobian at `theta(x_k)`, `G_k = d theta / d u`
//! and `D_k` spreading `d u_i / d c_it = (x_k - x0)^t`; `V` is block-diagonal, each block the
//! exact covariance of recording k's WV at `theta(x_k)` and `N_k` (§1.10). The coefficients'
//! intervals are Wald intervals (they are unbounded); the pointwise band of `theta_i(x)` maps
//! the interval of `u_i(x)` through `g_i^{-1}`. The test of "no dependence" is the Wald test
//! of every coefficient of degree >= 1 being zero, chi-squared with as many degrees of freedom.

use super::objective::Eval;
use super::optimize::{Edge, LeastSquares};
use super::pooled::{check_recordings, model_variance_weights, recording_objective};
use super::{
    minimize, Convergence, FitError, FitRecording, Gmwm, Objective, Parametrisation, PhiOrder,
};
use crate::model::Model;
use crate::ParamError;

use rayon::prelude::*;
use serde::Serialize;
use std::fmt;
use std::str::FromStr;

/// How one parameter depends on the covariate, on its transformed scale (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Dependence {
    /// The same value at every covariate level.
    Constant,
    /// `u(x) = c0 + c1 (x - x0)`.
    Affine,
    /// `u(x) = c0 + c1 (x - x0) + c2 (x - x0)^2`.
    Quadratic,
}

impl Dependence {
    /// The polynomial's degree.
    pub fn degree(self) -> usize {
        match self {
            Dependence::Constant => 0,
            Dependence::Affine => 1,
            Dependence::Quadratic => 2,
        }
    }

    /// Number of coefficients, `degree + 1`.
    pub fn terms(self) -> usize {
        self.degree() + 1
    }
}

impl fmt::Display for Dependence {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Dependence::Constant => "constant",
            Dependence::Affine => "affine",
            Dependence::Quadratic => "quadratic",
        })
    }
}

impl FromStr for Dependence {
    type Err = ParamError;
    fn from_str(s: &str) -> Result<Self, ParamError> {
        match s.trim().to_ascii_lowercase().as_str() {
            "constant" | "const" | "0" => Ok(Dependence::Constant),
            "affine" | "linear" | "1" => Ok(Dependence::Affine),
            "quadratic" | "2" => Ok(Dependence::Quadratic),
            _ => Err(ParamError::new(
                "dependence",
                s,
                "constant, affine or quadratic",
            )),
        }
    }
}

/// docs/methods.md §5.13: each parameter's dependence from a list of `NAME=FORM` entries,
/// later entries overriding earlier ones. NAME is a parameter label (`WN[0].sigma2`,
/// `GM[1].beta`; case-insensitive), `variances` (every variance: `sigma2`, `sigma2_gm`, `q2`,
/// `gamma2`) or `all`; FORM is `constant`, `affine` or `quadratic`. Without entries, every
/// variance is affine and the rest constant (a sensor's noise levels drift with temperature,
/// its correlation times much less).
///
/// ```
/// use gmwm::{dependences, Dependence, Model};
/// let m = Model::parse("WN()+GM()").unwrap();
/// let d = dependences(&m, &["GM[1].beta=affine".to_string()]).unwrap();
/// assert_eq!(d, [Dependence::Affine, Dependence::Affine, Dependence::Affine]);
/// ```
///
/// # Errors
/// [`ParamError`] naming the entry: no `=`, an unknown name (the labels listed) or form.
pub fn dependences(model: &Model, entries: &[String]) -> Result<Vec<Dependence>, ParamError> {
    let labels: Vec<(String, bool)> = model
        .components()
        .iter()
        .enumerate()
        .flat_map(|(ci, c)| {
            let kind = c.kind;
            kind.param_names()
                .iter()
                .enumerate()
                .map(move |(i, name)| {
                    (
                        format!("{}[{ci}].{name}", kind.base_name()),
                        kind.param_domain(i) == Some(crate::process::ParamDomain::Variance),
                    )
                })
                .collect::<Vec<_>>()
        })
        .collect();
    let mut out: Vec<Dependence> = labels
        .iter()
        .map(|(_, var)| {
            if *var {
                Dependence::Affine
            } else {
                Dependence::Constant
            }
        })
        .collect();
    for entry in entries {
        let Some((name, form)) = entry.split_once('=') else {
            return Err(ParamError::new(
                "dependence",
                entry,
                "NAME=FORM, e.g. WN[0].sigma2=affine",
            ));
        };
        let form: Dependence = form.parse()?;
        let name = name.trim();
        let hit: Vec<usize> = match name.to_ascii_lowercase().as_str() {
            "all" => (0..labels.len()).collect(),
            "variances" => (0..labels.len()).filter(|&i| labels[i].1).collect(),
            _ => labels
                .iter()
                .position(|(l, _)| l.eq_ignore_ascii_case(name))
                .into_iter()
                .collect(),
        };
        if hit.is_empty() {
            let names: Vec<&str> = labels.iter().map(|(l, _)| l.as_str()).collect();
            return Err(ParamError::new(
                "dependence",
                entry,
                format!(
                    "a parameter of the model ({}), `variances` or `all`",
                    names.join(", ")
                ),
            ));
        }
        for i in hit {
            out[i] = form;
        }
    }
    Ok(out)
}

/// docs/methods.md §5.13: the covariate level of a recording or window, the mean of its
/// covariate samples `values` (a temperature channel).
///
/// # Errors
/// [`ParamError`] for no sample or a non-finite one (named by its 1-based row).
pub fn covariate_level(values: &[f64]) -> Result<f64, ParamError> {
    if values.is_empty() {
        return Err(ParamError::new(
            "covariate",
            "no sample",
            "at least one sample",
        ));
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(ParamError::new(
            "covariate",
            format!("{} at sample {}", values[i], i + 1),
            "finite values: the covariate is averaged over the recording",
        ));
    }
    // a compensated mean: temperatures of 10^8 samples keep their last digits
    let mut sum = 0.0f64;
    let mut c = 0.0f64;
    for &v in values {
        let y = v - c;
        let t = sum + y;
        c = (t - sum) - y;
        sum = t;
    }
    Ok(sum / values.len() as f64)
}

/// docs/methods.md §5.13: one recording whose covariate drifts (a temperature ramp), cut into
/// `windows` contiguous windows of equal length (the last `N mod windows` samples left out):
/// each window's WV and weights, as [`FitRecording::from_series`], and its covariate level,
/// the mean of `covariate` over the window. The windows' WVs are treated as independent: the
/// Haar filter's differences see a random walk's increments, which are, and short-memory
/// processes decorrelate within a few of their correlation times, short beside a window.
///
/// # Errors
/// [`FitError::Length`] when `covariate` and `x` differ in length; [`FitError::Input`] for
/// fewer than 2 windows, a window of fewer than 2 samples, or a non-finite covariate sample;
/// as [`FitRecording::from_series`].
pub fn covariate_windows(
    x: &[f64],
    covariate: &[f64],
    freq_hz: f64,
    windows: usize,
    wv_opts: &crate::variance::wv::WvOptions,
    weighting: super::Weighting,
) -> Result<(Vec<FitRecording>, Vec<f64>), FitError> {
    if covariate.len() != x.len() {
        return Err(FitError::Length {
            what: "covariate samples",
            expected: x.len(),
            found: covariate.len(),
        });
    }
    if windows < 2 {
        return Err(ParamError::new("windows", windows, "at least 2").into());
    }
    let len = x.len() / windows;
    if len < 2 {
        return Err(ParamError::new(
            "windows",
            windows,
            format!("at most {} for {} samples", x.len() / 2, x.len()),
        )
        .into());
    }
    let mut recs = Vec::with_capacity(windows);
    let mut levels = Vec::with_capacity(windows);
    for k in 0..windows {
        let range = k * len..(k + 1) * len;
        levels.push(covariate_level(&covariate[range.clone()]).map_err(|e| {
            ParamError::new(
                "covariate",
                e.value,
                format!("{} (window {})", e.expected, k + 1),
            )
        })?);
        recs.push(FitRecording::from_series(
            &x[range], freq_hz, wv_opts, weighting,
        )?);
    }
    Ok((recs, levels))
}

/// The coefficients' layout: parameter `i` holds `terms[i]` coefficients from `offset[i]`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Layout {
    pub(crate) dependence: Vec<Dependence>,
    pub(crate) offset: Vec<usize>,
    /// The covariate's centre `x0`.
    pub(crate) centre: f64,
}

impl Layout {
    fn new(dependence: &[Dependence], centre: f64) -> Self {
        let mut at = 0;
        let offset = dependence
            .iter()
            .map(|d| {
                let o = at;
                at += d.terms();
                o
            })
            .collect();
        Self {
            dependence: dependence.to_vec(),
            offset,
            centre,
        }
    }

    /// Number of coefficients.
    pub(crate) fn len(&self) -> usize {
        self.dependence.iter().map(|d| d.terms()).sum()
    }

    /// `(x - x0)^t` for `t = 0..=2`.
    pub(crate) fn powers(&self, x: f64) -> [f64; 3] {
        let d = x - self.centre;
        [1.0, d, d * d]
    }

    /// `u(x)`, the transformed parameters at `x`, from the coefficients `c`.
    pub(crate) fn u_at(&self, c: &[f64], x: f64) -> Vec<f64> {
        let pw = self.powers(x);
        self.dependence
            .iter()
            .zip(&self.offset)
            .map(|(d, &o)| (0..d.terms()).map(|t| c[o + t] * pw[t]).sum())
            .collect()
    }

    /// Indices of the coefficients of degree >= 1 (all of them, or parameter `i`'s).
    pub(crate) fn slopes(&self, only: Option<usize>) -> Vec<usize> {
        self.dependence
            .iter()
            .zip(&self.offset)
            .enumerate()
            .filter(|(i, _)| only.map_or(true, |o| o == *i))
            .flat_map(|(_, (d, &o))| (1..d.terms()).map(move |t| o + t))
            .collect()
    }
}

/// The stacked least-squares problem in the coefficients (module doc): one GMWM objective per
/// recording, evaluated at `u(x_k)`.
struct CovariateObjective<'a> {
    parts: &'a [Objective],
    covariates: &'a [f64],
    layout: &'a Layout,
    edges: Vec<Edge>,
}

impl<'a> CovariateObjective<'a> {
    fn new(parts: &'a [Objective], covariates: &'a [f64], layout: &'a Layout) -> Self {
        let transforms = parts[0].parametrisation().transforms();
        let edges = layout
            .dependence
            .iter()
            .zip(transforms)
            .flat_map(|(d, t)| {
                // the intercept carries the parameter's edge (a variance fading to zero at
                // every covariate level); the slopes are free
                (0..d.terms()).map(move |k| if k == 0 { Edge::of(*t) } else { Edge::Free })
            })
            .collect();
        Self {
            parts,
            covariates,
            layout,
            edges,
        }
    }
}

impl LeastSquares for CovariateObjective<'_> {
    fn n_params(&self) -> usize {
        self.layout.len()
    }

    fn levels(&self) -> usize {
        self.parts.iter().map(Objective::levels).sum()
    }

    fn buffer(&self) -> Eval {
        let (j, q) = (LeastSquares::levels(self), self.layout.len());
        Eval {
            theta: vec![0.0; q],
            dtheta: Vec::new(),
            r: vec![0.0; j],
            jac: vec![0.0; j * q],
            nu: vec![0.0; j],
        }
    }

    fn evaluate(
        &self,
        c: &[f64],
        ev: &mut Eval,
        with_jacobian: bool,
    ) -> Result<(), crate::InputError> {
        let q = self.layout.len();
        ev.theta.copy_from_slice(c);
        let mut at = 0;
        for (obj, &x) in self.parts.iter().zip(self.covariates) {
            let u = self.layout.u_at(c, x);
            let mut part = obj.buffer();
            obj.evaluate(&u, &mut part, with_jacobian)?;
            let (levels, p) = (obj.levels(), obj.n_params());
            ev.r[at..at + levels].copy_from_slice(&part.r);
            ev.nu[at..at + levels].copy_from_slice(&part.nu);
            if with_jacobian {
                let pw = self.layout.powers(x);
                for j in 0..levels {
                    let row = &mut ev.jac[(at + j) * q..(at + j + 1) * q];
                    for (i, (d, &o)) in self
                        .layout
                        .dependence
                        .iter()
                        .zip(&self.layout.offset)
                        .enumerate()
                    {
                        let dr_du = part.jac[j * p + i];
                        for t in 0..d.terms() {
                            row[o + t] = dr_du * pw[t];
                        }
                    }
                }
            }
            at += levels;
        }
        Ok(())
    }

    fn scale(&self) -> f64 {
        self.parts.iter().map(Objective::scale).sum()
    }

    fn edges(&self) -> Vec<Edge> {
        self.edges.clone()
    }
}

/// A fit whose parameters are functions of a covariate (docs/methods.md §5.13).
///
/// Wire format: `model` (the model's text without values), `param_names`, `dependence` (per
/// parameter), `centre` (x0), `coefficients` (per parameter, `[c0, c1, c2]` up to its
/// degree, on the transformed scale), `objective`, `convergence`, `freq_hz`, `reweighted`,
/// `recordings[]` (`covariate`, `n`, `levels`, `theta` (the parameters at its covariate),
/// `objective`, `nu_hat`, `implied_wv`, `separate_theta`, `separate_objective`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CovariateFit {
    #[serde(serialize_with = "crate::fit::covariate::model_text")]
    pub(crate) model: Model,
    pub(crate) param_names: Vec<String>,
    pub(crate) dependence: Vec<Dependence>,
    pub(crate) centre: f64,
    pub(crate) coefficients: Vec<Vec<f64>>,
    pub(crate) objective: f64,
    pub(crate) convergence: Convergence,
    pub(crate) freq_hz: f64,
    pub(crate) reweighted: bool,
    pub(crate) recordings: Vec<CovariateRecording>,
    #[serde(skip)]
    pub(crate) param: Parametrisation,
    #[serde(skip)]
    pub(crate) inputs: Vec<FitRecording>,
}

fn model_text<S: serde::Serializer>(m: &Model, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(&m.to_string())
}

/// One recording's part of a [`CovariateFit`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CovariateRecording {
    /// Its covariate value `x_k`.
    pub covariate: f64,
    /// Series length `N_k`.
    pub n: usize,
    /// Levels `J_k`.
    pub levels: usize,
    /// The fitted parameters at `x_k` (model order).
    pub theta: Vec<f64>,
    /// `Q_k`, its own objective at `theta(x_k)` (final weights).
    pub objective: f64,
    /// Its empirical WV.
    pub nu_hat: Vec<f64>,
    /// The implied WV at `theta(x_k)`.
    pub implied_wv: Vec<f64>,
    /// Its own (separate) fit's estimates.
    pub separate_theta: Vec<f64>,
    /// Its own fit's objective.
    pub separate_objective: f64,
}

impl CovariateFit {
    /// The model (no values).
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// Parameter labels, model order.
    pub fn param_names(&self) -> &[String] {
        &self.param_names
    }

    /// Each parameter's dependence.
    pub fn dependence(&self) -> &[Dependence] {
        &self.dependence
    }

    /// The covariate's centre `x0` (the mean of the recordings' values).
    pub fn centre(&self) -> f64 {
        self.centre
    }

    /// Per parameter, its coefficients `[c0, c1, ...]` on the transformed scale.
    pub fn coefficients(&self) -> &[Vec<f64>] {
        &self.coefficients
    }

    /// `Q(c_hat)`.
    pub fn objective(&self) -> f64 {
        self.objective
    }

    /// How the final minimisation ended.
    pub fn convergence(&self) -> Convergence {
        self.convergence
    }

    /// Sampling rate of the recordings.
    pub fn freq_hz(&self) -> f64 {
        self.freq_hz
    }

    /// Per-recording parts, input order.
    pub fn recordings(&self) -> &[CovariateRecording] {
        &self.recordings
    }

    /// Whether the step-2 weights were used.
    pub fn reweighted(&self) -> bool {
        self.reweighted
    }

    pub(crate) fn layout(&self) -> Layout {
        Layout::new(&self.dependence, self.centre)
    }

    pub(crate) fn flat_coefficients(&self) -> Vec<f64> {
        self.coefficients.iter().flatten().copied().collect()
    }

    /// The parameters at covariate value `x` (model order, original parametrisation).
    ///
    /// # Errors
    /// [`FitError::Input`] for a non-finite `x`.
    pub fn theta_at(&self, x: f64) -> Result<Vec<f64>, FitError> {
        if !x.is_finite() {
            return Err(ParamError::new("covariate value", x, "a finite number").into());
        }
        let u = self.layout().u_at(&self.flat_coefficients(), x);
        self.param.to_theta(&u)
    }

    /// The model with its values at covariate value `x`.
    ///
    /// # Errors
    /// As [`CovariateFit::theta_at`]; [`FitError::Input`] when the parameters at `x` are not a
    /// valid model (a variance overflowing far outside the recordings' range).
    pub fn model_at(&self, x: f64) -> Result<Model, FitError> {
        Ok(self.model.with_values(&self.theta_at(x)?)?)
    }

    /// The parameters at `x` with the coefficients `c` (flat, as [`Self::flat_coefficients`])
    /// in place of the estimate's: a draw of them, for bands of functions of the parameters.
    pub(crate) fn theta_with(&self, c: &[f64], x: f64) -> Result<Vec<f64>, FitError> {
        let u = self.layout().u_at(c, x);
        self.param.to_theta(&u)
    }
}

/// Least-squares coefficients of `y` on `(x - x0)^0..=degree` (normal equations, at most 3x3);
/// `None` when singular.
fn polyfit(xs: &[f64], y: &[f64], layout: &Layout, degree: usize) -> Option<Vec<f64>> {
    let n = degree + 1;
    let mut m = vec![0.0; n * n];
    let mut b = vec![0.0; n];
    for (&x, &v) in xs.iter().zip(y) {
        let pw = layout.powers(x);
        for i in 0..n {
            b[i] += pw[i] * v;
            for j in 0..n {
                m[i * n + j] += pw[i] * pw[j];
            }
        }
    }
    let a = nalgebra::DMatrix::from_row_slice(n, n, &m);
    let sol = a.lu().solve(&nalgebra::DVector::from_vec(b))?;
    sol.iter()
        .all(|v| v.is_finite())
        .then(|| sol.iter().copied().collect())
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Transformed values far beyond any fit (a component collapsed in one recording's separate
/// fit sits at `u -> -inf`) are held here, so that one recording cannot throw the starts out.
const START_CLAMP: f64 = 60.0;

impl Gmwm {
    /// docs/methods.md §5.13: fits this estimator's model to `recordings` made at the
    /// covariate values `covariates`, parameter `i` depending on the covariate as
    /// `dependence[i]` (module doc).
    ///
    /// ```
    /// use gmwm::{Dependence, FitRecording, Gmwm, Model, WvOptions, Weighting, simulate_model};
    /// // a white noise whose variance doubles every 10 degrees, four recordings
    /// let temps = [5.0, 15.0, 25.0, 35.0];
    /// let recs: Vec<FitRecording> = temps
    ///     .iter()
    ///     .enumerate()
    ///     .map(|(k, &t)| {
    ///         let s2 = 1e-4 * 2f64.powf((t - 20.0) / 10.0);
    ///         let truth = Model::parse(&format!("WN(sigma2={s2})+RW(gamma2=1e-8)")).unwrap();
    ///         let x = simulate_model(&truth, 8192, 100.0, k as u64).unwrap();
    ///         FitRecording::from_series(&x, 100.0, &WvOptions::default(), Weighting::Fast).unwrap()
    ///     })
    ///     .collect();
    /// let gmwm = Gmwm::parse("WN()+RW()").unwrap().with_draws(500);
    /// let fit = gmwm
    ///     .fit_covariate(&recs, &temps, &[Dependence::Affine, Dependence::Constant])
    ///     .unwrap();
    /// // log sigma2 rises by ln 2 / 10 per degree
    /// assert!((fit.coefficients()[0][1] - 2f64.ln() / 10.0).abs() < 0.01);
    /// ```
    ///
    /// # Errors
    /// [`FitError::Length`] when `covariates` or `dependence` do not match the recordings or
    /// the model; [`FitError::Input`] for a non-finite covariate value or fewer distinct
    /// covariate values than a dependence needs (a constant covariate cannot explain a
    /// dependence); as [`Gmwm::fit_pooled`] otherwise.
    pub fn fit_covariate(
        &self,
        recordings: &[FitRecording],
        covariates: &[f64],
        dependence: &[Dependence],
    ) -> Result<CovariateFit, FitError> {
        check_recordings(self.model(), recordings, 1)?;
        let p = self.model().n_params();
        for (what, expected, found) in [
            ("covariate values", recordings.len(), covariates.len()),
            ("dependences", p, dependence.len()),
        ] {
            if found != expected {
                return Err(FitError::Length {
                    what,
                    expected,
                    found,
                });
            }
        }
        if let Some(x) = covariates.iter().find(|x| !x.is_finite()) {
            return Err(ParamError::new("covariate value", x, "a finite number").into());
        }
        let mut distinct = covariates.to_vec();
        distinct.sort_by(f64::total_cmp);
        distinct.dedup();
        if let Some((i, d)) = dependence
            .iter()
            .enumerate()
            .find(|(_, d)| d.terms() > distinct.len())
        {
            let names = Parametrisation::new(self.model(), self.settings().0, PhiOrder::Free, 1.0)
                .map(|p| p.names()[i].clone())
                .unwrap_or_else(|_| format!("parameter {}", i + 1));
            let why = if distinct.len() == 1 {
                "a covariate that does not vary cannot explain a dependence"
            } else {
                "add recordings at other levels or choose a lower degree"
            };
            return Err(ParamError::new(
                "covariate levels",
                format!("{} distinct value(s) over the recordings", distinct.len()),
                format!(
                    "the {d} dependence of {names} needs at least {} distinct levels: {why}",
                    d.terms()
                ),
            )
            .into());
        }
        let freq_hz = recordings[0].wv.freq_hz;
        let (preset, _, options) = self.settings();
        let param = Parametrisation::new(self.model(), preset, PhiOrder::Free, freq_hz)?;
        let centre = covariates.iter().sum::<f64>() / covariates.len() as f64;
        let layout = Layout::new(dependence, centre);

        let separate: Vec<super::GmwmFit> = recordings
            .par_iter()
            .map(|r| self.fit_auto(&r.wv, r.weights.clone(), r.inputs))
            .collect::<Result<_, _>>()?;
        let u_sep: Vec<Vec<f64>> = separate
            .iter()
            .map(|f| {
                let u = param.to_u_restart(&f.theta)?;
                Ok(u.iter()
                    .map(|v| v.clamp(-START_CLAMP, START_CLAMP))
                    .collect())
            })
            .collect::<Result<_, FitError>>()?;
        let mut regression = Vec::with_capacity(layout.len());
        let mut constant = Vec::with_capacity(layout.len());
        for (i, d) in dependence.iter().enumerate() {
            let mut y: Vec<f64> = u_sep.iter().map(|u| u[i]).collect();
            let fitted = polyfit(covariates, &y, &layout, d.degree());
            let m = median(&mut y);
            regression.extend(fitted.unwrap_or_else(|| {
                let mut c = vec![0.0; d.terms()];
                c[0] = m;
                c
            }));
            constant.push(m);
            constant.extend(std::iter::repeat(0.0).take(d.degree()));
        }
        let starts = [regression, constant];

        let objectives = |recs: &[FitRecording]| -> Result<Vec<Objective>, FitError> {
            recs.iter()
                .map(|r| Objective::new(self.model(), param.clone(), &r.wv.wv, &r.weights, freq_hz))
                .collect()
        };
        let best = |objs: &[Objective], starts: &[Vec<f64>]| {
            let problem = CovariateObjective::new(objs, covariates, &layout);
            let mut best: Option<super::optimize::Minimum> = None;
            let mut first_err = None;
            for s in starts {
                match minimize(&problem, s, &options) {
                    Ok(m) => {
                        if !matches!(&best, Some(b) if b.objective <= m.objective) {
                            best = Some(m);
                        }
                    }
                    Err(e) => {
                        first_err.get_or_insert(e);
                    }
                }
            }
            best.ok_or_else(|| first_err.expect("at least one start"))
        };
        let step1 = best(&objectives(recordings)?, &starts)?;
        let at = |c: &[f64], x: f64| -> Result<Model, FitError> {
            Ok(self
                .model()
                .with_values(&param.to_theta(&layout.u_at(c, x))?)?)
        };
        let step2: Result<Vec<FitRecording>, FitError> = recordings
            .iter()
            .zip(covariates)
            .enumerate()
            .map(|(k, (r, &x))| {
                model_variance_weights(
                    r,
                    &at(&step1.theta, x)?,
                    freq_hz,
                    k,
                    self.start_options.seed,
                )
            })
            .collect();
        let (inputs, minimum, reweighted) = match step2 {
            Ok(recs) => match best(&objectives(&recs)?, std::slice::from_ref(&step1.theta)) {
                Ok(mut m) => {
                    m.convergence.iterations += step1.convergence.iterations;
                    m.convergence.evaluations += step1.convergence.evaluations;
                    (recs, m, true)
                }
                Err(_) => (recordings.to_vec(), step1, false),
            },
            Err(_) => (recordings.to_vec(), step1, false),
        };
        let c = minimum.theta;
        let mut parts = Vec::with_capacity(inputs.len());
        for ((r, &x), s) in inputs.iter().zip(covariates).zip(&separate) {
            let model = at(&c, x)?;
            let implied = model.implied_wv(r.levels(), freq_hz)?.wv;
            let qk = recording_objective(r, &implied);
            parts.push(CovariateRecording {
                covariate: x,
                n: r.n(),
                levels: r.levels(),
                theta: model
                    .values()
                    .into_iter()
                    .map(|v| v.unwrap_or(f64::NAN))
                    .collect(),
                objective: qk,
                nu_hat: r.wv.wv.clone(),
                implied_wv: implied,
                separate_theta: s.theta.clone(),
                separate_objective: s.objective,
            });
        }
        let coefficients = layout
            .dependence
            .iter()
            .zip(&layout.offset)
            .map(|(d, &o)| c[o..o + d.terms()].to_vec())
            .collect();
        Ok(CovariateFit {
            model: self.model().without_values(),
            param_names: param.names().to_vec(),
            dependence: dependence.to_vec(),
            centre,
            coefficients,
            objective: minimum.objective,
            convergence: minimum.convergence,
            freq_hz,
            reweighted,
            recordings: parts,
            param,
            inputs,
        })
    }
}
