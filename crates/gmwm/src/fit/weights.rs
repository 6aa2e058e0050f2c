//! The weighting matrix Omega of the GMWM objective (docs/methods.md §5.2), diagonal in every
//! supported option.
//!
//! Levels whose weight cannot be formed (a zero or non-finite CI width or variance, e.g. a robust
//! level without a scale or the coefficient-less last level of a power-of-two series, §5.9) are
//! **rejected** with [`FitError::BadWeight`] naming the level, never dropped silently: the caller
//! decides to fit fewer levels.

use super::FitError;
use crate::variance::cov::{wv_diag_covariance, DiagDivisor};
use crate::variance::wv::WaveletVariance;
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// Which V (and Omega = V^{-1}) to use (docs/methods.md §5.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Weighting {
    /// `V = diag((hi_j - lo_j)^2)` from the WV confidence interval (robust CI if robust); the
    /// package default (`compute.v = "fast"`, used by `gmwm.imu`).
    #[default]
    Fast,
    /// Percival's asymptotic diagonal (docs/methods.md §1.10) with the per-level divisor, `/ eff`
    /// if robust; needs the series.
    Diag,
    /// docs/methods.md §5.2 `bootstrap`: fit with the fast weights, then (K rounds, default 1) take
    /// `V_jj` from a parametric bootstrap of the WV at the current estimate (H replicates of the
    /// observed length, default 100, §7.4) and refit stage 2 from the estimate with
    /// `Omega = diag(V)^{-1}` (the package ignores the off-diagonals; so do we).
    Bootstrap,
}

crate::names::named_values!(Weighting, "weights", {
    Fast => "fast",
    Diag => "diag",
    Bootstrap => "bootstrap",
}, derive(FromStr, Display));

/// Diagonal weights `omega_j = 1 / V_jj` (docs/methods.md §5.2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Weights {
    /// `V_jj`, the (proxy) variance of `nu2_hat_j` (the package's `orgV` diagonal).
    pub v: Vec<f64>,
    /// `omega_j = 1 / V_jj`.
    pub omega: Vec<f64>,
}

impl Weights {
    /// Weights from the diagonal of V; `what` names it in errors.
    pub(crate) fn from_v(v: Vec<f64>, what: &'static str) -> Result<Self, FitError> {
        for (j, &x) in v.iter().enumerate() {
            let omega = 1.0 / x;
            if !(x.is_finite() && x > 0.0 && omega.is_finite()) {
                return Err(FitError::BadWeight {
                    level: j + 1,
                    what,
                    value: x,
                });
            }
        }
        let omega = v.iter().map(|x| 1.0 / x).collect();
        Ok(Self { v, omega })
    }

    /// docs/methods.md §5.2 "fast": `V_jj = (ci_high_j - ci_low_j)^2`, Omega = V^{-1}.
    ///
    /// # Errors
    /// [`FitError::BadWeight`] for a level whose CI width is zero or not finite.
    pub fn fast(wv: &WaveletVariance) -> Result<Self, FitError> {
        let mut v = Vec::with_capacity(wv.levels());
        for (j, (&lo, &hi)) in wv.ci_low.iter().zip(&wv.ci_high).enumerate() {
            let width = hi - lo;
            if !(width.is_finite() && width > 0.0) {
                return Err(FitError::BadWeight {
                    level: j + 1,
                    what: "CI width",
                    value: width,
                });
            }
            v.push(width * width);
        }
        Self::from_v(v, "squared CI width")
    }

    /// docs/methods.md §5.2 "diag": `V_jj` from `wv_diag_covariance` of the series `x` at the
    /// levels and filter of `wv` (per-level divisor), divided by `eff` when `wv` is robust.
    ///
    /// Cost: one MODWT of `x` and one FFT per level.
    ///
    /// # Errors
    /// [`FitError::Input`] wrapping the error of `wv_diag_covariance`; [`FitError::BadWeight`] for a zero or non-finite `V_jj`.
    pub fn diag(x: &[f64], wv: &WaveletVariance) -> Result<Self, FitError> {
        let mut v = wv_diag_covariance(x, wv.filter, wv.levels(), DiagDivisor::Level)?;
        if let Some(r) = wv.robust {
            v.iter_mut().for_each(|x| *x /= r.eff());
        }
        Self::from_v(v, "diag variance")
    }

    /// docs/methods.md §5.4 stage 1: the flattening objective `F = sum_j (1 - nu2_j / nu2_hat_j)^2`
    /// is `Q` with `omega_j = 1 / nu2_hat_j^2` (`V_jj = nu2_hat_j^2`).
    ///
    /// # Errors
    /// [`FitError::BadWeight`] for a zero or non-finite `nu2_hat_j`.
    pub(crate) fn flattening(nu_hat: &[f64]) -> Result<Self, FitError> {
        Self::from_v(
            nu_hat.iter().map(|v| v * v).collect(),
            "squared wavelet variance",
        )
    }

    /// Omega = I (every level weighted 1), for tests and comparisons.
    pub fn unit(levels: usize) -> Self {
        Self {
            v: vec![1.0; levels],
            omega: vec![1.0; levels],
        }
    }

    /// Weights from a caller's diagonal of V.
    ///
    /// # Errors
    /// [`FitError::BadWeight`] for a zero or non-finite value.
    #[cfg(test)]
    pub(crate) fn from_variances(v: Vec<f64>) -> Result<Self, FitError> {
        Self::from_v(v, "variance")
    }

    /// Weights of the given kind; `x` is needed only by [`Weighting::Diag`]. For
    /// [`Weighting::Bootstrap`] these are the fast weights of the first fit.
    ///
    /// # Errors
    /// As [`Weights::fast`] / [`Weights::diag`]; [`FitError::Length`] (what = "series") when
    /// `Diag` is asked without a series.
    pub fn new(
        weighting: Weighting,
        wv: &WaveletVariance,
        x: Option<&[f64]>,
    ) -> Result<Self, FitError> {
        match (weighting, x) {
            (Weighting::Fast | Weighting::Bootstrap, _) => Self::fast(wv),
            (Weighting::Diag, Some(x)) => Self::diag(x, wv),
            (Weighting::Diag, None) => Err(FitError::Length {
                what: "series",
                expected: wv.n,
                found: 0,
            }),
        }
    }

    /// Number of levels.
    pub fn levels(&self) -> usize {
        self.omega.len()
    }
}

/// A full (non-diagonal) weighting `Omega = V^{-1}` given by a covariance `V` of the WV vector
/// (docs/methods.md §5.2 "full", §7.3 efficient weights), applied through a whitening matrix `W`
/// with `W' W = V^{-1}`: the objective's residuals become `W (nu2_hat - nu2(theta))`
/// ([`super::Objective::with_full_weights`]).
///
/// `W = L^{-1}` for the Cholesky factor `V = L L'`. WV levels span many decades, so the
/// factorisation runs on the correlation matrix `C = D^{-1} V D^{-1}`, `D = diag(sqrt V_jj)`:
/// `W = L_C^{-1} D^{-1}`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FullWeights {
    v: DMatrix<f64>,
    whitening: DMatrix<f64>,
}

impl FullWeights {
    /// Weights `Omega = V^{-1}` from a symmetric positive definite `V` (J x J).
    ///
    /// Cost: O(J^3) once.
    ///
    /// # Errors
    /// [`FitError::Length`] when `V` is not square; [`FitError::BadWeight`] for a zero or
    /// non-finite variance `V_jj`, a non-finite entry, or a non-positive Cholesky pivot of the
    /// correlation matrix (`V` not numerically positive definite), naming the level.
    pub(crate) fn from_covariance(v: &DMatrix<f64>) -> Result<Self, FitError> {
        let n = v.nrows();
        if v.ncols() != n {
            return Err(FitError::Length {
                what: "covariance columns",
                expected: n,
                found: v.ncols(),
            });
        }
        let mut d = Vec::with_capacity(n);
        for j in 0..n {
            let x = v[(j, j)];
            let s = x.sqrt();
            if !(x.is_finite() && x > 0.0 && (1.0 / s).is_finite()) {
                return Err(FitError::BadWeight {
                    level: j + 1,
                    what: "covariance diagonal",
                    value: x,
                });
            }
            d.push(s);
        }
        // Cholesky of the correlation matrix, lower triangle (row-major in a DMatrix).
        let mut l = DMatrix::<f64>::zeros(n, n);
        for i in 0..n {
            for j in 0..=i {
                let c = 0.5 * (v[(i, j)] + v[(j, i)]) / (d[i] * d[j]);
                if !c.is_finite() {
                    return Err(FitError::BadWeight {
                        level: i + 1,
                        what: "covariance entry",
                        value: v[(i, j)],
                    });
                }
                let s = c - (0..j).map(|k| l[(i, k)] * l[(j, k)]).sum::<f64>();
                if i == j {
                    if !(s > 0.0 && s.is_finite()) {
                        return Err(FitError::BadWeight {
                            level: i + 1,
                            what: "Cholesky pivot of the correlation matrix (V is not positive definite)",
                            value: s,
                        });
                    }
                    l[(i, i)] = s.sqrt();
                } else {
                    l[(i, j)] = s / l[(j, j)];
                }
            }
        }
        // W = L_C^{-1} D^{-1}: forward substitution column by column.
        let mut w = DMatrix::<f64>::zeros(n, n);
        for col in 0..n {
            for i in col..n {
                let rhs = if i == col { 1.0 } else { 0.0 };
                let s = rhs - (col..i).map(|k| l[(i, k)] * w[(k, col)]).sum::<f64>();
                w[(i, col)] = s / l[(i, i)];
            }
        }
        for col in 0..n {
            for i in col..n {
                w[(i, col)] /= d[col];
            }
        }
        Ok(Self {
            v: v.clone(),
            whitening: w,
        })
    }

    /// The lower-triangular whitening matrix `W`, `W' W = V^{-1}`.
    pub(crate) fn whitening(&self) -> &DMatrix<f64> {
        &self.whitening
    }

    /// `Omega = V^{-1} = W' W`.
    #[cfg(test)]
    pub(crate) fn omega(&self) -> DMatrix<f64> {
        self.whitening.transpose() * &self.whitening
    }

    /// Number of levels.
    pub(crate) fn levels(&self) -> usize {
        self.v.nrows()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{wavelet_variance, WvOptions};

    #[test]
    fn fast_weights_are_inverse_squared_ci_widths() {
        let x: Vec<f64> = (0..1000).map(|i| ((i * 7919) % 101) as f64).collect();
        let wv = wavelet_variance(&x, 1.0, &WvOptions::default()).unwrap();
        let w = Weights::fast(&wv).unwrap();
        for j in 0..wv.levels() {
            let width = wv.ci_high[j] - wv.ci_low[j];
            assert!((w.omega[j] * width * width - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn fast_v_matches_methods_5_9() {
        // CI bounds (2.19972535, 2.6215535): V = 0.42182815^2 = 0.1779390 (docs/methods.md §5.9)
        let x: Vec<f64> = (0..64).map(|i| ((i * 37) % 11) as f64).collect();
        let mut wv = wavelet_variance(&x, 1.0, &WvOptions::default()).unwrap();
        wv.ci_low[0] = 2.19972535;
        wv.ci_high[0] = 2.6215535;
        let w = Weights::fast(&wv).unwrap();
        assert!((w.v[0] / 0.1779390 - 1.0).abs() < 5e-7);
    }

    #[test]
    fn full_weights_whiten_to_the_inverse() {
        // V with decades-apart variances and strong correlation: W'W V = I
        let sd = [1e-3, 1e-6, 1e-9];
        let rho = [[1.0, 0.9, 0.5], [0.9, 1.0, 0.8], [0.5, 0.8, 1.0]];
        let v = DMatrix::from_fn(3, 3, |i, j| rho[i][j] * sd[i] * sd[j]);
        let w = FullWeights::from_covariance(&v).unwrap();
        let ident = w.omega() * &v;
        for i in 0..3 {
            for j in 0..3 {
                let want = if i == j { 1.0 } else { 0.0 };
                // compared in correlation units (D Omega V D^{-1} = C^{-1} C, scale-free): the condition
                // number of the correlation matrix is ~60, so 1e-12 leaves ample room
                let scaled = ident[(i, j)] * sd[i] / sd[j];
                assert!((scaled - want).abs() < 1e-12, "{ident}");
            }
        }
        assert_eq!(w.whitening()[(0, 1)], 0.0);
        // diagonal V: W = diag(1/sqrt(V_jj))
        let d = FullWeights::from_covariance(&DMatrix::from_diagonal(
            &nalgebra::DVector::from_vec(vec![4.0, 0.25]),
        ))
        .unwrap();
        assert!((d.whitening()[(0, 0)] - 0.5).abs() < 1e-15);
        assert!((d.whitening()[(1, 1)] - 2.0).abs() < 1e-15);
        // not positive definite: named level
        let bad = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        let e = FullWeights::from_covariance(&bad).unwrap_err();
        assert!(matches!(e, FitError::BadWeight { level: 2, .. }), "{e}");
        assert!(FullWeights::from_covariance(&DMatrix::zeros(2, 3)).is_err());
        assert!(FullWeights::from_covariance(&DMatrix::from_row_slice(1, 1, &[0.0])).is_err());
    }

    #[test]
    fn bad_levels_are_named() {
        let x: Vec<f64> = (0..64).map(|i| ((i * 37) % 11) as f64).collect();
        let mut wv = wavelet_variance(&x, 1.0, &WvOptions::default()).unwrap();
        wv.ci_low[2] = f64::NAN;
        let e = Weights::fast(&wv).unwrap_err();
        assert!(matches!(e, FitError::BadWeight { level: 3, .. }), "{e}");
        assert!(e.to_string().starts_with("level 3:"));
        assert!(Weights::from_variances(vec![1.0, 0.0]).is_err());
        let d = Weights::diag(&x, &wv).unwrap();
        assert_eq!(d.levels(), wv.levels());
    }
}
