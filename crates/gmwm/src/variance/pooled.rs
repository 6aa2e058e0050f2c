//! The pooled wavelet variance of K recordings of one sensor (docs/methods.md §5.12): what
//! `gmwm calibrate --pool` calibrates.
//!
//! # Estimator
//! Recording `k` (length `N_k`, `J_k` levels) gives `nu2_hat_kj` with the equivalent degrees
//! of freedom `eta_kj` of its chi-square interval (eta3 of docs/methods.md §1.7, which depends on
//! `N_k` and `j` only). Under one model, `eta_kj nu2_hat_kj / nu2_j` is approximately
//! chi-square with `eta_kj` degrees of freedom, so `Var(nu2_hat_kj) ~ 2 nu2_j^2 / eta_kj`: at a
//! level the recordings share one `nu2_j` and their inverse variances are proportional to
//! `eta_kj`. The pooled WV is their inverse-variance mean over the recordings that reach
//! level j,
//!
//! ```text
//! eta_bar_j = sum_k eta_kj,   w_kj = eta_kj / eta_bar_j,   nu2_bar_j = sum_k w_kj nu2_hat_kj
//! ```
//!
//! unbiased (a mean of unbiased estimates with weights that do not depend on the data) and,
//! the recordings being independent, with the sum of their degrees of freedom: its interval is
//! the chi-square interval with `eta_bar_j` (the robust interval of §2.5 widens it by the same
//! `1 / eff` rule). `J_bar = max_k J_k`; a level only the longest recordings reach is theirs.
//!
//! # Its covariance
//! The recordings are independent, so with `D_k` the `J_bar x J_k` matrix holding `w_kj` at
//! `(j, j)`, `Cov(nu2_bar) = sum_k D_k V_k D_k'`, `V_k` the covariance of recording k's WV
//! (exact at `N_k`, docs/methods.md §1.10, or simulated at `N_k`):
//! `sim::covariance::pooled_wv_covariance`.
//!
//! # Relation to the pooled GMWM (§5.11)
//! With diagonal weights `omega_kj`, `sum_k omega_kj (nu2_hat_kj - nu2_j)^2 = Omega_j
//! (nu2_bar_j - nu2_j)^2 + c_j` for `Omega_j = sum_k omega_kj`, the `omega`-weighted mean
//! `nu2_bar_j` and a `c_j` free of the model: the pooled objective is the single-recording
//! objective of the pooled WV. With `omega_kj` proportional to `eta_kj` (the precision above)
//! the minimisers coincide; a single GMWM on `nu2_bar` is MS-GMWM.

use crate::error::ParamError;
use crate::variance::ci::interval_unchecked;
use crate::variance::robust::robust_ci;
use crate::variance::wv::WaveletVariance;

/// The wavelet variance of several recordings of one sensor pooled level by level (module doc).
///
/// Worked example: the test `tests::examples::example_pooled_pooledwv`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PooledWv {
    /// The pooled WV: `n` the total length, `eta` and `n_coefficients` summed per level.
    pub(crate) wv: WaveletVariance,
    /// The recordings' own WVs, input order.
    pub(crate) parts: Vec<WaveletVariance>,
}

impl PooledWv {
    /// Pools `parts`, WVs of one sensor's recordings (module doc).
    ///
    /// # Errors
    /// [`ParamError`] for no WV, WVs of rates differing by more than
    /// [`crate::imu::read::RATE_TOLERANCE`] or of different estimators (transform, filter,
    /// interval level, robustness), naming the recording (1-based).
    pub(crate) fn new(parts: Vec<WaveletVariance>) -> Result<Self, ParamError> {
        let Some(first) = parts.first() else {
            return Err(ParamError::new(
                "wavelet variances",
                "none",
                "at least one to pool",
            ));
        };
        for (k, p) in parts.iter().enumerate().skip(1) {
            if (p.freq_hz - first.freq_hz).abs() > crate::imu::read::RATE_TOLERANCE * first.freq_hz
            {
                return Err(ParamError::new(
                    "rate",
                    format!("{} Hz of recording {}", p.freq_hz, k + 1),
                    format!(
                        "the first recording's rate, {} Hz, within 1%: the model's parameters are per sample",
                        first.freq_hz
                    ),
                ));
            }
            if p.transform != first.transform
                || p.filter != first.filter
                || p.alpha != first.alpha
                || p.robust != first.robust
            {
                return Err(ParamError::new(
                    "wavelet variance",
                    format!("of recording {}, of other settings", k + 1),
                    "the first recording's estimator (transform, filter, alpha, robustness)",
                ));
            }
        }
        let levels = parts.iter().map(WaveletVariance::levels).max().unwrap_or(0);
        let mut value = vec![0.0; levels];
        let mut eta = vec![0.0; levels];
        let mut counts = vec![0usize; levels];
        for p in &parts {
            for j in 0..p.levels() {
                eta[j] += p.eta[j];
                counts[j] += p.n_coefficients[j];
            }
        }
        for p in &parts {
            for j in 0..p.levels() {
                value[j] += p.eta[j] / eta[j] * p.wv[j];
            }
        }
        let n = parts.iter().map(|p| p.n).sum();
        let longest = parts
            .iter()
            .max_by_key(|p| p.levels())
            .expect("at least one part");
        let mut wv = longest.clone();
        wv.n = n;
        wv.ci_low = Vec::with_capacity(levels);
        wv.ci_high = Vec::with_capacity(levels);
        let mut lowest: Option<f64> = None;
        for j in 0..levels {
            let (lo, hi) = interval_unchecked(value[j], eta[j], first.alpha);
            let (lo, hi) = match first.robust {
                // §2.5 scales the classical interval's relative half-widths by 1 / sqrt(eff)
                Some(r) => {
                    let (lo, hi) = robust_ci(value[j], value[j], lo, hi, r.eff(), lowest);
                    if lo.is_finite() {
                        lowest = Some(lowest.map_or(lo, |l| l.min(lo)));
                    }
                    (lo, hi)
                }
                None => (lo, hi),
            };
            wv.ci_low.push(lo);
            wv.ci_high.push(hi);
        }
        wv.wv = value;
        wv.eta = eta;
        wv.n_coefficients = counts;
        wv.warnings = parts.iter().flat_map(|p| p.warnings.clone()).collect();
        wv.warnings.dedup();
        Ok(Self { wv, parts })
    }

    /// The pooled WV.
    pub(crate) fn wv(&self) -> &WaveletVariance {
        &self.wv
    }

    /// The recordings' WVs, input order.
    pub(crate) fn parts(&self) -> &[WaveletVariance] {
        &self.parts
    }

    /// Recording `k`'s weight `w_kj` at each of its levels (module doc).
    ///
    /// # Panics
    /// For `k` beyond the recordings.
    pub(crate) fn weights(&self, k: usize) -> Vec<f64> {
        let p = &self.parts[k];
        (0..p.levels()).map(|j| p.eta[j] / self.wv.eta[j]).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Model;
    use crate::sim::simulate_model;
    use crate::variance::robust::RobustOptions;
    use crate::variance::wv::{wavelet_variance, WvOptions};

    fn wvs(model: &str, lengths: &[usize], opts: &WvOptions) -> Vec<WaveletVariance> {
        let m = Model::parse(model).unwrap();
        lengths
            .iter()
            .enumerate()
            .map(|(k, &n)| {
                let x = simulate_model(&m, n, 100.0, 11 + k as u64).unwrap();
                wavelet_variance(&x, 100.0, opts).unwrap()
            })
            .collect()
    }

    #[test]
    fn one_recording_pools_to_itself() {
        let parts = wvs(
            "WN(sigma2=1)+RW(gamma2=1e-4)",
            &[5000],
            &WvOptions::default(),
        );
        let pooled = PooledWv::new(parts.clone()).unwrap();
        let (a, b) = (pooled.wv(), &parts[0]);
        assert_eq!(a.n, b.n);
        assert_eq!(a.eta, b.eta);
        for j in 0..b.levels() {
            // the same chi-square interval of the same value: equal up to the rounding of
            // eta / eta * nu (one ulp)
            for (x, y) in [
                (a.wv[j], b.wv[j]),
                (a.ci_low[j], b.ci_low[j]),
                (a.ci_high[j], b.ci_high[j]),
            ] {
                assert!(
                    (x - y).abs() <= 4.0 * f64::EPSILON * y.abs(),
                    "level {j}: {x} vs {y}"
                );
            }
        }
        assert_eq!(pooled.weights(0), vec![1.0; b.levels()]);
    }

    #[test]
    fn equal_recordings_keep_their_value_and_narrow_their_interval() {
        let parts = wvs("WN(sigma2=1)", &[4096], &WvOptions::default());
        let twice = PooledWv::new(vec![parts[0].clone(), parts[0].clone()]).unwrap();
        let one = &parts[0];
        for j in 0..one.levels() {
            assert!((twice.wv.wv[j] - one.wv[j]).abs() <= 1e-15 * one.wv[j]);
            assert_eq!(twice.wv.eta[j], 2.0 * one.eta[j]);
            assert!(twice.wv.ci_high[j] - twice.wv.ci_low[j] < one.ci_high[j] - one.ci_low[j]);
            // the interval is the chi-square one with the summed degrees of freedom
            let (lo, hi) = interval_unchecked(one.wv[j], 2.0 * one.eta[j], one.alpha);
            assert!((twice.wv.ci_low[j] - lo).abs() <= 1e-12 * lo);
            assert!((twice.wv.ci_high[j] - hi).abs() <= 1e-12 * hi);
        }
        for k in 0..2 {
            assert!(twice.weights(k).iter().all(|&w| (w - 0.5).abs() < 1e-15));
        }
    }

    #[test]
    fn weights_sum_to_one_and_the_longest_recording_alone_reaches_the_coarse_levels() {
        let parts = wvs(
            "WN(sigma2=1)+RW(gamma2=1e-4)",
            &[1000, 3000, 20000],
            &WvOptions::default(),
        );
        let pooled = PooledWv::new(parts.clone()).unwrap();
        assert_eq!(pooled.wv.levels(), parts[2].levels());
        for j in 0..pooled.wv.levels() {
            let sum: f64 = (0..3)
                .filter_map(|k| pooled.weights(k).get(j).copied())
                .sum();
            assert!((sum - 1.0).abs() < 1e-14, "level {j}: weights sum to {sum}");
            // the pooled value lies between the recordings' values at that level
            let at: Vec<f64> = parts.iter().filter_map(|p| p.wv.get(j).copied()).collect();
            let (lo, hi) = at
                .iter()
                .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
            assert!(pooled.wv.wv[j] >= lo * (1.0 - 1e-15) && pooled.wv.wv[j] <= hi * (1.0 + 1e-15));
        }
        let last = pooled.wv.levels() - 1;
        assert_eq!(pooled.wv.wv[last], parts[2].wv[last]);
        assert_eq!(pooled.wv.n, 24000);
    }

    #[test]
    fn robust_parts_pool_with_the_robust_interval() {
        let opts = WvOptions {
            robust: Some(RobustOptions::default()),
            ..WvOptions::default()
        };
        let parts = wvs("WN(sigma2=1)", &[4096], &opts);
        let pooled = PooledWv::new(parts.clone()).unwrap();
        for j in 0..parts[0].levels() {
            assert!(
                (pooled.wv.ci_high[j] - parts[0].ci_high[j]).abs() <= 1e-12 * parts[0].ci_high[j]
            );
        }
    }

    #[test]
    fn mismatched_recordings_are_refused_by_number() {
        let a = wvs("WN(sigma2=1)", &[2048], &WvOptions::default()).remove(0);
        let mut b = a.clone();
        b.freq_hz = 200.0;
        let e = PooledWv::new(vec![a.clone(), b]).unwrap_err().to_string();
        assert!(e.contains("recording 2") && e.contains("200 Hz"), "{e}");
        let mut c = a.clone();
        c.alpha = 0.1;
        let e = PooledWv::new(vec![a, c]).unwrap_err().to_string();
        assert!(e.contains("recording 2") && e.contains("estimator"), "{e}");
        assert!(PooledWv::new(Vec::new()).is_err());
    }
}
