//! Components a fit drove to the boundary of the parameter space (a variance to 0, a drift to
//! omega = 0), and the sub-model of the others.
//!
//! Such a component contributes nothing to the implied WV and stays there under small changes
//! of `nu2_hat`: its derivative `d theta_hat / d nu2_hat'` is zero, its Jacobian column (and,
//! for an AR1 whose variance vanished, its phi's column) is zero, and its value may lie outside
//! the domain of its transform (a drift of exactly 0). Standard errors, the sandwich
//! (docs/methods.md §7.1), the J-test (§7.3), the bootstrap refits (§7.4) and the optimism
//! (§8.2–§8.3) are therefore computed on the active sub-model, which has the same implied WV and
//! objective; the boundary parameters are reported without a standard error.

use super::{FitError, GmwmFit};
use crate::model::{Component, ImpliedWv, Model};

/// A component whose implied WV is below this share of the model's at every level counts as
/// fitted to nothing; its effect on the objective is of the order of this share, far below
/// what separates candidate models or moves an estimate.
pub(crate) const NEGLIGIBLE_WV_SHARE: f64 = 1e-6;

/// Per component of `implied`, whether it contributes: its implied WV exceeds
/// [`NEGLIGIBLE_WV_SHARE`] of the model's at some level.
pub(crate) fn active_components(implied: &ImpliedWv) -> Vec<bool> {
    implied
        .processes
        .iter()
        .map(|c| {
            c.wv.iter()
                .zip(&implied.wv)
                .any(|(x, t)| x.abs() > NEGLIGIBLE_WV_SHARE * t.abs())
        })
        .collect()
}

/// The active components of a fit as a guess-mode model (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SubModel {
    /// The active components, in model order, without values.
    pub(crate) model: Model,
    /// Indices into the full theta of the sub-model's parameters.
    pub(crate) keep: Vec<usize>,
    /// The fit's estimates of those parameters (a starting point for refits).
    pub(crate) start: Vec<f64>,
}

impl SubModel {
    /// The full theta: `theta` (the sub-model's parameters) at the kept indices, `boundary`
    /// (the full fit's values) elsewhere.
    pub(crate) fn expand(&self, theta: &[f64], boundary: &[f64]) -> Vec<f64> {
        let mut out = boundary.to_vec();
        for (&k, &t) in self.keep.iter().zip(theta) {
            out[k] = t;
        }
        out
    }
}

impl GmwmFit {
    /// Indices (into theta) of the parameters of the components that contribute to the fit:
    /// all but those whose implied WV is below [`NEGLIGIBLE_WV_SHARE`] of the model's at every
    /// level (see the module docs).
    pub(crate) fn active_parameters(&self) -> Vec<usize> {
        let mut keep = Vec::with_capacity(self.theta.len());
        let mut at = 0;
        let active = active_components(&self.implied_wv);
        for (c, active) in self.model.components().iter().zip(active) {
            let k = c.kind.n_params();
            if active {
                keep.extend(at..at + k);
            }
            at += k;
        }
        keep
    }

    /// The fitted model without its inactive components (with their estimates): what the
    /// parametric bootstraps simulate, so that a component at the boundary does not shift
    /// their random streams. The whole fitted model when all are active.
    ///
    /// # Errors
    /// As [`GmwmFit::active_sub_model`].
    pub(crate) fn active_model(&self) -> Result<Model, FitError> {
        match self.active_sub_model()? {
            Some(sub) => Ok(sub.model.with_values(&sub.start)?),
            None => Ok(self.model.clone()),
        }
    }

    /// The sub-model of the active components, or `None` when every component is active (or
    /// none is: a model fitted to nothing is kept whole).
    ///
    /// # Errors
    /// [`FitError::Input`] if the sub-model cannot be built (it always can: its components
    /// are a subset of a valid model's).
    pub(crate) fn active_sub_model(&self) -> Result<Option<SubModel>, FitError> {
        let keep = self.active_parameters();
        if keep.len() == self.theta.len() || keep.is_empty() {
            return Ok(None);
        }
        let mut components = Vec::new();
        let mut at = 0;
        for c in self.model.components() {
            if keep.contains(&at) {
                components.push(Component::guess(c.kind));
            }
            at += c.kind.n_params();
        }
        let model = Model::new(components)?;
        let start = keep.iter().map(|&k| self.theta[k]).collect();
        Ok(Some(SubModel { model, keep, start }))
    }
}
