//! Deterministic drift (docs/methods.md §0.2, §4.2, §10.1).

use super::{CovariancePart, ParamTransform, Role, BASE};
use crate::process::sampler::SimRng;
use serde::Serialize;

use super::{add_scaled, half_widths, LatentProcess, Occurs, Params, Simulate, Spec};
use crate::error::ParamError;
use crate::process::sampler::{Sampler, Step};
use crate::process::ParamDomain;
use crate::process::StartMode;

/// `DR(omega)`: may appear once in a model; `omega` has any sign.
pub(crate) const SPEC: Spec = Spec {
    name: "DR",
    syntax: "DR()",
    params: Params::Fixed(&[("omega", ParamDomain::Finite)], (0, 0)),
    orders: None,
    occurs: Occurs::Once,
    build: |_, v, _| Ok(Dr::new(v[0])?.into()),
    role: Role::Drift,
    transforms: |_, _| vec![ParamTransform::LogAbs],
    draw: |d, _, given, out| {
        let r = d.ctx.range;
        // docs/methods.md §6.3: U(R / 100, R / 2)
        out.push(given[0].unwrap_or_else(|| d.unif(r / 100.0, r / 2.0)));
    },
    unit_shapes: |_, _| vec![(vec![1.0], f64::sqrt)],
    physical: |v, f, u| vec![("drift_rate", v[0] * f, format!("{u}/s"))],
    ..BASE
};

/// Deterministic drift: the ramp `x_t = omega (t + 1)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Dr {
    /// Slope per sample (any sign).
    pub(crate) omega: f64,
}

impl Dr {
    /// Slope per sample.
    pub fn omega(&self) -> f64 {
        self.omega
    }
}

impl Dr {
    /// Builds the process.
    ///
    /// # Errors
    /// [`ParamError`] naming `omega` unless it is finite.
    pub fn new(omega: f64) -> Result<Self, ParamError> {
        if !omega.is_finite() {
            return Err(ParamError::new("omega", omega, "a finite number"));
        }
        Ok(Self { omega })
    }
}

/// docs/methods.md §4.2: `nu2 = omega^2 tau^2 / 16`, `tau = 2m`.
fn unit_wv(m: f64) -> f64 {
    let tau = 2.0 * m;
    tau * tau / 16.0
}

impl LatentProcess for Dr {
    fn name(&self) -> &'static str {
        SPEC.name
    }
    fn param_names(&self) -> Vec<&'static str> {
        SPEC.fixed_names()
    }
    fn params(&self) -> Vec<f64> {
        vec![self.omega]
    }
    fn wv(&self, levels: usize) -> Vec<f64> {
        half_widths(levels)
            .map(|m| self.omega * self.omega * unit_wv(m))
            .collect()
    }
    fn add_wv(&self, out: &mut [f64]) {
        add_scaled(out, self.omega * self.omega, unit_wv);
    }
    fn jacobian(&self, levels: usize) -> Vec<Vec<f64>> {
        half_widths(levels)
            .map(|m| vec![2.0 * self.omega * unit_wv(m)])
            .collect()
    }
    fn write_jacobian(&self, levels: usize, a: &mut [f64], stride: usize, col: usize) {
        super::write_scalar_jacobian(levels, a, stride, col, |m| 2.0 * self.omega * unit_wv(m));
    }
    fn hessian(&self, levels: usize) -> Vec<Vec<Vec<f64>>> {
        half_widths(levels)
            .map(|m| vec![vec![2.0 * unit_wv(m)]])
            .collect()
    }
    fn spectral_density(&self, f: f64) -> Option<f64> {
        let _ = f;
        None
    }
}

/// docs/methods.md §10.1: `x_t = omega (t + 1)`, t = 0, 1, ... across chunks (no randomness).
#[derive(Debug, Clone)]
struct DrSampler {
    omega: f64,
    t: u64,
}

impl Step for DrSampler {
    #[inline]
    fn step(&mut self) -> f64 {
        self.t += 1;
        self.omega * self.t as f64
    }
}

impl Simulate for Dr {
    fn covariance_part(&self) -> Result<CovariancePart, ParamError> {
        Ok(CovariancePart::Drift(self.omega))
    }
    fn sampler(&self, _: SimRng, _: StartMode) -> Result<Box<dyn Sampler>, ParamError> {
        Ok(Box::new(DrSampler {
            omega: self.omega,
            t: 0,
        }))
    }
}
