//! Sinusoid with random phase, the vibration term of Voirol, Cucci, Karemera, Chu, Molinari and
//! Guerrier, "Accounting for Vibration Noise in Stochastic Measurement Errors", IEEE TSP
//! (arXiv 2303.18167).
//!
//! `x_t = amplitude sin(2 pi omega t + phi)`, `phi ~ U(0, 2 pi)`, `t` in samples: a stationary
//! process with autocovariance `gamma_h = (amplitude^2 / 2) cos(2 pi omega h)`, a line spectrum
//! of power `amplitude^2 / 4` at `+-omega`. Its Haar WV is that power times the squared gain of
//! the level-j Haar filter (docs/methods.md §1.9) at both lines:
//!
//! `nu2_j = (amplitude^2 / 2) sin^4(pi omega m) / (m^2 sin^2(pi omega))`, `m = 2^{j-1}`,
//!
//! which the §4.1 sum over these autocovariances reproduces (the tests compare the two).
//!
//! # Parametrisation
//! `SIN(amplitude, omega)`: `amplitude` in the data unit (`> 0`, the peak of the sinusoid; its
//! variance is `amplitude^2 / 2`), `omega` in cycles per sample in the open interval
//! `(0, 1/2)` (below Nyquist; `omega` and `1 - omega` are the same line). The physical read-off
//! is `frequency = omega freq_hz` (Hz) and `amplitude` (data unit). In a fit, `amplitude` is
//! log-transformed and `omega` logit-transformed on `(0, 1/2)` under both presets
//! ([`ParamTransform::LogitHalf`]).
//!
//! # Where the hump lies
//! With `x = pi omega m`, `nu2_j` is `(amplitude^2 / 2) (pi omega / sin(pi omega))^2 sin^4(x) /
//! x^2`; `sin^4(x) / x^2` is largest at `tan x = 2 x`, `x = 1.1656`, where it is `0.525`. The WV
//! of a sinusoid is therefore a hump peaking at `tau = 2 m = 2 x / (pi omega) = 0.742 / omega`
//! samples (0.742 periods), of height about half its variance, and falls as `tau^-2` beyond
//! (with zeros at `tau = 2 k / omega`).
//!
//! # Evaluation
//! The argument `pi omega m` is reduced by the nearest integer `k` of `omega m` before the sine
//! (`omega m` is exact: `m` is a power of 2), so that deep levels keep full precision;
//! `sin^4` is blind to the sign `(-1)^k`. Derivatives are exact (forward-mode jets).

use super::draw::Draw;
use super::{
    half_widths, jet_levels, jets_hessian, jets_jacobian, Jet, LatentProcess, Occurs,
    ParamTransform, Params, Physical, ProcessKind, Role, Simulate, Spec, BASE,
};
use crate::error::ParamError;
use crate::math::elementary;
use crate::process::sampler::{uniform, Sampler, SimRng, Step};
use crate::process::ParamDomain;
use crate::process::StartMode;
use serde::Serialize;
use std::f64::consts::PI;

/// `SIN(amplitude, omega)`: any number of times in a model (one per vibration line); no navigation read-off of N, K, B, its
/// physical read-off is its frequency (Hz) and amplitude.
pub(crate) const SPEC: Spec = Spec {
    name: "SIN",
    syntax: "SIN()",
    params: Params::Fixed(
        &[
            ("amplitude", ParamDomain::Positive),
            ("omega", ParamDomain::HalfCycle),
        ],
        (0, 0),
    ),
    orders: None,
    occurs: Occurs::Repeats,
    build: |_, v, _| Ok(Sin::new(v[0], v[1])?.into()),
    role: Role::Periodic,
    transforms: |_, _| vec![ParamTransform::Log, ParamTransform::LogitHalf],
    draw,
    physical,
    // several vibration lines are listed by frequency
    rank: |v| v[1],
    ..BASE
};

/// The smallest power share `amplitude^2 / (2 sigma2_T)` a draw tries.
const POWER_SHARE_MIN: f64 = 1e-4;
/// The largest power share: the hump peaks at about half the variance (module doc) and cannot
/// exceed `sigma2_T`, the sum of the WV.
const POWER_SHARE_MAX: f64 = 2.0;
/// The highest `omega` a draw tries, just below Nyquist.
const OMEGA_MAX: f64 = 0.49;

/// The peak of `sin^4(x) / x^2` (module doc): the hump of a sinusoid lies at
/// `tau = 2 HUMP_X / (pi omega)` samples.
const HUMP_X: f64 = 1.165_561_185_207_2;
/// The share of draws that start at the empirical WV's hump when it has one.
const HUMP_SHARE: f64 = 0.9;
/// Its height: the hump's WV is about `HUMP_HEIGHT amplitude^2 / 2`.
const HUMP_HEIGHT: f64 = 0.525;

/// The humps of the empirical WV: the levels among `2..=J - 3` (the last levels are too noisy
/// to place a hump) where it exceeds the geometric mean of its neighbours (`ln nu2` locally
/// concave) by a larger share than at the levels either side (one entry per hump, not one per
/// level of a wide hump), as `(tau_j, nu2_j - sqrt(nu2_{j-1} nu2_{j+1}))`, largest excess first
/// (a sinusoid's side lobes, beside the zeros of its WV, are humps of large share and small
/// excess).
fn wv_humps(wv: &[f64]) -> Vec<(f64, f64)> {
    let last = wv.len().saturating_sub(3);
    let share = |j: usize| {
        if j == 0 || j + 1 >= wv.len() {
            return f64::NEG_INFINITY;
        }
        let mean = (wv[j - 1] * wv[j + 1]).sqrt();
        let e = (wv[j] - mean) / mean;
        if e.is_finite() {
            e
        } else {
            f64::NEG_INFINITY
        }
    };
    let mut humps: Vec<(f64, f64)> = (1..last)
        .filter(|&j| share(j) > 0.0 && share(j) >= share(j - 1) && share(j) >= share(j + 1))
        .map(|j| {
            let e = wv[j] - (wv[j - 1] * wv[j + 1]).sqrt();
            (2f64.powi(j as i32 + 1), e)
        })
        .collect();
    humps.sort_by(|a, b| b.1.total_cmp(&a.1));
    humps
}

/// Starting values (the §6.3 search, paper Appendix C, extended): a sinusoid's signature is
/// a hump peaking at `tau = 0.742 / omega` samples of height about `0.525 amplitude^2 / 2`
/// (module doc). [`HUMP_SHARE`] of the draws start at one of the two largest humps of the
/// empirical WV ([`wv_humps`]), at random (at the hump nearest a given `omega`'s peak when
/// `omega` is given):
/// `omega` log-uniform within a factor 2 of `0.742 / tau` (one level either side) and
/// `amplitude^2 / 2` within a factor 3 of the excess over `0.525`. The others, and all
/// draws when the WV has no hump, are broad: `omega` log-uniform between two cycles over the
/// series (`2 / N`) and [`OMEGA_MAX`], `amplitude^2 / 2` a log-uniform share of `sigma2_T`
/// between [`POWER_SHARE_MIN`] and [`POWER_SHARE_MAX`]. The search keeps the draw whose WV
/// fits best, so this is a multi-start over frequencies. Given values are kept.
fn draw(d: &mut Draw<'_>, _: ProcessKind, given: &[Option<f64>], out: &mut Vec<f64>) {
    let st = d.ctx.sigma2_t;
    let humps = wv_humps(&d.ctx.wv);
    let hump = if !humps.is_empty() && d.unif(0.0, 1.0) < HUMP_SHARE {
        match given[1] {
            // the hump where the given line's WV peaks
            Some(omega) => {
                let peak = 2.0 * HUMP_X / (PI * omega);
                humps.iter().copied().min_by(|a, b| {
                    elementary::log(a.0 / peak)
                        .abs()
                        .total_cmp(&elementary::log(b.0 / peak).abs())
                })
            }
            // one of the two largest humps, at random
            None => {
                let k = humps.len().min(2);
                let i = (d.unif(0.0, k as f64) as usize).min(k - 1);
                Some(humps[i])
            }
        }
    } else {
        None
    };
    let (power, omega) = match hump {
        Some((tau, excess)) => {
            let peak = 2.0 * HUMP_X / (PI * tau);
            let omega = (peak
                * elementary::exp(d.unif(-(elementary::log(2f64)), elementary::log(2f64))))
            .min(OMEGA_MAX);
            let power = excess / HUMP_HEIGHT
                * elementary::exp(d.unif(-(elementary::log(3f64)), elementary::log(3f64)));
            (power, omega)
        }
        None => {
            let share = elementary::exp(d.unif(
                elementary::log(POWER_SHARE_MIN),
                elementary::log(POWER_SHARE_MAX),
            ));
            let lo = (2.0 / d.ctx.n).min(0.25 * OMEGA_MAX);
            (
                share * st,
                elementary::exp(d.unif(elementary::log(lo), elementary::log(OMEGA_MAX))),
            )
        }
    };
    out.push(given[0].unwrap_or((2.0 * power).sqrt()));
    out.push(given[1].unwrap_or(omega));
}

/// The physical read-off (docs/methods.md §14): `frequency` in Hz at the rate `freq_hz` and the
/// `amplitude` in the data unit `u`; none without both values.
fn physical(v: &[f64], freq_hz: f64, u: &str) -> Vec<Physical> {
    if v.len() < 2 {
        return Vec::new();
    }
    vec![
        ("frequency", v[1] * freq_hz, "Hz".to_string()),
        ("amplitude", v[0], u.to_string()),
    ]
}

/// A sinusoid with uniformly random phase (module doc): `x_t = amplitude sin(2 pi omega t +
/// phi)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Sin {
    /// Peak amplitude, data unit.
    pub(crate) amplitude: f64,
    /// Frequency, cycles per sample, in `(0, 1/2)`.
    pub(crate) omega: f64,
}

impl Sin {
    /// Builds the process.
    ///
    /// # Errors
    /// [`ParamError`] naming `amplitude` unless it is finite and `> 0`, or `omega` unless it
    /// lies in the open interval `(0, 1/2)` (cycles per sample).
    pub fn new(amplitude: f64, omega: f64) -> Result<Self, ParamError> {
        if !ParamDomain::Positive.contains(amplitude) {
            return Err(ParamError::new(
                "amplitude",
                amplitude,
                ParamDomain::Positive.expected(),
            ));
        }
        if !ParamDomain::HalfCycle.contains(omega) {
            return Err(ParamError::new(
                "omega",
                omega,
                ParamDomain::HalfCycle.expected(),
            ));
        }
        Ok(Self { amplitude, omega })
    }

    /// Peak amplitude, data unit.
    pub fn amplitude(&self) -> f64 {
        self.amplitude
    }

    /// Frequency in cycles per sample.
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// Frequency in Hz at a sampling rate.
    pub fn frequency_hz(&self, freq_hz: f64) -> f64 {
        self.omega * freq_hz
    }

    /// `G(n) = Var(x_1 + ... + x_n) = (amplitude^2 / 2) sin^2(pi omega n) / sin^2(pi omega)`:
    /// the autocovariance below summed over the `n x n` lags (a Dirichlet kernel).
    pub(crate) fn increment_variance(&self, n: f64) -> f64 {
        let p = 0.5 * self.amplitude * self.amplitude;
        // reduce omega n modulo 1 before the sine: n reaches 1e9
        let c = self.omega * n;
        let r = elementary::sin(PI * (c - c.floor())) / elementary::sin(PI * self.omega);
        p * r * r
    }

    /// Autocovariance `gamma_h = (amplitude^2 / 2) cos(2 pi omega h)` at lags `0..lags`.
    pub(crate) fn autocovariance(&self, lags: usize) -> Vec<f64> {
        let p = 0.5 * self.amplitude * self.amplitude;
        (0..lags)
            .map(|h| {
                let c = self.omega * h as f64;
                p * elementary::cos(2.0 * PI * (c - c.round()))
            })
            .collect()
    }

    fn jets<const H: bool>(&self, levels: usize) -> Vec<Jet<2, H>> {
        jet_levels([self.amplitude, self.omega], levels, |v, m| {
            sin_wv_jet(v[0], v[1], m)
        })
    }
}

/// `sin(x)` of a jet.
fn jet_sin<const N: usize, const H: bool>(x: Jet<N, H>) -> Jet<N, H> {
    let (s, c) = elementary::sincos(x.v);
    x.chain(s, c, -s)
}

/// Implied WV at half-width `m` (module doc):
/// `nu2 = (amplitude^2 / 2) sin^4(pi (omega m - k)) / (m^2 sin^2(pi omega))`, `k` the integer
/// nearest `omega m`.
fn sin_wv_jet<const N: usize, const H: bool>(
    amplitude: Jet<N, H>,
    omega: Jet<N, H>,
    m: f64,
) -> Jet<N, H> {
    let k = (omega.v * m).round();
    let num = jet_sin((omega.scale(m) - k).scale(PI)).powi(4);
    let den = jet_sin(omega.scale(PI)).powi(2).scale(m * m);
    amplitude.powi(2).scale(0.5) * num / den
}

/// [`sin_wv_jet`] in `f64` (the objective's hot path).
fn sin_wv(amplitude: f64, omega: f64, m: f64) -> f64 {
    let k = (omega * m).round();
    let num = elementary::sin(PI * (omega * m - k)).powi(4);
    let s = elementary::sin(PI * omega);
    0.5 * amplitude * amplitude * num / (m * m * s * s)
}

impl LatentProcess for Sin {
    fn name(&self) -> &'static str {
        SPEC.name
    }
    fn param_names(&self) -> Vec<&'static str> {
        SPEC.fixed_names()
    }
    fn params(&self) -> Vec<f64> {
        vec![self.amplitude, self.omega]
    }
    fn wv(&self, levels: usize) -> Vec<f64> {
        half_widths(levels)
            .map(|m| sin_wv(self.amplitude, self.omega, m))
            .collect()
    }
    fn add_wv(&self, out: &mut [f64]) {
        for (o, m) in out.iter_mut().zip(half_widths(usize::MAX)) {
            *o += sin_wv(self.amplitude, self.omega, m);
        }
    }
    fn jacobian(&self, levels: usize) -> Vec<Vec<f64>> {
        jets_jacobian(&self.jets::<false>(levels))
    }
    fn hessian(&self, levels: usize) -> Vec<Vec<Vec<f64>>> {
        jets_hessian(&self.jets::<true>(levels))
    }
    /// A line spectrum has no density: `None` (the §1.9 quadrature does not apply; the tests
    /// check the WV against the §4.1 sum of `Sin::autocovariance`).
    fn spectral_density(&self, f: f64) -> Option<f64> {
        let _ = f;
        None
    }
}

/// `x_t = amplitude sin(2 pi (omega t + p))` with the phase `p ~ U(0, 1)` drawn first from the
/// component's stream; the phase `omega t + p` is reduced modulo 1 before the sine so that
/// long series keep full precision. Stationary in both start modes.
#[derive(Debug, Clone)]
struct SinSampler {
    amplitude: f64,
    omega: f64,
    phase: f64,
    t: u64,
}

impl Step for SinSampler {
    #[inline]
    fn step(&mut self) -> f64 {
        let c = self.omega * self.t as f64 + self.phase;
        self.t += 1;
        self.amplitude * elementary::sin(2.0 * PI * (c - c.floor()))
    }
}

impl Simulate for Sin {
    fn sampler(&self, mut rng: SimRng, _: StartMode) -> Result<Box<dyn Sampler>, ParamError> {
        let phase = uniform(&mut rng);
        Ok(Box::new(SinSampler {
            amplitude: self.amplitude,
            omega: self.omega,
            phase,
            t: 0,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::process::autocovariance_wv;

    /// The hump of the module doc: `tan x = 2 x` at `x = 1.1656`, height `0.525`.
    #[test]
    fn sin_wv_hump_location() {
        let f = |x: f64| x.sin().powi(4) / (x * x);
        let x = HUMP_X;
        assert!((x.tan() - 2.0 * x).abs() < 1e-9);
        assert!(f(x) > f(x - 1e-3) && f(x) > f(x + 1e-3));
        assert!((f(x) - HUMP_HEIGHT).abs() < 1e-3, "{}", f(x));
    }

    /// The hump of a sinusoid over white noise is found at its level.
    #[test]
    fn sin_wv_hump_is_found() {
        let s = Sin::new(1.0, 0.0058).unwrap();
        let wv: Vec<f64> = s
            .wv(16)
            .iter()
            .zip(half_widths(16))
            .map(|(v, m)| v + 1e-3 / (2.0 * m))
            .collect();
        let (tau, excess) = wv_humps(&wv)[0];
        assert_eq!(tau, 128.0);
        assert!(excess > 0.0);
        assert!(wv_humps(&[1.0, 0.5, 0.25, 0.125, 0.0625, 0.03]).is_empty());
        // two lines over white noise: one entry per line (a wide hump spans two levels), the
        // larger excess first, so that two SIN() draws start at both
        let (a, b) = (
            Sin::new(1.0, 0.073).unwrap(),
            Sin::new(0.4, 0.0055).unwrap(),
        );
        let wv: Vec<f64> = (a.wv(18).iter().zip(b.wv(18)))
            .zip(half_widths(18))
            .map(|((x, y), m)| x + y + 1.0 / (2.0 * m))
            .collect();
        let taus: Vec<f64> = wv_humps(&wv).iter().take(2).map(|h| h.0).collect();
        assert_eq!(taus, [16.0, 128.0], "{:?}", wv_humps(&wv));
    }

    /// The f64 hot path and the jets agree; the §4.1 sum agrees at the first levels.
    #[test]
    fn sin_wv_paths_agree() {
        let s = Sin::new(1.7, 0.073).unwrap();
        let wv = s.wv(16);
        let mut out = vec![0.0; 16];
        s.add_wv(&mut out);
        for (j, jet) in s.jets::<true>(16).iter().enumerate() {
            assert!((jet.v - wv[j]).abs() <= 1e-14 * wv[j], "level {}", j + 1);
            assert_eq!(out[j], wv[j]);
        }
        let acf = autocovariance_wv(&s.autocovariance(1 << 8), 8);
        for j in 0..8 {
            assert!((acf[j] - wv[j]).abs() <= 1e-10 * wv[j], "level {}", j + 1);
        }
    }

    #[test]
    fn sin_logit_half_round_trips() {
        let t = ParamTransform::LogitHalf;
        for u in [-9.0, -1.0, 0.0, 0.3, 4.0] {
            let theta = t.to_theta(u);
            assert!(theta > 0.0 && theta < 0.5);
            let back = t.to_u(theta).unwrap();
            assert!((back - u).abs() < 1e-9 * (1.0 + u.abs()), "{u} {back}");
            let h = 1e-5;
            let fd = (t.to_theta(u + h) - t.to_theta(u - h)) / (2.0 * h);
            assert!((fd - t.dtheta_du(u)).abs() < 1e-8, "{u}");
        }
        assert_eq!(t.to_u(0.5), None);
        assert_eq!(t.to_u(0.0), None);
        assert!(t.to_u(t.inside(0.5)).is_some());
        assert!(t.to_u(t.inside(0.0)).is_some());
    }

    #[test]
    fn sin_new_accepts_and_rejects() {
        assert!(Sin::new(1.0, 0.25).is_ok());
        for (a, w) in [
            (0.0, 0.1),
            (-1.0, 0.1),
            (f64::NAN, 0.1),
            (1.0, 0.0),
            (1.0, 0.5),
            (1.0, -0.1),
            (1.0, f64::INFINITY),
        ] {
            assert!(Sin::new(a, w).is_err(), "{a} {w}");
        }
    }
}
