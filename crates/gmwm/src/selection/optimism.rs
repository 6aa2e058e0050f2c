//! The optimism of a candidate's apparent loss (docs/methods.md §8.1–§8.3): how much lower its GMWM
//! objective is on the data it was fitted to than it would be on new data.
//!
//! # Asymptotic optimism (§8.2)
//! At the candidate's `theta_hat`, with `A` its J x p Jacobian (§4.5), `B = A' Omega A` and
//! `D_kl = sum_j (d^2 nu2_j / d theta_k d theta_l) [Omega (nu2(theta_hat) - nu2_hat)]_j` (§4.6):
//!
//! ```text
//! corrected (default):  dTheta = (B + D)^+ A' Omega,  optimism = 2 tr(Omega A dTheta V)
//! package:              dTheta = -((D - B)'(D - B))^+ (D - B)' A' Omega,
//!                       optimism = 2 tr(A dTheta Omega V)
//! ```
//!
//! The corrected form differentiates the first-order condition `A' Omega (nu2(theta) -
//! nu2_hat) = 0`, which gives `B + D` (the package uses `B - D`, §13.15), and takes
//! `tr(Cov(nu2_hat, Omega nu2(theta_hat))) = tr(Omega A dTheta V)`; the package's trace order
//! agrees only when Omega and V commute (e.g. V diagonal). With D = 0 and V = Omega^{-1} the
//! optimism is 2p (the AIC identity).
//!
//! Numerics (port): the optimism is invariant under a rescaling of the parameters, so the
//! matrix `M` to invert (`B + D` or `D - B`) is scaled symmetrically to a unit diagonal
//! (`S M S`, `A -> A S`) before the pseudo-inverse. IMU parameters span twenty decades (phi ~ 1
//! beside sigma2 ~ 1e-10), and a term fitted to nothing (a drift with omega ~ 0 has a zero
//! Jacobian column but a non-zero `D` entry) would otherwise dominate `M`; unscaled, a
//! pseudo-inverse with a relative cut-off would drop every other direction. The package's
//! `((D - B)'(D - B))^+ (D - B)'` is evaluated as the identical `(D - B)^+`, which does not
//! square the condition number.
//!
//! # Bootstrap optimism (§8.3)
//! `optimism = 2 tr(C Omega)` with `C = Cov(nu2_hat*, nu2(theta*))` over replicates simulated
//! from the candidate's estimate and refitted ([`bootstrap_optimism`]).

use crate::fit::FitError;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// How the optimism is estimated (docs/methods.md §8.2, §8.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum OptimismMethod {
    /// Closed form at theta_hat with the full model's V, exact or simulated (§8.2); the package default.
    #[default]
    Asymptotic,
    /// Per candidate, a parametric bootstrap from its estimate (§8.3); about K times slower
    /// for K candidates.
    Bootstrap,
}

crate::names::named_values!(OptimismMethod, "optimism", {
    Asymptotic => "asymptotic",
    Bootstrap => "bootstrap",
}, derive(FromStr, Display));

/// Which asymptotic formula (docs/methods.md §8.2, §13.15).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum OptimismConvention {
    /// `(B + D)^+ A' Omega` and `tr(Omega A dTheta V)`: the derivative of the first-order
    /// condition and the covariance trace in the right order.
    #[default]
    Corrected,
    /// The package's `-((D - B)'(D - B))^+ (D - B)' A' Omega` and `tr(A dTheta Omega V)`.
    Package,
}

crate::names::named_values!(OptimismConvention, "convention", {
    Corrected => "corrected",
    Package => "package",
}, derive(FromStr, Display));

/// docs/methods.md §8.2, §4.6: `D_kl = sum_j H_jkl [Omega (nu2(theta_hat) - nu2_hat)]_j`, from the
/// model Hessian `hessian[level][k][l]` ([`Model::hessian`](crate::model::Model::hessian)), the
/// weighting matrix, the implied and the empirical WV.
///
/// # Errors
/// [`FitError::Length`] when the sizes disagree.
pub(crate) fn d_matrix(
    hessian: &[Vec<Vec<f64>>],
    omega: &DMatrix<f64>,
    implied: &[f64],
    nu_hat: &[f64],
) -> Result<DMatrix<f64>, FitError> {
    let j = nu_hat.len();
    check_len("implied WV", j, implied.len())?;
    check_len("Hessian levels", j, hessian.len())?;
    check_len("Omega rows", j, omega.nrows())?;
    check_len("Omega columns", j, omega.ncols())?;
    let p = hessian.first().map_or(0, Vec::len);
    let diff = DVector::from_iterator(j, implied.iter().zip(nu_hat).map(|(a, b)| a - b));
    let w = omega * diff;
    let mut d = DMatrix::zeros(p, p);
    for (level, h) in hessian.iter().enumerate() {
        check_len("Hessian rows", p, h.len())?;
        for (k, row) in h.iter().enumerate() {
            check_len("Hessian columns", p, row.len())?;
            for (l, &x) in row.iter().enumerate() {
                d[(k, l)] += x * w[level];
            }
        }
    }
    Ok(d)
}

/// docs/methods.md §8.2: the asymptotic optimism from the Jacobian `a` (J x p), `d` (`d_matrix`,
/// p x p), the weighting matrix `omega` and the covariance `v` of the WV (both J x J).
///
/// # Errors
/// [`FitError::Length`] when the sizes disagree.
///
/// # Examples
/// Worked example: the test `tests::examples::example_optimism_asymptotic_optimism`.
pub(crate) fn asymptotic_optimism(
    a: &DMatrix<f64>,
    d: &DMatrix<f64>,
    omega: &DMatrix<f64>,
    v: &DMatrix<f64>,
    convention: OptimismConvention,
) -> Result<f64, FitError> {
    let (j, p) = a.shape();
    check_len("D rows", p, d.nrows())?;
    check_len("D columns", p, d.ncols())?;
    check_len("Omega rows", j, omega.nrows())?;
    check_len("Omega columns", j, omega.ncols())?;
    check_len("V rows", j, v.nrows())?;
    check_len("V columns", j, v.ncols())?;
    // a parameter whose derivatives are not finite sits on the edge of its domain (a GM whose
    // phi underflowed, a variance at zero): it has no local influence to be optimistic about
    // and is left out, as inference leaves it out of the sandwich
    let keep: Vec<usize> = (0..p)
        .filter(|&k| {
            a.column(k).iter().all(|x| x.is_finite())
                && d.row(k).iter().all(|x| x.is_finite())
                && d.column(k).iter().all(|x| x.is_finite())
        })
        .collect();
    if keep.len() < p {
        if keep.is_empty() {
            return Ok(0.0);
        }
        let a = a.select_columns(&keep);
        let d = d.select_rows(&keep).select_columns(&keep);
        return asymptotic_optimism(&a, &d, omega, v, convention);
    }
    let at_omega = a.transpose() * omega;
    let b = &at_omega * a;
    // M is the matrix to pseudo-invert: B + D (corrected) or D - B (package)
    let m = match convention {
        OptimismConvention::Corrected => &b + d,
        OptimismConvention::Package => d - &b,
    };
    // symmetric scaling S with |(S M S)_kk| = 1 (see the module docs); dTheta -> S^{-1} dTheta
    let s = DVector::from_iterator(
        p,
        (0..p).map(|k| {
            let n = m[(k, k)].abs().sqrt();
            if n.is_finite() && n > 0.0 {
                1.0 / n
            } else {
                1.0
            }
        }),
    );
    let s = DMatrix::from_diagonal(&s);
    // dTheta_s = (S M S)^+ S A' Omega, A dTheta = (A S) dTheta_s; the package's
    // ((D - B)'(D - B))^+ (D - B)' is exactly (D - B)^+ (a Moore-Penrose identity), evaluated
    // so because the former squares the condition number
    let a_s = a * &s;
    let dtheta_s = pinv(&(&s * m * &s)) * a_s.transpose() * omega;
    let opt = match convention {
        OptimismConvention::Corrected => 2.0 * (omega * &a_s * dtheta_s * v).trace(),
        OptimismConvention::Package => -2.0 * (&a_s * dtheta_s * omega * v).trace(),
    };
    Ok(opt)
}

/// docs/methods.md §8.3: `2 tr(C Omega)` with `C` the cross-covariance (divisor H - 1) of the
/// replicate WVs `nu_hat_star[r]` and the implied WVs of the refitted estimates
/// `nu_theta_star[r]`.
///
/// # Errors
/// [`FitError::Length`] for fewer than 2 replicates or vectors of different lengths.
pub(crate) fn bootstrap_optimism(
    nu_hat_star: &[Vec<f64>],
    nu_theta_star: &[Vec<f64>],
    omega: &DMatrix<f64>,
) -> Result<f64, FitError> {
    let h = nu_hat_star.len();
    check_len("refitted replicates", h, nu_theta_star.len())?;
    if h < 2 {
        return Err(FitError::Length {
            what: "bootstrap replicates",
            expected: 2,
            found: h,
        });
    }
    let j = omega.nrows();
    check_len("Omega columns", j, omega.ncols())?;
    for (x, y) in nu_hat_star.iter().zip(nu_theta_star) {
        check_len("replicate WV", j, x.len())?;
        check_len("replicate implied WV", j, y.len())?;
    }
    let mean = |s: &[Vec<f64>]| {
        let mut m = DVector::zeros(j);
        for x in s {
            m += DVector::from_column_slice(x);
        }
        m / h as f64
    };
    let (mx, my) = (mean(nu_hat_star), mean(nu_theta_star));
    let mut c = DMatrix::zeros(j, j);
    for (x, y) in nu_hat_star.iter().zip(nu_theta_star) {
        let dx = DVector::from_column_slice(x) - &mx;
        let dy = DVector::from_column_slice(y) - &my;
        c.ger(1.0, &dx, &dy, 1.0);
    }
    c /= (h - 1) as f64;
    Ok(2.0 * (c * omega).trace())
}

/// Moore–Penrose pseudo-inverse by SVD, singular values below `max(m, n) eps sigma_max`
/// treated as zero (the LAPACK/Armadillo default cut-off).
pub(crate) fn pinv(m: &DMatrix<f64>) -> DMatrix<f64> {
    let (r, c) = m.shape();
    if r == 0 || c == 0 {
        return DMatrix::zeros(c, r);
    }
    if m.iter().any(|v| !v.is_finite()) {
        // an SVD of a matrix holding NaN or infinity panics or never converges: no inverse
        return DMatrix::from_element(c, r, f64::NAN);
    }
    let svd = m.clone().svd(true, true);
    let smax = svd.singular_values.iter().copied().fold(0.0, f64::max);
    let tol = r.max(c) as f64 * f64::EPSILON * smax;
    // cannot fail: both U and V were computed and the tolerance is non-negative
    svd.pseudo_inverse(tol.max(0.0))
        .unwrap_or_else(|_| DMatrix::from_element(c, r, f64::NAN))
}

fn check_len(what: &'static str, expected: usize, found: usize) -> Result<(), FitError> {
    if expected == found {
        Ok(())
    } else {
        Err(FitError::Length {
            what,
            expected,
            found,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pinv_inverts_a_regular_matrix_and_handles_a_singular_one() {
        let m = DMatrix::from_row_slice(2, 2, &[2.0, 1.0, 1.0, 3.0]);
        let e = (&m * pinv(&m) - DMatrix::identity(2, 2)).norm();
        assert!(e < 1e-14, "{e}");
        let s = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0]);
        // pinv of the all-ones 2x2 is itself / 4
        assert!((pinv(&s) - &s / 4.0).norm() < 1e-14);
    }

    /// Issue 11 review: a Jacobian or D with NaN/inf (a parameter on the edge of its domain)
    /// made the SVD panic or never return; pinv gives NaN, the optimism leaves the parameter out.
    #[test]
    fn issue_11_optimism_survives_non_finite_derivatives() {
        let nan = DMatrix::from_row_slice(2, 2, &[1.0, f64::NAN, 0.0, 1.0]);
        assert!(pinv(&nan).iter().all(|v| v.is_nan()));
        let inf = DMatrix::from_row_slice(2, 2, &[f64::INFINITY, 0.0, 0.0, 1.0]);
        assert!(pinv(&inf).iter().all(|v| v.is_nan()));
        let a = DMatrix::from_row_slice(3, 2, &[1.0, f64::NAN, 0.5, f64::NAN, 0.25, f64::NAN]);
        let d = DMatrix::zeros(2, 2);
        let omega = DMatrix::identity(3, 3);
        let v = DMatrix::identity(3, 3) * 0.1;
        let with = asymptotic_optimism(&a, &d, &omega, &v, OptimismConvention::Corrected).unwrap();
        let alone = asymptotic_optimism(
            &a.columns(0, 1).into_owned(),
            &DMatrix::zeros(1, 1),
            &omega,
            &v,
            OptimismConvention::Corrected,
        )
        .unwrap();
        assert!(
            with.is_finite() && (with - alone).abs() < 1e-15,
            "{with} {alone}"
        );
    }

    #[test]
    fn bootstrap_optimism_of_known_samples() {
        // x = (1, 2, 3), y = 2x at one level: Cov = 2 Var(x) = 2, Omega = 3 -> 2 * 2 * 3 = 12
        let x = vec![vec![1.0], vec![2.0], vec![3.0]];
        let y = vec![vec![2.0], vec![4.0], vec![6.0]];
        let o = bootstrap_optimism(&x, &y, &DMatrix::from_element(1, 1, 3.0)).unwrap();
        assert!((o - 12.0).abs() < 1e-12, "{o}");
        assert!(bootstrap_optimism(&x[..1], &y[..1], &DMatrix::identity(1, 1)).is_err());
    }
}
