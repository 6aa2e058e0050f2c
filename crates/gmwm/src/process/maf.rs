//! The sensor's own filter: white noise through an `L`-sample moving average, `MAF(L)`
//! (parameter `sigma2`).
//!
//! # The process
//! `x_t = (1/L) sum_{k<L} w_{t-k}`, `w ~ N(0, sigma2)`: the boxcar an IMU's decimation or
//! averaging filter applies before the samples leave it, at the output rate. Its spectrum is
//! `sigma2 |sin(pi f L) / (L sin(pi f))|^2` (cycles per sample): `sigma2` at low frequency, with
//! zeros at multiples of `1/L`. Parametrised so that `sigma2` is the *long-run* variance
//! (`gamma_0 + 2 sum_k gamma_k`): at every scale longer than the filter the process is white
//! noise of variance `sigma2`, and its noise density `N = sqrt(sigma2 / f)` is the one a
//! navigation filter integrating over longer than `L / f` sees. It therefore takes the white
//! noise role: the canonical model reads it as `WN()` with that density, and N, its interval
//! and the exports come from it. The first scales, which the filter shapes (the Haar WV there is
//! below white noise's), are what tells it from `WN()`.
//!
//! # Implied WV (closed form, derived here)
//! `gamma_k = sigma2 (L - k) / L^2` for `k < L`, 0 beyond. In the §4.1 sum for a Haar
//! coefficient over `2m` samples, every `gamma` beyond lag `L - 1` vanishes, so for `m >= L`
//!
//! `nu2(2m) = S / (2m) - 3 M / (2 m^2)`, `S = sigma2`, `M = sum_{k=1}^{L-1} k gamma_k
//! = sigma2 (L^2 - 1) / (6 L)`,
//!
//! i.e. white noise's `sigma2 / tau` less a `1/tau^2` term: `nu2(2m) = sigma2 / (2m) -
//! sigma2 (L^2 - 1) / (4 L m^2)`. For `m < L` (at most the first `log2 L + 1` levels) the §4.1
//! sum is taken directly over its `m` terms. The WV is linear in `sigma2`: the jacobian is
//! the unit WV, the hessian zero. Checked against the §4.1 route on the full autocovariance
//! (`maf_wv_matches_autocovariance_route`) and the simulated mean WV
//! (`maf_simulation_matches_implied_wv`, in `crate::tests`).
//!
//! # Simulation
//! A running sum of the last `L` innovations, divided by `L`; the stationary start draws the
//! `L - 1` innovations before the first sample, [`StartMode::Zero`] takes them as 0. Cost: one
//! normal draw and two adds per sample.

use super::{
    half_widths, LatentProcess, Occurs, Orders, ParamTransform, Params, ProcessKind, Role,
    Simulate, Spec, BASE,
};
use crate::error::ParamError;
use crate::math::elementary;
use crate::process::sampler::{normal, Sampler, SimRng, Step};
use crate::process::ParamDomain;
use crate::process::StartMode;
use serde::Serialize;
use std::collections::VecDeque;

/// `MAF(L)`, a filter length from 2 to 100 samples: may appear once in a model.
pub(crate) const SPEC: Spec = Spec {
    name: "MAF",
    syntax: "MAF(L)",
    params: Params::Fixed(&[("sigma2", ParamDomain::Variance)], (0, 0)),
    orders: Some(Orders {
        ar: false,
        ma: true,
        min: 2,
        expected: "a filter length from 2 to 100 samples",
        all_zero: "a filter length from 2 to 100 samples",
        example: "MAF(4)",
        make: |_, l| ProcessKind::Maf(l),
    }),
    occurs: Occurs::Once,
    build: |kind, v, _| Ok(Maf::new(kind.orders().1, v[0])?.into()),
    role: Role::WhiteNoise,
    transforms: |_, _| vec![ParamTransform::Log],
    // as white noise's: the starting value and the read-off of a long-run variance
    draw: super::wn::draw,
    unit_shapes: |_, _| vec![(vec![1.0], |t| t)],
    physical: super::wn::white_noise_density,
    ..BASE
};

/// White noise through an `L`-sample moving average; `sigma2` is its long-run variance per
/// sample (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Maf {
    /// Filter length in samples, 2 to 100.
    pub(crate) length: usize,
    /// Long-run variance per sample (the innovations' variance).
    pub(crate) sigma2: f64,
}

impl Maf {
    /// Builds the process.
    ///
    /// # Errors
    /// [`ParamError`] naming `sigma2` unless it is finite and > 0, or `L` unless it is 2 to
    /// 100.
    pub fn new(length: usize, sigma2: f64) -> Result<Self, ParamError> {
        if !(2..=super::MAX_ORDER).contains(&length) {
            return Err(ParamError::new(
                "L",
                length as f64,
                "a filter length from 2 to 100 samples",
            ));
        }
        super::check_positive("sigma2", sigma2)?;
        Ok(Self { length, sigma2 })
    }

    /// Filter length in samples.
    pub fn length(&self) -> usize {
        self.length
    }

    /// Long-run variance per sample: the white noise the filter's output is at long scales.
    pub fn sigma2(&self) -> f64 {
        self.sigma2
    }

    /// Autocovariance at lag `k` per unit `sigma2`: `(L - k) / L^2` below `L`, else 0.
    pub(crate) fn unit_autocovariance(&self, k: usize) -> f64 {
        let l = self.length as f64;
        if k < self.length {
            (l - k as f64) / (l * l)
        } else {
            0.0
        }
    }

    /// `G(n) = Var(x_1 + ... + x_n) = n gamma_0 + 2 sum_{h<n} (n - h) gamma_h`: beyond the
    /// filter, `n sigma2 - sigma2 (L^2 - 1) / (3 L)` (white noise's, less the filter's edges).
    pub(crate) fn increment_variance(&self, n: usize) -> f64 {
        let lags = n.min(self.length);
        let mut g = n as f64 * self.unit_autocovariance(0);
        for h in 1..lags {
            g += 2.0 * (n - h) as f64 * self.unit_autocovariance(h);
        }
        self.sigma2 * g
    }

    /// The Haar WV at `tau = 2m` per unit `sigma2` (module doc).
    fn unit_wv(&self, m: f64) -> f64 {
        let l = self.length as f64;
        if m >= l {
            return 1.0 / (2.0 * m) - (l * l - 1.0) / (4.0 * l * m * m);
        }
        // the §4.1 sum over its m terms (m < L <= 100)
        let mi = m as usize;
        let g = |k: usize| self.unit_autocovariance(k);
        let mut s = m * (g(0) - g(mi));
        for i in 1..mi {
            s += i as f64 * (2.0 * g(mi - i) - g(i) - g(2 * mi - i));
        }
        s / (2.0 * m * m)
    }
}

impl LatentProcess for Maf {
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
            .map(|m| self.sigma2 * self.unit_wv(m))
            .collect()
    }
    fn add_wv(&self, out: &mut [f64]) {
        for (o, m) in out.iter_mut().zip(half_widths(usize::MAX)) {
            *o += self.sigma2 * self.unit_wv(m);
        }
    }
    fn jacobian(&self, levels: usize) -> Vec<Vec<f64>> {
        half_widths(levels).map(|m| vec![self.unit_wv(m)]).collect()
    }
    fn hessian(&self, levels: usize) -> Vec<Vec<Vec<f64>>> {
        half_widths(levels).map(|_| vec![vec![0.0]]).collect()
    }
    fn spectral_density(&self, f: f64) -> Option<f64> {
        let l = self.length as f64;
        let s = elementary::sin(std::f64::consts::PI * f);
        if s.abs() < 1e-300 {
            return Some(self.sigma2);
        }
        let r = elementary::sin(std::f64::consts::PI * f * l) / (l * s);
        Some(self.sigma2 * r * r)
    }
}

/// The running sum of the last `L` innovations (module doc).
#[derive(Debug, Clone)]
struct MafSampler {
    rng: SimRng,
    sd: f64,
    inv_len: f64,
    window: VecDeque<f64>,
    sum: f64,
}

impl Step for MafSampler {
    #[inline]
    fn step(&mut self) -> f64 {
        let w = self.sd * normal(&mut self.rng);
        self.sum += w;
        self.window.push_back(w);
        if let Some(old) = self.window.pop_front() {
            self.sum -= old;
        }
        self.sum * self.inv_len
    }
}

impl Simulate for Maf {
    fn sampler(&self, mut rng: SimRng, start: StartMode) -> Result<Box<dyn Sampler>, ParamError> {
        let sd = self.sigma2.sqrt();
        let window: VecDeque<f64> = (0..self.length - 1)
            .map(|_| match start {
                StartMode::Zero => 0.0,
                _ => sd * normal(&mut rng),
            })
            .collect();
        // the window holds L - 1 past innovations; each step adds one and drops the oldest,
        // so the sum runs over L
        let mut window = window;
        window.push_front(0.0);
        let sum = window.iter().sum();
        Ok(Box::new(MafSampler {
            rng,
            sd,
            inv_len: 1.0 / self.length as f64,
            window,
            sum,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::process::autocovariance_wv;

    /// The closed form beyond the filter and the direct sum below it agree with the §4.1 route
    /// on the full autocovariance, for several lengths.
    #[test]
    fn maf_wv_matches_autocovariance_route() {
        for length in [2, 3, 4, 7, 16, 100] {
            let p = Maf::new(length, 2.5).unwrap();
            let levels = 12;
            let gamma: Vec<f64> = (0..1usize << levels)
                .map(|k| 2.5 * p.unit_autocovariance(k))
                .collect();
            let oracle = autocovariance_wv(&gamma, levels);
            let wv = p.wv(levels);
            for (j, (a, b)) in wv.iter().zip(&oracle).enumerate() {
                assert!(
                    (a - b).abs() <= 1e-12 * b.abs(),
                    "L={length} level {}: {a} vs {b}",
                    j + 1
                );
            }
            // white noise of variance sigma2 at scales much longer than the filter
            let m = 2f64.powi(levels as i32 - 1);
            assert!((wv[levels - 1] * 2.0 * m / 2.5 - 1.0).abs() < 1.5 * length as f64 / m);
        }
    }

    /// The filter length is checked.
    #[test]
    fn maf_new_checks_its_length_and_variance() {
        assert!(Maf::new(1, 1.0).is_err());
        assert!(Maf::new(101, 1.0).is_err());
        assert!(Maf::new(4, 0.0).is_err());
        assert!(Maf::new(4, f64::NAN).is_err());
        assert_eq!(Maf::new(4, 1.0).unwrap().length(), 4);
    }
}
