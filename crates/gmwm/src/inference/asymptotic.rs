//! Asymptotic inference on a GMWM fit (docs/methods.md §7.1, §7.2, §7.6): the sandwich covariance
//! and confidence intervals.
//!
//! # Intervals (port choices, documented deviations from the package)
//! - `z = Phi^{-1}(1 - alpha/2)` by default ([`ZConvention::TwoSided`]); the package's
//!   `Phi^{-1}(1 - alpha)` (a 90% interval labelled 95%, §13.13) is [`ZConvention::Package`].
//! - GM parameters: the Jacobian `A` is taken in the GM parametrisation `(beta, sigma2_gm)`
//!   (docs/methods.md §4.5), so the sandwich is directly the covariance of `(beta_hat,
//!   sigma2_gm_hat)`: this *is* the delta method, exact in the Jacobian, and the SE column is in GM
//!   units (the package leaves it in AR1 units and maps the endpoints one by one, §13.19).
//! - [`IntervalScale::Transformed`] (default): a Wald interval on `g(theta)` mapped back, with
//!   `g = ln` for the parameters living on `(0, inf)` (every variance, the GM `beta`), `g = atanh`
//!   for the coefficients living on `(-1, 1)` (AR1 `phi`, MA1 `theta`, ARMA11 `phi`, `theta`)
//!   and `g` = identity for the others (DR `omega`, AR(p)/MA(q)/ARMA(p,q) coefficients); the SE of
//!   `g(theta_hat)` is `SE / |g'(theta_hat)|` (delta method). The intervals stay inside the
//!   parameter domain, and for a GM the `beta` interval is the image of an interval on
//!   `ln(-ln phi)` under the monotone map `beta = -freq ln(phi)` (valid, §7.6). Variance
//!   estimators are right-skewed (the WV is a sum of squares), which a log scale follows.
//!   [`IntervalScale::Natural`] gives the package's `theta_hat +- z SE`.

use crate::error::ParamError;
use crate::fit::FitError;
use crate::math::elementary;
use crate::model::{Model, ParamDomain};
use crate::variance::ci::check_alpha;
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};
use statrs::distribution::{ContinuousCDF, Normal};

/// Which normal quantile multiplies the SE (docs/methods.md §7.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ZConvention {
    /// `z = Phi^{-1}(1 - alpha/2)`: a two-sided `1 - alpha` interval (default, correct).
    #[default]
    TwoSided,
    /// `z = Phi^{-1}(1 - alpha)`, as the package (two-sided `1 - 2 alpha`, §13.13); for
    /// reproducing package numbers only.
    Package,
}

/// On which scale the Wald intervals are built (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum IntervalScale {
    /// Log scale for `(0, inf)` parameters, atanh for `(-1, 1)` ones, natural otherwise
    /// (default: intervals inside the domain).
    #[default]
    Transformed,
    /// `theta_hat +- z SE` for every parameter (the package).
    Natural,
}

/// docs/methods.md §7.2: the normal quantile `z` for `alpha` under `convention`
/// (`alpha = 0.05`: 1.959964 two-sided, 1.644854 package).
///
/// # Errors
/// [`ParamError`] unless `0 < alpha < 1`.
pub(crate) fn z_value(alpha: f64, convention: ZConvention) -> Result<f64, ParamError> {
    check_alpha(alpha)?;
    let tail = match convention {
        ZConvention::TwoSided => alpha / 2.0,
        ZConvention::Package => alpha,
    };
    // -Phi^{-1}(tail) rather than Phi^{-1}(1 - tail): 1 - tail rounds for tiny alpha
    let normal = Normal::standard();
    Ok(-normal.inverse_cdf(tail))
}

/// The sandwich covariance of docs/methods.md §7.1 and the rank of `A' Omega A`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Sandwich {
    /// `Psi = H V H'` (p x p).
    pub(crate) psi: DMatrix<f64>,
    /// `H = (A' Omega A)^+ A' Omega` (p x J).
    pub(crate) h: DMatrix<f64>,
    /// Numerical rank of `A' Omega A` (p when the model is locally identified).
    pub(crate) rank: usize,
}

/// Relative singular-value cut-off of the pseudo-inverse: singular values of the
/// column-equilibrated `A' Omega A` below `1e-12` times the largest count as zero (about 1e4
/// times the rounding level of its entries).
pub(crate) const PINV_RCOND: f64 = 1e-12;

/// docs/methods.md §7.1: `H = (A' Omega A)^+ A' Omega`, `Psi = H V H'` with `A` (J x p), `Omega`
/// (J x J) and `V` (J x J).
///
/// The columns of `A` are first scaled to unit `Omega`-norm (parameters differ by many decades,
/// e.g. a GM `beta` and `sigma2_gm`), the pseudo-inverse of the equilibrated `p x p` matrix uses
/// the relative cut-off `PINV_RCOND` and the scaling is undone; for a full-rank matrix this is
/// exactly the inverse.
///
/// # Errors
/// [`FitError::Length`] for inconsistent sizes; [`FitError::Input`] when a column of `A` has
/// zero or non-finite `Omega`-norm (a parameter without influence on the WV: its variance is not
/// identified).
pub(crate) fn sandwich(
    a: &DMatrix<f64>,
    omega: &DMatrix<f64>,
    v: &DMatrix<f64>,
) -> Result<Sandwich, FitError> {
    let (levels, p) = a.shape();
    for (what, m) in [("Omega", omega), ("V", v)] {
        if m.shape() != (levels, levels) {
            return Err(FitError::Length {
                what: if what == "V" { "V rows" } else { "Omega rows" },
                expected: levels,
                found: m.nrows(),
            });
        }
    }
    let b = a.transpose() * omega * a;
    let mut s = Vec::with_capacity(p);
    for k in 0..p {
        let x = b[(k, k)].sqrt();
        if !(x.is_finite() && x > 0.0) {
            return Err(ParamError::new(
                "theta",
                k,
                "has no influence on the implied WV at the estimate, so its variance is not identified",
            )
            .into());
        }
        s.push(x);
    }
    let bs = DMatrix::from_fn(p, p, |i, j| b[(i, j)] / (s[i] * s[j]));
    let svd = bs.svd(true, true);
    let max_sv = svd.singular_values.max();
    let rank = svd
        .singular_values
        .iter()
        .filter(|&&x| x > PINV_RCOND * max_sv)
        .count();
    let pinv = svd
        .pseudo_inverse(PINV_RCOND * max_sv)
        .map_err(|e| FitError::from(ParamError::new("A' Omega A", e, "an SVD")))?;
    // (A' Omega A)^+ = S^{-1} Bs^+ S^{-1}
    let binv = DMatrix::from_fn(p, p, |i, j| pinv[(i, j)] / (s[i] * s[j]));
    let h = binv * a.transpose() * omega;
    let psi = &h * v * h.transpose();
    // symmetrise against rounding
    let psi = (&psi + psi.transpose()) * 0.5;
    Ok(Sandwich { psi, h, rank })
}

/// The interval transform `g` of one parameter (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Scale {
    Identity,
    Log,
    Atanh,
}

impl Scale {
    /// The transform of a parameter with `domain` under `scale`.
    pub(crate) fn of(domain: Option<ParamDomain>, scale: IntervalScale) -> Self {
        match (scale, domain) {
            (IntervalScale::Natural, _) => Scale::Identity,
            (_, Some(ParamDomain::Variance | ParamDomain::Rate)) => Scale::Log,
            (_, Some(ParamDomain::UnitInterval)) => Scale::Atanh,
            _ => Scale::Identity,
        }
    }

    /// `g(x)`.
    pub(crate) fn forward(self, x: f64) -> f64 {
        match self {
            Scale::Identity => x,
            Scale::Log => elementary::log(x),
            Scale::Atanh => elementary::atanh(x),
        }
    }

    /// `g^{-1}(y)`.
    pub(crate) fn inverse(self, y: f64) -> f64 {
        match self {
            Scale::Identity => y,
            Scale::Log => elementary::exp(y),
            Scale::Atanh => elementary::tanh(y),
        }
    }

    /// `g'(x)`.
    pub(crate) fn derivative(self, x: f64) -> f64 {
        match self {
            Scale::Identity => 1.0,
            Scale::Log => 1.0 / x,
            Scale::Atanh => 1.0 / ((1.0 - x) * (1.0 + x)),
        }
    }

    /// Wald interval `g^{-1}(g(x) +- z se_g)` given the SE on the transformed scale.
    pub(crate) fn interval(self, x: f64, se_g: f64, z: f64) -> (f64, f64) {
        let c = self.forward(x);
        (self.inverse(c - z * se_g), self.inverse(c + z * se_g))
    }
}

/// The interval transform of each parameter of `model` (model order).
pub(crate) fn scales(model: &Model, scale: IntervalScale) -> Vec<Scale> {
    model
        .components()
        .iter()
        .flat_map(|c| (0..c.kind.n_params()).map(move |i| Scale::of(c.kind.param_domain(i), scale)))
        .collect()
}

/// docs/methods.md §7.2 with the scale of the module doc: the interval of `estimate` with standard
/// error `se` (natural units) for a parameter of `domain`, `z` from `z_value`.
///
/// # Examples
/// Worked example: the test `tests::examples::example_asymptotic_wald_interval`.
pub(crate) fn wald_interval(
    estimate: f64,
    se: f64,
    z: f64,
    domain: Option<ParamDomain>,
    scale: IntervalScale,
) -> (f64, f64) {
    let g = Scale::of(domain, scale);
    g.interval(estimate, se * g.derivative(estimate).abs(), z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn z_values_match_methods_7_2() {
        // Phi^{-1}(0.975) = 1.959963985, Phi^{-1}(0.95) = 1.644853627
        let two = z_value(0.05, ZConvention::TwoSided).unwrap();
        let pkg = z_value(0.05, ZConvention::Package).unwrap();
        assert!((two - 1.959_963_985).abs() < 1e-8, "{two}");
        assert!((pkg - 1.644_853_627).abs() < 1e-8, "{pkg}");
        assert!(z_value(0.0, ZConvention::TwoSided).is_err());
        assert!(z_value(1e-20, ZConvention::TwoSided).unwrap().is_finite());
    }

    #[test]
    fn sandwich_matches_methods_7_1() {
        // WN at tau (2, 4, 8), theta 1, Omega = V = I: Psi = 1 / 0.328125 = 3.047619
        let a = DMatrix::from_column_slice(3, 1, &[0.5, 0.25, 0.125]);
        let s = sandwich(&a, &DMatrix::identity(3, 3), &DMatrix::identity(3, 3)).unwrap();
        assert!((s.psi[(0, 0)] - 1.0 / 0.328125).abs() < 1e-12);
        assert_eq!(s.rank, 1);
        // a parameter without influence is refused
        let z = DMatrix::zeros(3, 1);
        assert!(sandwich(&z, &DMatrix::identity(3, 3), &DMatrix::identity(3, 3)).is_err());
    }

    #[test]
    fn transformed_intervals_stay_in_the_domain() {
        let (lo, hi) = wald_interval(
            0.1,
            0.2,
            1.96,
            Some(ParamDomain::Variance),
            IntervalScale::Transformed,
        );
        assert!(lo > 0.0 && hi > 0.1);
        // log-scale interval is multiplicative: lo * hi = x^2
        assert!((lo * hi / 0.01 - 1.0).abs() < 1e-12);
        let (lo, hi) = wald_interval(
            0.99,
            0.05,
            1.96,
            Some(ParamDomain::UnitInterval),
            IntervalScale::Transformed,
        );
        assert!(lo > -1.0 && hi < 1.0 && lo < 0.99 && hi > 0.99);
        // small SE: the transformed interval approaches the natural one
        let (lo, hi) = wald_interval(
            2.0,
            1e-6,
            1.96,
            Some(ParamDomain::Rate),
            IntervalScale::Transformed,
        );
        assert!((lo - (2.0 - 1.96e-6)).abs() < 1e-11 && (hi - (2.0 + 1.96e-6)).abs() < 1e-11);
    }
}
