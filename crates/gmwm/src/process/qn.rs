//! Quantisation noise (METHODS §0.2, §4.2).

use serde::{Deserialize, Serialize};

use super::{add_scaled, check_positive, half_widths, LatentProcess, Occurs, Params, Spec};
use crate::error::ParamError;
use crate::model::ParamDomain;

/// `QN(q2)`: may appear once in a model.
pub(crate) const SPEC: Spec = Spec {
    name: "QN",
    syntax: "QN()",
    params: Params::Fixed(&[("q2", ParamDomain::Variance)], (0, 0)),
    orders: None,
    occurs: Occurs::Once,
    build: |_, v, _| Ok(Qn::new(v[0])?.into()),
};

/// Quantisation noise: first difference of white noise of variance `q2`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Qn {
    /// Quantisation parameter Q^2.
    pub q2: f64,
}

impl Qn {
    /// Builds the process.
    ///
    /// # Errors
    /// [`ParamError`] naming `q2` unless it is finite and > 0.
    pub fn new(q2: f64) -> Result<Self, ParamError> {
        check_positive("q2", q2)?;
        Ok(Self { q2 })
    }
}

/// METHODS §4.2: `nu2 = 6 q2 / tau^2`, `tau = 2m`.
fn unit_wv(m: f64) -> f64 {
    let tau = 2.0 * m;
    6.0 / (tau * tau)
}

impl LatentProcess for Qn {
    fn name(&self) -> &'static str {
        SPEC.name
    }
    fn param_names(&self) -> Vec<&'static str> {
        SPEC.fixed_names()
    }
    fn params(&self) -> Vec<f64> {
        vec![self.q2]
    }
    fn wv(&self, levels: usize) -> Vec<f64> {
        half_widths(levels).map(|m| self.q2 * unit_wv(m)).collect()
    }
    fn add_wv(&self, out: &mut [f64]) {
        add_scaled(out, self.q2, unit_wv);
    }
    fn jacobian(&self, levels: usize) -> Vec<Vec<f64>> {
        half_widths(levels).map(|m| vec![unit_wv(m)]).collect()
    }
    fn hessian(&self, levels: usize) -> Vec<Vec<Vec<f64>>> {
        half_widths(levels).map(|_| vec![vec![0.0]]).collect()
    }
    fn spectral_density(&self, f: f64) -> Option<f64> {
        let s = (std::f64::consts::PI * f).sin();
        Some(4.0 * self.q2 * s * s)
    }
}
