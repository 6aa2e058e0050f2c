//! What every GMWM fit reports, one recording's ([`GmwmFit`](super::GmwmFit)) or several's
//! ([`PooledFit`](super::PooledFit)): one type, read through either fit.

use super::Convergence;
use crate::model::Model;
use serde::Serialize;

/// The estimates of a GMWM fit (docs/methods.md §5.9, §5.11): the model with its estimated
/// values, `theta` and its labels, the objective at the minimum, how the optimiser ended and
/// the sampling rate. Both fits dereference to it, so `fit.theta()` reads the same on either.
///
/// Wire format (flattened into the fit's): `model` (text with the estimates), `theta`,
/// `param_names`, `objective`, `convergence`, `freq_hz`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitEstimates {
    pub(crate) model: Model,
    pub(crate) theta: Vec<f64>,
    pub(crate) param_names: Vec<String>,
    pub(crate) objective: f64,
    pub(crate) convergence: Convergence,
    pub(crate) freq_hz: f64,
}

impl FitEstimates {
    /// The model with the estimates.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// FitEstimates in model order (original parametrisation).
    pub fn theta(&self) -> &[f64] {
        &self.theta
    }

    /// Labels of `theta`, `KIND[component].name`.
    pub fn param_names(&self) -> &[String] {
        &self.param_names
    }

    /// The objective at the estimates: `Q(theta_hat)` (docs/methods.md §5.1), or for a pooled
    /// fit `Q_pool(theta_hat) = sum_k Q_k(theta_hat)` (§5.11).
    pub fn objective(&self) -> f64 {
        self.objective
    }

    /// How the optimiser ended.
    pub fn convergence(&self) -> Convergence {
        self.convergence
    }

    /// Sampling rate in Hz (a pooled fit's: its first recording's).
    pub fn freq_hz(&self) -> f64 {
        self.freq_hz
    }
}
