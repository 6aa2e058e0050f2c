//! Quantisation noise (docs/methods.md §0.2, §4.2, §10.1).

use super::draw::{Dominance, Draw};
use super::{CovariancePart, ParamTransform, ProcessKind, Role, BASE};
use crate::math::elementary;
use crate::process::sampler::SimRng;
use serde::Serialize;

use super::{
    add_scaled, check_positive, half_widths, LatentProcess, Occurs, Params, Simulate, Spec,
};
use crate::error::ParamError;
use crate::process::sampler::{uniform, Sampler, Step};
use crate::process::ParamDomain;
use crate::process::StartMode;

/// `QN(q2)`: may appear once in a model.
pub(crate) const SPEC: Spec = Spec {
    name: "QN",
    syntax: "QN()",
    params: Params::Fixed(&[("q2", ParamDomain::Variance)], (0, 0)),
    orders: None,
    occurs: Occurs::Once,
    build: |_, v, _| Ok(Qn::new(v[0])?.into()),
    role: Role::Quantization,
    transforms: |_, _| vec![ParamTransform::Log],
    draw,
    unit_shapes: |_, _| vec![(vec![1.0], |t| t)],
    physical: |v, f, u| {
        vec![(
            "quantization_coefficient",
            v[0].sqrt() / f,
            format!("{u}*s"),
        )]
    },
    ..BASE
};

/// docs/methods.md §6.3: `U(sigma2_T / 8, sigma2_T / 3)` where quantisation noise dominates the
/// first scales (or is the only term), else `U(5e-6 sigma2_T, sigma2_T / 100)`.
fn draw(d: &mut Draw<'_>, _: ProcessKind, given: &[Option<f64>], out: &mut Vec<f64>) {
    let (st, dominant) = (d.ctx.sigma2_t, d.ctx.only_qn || d.ctx.dom == Dominance::Qn);
    out.push(given[0].unwrap_or_else(|| {
        if dominant {
            d.unif(st / 8.0, st / 3.0)
        } else {
            d.unif(5e-6 * st, st / 100.0)
        }
    }));
}

/// `sqrt(12)`: scales `U(0, 1)` to variance 1 for quantisation noise (docs/methods.md §10.1).
const SQRT_12: f64 = 3.464_101_615_137_754_6;

/// Quantisation noise: first difference of white noise of variance `q2`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Qn {
    /// Quantisation parameter Q^2.
    pub(crate) q2: f64,
}

impl Qn {
    /// Quantisation variance parameter Q^2.
    pub fn q2(&self) -> f64 {
        self.q2
    }
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

/// docs/methods.md §4.2: `nu2 = 6 q2 / tau^2`, `tau = 2m`.
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
    fn write_jacobian(&self, levels: usize, a: &mut [f64], stride: usize, col: usize) {
        super::write_scalar_jacobian(levels, a, stride, col, unit_wv);
    }
    fn hessian(&self, levels: usize) -> Vec<Vec<Vec<f64>>> {
        half_widths(levels).map(|_| vec![vec![0.0]]).collect()
    }
    fn spectral_density(&self, f: f64) -> Option<f64> {
        let s = elementary::sin(std::f64::consts::PI * f);
        Some(4.0 * self.q2 * s * s)
    }
}

/// One QN value from consecutive uniforms (docs/methods.md §10.1): `sqrt(q2) (u_{t+1} - u_t)`.
#[inline]
pub(crate) fn qn_value(sqrt_q2: f64, u_t: f64, u_next: f64) -> f64 {
    sqrt_q2 * (u_next - u_t)
}

/// docs/methods.md §10.1: `x_t = sqrt(q2) (u_{t+1} - u_t)`, `u ~ sqrt(12) U(0, 1)`; `u` is the last
/// uniform drawn.
#[derive(Debug, Clone)]
struct QnSampler {
    rng: SimRng,
    sqrt_q2: f64,
    u: f64,
}

impl Step for QnSampler {
    #[inline]
    fn step(&mut self) -> f64 {
        let next = SQRT_12 * uniform(&mut self.rng);
        let x = qn_value(self.sqrt_q2, self.u, next);
        self.u = next;
        x
    }
}

impl Simulate for Qn {
    fn covariance_part(&self) -> Result<CovariancePart, ParamError> {
        Ok(CovariancePart::Quantization(self.q2))
    }
    fn sampler(&self, mut rng: SimRng, _: StartMode) -> Result<Box<dyn Sampler>, ParamError> {
        let u = SQRT_12 * uniform(&mut rng);
        Ok(Box::new(QnSampler {
            rng,
            sqrt_q2: self.q2.sqrt(),
            u,
        }))
    }
}
