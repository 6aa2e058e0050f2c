//! The GMWM estimator settings and the fit from caller-given starting values (docs/methods.md §5.5
//! steps 3, 4, 6, 8, 10–12), the bootstrap weighting (§5.2) and the refit of another model on
//! a fit's WV (`update`, §5.9); the fit with generated starting values (§6) is in
//! [`super::auto`].

use super::estimates::FitEstimates;
use super::revive::{revival_start, MAX_REVIVALS};
use super::{
    minimize, FitError, LmOptions, Objective, Parametrisation, PhiOrder, StartInputs, StartOptions,
    TransformPreset, Weighting, Weights,
};
use crate::error::ParamError;
use crate::model::{ImpliedWv, Model};
use crate::sim::bootstrap::wv_bootstrap;
#[cfg(test)]
use crate::variance::wv::wavelet_variance;
use crate::variance::wv::{WaveletVariance, WvOptions};
use serde::Serialize;

/// Default number of bootstrap replicates H behind [`Weighting::Bootstrap`] (docs/methods.md §5.7).
pub(crate) const DEFAULT_BOOTSTRAP_REPLICATES: usize = 100;

/// GMWM estimator settings (docs/methods.md §5): the model and how to fit it. Build with
/// [`Gmwm::new`] and the `with_*` setters, then call [`Gmwm::fit`] (a series) or [`Gmwm::fit_wv`] (its WV).
///
/// ```
/// use gmwm::Gmwm;
/// use gmwm::Model;
/// use gmwm::{simulate_model, wavelet_variance, WvOptions};
/// let truth = Model::parse("AR1(phi=0.9, sigma2=0.1)+WN(sigma2=1)").unwrap();
/// let x = simulate_model(&truth, 10_000, 1.0, 1).unwrap();
/// let wv = wavelet_variance(&x, 1.0, &WvOptions::default()).unwrap();
/// let fit = Gmwm::new(Model::parse("AR1()+WN()").unwrap())
///     .fit_wv(&wv, 1.0, &[0.5, 0.5, 0.5])
///     .unwrap();
/// assert!(fit.convergence().converged);
/// assert!((fit.theta()[0] - 0.9).abs() < 0.05);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Gmwm {
    model: Model,
    weighting: Weighting,
    preset: TransformPreset,
    phi_order: PhiOrder,
    options: LmOptions,
    /// The values the user gave (kept in the §6 draws; all `Some`: the fit's start).
    pub(crate) given: Vec<Option<f64>>,
    /// Starting-value search settings (docs/methods.md §6).
    pub(crate) start_options: StartOptions,
    /// Bootstrap weighting: replicates H and rounds K (docs/methods.md §5.2, §5.5 step 8).
    bootstrap_replicates: usize,
    bootstrap_rounds: usize,
}

impl Gmwm {
    /// An estimator of `model` with the IMU defaults: fast weights, IMU transforms, ordered
    /// AR1/GM components. Its values are ignored by the explicit-start fits
    /// ([`Gmwm::fit_wv`], ...) and used by [`Gmwm::fit`] / [`Gmwm::fit_from_wv`]: all given
    /// means the start, some given means kept in the starting-value draws (docs/methods.md §6).
    pub fn new(model: Model) -> Self {
        Self {
            given: model.values(),
            start_options: StartOptions::default(),
            model: model.without_values(),
            weighting: Weighting::Fast,
            preset: TransformPreset::Imu,
            phi_order: PhiOrder::Ordered,
            options: LmOptions::default(),
            bootstrap_replicates: DEFAULT_BOOTSTRAP_REPLICATES,
            bootstrap_rounds: 1,
        }
    }

    /// Model text or model, parsed: `Gmwm::parse("3*GM()+WN()")`.
    ///
    /// # Errors
    /// The model's [`ModelParseError`](crate::model::ModelParseError).
    pub fn parse(text: &str) -> Result<Self, crate::model::ModelParseError> {
        Ok(Self::new(Model::parse(text)?))
    }

    /// Sets the replicates H and rounds K of [`Weighting::Bootstrap`] (docs/methods.md §5.2;
    /// defaults 100 and 1).
    ///
    /// # Errors
    /// [`ParamError`] for `replicates < 2` (no covariance) or `rounds == 0`.
    pub fn with_bootstrap(mut self, replicates: usize, rounds: usize) -> Result<Self, ParamError> {
        if replicates < 2 {
            return Err(ParamError::new(
                "bootstrap replicates",
                replicates,
                "must be at least 2 (a variance needs two replicates)",
            ));
        }
        if rounds == 0 {
            return Err(ParamError::new(
                "bootstrap rounds",
                rounds,
                "must be at least 1",
            ));
        }
        self.bootstrap_replicates = replicates;
        self.bootstrap_rounds = rounds;
        Ok(self)
    }

    /// Sets the weighting (docs/methods.md §5.2); default [`Weighting::Fast`].
    pub fn with_weighting(mut self, weighting: Weighting) -> Self {
        self.weighting = weighting;
        self
    }

    /// Sets the transform preset (docs/methods.md §5.3); default [`TransformPreset::Imu`].
    pub(crate) fn with_preset(mut self, preset: TransformPreset) -> Self {
        self.preset = preset;
        self
    }

    /// Sets how several AR1/GM components are parametrised; default [`PhiOrder::Ordered`].
    pub(crate) fn with_phi_order(mut self, phi_order: PhiOrder) -> Self {
        self.phi_order = phi_order;
        self
    }

    /// Sets the seed of the starting-value search (docs/methods.md §5.7; default 1337).
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.start_options.seed = seed;
        self
    }

    /// Sets the number of starting-value draws G (default `super::start::default_draws`).
    pub fn with_draws(mut self, draws: usize) -> Self {
        self.start_options.draws = Some(draws);
        self
    }

    /// Caps the optimiser's accepted steps (default 2000; 0 is taken as 1). A fit that reaches the cap ends
    /// "not converged" (the fit's `convergence()` says so): for callers that bound
    /// the time of a fit whatever the data (the fuzz targets), not for estimates.
    ///
    /// ```
    /// use gmwm::{Gmwm, Model};
    /// let gmwm = Gmwm::new("AR1()+WN()".parse::<Model>().unwrap()).with_max_iterations(100);
    /// # let _ = gmwm;
    /// ```
    pub fn with_max_iterations(mut self, iterations: usize) -> Self {
        self.options.max_iterations = iterations.max(1);
        self
    }

    /// The weighting (docs/methods.md §5.2).
    pub fn weighting(&self) -> Weighting {
        self.weighting
    }

    /// The model template.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// Transform preset, phi order and optimiser options (for the fits built outside this
    /// file, e.g. [`super::pooled`]).
    pub(crate) fn settings(&self) -> (TransformPreset, PhiOrder, LmOptions) {
        (self.preset, self.phi_order, self.options)
    }

    /// This estimator's settings (weighting, transforms, phi order, optimiser, search) for
    /// another model, in guess mode.
    pub fn for_model(&self, model: Model) -> Gmwm {
        let mut g = self.clone();
        g.given = vec![None; model.n_params()];
        g.model = model.without_values();
        g
    }

    /// Fits the model to an empirical WV (docs/methods.md §5.5) from `start` (theta in model order,
    /// original parametrisation). Works with the fast and bootstrap weightings; the diag weights
    /// need the series ([`Gmwm::fit`]).
    ///
    /// # Errors
    /// [`FitError::Length`] for a wrong-length start or [`Weighting::Diag`]; errors of
    /// [`Weights::fast`], `Parametrisation::to_u` (a start outside its domain) and
    /// `Objective::new` (more parameters than levels; a robust WV needs one level more,
    /// §5.7, reported with `params` counting that extra one); [`FitError::BadStart`] when the
    /// start is not a valid model.
    pub fn fit_wv(
        &self,
        wv: &WaveletVariance,
        freq_hz: f64,
        start: &[f64],
    ) -> Result<GmwmFit, FitError> {
        super::check_haar(wv.filter)?;
        let weights = Weights::new(self.weighting, wv, None)?;
        self.check_robust_levels(wv)?;
        let fit = self.fit_weighted(&wv.wv, weights, freq_hz, start)?;
        self.finish(fit, wv, StartInputs::from_wv(wv))
    }

    /// docs/methods.md §5.7: a robust fit needs parameters + 1 <= J.
    fn check_robust_levels(&self, wv: &WaveletVariance) -> Result<(), FitError> {
        let params = self.model.n_params();
        if wv.robust.is_some() && params + 1 > wv.levels() {
            return Err(FitError::TooFewLevels {
                params: params + 1,
                levels: wv.levels(),
            });
        }
        Ok(())
    }

    /// Computes the WV of `x` (docs/methods.md §5.5 step 3, with `wv_options`) and the weights,
    /// then fits as [`Gmwm::fit_wv`]; works with every [`Weighting`].
    ///
    /// # Errors
    /// As [`wavelet_variance`] (wrapped in [`FitError::Input`]) and [`Gmwm::fit_wv`].
    #[cfg(test)]
    pub(crate) fn fit_series(
        &self,
        x: &[f64],
        freq_hz: f64,
        wv_options: &WvOptions,
        start: &[f64],
    ) -> Result<GmwmFit, FitError> {
        super::check_haar(wv_options.filter)?;
        let wv = wavelet_variance(x, freq_hz, wv_options)?;
        let weights = Weights::new(self.weighting, &wv, Some(x))?;
        self.check_robust_levels(&wv)?;
        let fit = self.fit_weighted(&wv.wv, weights, freq_hz, start)?;
        self.finish(fit, &wv, StartInputs::from_series(x))
    }

    /// docs/methods.md §5.5 step 8 and §5.9: the bootstrap rounds when asked, then the empirical WV
    /// and the search inputs are attached to the fit (for `update` and reporting).
    pub(crate) fn finish(
        &self,
        mut fit: GmwmFit,
        wv: &WaveletVariance,
        inputs: StartInputs,
    ) -> Result<GmwmFit, FitError> {
        if self.weighting == Weighting::Bootstrap {
            let org_v = fit.weights.v.clone();
            let opts = WvOptions {
                transform: wv.transform,
                filter: wv.filter,
                levels: Some(wv.levels()),
                alpha: wv.alpha,
                robust: wv.robust,
            };
            for round in 0..self.bootstrap_rounds {
                let seed = self.start_options.seed.wrapping_add(1 + round as u64);
                let boot = wv_bootstrap(
                    &fit.model,
                    wv.n,
                    fit.freq_hz,
                    &opts,
                    self.bootstrap_replicates,
                    seed,
                )?;
                let weights = Weights::from_v(boot.variances(), "bootstrap variance")?;
                let start = fit.theta.clone();
                let keep = fit.start.clone();
                fit = self.fit_weighted(&wv.wv, weights, fit.freq_hz, &start)?;
                fit.start = keep;
            }
            fit.org_v = Some(org_v);
            fit.bootstrap_replicates = Some(self.bootstrap_replicates);
        }
        fit.empirical = Some(wv.clone());
        fit.inputs = Some(inputs);
        Ok(fit)
    }

    /// The package's `update` (docs/methods.md §5.9): fits this estimator's model to the WV stored
    /// in `fit` with `fit`'s original (fast or diag) weights, without recomputing the WV. Values
    /// in this model are starting values as in [`Gmwm::fit`]; the starting-value search uses
    /// this estimator's seed and G and the stored N and range.
    ///
    /// ```
    /// use gmwm::{simulate_model, Gmwm, Model, WvOptions};
    /// let truth = Model::parse("AR1(phi=0.99, sigma2=0.01)+WN(sigma2=1)").unwrap();
    /// let x = simulate_model(&truth, 20_000, 1.0, 3).unwrap();
    /// let full = Gmwm::parse("AR1()+WN()+RW()").unwrap().with_draws(2000);
    /// let fit = full.fit(&x, 1.0, &WvOptions::default()).unwrap();
    /// let small = Gmwm::parse("AR1()+WN()").unwrap().with_draws(2000).update(&fit).unwrap();
    /// assert_eq!(small.empirical(), fit.empirical());
    /// ```
    ///
    /// # Errors
    /// [`FitError::Length`] (what = "stored WV") when `fit` carries no empirical WV (a fit made
    /// by `Gmwm::fit_weighted` alone); as [`Gmwm::fit_from_wv`].
    pub fn update(&self, fit: &GmwmFit) -> Result<GmwmFit, FitError> {
        let (Some(wv), Some(inputs)) = (&fit.empirical, fit.inputs) else {
            return Err(FitError::Length {
                what: "stored WV",
                expected: fit.nu_hat.len(),
                found: 0,
            });
        };
        super::check_haar(wv.filter)?;
        let weights = match &fit.org_v {
            Some(v) => Weights::from_v(v.clone(), "stored variance")?,
            None => fit.weights.clone(),
        };
        let refit = self.fit_auto(wv, weights, inputs)?;
        self.finish(refit, wv, inputs)
    }

    /// Fits the model to `nu_hat` with the given weights from `start` (a value exactly on the
    /// edge of its domain, as an earlier estimate can be, starts just inside:
    /// [`Parametrisation::to_u_restart`]).
    ///
    /// # Errors
    /// As [`Gmwm::fit_wv`].
    pub(crate) fn fit_weighted(
        &self,
        nu_hat: &[f64],
        weights: Weights,
        freq_hz: f64,
        start: &[f64],
    ) -> Result<GmwmFit, FitError> {
        let param = Parametrisation::new(&self.model, self.preset, self.phi_order, freq_hz)?;
        let start = Parametrisation::canonical_order(&self.model, start)?;
        let u0 = param.to_u_restart(&start)?;
        let param_names = param.names().to_vec();
        let objective = Objective::new(&self.model, param.clone(), nu_hat, &weights, freq_hz)?;
        let mut min = minimize(&objective, &u0, &self.options)?;
        // docs/methods.md §5.6 (port): stable sort of the AR1/GM blocks, phi decreasing (a no-op
        // for the ordered chain); then leave a false boundary point (components fitted to nothing
        // that the data want back, fit::revive), at most MAX_REVIVALS times
        let mut revivals = 0;
        let (theta, fitted, implied_wv) = loop {
            let theta = Parametrisation::canonical_order(&self.model, &min.theta)?;
            let fitted = self.model.with_values(&theta)?;
            let implied = fitted.implied_wv(nu_hat.len(), freq_hz)?;
            let revived = if revivals < MAX_REVIVALS {
                revival_start(
                    &fitted,
                    &theta,
                    &implied,
                    nu_hat,
                    &weights.omega,
                    freq_hz,
                    min.objective,
                )?
            } else {
                None
            };
            // a start the transforms refuse (e.g. two AR1s with equal phi) is no revival
            let next = revived
                .and_then(|r| {
                    Parametrisation::canonical_order(&self.model, &r)
                        .and_then(|t| param.to_u_restart(&t))
                        .ok()
                })
                .map(|u| minimize(&objective, &u, &self.options))
                .transpose()?;
            match next {
                Some(next) if next.objective < min.objective => {
                    let (it, ev) = (min.convergence.iterations, min.convergence.evaluations);
                    min = next;
                    min.convergence.iterations += it;
                    min.convergence.evaluations += ev;
                    revivals += 1;
                }
                _ => break (theta, fitted, implied),
            }
        };
        let mut fit = GmwmFit {
            weighting: self.weighting,
            org_v: None,
            bootstrap_replicates: None,
            empirical: None,
            inputs: None,
            collapsed: Vec::new(),
            estimates: FitEstimates {
                model: fitted,
                theta,
                param_names,
                objective: min.objective,
                convergence: min.convergence,
                freq_hz,
            },
            start,
            nu_hat: nu_hat.to_vec(),
            implied_wv,
            weights,
            preset: self.preset,
            phi_order: self.phi_order,
        };
        let active = fit.active_parameters();
        fit.collapsed = (0..fit.theta.len())
            .filter(|k| !active.contains(k))
            .map(|k| fit.param_names[k].clone())
            .collect();
        Ok(fit)
    }
}

/// The result of a GMWM fit (docs/methods.md §5.9).
///
/// Wire format: `model` (text with the estimates), `theta` and `param_names` (model order,
/// original parametrisation, GM as `beta`, `sigma2_gm`), `start`, `objective` (`Q`, §5.1),
/// `convergence` (`iterations`, `evaluations`, `reason`, `converged`), `nu_hat`, `implied_wv`
/// (model and per component), `weights` (`v`, `omega`: the final weights), `weighting`,
/// `org_v` (bootstrap weighting only: the fast V of the first fit), `bootstrap_replicates`,
/// `empirical` (the WV with its CI), `inputs` (`n`, `range`), `freq_hz`, `preset`,
/// `phi_order`. [`GmwmFit::parameters`] and [`GmwmFit::navigation`] give the per-parameter
/// and physical-unit views.
#[derive(Debug, Clone, PartialEq)]
pub struct GmwmFit {
    /// The model with the estimates, `theta`, their labels, `Q(theta_hat)` (docs/methods.md
    /// §5.1), how the optimiser ended and the sampling rate: what every fit reports.
    pub(crate) estimates: FitEstimates,
    /// The starting values used (after the §5.6 ordering).
    pub(crate) start: Vec<f64>,
    /// The empirical WV fitted.
    pub(crate) nu_hat: Vec<f64>,
    /// Implied WV at the estimates, per component too (§5.5 step 11).
    pub(crate) implied_wv: ImpliedWv,
    /// The weights (V and Omega diagonals).
    pub(crate) weights: Weights,
    /// Transform preset used.
    pub(crate) preset: TransformPreset,
    /// AR1/GM parametrisation used.
    pub(crate) phi_order: PhiOrder,
    /// Which weighting produced `weights` (docs/methods.md §5.2).
    pub(crate) weighting: Weighting,
    /// The fast V of the first fit when the bootstrap weighting replaced it (the package's
    /// `orgV`); `None` otherwise (then `weights.v` is `orgV`).
    pub(crate) org_v: Option<Vec<f64>>,
    /// Replicates H of the bootstrap weighting, when used.
    pub(crate) bootstrap_replicates: Option<usize>,
    /// The empirical WV fitted, with its CI (`None` only for a bare `Gmwm::fit_weighted`).
    pub(crate) empirical: Option<WaveletVariance>,
    /// Series length and range behind the starting values (docs/methods.md §6.1), kept for
    /// `update`.
    pub(crate) inputs: Option<StartInputs>,
    /// Labels of the parameters of the components fitted to nothing (implied WV below
    /// `super::NEGLIGIBLE_WV_SHARE` of the model's at every level,
    /// [`GmwmFit::active_parameters`]): the fit is a boundary point and a smaller model fits as
    /// well. Inference reports these parameters without a standard error.
    pub(crate) collapsed: Vec<String>,
}

/// The estimates every fit reports ([`FitEstimates`]), read through the fit: `fit.theta()`.
impl std::ops::Deref for GmwmFit {
    type Target = FitEstimates;
    fn deref(&self) -> &FitEstimates {
        &self.estimates
    }
}

/// The wire format of the type's doc, field by field in that order (the estimates are not one
/// block there: `start` comes before `objective`, `freq_hz` after `weights`).
impl Serialize for GmwmFit {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let e = &self.estimates;
        let mut st = serializer.serialize_struct("GmwmFit", 18)?;
        st.serialize_field("model", &e.model)?;
        st.serialize_field("theta", &e.theta)?;
        st.serialize_field("param_names", &e.param_names)?;
        st.serialize_field("start", &self.start)?;
        st.serialize_field("objective", &e.objective)?;
        st.serialize_field("convergence", &e.convergence)?;
        st.serialize_field("nu_hat", &self.nu_hat)?;
        st.serialize_field("implied_wv", &self.implied_wv)?;
        st.serialize_field("weights", &self.weights)?;
        st.serialize_field("freq_hz", &e.freq_hz)?;
        st.serialize_field("preset", &self.preset)?;
        st.serialize_field("phi_order", &self.phi_order)?;
        st.serialize_field("weighting", &self.weighting)?;
        st.serialize_field("org_v", &self.org_v)?;
        st.serialize_field("bootstrap_replicates", &self.bootstrap_replicates)?;
        st.serialize_field("empirical", &self.empirical)?;
        st.serialize_field("inputs", &self.inputs)?;
        st.serialize_field("collapsed", &self.collapsed)?;
        st.end()
    }
}

/// Read access to the results; the fields are the engine's own.
impl GmwmFit {
    /// The starting values used (after the §5.6 ordering).
    pub fn start(&self) -> &[f64] {
        &self.start
    }

    /// The empirical WV fitted.
    pub fn nu_hat(&self) -> &[f64] {
        &self.nu_hat
    }

    /// Implied WV at the estimates, per component too (§5.5 step 11).
    pub fn implied_wv(&self) -> &ImpliedWv {
        &self.implied_wv
    }

    /// The weights (V and Omega diagonals).
    pub fn weights(&self) -> &Weights {
        &self.weights
    }

    /// Which weighting produced `weights` (docs/methods.md §5.2).
    pub fn weighting(&self) -> Weighting {
        self.weighting
    }

    /// The fast V of the first fit when the bootstrap weighting replaced it (the package's
    /// `orgV`); `None` otherwise (then `weights.v` is `orgV`).
    #[cfg(test)]
    pub(crate) fn org_v(&self) -> Option<&[f64]> {
        self.org_v.as_deref()
    }

    /// Replicates H of the bootstrap weighting, when used.
    pub fn bootstrap_replicates(&self) -> Option<usize> {
        self.bootstrap_replicates
    }

    /// The empirical WV fitted, with its CI (`None` only for a bare `Gmwm::fit_weighted`).
    pub fn empirical(&self) -> Option<&WaveletVariance> {
        self.empirical.as_ref()
    }

    /// Series length and range behind the starting values (docs/methods.md §6.1), kept for
    /// `update`.
    pub fn inputs(&self) -> Option<StartInputs> {
        self.inputs
    }

    /// Labels of the parameters of the components fitted to nothing (implied WV below
    /// `super::NEGLIGIBLE_WV_SHARE` of the model's at every level,
    /// `GmwmFit::active_parameters`): the fit is a boundary point and a smaller model fits as
    /// well. Inference reports these parameters without a standard error.
    pub fn collapsed(&self) -> &[String] {
        &self.collapsed
    }
}
