//! ARMA(1,1) (docs/methods.md §0.2, §4.2, §4.5, §4.6).
//!
//! Near `phi = 1` the closed form cancels like the AR1 one. Its autocovariance is
//! `gamma_0 = sigma2 (1 + 2 theta phi + theta^2)/(1 - phi^2)`,
//! `gamma_h = sigma2 (1 + theta phi)(phi + theta) phi^{h-1}/(1 - phi^2)` (h >= 1), i.e. white
//! noise of variance `-sigma2 theta / phi` plus an AR1 with innovation variance
//! `sigma2 (1 + theta phi)(phi + theta)/phi`; by linearity of §4.1 the WV is the sum of theirs,
//! and the AR1 part uses the stable evaluation of [`super::ar1`]. This is used for
//! `phi > 1/2`; below, the closed form is used as written.

use super::{CovariancePart, ParamTransform, Role, BASE};
use crate::math::elementary;
use crate::process::sampler::SimRng;
use serde::Serialize;

use super::ar1::ar1_wv_jet;
use super::{
    check_positive, check_unit, jet_levels, jets_hessian, jets_jacobian, one_minus, Jet,
    LatentProcess, Occurs, Params, Simulate, Spec,
};
use crate::error::ParamError;
use crate::process::sampler::{normal, Sampler, Step};
use crate::process::ParamDomain;
use crate::process::StartMode;

/// `ARMA11(phi, theta, sigma2)`: of the ARMA family.
pub(crate) const SPEC: Spec = Spec {
    name: "ARMA11",
    syntax: "ARMA11()",
    params: Params::Fixed(
        &[
            ("phi", ParamDomain::UnitInterval),
            ("theta", ParamDomain::UnitInterval),
            ("sigma2", ParamDomain::Variance),
        ],
        (1, 1),
    ),
    orders: None,
    occurs: Occurs::ArmaFamily,
    build: |_, v, _| Ok(Arma11::new(v[0], v[1], v[2])?.into()),
    role: Role::Other,
    transforms: |_, _| {
        use ParamTransform as T;
        vec![T::PseudoLogit, T::PseudoLogit, T::Log]
    },
    draw: super::arma::draw,
    ..BASE
};

/// From this `phi` on, the WN + AR1 decomposition of the module doc is used (it divides by
/// `phi`, so it is not used near 0, where the closed form has no cancellation).
const DECOMPOSE_FROM_PHI: f64 = 0.5;

/// ARMA(1,1) `x_t = phi x_{t-1} + w_t + theta w_{t-1}`, `Var w_t = sigma2`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Arma11 {
    /// Autoregressive coefficient, `|phi| < 1`.
    pub(crate) phi: f64,
    /// Moving-average coefficient, `|theta| < 1`.
    pub(crate) theta: f64,
    /// Innovation variance per sample.
    pub(crate) sigma2: f64,
}

impl Arma11 {
    /// AR coefficient.
    pub fn phi(&self) -> f64 {
        self.phi
    }
    /// MA coefficient.
    pub fn theta(&self) -> f64 {
        self.theta
    }
    /// Innovation variance per sample.
    pub fn sigma2(&self) -> f64 {
        self.sigma2
    }
}

impl Arma11 {
    /// Builds an ARMA(1,1).
    ///
    /// # Errors
    /// [`ParamError`] naming `phi` unless `|phi| < 1` (stationarity), `theta` unless
    /// `|theta| < 1` (invertibility), or `sigma2` unless finite and `> 0`.
    pub fn new(phi: f64, theta: f64, sigma2: f64) -> Result<Self, ParamError> {
        check_unit("phi", phi, "|phi| < 1 for a stationary ARMA11")?;
        check_unit("theta", theta, "|theta| < 1 for an invertible ARMA11")?;
        check_positive("sigma2", sigma2)?;
        Ok(Self { phi, theta, sigma2 })
    }

    fn jets<const H: bool>(&self, levels: usize) -> Vec<Jet<3, H>> {
        jet_levels([self.phi, self.theta, self.sigma2], levels, |v, m| {
            arma11_wv_jet(v[0], v[1], v[2], m)
        })
    }
}

/// docs/methods.md §4.2 (ARMA11 row):
/// `nu2 = sigma2 [(1+theta)^2 (1-phi^2) tau - 2 (theta+phi)(1+theta phi) K] / [tau^2 (1-phi)^3 (1+phi)]`,
/// `K = 3 - 4 phi^{tau/2} + phi^tau`; for `phi > 1/2` through the decomposition of the module doc.
pub(crate) fn arma11_wv_jet<const N: usize, const H: bool>(
    phi: Jet<N, H>,
    theta: Jet<N, H>,
    sigma2: Jet<N, H>,
    m: f64,
) -> Jet<N, H> {
    let tau = 2.0 * m;
    if phi.v > DECOMPOSE_FROM_PHI {
        let wn = -(sigma2 * theta / phi) / tau;
        let s_ar = sigma2 * (theta * phi + 1.0) * (phi + theta) / phi;
        wn + ar1_wv_jet(phi, None, s_ar, m)
    } else {
        let a = phi.powi(m as i32);
        let k = -a * 4.0 + a * a + 3.0;
        let n = (theta + 1.0).powi(2) * one_minus(phi * phi) * tau
            - (theta + phi) * (theta * phi + 1.0) * k * 2.0;
        let d = one_minus(phi).powi(3) * (phi + 1.0) * (tau * tau);
        sigma2 * n / d
    }
}

impl LatentProcess for Arma11 {
    fn name(&self) -> &'static str {
        SPEC.name
    }
    fn param_names(&self) -> Vec<&'static str> {
        SPEC.fixed_names()
    }
    fn params(&self) -> Vec<f64> {
        vec![self.phi, self.theta, self.sigma2]
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
        let s2 = s * s;
        let (p, t) = (self.phi, self.theta);
        let num = (1.0 + t) * (1.0 + t) - 4.0 * t * s2;
        let den = (1.0 - p) * (1.0 - p) + 4.0 * p * s2;
        Some(self.sigma2 * num / den)
    }
}

/// docs/methods.md §10.1: `x_t = phi x_{t-1} + w_t + theta w_{t-1}`; `(x, w)` are the last values.
#[derive(Debug, Clone)]
struct Arma11Sampler {
    rng: SimRng,
    phi: f64,
    theta: f64,
    sd: f64,
    x: f64,
    w: f64,
}

impl Step for Arma11Sampler {
    #[inline]
    fn step(&mut self) -> f64 {
        let next = self.sd * normal(&mut self.rng);
        self.x = self.phi * self.x + next + self.theta * self.w;
        self.w = next;
        self.x
    }
}

impl Simulate for Arma11 {
    fn covariance_part(&self) -> Result<CovariancePart, ParamError> {
        let (phi, theta, s2) = (self.phi, self.theta, self.sigma2);
        let den = (1.0 - phi) * (1.0 + phi);
        Ok(CovariancePart::Autoregressive {
            phi,
            r0: s2 * (1.0 + 2.0 * phi * theta + theta * theta) / den,
            r1: s2 * (1.0 + phi * theta) * (phi + theta) / den,
        })
    }
    /// Draws `w_{-1}`, then in [`StartMode::Stationary`] `x_{-1}` from the stationary joint law
    /// (`Cov(x, w) = sigma2`, `Var x = gamma_0`: `x_{-1} = w_{-1} + N(0, gamma_0 - sigma2)`,
    /// `gamma_0 - sigma2 = sigma2 (phi + theta)^2 / (1 - phi^2)`); in [`StartMode::Zero`]
    /// `x_{-1} = 0`, so the first value is `w_0 + theta w_{-1}`.
    fn sampler(&self, mut rng: SimRng, start: StartMode) -> Result<Box<dyn Sampler>, ParamError> {
        let (phi, theta, sigma2) = (self.phi, self.theta, self.sigma2);
        let sd = sigma2.sqrt();
        let w = sd * normal(&mut rng);
        let x = if start == StartMode::Stationary {
            w + (sigma2 / (1.0 - phi * phi)).sqrt() * (phi + theta).abs() * normal(&mut rng)
        } else {
            0.0
        };
        Ok(Box::new(Arma11Sampler {
            rng,
            phi,
            theta,
            sd,
            x,
            w,
        }))
    }
}
