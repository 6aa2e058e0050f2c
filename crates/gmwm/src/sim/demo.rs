//! The built-in demo sensor behind `gmwm demo`: a known truth to simulate, analyse and recover
//! (docs/methods.md §5.10, §10).

use crate::error::InputError;
use crate::model::Model;
use serde::Serialize;

/// The NavChip Y-axis gyroscope of paper Table I (docs/methods.md §5.10), classical column, at 250
/// Hz: `3*GM() + WN() + QN() + RW()` with beta = (0.250, 6.28e-3, 8.48) 1/s,
/// sigma2_gm = (7.08e-9, 1.28e-8, 6.48e-9), WN 6.94e-7, QN 2.29e-6, RW 3.90e-14.
pub(crate) const DEMO_MODEL: &str =
    "GM(beta=0.25, sigma2_gm=7.08e-9)+GM(beta=6.28e-3, sigma2_gm=1.28e-8)\
+GM(beta=8.48, sigma2_gm=6.48e-9)+WN(sigma2=6.94e-7)+QN(q2=2.29e-6)+RW(gamma2=3.9e-14)";

/// Sampling rate of the demo sensor (NavChip, paper Sec. III).
pub(crate) const DEMO_FREQ_HZ: f64 = 250.0;

/// A simulated sensor with known truth.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DemoSensor {
    /// The true error model (fully specified).
    pub model: Model,
    /// Sampling rate in Hz.
    pub freq_hz: f64,
}

impl Default for DemoSensor {
    /// The NavChip truth of docs/methods.md §5.10 (`DEMO_MODEL` at `DEMO_FREQ_HZ`).
    fn default() -> Self {
        Self {
            model: DEMO_MODEL
                .parse()
                .expect("the built-in demo model is valid text"),
            freq_hz: DEMO_FREQ_HZ,
        }
    }
}

impl DemoSensor {
    /// Simulates `n` samples with `seed` (docs/methods.md §10.2, stationary starts).
    ///
    /// # Errors
    /// `n == 0`.
    pub fn simulate(&self, n: usize, seed: u64) -> Result<Vec<f64>, InputError> {
        super::simulate_model(&self.model, n, self.freq_hz, seed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn demo_sensor_reproduces_methods_5_10() {
        // docs/methods.md §5.10: implied WV at tau = 2, 2^10, 2^21 (package and hand agree, 7
        // digits)
        let s = DemoSensor::default();
        let wv = s.model.implied_wv(21, s.freq_hz).unwrap();
        for (j, want) in [(1, 3.782112e-6), (10, 1.927074e-9), (21, 7.281275e-9)] {
            let got = wv.wv[j - 1];
            assert!(
                (got / want - 1.0).abs() < 5e-7,
                "tau 2^{j}: {got:e} vs {want:e}"
            );
        }
        let x = s.simulate(1000, 7).unwrap();
        assert_eq!(x, s.simulate(1000, 7).unwrap());
        assert!(s.simulate(0, 7).is_err());
    }
}
