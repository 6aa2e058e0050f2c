//! Random walk (docs/methods.md §0.2, §4.2, §10.1).

use super::{CovariancePart, ParamTransform, Role, BASE};
use crate::math::elementary;
use crate::process::sampler::SimRng;
use serde::Serialize;

use super::ar1::Ar1Sampler;
use super::{
    add_scaled, check_positive, half_widths, LatentProcess, Occurs, Params, Simulate, Spec,
};
use crate::error::ParamError;
use crate::process::sampler::Sampler;
use crate::process::ParamDomain;
use crate::process::StartMode;

/// `RW(gamma2)`: may appear once in a model.
pub(crate) const SPEC: Spec = Spec {
    name: "RW",
    syntax: "RW()",
    params: Params::Fixed(&[("gamma2", ParamDomain::Variance)], (0, 0)),
    orders: None,
    occurs: Occurs::Once,
    build: |_, v, _| Ok(Rw::new(v[0])?.into()),
    role: Role::RandomWalk,
    transforms: |_, _| vec![ParamTransform::Log],
    draw: |d, _, given, out| {
        let (st, n) = (d.ctx.sigma2_t, d.ctx.n);
        // docs/methods.md §6.3: U(1e-5 sigma2_T / N, sigma2_T / N)
        out.push(given[0].unwrap_or_else(|| d.unif(1e-5 * st / n, st / n)));
    },
    unit_shapes: |_, _| vec![(vec![1.0], |t| t)],
    physical: |v, f, u| {
        vec![(
            "rate_random_walk_density",
            (v[0] * f).sqrt(),
            format!("{u}*sqrt(Hz)"),
        )]
    },
    ..BASE
};

/// Random walk: cumulative sum of white noise with increment variance `gamma2`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Rw {
    /// Increment variance.
    pub(crate) gamma2: f64,
}

impl Rw {
    /// Increment variance per sample.
    pub fn gamma2(&self) -> f64 {
        self.gamma2
    }
}

impl Rw {
    /// Builds the process.
    ///
    /// # Errors
    /// [`ParamError`] naming `gamma2` unless it is finite and > 0.
    pub fn new(gamma2: f64) -> Result<Self, ParamError> {
        check_positive("gamma2", gamma2)?;
        Ok(Self { gamma2 })
    }
}

/// docs/methods.md §4.2: `nu2 = gamma2 (tau^2 + 2) / (12 tau)`, `tau = 2m`.
fn unit_wv(m: f64) -> f64 {
    let tau = 2.0 * m;
    (tau * tau + 2.0) / (12.0 * tau)
}

impl LatentProcess for Rw {
    fn name(&self) -> &'static str {
        SPEC.name
    }
    fn param_names(&self) -> Vec<&'static str> {
        SPEC.fixed_names()
    }
    fn params(&self) -> Vec<f64> {
        vec![self.gamma2]
    }
    fn wv(&self, levels: usize) -> Vec<f64> {
        half_widths(levels)
            .map(|m| self.gamma2 * unit_wv(m))
            .collect()
    }
    fn add_wv(&self, out: &mut [f64]) {
        add_scaled(out, self.gamma2, unit_wv);
    }
    fn jacobian(&self, levels: usize) -> Vec<Vec<f64>> {
        half_widths(levels).map(|m| vec![unit_wv(m)]).collect()
    }
    fn write_jacobian(&self, levels: usize, a: &mut [f64], stride: usize, col: usize) {
        super::write_scalar_jacobian(levels, a, stride, col, unit_wv);
    }
    fn hessian(&self, levels: usize) -> Vec<Vec<Vec<f64>>> {
        half_widths(levels).map(|_| vec![vec![0.0]]).collect()
    }
    fn spectral_density(&self, f: f64) -> Option<f64> {
        let s = elementary::sin(std::f64::consts::PI * f);
        Some(self.gamma2 / (4.0 * s * s))
    }
}

impl Simulate for Rw {
    fn covariance_part(&self) -> Result<CovariancePart, ParamError> {
        Ok(CovariancePart::RandomWalk(self.gamma2))
    }
    fn sampler(&self, rng: SimRng, _: StartMode) -> Result<Box<dyn Sampler>, ParamError> {
        // docs/methods.md §10.1: `x_t = sum_{i=0}^{t} w_i`, `w ~ N(0, gamma2)` (the first value is
        // `w_0`, not 0): the AR1 recursion with phi = 1 from x = 0, whose products by 1 are
        // exact, so the blocks of four are the running sum's
        Ok(Box::new(Ar1Sampler::new(rng, 1.0, self.gamma2.sqrt(), 0.0)))
    }
}
