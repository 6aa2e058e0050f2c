//! Goodness of fit: the J-test of over-identifying restrictions (docs/methods.md §7.3, paper eq.
//! 4).
//!
//! The package re-estimates with `V` itself as the weight (§13.11); here the statistic is the
//! efficient-weight one: re-minimise `Q` from `theta_hat` (stage 2 only) with `Omega = V^{-1}`,
//! then `T = (nu2_hat - nu2(theta_tilde))' V^{-1} (nu2_hat - nu2(theta_tilde))`, which is
//! asymptotically chi-square with `J - p` degrees of freedom under a correct model. With
//! N ~ 1e6 the test rejects almost any model: report it, never rank by it.

use crate::error::ParamError;
use crate::fit::weights::FullWeights;
use crate::fit::{minimize, FitError, Gmwm, GmwmFit, LmOptions, Objective, Parametrisation};
use nalgebra::DMatrix;
use serde::Serialize;
use statrs::function::gamma::gamma_ur;
use std::fmt;

/// The J-test result (docs/methods.md §7.3).
///
/// Wire format: `statistic` (T), `df` (J - p), `p_value` (`1 - F_chi2(T; df)`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JTest {
    /// `T = r' V^{-1} r` at the efficient-weight estimate.
    pub statistic: f64,
    /// Degrees of freedom `J - p`.
    pub df: usize,
    /// Upper chi-square tail probability of `statistic`.
    pub p_value: f64,
}

impl fmt::Display for JTest {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "J-test: T = {:.6}, df = {}, p-value = {:.4e}",
            self.statistic, self.df, self.p_value
        )
    }
}

/// Upper tail `1 - F_chi2(t; df)` of the chi-square distribution (docs/methods.md §7.3), accurate
/// far into the tail (regularised upper incomplete gamma `Q(df/2, t/2)`); 1 for `t <= 0`, NaN for a
/// NaN `t`. With `df = 0` the distribution is the point mass at 0, whose upper tail at `t > 0`
/// is 0.
pub(crate) fn chi_square_upper_tail(t: f64, df: usize) -> f64 {
    if t <= 0.0 {
        1.0
    } else if t.is_infinite() || df == 0 {
        0.0
    } else {
        gamma_ur(df as f64 / 2.0, t / 2.0)
    }
}

/// Hartlap et al. (2007, A&A 464, 399, eq. 17) debiasing factor `(H - J - 2) / (H - 1)`:
/// if `S` is the sample covariance of `H` Gaussian `J`-vectors, `E[S^{-1}] = V^{-1} (H - 1) /
/// (H - J - 2)`, so `factor x S^{-1}` is unbiased for `V^{-1}`. Scaling `S` by `1 / factor`
/// before [`j_test`] applies it. `None` unless `H > J + 2`.
pub(crate) fn hartlap_factor(replicates: usize, levels: usize) -> Option<f64> {
    (replicates > levels + 2).then(|| (replicates - levels - 2) as f64 / (replicates - 1) as f64)
}

/// docs/methods.md §7.3, paper eq. (4): the J-test of `fit` (a fit by `gmwm`) with `v`, a
/// covariance of the WV vector (J x J, full or diagonal; e.g. a parametric-bootstrap covariance,
/// which the caller should debias with [`hartlap_factor`] since the statistic uses its inverse).
///
/// Re-minimises the objective from `fit.theta` (stage 2 only, default [`LmOptions`]) with
/// `Omega = V^{-1}`, `T = Q` at that minimum, `df = J - p`, `p = 1 - F_chi2(T; df)`. Components
/// the fit drove to the boundary ([`GmwmFit::active_sub_model`]) are left out: the test is that
/// of the active sub-model, with `p` its parameter count.
///
/// Cost: one Cholesky of V and one stage-2 fit.
///
/// # Errors
/// [`FitError::Length`] when `v` is not J x J; [`FitError::BadWeight`] when `v` is not
/// positive definite ([`FullWeights::from_covariance`]); [`FitError::Input`] with a
/// [`ParamError`] when `J <= p` (no degrees of freedom); errors of the fit's parametrisation
/// and optimiser.
pub(crate) fn j_test(gmwm: &Gmwm, fit: &GmwmFit, v: &DMatrix<f64>) -> Result<JTest, FitError> {
    let levels = fit.nu_hat.len();
    // components at the boundary stay there: test the active sub-model (crate::fit::active)
    let sub = fit.active_sub_model()?;
    let (model, theta) = match &sub {
        Some(s) => (s.model.clone(), &s.start[..]),
        None => (gmwm.model().clone(), &fit.theta[..]),
    };
    let p = theta.len();
    if v.nrows() != levels {
        return Err(FitError::Length {
            what: "covariance rows",
            expected: levels,
            found: v.nrows(),
        });
    }
    if levels <= p {
        return Err(ParamError::new(
            "levels",
            levels,
            format!("the J-test needs more levels than the {p} parameters (df = J - p >= 1)"),
        )
        .into());
    }
    let weights = FullWeights::from_covariance(v)?;
    let param = Parametrisation::new(&model, fit.preset, fit.phi_order, fit.freq_hz)?;
    let u0 = param.to_u_restart(theta)?;
    let objective =
        Objective::with_full_weights(&model, param, &fit.nu_hat, &weights, fit.freq_hz)?;
    let min = minimize(&objective, &u0, &LmOptions::default())?;
    let df = levels - p;
    Ok(JTest {
        statistic: min.objective,
        df,
        p_value: chi_square_upper_tail(min.objective, df),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi_square_upper_tail_matches_closed_forms() {
        // df = 2: exp(-t/2); df = 1 at t = 3.841459 (the 95% quantile): 0.05
        for t in [0.1, 1.0, 10.0, 200.0] {
            let want = (-t / 2.0f64).exp();
            assert!((chi_square_upper_tail(t, 2) / want - 1.0).abs() < 1e-12);
        }
        assert!((chi_square_upper_tail(3.841_458_820_694_124, 1) - 0.05).abs() < 1e-12);
        assert_eq!(chi_square_upper_tail(0.0, 3), 1.0);
        // df = 0 (the point mass at 0) and NaN are answers, not panics
        assert_eq!(chi_square_upper_tail(1.0, 0), 0.0);
        assert!(chi_square_upper_tail(f64::NAN, 2).is_nan());
    }

    #[test]
    fn hartlap_factor_needs_more_replicates_than_levels() {
        assert_eq!(hartlap_factor(100, 10), Some(88.0 / 99.0));
        assert_eq!(hartlap_factor(12, 10), None);
    }
}
