//! Latent processes of an IMU error model and their implied (theoretical) Haar wavelet variance,
//! with first and second derivatives (docs/methods.md §4).
//!
//! Every process implements [`LatentProcess`]; [`Process`] is the closed set of them. Levels are
//! `j = 1..=levels` at scales `tau_j = 2^j` samples, parameters are per sample (docs/methods.md
//! §0.1); only [`Gm`] carries a sampling rate (§4.3).
//!
//! Each process's module holds all of its facts: its name and parameters in the model language
//! (with their domains), its validating constructor, its implied WV and derivatives, its
//! spectral density, how it is simulated (docs/methods.md §10.1), its part of the exact WV
//! covariance, its parameter transforms, starting values, role and physical read-off (the
//! `Spec` of `facts.rs`). One table, the `processes!` rows below, declares [`ProcessKind`] and
//! [`Process`] and maps each kind to those facts; no code outside this module matches on a
//! kind. A new process is its file, its `mod` line and one row of the table.
//!
//! Derivatives of the closed forms are exact (forward-mode automatic differentiation of the
//! numerically stable evaluation, see `ar1`), so they stay accurate where the textbook quotient
//! of §4.5 cancels (AR1/GM with `phi` near 1). The generic [`Arma`]'s §4.4 computation is
//! differentiated the same way, in the dual numbers of `scalar` (§4.7). `spectral` holds the slow quadrature oracle of §1.9.

use serde::Serialize;

pub(crate) mod ar1;
pub(crate) mod arma;
pub(crate) mod arma11;
pub(crate) mod dr;
pub(crate) mod draw;
mod facts;
pub(crate) mod flicker;
mod kind;
pub(crate) mod ma1;
pub(crate) mod maf;
mod param;
pub(crate) mod qn;
pub(crate) mod rw;
pub(crate) mod sampler;
pub(crate) mod scalar;
pub(crate) mod sin;
#[cfg(test)]
pub(crate) mod spectral;
pub(crate) mod wn;

pub use ar1::{Ar1, Gm};
pub use arma::Arma;
pub use arma11::Arma11;
pub use dr::Dr;
pub use flicker::Flicker;
pub use ma1::Ma1;
pub use maf::Maf;
pub use qn::Qn;
pub use rw::Rw;
pub use sin::Sin;
pub use wn::Wn;

pub(crate) use draw::Dominance;
pub(crate) use facts::{
    kind_of, Markov, MarkovForms, Occurs, Orders, Params, Physical, Role, Spec, UnitShape, BASE,
};
pub(crate) use kind::ParamDomain;
pub(crate) use kind::MAX_ORDER;
pub(crate) use param::ChainSlot;
pub use param::TransformPreset;
pub(crate) use param::{logistic, ParamTransform, RESTART_EDGE};
pub use sampler::StartMode;
use scalar::Scalar;

use crate::error::ParamError;
use sampler::{Sampler, SimRng};

/// A latent process with an implied Haar wavelet variance (docs/methods.md §4). Object safe.
pub trait LatentProcess {
    /// Component name as in docs/methods.md §0.2: "WN", "QN", "RW", "DR", "AR1", "GM", "MA1",
    /// "ARMA11", "ARMA"; "FN" (flicker, `flicker.rs`), "SIN" (vibration, `sin.rs`), "MAF"
    /// (the sensor's filter, `maf.rs`).
    fn name(&self) -> &'static str;
    /// Parameter names in docs/methods.md §0.2 order.
    fn param_names(&self) -> Vec<&'static str>;
    /// Parameter values in the order of [`LatentProcess::param_names`].
    fn params(&self) -> Vec<f64>;
    /// docs/methods.md §4.2: implied Haar WV at `tau_j = 2^j` samples, `j = 1..=levels`.
    fn wv(&self, levels: usize) -> Vec<f64>;
    /// Adds the implied WV at levels `1..=out.len()` to `out` (the objective's and the
    /// starting-value search's hot path: no allocation where a process overrides it).
    fn add_wv(&self, out: &mut [f64]) {
        let wv = self.wv(out.len());
        for (o, w) in out.iter_mut().zip(wv) {
            *o += w;
        }
    }
    /// docs/methods.md §4.5: Jacobian `d nu2_j / d theta_k`, indexed `[level][param]`.
    fn jacobian(&self, levels: usize) -> Vec<Vec<f64>>;
    /// [`jacobian`](Self::jacobian) written into a row-major matrix: level `j`'s row at
    /// `a[j * stride + col..]` (the same values, without a vector per level; the fit's hot
    /// path).
    fn write_jacobian(&self, levels: usize, a: &mut [f64], stride: usize, col: usize) {
        for (j, row) in self.jacobian(levels).iter().enumerate() {
            a[j * stride + col..j * stride + col + row.len()].copy_from_slice(row);
        }
    }
    /// docs/methods.md §4.6: second derivatives, indexed `[level][param][param]` (symmetric).
    fn hessian(&self, levels: usize) -> Vec<Vec<Vec<f64>>>;
    /// docs/methods.md §1.9: spectral density `S(f)` on `|f| <= 1/2` (cycles per sample); the RW
    /// pseudo-spectrum for RW; `None` for the deterministic drift.
    fn spectral_density(&self, f: f64) -> Option<f64>;
}

/// What the engine needs of a process beyond [`LatentProcess`]: its validation, again, and its
/// simulation (docs/methods.md §10.1). Implemented by every process next to its implied WV.
pub(crate) trait Simulate: LatentProcess {
    /// The simulation state on `rng`, the component's own stream; initial draws come first in
    /// it, per `start` for the autoregressive processes.
    ///
    /// # Errors
    /// [`ParamError`] only for a generic ARMA whose burn-in would be too long.
    fn sampler(&self, rng: SimRng, start: StartMode) -> Result<Box<dyn Sampler>, ParamError>;
    /// What the exact covariance of the WV (docs/methods.md §1.10,
    /// `crate::variance::implied_cov`) needs of the process.
    ///
    /// # Errors
    /// [`ParamError`] naming what the exact covariance does not cover (the default: a
    /// process without a part).
    fn covariance_part(&self) -> Result<CovariancePart, ParamError> {
        Err(ParamError::new(
            "model",
            format!("a {} term", self.name()),
            "only WN, QN, RW, DR, AR1, GM, MA1 and ARMA11 terms for the exact WV covariance (--covariance auto or bootstrap simulates V)",
        ))
    }
}

/// A process as the exact covariance of the WV sees it (docs/methods.md §1.10): its
/// autocovariance in closed form, as one of the shapes that covariance sums.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum CovariancePart {
    /// White noise of this variance.
    White(f64),
    /// A random walk of this increment variance.
    RandomWalk(f64),
    /// Quantisation noise of this `q2`.
    Quantization(f64),
    /// A drift of this slope.
    Drift(f64),
    /// An autocovariance `gamma(0) = r0`, `gamma(h) = r1 phi^(h - 1)` for `h >= 1` (AR1, GM,
    /// MA1 with `phi = 0`, ARMA11), `phi` in (-1, 1); the exact covariance takes `phi >= 0`.
    Autoregressive {
        /// The decay per lag.
        phi: f64,
        /// `gamma(0)`.
        r0: f64,
        /// `gamma(1)`.
        r1: f64,
    },
}

/// Declares the one table of processes: each row a [`ProcessKind`] (with its orders, and an
/// example kind for lists), the [`Spec`] of its facts in the kind's own module, and for the
/// row that owns a struct, the [`Process`] variant over it. It defines [`ProcessKind`],
/// [`Process`] with its dispatch and `From` conversions, `spec` (the only map from a kind to
/// its facts) and `KINDS` (every kind once, in table order: the order of lists in messages).
macro_rules! processes {
    ($(
        $(#[doc = $doc:literal])*
        $kind:ident $(($($order:ty),+) = $example:expr)? => $spec:path
        $(, process $(#[doc = $pdoc:literal])* $variant:ident($ty:ty))?;
    )*) => {
        /// The kind of one latent process (docs/methods.md §0.2).
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum ProcessKind {
            $($(#[doc = $doc])* $kind $(($($order),+))?,)*
        }

        /// One latent process of a model, with its values (docs/methods.md §0.2).
        #[derive(Debug, Clone, PartialEq, Serialize)]
        pub enum Process {
            $($($(#[doc = $pdoc])* $variant($ty),)?)*
        }

        impl Process {
            fn inner(&self) -> &dyn Simulate {
                match self {
                    $($(Process::$variant(p) => p,)?)*
                }
            }
        }

        $($(impl From<$ty> for Process {
            fn from(p: $ty) -> Self {
                Process::$variant(p)
            }
        })?)*

        /// The facts of `kind`.
        pub(crate) fn spec(kind: ProcessKind) -> &'static Spec {
            match kind {
                $(ProcessKind::$kind { .. } => &$spec,)*
            }
        }

        /// Every kind once, in table order (the order of lists in messages); order kinds with
        /// example orders.
        pub(crate) const KINDS: &[ProcessKind] = &[$(processes!(@example $kind $(, $example)?),)*];
    };
    (@example $kind:ident) => { ProcessKind::$kind };
    (@example $kind:ident, $example:expr) => { $example };
}

processes! {
    /// White noise, parameter `sigma2`.
    Wn => wn::SPEC, process /// White noise.
        Wn(Wn);
    /// Quantisation noise, parameter `q2` (Q^2).
    Qn => qn::SPEC, process /// Quantisation noise.
        Qn(Qn);
    /// Random walk, parameter `gamma2` (increment variance).
    Rw => rw::SPEC, process /// Random walk.
        Rw(Rw);
    /// Deterministic drift, parameter `omega` (slope per sample).
    Dr => dr::SPEC, process /// Deterministic drift.
        Dr(Dr);
    /// Flicker (1/f, bias-instability) noise, parameter `b2` (B^2: innovation variance of the
    /// d = 1/2 fractional integration).
    Fn => flicker::SPEC, process /// Flicker noise.
        Flicker(Flicker);
    /// White noise through the sensor's `L`-sample moving-average filter, parameter `sigma2`
    /// (its long-run variance: the white noise it is beyond the filter).
    Maf(usize) = ProcessKind::Maf(4) => maf::SPEC, process /// The sensor's moving-average filter.
        Maf(Maf);
    /// First-order autoregression, parameters `phi`, `sigma2`.
    Ar1 => ar1::AR1_SPEC, process /// First-order autoregression.
        Ar1(Ar1);
    /// Gauss–Markov process (AR1 reparametrised with the sampling rate, docs/methods.md §4.3),
    /// parameters `beta`, `sigma2_gm`.
    Gm => ar1::GM_SPEC, process /// Gauss–Markov (AR1 at a sampling rate).
        Gm(Gm);
    /// First-order moving average, parameters `theta`, `sigma2`.
    Ma1 => ma1::SPEC, process /// First-order moving average.
        Ma1(Ma1);
    /// ARMA(1,1), parameters `phi`, `theta`, `sigma2`.
    Arma11 => arma11::SPEC, process /// ARMA(1,1).
        Arma11(Arma11);
    /// Autoregression of order p, parameters `ar1..arp`, `sigma2`.
    Ar(usize) = ProcessKind::Ar(1) => arma::AR_SPEC;
    /// Moving average of order q, parameters `ma1..maq`, `sigma2`.
    Ma(usize) = ProcessKind::Ma(1) => arma::MA_SPEC;
    /// ARMA(p, q) (package name `SARIMA` without seasonal part), parameters `ar1..arp`,
    /// `ma1..maq`, `sigma2`; R sign convention (docs/methods.md §0.2).
    Arma(usize, usize) = ProcessKind::Arma(1, 1) => arma::ARMA_SPEC, process /// General ARMA(p, q).
        Arma(Arma);
    /// Sinusoid with random phase (vibration), parameters `amplitude` (data unit), `omega`
    /// (cycles per sample, in (0, 1/2)).
    Sin => sin::SPEC, process /// Sinusoid with random phase (vibration).
        Sin(Sin);
}

impl Process {
    /// [`Simulate::covariance_part`].
    pub(crate) fn covariance_part(&self) -> Result<CovariancePart, ParamError> {
        self.inner().covariance_part()
    }

    /// [`Simulate::sampler`].
    pub(crate) fn sampler(
        &self,
        rng: SimRng,
        start: StartMode,
    ) -> Result<Box<dyn Sampler>, ParamError> {
        self.inner().sampler(rng, start)
    }
}

impl LatentProcess for Process {
    fn name(&self) -> &'static str {
        self.inner().name()
    }
    fn param_names(&self) -> Vec<&'static str> {
        self.inner().param_names()
    }
    fn params(&self) -> Vec<f64> {
        self.inner().params()
    }
    fn wv(&self, levels: usize) -> Vec<f64> {
        self.inner().wv(levels)
    }
    fn add_wv(&self, out: &mut [f64]) {
        self.inner().add_wv(out)
    }
    fn jacobian(&self, levels: usize) -> Vec<Vec<f64>> {
        self.inner().jacobian(levels)
    }
    fn write_jacobian(&self, levels: usize, a: &mut [f64], stride: usize, col: usize) {
        self.inner().write_jacobian(levels, a, stride, col)
    }
    fn hessian(&self, levels: usize) -> Vec<Vec<Vec<f64>>> {
        self.inner().hessian(levels)
    }
    fn spectral_density(&self, f: f64) -> Option<f64> {
        self.inner().spectral_density(f)
    }
}

/// docs/methods.md §4.1: Haar WV at `tau_j = 2^j`, `j = 1..=levels`, from autocovariances
/// `gamma_0, gamma_1, ...`:
/// `nu2(tau) = [m (gamma_0 - gamma_m) + sum_{i=1}^{m-1} i (2 gamma_{m-i} - gamma_i - gamma_{2m-i})] / (2 m^2)`
/// with `m = tau / 2`. Level `j` needs `gamma_0 .. gamma_{2^j - 1}`; levels whose lags are not
/// all given are left out, so the result may be shorter than `levels`.
///
/// Cost: `O(2^levels)`.
pub(crate) fn autocovariance_wv<T: Scalar>(gamma: &[T], levels: usize) -> Vec<T> {
    let mut out = Vec::with_capacity(levels);
    for j in 1..=levels.min(62) {
        let m = 1usize << (j - 1);
        if 2 * m > gamma.len() {
            break;
        }
        let mut s = (gamma[0] - gamma[m]) * m as f64;
        for i in 1..m {
            s = s + (gamma[m - i] * 2.0 - gamma[i] - gamma[2 * m - i]) * i as f64;
        }
        let mf = m as f64;
        out.push(s / (2.0 * mf * mf));
    }
    out
}

/// Half-widths `m_j = 2^{j-1}` for `j = 1..=levels` (docs/methods.md §0.1), as `f64`.
/// Adds `scale * unit(m)` at half-widths `m = 1, 2, 4, ...` to `out` (the implied WV of a
/// process that is one parameter times a fixed shape: WN, QN, RW, DR).
pub(crate) fn add_scaled(out: &mut [f64], scale: f64, unit: impl Fn(f64) -> f64) {
    for (o, m) in out.iter_mut().zip(half_widths(usize::MAX)) {
        *o += scale * unit(m);
    }
}

pub(crate) fn half_widths(levels: usize) -> impl Iterator<Item = f64> {
    // 2^(j-1) by doubling: exact, as `2f64.powi` is, without its library call per level (a
    // few percent of a model selection's time went there)
    std::iter::successors(Some(1.0f64), |m| Some(m * 2.0)).take(levels)
}

/// Checks a variance-like parameter: finite and `> 0`.
pub(crate) fn check_positive(name: &'static str, v: f64) -> Result<(), ParamError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(ParamError::new(name, v, "a finite number > 0"))
    }
}

/// Checks a coefficient with `|v| < 1`.
pub(crate) fn check_unit(name: &'static str, v: f64, expected: &str) -> Result<(), ParamError> {
    if v.is_finite() && v.abs() < 1.0 {
        Ok(())
    } else {
        Err(ParamError::new(name, v, expected))
    }
}

/// Evaluates a function of `N` parameters in jets and splits value, gradient and Hessian per
/// level. `f(params, m)` returns the level's jet.
pub(crate) fn jet_levels<const N: usize, const H: bool>(
    params: [f64; N],
    levels: usize,
    f: impl Fn(&[Jet<N, H>; N], f64) -> Jet<N, H>,
) -> Vec<Jet<N, H>> {
    let vars: [Jet<N, H>; N] = std::array::from_fn(|k| Jet::var(params[k], k));
    half_widths(levels).map(|m| f(&vars, m)).collect()
}

/// Jacobian rows from jets.
pub(crate) fn jets_jacobian<const N: usize, const H: bool>(jets: &[Jet<N, H>]) -> Vec<Vec<f64>> {
    jets.iter().map(|j| j.g.to_vec()).collect()
}

/// [`jets_jacobian`] written into rows of `a` (see [`LatentProcess::write_jacobian`]).
pub(crate) fn write_jets_jacobian<const N: usize, const H: bool>(
    jets: &[Jet<N, H>],
    a: &mut [f64],
    stride: usize,
    col: usize,
) {
    for (j, jet) in jets.iter().enumerate() {
        a[j * stride + col..j * stride + col + N].copy_from_slice(&jet.g);
    }
}

/// A one-parameter process's Jacobian `d(m)` at the half-widths, written into column `col` of
/// `a` (see [`LatentProcess::write_jacobian`]).
pub(crate) fn write_scalar_jacobian(
    levels: usize,
    a: &mut [f64],
    stride: usize,
    col: usize,
    d: impl Fn(f64) -> f64,
) {
    for (j, m) in half_widths(levels).enumerate() {
        a[j * stride + col] = d(m);
    }
}

/// Hessian blocks from jets.
pub(crate) fn jets_hessian<const N: usize>(jets: &[Jet<N>]) -> Vec<Vec<Vec<f64>>> {
    jets.iter()
        .map(|j| j.h.iter().map(|r| r.to_vec()).collect())
        .collect()
}

/// A second-order forward-mode jet: value, gradient and Hessian with respect to `N` parameters.
/// Arithmetic on jets gives exact derivatives of whatever formula is evaluated (no differencing).
/// With `H = false` the Hessian is not propagated (it stays zero): a Jacobian costs less than
/// half as much, and the value and gradient are computed by the very same operations, so they
/// are the same bits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Jet<const N: usize, const H: bool = true> {
    /// Value.
    pub(crate) v: f64,
    /// Gradient.
    pub(crate) g: [f64; N],
    /// Hessian.
    pub(crate) h: [[f64; N]; N],
}

impl<const N: usize, const H: bool> Jet<N, H> {
    /// A constant.
    pub(crate) fn c(v: f64) -> Self {
        Self {
            v,
            g: [0.0; N],
            h: [[0.0; N]; N],
        }
    }
    /// The `k`-th independent variable at value `v`.
    pub(crate) fn var(v: f64, k: usize) -> Self {
        let mut s = Self::c(v);
        if k < N {
            s.g[k] = 1.0;
        }
        s
    }
    /// `f(self)` given `f`, `f'`, `f''` at `self.v`.
    pub(crate) fn chain(self, f0: f64, f1: f64, f2: f64) -> Self {
        let mut out = Self::c(f0);
        for a in 0..N {
            out.g[a] = f1 * self.g[a];
            if H {
                for b in 0..N {
                    out.h[a][b] = f1 * self.h[a][b] + f2 * self.g[a] * self.g[b];
                }
            }
        }
        out
    }
    /// `exp`.
    pub(crate) fn exp(self) -> Self {
        let e = self.v.exp();
        self.chain(e, e, e)
    }
    /// `exp(x) - 1`, accurate near 0.
    pub(crate) fn exp_m1(self) -> Self {
        let e = self.v.exp();
        self.chain(self.v.exp_m1(), e, e)
    }
    /// Natural logarithm.
    pub(crate) fn ln(self) -> Self {
        let v = self.v;
        self.chain(v.ln(), 1.0 / v, -1.0 / (v * v))
    }
    /// Integer power.
    pub(crate) fn powi(self, n: i32) -> Self {
        let v = self.v;
        let nf = f64::from(n);
        let d1 = if n == 0 { 0.0 } else { nf * v.powi(n - 1) };
        let d2 = if n <= 1 {
            0.0
        } else {
            nf * (nf - 1.0) * v.powi(n - 2)
        };
        self.chain(v.powi(n), d1, d2)
    }
    /// `1 / x`.
    pub(crate) fn recip(self) -> Self {
        let v = self.v;
        self.chain(1.0 / v, -1.0 / (v * v), 2.0 / (v * v * v))
    }
    /// Multiplies by a constant.
    pub(crate) fn scale(self, s: f64) -> Self {
        let mut out = self;
        out.v *= s;
        for a in 0..N {
            out.g[a] *= s;
            if H {
                for b in 0..N {
                    out.h[a][b] *= s;
                }
            }
        }
        out
    }
}

impl<const N: usize, const H: bool> std::ops::Add for Jet<N, H> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        let mut out = self;
        out.v += o.v;
        for a in 0..N {
            out.g[a] += o.g[a];
            if H {
                for b in 0..N {
                    out.h[a][b] += o.h[a][b];
                }
            }
        }
        out
    }
}

impl<const N: usize, const H: bool> std::ops::Add<f64> for Jet<N, H> {
    type Output = Self;
    fn add(self, o: f64) -> Self {
        let mut out = self;
        out.v += o;
        out
    }
}

impl<const N: usize, const H: bool> std::ops::Neg for Jet<N, H> {
    type Output = Self;
    fn neg(self) -> Self {
        self.scale(-1.0)
    }
}

impl<const N: usize, const H: bool> std::ops::Sub for Jet<N, H> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        self + (-o)
    }
}

impl<const N: usize, const H: bool> std::ops::Sub<f64> for Jet<N, H> {
    type Output = Self;
    fn sub(self, o: f64) -> Self {
        self + (-o)
    }
}

impl<const N: usize, const H: bool> std::ops::Mul for Jet<N, H> {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        let mut out = Self::c(self.v * o.v);
        for a in 0..N {
            out.g[a] = self.g[a] * o.v + self.v * o.g[a];
            if H {
                for b in 0..N {
                    out.h[a][b] = self.h[a][b] * o.v
                        + self.v * o.h[a][b]
                        + self.g[a] * o.g[b]
                        + self.g[b] * o.g[a];
                }
            }
        }
        out
    }
}

impl<const N: usize, const H: bool> std::ops::Mul<f64> for Jet<N, H> {
    type Output = Self;
    fn mul(self, o: f64) -> Self {
        self.scale(o)
    }
}

impl<const N: usize, const H: bool> std::ops::Div for Jet<N, H> {
    type Output = Self;
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn div(self, o: Self) -> Self {
        self * o.recip()
    }
}

impl<const N: usize, const H: bool> std::ops::Div<f64> for Jet<N, H> {
    type Output = Self;
    fn div(self, o: f64) -> Self {
        self.scale(1.0 / o)
    }
}

/// `1 - x` for a jet.
pub(crate) fn one_minus<const N: usize, const H: bool>(x: Jet<N, H>) -> Jet<N, H> {
    -x + 1.0
}

#[cfg(test)]
mod add_wv_tests {
    use super::*;

    /// One process of every kind with its own hot-path overrides, and ARMA for the defaults.
    fn sample_processes() -> Vec<Process> {
        vec![
            Wn::new(2.0).unwrap().into(),
            Qn::new(0.5).unwrap().into(),
            Rw::new(1e-3).unwrap().into(),
            Dr::new(0.01).unwrap().into(),
            Ar1::new(0.97, 0.2).unwrap().into(),
            Ar1::new(-0.4, 0.2).unwrap().into(),
            Gm::new(0.25, 7e-9, 250.0).unwrap().into(),
            Arma::new(vec![0.5], vec![0.3], 1.0).unwrap().into(),
        ]
    }

    /// `add_wv` (the hot path) adds exactly what `wv` returns, for every process kind with an
    /// override and for the default (ARMA).
    #[test]
    fn add_wv_adds_wv() {
        for p in &sample_processes() {
            let wv = p.wv(18);
            let mut out = vec![1.0; 18];
            p.add_wv(&mut out);
            for (j, (a, b)) in out.iter().zip(&wv).enumerate() {
                // the f64 AR1 loop and the jets agree to ~1e-13 (ar1 tests); the others exactly
                assert!(
                    (a - 1.0 - b).abs() <= 1e-12 * (1.0 + b.abs()),
                    "{p:?} level {}: {a} vs 1 + {b}",
                    j + 1
                );
            }
        }
    }

    /// `write_jacobian` (the fit's hot path, first-order jets) writes the very bits of
    /// `jacobian`, and those are the gradients of the second-order jets the Hessian uses.
    #[test]
    fn write_jacobian_writes_the_jacobian_bit_for_bit() {
        let mut processes = sample_processes();
        processes.push(Ar1::new(0.999_99, 0.2).unwrap().into());
        let levels = 22;
        for p in &processes {
            let jac = p.jacobian(levels);
            let k = jac[0].len();
            // two columns either side, to see that nothing else is written
            let stride = k + 4;
            let mut a = vec![f64::NAN; levels * stride];
            p.write_jacobian(levels, &mut a, stride, 2);
            for (j, row) in jac.iter().enumerate() {
                for c in 0..stride {
                    let got = a[j * stride + c];
                    if (2..2 + k).contains(&c) {
                        assert_eq!(got.to_bits(), row[c - 2].to_bits(), "{p:?} level {}", j + 1);
                    } else {
                        assert!(got.is_nan(), "{p:?} wrote column {c}");
                    }
                }
            }
        }
        // first-order jets: the value and gradient of the second-order ones, bit for bit
        let first = jet_levels::<2, false>([0.97, 0.2], levels, |v, m| {
            ar1::ar1_wv_jet(v[0], None, v[1], m)
        });
        let second = jet_levels::<2, true>([0.97, 0.2], levels, |v, m| {
            ar1::ar1_wv_jet(v[0], None, v[1], m)
        });
        for (f, s) in first.iter().zip(&second) {
            assert_eq!(f.v.to_bits(), s.v.to_bits());
            assert_eq!(f.g.map(f64::to_bits), s.g.map(f64::to_bits));
            assert_eq!(f.h, [[0.0; 2]; 2]);
        }
    }
}
