//! Robust wavelet variance: Tukey-biweight M-estimator of scale (docs/methods.md §2).
//!
//! Per level, the robust WV is the `s^2` solving the "Huber Proposal 2" scale equation
//! `(1/n) sum_i psi_c(y_i / s)^2 = a(c)` built on Tukey's biweight `psi_c` (§2.1), with the
//! tuning constant `c` chosen for a requested Gaussian efficiency (§2.3).
//!
//! Two conventions ([`RobustConvention`]):
//! - [`RobustConvention::Exact`] (default): the correct efficiency formula, `c` by a root
//!   finder, and the scale equation solved from a robust (MAD) start by a fixed-point iteration
//!   with a bracketing root-finder fallback (§2.4 "Port").
//! - [`RobustConvention::Package`]: the R package's constant (with its `mu_18` sign slip,
//!   §13.5) found by Brent minimisation, and its squared-equation solver on `[0, 2] x var(y)`
//!   (§2.4 steps 1–3, §13.6), which can stop at a local minimum.
//!
//! Callers compute `c` once per call ([`tuning_constant`]) and pass it to [`robust_scale`] for
//! every level.

use crate::error::{InputError, ParamError, SeriesError};
use crate::math::brent::{find_root, minimize, OPTIMIZE_TOL};
use crate::math::elementary;
use crate::math::sum::NeumaierSum;
use serde::{Deserialize, Serialize};
use std::str::FromStr;

/// Which tuning constant and solver to use (docs/methods.md §2.3–§2.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RobustConvention {
    /// Correct efficiency formula and a root-finder from a robust start (default).
    #[default]
    Exact,
    /// The R package's constant (with its §13.5 sign slip) and its Brent solver on [0, 2].
    Package,
}

// `exact` or `package` (docs/methods.md §2.3–§2.4), the spelling `FromStr` accepts
crate::names::named_values!(RobustConvention, "robust-convention", {
    Exact => "exact",
    Package => "package",
}, derive(Display));

impl FromStr for RobustConvention {
    type Err = ParamError;

    /// Parses `exact` or `package`, case-insensitively (docs/methods.md §2.3–§2.4).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s.eq_ignore_ascii_case("exact") {
            Ok(RobustConvention::Exact)
        } else if s.eq_ignore_ascii_case("package") {
            Ok(RobustConvention::Package)
        } else {
            Err(ParamError::new(
                "robust-convention",
                format!("{s:?}"),
                "one of \"exact\" (correct formulas, default) or \"package\" (R package compatible)",
            ))
        }
    }
}

/// Default requested Gaussian efficiency, the package's `eff = 0.6` (docs/methods.md §2.3; paper
/// Sec. III: near 0.5 is highly robust).
pub(crate) const DEFAULT_EFF: f64 = 0.6;

/// Largest efficiency accepted; the package refuses `eff > 0.99` for robust estimation
/// (docs/methods.md §2.5 R-level guard): the tuning constant grows without bound as eff -> 1 and
/// the estimator stops being robust.
pub(crate) const MAX_EFF: f64 = 0.99;

/// Options of the robust estimator (docs/methods.md §2), with their tuning constant solved once
/// (§2.3). Made by [`RobustOptions::new`] (or read from JSON, a saved WV or a calibration, and
/// checked the same way): a value that exists is valid.
///
/// Wire format: `eff`, `convention`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RobustOptionsDoc")]
pub struct RobustOptions {
    /// Requested Gaussian efficiency in (0, 0.99] (docs/methods.md §2.3).
    eff: f64,
    /// Convention (docs/methods.md §2.3–§2.4).
    convention: RobustConvention,
    /// The tuning constant `c` of `eff` under `convention` (§2.3).
    #[serde(skip)]
    c: f64,
}

/// [`RobustOptions`] as JSON holds them, before the check.
#[derive(Deserialize)]
struct RobustOptionsDoc {
    eff: f64,
    convention: RobustConvention,
}

impl TryFrom<RobustOptionsDoc> for RobustOptions {
    type Error = ParamError;

    fn try_from(doc: RobustOptionsDoc) -> Result<Self, ParamError> {
        Self::new(doc.eff, doc.convention)
    }
}

impl Default for RobustOptions {
    /// `eff = 0.6` (the package default, docs/methods.md §2.3) with the [`RobustConvention::Exact`]
    /// convention (correct formulas, docs/methods.md §2.4 "Port").
    fn default() -> Self {
        Self::new(DEFAULT_EFF, RobustConvention::Exact).expect("the default efficiency is valid")
    }
}

impl RobustOptions {
    /// Validated constructor (docs/methods.md §2.3, §2.5).
    ///
    /// # Errors
    /// [`ParamError`] (name `eff`) unless `eff` is finite and in `(0, 0.99]`; values above 0.99
    /// are refused as the package does (§2.5).
    pub fn new(eff: f64, convention: RobustConvention) -> Result<Self, ParamError> {
        let c = tuning_constant(eff, convention)?;
        Ok(Self { eff, convention, c })
    }

    /// The requested Gaussian efficiency (docs/methods.md §2.3).
    pub fn eff(&self) -> f64 {
        self.eff
    }

    /// The convention (docs/methods.md §2.3–§2.4).
    pub fn convention(&self) -> RobustConvention {
        self.convention
    }

    /// The tuning constant `c` of these options (docs/methods.md §2.3, `tuning_constant`),
    /// solved once when the options were made.
    pub(crate) fn tuning_constant(&self) -> f64 {
        self.c
    }
}

fn check_eff(eff: f64) -> Result<(), ParamError> {
    if !eff.is_finite() {
        return Err(ParamError::new(
            "eff",
            eff,
            "a finite Gaussian efficiency in (0, 0.99]",
        ));
    }
    if eff <= 0.0 {
        return Err(ParamError::new(
            "eff",
            eff,
            "a Gaussian efficiency in (0, 0.99]; it must be positive",
        ));
    }
    if eff > MAX_EFF {
        return Err(ParamError::new(
            "eff",
            eff,
            "at most 0.99: the tuning constant diverges as eff -> 1, leaving no robustness \
             (the package refuses eff > 0.99 too); use the classical estimator instead",
        ));
    }
    Ok(())
}

fn check_c(c: f64) -> Result<(), ParamError> {
    if c.is_finite() && c > 0.0 {
        Ok(())
    } else {
        Err(ParamError::new(
            "c",
            c,
            "a finite positive biweight tuning constant (see tuning_constant)",
        ))
    }
}

/// `1 / sqrt(2 pi)`, the standard normal density at 0.
const INV_SQRT_2PI: f64 = 0.398_942_280_401_432_7;

/// Truncated standard normal moments `mu_0, mu_2, ..., mu_20` at `c` (docs/methods.md §2.2).
///
/// # Formula
/// `mu_{2k}(c) = E[Z^{2k} 1{|Z| <= c}]`, `Z ~ N(0, 1)`, by the recursion
/// `mu_0 = 2 Phi(c) - 1`, `mu_{2k} = (2k - 1) mu_{2k-2} - 2 c^{2k-1} phi(c)`. Element `k` of
/// the result is `mu_{2k}`.
///
/// The recursion cancels badly for small `c` (below about 1.5 the higher moments lose all
/// digits); the tuning constants of §2.3 are above 2.39, where it is accurate to a few ulps
/// relative. For non-finite or non-positive `c` the result is NaN/garbage: callers validate.
pub(crate) fn truncated_normal_moments(c: f64) -> [f64; 11] {
    let mut mu = [0.0; 11];
    let two_phi = 2.0 * INV_SQRT_2PI * elementary::exp(-0.5 * c * c);
    mu[0] = central_normal_mass(c, two_phi);
    let mut c_pow = c; // c^{2k-1}
    for k in 1..11 {
        mu[k] = (2 * k - 1) as f64 * mu[k - 1] - c_pow * two_phi;
        c_pow *= c * c;
    }
    mu
}

/// Beyond this `c`, `P(|Z| > c) < 2e-17` is below half an ulp of 1 (docs/methods.md §2.2).
const CENTRAL_MASS_ONE: f64 = 8.5;

/// `P(|Z| <= c) = 2 Phi(c) - 1` for `c >= 0`, given `two_phi = 2 phi(c)` (docs/methods.md §2.2).
///
/// Series `2 phi(c) sum_{n >= 0} c^{2n+1} / (2n+1)!!` (all terms positive, so no
/// cancellation; relative error a few ulps). Used instead of `statrs`' erf, whose error near
/// `c ~ 1..2` is ~3e-11 and which the `(2k-1)!!` growth of the recursion would amplify.
fn central_normal_mass(c: f64, two_phi: f64) -> f64 {
    if c.is_nan() {
        return f64::NAN;
    }
    let x = c.abs();
    if x > CENTRAL_MASS_ONE {
        return 1.0;
    }
    let x2 = x * x;
    let mut term = x;
    let mut total = x;
    let mut n = 0.0;
    while term > f64::EPSILON * 0.25 * total {
        n += 1.0;
        term *= x2 / (2.0 * n + 1.0);
        total += term;
    }
    (two_phi * total).min(1.0)
}

/// `sum_i coef[i] mu[first + i] / c^{2i}`: a binomial expansion in `z^2 / c^2` (docs/methods.md
/// §2.2–2.3).
fn expand(mu: &[f64; 11], first: usize, coef: &[f64], c: f64) -> f64 {
    let inv_c2 = 1.0 / (c * c);
    let mut scale = 1.0;
    let mut total = 0.0;
    for (i, &b) in coef.iter().enumerate() {
        total += b * mu[first + i] * scale;
        scale *= inv_c2;
    }
    total
}

/// Binomial coefficients of `(1 - x)^4` (docs/methods.md §2.2).
const BINOM4: [f64; 5] = [1.0, -4.0, 6.0, -4.0, 1.0];
/// Binomial coefficients of `(1 - x)^8` (docs/methods.md §2.3).
const BINOM8: [f64; 9] = [1.0, -8.0, 28.0, -56.0, 70.0, -56.0, 28.0, -8.0, 1.0];
/// The package's `(1 - x)^8` with the sign slip on the `mu_18` term (docs/methods.md §2.3, §13.5).
const BINOM8_PACKAGE: [f64; 9] = [1.0, -8.0, 28.0, -56.0, 70.0, -56.0, 28.0, 8.0, 1.0];

/// `a(c) = E[psi_c(Z)^2]`, the Gaussian consistency constant of the biweight scale equation
/// (docs/methods.md §2.2).
///
/// # Formula
/// `a(c) = mu_2 - 4 mu_4 / c^2 + 6 mu_6 / c^4 - 4 mu_8 / c^6 + mu_10 / c^8`
/// with `mu_{2k}` from `truncated_normal_moments`.
///
/// # Examples
/// Worked example: the test `tests::examples::example_robust_a_of_c`.
pub(crate) fn a_of_c(c: f64) -> f64 {
    let mu = truncated_normal_moments(c);
    expand(&mu, 1, &BINOM4, c)
}

/// `M(c)` and `Q(c)` of docs/methods.md §2.3, with the given `(1 - x)^8` coefficients.
fn m_and_q(c: f64, binom8: &[f64; 9]) -> (f64, f64) {
    let mu = truncated_normal_moments(c);
    let a = expand(&mu, 1, &BINOM4, c);
    let m = expand(&mu, 2, &BINOM4, c) - a;
    let q = expand(&mu, 2, binom8, c) - a * a;
    (m, q)
}

/// Gaussian efficiency of the biweight scale estimate with tuning constant `c`, relative to the
/// MLE of the variance (docs/methods.md §2.3, correct formula).
///
/// # Formula
/// `M(c) = mu_4 - 4 mu_6/c^2 + 6 mu_8/c^4 - 4 mu_10/c^6 + mu_12/c^8 - a(c)`,
/// `Q(c) = sum_{i=0}^{8} (-1)^i binom(8, i) mu_{4+2i} / c^{2i} - a(c)^2`,
/// `eff(c) = M(c)^2 / (2 Q(c))`.
///
/// `eff` is increasing in `c` from 0 at `c ~ 2.39498` (where `M` vanishes) to 1 as `c -> inf`;
/// below that point the formula rises again (spurious branch with `M < 0`).
pub(crate) fn efficiency(c: f64) -> f64 {
    let (m, q) = m_and_q(c, &BINOM8);
    m * m / (2.0 * q)
}

/// The package's efficiency formula: [`efficiency`] with the `mu_18` term of `Q` carrying
/// `+8/c^14` instead of `-8/c^14` (docs/methods.md §2.3, §13.5).
///
/// # Formula
/// As [`efficiency`] with `Q` coefficients `1, -8, 28, -56, 70, -56, 28, +8, 1`.
pub(crate) fn package_efficiency(c: f64) -> f64 {
    let (m, q) = m_and_q(c, &BINOM8_PACKAGE);
    m * m / (2.0 * q)
}

/// Absolute tolerance on the correct tuning constant: ~10 ulps at c ~ 5, far below the 1e-6
/// of the docs/methods.md §2.3 table.
const C_ROOT_TOL: f64 = 1e-14;
/// Bracket for the zero of `M(c)` (docs/methods.md §2.3), which lies at c ~ 2.39498: `M(2) < 0 <
/// M(3)`.
const M_ZERO_BRACKET: (f64, f64) = (2.0, 3.0);
/// Upper end of the tuning-constant search, as the package's `[0, 100]` (docs/methods.md §2.3):
/// `eff(100) = 0.999998 > 0.99`.
const C_MAX: f64 = 100.0;

/// Tuning constant `c` for the requested Gaussian efficiency (docs/methods.md §2.3).
///
/// - [`RobustConvention::Exact`]: solves `efficiency(c) = eff` by Brent–Dekker root finding
///   (to about 1e-14) on `[c_0, 100]`, where `c_0 ~ 2.39498` is the zero of `M(c)`; efficiency
///   increases from 0 to 1 on that bracket. eff 0.6 gives c = 4.400278.
/// - [`RobustConvention::Package`]: minimises `(package_efficiency(c) - eff)^2` over
///   `[0, 100]` with Brent's minimiser at R's `optimize` tolerance `eps^0.25`, as the package
///   does; eff 0.6 gives c ~ 4.9734 (true efficiency ~0.727).
///
/// Cost: a few hundred evaluations of closed forms (microseconds); compute it once per call.
///
/// # Errors
/// [`ParamError`] (name `eff`) unless `eff` is finite and in `(0, 0.99]`.
///
/// # Examples
/// Worked example: the test `tests::examples::example_robust_tuning_constant`.
pub(crate) fn tuning_constant(eff: f64, convention: RobustConvention) -> Result<f64, ParamError> {
    check_eff(eff)?;
    match convention {
        RobustConvention::Exact => {
            let m_of_c = |c: f64| m_and_q(c, &BINOM8).0;
            let c0 = find_root(m_of_c, M_ZERO_BRACKET.0, M_ZERO_BRACKET.1, C_ROOT_TOL)?.x;
            Ok(find_root(|c| efficiency(c) - eff, c0, C_MAX, C_ROOT_TOL)?.x)
        }
        RobustConvention::Package => {
            let objective = |c: f64| {
                let d = package_efficiency(c) - eff;
                d * d
            };
            Ok(minimize(objective, 0.0, C_MAX, OPTIMIZE_TOL)?.x)
        }
    }
}

/// Tukey's biweight `psi_c(r) = r (1 - r^2/c^2)^2` for `|r| <= c`, 0 otherwise (docs/methods.md
/// §2.1).
#[cfg(test)]
pub(crate) fn psi_biweight(r: f64, c: f64) -> f64 {
    if r.abs() <= c {
        let t = 1.0 - (r / c) * (r / c);
        r * t * t
    } else {
        0.0
    }
}

/// Terms summed naively per block before entering the compensated total: keeps the rounding
/// error of a 1e7-term mean near 1e-15 relative at a fraction of Neumaier's cost per term.
const BLOCK: usize = 256;

/// `(1/n) sum_i psi_c(y_i * inv_s)^2` (docs/methods.md §2.1), one O(n) pass, no allocation.
fn mean_psi2(y: &[f64], inv_s: f64, c: f64) -> f64 {
    let inv_c2 = 1.0 / (c * c);
    let c2 = c * c;
    let mut total = NeumaierSum::default();
    for block in y.chunks(BLOCK) {
        let mut s = 0.0;
        for &yi in block {
            let r = yi * inv_s;
            let r2 = r * r;
            if r2 <= c2 {
                let t = 1.0 - r2 * inv_c2;
                let t2 = t * t;
                s += r2 * t2 * t2;
            }
        }
        total.add(s);
    }
    total.total() / y.len() as f64
}

/// Standard normal quantile at 0.75, `Phi^{-1}(3/4)`: MAD / this is consistent for the
/// standard deviation at the Gaussian (docs/methods.md §2.4 "Port").
pub(crate) const MAD_CONSISTENCY: f64 = 0.674_489_750_196_081_7;

/// Relative change of `s^2` between fixed-point iterates at which the port stops (docs/methods.md
/// §2.4: the test values were produced at 1e-12).
pub(crate) const FIXED_POINT_TOL: f64 = 1e-12;

/// Iteration cap of the fixed point; Gaussian-like levels converge in a few dozen steps, and
/// beyond the cap the bracketing fallback takes over (docs/methods.md §2.4).
pub(crate) const FIXED_POINT_MAX_ITER: usize = 500;

/// Robust variance `s^2` of zero-mean coefficients `y` (docs/methods.md §2.1, §2.4), for a tuning
/// constant `c` from [`tuning_constant`].
///
/// # Formula
/// `s > 0` solving `(1/n) sum_i psi_c(y_i / s)^2 = a(c)` (§2.1), returned as `s^2`.
///
/// - [`RobustConvention::Exact`] (§2.4 "Port"): start from `s0 = median|y| / 0.6744898` (MAD
///   about 0, no centring), iterate `s^2 <- s^2 mean(psi_c(y/s)^2) / a(c)` until the relative
///   change is below 1e-12; if the iteration stalls (no convergence in 500 steps, or all residuals fall outside `[-c, c]`), find the root of
///   `mean(psi_c(y/s)^2) - a(c)` in `s` by Brent–Dekker on the sign-changing bracket (from `+`
///   below to `-` above, the stable root) nearest `s0` on a geometric grid.
/// - [`RobustConvention::Package`] (§2.4 steps 1–3): `x = y / sd(y)`, minimise
///   `G(s2) = (mean(psi_c(x / sqrt(s2))^2) - a(c))^2` over `s2 in [0, 2]` with Brent's
///   minimiser (tolerance `eps^0.25`), return `s2* var(y)` (`sd`, `var` centred, divisor
///   `n - 1`). Capped at `2 var(y)` and may stop at a local minimum (§13.6).
///
/// Cost: O(n) per iteration; the only allocation is one copy of `|y|` for the median (Exact).
///
/// # Errors
/// - [`SeriesError::Empty`] for empty `y`; [`SeriesError::NonFinite`] for a NaN/infinite value;
/// - [`SeriesError::Constant`] if every value is 0 (Exact) or all are equal (Package);
/// - [`ParamError`] (name `coefficients`) if more than half the values are exactly 0 (Exact:
///   the MAD start, hence the robust scale, is undefined);
/// - [`SeriesError::TooShort`] for a single value in Package mode (needs `var(y)`);
/// - [`ParamError`] (name `c`) for a non-finite or non-positive `c`, or (name `robust scale`)
///   if the scale equation has no root (coefficients so dispersed that `mean(psi_c^2)` never
///   reaches `a(c)`).
///
/// # Examples
/// Worked example: the test `tests::examples::example_robust_robust_scale`.
pub(crate) fn robust_scale(
    y: &[f64],
    c: f64,
    convention: RobustConvention,
) -> Result<f64, InputError> {
    check_c(c)?;
    if y.is_empty() {
        return Err(SeriesError::Empty.into());
    }
    if let Some((index, &value)) = y.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(SeriesError::NonFinite { index, value }.into());
    }
    let a = a_of_c(c);
    if !(a.is_finite() && a > 0.0) {
        // only for c far below any tuning constant (c < ~1), where §2.2's recursion breaks down
        return Err(ParamError::new(
            "c",
            c,
            "a tuning constant with a(c) > 0; constants from tuning_constant are above 2.39",
        )
        .into());
    }
    match convention {
        RobustConvention::Exact => scale_exact(y, c, a),
        RobustConvention::Package => scale_package(y, c, a),
    }
}

/// Median of `|y|` on a one-time scratch copy (O(n) selection).
fn median_abs(y: &[f64]) -> f64 {
    let mut scratch: Vec<f64> = y.iter().map(|v| v.abs()).collect();
    let n = scratch.len();
    let mid = n / 2;
    let (lower, upper, _) = scratch.select_nth_unstable_by(mid, f64::total_cmp);
    let upper = *upper;
    if n % 2 == 1 {
        upper
    } else {
        // the largest of the lower half is the other middle order statistic
        let below = lower.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        0.5 * (below + upper)
    }
}

fn scale_exact(y: &[f64], c: f64, a: f64) -> Result<f64, InputError> {
    let mad = median_abs(y);
    // Quantised sensors give many exactly-zero coefficients at fine levels: with more than half
    // of them zero the MAD is 0 and only serves as no start; the root-mean-square then starts
    // the iteration instead (the estimating equation is unchanged). All zero: the scale is 0.
    let s0 = if mad > 0.0 {
        mad / MAD_CONSISTENCY
    } else {
        let rms = (y.iter().map(|v| v * v).sum::<f64>() / y.len() as f64).sqrt();
        if rms == 0.0 {
            return Ok(0.0);
        }
        rms
    };
    let mut s2 = s0 * s0;
    let mut next_polish = POLISH_FROM;
    for _ in 0..FIXED_POINT_MAX_ITER {
        let m = mean_psi2(y, 1.0 / s2.sqrt(), c);
        let next = s2 * m / a;
        if !(next.is_finite() && next > 0.0) {
            break;
        }
        let change = (next - s2).abs() / next;
        if change <= FIXED_POINT_TOL {
            return Ok(next);
        }
        if change <= next_polish {
            if let Some(root) = polish(y, c, a, next.sqrt(), change) {
                return Ok(root * root);
            }
            next_polish = change * 0.1;
        }
        s2 = next;
    }
    scale_exact_bracketed(y, c, a, s0)
}

/// Coefficient series at least this long take the windowed route of [`robust_scale_long`];
/// shorter ones the direct iteration (a few dozen passes over at most 32 Ki values).
pub(crate) const LONG_MIN: usize = 1 << 15;
/// Target size of the strided subsample that locates the root for [`robust_scale_long`]: its
/// root is within about 1% of the full one for Gaussian-like levels (sd of the eff-0.6 scale
/// estimate from 8 Ki values, ~0.9%), well inside [`WINDOW`].
pub(crate) const SUBSAMPLE: usize = 1 << 13;
/// Half-width factor of the search window in `s` around the subsample's root: `[s/W, s W]`.
const WINDOW: f64 = 1.1;
/// Windows tried (each one pass over the data) before the direct iteration takes over.
pub(crate) const WINDOW_SLIDES: usize = 3;
/// Largest `u = (y / (c s))^2` summed through power sums in [`PowerWindow`]: there
/// `|u - 4u^2 + 6u^3 - 4u^4 + u^5| / u (1 - u)^4`, the cancellation of the expanded biweight,
/// is at most 20, so `mean psi_c^2` keeps ~14 digits.
const U_POWER_MAX: f64 = 0.36;

/// Robust variance of a long coefficient series, [`RobustConvention::Exact`] (docs/methods.md §2.4
/// "Port"): the same root as [`robust_scale`] — the down-crossing of
/// `h(s) = mean(psi_c(y/s)^2) - a(c)` that the fixed point from the MAD start reaches — found in
/// about one pass over the data instead of dozens.
///
/// 1. The Exact solve of [`robust_scale`] (MAD start, fixed point, Brent–Dekker polish) on a
///    deterministic strided subsample of about 8 Ki values locates the root, `s_sub`.
/// 2. One pass over `y` builds a [`PowerWindow`] for `s` in `[s_sub / 1.1, s_sub 1.1]`: values
///    whose `u = (y / (c s))^2` stays below 0.36 on the whole window enter through five power sums
///    (`psi_c(r)^2 = c^2 u (1 - u)^4` is a polynomial of degree 5 in `u`), the few (~2% at the
///    Gaussian) that may cross `|r| = c` are kept; every `mean psi_c^2(s)` on the window then
///    costs O(kept).
/// 3. If `h` changes sign from `+` to `-` across the window, Brent–Dekker finds the root to
///    1e-14 relative in `s`; otherwise the window slides (a new pass) towards the root, at most
///    three times, and the direct iteration of [`robust_scale`] decides.
///
/// `y` of fewer than [`LONG_MIN`] values, a subsample without a root, and non-finite squares go
/// straight to [`robust_scale`]. Results agree with [`robust_scale`] to the solvers' tolerance
/// (~1e-13 relative; tested on real and contaminated data).
///
/// # Errors
/// As [`robust_scale`].
// The standalone route, kept as the reference the per-level passes of `haar_robust` follow and
// tested against the direct root.
#[cfg_attr(not(test), allow(dead_code))]
pub(crate) fn robust_scale_long(y: &[f64], c: f64) -> Result<f64, InputError> {
    check_c(c)?;
    let n = y.len();
    if n < LONG_MIN {
        return robust_scale(y, c, RobustConvention::Exact);
    }
    let a = a_of_c(c);
    if !(a.is_finite() && a > 0.0) {
        return robust_scale(y, c, RobustConvention::Exact);
    }
    let stride = n / SUBSAMPLE;
    let sub: Vec<f64> = y.iter().step_by(stride).copied().collect();
    let s_sub = match robust_scale(&sub, c, RobustConvention::Exact) {
        Ok(s2) if s2 > 0.0 && s2.is_finite() => s2.sqrt(),
        _ => return robust_scale(y, c, RobustConvention::Exact),
    };
    let (mut lo, mut hi) = window_around(s_sub);
    for _ in 0..WINDOW_SLIDES {
        let Some(window) = PowerWindow::new(y, c, lo, hi) else {
            break; // a non-finite square: let the direct route report or handle it
        };
        match window.solve(a, lo, hi)? {
            WindowOutcome::Root(s2) => return Ok(s2),
            WindowOutcome::Slide(l, h) => (lo, hi) = (l, h),
        }
    }
    robust_scale(y, c, RobustConvention::Exact)
}

/// The first search window of [`robust_scale_long`] around a located root `s`.
pub(crate) fn window_around(s: f64) -> (f64, f64) {
    (s / WINDOW, s * WINDOW)
}

/// Result of [`PowerWindow::solve`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum WindowOutcome {
    /// The robust variance `s^2`.
    Root(f64),
    /// No down-crossing on the window: the next window to try.
    Slide(f64, f64),
}

/// `mean(psi_c(y/s)^2)` for every `s` in a window `[s_lo, s_hi]`, from one pass over `y`
/// (docs/methods.md §2.1; see [`robust_scale_long`]).
///
/// With `u = y^2 k2`, `k2 = 1 / (c s)^2`: `psi_c(y/s)^2 = c^2 P(u) 1{u <= 1}`,
/// `P(u) = u (1 - u)^4 = u - 4u^2 + 6u^3 - 4u^4 + u^5`. Values with `y^2 < L`,
/// `L = 0.36 (c s_lo)^2`, have `u < 0.36` on the whole window: their share is
/// `sum_m coef_m (L k2)^m T_m` with `T_m = sum (y^2 / L)^m` (compensated sums). Values with
/// `y^2 > (c s_hi)^2` contribute 0 on the window. The rest are kept and evaluated one by one.
pub(crate) struct PowerWindow {
    c: f64,
    n: f64,
    below: f64,
    powers: [f64; 5],
    kept: Vec<f64>,
    sum_squares: f64,
}

/// The pass behind [`PowerWindow`], fed in pieces (e.g. by the blocks of a pyramid) and merged
/// in a fixed order (docs/methods.md §2.1; see [`robust_scale_long`]).
#[derive(Debug, Clone)]
pub(crate) struct PowerAccumulator {
    c: f64,
    n: usize,
    below: f64,
    inv_below: f64,
    above: f64,
    scale2: f64,
    totals: [NeumaierSum; 6],
    outside: usize,
    kept: Vec<f64>,
    probe: f64,
}

impl PowerAccumulator {
    /// An empty pass for the window `[s_lo, s_hi]` on values `y = scale2.sqrt() v` given as `v`
    /// (`scale2` multiplies the squares; a power of 4 keeps them exact).
    pub(crate) fn new(c: f64, s_lo: f64, s_hi: f64, scale2: f64) -> Self {
        let below = U_POWER_MAX * (c * s_lo) * (c * s_lo);
        Self {
            c,
            n: 0,
            below,
            inv_below: 1.0 / below,
            above: (c * s_hi) * (c * s_hi),
            scale2,
            totals: [NeumaierSum::default(); 6],
            outside: 0,
            kept: Vec::new(),
            probe: 0.0,
        }
    }

    /// Adds values (see [`new`](Self::new) for their scale).
    pub(crate) fn push(&mut self, v: &[f64]) {
        let (above, inv_below, scale2) = (self.above, self.inv_below, self.scale2);
        let mut scratch = [0.0f64; POWER_BLOCK];
        for block in v.chunks(POWER_BLOCK) {
            // p = min(q / L, 1): the values that may cross |r| = c get p = 1 and are counted
            // out again below (branch-free, vectorised sums)
            let p = &mut scratch[..block.len()];
            for (p, &vi) in p.iter_mut().zip(block) {
                *p = (vi * vi * scale2 * inv_below).min(1.0);
            }
            let p: &[f64] = p;
            let powers = power_sums(p);
            let sums = [
                powers[0],
                powers[1],
                powers[2],
                powers[3],
                powers[4],
                lane_sum(block, |v| v * v * scale2),
            ];
            // the values with p = 1 (`min` maps NaN to 1 too), found eight at a time
            let mut outside = 0usize;
            for (p8, v8) in p.chunks(8).zip(block.chunks(8)) {
                let top = p8.iter().fold(0.0f64, |m, &x| if x > m { x } else { m });
                if top < 1.0 {
                    continue;
                }
                for (&pi, &vi) in p8.iter().zip(v8) {
                    if pi >= 1.0 {
                        outside += 1;
                        let q = vi * vi * scale2;
                        if q <= above {
                            self.kept.push(q);
                        }
                    }
                }
            }
            for (t, s) in self.totals.iter_mut().zip(sums) {
                t.add(s);
            }
            self.outside += outside;
            // NaN iff some square is not finite
            self.probe += sums[5] * 0.0;
        }
        self.n += v.len();
    }

    /// Appends `other` (a later piece of the same series and window).
    pub(crate) fn merge(&mut self, other: &Self) {
        for (t, o) in self.totals.iter_mut().zip(&other.totals) {
            t.add(o.total());
        }
        self.kept.extend_from_slice(&other.kept);
        self.probe += other.probe;
        self.outside += other.outside;
        self.n += other.n;
    }

    /// The window, `None` if some square was not finite or nothing was pushed.
    pub(crate) fn finish(self) -> Option<PowerWindow> {
        let sum_squares = self.totals[5].total();
        if self.n == 0 || !self.probe.is_finite() || !sum_squares.is_finite() {
            return None;
        }
        // every value outside [0, L) entered each power sum as 1
        let mut powers = [0.0; 5];
        for (p, t) in powers.iter_mut().zip(&self.totals) {
            let mut t = *t;
            t.add(-(self.outside as f64));
            *p = t.total();
        }
        Some(PowerWindow {
            c: self.c,
            n: self.n as f64,
            below: self.below,
            powers,
            kept: self.kept,
            sum_squares,
        })
    }
}

/// Values per block of the [`PowerWindow`] pass before the lane sums enter the compensated
/// totals (16 KiB of scratch on the stack).
const POWER_BLOCK: usize = 2048;

/// `sum p^m` for `m = 1..=5` over `p`, in one pass with four lanes per power (vectorised).
#[inline(always)]
fn power_sums(p: &[f64]) -> [f64; 5] {
    let mut a1 = [0.0f64; 4];
    let mut a2 = [0.0f64; 4];
    let mut a3 = [0.0f64; 4];
    let mut a4 = [0.0f64; 4];
    let mut a5 = [0.0f64; 4];
    let mut c4 = p.chunks_exact(4);
    for x in &mut c4 {
        for k in 0..4 {
            let p1 = x[k];
            let p2 = p1 * p1;
            let p4 = p2 * p2;
            a1[k] += p1;
            a2[k] += p2;
            a3[k] += p2 * p1;
            a4[k] += p4;
            a5[k] += p4 * p1;
        }
    }
    for &p1 in c4.remainder() {
        let p2 = p1 * p1;
        let p4 = p2 * p2;
        a1[0] += p1;
        a2[0] += p2;
        a3[0] += p2 * p1;
        a4[0] += p4;
        a5[0] += p4 * p1;
    }
    let total = |a: [f64; 4]| (a[0] + a[2]) + (a[1] + a[3]);
    [total(a1), total(a2), total(a3), total(a4), total(a5)]
}

/// `sum f(v)` over `v` with eight lanes (vectorised; even and odd lanes are added apart, the
/// order of two-wide registers).
#[inline(always)]
fn lane_sum(v: &[f64], f: impl Fn(f64) -> f64) -> f64 {
    let mut acc = [0.0f64; 8];
    let mut c8 = v.chunks_exact(8);
    for x in &mut c8 {
        for k in 0..8 {
            acc[k] += f(x[k]);
        }
    }
    let mut tail = 0.0;
    for &x in c8.remainder() {
        tail += f(x);
    }
    let even = (acc[0] + acc[2]) + (acc[4] + acc[6]);
    let odd = (acc[1] + acc[3]) + (acc[5] + acc[7]);
    even + odd + tail
}

impl PowerWindow {
    /// One pass over `y` for the window `[s_lo, s_hi]` (`0 < s_lo < s_hi`); `None` if some
    /// `y^2` is not finite.
    #[cfg_attr(not(test), allow(dead_code))]
    pub(crate) fn new(y: &[f64], c: f64, s_lo: f64, s_hi: f64) -> Option<Self> {
        let mut acc = PowerAccumulator::new(c, s_lo, s_hi, 1.0);
        acc.push(y);
        acc.finish()
    }

    /// `mean(psi_c(y/s)^2)` at `s` in the window (docs/methods.md §2.1).
    pub(crate) fn mean_psi2(&self, s: f64) -> f64 {
        let k2 = 1.0 / ((self.c * s) * (self.c * s));
        let kappa = self.below * k2;
        let mut below = 0.0;
        let mut kappa_m = 1.0;
        for (coef, t) in [1.0, -4.0, 6.0, -4.0, 1.0].iter().zip(&self.powers) {
            kappa_m *= kappa;
            below += coef * kappa_m * t;
        }
        let mut acc = [0.0f64; 4];
        let mut quads = self.kept.chunks_exact(4);
        for q in &mut quads {
            for k in 0..4 {
                let u = q[k] * k2;
                let t = 1.0 - u;
                let t2 = t * t;
                acc[k] += if u <= 1.0 { u * t2 * t2 } else { 0.0 };
            }
        }
        let mut tail = 0.0;
        for &q in quads.remainder() {
            let u = q * k2;
            if u <= 1.0 {
                let t = 1.0 - u;
                tail += u * (t * t) * (t * t);
            }
        }
        let kept = (acc[0] + acc[2]) + (acc[1] + acc[3]) + tail;
        self.c * self.c * (below + kept) / self.n
    }

    /// The down-crossing of `h(s) = mean(psi_c(y/s)^2) - a` on the window `[lo, hi]` by
    /// Brent–Dekker to 1e-14 relative in `s` (docs/methods.md §2.4), or, when `h` does not go from
    /// `+` to `-` across it, the next window towards the root in the direction the fixed point
    /// moves (down where `h(lo) <= 0`, up otherwise), twice as wide.
    pub(crate) fn solve(&self, a: f64, lo: f64, hi: f64) -> Result<WindowOutcome, InputError> {
        let h = |s: f64| self.mean_psi2(s) - a;
        let (h_lo, h_hi) = (h(lo), h(hi));
        if h_lo > 0.0 && h_hi <= 0.0 {
            let root = find_root(h, lo, hi, (S_ROOT_RTOL * lo).max(f64::MIN_POSITIVE))?;
            return Ok(WindowOutcome::Root(root.x * root.x));
        }
        Ok(if h_lo <= 0.0 {
            WindowOutcome::Slide(lo / (WINDOW * WINDOW), lo)
        } else {
            WindowOutcome::Slide(hi, hi * WINDOW * WINDOW)
        })
    }

    /// Mean of `y^2` over the whole pass (the classical WV of the level, docs/methods.md §1.5).
    pub(crate) fn mean_square(&self) -> f64 {
        self.sum_squares / self.n
    }
}

/// Relative change of the fixed point below which a local bracket is tried (docs/methods.md §2.4):
/// the iteration contracts linearly (rate ~0.5 at the Gaussian, closer to 1 with outliers), a
/// Brent–Dekker polish from here costs ~8 passes instead of ~25–400.
const POLISH_FROM: f64 = 1e-4;
/// Bracket widenings tried by [`polish`], each by a factor 4 (covers contraction rates up to
/// ~1 - 1/256).
const POLISH_WIDENINGS: usize = 4;

/// Root of `h(s) = mean(psi_c(y/s)^2) - a(c)` on a small bracket around the fixed-point iterate
/// `s` (docs/methods.md §2.4): the stable root the iteration converges to is a down-crossing of `h`
/// (`h > 0` below, `h <= 0` above). `None` if no such bracket within the widenings, in which case
/// the caller keeps iterating.
fn polish(y: &[f64], c: f64, a: f64, s: f64, change: f64) -> Option<f64> {
    let h = |s: f64| mean_psi2(y, 1.0 / s, c) - a;
    let mut delta = 4.0 * change;
    for _ in 0..POLISH_WIDENINGS {
        let (lo, hi) = (s * (1.0 - delta), s * (1.0 + delta));
        if lo > 0.0 && h(lo) > 0.0 && h(hi) <= 0.0 {
            return find_root(h, lo, hi, (S_ROOT_RTOL * lo).max(f64::MIN_POSITIVE))
                .ok()
                .map(|r| r.x);
        }
        delta *= 4.0;
    }
    None
}

/// Grid ratio of the bracket search in `s` (docs/methods.md §2.4 fallback): `2^(1/4)`, fine enough
/// not to step over the stable root of a Gaussian-like level.
const GRID_RATIO: f64 = 1.189_207_115_002_721;
/// Grid points searched on each side of `s0`: `2^(±60)` covers any sensible scale.
const GRID_STEPS: i32 = 240;
/// Relative tolerance on `s` for the fallback root finder (squared: ~2e-14 on `s^2`).
const S_ROOT_RTOL: f64 = 1e-14;

/// Fallback of docs/methods.md §2.4: Brent–Dekker on `h(s) = mean(psi_c(y/s)^2) - a(c)`, on the
/// down-crossing (`h > 0` below, `h <= 0` above; the root the fixed point is attracted to)
/// nearest `s0`. `h < 0` both for `s -> 0` and `s -> inf`.
#[cold]
fn scale_exact_bracketed(y: &[f64], c: f64, a: f64, s0: f64) -> Result<f64, InputError> {
    let h = |s: f64| mean_psi2(y, 1.0 / s, c) - a;
    let mut bracket = None;
    let mut best_distance = i32::MAX;
    // scan upward and downward from s0 for the nearest (+, -) pair of adjacent grid points
    let mut h_prev = h(s0);
    let mut s_prev = s0;
    for k in 1..=GRID_STEPS {
        let s = s_prev * GRID_RATIO;
        let hs = h(s);
        if h_prev > 0.0 && hs <= 0.0 {
            bracket = Some((s_prev, s));
            best_distance = k;
            break;
        }
        s_prev = s;
        h_prev = hs;
    }
    let mut h_next = h(s0);
    let mut s_next = s0;
    for _ in 1..=GRID_STEPS.min(best_distance) {
        let s = s_next / GRID_RATIO;
        let hs = h(s);
        if hs > 0.0 && h_next <= 0.0 {
            bracket = Some((s, s_next));
            break;
        }
        s_next = s;
        h_next = hs;
    }
    let (lo, hi) = bracket.ok_or(SeriesError::NoRobustScale { a, c })?;
    let root = find_root(h, lo, hi, (S_ROOT_RTOL * lo).max(f64::MIN_POSITIVE))?;
    Ok(root.x * root.x)
}

/// Upper end of the package's search interval for `s2 = s^2 / var(y)` (docs/methods.md §2.4 step
/// 2).
const PACKAGE_S2_MAX: f64 = 2.0;

fn scale_package(y: &[f64], c: f64, a: f64) -> Result<f64, InputError> {
    let n = y.len();
    if n < 2 {
        return Err(SeriesError::TooShort {
            n,
            needed: 2,
            what: "the package robust scale (sample variance)".into(),
        }
        .into());
    }
    let mut sum = NeumaierSum::default();
    for &v in y {
        sum.add(v);
    }
    let mean = sum.total() / n as f64;
    let mut ss = NeumaierSum::default();
    for &v in y {
        ss.add((v - mean) * (v - mean));
    }
    let var = ss.total() / (n - 1) as f64;
    if var <= 0.0 {
        return Err(SeriesError::Constant { value: y[0] }.into());
    }
    let sd = var.sqrt();
    // x_i = y_i / sd, then r_i = x_i / sqrt(s2)
    let objective = |s2: f64| {
        let d = mean_psi2_scaled(y, sd, s2.sqrt(), c) - a;
        d * d
    };
    let m = minimize(objective, 0.0, PACKAGE_S2_MAX, OPTIMIZE_TOL)?;
    Ok(m.x * var)
}

/// `mean(psi_c((y_i / sd) / s)^2)` in the package's order of operations (docs/methods.md §2.4).
fn mean_psi2_scaled(y: &[f64], sd: f64, s: f64, c: f64) -> f64 {
    let inv_c2 = 1.0 / (c * c);
    let mut total = NeumaierSum::default();
    for block in y.chunks(BLOCK) {
        let mut acc = 0.0;
        for &yi in block {
            let r = (yi / sd) / s;
            if r.abs() <= c {
                let t = 1.0 - r * r * inv_c2;
                let psi = r * t * t;
                acc += psi * psi;
            }
        }
        total.add(acc);
    }
    total.total() / y.len() as f64
}

/// Robust confidence interval of one level (docs/methods.md §2.5).
///
/// # Formula
/// With `k = sqrt(1 / eff)`, classical WV `nu_c` and its eta3 CI `(lo_c, hi_c)` on the same
/// coefficients:
/// `lo_r = nu_r (1 - k (nu_c - lo_c) / nu_c)`, `hi_r = nu_r (1 + k (hi_c - nu_c) / nu_c)`.
/// If `lo_r <= 0` the package substitutes `min(nu_r / 2, smallest lower bound of earlier
/// levels)`; pass that smallest earlier lower bound as `lowest_previous`. At level 1 there is
/// no earlier level (`None`): the package reads an empty range there (§13.6), and this port
/// uses `nu_r / 2`.
///
/// Returns `(lo_r, hi_r)`; non-finite inputs propagate as NaN.
///
/// # Examples
/// Worked example: the test `tests::examples::example_robust_robust_ci`.
pub(crate) fn robust_ci(
    nu_r: f64,
    nu_c: f64,
    lo_c: f64,
    hi_c: f64,
    eff: f64,
    lowest_previous: Option<f64>,
) -> (f64, f64) {
    let k = (1.0 / eff).sqrt();
    let mut lo = nu_r * (1.0 - k * (nu_c - lo_c) / nu_c);
    let hi = nu_r * (1.0 + k * (hi_c - nu_c) / nu_c);
    if lo <= 0.0 {
        let half = 0.5 * nu_r;
        lo = match lowest_previous {
            Some(prev) => half.min(prev),
            None => half,
        };
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Options read from JSON are checked as the constructor checks them: a saved WV or a
    /// calibration with an efficiency outside (0, 0.99] is refused, naming `eff`.
    #[test]
    fn robust_options_from_json_are_checked() {
        let ok: RobustOptions =
            serde_json::from_str(r#"{"eff": 0.6, "convention": "exact"}"#).unwrap();
        assert_eq!(ok, RobustOptions::default());
        for eff in ["1.5", "0", "-0.2"] {
            let text = format!(r#"{{"eff": {eff}, "convention": "exact"}}"#);
            let e = serde_json::from_str::<RobustOptions>(&text).unwrap_err();
            assert!(e.to_string().contains("eff"), "{eff}: {e}");
        }
    }
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use rand_distr::StandardNormal;

    #[test]
    fn robust_options_validates_eff() {
        assert!(RobustOptions::new(0.6, RobustConvention::Exact).is_ok());
        assert!(RobustOptions::new(0.99, RobustConvention::Package).is_ok());
        for bad in [0.0, -0.1, 0.991, 1.0, f64::NAN, f64::INFINITY] {
            let err = RobustOptions::new(bad, RobustConvention::Exact).unwrap_err();
            assert_eq!(err.name, "eff");
        }
        let msg = RobustOptions::new(1.0, RobustConvention::Exact)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("at most 0.99"), "{msg}");
    }

    #[test]
    fn robust_options_default_is_exact_0_6() {
        let d = RobustOptions::default();
        assert_eq!(d.eff, 0.6);
        assert_eq!(d.convention, RobustConvention::Exact);
    }

    #[test]
    fn robust_convention_round_trips_text() {
        for conv in [RobustConvention::Exact, RobustConvention::Package] {
            assert_eq!(conv.to_string().parse::<RobustConvention>(), Ok(conv));
        }
        assert_eq!("PACKAGE".parse(), Ok(RobustConvention::Package));
        assert_eq!("Exact".parse(), Ok(RobustConvention::Exact));
        let err = "r".parse::<RobustConvention>().unwrap_err();
        assert_eq!(err.name, "robust-convention");
    }

    #[test]
    fn truncated_normal_moments_tend_to_double_factorials() {
        // docs/methods.md §2.2: mu_{2k}(inf) = (2k - 1)!!
        let mu = truncated_normal_moments(40.0);
        let mut df = 1.0;
        for (k, &m) in mu.iter().enumerate() {
            if k > 0 {
                df *= (2 * k - 1) as f64;
            }
            assert!((m - df).abs() <= 1e-12 * df, "k = {k}: {m} vs {df}");
        }
    }

    #[test]
    fn central_normal_mass_matches_high_precision() {
        // 2 Phi(c) - 1 from mpmath at 30 digits
        let cases: [(f64, f64); 6] = [
            (0.5, 0.382_924_922_548_026_2),
            (1.0, 0.682_689_492_137_085_9),
            (1.959963984540054, 0.95),
            (3.0, 0.997_300_203_936_739_8),
            (4.4, 0.999_989_174_912_184_6),
            (20.0, 1.0),
        ];
        for (c, expected) in cases {
            let two_phi = 2.0 * INV_SQRT_2PI * (-0.5 * c * c).exp();
            let got = central_normal_mass(c, two_phi);
            assert!((got - expected).abs() <= 4.0 * f64::EPSILON, "{c}: {got}");
        }
    }

    #[test]
    fn scale_exact_bracketed_agrees_with_iteration() {
        // docs/methods.md §2.4: the fallback finds the same root as the fixed point + polish
        let c = 4.400278;
        let a = a_of_c(c);
        for y in [
            &[-1.2, 0.3, 0.8, -0.4, 1.1, -0.9, 0.2, -0.1, 0.6, -0.7][..],
            &[-2.0, -1.5, -1.0, -0.5, 0.0, 0.5, 1.0, 1.5, 2.0, 30.0][..],
        ] {
            let s0 = median_abs(y) / MAD_CONSISTENCY;
            let direct = scale_exact(y, c, a).unwrap();
            let fallback = scale_exact_bracketed(y, c, a, s0).unwrap();
            assert!(
                (direct - fallback).abs() < 1e-12 * direct,
                "{direct} {fallback}"
            );
        }
    }

    #[test]
    fn median_abs_handles_odd_and_even() {
        assert_eq!(median_abs(&[3.0, -1.0, 2.0]), 2.0);
        assert_eq!(median_abs(&[3.0, -1.0, 2.0, -4.0]), 2.5);
        assert_eq!(median_abs(&[-5.0]), 5.0);
    }

    #[test]
    fn psi_biweight_vanishes_outside_c() {
        assert_eq!(psi_biweight(5.0, 4.0), 0.0);
        assert_eq!(psi_biweight(4.0, 4.0), 0.0);
        assert!((psi_biweight(1.0, 2.0) - 0.5625).abs() < 1e-15);
    }

    #[test]
    fn robust_ci_level_one_fallback_is_half() {
        // lo_r <= 0: k (nu_c - lo_c) / nu_c >= 1
        let (lo, _) = robust_ci(2.0, 1.0, 0.1, 3.0, 0.5, None);
        assert_eq!(lo, 1.0);
        let (lo, _) = robust_ci(2.0, 1.0, 0.1, 3.0, 0.5, Some(0.3));
        assert_eq!(lo, 0.3);
        let (lo, _) = robust_ci(2.0, 1.0, 0.1, 3.0, 0.5, Some(5.0));
        assert_eq!(lo, 1.0);
    }

    #[test]
    fn robust_scale_long_finds_the_direct_root() {
        // docs/methods.md §2.4: the windowed route (subsample root, one power-sum pass, Brent on
        // the window) and the direct fixed point from the exact MAD start solve the same equation
        // to ~1e-14 in s; 1e-11 on s^2 leaves room for the different summation orders. Cases: clean
        // Gaussian, 2% gross outliers, a heavy-tailed mixture (MAD start far from the root), and a
        // window that must slide (a subsample that misses the contaminated stretch).
        let c = tuning_constant(0.6, RobustConvention::Exact).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(77);
        let n = 100_000;
        let gauss: Vec<f64> = (0..n)
            .map(|_| rng.sample::<f64, _>(StandardNormal))
            .collect();
        let mut outliers = gauss.clone();
        for v in outliers.iter_mut().step_by(50) {
            *v = 100.0;
        }
        let mixture: Vec<f64> = gauss
            .iter()
            .enumerate()
            .map(|(i, v)| if i % 5 == 0 { 6.0 * v } else { *v })
            .collect();
        let mut stretch = gauss.clone();
        // every 12th value (the subsample's stride is n / 8192 = 12) is left clean; the rest of
        // one third of the series is wider: the subsample sees a narrower distribution
        for (i, v) in stretch.iter_mut().enumerate().take(n / 3) {
            if i % 12 != 0 {
                *v *= 3.0;
            }
        }
        for (y, what) in [
            (&gauss, "gaussian"),
            (&outliers, "outliers"),
            (&mixture, "mixture"),
            (&stretch, "stretch"),
        ] {
            let long = robust_scale_long(y, c).unwrap();
            let direct = robust_scale(y, c, RobustConvention::Exact).unwrap();
            assert!(
                ((long - direct) / direct).abs() < 1e-11,
                "{what}: {long} vs {direct}"
            );
        }
    }
}
