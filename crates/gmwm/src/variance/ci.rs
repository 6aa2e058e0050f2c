//! Chi-square ("eta3") confidence intervals of a variance estimate (docs/methods.md §1.7).

use crate::error::ParamError;
use crate::math::elementary;
use statrs::distribution::{ChiSquared, Continuous, ContinuousCDF, Normal};
use statrs::function::gamma::{gamma_lr, gamma_ur};

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

/// Equivalent degrees of freedom of the level-j WV, docs/methods.md §1.7, paper eq. (1) CI:
/// `eta_j = max(M_j / 2^j, 1)` with `M_j` the number of kept coefficients.
pub(crate) fn eta3(kept: usize, j: usize) -> f64 {
    (kept as f64 / elementary::exp2(j as f64)).max(1.0)
}

/// Why `alpha` is not a significance level the front ends accept, or `None` when it is one:
/// `(0, 0.5]`. A value above 0.5 is most likely a confidence level (`0.95` for 95% intervals,
/// which as alpha would give 5% ones), so the command line and the Python calls refuse it
/// rather than obey it; the engine itself takes any level in `(0, 1)`.
///
/// ```
/// use gmwm::significance_level_problem;
/// assert!(significance_level_problem(0.05).is_none());
/// assert!(significance_level_problem(0.95).unwrap().contains("for 95% intervals give 0.05"));
/// ```
pub fn significance_level_problem(alpha: f64) -> Option<String> {
    // six decimals: 1 - 0.95 prints as 0.05, not 0.050000000000000044
    let short = |v: f64| format!("{}", (v * 1e6).round() / 1e6);
    if alpha > 0.0 && alpha <= 0.5 {
        None
    } else if alpha > 0.5 && alpha < 1.0 {
        Some(format!(
            "alpha is the significance level, in (0, 0.5]: the intervals cover 1 - alpha, so {} would give {}% intervals; for {}% intervals give {}",
            short(alpha),
            short(100.0 * (1.0 - alpha)),
            short(100.0 * alpha),
            short(1.0 - alpha),
        ))
    } else {
        Some("must be a significance level in (0, 0.5]: 0.05 gives 95% intervals".to_string())
    }
}

/// Checks chi-square degrees of freedom: finite and positive (they may be fractional).
fn check_df(name: &'static str, df: f64) -> Result<(), ParamError> {
    if df.is_finite() && df > 0.0 {
        Ok(())
    } else {
        Err(ParamError::new(
            name,
            df,
            "must be a finite positive number of degrees of freedom",
        ))
    }
}

/// Chi-square interval of a variance estimate with `eta` equivalent degrees of freedom,
/// docs/methods.md §1.7: `[eta v / q(1 - alpha/2; eta), eta v / q(alpha/2; eta)]`.
///
/// # Errors
/// [`ParamError`] naming `alpha` when it is outside (0, 1) ([`check_alpha`]), `eta` when it is
/// not finite and positive, or `estimate` when it is negative or not finite.
#[cfg(test)]
pub(crate) fn chi_square_interval(
    estimate: f64,
    eta: f64,
    alpha: f64,
) -> Result<(f64, f64), ParamError> {
    check_alpha(alpha)?;
    check_df("eta", eta)?;
    if !(estimate.is_finite() && estimate >= 0.0) {
        return Err(ParamError::new(
            "estimate",
            estimate,
            "must be a finite non-negative variance",
        ));
    }
    Ok(interval_unchecked(estimate, eta, alpha))
}

/// [`chi_square_interval`] for arguments the caller has validated (`alpha` in (0, 1), finite
/// `eta > 0`).
pub(crate) fn interval_unchecked(estimate: f64, eta: f64, alpha: f64) -> (f64, f64) {
    // Solve each tail directly: 1 - alpha/2 rounds to 1 for alpha < ~2e-16.
    let upper_q = quantile_from_tail(alpha / 2.0, true, eta);
    let lower_q = quantile_from_tail(alpha / 2.0, false, eta);
    (eta * estimate / upper_q, eta * estimate / lower_q)
}

/// Quantile of the chi-square distribution with real `df > 0` at probability `p` in (0, 1)
/// (docs/methods.md §12).
///
/// statrs' own `inverse_cdf` returns NaN at df = 1, p = 0.025 and is off by 4e-3 in probability
/// at df = 5e5 (the level-1 eta of a 1e6-sample series), so this solves `P(df/2, x/2) = p`
/// (or `Q(df/2, x/2) = 1 - p` above the median, for accuracy in the upper tail) by Newton steps
/// safeguarded by a bisection bracket, from the Wilson–Hilferty start, to ~1e-15 relative.
///
/// # Errors
/// [`ParamError`] naming `p` when it is outside (0, 1) or `df` when it is not finite and
/// positive.
pub(crate) fn chi_square_quantile(p: f64, df: f64) -> Result<f64, ParamError> {
    if !(p > 0.0 && p < 1.0) {
        return Err(ParamError::new("p", p, "must be a probability in (0, 1)"));
    }
    check_df("df", df)?;
    Ok(if p > 0.5 {
        quantile_from_tail(1.0 - p, true, df)
    } else {
        quantile_from_tail(p, false, df)
    })
}

/// The chi-square quantile whose lower tail (`upper = false`) or upper tail (`upper = true`)
/// has probability `tail` in (0, 1/2].
fn quantile_from_tail(tail: f64, upper: bool, df: f64) -> f64 {
    let k = df / 2.0;
    // residual r(x), increasing in x, computed from the tail that is accurate
    let residual = |x: f64| -> f64 {
        if upper {
            tail - gamma_ur(k, x / 2.0)
        } else {
            gamma_lr(k, x / 2.0) - tail
        }
    };
    let Ok(chi) = ChiSquared::new(df) else {
        return f64::NAN; // unreachable: callers pass a finite df > 0
    };
    let z_lower = Normal::standard().inverse_cdf(tail);
    let z = if upper { -z_lower } else { z_lower };
    let c = 2.0 / (9.0 * df);
    let wh = df * (1.0 - c + z * c.sqrt()).powi(3);
    let mut x = if wh > 0.0 { wh } else { df.min(1.0) * 1e-3 };
    // bracket [lo, hi] with r(lo) < 0 < r(hi)
    let (mut lo, mut hi) = (0.0, x.max(1.0));
    while residual(hi) < 0.0 {
        if hi > f64::MAX / 4.0 {
            return f64::INFINITY;
        }
        lo = hi;
        hi *= 2.0;
    }
    for _ in 0..200 {
        let r = residual(x);
        if r == 0.0 {
            return x;
        }
        if r < 0.0 {
            lo = lo.max(x);
        } else {
            hi = hi.min(x);
        }
        let step = r / chi.pdf(x);
        let mut next = x - step;
        if !(next > lo && next < hi && next.is_finite()) {
            next = 0.5 * (lo + hi);
        }
        if (next - x).abs() <= 1e-15 * x || hi - lo <= 1e-15 * hi {
            return next;
        }
        x = next;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// statrs inverts the regularised gamma by bisection/Newton to ~1e-9 relative; the test
    /// values of docs/methods.md carry 7 significant digits.
    const TOL: f64 = 5e-7;

    fn close(a: f64, b: f64) -> bool {
        ((a - b) / b).abs() < TOL
    }

    #[test]
    fn chi_square_interval_matches_methods_1_7() {
        // docs/methods.md §1.10 test values: nu = 1, M = 100, alpha = 0.05
        for (j, lo, hi) in [
            (1, 0.7000821, 1.545243),
            (2, 0.6150596, 1.905528),
            (3, 0.5200056, 2.657153),
        ] {
            let (l, h) = chi_square_interval(1.0, eta3(100, j), 0.05).unwrap();
            assert!(close(l, lo) && close(h, hi), "level {j}: {l} {h}");
        }
        // x = 1..8: level 1 eta 3.5, level 2 eta 1.25
        let (l, h) = chi_square_interval(0.25, eta3(7, 1), 0.05).unwrap();
        assert!(close(l, 0.08526516) && close(h, 2.582085), "{l} {h}");
        let (l, h) = chi_square_interval(1.0, eta3(5, 2), 0.05).unwrap();
        assert!(close(l, 0.22025899) && close(h, 271.909147), "{l} {h}");
    }

    #[test]
    fn chi_square_quantile_inverts_the_cdf() {
        // Independent truth: the regularised incomplete gamma (statrs' cdf, accurate to ~1e-15).
        for df in [1.0, 1.25, 3.5, 12.5, 50.0, 1e3, 5e5, 4e7] {
            let chi = ChiSquared::new(df).unwrap();
            for p in [1e-6, 0.025, 0.5, 0.975] {
                let q = chi_square_quantile(p, df).unwrap();
                let err = if p > 0.5 {
                    chi.sf(q) - (1.0 - p)
                } else {
                    chi.cdf(q) - p
                };
                // probability error mapped to a relative quantile error: dx / x = dp / (f(x) x);
                // the cdf itself carries ~1e-12 absolute error at df = 5e5.
                let rel_x = err.abs() / (chi.pdf(q) * q);
                assert!(
                    rel_x < 1e-11,
                    "df {df} p {p}: {err:e} ({rel_x:e} relative in x)"
                );
            }
        }
        // R: qchisq(0.975, 1) = 5.023886187314888, qchisq(0.025, 1) = 0.000982069117175
        // (statrs' inverse_cdf returns NaN for the latter)
        assert!((chi_square_quantile(0.975, 1.0).unwrap() - 5.023886187314888).abs() < 1e-13);
        assert!((chi_square_quantile(0.025, 1.0).unwrap() / 0.000982069117175 - 1.0).abs() < 1e-9);
    }

    #[test]
    fn tiny_alpha_gives_finite_wide_intervals() {
        // 1 - 1e-16 / 2 rounds to 1: the tails must be solved directly (review finding)
        for alpha in [1e-16, 1e-300] {
            let (lo, hi) = chi_square_interval(1.0, 50.0, alpha).unwrap();
            assert!(
                lo > 0.0 && lo < 0.7 && hi > 1.5 && hi.is_finite(),
                "{alpha}: {lo} {hi}"
            );
        }
    }

    #[test]
    fn bad_arguments_are_errors_not_panics() {
        for df in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(chi_square_quantile(0.5, df).unwrap_err().name, "df");
            assert_eq!(chi_square_interval(1.0, df, 0.05).unwrap_err().name, "eta");
        }
        for p in [0.0, 1.0, -0.5, 2.0, f64::NAN] {
            assert_eq!(chi_square_quantile(p, 3.0).unwrap_err().name, "p");
        }
        assert_eq!(
            chi_square_interval(1.0, 3.0, 1.5).unwrap_err().name,
            "alpha"
        );
        for v in [-1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(
                chi_square_interval(v, 3.0, 0.05).unwrap_err().name,
                "estimate"
            );
        }
        // fractional df below 1 is a valid chi-square
        let q = chi_square_quantile(0.5, 0.5).unwrap();
        let chi = ChiSquared::new(0.5).unwrap();
        assert!((chi.cdf(q) - 0.5).abs() < 1e-12, "{q}");
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
