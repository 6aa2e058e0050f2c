//! Chi-square ("eta3") confidence intervals of a variance estimate (METHODS §1.7).

use crate::error::ParamError;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// Checks a confidence level `alpha` in (0, 1).
///
/// # Errors
/// [`ParamError`] naming `alpha` when it is outside (0, 1) or not finite.
pub fn check_alpha(alpha: f64) -> Result<(), ParamError> {
    if alpha.is_finite() && alpha > 0.0 && alpha < 1.0 {
        Ok(())
    } else {
        Err(ParamError::new(
            "alpha",
            alpha,
            "must be in (0, 1), e.g. 0.05 for 95% intervals",
        ))
    }
}

/// Equivalent degrees of freedom of the level-j WV, METHODS §1.7, paper eq. (1) CI:
/// `eta_j = max(M_j / 2^j, 1)` with `M_j` the number of kept coefficients.
pub fn eta3(kept: usize, j: usize) -> f64 {
    (kept as f64 / (j as f64).exp2()).max(1.0)
}

/// Chi-square interval of a variance estimate with `eta` equivalent degrees of freedom,
/// METHODS §1.7: `[eta v / q(1 - alpha/2; eta), eta v / q(alpha/2; eta)]`.
///
/// `alpha` must already be valid ([`check_alpha`]) and `eta >= 1`.
pub fn chi_square_interval(estimate: f64, eta: f64, alpha: f64) -> (f64, f64) {
    // eta >= 1 > 0, so the distribution exists; the quantiles are finite for alpha in (0, 1).
    let chi = ChiSquared::new(eta).expect("eta >= 1 is a valid chi-square df");
    let upper_q = chi.inverse_cdf(1.0 - alpha / 2.0);
    let lower_q = chi.inverse_cdf(alpha / 2.0);
    (eta * estimate / upper_q, eta * estimate / lower_q)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// statrs inverts the regularised gamma by bisection/Newton to ~1e-9 relative; the METHODS
    /// values carry 7 significant digits.
    const TOL: f64 = 5e-7;

    fn close(a: f64, b: f64) -> bool {
        ((a - b) / b).abs() < TOL
    }

    #[test]
    fn chi_square_interval_matches_methods_1_7() {
        // METHODS §1.10 test values: nu = 1, M = 100, alpha = 0.05
        for (j, lo, hi) in [
            (1, 0.7000821, 1.545243),
            (2, 0.6150596, 1.905528),
            (3, 0.5200056, 2.657153),
        ] {
            let (l, h) = chi_square_interval(1.0, eta3(100, j), 0.05);
            assert!(close(l, lo) && close(h, hi), "level {j}: {l} {h}");
        }
        // x = 1..8: level 1 eta 3.5, level 2 eta 1.25
        let (l, h) = chi_square_interval(0.25, eta3(7, 1), 0.05);
        assert!(close(l, 0.08526516) && close(h, 2.582085), "{l} {h}");
        let (l, h) = chi_square_interval(1.0, eta3(5, 2), 0.05);
        assert!(close(l, 0.22025899) && close(h, 271.909147), "{l} {h}");
    }

    #[test]
    fn eta3_is_at_least_one() {
        assert_eq!(eta3(1, 5), 1.0);
        assert_eq!(eta3(64, 3), 8.0);
    }

    #[test]
    fn check_alpha_rejects_out_of_range() {
        assert!(check_alpha(0.05).is_ok());
        for a in [0.0, 1.0, -0.1, f64::NAN] {
            assert!(check_alpha(a).is_err());
        }
    }
}
