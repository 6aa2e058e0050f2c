//! The full GMWM pipeline with generated starting values (docs/methods.md §5.4–§5.5, §6).
//!
//! A fully specified model starts from its values and only stage 2 (minimise `Q`) runs.
//! Otherwise the §6 search gives the best draw, stage 1 minimises the flattening objective
//! `F` from it and stage 2 minimises `Q` from the stage-1 result. As cheap insurance against
//! a poor stage 1 (a port addition), stage 2 is also run directly from the best draw and the
//! fit with the lower final `Q` is kept. `GmwmFit::start` records the start used: the user's
//! values or the best draw (after the §5.6 ordering).

use super::start::{starting_values, StartInputs};
use super::{FitError, Gmwm, GmwmFit, Parametrisation, Weights};
use crate::model::{Component, Model};
use crate::variance::wv::{wavelet_variance, WaveletVariance, WvOptions};

impl Gmwm {
    /// Computes the WV of `x` (with `wv_opts`) and fits the model (docs/methods.md §5.5),
    /// generating starting values unless the model is fully specified. Works with every weighting.
    ///
    /// # Errors
    /// As [`wavelet_variance`] (in [`FitError::Input`]), [`Weights::new`],
    /// `starting_values` and `Gmwm::fit_weighted`.
    pub fn fit(&self, x: &[f64], freq_hz: f64, wv_opts: &WvOptions) -> Result<GmwmFit, FitError> {
        super::check_haar(wv_opts.filter)?;
        let wv = wavelet_variance(x, freq_hz, wv_opts)?;
        let weights = Weights::new(self.weighting(), &wv, Some(x))?;
        let inputs = StartInputs::from_series(x);
        let fit = self.fit_auto(&wv, weights, inputs)?;
        self.finish(fit, &wv, inputs)
    }

    /// Fits a precomputed WV (its `freq_hz` is used), generating starting values unless the
    /// model is fully specified; `inputs` supplies N and R (e.g. [`StartInputs::from_wv`]).
    /// Needs a weighting that does not need the series (fast or bootstrap, not diag).
    ///
    /// # Errors
    /// As [`Gmwm::fit`] ([`FitError::Length`] for the diag weighting).
    pub fn fit_from_wv(
        &self,
        wv: &WaveletVariance,
        inputs: StartInputs,
    ) -> Result<GmwmFit, FitError> {
        super::check_haar(wv.filter)?;
        let weights = Weights::new(self.weighting(), wv, None)?;
        let fit = self.fit_auto(wv, weights, inputs)?;
        self.finish(fit, wv, inputs)
    }

    /// The model template carrying the user's (partial) values.
    fn given_model(&self) -> Result<Model, FitError> {
        let mut at = 0;
        let mut comps = Vec::with_capacity(self.model().n_components());
        for c in self.model().components() {
            let n = c.kind.n_params();
            let values = self.given.get(at..at + n).ok_or(FitError::Length {
                what: "model values",
                expected: self.model().n_params(),
                found: self.given.len(),
            })?;
            at += n;
            comps.push(Component::new(c.kind, values.to_vec())?);
        }
        Ok(Model::new(comps)?)
    }

    /// The search and two-stage fit on given weights (no bootstrap rounds, nothing attached).
    pub(crate) fn fit_auto(
        &self,
        wv: &WaveletVariance,
        weights: Weights,
        inputs: StartInputs,
    ) -> Result<GmwmFit, FitError> {
        let params = self.model().n_params();
        if wv.robust.is_some() && params + 1 > wv.levels() {
            return Err(FitError::TooFewLevels {
                params: params + 1,
                levels: wv.levels(),
            });
        }
        let freq_hz = wv.freq_hz;
        let nu = &wv.wv;
        if self.given.iter().all(Option::is_some) {
            let start: Vec<f64> = self.given.iter().flatten().copied().collect();
            return self.fit_weighted(nu, weights, freq_hz, &start);
        }
        let given_model = self.given_model()?;
        let best = starting_values(&given_model, wv, &inputs, &self.start_options)?;
        let start = Parametrisation::canonical_order(self.model(), &best.theta)?;
        let stage1 = self
            .fit_weighted(nu, Weights::flattening(nu)?, freq_hz, &best.theta)
            .and_then(|s1| self.fit_weighted(nu, weights.clone(), freq_hz, &s1.theta));
        let direct = self.fit_weighted(nu, weights, freq_hz, &best.theta);
        let mut fit = match (stage1, direct) {
            (Ok(a), Ok(b)) => {
                if b.objective < a.objective {
                    b
                } else {
                    a
                }
            }
            (Ok(a), Err(_)) => a,
            (Err(_), Ok(b)) => b,
            (Err(e), Err(_)) => return Err(e),
        };
        fit.start = start;
        Ok(fit)
    }
}
