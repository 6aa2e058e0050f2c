//! The arithmetic the generic ARMA computation (docs/methods.md §4.4) is written in: `f64`
//! for values, [`Dual`] for exact gradients with respect to the coefficients.
//!
//! One implementation of §4.4 then gives both the implied WV and its Jacobian: the `f64`
//! instance performs the very operations it always did (same bits), and the `Dual` instance
//! carries `d/dc` through them, so the Jacobian is the derivative of the computed function,
//! not a difference quotient (§4.7's Richardson differences needed `8 (p + q)` evaluations and
//! left ~1e-11 relative error; one dual pass covers eight coefficients).

use std::ops::{Add, Div, Mul, Neg, Sub};

/// A number the ARMA autocovariance and WV can be computed in.
pub(crate) trait Scalar:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
    + Neg<Output = Self>
{
    /// A constant.
    fn lift(v: f64) -> Self;
    /// Not a number, in every component (a failed computation must not pass for a zero
    /// derivative).
    fn nan() -> Self;
    /// The value (for pivoting and tests of finiteness).
    fn value(self) -> f64;
    /// Whether every component is exactly zero (a product with it may be skipped).
    fn is_zero(self) -> bool;
    /// Whether `next` equals `prev` to rounding, component by component relative to the
    /// largest magnitude of that component over the slice (a fixed point of repeated squaring).
    fn settled(next: &[Self], prev: &[Self]) -> bool;
}

/// Sum of the items, starting from the first (no zero is added: `-0.0` stays `-0.0`, and for
/// `f64` the result is the bits of `Iterator::sum` whenever the sum is not a signed zero).
pub(crate) fn sum<T: Scalar>(items: impl IntoIterator<Item = T>) -> T {
    let mut it = items.into_iter();
    match it.next() {
        Some(first) => it.fold(first, |s, x| s + x),
        None => T::lift(0.0),
    }
}

/// The relative rounding a fixed point of [`Scalar::settled`] allows.
const SETTLED: f64 = f64::EPSILON;

impl Scalar for f64 {
    fn lift(v: f64) -> Self {
        v
    }
    fn nan() -> Self {
        f64::NAN
    }
    fn value(self) -> f64 {
        self
    }
    fn is_zero(self) -> bool {
        self == 0.0
    }
    fn settled(next: &[Self], prev: &[Self]) -> bool {
        component_settled(next, prev, |x| *x)
    }
}

/// [`Scalar::settled`] for one component of the items, read by `part`.
fn component_settled<T>(next: &[T], prev: &[T], part: impl Fn(&T) -> f64) -> bool {
    let size = next.iter().fold(0.0f64, |m, x| m.max(part(x).abs()));
    next.iter()
        .zip(prev)
        .all(|(a, b)| (part(a) - part(b)).abs() <= SETTLED * size)
}

/// A forward-mode dual number: a value and its gradient with respect to `N` variables.
/// (The process module's `Jet` also carries a Hessian's storage, which a matrix of them would
/// copy at every operation.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Dual<const N: usize> {
    /// Value.
    pub(crate) v: f64,
    /// Gradient.
    pub(crate) g: [f64; N],
}

impl<const N: usize> Dual<N> {
    /// The `k`-th independent variable at value `v`.
    pub(crate) fn var(v: f64, k: usize) -> Self {
        let mut g = [0.0; N];
        if k < N {
            g[k] = 1.0;
        }
        Self { v, g }
    }
}

impl<const N: usize> Scalar for Dual<N> {
    fn lift(v: f64) -> Self {
        Self { v, g: [0.0; N] }
    }
    fn nan() -> Self {
        Self {
            v: f64::NAN,
            g: [f64::NAN; N],
        }
    }
    fn value(self) -> f64 {
        self.v
    }
    fn is_zero(self) -> bool {
        self.v == 0.0 && self.g.iter().all(|&g| g == 0.0)
    }
    fn settled(next: &[Self], prev: &[Self]) -> bool {
        component_settled(next, prev, |x| x.v)
            && (0..N).all(|k| component_settled(next, prev, |x| x.g[k]))
    }
}

impl<const N: usize> Add for Dual<N> {
    type Output = Self;
    fn add(mut self, o: Self) -> Self {
        self.v += o.v;
        for (a, b) in self.g.iter_mut().zip(o.g) {
            *a += b;
        }
        self
    }
}

impl<const N: usize> Sub for Dual<N> {
    type Output = Self;
    fn sub(mut self, o: Self) -> Self {
        self.v -= o.v;
        for (a, b) in self.g.iter_mut().zip(o.g) {
            *a -= b;
        }
        self
    }
}

impl<const N: usize> Neg for Dual<N> {
    type Output = Self;
    fn neg(mut self) -> Self {
        self.v = -self.v;
        for a in &mut self.g {
            *a = -*a;
        }
        self
    }
}

impl<const N: usize> Mul for Dual<N> {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        let mut g = [0.0; N];
        for ((g, a), b) in g.iter_mut().zip(self.g).zip(o.g) {
            *g = a * o.v + self.v * b;
        }
        Self { v: self.v * o.v, g }
    }
}

impl<const N: usize> Div for Dual<N> {
    type Output = Self;
    fn div(self, o: Self) -> Self {
        let v = self.v / o.v;
        let mut g = [0.0; N];
        for ((g, a), b) in g.iter_mut().zip(self.g).zip(o.g) {
            *g = (a - v * b) / o.v;
        }
        Self { v, g }
    }
}

impl<const N: usize> Mul<f64> for Dual<N> {
    type Output = Self;
    fn mul(mut self, s: f64) -> Self {
        self.v *= s;
        for a in &mut self.g {
            *a *= s;
        }
        self
    }
}

impl<const N: usize> Div<f64> for Dual<N> {
    type Output = Self;
    fn div(mut self, s: f64) -> Self {
        self.v /= s;
        for a in &mut self.g {
            *a /= s;
        }
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dual_arithmetic_follows_the_derivative_rules() {
        // f(x, y) = (x y - x / y) * 3 / (x + 2), at (1.5, 0.5)
        let (x, y) = (Dual::<2>::var(1.5, 0), Dual::<2>::var(0.5, 1));
        let f = (x * y - x / y) * 3.0 / (x + Dual::lift(2.0));
        let fx = |x: f64, y: f64| (x * y - x / y) * 3.0 / (x + 2.0);
        assert_eq!(f.v, fx(1.5, 0.5));
        let h = 1e-6;
        let dx = (fx(1.5 + h, 0.5) - fx(1.5 - h, 0.5)) / (2.0 * h);
        let dy = (fx(1.5, 0.5 + h) - fx(1.5, 0.5 - h)) / (2.0 * h);
        // central differences carry ~h^2 f''' + eps/h ~ 1e-10 relative here
        assert!((f.g[0] - dx).abs() <= 1e-8 * dx.abs(), "{} {dx}", f.g[0]);
        assert!((f.g[1] - dy).abs() <= 1e-8 * dy.abs(), "{} {dy}", f.g[1]);
        let n = -Dual::<2>::var(2.0, 1);
        assert_eq!((n.v, n.g), (-2.0, [0.0, -1.0]));
        let q = Dual::<2>::var(3.0, 0) / 4.0;
        assert_eq!((q.v, q.g), (0.75, [0.25, 0.0]));
        assert!(Dual::<2>::nan().g.iter().all(|g| g.is_nan()));
    }

    #[test]
    fn sum_starts_from_the_first_item() {
        assert_eq!(sum([1.0, 2.0, 0.5]), 3.5);
        assert_eq!(sum(Vec::<f64>::new()), 0.0);
        assert!(sum([-0.0f64]).is_sign_negative());
    }

    #[test]
    fn settled_compares_each_component_on_its_own_scale() {
        let a = [Dual::<1> { v: 1.0, g: [1e-20] }];
        let b = [Dual::<1> { v: 1.0, g: [2e-20] }];
        // the values agree, but the gradient moved by half its size
        assert!(!Dual::settled(&a, &b));
        assert!(Dual::settled(&a, &a));
        assert!(f64::settled(&[1.0, 1e-30], &[1.0, 2e-30]));
    }
}
