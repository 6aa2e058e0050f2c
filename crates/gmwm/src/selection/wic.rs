//! The selection procedure (docs/methods.md §8.6): fit the full model, bootstrap V from it, fit
//! every candidate against the same empirical WV and weights, score it, rank by WIC.

use super::candidates::{check_candidate, common_denominator, nested_candidates, same_terms};
use super::optimism::{
    asymptotic_optimism, bootstrap_optimism, d_matrix, OptimismConvention, OptimismMethod,
};
use super::SelectionError;
use crate::error::check_freq;
use crate::fit::canonical::wv_separation;
use crate::fit::{CanonicalModel, FitError, Gmwm, GmwmFit, StartInputs, Weights, SEPARATION_LIMIT};
use crate::inference::gof::{hartlap_factor, j_test};
use crate::inference::{NoProgress, Progress};
use crate::model::Model;
use crate::process::{spec, Role};
use crate::sim::bootstrap::map_replicates;
use crate::sim::covariance::{pooled_wv_covariance, wv_covariance, CovarianceMethod, VSource};
use crate::sim::replicate_seed;
use crate::variance::pooled::PooledWv;
use crate::variance::wv::{wavelet_variance, WaveletVariance, WvOptions};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use serde::Serialize;
use std::fmt;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Default number of bootstrap replicates B (the package's `B = 50`).
pub(crate) const DEFAULT_BOOTSTRAP: usize = 50;
/// Default seed (the package's 1337).
pub(crate) const DEFAULT_SEED: u64 = 1337;
/// Starting-value draws of the fresh fits behind the bootstrap GoF p-value (docs/methods.md §7.4:
/// "a fresh guess with G = 10000 draws").
pub(crate) const DEFAULT_BOOTSTRAP_DRAWS: usize = 10_000;
/// The bootstrap replicates are seeded from `seed + 5`, as the package's `summary` (§7.5), so
/// that their random streams differ from those of the starting-value search seeded by `seed`.
const BOOTSTRAP_SEED_OFFSET: u64 = 5;

/// A WIC model selection (docs/methods.md §8): the full model, the candidates and the settings.
/// Build with [`Wic::nested`] or [`Wic::list`], adjust with the `with_*` setters, run with
/// [`Wic::select`].
#[derive(Debug, Clone, PartialEq)]
pub struct Wic {
    full: Model,
    candidates: Vec<Model>,
    method: OptimismMethod,
    convention: OptimismConvention,
    bootstrap: usize,
    covariance: CovarianceMethod,
    seed: u64,
    draws: Option<usize>,
    bootstrap_draws: usize,
    wv_options: WvOptions,
    rule: SelectionRule,
    separation_limit: f64,
}

/// How the selected row is chosen among the rows of canonical models (module docs of
/// `super`): every rule ranks the rows by WIC; they differ in what they do with the rows
/// whose WIC exceeds the minimum by at most one standard error of that difference
/// (`WIC_EQUIVALENCE_SE`, `wic_difference_se`): the criterion cannot tell those apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SelectionRule {
    /// The row with the smallest WIC (the package's rule, applied to canonical models).
    WicMinimum,
    /// Among the rows within one standard error of the WIC minimum, the canonical model with
    /// the fewest parameters (then the smaller WIC): the "equivalent models" rule of the R
    /// follow-up `mgmwm` (the least complex candidate whose criterion lies within the best
    /// one's interval), Breiman's one-standard-error rule.
    Parsimonious,
    /// Among the rows within one standard error of the WIC minimum, the canonical model with
    /// the most of the two terms every navigation filter carries, white noise and random walk,
    /// then the fewest parameters, then the smaller WIC (default): a bias random walk the
    /// criterion cannot exclude is kept (dropping it makes a filter overconfident), a drift is
    /// never preferred to a random walk the criterion cannot tell from it, and any other term
    /// the criterion cannot confirm is left out.
    #[default]
    Navigation,
}

crate::names::named_values!(SelectionRule, "rule", {
    Navigation => "navigation",
    Parsimonious => "parsimonious",
    WicMinimum => "wic-minimum",
}, derive(FromStr, Display));

impl Wic {
    fn with_candidates(full: Model, candidates: Vec<Model>) -> Self {
        Self {
            full,
            candidates,
            method: OptimismMethod::default(),
            convention: OptimismConvention::default(),
            bootstrap: DEFAULT_BOOTSTRAP,
            covariance: CovarianceMethod::Auto,
            seed: DEFAULT_SEED,
            draws: None,
            bootstrap_draws: DEFAULT_BOOTSTRAP_DRAWS,
            wv_options: WvOptions::default(),
            rule: SelectionRule::default(),
            separation_limit: SEPARATION_LIMIT,
        }
    }

    /// Nested selection (docs/methods.md §8.4, `auto.imu`, `rank.models(nested = TRUE)`): every
    /// sub-model of `full` (`nested_candidates`); values in `full` are ignored.
    ///
    /// # Errors
    /// As `nested_candidates`.
    pub fn nested(full: Model) -> Result<Self, SelectionError> {
        let candidates = nested_candidates(&full)?;
        Ok(Self::with_candidates(full.without_values(), candidates))
    }

    /// Selection among a user's list (docs/methods.md §8.5, `rank.models(nested = FALSE)`): the
    /// candidates in the order given (identical term lists merged, values ignored); the common
    /// denominator (`common_denominator`) plays the full model and is appended as a candidate
    /// unless a given one has the same terms (which then plays the full model).
    ///
    /// # Errors
    /// As `common_denominator`.
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

    /// Sets the bootstrap replicates B (of a bootstrap V for the asymptotic optimism, per
    /// candidate for the bootstrap one); default `DEFAULT_BOOTSTRAP`; at least 2.
    pub fn with_bootstrap(mut self, replicates: usize) -> Self {
        self.bootstrap = replicates;
        self
    }

    /// Sets how V, the covariance of the WV at the full model's estimate, is obtained
    /// (default [`CovarianceMethod::Auto`]: exact when the model is covered;
    /// [`CovarianceMethod::Bootstrap`] simulates B series, as the package).
    pub fn with_covariance(mut self, method: CovarianceMethod) -> Self {
        self.covariance = method;
        self
    }

    /// Sets the seed (starting values of every candidate, bootstrap); default
    /// `DEFAULT_SEED`. Every candidate's search restarts from it, as in the package.
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// Sets the starting-value draws G of every fit; default as [`Gmwm`]
    /// (`default_draws`).
    pub fn with_draws(mut self, draws: usize) -> Self {
        self.draws = Some(draws);
        self
    }

    /// Sets the draws of the fresh fits behind the bootstrap GoF p-value; default
    /// [`DEFAULT_BOOTSTRAP_DRAWS`].
    #[cfg(test)]
    pub(crate) fn with_bootstrap_draws(mut self, draws: usize) -> Self {
        self.bootstrap_draws = draws;
        self
    }

    /// Sets the WV estimator (classical or robust, docs/methods.md §8.6 `robust`, `eff`, `alpha`);
    /// default [`WvOptions::default`]. `levels` applies to the data and every replicate.
    pub fn with_wv_options(mut self, options: WvOptions) -> Self {
        self.wv_options = options;
        self
    }

    /// Sets how the selected row is chosen ([`SelectionRule`]; default
    /// [`SelectionRule::Navigation`]).
    pub fn with_rule(mut self, rule: SelectionRule) -> Self {
        self.rule = rule;
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
        if !(self.separation_limit.is_finite() && self.separation_limit >= 0.0) {
            return Err(SelectionError::Setting {
                name: "separation limit",
                value: self.separation_limit.to_string(),
                expected: "a finite number of standard errors >= 0",
            });
        }
        for c in &self.candidates {
            check_candidate(c)?;
        }
        Ok(())
    }

    /// Runs the selection on the series `x` sampled at `freq_hz` (docs/methods.md §8.6):
    ///
    /// 1. the WV of `x`, its fast weights, and the full model fitted in guess mode;
    /// 2. asymptotic optimism: `V` = full covariance of the WV at the full model's estimate
    ///    (reused for every candidate, a package design choice, §13.15), exact or over B
    ///    series simulated from it ([`Wic::with_covariance`]);
    /// 3. every candidate (in parallel; each search seeded with `seed`) fitted in guess mode
    ///    against the same WV and weights; objective, optimism, WIC, GoF p-value (the J-test of
    ///    §7.3 with `V`, or with the bootstrap optimism the bootstrap p-value of §7.4).
    ///    Candidates with one canonical model and one objective (within `WIC_TIE_REL`) are
    ///    one fit up to terms fitted to nothing: they share the GoF p-value of their smallest
    ///    member, and with the bootstrap optimism its optimism too, bootstrapped once for the
    ///    group (the asymptotic optimisms of such members agree, their terms fitted to nothing
    ///    being inactive; a member bootstrapped apart would refit those terms on the
    ///    replicates, where they are not);
    /// 4. each candidate's fit read as its canonical model
    ///    ([`GmwmFit::canonical`](crate::fit::GmwmFit::canonical)); candidates with the same
    ///    canonical model are one row, scored by its smallest member (fewest parameters, then
    ///    smallest WIC), so a superset whose extra terms collapsed or stand in for others never
    ///    wins on the noise of its optimism;
    /// 5. rows sorted by WIC (a NaN WIC last; ties within `WIC_TIE_REL` go to the model with
    ///    fewer parameters); the selected row is chosen by the [`SelectionRule`] among the rows
    ///    whose fits the data cannot separate from the WIC minimum's.
    ///
    /// Not reproduced from the package: after scoring, its asymptotic mode replaces the
    /// optimism of a bigger model with a higher objective but lower WIC than a smaller one by
    /// the smaller one's optimism plus a random `|N(0, obj/10)|` draw; here every optimism is
    /// the formula's.
    ///
    /// Cost: one WV of `x`, V (exact: O(J^2); bootstrap: B simulations and WVs of length N),
    /// one fit per candidate plus the
    /// refits of its canonical reading (with the bootstrap optimism, B simulations, WVs and two
    /// fits per tie group on top).
    ///
    /// # Errors
    /// [`SelectionError::Setting`] for B < 2 or G = 0; [`SelectionError::Input`] for an
    /// unusable series or rate, or a non-Haar wavelet filter; [`SelectionError::Fit`] naming
    /// the candidate whose fit, optimism or GoF failed.
    pub fn select(&self, x: &[f64], freq_hz: f64) -> Result<ModelSelection, SelectionError> {
        self.select_with_progress(x, freq_hz, &NoProgress)
    }

    /// [`Wic::select`] reporting the scored candidates to `progress` (`start` with the number
    /// of candidates, then an `advance` as candidates are scored, a tie group's members at
    /// once, in completion order).
    ///
    /// # Errors
    /// As [`Wic::select`].
    pub fn select_with_progress(
        &self,
        x: &[f64],
        freq_hz: f64,
        progress: &dyn Progress,
    ) -> Result<ModelSelection, SelectionError> {
        self.check_settings()?;
        check_freq(freq_hz)?;
        check_haar(self.wv_options.filter)?;
        let wv = wavelet_variance(x, freq_hz, &self.wv_options)?;
        self.select_from(&wv, StartInputs::from_series(x), None, progress)
    }

    /// [`Wic::select`] on a wavelet variance computed before (e.g. read by
    /// [`read_wv_json`](crate::variance::read_wv_json)) instead of a series: the same steps, the
    /// starting values from the WV alone ([`StartInputs::from_wv`]: no series range for drift
    /// draws), the bootstrap V simulated at the WV's `n` and rate with its own estimator
    /// settings (transform, filter, alpha, robustness, levels); the `wv_options` of this
    /// selection are not used.
    ///
    /// # Errors
    /// As [`Wic::select`] (a non-Haar WV is refused).
    #[cfg(test)]
    pub(crate) fn select_wv(&self, wv: &WaveletVariance) -> Result<ModelSelection, SelectionError> {
        self.select_wv_with_progress(wv, &NoProgress)
    }

    /// `Wic::select_wv` reporting each scored candidate to `progress` (as
    /// [`Wic::select_with_progress`]).
    ///
    /// # Errors
    /// As `Wic::select_wv`.
    pub fn select_wv_with_progress(
        &self,
        wv: &WaveletVariance,
        progress: &dyn Progress,
    ) -> Result<ModelSelection, SelectionError> {
        self.check_settings()?;
        check_freq(wv.freq_hz)?;
        check_haar(wv.filter)?;
        self.select_from(wv, StartInputs::from_wv(wv), None, progress)
    }

    /// [`Wic::select_wv`] on the pooled WV of several recordings (docs/methods.md §5.12, what
    /// `gmwm calibrate --pool` runs): the same steps on `pooled.wv()`, with the pooled WV's
    /// own covariance ([`PooledWv`]'s, every recording's V at its own length) behind the
    /// optimism and the WIC differences' standard errors.
    ///
    /// # Errors
    /// As [`Wic::select_wv`]; [`SelectionError::Setting`] for the bootstrap optimism, which
    /// simulates one series where the pooled WV comes from several.
    pub(crate) fn select_pooled_wv_with_progress(
        &self,
        pooled: &PooledWv,
        progress: &dyn Progress,
    ) -> Result<ModelSelection, SelectionError> {
        self.check_settings()?;
        if self.method == OptimismMethod::Bootstrap {
            return Err(SelectionError::Setting {
                name: "optimism",
                value: "bootstrap".into(),
                expected: "the asymptotic optimism for a pooled WV (the bootstrap simulates one series; the pooled WV comes from several)",
            });
        }
        let wv = pooled.wv();
        check_freq(wv.freq_hz)?;
        check_haar(wv.filter)?;
        self.select_from(wv, StartInputs::from_wv(wv), Some(pooled), progress)
    }

    /// Steps 1 (after the WV) to 5 of [`Wic::select`]; `pooled` is the pooled WV that `wv` is,
    /// whose covariance is its recordings' (docs/methods.md §5.12).
    fn select_from(
        &self,
        wv: &WaveletVariance,
        inputs: StartInputs,
        pooled: Option<&PooledWv>,
        progress: &dyn Progress,
    ) -> Result<ModelSelection, SelectionError> {
        let freq_hz = wv.freq_hz;
        let fit_error = |m: &Model| {
            let candidate = m.to_string();
            move |source| SelectionError::Fit { candidate, source }
        };
        progress.start(self.candidates.len());
        // every candidate with the package's fast weights (docs/methods.md §5.2, §8.6), for which
        // the asymptotic optimism is calibrated (selection module docs)
        let full_fit = self
            .estimator(&self.full)
            .fit_from_wv(wv, inputs)
            .map_err(fit_error(&self.full))?;
        let levels = wv.levels();
        // the WV's own settings: those of `wv_options` for a WV computed by `select`
        let replicate_opts = WvOptions {
            transform: wv.transform,
            filter: wv.filter,
            levels: Some(levels),
            alpha: wv.alpha,
            robust: wv.robust,
        };
        // V of the full model: the asymptotic optimism's, and with either optimism the
        // sampling covariance behind the WIC differences' standard errors (step 5)
        let full_active = full_fit.active_model().map_err(fit_error(&self.full))?;
        let v_seed = self.seed.wrapping_add(BOOTSTRAP_SEED_OFFSET);
        let covariance = match pooled {
            Some(p) => pooled_wv_covariance(
                &full_active,
                p,
                self.covariance,
                self.bootstrap,
                v_seed,
                &NoProgress,
            )?,
            None => wv_covariance(
                &full_active,
                wv.n,
                freq_hz,
                &replicate_opts,
                self.covariance,
                self.bootstrap,
                v_seed,
                &NoProgress,
            )?,
        };
        let v = covariance.v;
        let omega = DMatrix::from_diagonal(&DVector::from_column_slice(&full_fit.weights.omega));
        let context = Context {
            wic: self,
            wv,
            inputs,
            omega: &omega,
            v: (self.method == OptimismMethod::Asymptotic).then_some(&v),
            v_replicates: covariance.replicates,
            replicate_opts: &replicate_opts,
        };
        // step 3, first half: every candidate's fit and its canonical reading
        let fitted: Vec<(GmwmFit, CanonicalModel)> = self
            .candidates
            .par_iter()
            .map(|c| {
                let fit = if c.kinds() == self.full.kinds() {
                    full_fit.clone()
                } else {
                    self.estimator(c).fit_from_wv(wv, inputs)?
                };
                let canonical = fit.canonical_with(self.separation_limit)?;
                Ok((fit, canonical))
            })
            .zip(self.candidates.par_iter())
            .map(|(r, c): (Result<_, FitError>, _)| r.map_err(fit_error(c)))
            .collect::<Result<_, _>>()?;
        // second half: the scores. A tie group (one canonical model, one objective) is one fit
        // up to terms fitted to nothing; the bootstrap optimism simulates from that one fit,
        // so it runs once per group, on its smallest member, whose optimism and p-value every
        // member takes (as the p-value already was for the asymptotic optimism, step 4)
        let ties: Vec<(&Model, f64, usize)> = fitted
            .iter()
            .zip(&self.candidates)
            .map(|((fit, canonical), c)| (&canonical.model, fit.objective, c.n_params()))
            .collect();
        let representative: Vec<usize> = match self.method {
            OptimismMethod::Asymptotic => (0..ties.len()).collect(),
            OptimismMethod::Bootstrap => (0..ties.len())
                .map(|i| tie_representative(i, &ties))
                .collect(),
        };
        let mut groups: Vec<usize> = representative.clone();
        groups.sort_unstable();
        groups.dedup();
        let done = AtomicUsize::new(0);
        let group_scores: Vec<CandidateScore> = groups
            .par_iter()
            .map(|&g| {
                let (fit, canonical) = &fitted[g];
                let c = &self.candidates[g];
                let score = context
                    .score(c, &canonical.model, fit)
                    .map_err(fit_error(c))?;
                let members = representative.iter().filter(|&&r| r == g).count();
                progress.advance(done.fetch_add(members, Ordering::Relaxed) + members);
                Ok::<_, SelectionError>(score)
            })
            .collect::<Result<_, _>>()?;
        let scored: Vec<Scored> = fitted
            .into_iter()
            .zip(&self.candidates)
            .zip(&representative)
            .map(|(((fit, canonical), c), r)| {
                // `groups` is sorted and holds every representative
                let group = &group_scores[groups.partition_point(|g| g < r)];
                let score = CandidateScore {
                    model: c.clone(),
                    canonical_model: canonical.model.clone(),
                    objective: fit.objective,
                    wic: fit.objective + group.optimism,
                    converged: fit.convergence.converged,
                    ..group.clone()
                };
                Scored {
                    score,
                    fit,
                    canonical,
                }
            })
            .collect();
        Ok(self.assemble(
            scored,
            &full_fit.weights.omega,
            (&v, covariance.replicates),
            &wv.log_variance(),
        ))
    }

    /// Steps 4 and 5 of [`Wic::select`]: folds the scored candidates into rows of canonical
    /// models and chooses the selected row.
    fn assemble(
        &self,
        mut scored: Vec<Scored>,
        omega: &[f64],
        (v, v_replicates): (&DMatrix<f64>, Option<usize>),
        log_variance: &[f64],
    ) -> ModelSelection {
        // candidates with one canonical model and one objective (within WIC_TIE_REL) are one
        // fit up to terms fitted to nothing: one goodness-of-fit p-value, the smallest one's
        let ties: Vec<(&Model, f64, usize)> = scored
            .iter()
            .map(|s| {
                (
                    &s.score.canonical_model,
                    s.score.objective,
                    s.score.model.n_params(),
                )
            })
            .collect();
        let shared: Vec<(Option<f64>, bool)> = (0..scored.len())
            .map(|i| {
                let s = &scored[tie_representative(i, &ties)].score;
                (s.gof_p_value, s.gof_p_value_upper_bound)
            })
            .collect();
        for (s, (p, bound)) in scored.iter_mut().zip(shared) {
            s.score.gof_p_value = p;
            s.score.gof_p_value_upper_bound = bound;
        }
        // step 4: rows of equal canonical models, in order of first appearance
        let mut keys: Vec<&Model> = Vec::new();
        let mut members: Vec<Vec<usize>> = Vec::new();
        for (i, s) in scored.iter().enumerate() {
            match keys.iter().position(|k| **k == s.canonical.model) {
                Some(r) => members[r].push(i),
                None => {
                    keys.push(&s.canonical.model);
                    members.push(vec![i]);
                }
            }
        }
        // the row is scored by its best member, or by a smaller member whose fit the data
        // cannot tell from it (the smallest such): a superset whose extra terms collapsed or
        // stand in for others never wins on the noise of its optimism, and a member that fits
        // far better than a smaller one is not hidden behind it
        let mut rows: Vec<(usize, Vec<usize>)> = members
            .into_iter()
            .map(|m| {
                let best = *m
                    .iter()
                    .min_by(|&&a, &&b| scored[a].score.wic.total_cmp(&scored[b].score.wic))
                    .unwrap_or(&m[0]);
                let rep = *m
                    .iter()
                    .filter(|&&i| {
                        i == best
                            || wv_separation(
                                &scored[i].fit.implied_wv.wv,
                                &scored[best].fit.implied_wv.wv,
                                log_variance,
                            ) <= self.separation_limit
                    })
                    .min_by(|&&a, &&b| {
                        let (a, b) = (&scored[a].score, &scored[b].score);
                        a.model
                            .n_params()
                            .cmp(&b.model.n_params())
                            .then(a.wic.total_cmp(&b.wic))
                    })
                    .unwrap_or(&best);
                (rep, m)
            })
            .collect();
        // step 5: WIC order, then the rule among the rows not separable from the minimum
        let wics: Vec<f64> = rows.iter().map(|r| scored[r.0].score.wic).collect();
        let params: Vec<usize> = rows
            .iter()
            .map(|r| scored[r.0].canonical.model.n_params())
            .collect();
        let order = rank(&wics, &params);
        rows = order.iter().map(|&i| rows[i].clone()).collect();
        let best = &scored[rows[0].0];
        let delta_wic: Vec<f64> = rows
            .iter()
            .map(|r| scored[r.0].score.wic - best.score.wic)
            .collect();
        let delta_wic_se: Vec<f64> = rows
            .iter()
            .map(|r| {
                let s = &scored[r.0];
                wic_difference_se(
                    (
                        &s.fit.implied_wv.wv,
                        s.score.optimism,
                        s.fit.active_parameters().len(),
                    ),
                    (
                        &best.fit.implied_wv.wv,
                        best.score.optimism,
                        best.fit.active_parameters().len(),
                    ),
                    omega,
                    v,
                )
            })
            .collect();
        let equivalent: Vec<usize> = (0..rows.len())
            .filter(|&r| r == 0 || delta_wic[r] <= WIC_EQUIVALENCE_SE * delta_wic_se[r])
            .collect();
        let navigation_terms = |r: usize| navigation_terms(&scored[rows[r].0].canonical.model);
        let chosen = match self.rule {
            SelectionRule::WicMinimum => 0,
            SelectionRule::Parsimonious => *equivalent
                .iter()
                .min_by_key(|&&r| (params[order[r]], r))
                .unwrap_or(&0),
            SelectionRule::Navigation => *equivalent
                .iter()
                .min_by_key(|&&r| (std::cmp::Reverse(navigation_terms(r)), params[order[r]], r))
                .unwrap_or(&0),
        };
        let table: Vec<SelectionRow> = rows
            .iter()
            .enumerate()
            .map(|(r, (rep, m))| SelectionRow {
                score: scored[*rep].score.clone(),
                members: m.iter().map(|&i| scored[i].score.model.clone()).collect(),
                delta_wic: delta_wic[r],
                delta_wic_se: delta_wic_se[r],
                status: if r == chosen {
                    RowStatus::Selected
                } else if equivalent.contains(&r) {
                    RowStatus::Equivalent
                } else {
                    RowStatus::Separable
                },
            })
            .collect();
        let chosen_rep = rows[chosen].0;
        let cand_wics: Vec<f64> = scored.iter().map(|s| s.score.wic).collect();
        let cand_params: Vec<usize> = scored.iter().map(|s| s.score.model.n_params()).collect();
        let cand_order = rank(&cand_wics, &cand_params);
        let candidates = cand_order
            .iter()
            .map(|&i| scored[i].score.clone())
            .collect();
        let candidate_fits = cand_order.iter().map(|&i| scored[i].fit.clone()).collect();
        let chosen = &scored[chosen_rep];
        ModelSelection {
            full_model: self.full.clone(),
            method: self.method,
            convention: self.convention,
            bootstrap: self.bootstrap,
            rule: self.rule,
            separation_limit: self.separation_limit,
            rows: table,
            candidates,
            selected: chosen.score.model.clone(),
            selected_canonical: chosen.canonical.clone(),
            fit: chosen.fit.clone(),
            candidate_fits,
            v_source: VSource(v_replicates),
            wv_covariance: v.clone(),
        }
    }
}

/// The candidate that stands for candidate `i`'s tie group: among the candidates with `i`'s
/// canonical model and its objective within [`WIC_TIE_REL`] (`ties[j]` = canonical model,
/// objective, parameter count), the one with the fewest parameters, then the first.
fn tie_representative(i: usize, ties: &[(&Model, f64, usize)]) -> usize {
    let (model, objective, _) = ties[i];
    (0..ties.len())
        .filter(|&j| {
            ties[j].0 == model && (objective - ties[j].1).abs() <= WIC_TIE_REL * objective.abs()
        })
        .min_by_key(|&j| (ties[j].2, j))
        .unwrap_or(i)
}

/// How many of the two terms every navigation filter carries (white noise, random walk) a
/// model has.
fn navigation_terms(m: &Model) -> usize {
    let has = |role| m.kinds().iter().any(|&k| spec(k).role == role);
    usize::from(has(Role::WhiteNoise)) + usize::from(has(Role::RandomWalk))
}

/// One candidate's fit, score and canonical reading.
struct Scored {
    score: CandidateScore,
    fit: GmwmFit,
    canonical: CanonicalModel,
}

/// Two WICs closer than this (relative) are a tie. A term that a fit drives to zero (a
/// variance to its lower bound) leaves the candidate with its sub-model's implied WV, objective
/// and optimism up to the optimiser's tolerance (agreement to about 1e-7 relative seen on
/// gyro_x of adis_16405_imu1); the tie then goes to the sub-model. Differences this small are
/// far below the bootstrap noise of the optimism (about 10% with B = 50).
pub(crate) const WIC_TIE_REL: f64 = 1e-6;

/// Rows whose WIC exceeds the minimum by at most this many standard errors of the difference
/// are equivalent (the one-standard-error rule).
pub(crate) const WIC_EQUIVALENCE_SE: f64 = 1.0;

/// Standard error of the difference of two candidates' WICs under the sampling noise of the
/// empirical WV (Vuong 1989, for fitted criteria): a first-order term, from the derivative of
/// a fitted objective with respect to `nu2_hat`, `2 Omega (nu2_hat - nu2(theta_hat))`
/// (envelope theorem), and a second-order term, the spread of the chi-square-like drop in
/// objective that extra parameters buy on noise alone, which dominates when the two fits
/// nearly coincide (nested candidates):
///
/// ```text
/// se^2 = 4 d' Omega V Omega d  +  (opt_a - opt_b)^2 / (2 max(1, |p_a - p_b|))
/// ```
///
/// with `d = nu_a - nu_b` (the two fits' implied WVs), `V` the covariance of the WV (the full
/// model's bootstrap), `opt` the optimisms and `p` the numbers of active parameters: with `k`
/// extra parameters the drop is about `s chi2_k` with mean `s k` = half the optimism difference
/// (the AIC identity), so its variance is `2 k s^2`. For candidates of one size (not nested)
/// the term is small, their optimisms being close, and `k = 1` is used. Not included: the
/// optimisms' own estimation noise (about 10% of each with B = 50 replicates behind V), which
/// for nearly coinciding fits is of the order of this standard error.
pub(crate) fn wic_difference_se(
    a: (&[f64], f64, usize),
    b: (&[f64], f64, usize),
    omega: &[f64],
    v: &DMatrix<f64>,
) -> f64 {
    let ((nu_a, opt_a, p_a), (nu_b, opt_b, p_b)) = (a, b);
    let g = DVector::from_iterator(
        omega.len(),
        omega
            .iter()
            .zip(nu_a.iter().zip(nu_b))
            .map(|(w, (x, y))| w * (x - y)),
    );
    let first = 4.0 * (g.transpose() * v * &g)[(0, 0)].max(0.0);
    let k = p_a.abs_diff(p_b).max(1) as f64;
    let second = (opt_a - opt_b).powi(2) / (2.0 * k);
    (first + second).sqrt()
}

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
    /// Replicates behind V; `None` when exact.
    v_replicates: Option<usize>,
    replicate_opts: &'a WvOptions,
}

impl Context<'_> {
    fn score(
        &self,
        candidate: &Model,
        canonical_model: &Model,
        fit: &GmwmFit,
    ) -> Result<CandidateScore, FitError> {
        let (optimism, gof_p_value, gof_p_value_upper_bound) = match self.v {
            Some(v) => {
                let o = self.asymptotic(fit, v)?;
                (o, self.j_test_p_value(candidate, fit, v)?, false)
            }
            None => self.bootstrap(candidate, fit)?,
        };
        Ok(CandidateScore {
            model: candidate.clone(),
            canonical_model: canonical_model.clone(),
            objective: fit.objective,
            optimism,
            wic: fit.objective + optimism,
            gof_p_value,
            gof_p_value_upper_bound,
            converged: fit.convergence.converged,
        })
    }

    /// docs/methods.md §8.2 at the candidate's estimate, over the parameters of its active
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

    /// docs/methods.md §7.3 with the full model's V, a bootstrap one debiased for its inversion by
    /// the Hartlap factor ([`hartlap_factor`]); `None` when `J <= p` (no degrees of freedom), when
    /// B is too small for an invertible estimate (`B <= J + 2`), V is not positive definite or
    /// the estimate lies on the boundary of its transform domain.
    fn j_test_p_value(
        &self,
        candidate: &Model,
        fit: &GmwmFit,
        v: &DMatrix<f64>,
    ) -> Result<Option<f64>, FitError> {
        let levels = fit.nu_hat.len();
        let factor = match self.v_replicates {
            Some(b) => hartlap_factor(b, levels),
            None => Some(1.0),
        };
        let Some(factor) = factor else {
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

    /// docs/methods.md §8.3 and the bootstrap GoF p-value of §7.4: B series simulated from the
    /// candidate's estimate; each is refitted from theta_hat (stage 2, its own fast weights)
    /// for `C = Cov(nu2_hat*, nu2(theta*))`, and fitted afresh (guess mode, G =
    /// `bootstrap_draws`) for an objective value; the p-value is the share of those strictly
    /// above the observed objective.
    ///
    /// A component the fit drove to zero ([`GmwmFit::active_sub_model`]) is left out of the refits:
    /// it generates nothing in the replicates, and its boundary value (a drift of exactly 0)
    /// is no starting point for the transforms; the optimism is then that of the sub-model,
    /// as in the asymptotic form.
    fn bootstrap(
        &self,
        candidate: &Model,
        fit: &GmwmFit,
    ) -> Result<(f64, Option<f64>, bool), FitError> {
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
                let refit = stage2.fit_weighted(&wv.wv, weights.clone(), freq_hz, &start)?;
                let fresh = Gmwm::new(candidate.clone())
                    .with_seed(replicate_seed(seed, r as u64))
                    .with_draws(self.wic.bootstrap_draws)
                    .fit_auto(wv, weights, StartInputs::from_series(x))?;
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
        // no replicate above: the share is 0, and all the B replicates say is that the p-value
        // is small; it is reported as the bound 1 / (B + 1), the smallest value of the
        // (conservative) Monte Carlo p-value (1 + above) / (B + 1)
        let b = self.wic.bootstrap as f64;
        Ok(if above == 0 {
            (optimism, Some(1.0 / (b + 1.0)), true)
        } else {
            (optimism, Some(above as f64 / b), false)
        })
    }
}

/// One candidate of the selection (docs/methods.md §8.6).
///
/// Wire format: `model` (canonical text, guess mode), `canonical_model` (its fit read as a
/// canonical model, `canonical`), `objective` (`Q(theta_hat)`, §5.1),
/// `optimism`, `wic` (= objective + optimism), `gof_p_value` (null when undefined: J <= p,
/// B <= J + 2 bootstrap replicates (too few to invert V), V not positive definite or an
/// estimate on the boundary of its transform domain), `gof_p_value_upper_bound` (true when
/// the bootstrap p-value is a bound: no replicate exceeded the observed objective, so the
/// p-value is below `1 / (B + 1)`, the value given), `converged` (of the candidate's
/// optimiser). Candidates with one canonical model and one objective (within `WIC_TIE_REL`)
/// are one fit up to terms fitted to nothing, and report the p-value of the one with the
/// fewest parameters.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CandidateScore {
    /// The candidate (guess mode).
    pub model: Model,
    /// Its fit's canonical model (guess mode).
    pub canonical_model: Model,
    /// Its GMWM objective at the estimate, against the data's WV and fast weights.
    pub objective: f64,
    /// The optimism (§8.2 or §8.3).
    pub optimism: f64,
    /// `objective + optimism` (paper eq. 5).
    pub wic: f64,
    /// Goodness-of-fit p-value (§7.3 J-test with V, or the bootstrap one of §7.4).
    pub gof_p_value: Option<f64>,
    /// Whether `gof_p_value` is an upper bound (bootstrap p-value with no replicate above).
    pub gof_p_value_upper_bound: bool,
    /// Whether the candidate's optimiser converged.
    pub converged: bool,
}

/// Where a row stands in the selection.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum RowStatus {
    /// The selected row.
    Selected,
    /// Within one standard error of the WIC minimum, not selected.
    Equivalent,
    /// Further from the WIC minimum.
    Separable,
}

/// One row of the selection table: a canonical model and the candidates that read as it.
///
/// Wire format: the [`CandidateScore`] fields of the member whose scores the row shows
/// (fewest parameters, then smallest WIC: `model`, `canonical_model`, `objective`,
/// `optimism`, `wic`, `gof_p_value`, `gof_p_value_upper_bound`, `converged`), `members` (every
/// candidate with this canonical model), `delta_wic` (its WIC less the minimum's),
/// `delta_wic_se` (the standard error of that difference, `wic_difference_se`), `status`
/// (`selected`, `equivalent`, `separable`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SelectionRow {
    /// The scores of the member the row shows; `score.canonical_model` is the row's model.
    #[serde(flatten)]
    pub score: CandidateScore,
    /// Every candidate with this canonical model.
    pub members: Vec<Model>,
    /// WIC less the minimum's.
    pub delta_wic: f64,
    /// Standard error of `delta_wic` (`wic_difference_se`).
    pub delta_wic_se: f64,
    /// Selected, equivalent or separable.
    pub status: RowStatus,
}

/// The result of a WIC selection (docs/methods.md §8.6).
///
/// Wire format: `full_model`, `method` (`asymptotic`/`bootstrap`), `convention`
/// (`corrected`/`package`, used by the asymptotic optimism), `bootstrap` (B), `v_method`
/// (`exact`/`bootstrap`: how V was obtained), `v_replicates` (B, or null when exact), `rule`
/// ([`SelectionRule`]), `separation_limit` (of the canonical readings), `rows`
/// ([`SelectionRow`], one per canonical model,
/// sorted by `wic`), `candidates` ([`CandidateScore`], every candidate, sorted by `wic`
/// ascending), `selected` (the selected row's candidate, as fitted), `selected_canonical`
/// ([`CanonicalModel`]) and `fit` (the selected candidate's [`GmwmFit`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelSelection {
    /// The full model (guess mode).
    pub(crate) full_model: Model,
    /// Optimism estimator.
    pub(crate) method: OptimismMethod,
    /// Asymptotic formula.
    pub(crate) convention: OptimismConvention,
    /// Bootstrap replicates B.
    pub(crate) bootstrap: usize,
    /// How V was obtained: exact, or the replicates behind it.
    #[serde(flatten)]
    pub(crate) v_source: VSource,
    /// How the selected row was chosen.
    pub(crate) rule: SelectionRule,
    /// Separation below which a fit and its canonical reduction are not told apart.
    pub(crate) separation_limit: f64,
    /// One row per canonical model, sorted by WIC.
    pub(crate) rows: Vec<SelectionRow>,
    /// Every candidate, sorted by WIC ascending.
    pub(crate) candidates: Vec<CandidateScore>,
    /// The selected candidate (guess mode, as fitted).
    pub(crate) selected: Model,
    /// Its canonical model.
    pub(crate) selected_canonical: CanonicalModel,
    /// The selected candidate's fit.
    pub(crate) fit: GmwmFit,
    /// Every candidate's fit, in the order of `candidates` (not serialised).
    #[serde(skip)]
    pub(crate) candidate_fits: Vec<GmwmFit>,
    /// The covariance V of the WV at the full model's fit, which nests every candidate (exact,
    /// or over `bootstrap` replicates simulated from it), for inference on the selected fit
    /// without computing it again ([`crate::inference::infer_with_covariance`]); not
    /// serialised.
    #[serde(skip)]
    pub(crate) wv_covariance: DMatrix<f64>,
}

/// Read access to the results; the fields are the engine's own.
impl ModelSelection {
    /// The full model (guess mode).
    pub fn full_model(&self) -> &Model {
        &self.full_model
    }

    /// Optimism estimator.
    pub fn method(&self) -> OptimismMethod {
        self.method
    }

    /// Asymptotic formula.
    pub fn convention(&self) -> OptimismConvention {
        self.convention
    }

    /// Bootstrap replicates B.
    pub fn bootstrap(&self) -> usize {
        self.bootstrap
    }

    /// How the selected row was chosen.
    pub fn rule(&self) -> SelectionRule {
        self.rule
    }

    /// One row per canonical model, sorted by WIC.
    pub fn rows(&self) -> &[SelectionRow] {
        &self.rows
    }

    /// Every candidate, sorted by WIC ascending.
    pub fn candidates(&self) -> &[CandidateScore] {
        &self.candidates
    }

    /// The selected candidate (guess mode, as fitted).
    pub fn selected(&self) -> &Model {
        &self.selected
    }

    /// Its canonical model.
    pub fn selected_canonical(&self) -> &CanonicalModel {
        &self.selected_canonical
    }

    /// The selected candidate's fit.
    pub fn fit(&self) -> &GmwmFit {
        &self.fit
    }

    /// How V was obtained: `"exact"` or `"bootstrap"`.
    pub fn v_method(&self) -> &'static str {
        self.v_source.method()
    }

    /// Replicates behind V; `None` when exact.
    pub fn v_replicates(&self) -> Option<usize> {
        self.v_source.replicates()
    }
}

impl ModelSelection {
    /// The fit of the candidate `model` (guess mode, as listed in `candidates`).
    pub(crate) fn candidate_fit(&self, model: &Model) -> Option<&GmwmFit> {
        self.candidates
            .iter()
            .position(|c| &c.model == model)
            .and_then(|i| self.candidate_fits.get(i))
    }

    /// The selected row.
    pub fn selected_row(&self) -> &SelectionRow {
        self.rows
            .iter()
            .find(|r| r.status == RowStatus::Selected)
            .unwrap_or(&self.rows[0])
    }

    /// The table with at most `top` rows (0 for all); the selected and equivalent rows are
    /// always shown.
    pub fn table(&self, top: usize) -> SelectionTable<'_> {
        SelectionTable {
            selection: self,
            top,
        }
    }

    /// Why the selected row was chosen, in one sentence.
    pub fn reason(&self) -> String {
        let sel = self.selected_row();
        if std::ptr::eq(sel, &self.rows[0]) {
            return "the smallest WIC".to_string();
        }
        let why = match self.rule {
            SelectionRule::Navigation
                if navigation_terms(&sel.score.canonical_model)
                    > navigation_terms(&self.rows[0].score.canonical_model) =>
            {
                "it has the white noise and random walk a navigation filter carries"
            }
            _ => "it has fewer parameters",
        };
        // a row tied with the first (WIC_TIE_REL, ranked by fewer parameters) may lie below it
        let side = if sel.delta_wic >= 0.0 {
            "above the minimum"
        } else {
            "below the first row, a tie ranked by fewer parameters"
        };
        format!(
            "WIC {:.3e} {side} ({}), within one standard error ({:.3e}); {why}",
            sel.delta_wic.abs(),
            self.rows[0].score.canonical_model,
            sel.delta_wic_se
        )
    }
}

/// A view of a [`ModelSelection`] with at most a number of rows ([`ModelSelection::table`]).
#[derive(Debug, Clone, Copy)]
pub struct SelectionTable<'a> {
    selection: &'a ModelSelection,
    top: usize,
}

/// A p-value cell: `<x` for an upper bound, `-` when undefined, `<1e-300` for a tail that
/// underflowed.
fn p_cell(p: Option<f64>, bound: bool) -> String {
    match p {
        None => "-".to_string(),
        Some(p) if bound => format!("<{p:.2e}"),
        // a chi-square tail below the smallest double
        Some(0.0) => "<1e-300".to_string(),
        Some(p) => format!("{p:.2e}"),
    }
}

impl fmt::Display for SelectionTable<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = self.selection;
        writeln!(
            f,
            "WIC model selection: full model {}, {} candidates in {} canonical models, {} optimism, \
             B = {}, rule {}",
            s.full_model,
            s.candidates.len(),
            s.rows.len(),
            s.method,
            s.bootstrap,
            s.rule
        )?;
        let shown: Vec<usize> = (0..s.rows.len())
            .filter(|&r| self.top == 0 || r < self.top || s.rows[r].status != RowStatus::Separable)
            .collect();
        let width = shown
            .iter()
            .map(|&r| s.rows[r].score.canonical_model.to_string().len())
            .max()
            .unwrap_or(5)
            .max(15);
        writeln!(
            f,
            "  {:>3} {:<width$} {:>11} {:>11} {:>11} {:>10} {:>10} {:>10}  fitted as",
            "#", "canonical model", "objective", "optimism", "WIC", "dWIC", "se(dWIC)", "GoF p",
        )?;
        for &r in &shown {
            let row = &s.rows[r];
            let mark = match row.status {
                RowStatus::Selected => "*",
                RowStatus::Equivalent => "=",
                RowStatus::Separable => " ",
            };
            let sc = &row.score;
            let mut fitted: Vec<String> = vec![sc.model.to_string()];
            let others = row.members.len() - 1;
            if others > 0 {
                fitted.push(format!("(+{others} more)"));
            }
            let conv = if sc.converged { "" } else { " (not converged)" };
            writeln!(
                f,
                "{mark} {:>3} {:<width$} {:>11.5e} {:>11.5e} {:>11.5e} {:>10.3e} {:>10.3e} {:>10}  {}{conv}",
                r + 1,
                sc.canonical_model.to_string(),
                sc.objective,
                sc.optimism,
                sc.wic,
                row.delta_wic,
                row.delta_wic_se,
                p_cell(sc.gof_p_value, sc.gof_p_value_upper_bound),
                fitted.join(" ")
            )?;
        }
        let hidden = s.rows.len() - shown.len();
        if hidden > 0 {
            writeln!(f, "  ... {hidden} more rows (--top 0 shows all)")?;
        }
        writeln!(
            f,
            "  * selected, = equivalent (WIC within {WIC_EQUIVALENCE_SE} standard error of the \
             minimum: dWIC <= se(dWIC))"
        )?;
        writeln!(
            f,
            "selected: {} ({})",
            s.selected_row().score.canonical_model,
            s.reason()
        )?;
        write!(f, "{}", s.selected_canonical)
    }
}

impl fmt::Display for ModelSelection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.table(0))
    }
}

/// Refuses a wavelet variance with another filter than Haar: every implied WV is the Haar one
/// (docs/methods.md §1.8, §4), as [`crate::fit::FitError::NotHaar`] says for a single fit.
fn check_haar(filter: crate::WaveletFilter) -> Result<(), SelectionError> {
    crate::fit::check_haar(filter).map_err(|_| SelectionError::Setting {
        name: "filter",
        value: filter.to_string(),
        expected: "haar: every model's implied wavelet variance is the Haar one \
                   (docs/methods.md §1.8, §4); other filters are for display only",
    })
}
