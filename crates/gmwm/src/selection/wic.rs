//! The selection procedure (METHODS §8.6): fit the full model, bootstrap V from it, fit every
//! candidate against the same empirical WV and weights, score it, rank by WIC.

use super::candidates::{check_candidate, common_denominator, nested_candidates, same_terms};
use super::optimism::{
    asymptotic_optimism, bootstrap_optimism, d_matrix, OptimismConvention, OptimismMethod,
};
use super::SelectionError;
use crate::error::check_freq;
use crate::fit::{FitError, Gmwm, GmwmFit, StartInputs, Weights};
use crate::inference::gof::{hartlap_factor, j_test};
use crate::inference::{map_replicates, wv_bootstrap};
use crate::model::Model;
use crate::sim::replicate_seed;
use crate::variance::wv::{wavelet_variance, WaveletVariance, WvOptions};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use serde::Serialize;
use std::fmt;

/// Default number of bootstrap replicates B (the package's `B = 50`).
pub const DEFAULT_BOOTSTRAP: usize = 50;
/// Default seed (the package's 1337).
pub const DEFAULT_SEED: u64 = 1337;
/// Starting-value draws of the fresh fits behind the bootstrap GoF p-value (METHODS §7.4:
/// "a fresh guess with G = 10000 draws").
pub const DEFAULT_BOOTSTRAP_DRAWS: usize = 10_000;
/// The bootstrap replicates are seeded from `seed + 5`, as the package's `summary` (§7.5), so
/// that their random streams differ from those of the starting-value search seeded by `seed`.
const BOOTSTRAP_SEED_OFFSET: u64 = 5;

/// A WIC model selection (METHODS §8): the full model, the candidates and the settings. Build
/// with [`Wic::nested`] or [`Wic::list`], adjust with the `with_*` setters, run with
/// [`Wic::select`].
#[derive(Debug, Clone, PartialEq)]
pub struct Wic {
    full: Model,
    candidates: Vec<Model>,
    method: OptimismMethod,
    convention: OptimismConvention,
    bootstrap: usize,
    seed: u64,
    draws: Option<usize>,
    bootstrap_draws: usize,
    wv_options: WvOptions,
}

impl Wic {
    fn with_candidates(full: Model, candidates: Vec<Model>) -> Self {
        Self {
            full,
            candidates,
            method: OptimismMethod::default(),
            convention: OptimismConvention::default(),
            bootstrap: DEFAULT_BOOTSTRAP,
            seed: DEFAULT_SEED,
            draws: None,
            bootstrap_draws: DEFAULT_BOOTSTRAP_DRAWS,
            wv_options: WvOptions::default(),
        }
    }

    /// Nested selection (METHODS §8.4, `auto.imu`, `rank.models(nested = TRUE)`): every
    /// sub-model of `full` ([`nested_candidates`]); values in `full` are ignored.
    ///
    /// # Errors
    /// As [`nested_candidates`].
    pub fn nested(full: Model) -> Result<Self, SelectionError> {
        let candidates = nested_candidates(&full)?;
        Ok(Self::with_candidates(full.without_values(), candidates))
    }

    /// Selection among a user's list (METHODS §8.5, `rank.models(nested = FALSE)`): the
    /// candidates in the order given (identical term lists merged, values ignored); the common
    /// denominator ([`common_denominator`]) plays the full model and is appended as a candidate
    /// unless a given one has the same terms (which then plays the full model).
    ///
    /// # Errors
    /// As [`common_denominator`].
    pub fn list(models: &[Model]) -> Result<Self, SelectionError> {
        let denominator = common_denominator(models)?;
        let mut candidates: Vec<Model> = Vec::with_capacity(models.len() + 1);
        for m in models {
            let m = m.without_values();
            if !candidates.iter().any(|c| c.kinds() == m.kinds()) {
                candidates.push(m);
            }
        }
        let full = match candidates.iter().find(|c| same_terms(c, &denominator)) {
            Some(c) => c.clone(),
            None => {
                candidates.push(denominator.clone());
                denominator
            }
        };
        Ok(Self::with_candidates(full, candidates))
    }

    /// [`Wic::list`] from model texts (e.g. the CLI's `--candidates`); a text that does not
    /// parse is reported with its 1-based position.
    ///
    /// # Errors
    /// [`SelectionError::Parse`] and those of [`Wic::list`].
    pub fn parse_list<S: AsRef<str>>(texts: &[S]) -> Result<Self, SelectionError> {
        let models = texts
            .iter()
            .enumerate()
            .map(|(i, t)| {
                Model::parse(t.as_ref()).map_err(|source| SelectionError::Parse {
                    index: i + 1,
                    text: t.as_ref().to_string(),
                    source,
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Self::list(&models)
    }

    /// Sets the optimism estimator; default [`OptimismMethod::Asymptotic`].
    pub fn with_optimism(mut self, method: OptimismMethod) -> Self {
        self.method = method;
        self
    }

    /// Sets the asymptotic formula; default [`OptimismConvention::Corrected`] (§13.15).
    pub fn with_convention(mut self, convention: OptimismConvention) -> Self {
        self.convention = convention;
        self
    }

    /// Sets the bootstrap replicates B (of V for the asymptotic optimism, per candidate for the
    /// bootstrap one); default [`DEFAULT_BOOTSTRAP`]; at least 2.
    pub fn with_bootstrap(mut self, replicates: usize) -> Self {
        self.bootstrap = replicates;
        self
    }

    /// Sets the seed (starting values of every candidate, bootstrap); default
    /// [`DEFAULT_SEED`]. Every candidate's search restarts from it, as in the package.
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// Sets the starting-value draws G of every fit; default as [`Gmwm`]
    /// ([`default_draws`](crate::fit::start::default_draws)).
    pub fn with_draws(mut self, draws: usize) -> Self {
        self.draws = Some(draws);
        self
    }

    /// Sets the draws of the fresh fits behind the bootstrap GoF p-value; default
    /// [`DEFAULT_BOOTSTRAP_DRAWS`].
    pub fn with_bootstrap_draws(mut self, draws: usize) -> Self {
        self.bootstrap_draws = draws;
        self
    }

    /// Sets the WV estimator (classical or robust, METHODS §8.6 `robust`, `eff`, `alpha`);
    /// default [`WvOptions::default`]. `levels` applies to the data and every replicate.
    pub fn with_wv_options(mut self, options: WvOptions) -> Self {
        self.wv_options = options;
        self
    }

    /// The full model (guess mode).
    pub fn full_model(&self) -> &Model {
        &self.full
    }

    /// The candidates in processing order (guess mode).
    pub fn candidates(&self) -> &[Model] {
        &self.candidates
    }

    fn estimator(&self, model: &Model) -> Gmwm {
        let g = Gmwm::new(model.clone()).with_seed(self.seed);
        match self.draws {
            Some(d) => g.with_draws(d),
            None => g,
        }
    }

    fn check_settings(&self) -> Result<(), SelectionError> {
        if self.bootstrap < 2 {
            return Err(SelectionError::Setting {
                name: "bootstrap replicates",
                value: self.bootstrap.to_string(),
                expected: "at least 2 (a covariance needs two replicates)",
            });
        }
        if self.draws == Some(0) {
            return Err(SelectionError::Setting {
                name: "G",
                value: "0".into(),
                expected: "at least one starting-value draw",
            });
        }
        if self.method == OptimismMethod::Bootstrap && self.bootstrap_draws == 0 {
            return Err(SelectionError::Setting {
                name: "bootstrap G",
                value: "0".into(),
                expected: "at least one starting-value draw",
            });
        }
        for c in &self.candidates {
            check_candidate(c)?;
        }
        Ok(())
    }

    /// Runs the selection on the series `x` sampled at `freq_hz` (METHODS §8.6):
    ///
    /// 1. the WV of `x`, its fast weights, and the full model fitted in guess mode;
    /// 2. asymptotic optimism: `V` = full covariance of the WV over B series simulated from
    ///    the full model's estimate (reused for every candidate, a package design choice,
    ///    §13.15);
    /// 3. every candidate (in parallel; each search seeded with `seed`) fitted in guess mode
    ///    against the same WV and weights; objective, optimism, WIC, GoF p-value (the J-test of
    ///    §7.3 with `V`, or with the bootstrap optimism the bootstrap p-value of §7.4);
    /// 4. candidates sorted by WIC (a NaN WIC last; ties within [`WIC_TIE_REL`] go to the
    ///    model with fewer parameters); the first is selected.
    ///
    /// Not reproduced from the package: after scoring, its asymptotic mode replaces the
    /// optimism of a bigger model with a higher objective but lower WIC than a smaller one by
    /// the smaller one's optimism plus a random `|N(0, obj/10)|` draw; here every optimism is
    /// the formula's.
    ///
    /// Cost: one WV of `x`, B simulations and WVs of length N, one fit per candidate (with the
    /// bootstrap optimism, B simulations, WVs and two fits per candidate on top).
    ///
    /// # Errors
    /// [`SelectionError::Setting`] for B < 2 or G = 0; [`SelectionError::Engine`] for an
    /// unusable series or rate; [`SelectionError::Fit`] naming the candidate whose fit,
    /// optimism or GoF failed.
    pub fn select(&self, x: &[f64], freq_hz: f64) -> Result<ModelSelection, SelectionError> {
        self.check_settings()?;
        check_freq(freq_hz).map_err(crate::Error::from)?;
        let wv = wavelet_variance(x, freq_hz, &self.wv_options)?;
        let inputs = StartInputs::from_series(x);
        let fit_error = |m: &Model| {
            let candidate = m.to_string();
            move |source| SelectionError::Fit { candidate, source }
        };
        let full_fit = self
            .estimator(&self.full)
            .fit_from_wv(&wv, inputs)
            .map_err(fit_error(&self.full))?;
        let levels = wv.levels();
        let omega = DMatrix::from_diagonal(&DVector::from_column_slice(&full_fit.weights.omega));
        let replicate_opts = WvOptions {
            levels: Some(levels),
            ..self.wv_options
        };
        let v = match self.method {
            OptimismMethod::Asymptotic => Some(
                wv_bootstrap(
                    &full_fit.active_model().map_err(fit_error(&self.full))?,
                    x.len(),
                    freq_hz,
                    &replicate_opts,
                    self.bootstrap,
                    self.seed.wrapping_add(BOOTSTRAP_SEED_OFFSET),
                )?
                .cov,
            ),
            OptimismMethod::Bootstrap => None,
        };
        let context = Context {
            wic: self,
            wv: &wv,
            inputs,
            omega: &omega,
            v: v.as_ref(),
            replicate_opts: &replicate_opts,
        };
        let scored: Vec<(CandidateScore, GmwmFit)> = self
            .candidates
            .par_iter()
            .map(|c| {
                let fit = if c.kinds() == self.full.kinds() {
                    full_fit.clone()
                } else {
                    self.estimator(c).fit_from_wv(&wv, inputs)?
                };
                let score = context.score(c, &fit)?;
                Ok((score, fit))
            })
            .map(|r: Result<_, FitError>| r)
            .zip(self.candidates.par_iter())
            .map(|(r, c)| r.map_err(fit_error(c)))
            .collect::<Result<_, _>>()?;
        let wics: Vec<f64> = scored.iter().map(|s| s.0.wic).collect();
        let params: Vec<usize> = scored.iter().map(|s| s.0.model.n_params()).collect();
        let order = rank(&wics, &params);
        let best = order[0];
        let selected = scored[best].0.model.clone();
        let fit = scored[best].1.clone();
        let candidates = order.iter().map(|&i| scored[i].0.clone()).collect();
        Ok(ModelSelection {
            full_model: self.full.clone(),
            method: self.method,
            convention: self.convention,
            bootstrap: self.bootstrap,
            candidates,
            selected,
            fit,
        })
    }
}

/// Two WICs closer than this (relative) are a tie. A term that a fit drives to zero (a
/// variance to its lower bound) leaves the candidate with its sub-model's implied WV, objective
/// and optimism up to the optimiser's tolerance (agreement to about 1e-7 relative seen on
/// gyro_x of adis_16405_imu1); the tie then goes to the sub-model. Differences this small are
/// far below the bootstrap noise of the optimism (about 10% with B = 50).
pub const WIC_TIE_REL: f64 = 1e-6;

/// Candidate order: WIC ascending (NaN last); runs of ties ([`WIC_TIE_REL`] of the run's first
/// WIC) ordered by parameter count, then by processing order (port: the package keeps the
/// larger model of a tie when it comes first in set order).
fn rank(wics: &[f64], params: &[usize]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..wics.len()).collect();
    order.sort_by(|&a, &b| match (wics[a].is_nan(), wics[b].is_nan()) {
        (false, false) => wics[a].total_cmp(&wics[b]),
        (x, y) => x.cmp(&y),
    });
    let mut start = 0;
    while start < order.len() {
        let w0 = wics[order[start]];
        let mut end = start + 1;
        while end < order.len()
            && (wics[order[end]] - w0).abs() <= WIC_TIE_REL * w0.abs().max(f64::MIN_POSITIVE)
        {
            end += 1;
        }
        order[start..end].sort_by_key(|&i| params[i]);
        start = end;
    }
    order
}

/// What every candidate's score needs.
struct Context<'a> {
    wic: &'a Wic,
    wv: &'a WaveletVariance,
    inputs: StartInputs,
    omega: &'a DMatrix<f64>,
    v: Option<&'a DMatrix<f64>>,
    replicate_opts: &'a WvOptions,
}

impl Context<'_> {
    fn score(&self, candidate: &Model, fit: &GmwmFit) -> Result<CandidateScore, FitError> {
        let (optimism, gof_p_value) = match self.v {
            Some(v) => {
                let o = self.asymptotic(fit, v)?;
                (o, self.j_test_p_value(candidate, fit, v)?)
            }
            None => self.bootstrap(candidate, fit)?,
        };
        Ok(CandidateScore {
            model: candidate.clone(),
            objective: fit.objective,
            optimism,
            wic: fit.objective + optimism,
            gof_p_value,
            converged: fit.convergence.converged,
        })
    }

    /// METHODS §8.2 at the candidate's estimate, over the parameters of its active
    /// components ([`GmwmFit::active_parameters`], `crate::fit::active`).
    fn asymptotic(&self, fit: &GmwmFit, v: &DMatrix<f64>) -> Result<f64, FitError> {
        let levels = fit.nu_hat.len();
        let keep = fit.active_parameters();
        let jac = fit.model.jacobian(levels, fit.freq_hz)?;
        let a = DMatrix::from_fn(levels, keep.len(), |j, k| jac[j][keep[k]]);
        let h = fit.model.hessian(levels, fit.freq_hz)?;
        let d = d_matrix(&h, self.omega, &fit.implied_wv.wv, &fit.nu_hat)?;
        let d = DMatrix::from_fn(keep.len(), keep.len(), |k, l| d[(keep[k], keep[l])]);
        asymptotic_optimism(&a, &d, self.omega, v, self.wic.convention)
    }

    /// METHODS §7.3 with the full model's V, debiased for its inversion by the Hartlap
    /// factor ([`hartlap_factor`]); `None` when `J <= p` (no degrees of freedom), when B is
    /// too small for an invertible estimate (`B <= J + 2`), V is not positive definite or the
    /// estimate lies on the boundary of its transform domain.
    fn j_test_p_value(
        &self,
        candidate: &Model,
        fit: &GmwmFit,
        v: &DMatrix<f64>,
    ) -> Result<Option<f64>, FitError> {
        let levels = fit.nu_hat.len();
        let Some(factor) = hartlap_factor(self.wic.bootstrap, levels) else {
            return Ok(None);
        };
        if levels <= fit.active_parameters().len() {
            return Ok(None);
        }
        match j_test(&self.wic.estimator(candidate), fit, &(v / factor)) {
            Ok(t) => Ok(Some(t.p_value)),
            // V numerically singular (levels almost collinear), or an estimate on the boundary
            // of its parametrisation (an AR1 phi that underflowed to 0, two AR1s with equal
            // phi), from which the J-test cannot restart: no test, not a failed selection
            Err(
                FitError::BadWeight { .. }
                | FitError::OutOfDomain { .. }
                | FitError::PhiNotOrdered { .. },
            ) => Ok(None),
            Err(e) => Err(e),
        }
    }

    /// METHODS §8.3 and the bootstrap GoF p-value of §7.4: B series simulated from the
    /// candidate's estimate; each is refitted from theta_hat (stage 2, its own fast weights)
    /// for `C = Cov(nu2_hat*, nu2(theta*))`, and fitted afresh (guess mode, G =
    /// `bootstrap_draws`) for an objective value; the p-value is the share of those strictly
    /// above the observed objective.
    ///
    /// A component the fit drove to zero ([`GmwmFit::active_sub_model`]) is left out of the refits:
    /// it generates nothing in the replicates, and its boundary value (a drift of exactly 0)
    /// is no starting point for the transforms; the optimism is then that of the sub-model,
    /// as in the asymptotic form.
    fn bootstrap(&self, candidate: &Model, fit: &GmwmFit) -> Result<(f64, Option<f64>), FitError> {
        let (active, start) = match fit.active_sub_model()? {
            Some(sub) => (sub.model, sub.start),
            None => (candidate.clone(), fit.theta.clone()),
        };
        let stage2 = self.wic.estimator(&active);
        let freq_hz = self.wv.freq_hz;
        let seed = self.wic.seed.wrapping_add(BOOTSTRAP_SEED_OFFSET);
        let reps = map_replicates(
            &fit.active_model()?,
            self.inputs.n,
            freq_hz,
            self.replicate_opts,
            self.wic.bootstrap,
            seed,
            |r, wv, x| {
                let weights = Weights::fast(wv)?;
                let refit = stage2.fit_weighted(&wv.wv, weights, freq_hz, &start)?;
                let fresh = Gmwm::new(candidate.clone())
                    .with_seed(replicate_seed(seed, r as u64))
                    .with_draws(self.wic.bootstrap_draws)
                    .fit_from_wv(wv, StartInputs::from_series(x))?;
                Ok::<_, FitError>((wv.wv.clone(), refit.implied_wv.wv, fresh.objective))
            },
        )?;
        let (mut nu_hat, mut nu_theta) = (Vec::new(), Vec::new());
        let mut above = 0usize;
        for (a, b, obj) in reps {
            nu_hat.push(a);
            nu_theta.push(b);
            above += usize::from(obj > fit.objective);
        }
        let optimism = bootstrap_optimism(&nu_hat, &nu_theta, self.omega)?;
        Ok((optimism, Some(above as f64 / self.wic.bootstrap as f64)))
    }
}

/// One candidate's row of the selection table (METHODS §8.6).
///
/// Wire format: `model` (canonical text, guess mode), `objective` (`Q(theta_hat)`, §5.1),
/// `optimism`, `wic` (= objective + optimism), `gof_p_value` (null when undefined: J <= p,
/// B <= J + 2 bootstrap replicates (too few to invert V), V not positive definite or an
/// estimate on the boundary of its transform domain),
/// `converged` (of the candidate's optimiser).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CandidateScore {
    /// The candidate (guess mode).
    pub model: Model,
    /// Its GMWM objective at the estimate, against the data's WV and fast weights.
    pub objective: f64,
    /// The optimism (§8.2 or §8.3).
    pub optimism: f64,
    /// `objective + optimism` (paper eq. 5).
    pub wic: f64,
    /// Goodness-of-fit p-value (§7.3 J-test with V, or the bootstrap one of §7.4).
    pub gof_p_value: Option<f64>,
    /// Whether the candidate's optimiser converged.
    pub converged: bool,
}

/// The result of a WIC selection (METHODS §8.6).
///
/// Wire format: `full_model`, `method` (`asymptotic`/`bootstrap`), `convention`
/// (`corrected`/`package`, used by the asymptotic optimism), `bootstrap` (B), `candidates`
/// ([`CandidateScore`], sorted by `wic` ascending), `selected` (the first candidate's text) and
/// `fit` (its [`GmwmFit`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelSelection {
    /// The full model (guess mode).
    pub full_model: Model,
    /// Optimism estimator.
    pub method: OptimismMethod,
    /// Asymptotic formula.
    pub convention: OptimismConvention,
    /// Bootstrap replicates B.
    pub bootstrap: usize,
    /// Candidates sorted by WIC ascending.
    pub candidates: Vec<CandidateScore>,
    /// The selected model (smallest WIC), guess mode.
    pub selected: Model,
    /// The selected model's fit.
    pub fit: GmwmFit,
}

impl fmt::Display for ModelSelection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "WIC model selection: full model {}, {} optimism, B = {}",
            self.full_model, self.method, self.bootstrap
        )?;
        let width = self
            .candidates
            .iter()
            .map(|c| c.model.to_string().len())
            .max()
            .unwrap_or(5)
            .max(5);
        writeln!(
            f,
            "{:<width$} {:>14} {:>14} {:>14} {:>12}",
            "model", "objective", "optimism", "WIC", "GoF p-value"
        )?;
        for c in &self.candidates {
            let p = c
                .gof_p_value
                .map_or_else(|| "-".to_string(), |p| format!("{p:.4e}"));
            let mark = if c.converged { "" } else { " (not converged)" };
            writeln!(
                f,
                "{:<width$} {:>14.6e} {:>14.6e} {:>14.6e} {:>12}{mark}",
                c.model.to_string(),
                c.objective,
                c.optimism,
                c.wic,
                p
            )?;
        }
        writeln!(f, "selected: {}", self.selected)?;
        write!(f, "{}", self.fit)
    }
}
