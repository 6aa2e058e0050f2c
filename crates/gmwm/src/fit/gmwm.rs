//! The GMWM estimator settings and the fit from caller-given starting values (METHODS §5.5
//! steps 3, 4, 6, 10–12); the fit with generated starting values (§6) is in [`super::auto`],
//! the bootstrap V is not here yet.

use super::{
    minimize, Convergence, FitError, LmOptions, Objective, Parametrisation, PhiOrder, StartOptions,
    TransformPreset, Weighting, Weights,
};
use crate::model::{format_value, ImpliedWv, Model};
use crate::variance::wv::{wavelet_variance, WaveletVariance, WvOptions};
use serde::Serialize;
use std::fmt;

/// GMWM estimator settings (METHODS §5): the model and how to fit it. Build with
/// [`Gmwm::new`] and the `with_*` setters, then call [`Gmwm::fit_wv`] or [`Gmwm::fit_series`].
///
/// ```
/// use gmwm::fit::Gmwm;
/// use gmwm::model::Model;
/// use gmwm::{sim::simulate_model, wavelet_variance, WvOptions};
/// let truth = Model::parse("AR1(phi=0.9, sigma2=0.1)+WN(sigma2=1)").unwrap();
/// let x = simulate_model(&truth, 10_000, 1.0, 1).unwrap();
/// let wv = wavelet_variance(&x, 1.0, &WvOptions::default()).unwrap();
/// let fit = Gmwm::new(Model::parse("AR1()+WN()").unwrap())
///     .fit_wv(&wv, 1.0, &[0.5, 0.5, 0.5])
///     .unwrap();
/// assert!(fit.convergence.converged);
/// assert!((fit.theta[0] - 0.9).abs() < 0.05);
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
    /// Starting-value search settings (METHODS §6).
    pub(crate) start_options: StartOptions,
}

impl Gmwm {
    /// An estimator of `model` with the IMU defaults: fast weights, IMU transforms, ordered
    /// AR1/GM components. Its values are ignored by the explicit-start fits
    /// ([`Gmwm::fit_wv`], ...) and used by [`Gmwm::fit`] / [`Gmwm::fit_from_wv`]: all given
    /// means the start, some given means kept in the starting-value draws (METHODS §6).
    pub fn new(model: Model) -> Self {
        Self {
            given: model.values(),
            start_options: StartOptions::default(),
            model: model.without_values(),
            weighting: Weighting::Fast,
            preset: TransformPreset::Imu,
            phi_order: PhiOrder::Ordered,
            options: LmOptions::default(),
        }
    }

    /// Sets the weighting (METHODS §5.2); default [`Weighting::Fast`].
    pub fn with_weighting(mut self, weighting: Weighting) -> Self {
        self.weighting = weighting;
        self
    }

    /// Sets the transform preset (METHODS §5.3); default [`TransformPreset::Imu`].
    pub fn with_preset(mut self, preset: TransformPreset) -> Self {
        self.preset = preset;
        self
    }

    /// Sets how several AR1/GM components are parametrised; default [`PhiOrder::Ordered`].
    pub fn with_phi_order(mut self, phi_order: PhiOrder) -> Self {
        self.phi_order = phi_order;
        self
    }

    /// Sets the optimiser options; default [`LmOptions::default`].
    pub fn with_options(mut self, options: LmOptions) -> Self {
        self.options = options;
        self
    }

    /// Sets the seed of the starting-value search (METHODS §5.7; default 1337).
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.start_options.seed = seed;
        self
    }

    /// Sets the number of starting-value draws G (default [`super::start::default_draws`]).
    pub fn with_draws(mut self, draws: usize) -> Self {
        self.start_options.draws = Some(draws);
        self
    }

    /// The weighting (METHODS §5.2).
    pub fn weighting(&self) -> Weighting {
        self.weighting
    }

    /// The model template.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// Fits the model to an empirical WV (METHODS §5.5) from `start` (theta in model order,
    /// original parametrisation). Needs [`Weighting::Fast`]: the diag weights need the series
    /// ([`Gmwm::fit_series`]).
    ///
    /// # Errors
    /// [`FitError::Length`] for a wrong-length start or [`Weighting::Diag`]; errors of
    /// [`Weights::fast`], [`Parametrisation::to_u`] (a start outside its domain) and
    /// [`Objective::new`] (more parameters than levels; a robust WV needs one level more,
    /// §5.7, reported with `params` counting that extra one); [`FitError::BadStart`] when the
    /// start is not a valid model.
    pub fn fit_wv(
        &self,
        wv: &WaveletVariance,
        freq_hz: f64,
        start: &[f64],
    ) -> Result<GmwmFit, FitError> {
        let weights = Weights::new(self.weighting, wv, None)?;
        self.check_robust_levels(wv)?;
        self.fit_weighted(&wv.wv, weights, freq_hz, start)
    }

    /// METHODS §5.7: a robust fit needs parameters + 1 <= J.
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

    /// Computes the WV of `x` (METHODS §5.5 step 3, with `wv_options`) and the weights, then
    /// fits as [`Gmwm::fit_wv`]; works with every [`Weighting`].
    ///
    /// # Errors
    /// As [`wavelet_variance`] (wrapped in [`FitError::Engine`]) and [`Gmwm::fit_wv`].
    pub fn fit_series(
        &self,
        x: &[f64],
        freq_hz: f64,
        wv_options: &WvOptions,
        start: &[f64],
    ) -> Result<GmwmFit, FitError> {
        let wv = wavelet_variance(x, freq_hz, wv_options)?;
        let weights = Weights::new(self.weighting, &wv, Some(x))?;
        self.check_robust_levels(&wv)?;
        self.fit_weighted(&wv.wv, weights, freq_hz, start)
    }

    /// Fits the model to `nu_hat` with the given weights from `start`.
    ///
    /// # Errors
    /// As [`Gmwm::fit_wv`].
    pub fn fit_weighted(
        &self,
        nu_hat: &[f64],
        weights: Weights,
        freq_hz: f64,
        start: &[f64],
    ) -> Result<GmwmFit, FitError> {
        let param = Parametrisation::new(&self.model, self.preset, self.phi_order, freq_hz)?;
        let start = Parametrisation::canonical_order(&self.model, start)?;
        let u0 = param.to_u(&start)?;
        let param_names = param.names().to_vec();
        let objective = Objective::new(&self.model, param, nu_hat, &weights, freq_hz)?;
        let min = minimize(&objective, &u0, &self.options)?;
        // METHODS §5.6 (port): stable sort of the AR1/GM blocks, phi decreasing (a no-op for
        // the ordered chain)
        let theta = Parametrisation::canonical_order(&self.model, &min.theta)?;
        let fitted = self.model.with_values(&theta).map_err(crate::Error::from)?;
        let implied_wv = fitted.implied_wv(nu_hat.len(), freq_hz)?;
        Ok(GmwmFit {
            model: fitted,
            theta,
            param_names,
            start,
            objective: min.objective,
            convergence: min.convergence,
            nu_hat: nu_hat.to_vec(),
            implied_wv,
            weights,
            freq_hz,
            preset: self.preset,
            phi_order: self.phi_order,
        })
    }
}

/// The result of a GMWM fit (METHODS §5.9, the fields implemented so far).
///
/// Wire format: `model` (text with the estimates), `theta` and `param_names` (model order,
/// original parametrisation, GM as `beta`, `sigma2_gm`), `start`, `objective` (`Q`, §5.1),
/// `convergence` (`iterations`, `evaluations`, `reason`, `converged`), `nu_hat`, `implied_wv`
/// (model and per component), `weights` (`v`, `omega`), `freq_hz`, `preset`, `phi_order`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GmwmFit {
    /// The model with the estimates.
    pub model: Model,
    /// Estimates in model order (original parametrisation).
    pub theta: Vec<f64>,
    /// Labels of `theta`, `KIND[component].name`.
    pub param_names: Vec<String>,
    /// The starting values used (after the §5.6 ordering).
    pub start: Vec<f64>,
    /// `Q(theta_hat)` (METHODS §5.1).
    pub objective: f64,
    /// How the optimiser ended.
    pub convergence: Convergence,
    /// The empirical WV fitted.
    pub nu_hat: Vec<f64>,
    /// Implied WV at the estimates, per component too (§5.5 step 11).
    pub implied_wv: ImpliedWv,
    /// The weights (V and Omega diagonals).
    pub weights: Weights,
    /// Sampling rate in Hz.
    pub freq_hz: f64,
    /// Transform preset used.
    pub preset: TransformPreset,
    /// AR1/GM parametrisation used.
    pub phi_order: PhiOrder,
}

impl fmt::Display for GmwmFit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "GMWM fit of {} at {} Hz", self.model, self.freq_hz)?;
        writeln!(f, "{:<20} {:>14} {:>14}", "parameter", "estimate", "start")?;
        for ((name, t), s) in self.param_names.iter().zip(&self.theta).zip(&self.start) {
            writeln!(
                f,
                "{name:<20} {:>14} {:>14}",
                format_value(*t),
                format_value(*s)
            )?;
        }
        writeln!(f, "objective Q = {:e}", self.objective)?;
        write!(f, "optimiser: {}", self.convergence)
    }
}
