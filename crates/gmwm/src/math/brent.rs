//! Brent's one-dimensional minimiser and bracketing root finder (docs/methods.md §12).
//!
//! Both follow R. P. Brent, *Algorithms for Minimization without Derivatives*, Prentice-Hall
//! 1973: chapter 5 (`localmin`: golden section + successive parabolic interpolation, the method
//! behind R's `optimize`) and chapter 4 (`zero`: bisection + secant + inverse quadratic
//! interpolation, the Brent–Dekker method). Neither allocates; each costs one function
//! evaluation per step.

use crate::error::ParamError;

/// R's `optimize` default tolerance `.Machine$double.eps^0.25` (docs/methods.md §2.3): `2^-52` to
/// the quarter power is exactly `2^-13`.
pub(crate) const OPTIMIZE_TOL: f64 = 1.220_703_125e-4;

/// Square of the golden-section ratio, `(3 - sqrt 5) / 2` (Brent 1973, ch. 5).
const GOLDEN: f64 = 0.381_966_011_250_105_1;

/// Safety cap on the number of steps of either method. Brent's methods terminate on their own
/// (at worst about `(log2((b - a) / tol))^2` steps); the cap only guards against a function that
/// returns inconsistent values.
pub(crate) const MAX_STEPS: usize = 10_000;

/// Result of [`minimize`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Minimum {
    /// Abscissa of the (local) minimum.
    pub(crate) x: f64,
    /// Function value at `x` (non-finite values were replaced by `f64::MAX`).
    pub(crate) fx: f64,
    /// Number of function evaluations.
    pub(crate) evaluations: usize,
}

/// Result of [`find_root`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Root {
    /// Abscissa of the root (the bracket end with the smaller `|f|` at termination).
    pub(crate) x: f64,
    /// Function value at `x`.
    pub(crate) fx: f64,
    /// Number of function evaluations.
    pub(crate) evaluations: usize,
}

fn check_interval(lower: f64, upper: f64, tol: f64) -> Result<(), ParamError> {
    if !(lower.is_finite() && upper.is_finite() && lower < upper) {
        return Err(ParamError::new(
            "interval",
            format!("[{lower}, {upper}]"),
            "finite end points with lower < upper",
        ));
    }
    if !(tol.is_finite() && tol > 0.0) {
        return Err(ParamError::new("tol", tol, "a finite positive tolerance"));
    }
    Ok(())
}

/// Local minimum of `f` on `(lower, upper)` by Brent's method, as R's `optimize` (docs/methods.md
/// §12, §2.3, §2.4).
///
/// # Formula
/// Brent (1973), ch. 5, `localmin`. The first point is `lower + 0.381966 (upper - lower)`; each
/// step tries a parabola through the three best points and falls back to a golden-section step
/// when the parabola's minimum is outside the bracket or the step does not shrink fast enough.
/// The iterate `x` is accurate to `3 * sqrt(eps) |x| + tol`, with `sqrt(eps) = 2^-26` relative
/// and `tol / 3` absolute per side, as R's `optimize(tol = tol)`. End points are never
/// evaluated. Non-finite function values are replaced by `f64::MAX` (R does the same, with a
/// warning).
///
/// Only a *local* minimum is guaranteed: that is precisely the package behaviour docs/methods.md
/// §2.4 documents (test value 176.0876).
///
/// # Errors
/// [`ParamError`] if the interval is not finite with `lower < upper`, or `tol` is not positive.
///
/// Examples: the unit tests below (the module is crate-internal).
pub(crate) fn minimize<F: FnMut(f64) -> f64>(
    mut f: F,
    lower: f64,
    upper: f64,
    tol: f64,
) -> Result<Minimum, ParamError> {
    check_interval(lower, upper, tol)?;
    let mut eval = |x: f64| {
        let v = f(x);
        if v.is_finite() {
            v
        } else {
            f64::MAX
        }
    };
    let sqrt_eps = f64::EPSILON.sqrt();
    let tol3 = tol / 3.0;
    let (mut a, mut b) = (lower, upper);
    // x: best point so far; w: second best; v: previous value of w.
    let mut x = a + GOLDEN * (b - a);
    let mut w = x;
    let mut v = x;
    let mut fx = eval(x);
    let mut fw = fx;
    let mut fv = fx;
    let mut evaluations = 1;
    // d: the last step; e: the step before it (parabolic steps must shrink against e).
    let mut d: f64 = 0.0;
    let mut e: f64 = 0.0;
    for _ in 0..MAX_STEPS {
        let xm = 0.5 * (a + b);
        let tol1 = sqrt_eps * x.abs() + tol3;
        let tol2 = 2.0 * tol1;
        if (x - xm).abs() <= tol2 - 0.5 * (b - a) {
            break;
        }
        let mut p = 0.0;
        let mut q = 0.0;
        let mut previous_e = 0.0;
        if e.abs() > tol1 {
            // parabola through (v, fv), (w, fw), (x, fx): its vertex is x + p / q
            let r = (x - w) * (fx - fv);
            q = (x - v) * (fx - fw);
            p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            } else {
                q = -q;
            }
            previous_e = e;
            e = d;
        }
        let parabolic_ok =
            p.abs() < (0.5 * q * previous_e).abs() && p > q * (a - x) && p < q * (b - x);
        if parabolic_ok {
            d = p / q;
            let u = x + d;
            // never evaluate too close to the bracket ends
            if u - a < tol2 || b - u < tol2 {
                d = if x < xm { tol1 } else { -tol1 };
            }
        } else {
            // golden section into the larger of the two segments
            e = if x < xm { b - x } else { a - x };
            d = GOLDEN * e;
        }
        // never evaluate closer than tol1 to x
        let u = if d.abs() >= tol1 {
            x + d
        } else if d > 0.0 {
            x + tol1
        } else {
            x - tol1
        };
        let fu = eval(u);
        evaluations += 1;
        if fu <= fx {
            if u < x {
                b = x;
            } else {
                a = x;
            }
            v = w;
            fv = fw;
            w = x;
            fw = fx;
            x = u;
            fx = fu;
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                v = w;
                fv = fw;
                w = u;
                fw = fu;
            } else if fu <= fv || v == x || v == w {
                v = u;
                fv = fu;
            }
        }
    }
    Ok(Minimum { x, fx, evaluations })
}

/// Root of `f` in the bracket `[lower, upper]` by the Brent–Dekker method (docs/methods.md §12,
/// §2.3, §2.4).
///
/// # Formula
/// Brent (1973), ch. 4, `zero`: keeps a sign-changing bracket `[b, c]` and steps by inverse
/// quadratic interpolation (secant when only two points are distinct), falling back to
/// bisection whenever the interpolated step is not safely inside the bracket or fails to halve
/// the step of two iterations ago. Terminates when the bracket half-width is at most
/// `2 eps |b| + tol / 2`, so the root is accurate to about `tol` absolute plus a few ulps.
///
/// # Errors
/// [`ParamError`] if the interval is not finite with `lower < upper`, `tol` is not positive,
/// `f` is not finite at an end point or inside, or `f(lower)` and `f(upper)` have the same
/// strict sign (no bracket).
///
/// Examples: the unit tests below (the module is crate-internal).
pub(crate) fn find_root<F: FnMut(f64) -> f64>(
    mut f: F,
    lower: f64,
    upper: f64,
    tol: f64,
) -> Result<Root, ParamError> {
    check_interval(lower, upper, tol)?;
    let (mut a, mut b) = (lower, upper);
    let mut fa = f(a);
    let mut fb = f(b);
    let mut evaluations = 2;
    if !(fa.is_finite() && fb.is_finite()) {
        return Err(non_finite_value(if fa.is_finite() { b } else { a }));
    }
    if fa == 0.0 {
        return Ok(Root {
            x: a,
            fx: fa,
            evaluations,
        });
    }
    if (fa > 0.0) == (fb > 0.0) && fb != 0.0 {
        return Err(ParamError::new(
            "bracket",
            format!("[{lower}, {upper}] with f = ({fa}, {fb})"),
            "end points where f has opposite signs",
        ));
    }
    // b: best estimate; c: the point with f of opposite sign to f(b); a: previous b.
    let mut c = a;
    let mut fc = fa;
    let mut d = b - a;
    let mut e = d;
    for _ in 0..MAX_STEPS {
        if (fb > 0.0) == (fc > 0.0) && fb != 0.0 {
            // the bracket is [a, b] again
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol1 = 2.0 * f64::EPSILON * b.abs() + 0.5 * tol;
        let xm = 0.5 * (c - b);
        if xm.abs() <= tol1 || fb == 0.0 {
            return Ok(Root {
                x: b,
                fx: fb,
                evaluations,
            });
        }
        if e.abs() >= tol1 && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut p, mut q) = if a == c {
                // secant
                (2.0 * xm * s, 1.0 - s)
            } else {
                // inverse quadratic interpolation through a, b, c
                let qa = fa / fc;
                let r = fb / fc;
                (
                    s * (2.0 * xm * qa * (qa - r) - (b - a) * (r - 1.0)),
                    (qa - 1.0) * (r - 1.0) * (s - 1.0),
                )
            };
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < (3.0 * xm * q - (tol1 * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = xm;
                e = d;
            }
        } else {
            d = xm;
            e = d;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol1 { d } else { tol1.copysign(xm) };
        fb = f(b);
        evaluations += 1;
        if !fb.is_finite() {
            return Err(non_finite_value(b));
        }
    }
    Ok(Root {
        x: b,
        fx: fb,
        evaluations,
    })
}

#[cold]
fn non_finite_value(x: f64) -> ParamError {
    ParamError::new(
        "bracket",
        format!("f({x}) not finite"),
        "a function finite on the whole bracket",
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn optimize_tol_is_eps_to_the_quarter() {
        assert_eq!(OPTIMIZE_TOL, f64::EPSILON.powf(0.25));
    }

    #[test]
    fn minimize_rejects_bad_interval() {
        assert!(minimize(|x| x, 1.0, 0.0, OPTIMIZE_TOL).is_err());
        assert!(minimize(|x| x, f64::NAN, 1.0, OPTIMIZE_TOL).is_err());
        assert!(minimize(|x| x, 0.0, 1.0, 0.0).is_err());
    }

    #[test]
    fn find_root_rejects_missing_bracket() {
        let err = find_root(|x| x * x + 1.0, -1.0, 1.0, 1e-12).unwrap_err();
        assert_eq!(err.name, "bracket");
        assert!(find_root(|x| 1.0 / x - 1.0, 0.0, 2.0, 1e-12).is_err());
        assert!(find_root(|x| x, 1.0, -1.0, 1e-12).is_err());
    }

    #[test]
    fn find_root_accepts_root_at_end_point() {
        let r = find_root(|x| x - 1.0, 1.0, 2.0, 1e-12).unwrap();
        assert_eq!(r.x, 1.0);
        let r = find_root(|x| x - 2.0, 1.0, 2.0, 1e-12).unwrap();
        assert_eq!(r.x, 2.0);
    }

    #[test]
    fn brent_minimize_finds_parabola_vertex() {
        let m = minimize(|x| (x - 2.0) * (x - 2.0), 0.0, 5.0, OPTIMIZE_TOL).unwrap();
        assert!((m.x - 2.0).abs() < OPTIMIZE_TOL, "{m:?}");
        assert!(m.evaluations < 50);
    }

    #[test]
    fn brent_minimize_finds_cos_minimum_at_pi() {
        let m = minimize(f64::cos, 3.0, 4.0, 1e-10).unwrap();
        // cos is flat at pi: x is found to about sqrt(eps) relative
        assert!((m.x - std::f64::consts::PI).abs() < 1e-7, "{m:?}");
        assert!((m.fx + 1.0).abs() < 1e-14);
    }

    #[test]
    fn brent_minimize_respects_interval_ends() {
        // minimum outside the interval: iterate approaches the nearest end within tolerance
        let m = minimize(|x| x, 1.0, 3.0, OPTIMIZE_TOL).unwrap();
        assert!(m.x > 1.0 && m.x - 1.0 < 2.0 * OPTIMIZE_TOL, "{m:?}");
    }

    #[test]
    fn brent_find_root_finds_cube_root_of_two() {
        let r = find_root(|x| x * x * x - 2.0, 0.0, 2.0, 1e-14).unwrap();
        assert!((r.x - 2f64.cbrt()).abs() < 1e-13, "{r:?}");
        let r = find_root(f64::cos, 1.0, 2.0, 1e-15).unwrap();
        assert!((r.x - std::f64::consts::FRAC_PI_2).abs() < 1e-14, "{r:?}");
    }
}
