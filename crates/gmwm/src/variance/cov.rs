//! Asymptotic diagonal covariance of the wavelet variance ("diag", Percival 1995; docs/methods.md
//! §1.10).

use crate::error::{check_series, InputError};
use crate::wavelet::{Modwt, WaveletFilter};
use rustfft::{num_complex::Complex, FftPlanner};
use serde::{Deserialize, Serialize};

/// Which count divides `A_j` (docs/methods.md §1.10, §13.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub(crate) enum DiagDivisor {
    /// `V_jj = 2 A_j / n_j` with `n_j` the kept count of level j (correct; default).
    #[default]
    Level,
    /// `V_jj = 2 A_j / n_1` for every level, as the R package does (§13.4).
    Package,
}

/// `A = s_0^2 / 2 + sum_{k >= 1} s_k^2` for the biased, non-centred sample autocovariance
/// `s_k = (1/n) sum_t w_t w_{t+k}` of `w` (docs/methods.md §1.10).
///
/// Computed with one zero-padded FFT and Parseval: with padding `L >= 2n - 1` the circular
/// autocovariance equals the linear one, so `sum_{|k| < n} s_k^2 = (1/L) sum_f |X_f|^4 / n^2`
/// and `A` is half of that. O(n log n); short inputs use the direct O(n^2) sum.
pub(crate) fn half_sum_squared_autocovariance(w: &[f64]) -> f64 {
    let n = w.len();
    if n == 0 {
        return f64::NAN;
    }
    let nf = n as f64;
    if n <= 64 {
        let s = |k: usize| (0..n - k).map(|t| w[t] * w[t + k]).sum::<f64>() / nf;
        let s0 = s(0);
        return 0.5 * s0 * s0 + (1..n).map(|k| s(k).powi(2)).sum::<f64>();
    }
    let len = (2 * n - 1).next_power_of_two();
    let mut buf: Vec<Complex<f64>> = w.iter().map(|&v| Complex::new(v, 0.0)).collect();
    buf.resize(len, Complex::new(0.0, 0.0));
    FftPlanner::new().plan_fft_forward(len).process(&mut buf);
    let total: f64 = buf.iter().map(|c| c.norm_sqr().powi(2)).sum();
    0.5 * total / (len as f64 * nf * nf)
}

/// Diagonal of the asymptotic covariance matrix V of the MODWT wavelet variance at levels
/// `1..=levels`, docs/methods.md §1.10: `V_jj = 2 A_j / n_j` (or `/ n_1` with
/// [`DiagDivisor::Package`]). Multiply by `1 / eff` for the robust estimator.
///
/// # Errors
/// Bad series or levels, as [`Modwt::transform`].
pub(crate) fn wv_diag_covariance(
    x: &[f64],
    filter: WaveletFilter,
    levels: usize,
    divisor: DiagDivisor,
) -> Result<Vec<f64>, InputError> {
    check_series(x)?;
    let coefs = Modwt::new(filter, levels)?.transform(x)?;
    let n1 = coefs.kept(1).len() as f64;
    Ok((1..=levels)
        .map(|j| {
            let w = coefs.kept(j);
            let a = half_sum_squared_autocovariance(w);
            let n = match divisor {
                DiagDivisor::Level => w.len() as f64,
                DiagDivisor::Package => n1,
            };
            2.0 * a / n
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The test values of docs/methods.md carry 7 significant digits.
    const TOL: f64 = 5e-7;

    #[test]
    fn wv_diag_covariance_matches_methods_1_10() {
        let x = [1.0, 3.0, 2.0, 5.0, 4.0, 6.0, 8.0, 7.0];
        let package = wv_diag_covariance(&x, WaveletFilter::Haar, 2, DiagDivisor::Package).unwrap();
        assert!((package[0] / 0.1720117 - 1.0).abs() < TOL, "{package:?}");
        assert!((package[1] / 0.4915179 - 1.0).abs() < TOL, "{package:?}");
        let correct = wv_diag_covariance(&x, WaveletFilter::Haar, 2, DiagDivisor::Level).unwrap();
        assert_eq!(correct[0], package[0]);
        assert!((correct[1] / 0.688125 - 1.0).abs() < 1e-12, "{correct:?}");
    }

    #[test]
    fn fft_route_equals_direct_sum() {
        let w: Vec<f64> = (0..300)
            .map(|i| ((i * 37 % 101) as f64 - 50.0) / 7.0)
            .collect();
        let n = w.len();
        let s = |k: usize| (0..n - k).map(|t| w[t] * w[t + k]).sum::<f64>() / n as f64;
        let direct = 0.5 * s(0).powi(2) + (1..n).map(|k| s(k).powi(2)).sum::<f64>();
        let fft = half_sum_squared_autocovariance(&w);
        assert!((fft / direct - 1.0).abs() < 1e-12, "{fft} vs {direct}");
    }
}
