//! First-order moving average (docs/methods.md §0.2, §4.2, §4.5, §4.6, §10.1).

use super::{CovariancePart, ParamTransform, Role, BASE};
use crate::math::elementary;
use crate::process::sampler::SimRng;
use serde::Serialize;

use super::{
    check_positive, check_unit, jet_levels, jets_hessian, jets_jacobian, Jet, LatentProcess,
    Occurs, Params, Simulate, Spec,
};
use crate::error::ParamError;
use crate::process::sampler::{normal, Sampler, Step};
use crate::process::ParamDomain;
use crate::process::StartMode;

/// `MA1(theta, sigma2)`: an ARMA(0, 1), of the ARMA family.
pub(crate) const SPEC: Spec = Spec {
    name: "MA1",
    syntax: "MA1()",
    params: Params::Fixed(
        &[
            ("theta", ParamDomain::UnitInterval),
            ("sigma2", ParamDomain::Variance),
        ],
        (0, 1),
    ),
    orders: None,
    occurs: Occurs::ArmaFamily,
    build: |_, v, _| Ok(Ma1::new(v[0], v[1])?.into()),
    role: Role::Other,
    transforms: |_, preset| vec![preset.unit_coefficient(), ParamTransform::Log],
    draw: |d, _, given, out| {
        // §6.5 port rule: theta ~ U(0, 1), sigma2 = sigma2_T / (1 + theta^2)
        let t = given[0].unwrap_or_else(|| d.unif(0.0, 1.0));
        out.push(t);
        out.push(given[1].unwrap_or(d.ctx.sigma2_t / (1.0 + t * t)));
    },
    ..BASE
};

/// First-order moving average `x_t = w_t + theta w_{t-1}`, `Var w_t = sigma2`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Ma1 {
    /// Moving-average coefficient, `|theta| < 1` (invertible, hence identifiable).
    pub(crate) theta: f64,
    /// Innovation variance per sample.
    pub(crate) sigma2: f64,
}

impl Ma1 {
    /// MA coefficient.
    pub fn theta(&self) -> f64 {
        self.theta
    }
    /// Innovation variance per sample.
    pub fn sigma2(&self) -> f64 {
        self.sigma2
    }
}

impl Ma1 {
    /// Builds an MA1. Every finite `theta` gives a valid process, but `theta` and `1/theta` give
    /// the same autocovariances up to scale; only the invertible `|theta| < 1` is accepted.
    ///
    /// # Errors
    /// [`ParamError`] naming `theta` unless `|theta| < 1`, or `sigma2` unless finite and `> 0`.
    pub fn new(theta: f64, sigma2: f64) -> Result<Self, ParamError> {
        check_unit("theta", theta, "|theta| < 1 for an invertible MA1")?;
        check_positive("sigma2", sigma2)?;
        Ok(Self { theta, sigma2 })
    }

    fn jets<const H: bool>(&self, levels: usize) -> Vec<Jet<2, H>> {
        jet_levels([self.theta, self.sigma2], levels, |v, m| {
            ma1_wv_jet(v[0], v[1], m)
        })
    }
}

/// docs/methods.md §4.2 (MA1 row): `nu2 = sigma2 [(1 + theta)^2 tau - 6 theta] / tau^2`, `tau =
/// 2m`.
pub(crate) fn ma1_wv_jet<const N: usize, const H: bool>(
    theta: Jet<N, H>,
    sigma2: Jet<N, H>,
    m: f64,
) -> Jet<N, H> {
    let tau = 2.0 * m;
    sigma2 * ((theta + 1.0).powi(2) * tau - theta * 6.0) / (tau * tau)
}

impl LatentProcess for Ma1 {
    fn name(&self) -> &'static str {
        SPEC.name
    }
    fn param_names(&self) -> Vec<&'static str> {
        SPEC.fixed_names()
    }
    fn params(&self) -> Vec<f64> {
        vec![self.theta, self.sigma2]
    }
    fn wv(&self, levels: usize) -> Vec<f64> {
        self.jets::<false>(levels).iter().map(|j| j.v).collect()
    }
    fn jacobian(&self, levels: usize) -> Vec<Vec<f64>> {
        jets_jacobian(&self.jets::<false>(levels))
    }
    fn hessian(&self, levels: usize) -> Vec<Vec<Vec<f64>>> {
        jets_hessian(&self.jets::<true>(levels))
    }
    fn spectral_density(&self, f: f64) -> Option<f64> {
        let s = elementary::sin(std::f64::consts::PI * f);
        let t = self.theta;
        Some(self.sigma2 * ((1.0 + t) * (1.0 + t) - 4.0 * t * s * s))
    }
}

/// docs/methods.md §10.1: `x_t = w_t + theta w_{t-1}`, stationary in both start modes (one extra
/// innovation `w` drawn first).
#[derive(Debug, Clone)]
struct Ma1Sampler {
    rng: SimRng,
    theta: f64,
    sd: f64,
    w: f64,
}

impl Step for Ma1Sampler {
    #[inline]
    fn step(&mut self) -> f64 {
        let next = self.sd * normal(&mut self.rng);
        let x = next + self.theta * self.w;
        self.w = next;
        x
    }
}

impl Simulate for Ma1 {
    fn covariance_part(&self) -> Result<CovariancePart, ParamError> {
        Ok(CovariancePart::Autoregressive {
            phi: 0.0,
            r0: self.sigma2 * (1.0 + self.theta * self.theta),
            r1: self.sigma2 * self.theta,
        })
    }
    fn sampler(&self, mut rng: SimRng, _: StartMode) -> Result<Box<dyn Sampler>, ParamError> {
        let sd = self.sigma2.sqrt();
        let w = sd * normal(&mut rng);
        Ok(Box::new(Ma1Sampler {
            rng,
            theta: self.theta,
            sd,
            w,
        }))
    }
}
