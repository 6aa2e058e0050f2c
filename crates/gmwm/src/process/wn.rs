//! White noise (docs/methods.md §0.2, §4.2, §10.1).

use crate::process::sampler::SimRng;
use serde::Serialize;

use super::draw::{Dominance, Draw};
use super::{
    add_scaled, check_positive, half_widths, CovariancePart, LatentProcess, Occurs, ParamTransform,
    Params, ProcessKind, Role, Simulate, Spec, BASE,
};
use crate::error::ParamError;
use crate::process::sampler::{normal, Sampler, Step};
use crate::process::ParamDomain;
use crate::process::StartMode;

/// `WN(sigma2)`: may appear once in a model.
pub(crate) const SPEC: Spec = Spec {
    name: "WN",
    syntax: "WN()",
    params: Params::Fixed(&[("sigma2", ParamDomain::Variance)], (0, 0)),
    orders: None,
    occurs: Occurs::Once,
    build: |_, v, _| Ok(Wn::new(v[0])?.into()),
    role: Role::WhiteNoise,
    transforms: |_, _| vec![ParamTransform::Log],
    draw,
    unit_shapes: |_, _| vec![(vec![1.0], |t| t)],
    physical: white_noise_density,
    ..BASE
};

/// The white-noise density `sqrt(sigma2 / f)` of a term whose first parameter is its (long-run)
/// per-sample variance: WN, and the filter term `MAF(L)` (`maf.rs`).
pub(crate) fn white_noise_density(v: &[f64], f: f64, u: &str) -> Vec<super::Physical> {
    vec![(
        "white_noise_density",
        (v[0] / f).sqrt(),
        format!("{u}/sqrt(Hz)"),
    )]
}

/// docs/methods.md §6.3: `U(sigma2_T / 2, sigma2_T)` where white noise dominates the first
/// scales (or is the only term), else `U(1e-5 sigma2_T, 0.1 sigma2_T)`; also the filter term's
/// (`maf.rs`).
pub(crate) fn draw(d: &mut Draw<'_>, _: ProcessKind, given: &[Option<f64>], out: &mut Vec<f64>) {
    let (st, dominant) = (d.ctx.sigma2_t, d.ctx.only_wn || d.ctx.dom == Dominance::Wn);
    out.push(given[0].unwrap_or_else(|| {
        if dominant {
            d.unif(st / 2.0, st)
        } else {
            d.unif(1e-5 * st, 0.1 * st)
        }
    }));
}

/// White noise: independent samples of variance `sigma2`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Wn {
    /// Variance per sample.
    pub(crate) sigma2: f64,
}

impl Wn {
    /// Variance per sample.
    pub fn sigma2(&self) -> f64 {
        self.sigma2
    }
}

impl Wn {
    /// Builds the process.
    ///
    /// # Errors
    /// [`ParamError`] naming `sigma2` unless it is finite and > 0.
    pub fn new(sigma2: f64) -> Result<Self, ParamError> {
        check_positive("sigma2", sigma2)?;
        Ok(Self { sigma2 })
    }
}

/// docs/methods.md §4.2: `nu2 = sigma2 / tau`, `tau = 2m`.
fn unit_wv(m: f64) -> f64 {
    let tau = 2.0 * m;
    1.0 / tau
}

impl LatentProcess for Wn {
    fn name(&self) -> &'static str {
        SPEC.name
    }
    fn param_names(&self) -> Vec<&'static str> {
        SPEC.fixed_names()
    }
    fn params(&self) -> Vec<f64> {
        vec![self.sigma2]
    }
    fn wv(&self, levels: usize) -> Vec<f64> {
        half_widths(levels)
            .map(|m| self.sigma2 * unit_wv(m))
            .collect()
    }
    fn add_wv(&self, out: &mut [f64]) {
        add_scaled(out, self.sigma2, unit_wv);
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
        let _ = f;
        Some(self.sigma2)
    }
}

/// docs/methods.md §10.1: `x_t ~ N(0, sigma2)` i.i.d.
#[derive(Debug, Clone)]
struct WnSampler {
    rng: SimRng,
    sd: f64,
}

impl Step for WnSampler {
    #[inline]
    fn step(&mut self) -> f64 {
        self.sd * normal(&mut self.rng)
    }
}

impl Simulate for Wn {
    fn covariance_part(&self) -> Result<CovariancePart, ParamError> {
        Ok(CovariancePart::White(self.sigma2))
    }
    fn sampler(&self, rng: SimRng, _: StartMode) -> Result<Box<dyn Sampler>, ParamError> {
        Ok(Box::new(WnSampler {
            rng,
            sd: self.sigma2.sqrt(),
        }))
    }
}
