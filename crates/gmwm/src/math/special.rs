//! Special functions the statistics need and `statrs` does not provide.

/// The trigamma function `psi'(x) = d^2 ln Gamma(x) / dx^2` for `x > 0`; NaN otherwise.
///
/// `Var(ln X) = psi'(eta / 2)` when `eta X / s` is chi-square with `eta` degrees of freedom
/// (the log of a scaled chi-square variable), which is how the noise of a wavelet-variance
/// estimate is measured on the log scale of its plots.
///
/// # Formula
/// The recurrence `psi'(x) = psi'(x + 1) + 1 / x^2` moves `x` to at least 10, then the
/// asymptotic series `1/x + 1/(2x^2) + sum_k B_2k / x^(2k+1)` (Bernoulli numbers
/// `1/6, -1/30, 1/42, -1/30, 5/66, -691/2730, 7/6`; Abramowitz & Stegun 6.4.12) whose first
/// omitted term at `x = 10`, `|B_16| / 10^17 ~ 7e-17`, is below the rounding of the sum.
/// Test values `psi'(1) = pi^2 / 6`, `psi'(1/2) = pi^2 / 2` (unit tests).
pub(crate) fn trigamma(x: f64) -> f64 {
    if !(x > 0.0 && x.is_finite()) {
        return f64::NAN;
    }
    let mut x = x;
    let mut acc = 0.0;
    while x < 10.0 {
        acc += 1.0 / (x * x);
        x += 1.0;
    }
    let z = 1.0 / (x * x);
    // B_2k / x^(2k+1), k = 1..7, in Horner form in z = 1/x^2
    let series = z
        * (1.0 / 6.0
            + z * (-1.0 / 30.0
                + z * (1.0 / 42.0
                    + z * (-1.0 / 30.0
                        + z * (5.0 / 66.0 + z * (-691.0 / 2730.0 + z * (7.0 / 6.0)))))));
    acc + 1.0 / x + 0.5 * z + series / x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trigamma_matches_closed_forms_and_its_recurrence() {
        let pi2 = std::f64::consts::PI.powi(2);
        // psi'(1) = pi^2/6, psi'(1/2) = pi^2/2, psi'(2) = pi^2/6 - 1, psi'(3/2) = pi^2/2 - 4
        assert!((trigamma(1.0) - pi2 / 6.0).abs() < 1e-14);
        assert!((trigamma(0.5) - pi2 / 2.0).abs() < 1e-13);
        assert!((trigamma(2.0) - (pi2 / 6.0 - 1.0)).abs() < 1e-14);
        assert!((trigamma(1.5) - (pi2 / 2.0 - 4.0)).abs() < 1e-13);
        // large x: psi'(x) ~ 1/x + 1/(2x^2) + 1/(6x^3)
        let x = 1e6;
        assert!((trigamma(x) / (1.0 / x + 0.5 / (x * x)) - 1.0).abs() < 1e-12);
        for x in [0.3, 2.7, 6.5, 40.0] {
            let r = trigamma(x) - trigamma(x + 1.0) - 1.0 / (x * x);
            assert!(r.abs() < 1e-13 * trigamma(x), "{x}: {r}");
        }
        assert!(trigamma(0.0).is_nan() && trigamma(-1.0).is_nan() && trigamma(f64::NAN).is_nan());
    }
}
