//! The built-in demo sensor behind `gmwm demo` (METHODS §5.10, §10.1–§10.2).

use crate::error::ParamError;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

/// The built-in demo sensor: white noise + random walk + one first-order autoregressive
/// process, per-sample parameters, with the values of the NavChip gyroscope of paper Table I
/// (METHODS §5.10; its slowest GM component only).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DemoSensor {
    /// Sampling rate in Hz.
    pub freq_hz: f64,
    /// White-noise variance `sigma2`.
    pub wn_sigma2: f64,
    /// Random-walk increment variance `gamma2`.
    pub rw_gamma2: f64,
    /// AR1 coefficient `phi`.
    pub ar1_phi: f64,
    /// AR1 innovation variance `sigma2`.
    pub ar1_sigma2: f64,
}

impl Default for DemoSensor {
    /// NavChip-like truth at 250 Hz (METHODS §5.10): WN 6.94e-7, RW 3.90e-14,
    /// AR1 (0.9990005, 1.414585e-11).
    fn default() -> Self {
        Self {
            freq_hz: 250.0,
            wn_sigma2: 6.94e-7,
            rw_gamma2: 3.90e-14,
            ar1_phi: 0.9990005,
            ar1_sigma2: 1.414585e-11,
        }
    }
}

impl DemoSensor {
    /// Canonical model text of the truth, in the model language of METHODS §0.2.
    pub fn model_text(&self) -> String {
        format!(
            "AR1(phi={}, sigma2={})+WN(sigma2={})+RW(gamma2={})",
            number(self.ar1_phi),
            number(self.ar1_sigma2),
            number(self.wn_sigma2),
            number(self.rw_gamma2)
        )
    }

    /// Simulates `n` samples with the given seed (METHODS §10.1–§10.2): components drawn in
    /// model order from one ChaCha8 stream (same seed, same bits on every platform), the AR1
    /// started from its stationary law `N(0, sigma2 / (1 - phi^2))` (the port's default, §10.1).
    ///
    /// # Errors
    /// [`ParamError`] for `n == 0` or a parameter outside its domain (variances >= 0, |phi| < 1).
    pub fn simulate(&self, n: usize, seed: u64) -> Result<Vec<f64>, ParamError> {
        if n == 0 {
            return Err(ParamError::new("n", n, "must be at least 1"));
        }
        for (name, v) in [
            ("wn_sigma2", self.wn_sigma2),
            ("rw_gamma2", self.rw_gamma2),
            ("ar1_sigma2", self.ar1_sigma2),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(ParamError::new(name, v, "must be a finite variance >= 0"));
            }
        }
        if !(self.ar1_phi.is_finite() && self.ar1_phi.abs() < 1.0) {
            return Err(ParamError::new(
                "ar1_phi",
                self.ar1_phi,
                "must satisfy |phi| < 1",
            ));
        }
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut z = || -> f64 { StandardNormal.sample(&mut rng) };
        let sd_ar = self.ar1_sigma2.sqrt();
        let mut ar = z() * (self.ar1_sigma2 / (1.0 - self.ar1_phi * self.ar1_phi)).sqrt();
        let mut x = Vec::with_capacity(n);
        for _ in 0..n {
            x.push(ar);
            ar = self.ar1_phi * ar + sd_ar * z();
        }
        let sd_wn = self.wn_sigma2.sqrt();
        for v in x.iter_mut() {
            *v += sd_wn * z();
        }
        let sd_rw = self.rw_gamma2.sqrt();
        let mut rw = 0.0;
        for v in x.iter_mut() {
            rw += sd_rw * z();
            *v += rw;
        }
        Ok(x)
    }
}

/// Shortest round-tripping text of a parameter, in scientific notation when it is small or
/// large (`1.414585e-11` rather than `0.00000000001414585`).
fn number(v: f64) -> String {
    if v != 0.0 && !(1e-4..1e6).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn demo_sensor_is_reproducible_and_validated() {
        let s = DemoSensor::default();
        assert_eq!(s.simulate(100, 7).unwrap(), s.simulate(100, 7).unwrap());
        assert_ne!(s.simulate(100, 7).unwrap(), s.simulate(100, 8).unwrap());
        assert!(s.simulate(0, 7).is_err());
        assert_eq!(
            s.model_text(),
            "AR1(phi=0.9990005, sigma2=1.414585e-11)+WN(sigma2=6.94e-7)+RW(gamma2=3.9e-14)"
        );
        let bad = DemoSensor { ar1_phi: 1.0, ..s };
        assert!(bad.simulate(10, 1).is_err());
    }
}
