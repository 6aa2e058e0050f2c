//! Quantisation noise (METHODS §0.2, §4.2).

use serde::{Deserialize, Serialize};

use super::{add_scaled, check_positive, half_widths, LatentProcess};
use crate::error::ParamError;

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
        "QN"
    }
    fn param_names(&self) -> Vec<&'static str> {
        vec!["q2"]
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
