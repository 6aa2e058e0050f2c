//! Multi-recording GMWM (MS-GMWM, docs/methods.md §5.11): one model fitted to K recordings of
//! the same sensor, each recording's WV weighted by its own precision.
//!
//! # Estimator
//! Recording `k` (length `N_k`, `J_k` levels, empirical WV `nu2_hat_k`, diagonal weights
//! `Omega_k` of its own, e.g. the fast weights from its own CIs) contributes its own GMWM
//! objective; the pooled estimate minimises their sum
//!
//! ```text
//! Q_pool(theta) = sum_k Q_k(theta),  Q_k(theta) = sum_{j <= J_k} omega_kj (nu2_hat_kj - nu2_j(theta))^2
//! ```
//!
//! The implied WV `nu2_j(theta)` does not depend on `N_k`, so recordings of different lengths
//! share it level by level; a long recording has more levels and tighter weights and counts
//! more, as it should. It is one least-squares problem on the concatenated whitened residuals
//! (`super::Objective` in its stacked form), minimised by the crate's Levenberg–Marquardt.
//!
//! **Rate.** The model's parameters are per sample (WN, RW, AR1 phi, ...), so the recordings
//! must share one sampling rate: rates differing by more than
//! [`RATE_TOLERANCE`] (relative) are refused
//! ([`FitError::RateMismatch`]); the fit uses the first recording's rate.
//!
//! **Starting values.** Each recording is first fitted alone (the two-stage fit with the §6
//! search, [`Gmwm::fit_from_wv`] without the bootstrap rounds); the pooled objective is
//! minimised (stage 2) from each of the K separate estimates and the lowest `Q_pool` is kept.
//!
//! **Weights, two steps.** Step 1 minimises `Q_pool` with each recording's own weights (fast
//! by default, from its own CIs; diag needs the series, [`Recording::from_series`]). Step 2
//! replaces them by `omega_kj = 1 / V_k,jj(theta_1)`, the model's variance of recording k's
//! WV at level j at the step-1 estimate and `N_k` (exact, §1.10), and minimises again from
//! `theta_1`. Reason: a fast weight `1 / (hi - lo)^2` scales with `1 / nu2_hat_kj^2`, so a
//! level that came out low is weighted up and the estimate is biased down by a fraction that
//! does not shrink when recordings are added, while the standard error does: with K = 4
//! recordings the random-walk intervals of step 1 alone covered 0.908 (1000 replicates, the
//! longest recording's own fit 0.947). Step-2 weights depend on the data only through
//! `theta_1`. The bootstrap rounds of §5.2 are not run. `PooledFit::inputs` carries the
//! step-2 weights, which the sandwich uses.
//!
//! # Inference
//! Recordings are independent, so with `A` the stacked Jacobians `[A_1; ...; A_K]` (each
//! `A_k` the `J_k x p` Jacobian of the implied WV at `theta_hat`), `Omega = diag(Omega_k)`
//! and `V = diag(V_k)` (block diagonal, `V_k` the covariance of `nu2_hat_k`, exact at the
//! pooled estimate and `N_k`, docs/methods.md §1.10), the first-order expansion of the pooled
//! first-order condition `A' Omega (nu2_hat - nu2(theta_hat)) = 0` gives
//!
//! ```text
//! theta_hat - theta_0 ~ (A' Omega A)^{-1} A' Omega (nu2_hat - nu2(theta_0)),
//! Cov(theta_hat) ~ H V H',  H = (A' Omega A)^{-1} A' Omega = (sum_k A_k' Omega_k A_k)^{-1} [A_1' Omega_1, ..., A_K' Omega_K]
//! ```
//!
//! the sandwich of §7.1 on the stacked matrices ([`PooledFit::sandwich`]); the intervals are
//! those of §7.2 (log scale for variances, atanh for coefficients). The parametric bootstrap
//! ([`PooledFit::bootstrap`]) simulates every replicate's K recordings at their own lengths
//! from the pooled estimate, recomputes their WVs and fast weights and refits the pooled
//! objective from the estimate.

use super::estimates::FitEstimates;
use super::weights::FullWeights;
use super::{
    minimize, FitError, Gmwm, Objective, Parametrisation, StartInputs, Weighting, Weights,
};
use crate::imu::read::RATE_TOLERANCE;
use crate::model::Model;
use crate::progress::NoProgress;
use crate::sim::covariance::{wv_covariance, CovarianceMethod};
use crate::sim::replicate_seed;
use crate::variance::wv::{wavelet_variance, WaveletVariance, WvOptions};

use rayon::prelude::*;
use serde::Serialize;

/// Replicates of the bootstrap V used when the exact WV covariance does not cover the model
/// (as the single-recording inference, docs/methods.md §7.4).
pub(crate) const POOLED_V_REPLICATES: usize = 100;

/// One recording of a pooled fit: its WV, its weights and the search inputs (N, range).
#[derive(Debug, Clone, PartialEq)]
pub struct FitRecording {
    pub(crate) wv: WaveletVariance,
    pub(crate) weights: Weights,
    pub(crate) inputs: StartInputs,
}

impl FitRecording {
    /// The recording of the series `x` at `freq_hz`: its WV (`wv_opts`) and the weights of
    /// `weighting` (the bootstrap weighting gives the fast weights, module doc).
    ///
    /// # Errors
    /// As [`wavelet_variance`] and [`Weights::new`]; [`FitError::NotHaar`].
    pub fn from_series(
        x: &[f64],
        freq_hz: f64,
        wv_opts: &WvOptions,
        weighting: Weighting,
    ) -> Result<Self, FitError> {
        super::check_haar(wv_opts.filter)?;
        let wv = wavelet_variance(x, freq_hz, wv_opts)?;
        let weights = Weights::new(weighting, &wv, Some(x))?;
        Ok(Self {
            wv,
            weights,
            inputs: StartInputs::from_series(x),
        })
    }

    /// The recording of a precomputed WV with its fast weights (N from the WV, range 0).
    ///
    /// # Errors
    /// As [`Weights::fast`]; [`FitError::NotHaar`].
    pub fn from_wv(wv: WaveletVariance) -> Result<Self, FitError> {
        super::check_haar(wv.filter)?;
        let weights = Weights::fast(&wv)?;
        let inputs = StartInputs::from_wv(&wv);
        Ok(Self {
            wv,
            weights,
            inputs,
        })
    }

    /// The recording's WV.
    pub fn wv(&self) -> &WaveletVariance {
        &self.wv
    }

    /// Its weights.
    pub fn weights(&self) -> &Weights {
        &self.weights
    }

    /// Series length N.
    pub fn n(&self) -> usize {
        self.wv.n
    }

    /// Number of levels `J_k`.
    pub fn levels(&self) -> usize {
        self.wv.levels()
    }
}

/// The checks every pooled computation starts with: at least `min` recordings, one rate,
/// one WV estimator, and at least as many levels as parameters in each (docs/methods.md §5.11).
pub(crate) fn check_recordings(
    model: &Model,
    recordings: &[FitRecording],
    min: usize,
) -> Result<(), FitError> {
    if recordings.len() < min {
        return Err(FitError::TooFewRecordings {
            needed: min,
            found: recordings.len(),
        });
    }
    let first = &recordings[0].wv;
    let params = model.n_params();
    for (k, r) in recordings.iter().enumerate() {
        let f = r.wv.freq_hz;
        if (f - first.freq_hz).abs() > RATE_TOLERANCE * first.freq_hz {
            return Err(FitError::RateMismatch {
                recording: k + 1,
                rate: f,
                first_rate: first.freq_hz,
            });
        }
        if r.wv.robust != first.robust || r.wv.transform != first.transform {
            return Err(FitError::EstimatorMismatch { recording: k + 1 });
        }
        super::check_haar(r.wv.filter)?;
        let needed = params + usize::from(r.wv.robust.is_some());
        if r.levels() < needed {
            return Err(FitError::RecordingTooShort {
                recording: k + 1,
                n: r.n(),
                levels: r.levels(),
                params: needed,
            });
        }
    }
    Ok(())
}

/// Step 2 of the two-step weights (module doc): recording `r` (the `k`-th) weighted by the
/// diagonal of `model`'s covariance (at the fit's rate `freq_hz`) of its WV at its length (exact, or a bootstrap of
/// [`POOLED_V_REPLICATES`] seeded from `seed` and `k`).
pub(crate) fn model_variance_weights(
    r: &FitRecording,
    model: &Model,
    freq_hz: f64,
    k: usize,
    seed: u64,
) -> Result<FitRecording, FitError> {
    let v = wv_covariance(
        model,
        r.n(),
        freq_hz,
        &r.wv.options(),
        CovarianceMethod::Auto,
        POOLED_V_REPLICATES,
        replicate_seed(seed, k as u64),
        &NoProgress,
    )?;
    let diag = (0..r.levels()).map(|l| v.v[(l, l)]).collect();
    Ok(FitRecording {
        weights: Weights::from_v(diag, "model variance of the WV")?,
        ..r.clone()
    })
}

/// `Q_k = sum_j omega_kj (nu2_hat_kj - nu_j)^2`, recording `r`'s own objective at the implied
/// WV `nu` (its levels).
pub(crate) fn recording_objective(r: &FitRecording, nu: &[f64]) -> f64 {
    r.wv.wv
        .iter()
        .zip(nu)
        .zip(&r.weights.omega)
        .map(|((h, n), w)| w * (h - n) * (h - n))
        .sum()
}

/// The stacked objective of `model` over `recordings` with each one's diagonal weights, or
/// with the full weights `full[k]` when given.
pub(crate) fn pooled_objective(
    model: &Model,
    param: Parametrisation,
    recordings: &[FitRecording],
    full: Option<&[FullWeights]>,
    freq_hz: f64,
) -> Result<Objective, FitError> {
    let blocks: Vec<(&[f64], Result<&FullWeights, &Weights>)> = recordings
        .iter()
        .enumerate()
        .map(|(k, r)| {
            let w = match full {
                Some(f) => Ok(&f[k]),
                None => Err(&r.weights),
            };
            (&r.wv.wv[..], w)
        })
        .collect();
    Objective::stacked(model, param, &blocks, freq_hz)
}

/// The minimum of `objective` over several starts (theta, original parametrisation; starts
/// the transforms refuse are skipped): `(theta, Q, convergence)` of the lowest.
pub(crate) fn best_of(
    gmwm: &Gmwm,
    objective: &Objective,
    starts: &[Vec<f64>],
) -> Result<(Vec<f64>, f64, super::Convergence), FitError> {
    let (_, _, options) = gmwm.settings();
    let model = objective.model();
    let mut best: Option<(Vec<f64>, f64, super::Convergence)> = None;
    let mut first_err = None;
    for s in starts {
        let u0 = match Parametrisation::canonical_order(model, s)
            .and_then(|t| objective.parametrisation().to_u_restart(&t))
        {
            Ok(u) => u,
            Err(e) => {
                first_err.get_or_insert(e);
                continue;
            }
        };
        match minimize(objective, &u0, &options) {
            Ok(m) => {
                if !matches!(&best, Some(b) if b.1 <= m.objective) {
                    let theta = Parametrisation::canonical_order(model, &m.theta)?;
                    best = Some((theta, m.objective, m.convergence));
                }
            }
            Err(e) => {
                first_err.get_or_insert(e);
            }
        }
    }
    match (best, first_err) {
        (Some(b), _) => Ok(b),
        (None, Some(e)) => Err(e),
        (None, None) => Err(FitError::Length {
            what: "starting values",
            expected: 1,
            found: 0,
        }),
    }
}

/// A multi-recording GMWM fit (docs/methods.md §5.11).
///
/// Wire format: `model` (text with the estimates), `theta`, `param_names`, `objective`
/// (`Q_pool`), `convergence`, `freq_hz`, `reweighted` (step 2 ran), `recordings[]` (`n`, `levels`, `objective` (its
/// `Q_k` at the pooled estimate), `nu_hat`, `implied_wv`, `separate` (its own fit's `theta`
/// and `objective`)).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PooledFit {
    /// The pooled estimates; `objective` is `Q_pool`, `freq_hz` the first recording's.
    #[serde(flatten)]
    pub(crate) estimates: FitEstimates,
    pub(crate) recordings: Vec<PooledRecording>,
    #[serde(skip)]
    pub(crate) inputs: Vec<FitRecording>,
    /// Whether step 2 (model-variance weights, module doc) ran; `false`: the step-1 weights.
    pub(crate) reweighted: bool,
}

/// One recording's part of a [`PooledFit`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PooledRecording {
    /// Series length `N_k`.
    pub n: usize,
    /// Levels `J_k`.
    pub levels: usize,
    /// `Q_k(theta_hat)`, its own objective at the pooled estimate.
    pub objective: f64,
    /// Its empirical WV.
    pub nu_hat: Vec<f64>,
    /// The pooled model's implied WV at its levels.
    pub implied_wv: Vec<f64>,
    /// Its own (separate) fit's estimates, model order.
    pub separate_theta: Vec<f64>,
    /// Its own fit's objective `Q_k(theta_hat_k)`.
    pub separate_objective: f64,
}

/// The pooled estimates ([`FitEstimates`]), read through the fit: `fit.theta()`.
impl std::ops::Deref for PooledFit {
    type Target = FitEstimates;
    fn deref(&self) -> &FitEstimates {
        &self.estimates
    }
}

impl PooledFit {
    /// Per-recording parts, input order.
    pub fn recordings(&self) -> &[PooledRecording] {
        &self.recordings
    }

    /// Whether the step-2 weights (the model's WV variances at the step-1 estimate) were
    /// used; `false` when they could not be formed and the step-1 weights were kept.
    pub fn reweighted(&self) -> bool {
        self.reweighted
    }

    /// The inputs the fit was made on, with the weights of its final step.
    pub fn inputs(&self) -> &[FitRecording] {
        &self.inputs
    }
}

impl Gmwm {
    /// docs/methods.md §5.11: fits this estimator's model to all `recordings` at once (module
    /// doc): the separate fits give the starts, the pooled objective is minimised from each.
    ///
    /// ```
    /// use gmwm::{FitRecording, Gmwm};
    /// use gmwm::{simulate_model, Model, Weighting, WvOptions};
    /// let truth = Model::parse("WN(sigma2=1)+RW(gamma2=1e-4)").unwrap();
    /// let recs: Vec<FitRecording> = [4000, 8000, 16000]
    ///     .iter()
    ///     .enumerate()
    ///     .map(|(k, &n)| {
    ///         let x = simulate_model(&truth, n, 1.0, k as u64).unwrap();
    ///         FitRecording::from_series(&x, 1.0, &WvOptions::default(), Weighting::Fast).unwrap()
    ///     })
    ///     .collect();
    /// let fit = Gmwm::parse("WN()+RW()").unwrap().with_draws(2000).fit_pooled(&recs).unwrap();
    /// assert!((fit.theta()[0] - 1.0).abs() < 0.05);
    /// assert_eq!(fit.recordings().len(), 3);
    /// ```
    ///
    /// # Errors
    /// [`FitError::TooFewRecordings`] for no recording; [`FitError::RateMismatch`],
    /// [`FitError::EstimatorMismatch`], [`FitError::RecordingTooShort`] naming the recording
    /// (1-based); errors of the separate fits and the optimiser.
    pub fn fit_pooled(&self, recordings: &[FitRecording]) -> Result<PooledFit, FitError> {
        check_recordings(self.model(), recordings, 1)?;
        let separate: Vec<super::GmwmFit> = recordings
            .par_iter()
            .map(|r| self.fit_auto(&r.wv, r.weights.clone(), r.inputs))
            .collect::<Result<_, _>>()?;
        let starts: Vec<Vec<f64>> = separate.iter().map(|f| f.theta.clone()).collect();
        self.fit_pooled_from(recordings, Some(&separate), &starts)
    }

    /// The pooled fit from given starts, with the separate fits attached.
    pub(crate) fn fit_pooled_from(
        &self,
        recordings: &[FitRecording],
        separate: Option<&[super::GmwmFit]>,
        starts: &[Vec<f64>],
    ) -> Result<PooledFit, FitError> {
        let freq_hz = recordings[0].wv.freq_hz;
        let (preset, phi_order, _) = self.settings();
        let param = Parametrisation::new(self.model(), preset, phi_order, freq_hz)?;
        let param_names = param.names().to_vec();
        let objective = pooled_objective(self.model(), param.clone(), recordings, None, freq_hz)?;
        let (theta1, q1, conv1) = best_of(self, &objective, starts)?;
        // step 2 (module doc): each recording weighted by the model's variance of its WV at
        // the step-1 estimate, which does not move with the recording's own WV
        let model1 = self.model().with_values(&theta1)?;
        let step2: Result<Vec<FitRecording>, FitError> = recordings
            .iter()
            .enumerate()
            .map(|(k, r)| model_variance_weights(r, &model1, freq_hz, k, self.start_options.seed))
            .collect();
        // a step-1 model whose WV variance is not usable (a component at the edge of its
        // domain, e.g. a collapsed AR1) keeps the step-1 weights: `reweighted` says which
        let (recordings, theta, q, convergence, reweighted) = match step2 {
            Ok(recs) => {
                let objective = pooled_objective(self.model(), param, &recs, None, freq_hz)?;
                match best_of(self, &objective, std::slice::from_ref(&theta1)) {
                    Ok((theta, q, mut c)) => {
                        c.iterations += conv1.iterations;
                        c.evaluations += conv1.evaluations;
                        (recs, theta, q, c, true)
                    }
                    Err(_) => (recordings.to_vec(), theta1, q1, conv1, false),
                }
            }
            Err(_) => (recordings.to_vec(), theta1, q1, conv1, false),
        };
        let model = self.model().with_values(&theta)?;
        let jmax = recordings
            .iter()
            .map(FitRecording::levels)
            .max()
            .unwrap_or(0);
        let implied = model.implied_wv(jmax, freq_hz)?;
        let parts = recordings
            .iter()
            .enumerate()
            .map(|(k, r)| {
                let s = separate.map(|s| &s[k]);
                let j = r.levels();
                let nu = implied.wv[..j].to_vec();
                let qk = recording_objective(r, &nu);
                PooledRecording {
                    n: r.n(),
                    levels: j,
                    objective: qk,
                    nu_hat: r.wv.wv.clone(),
                    implied_wv: nu,
                    separate_theta: s.map(|s| s.theta.clone()).unwrap_or_default(),
                    separate_objective: s.map_or(f64::NAN, |s| s.objective),
                }
            })
            .collect();
        Ok(PooledFit {
            estimates: FitEstimates {
                model,
                theta,
                param_names,
                objective: q,
                convergence,
                freq_hz,
            },
            recordings: parts,
            inputs: recordings,
            reweighted,
        })
    }
}
