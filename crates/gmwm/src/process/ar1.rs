//! AR1 and Gauss–Markov processes (docs/methods.md §0.2, §4.2, §4.3, §4.5, §4.6).
//!
//! # Numerically stable evaluation
//! The closed form of §4.2, written with `m = tau/2`, is
//! `nu2 = sigma2 B / (2 m^2 (1-phi)^3 (1+phi))`, `B = m (1-phi^2) - phi (1-a)(3-a)`, `a = phi^m`.
//! `B` vanishes like `(1-phi)^3`: for `phi` near 1 its two terms cancel. With `L = -ln phi > 0`
//! and `x = m L`, expanding every exponential gives the convergent series
//! `B = sum_{k>=3} (-1)^k L^k p_k(m) / k!`, `p_k(m) = 4 (1+m)^k - (1+2m)^k - 2^k m - 3`
//! (the terms `k = 0, 1, 2` vanish identically), so
//! `nu2 = sigma2 G(L) R(L) / (2 m^2)` with `G = B / L^3 = sum_{k>=3} (-1)^k p_k(m) L^{k-3} / k!`
//! and `R = (L / (1 - e^{-L}))^3 / (1 + e^{-L})`. Used when `x < 1/2`; otherwise the closed form
//! is evaluated with `exp_m1` (its condition number there is below ~12). Derivatives are exact
//! derivatives of this evaluation (forward-mode jets), so they inherit its accuracy.

use super::draw::Draw;
use super::{
    ChainSlot, CovariancePart, Markov, MarkovForms, ParamTransform, Physical, ProcessKind, Role,
    UnitShape, BASE,
};
use crate::math::elementary;
use crate::process::sampler::SimRng;
use serde::Serialize;

use super::{
    check_positive, check_unit, jet_levels, jets_hessian, jets_jacobian, one_minus, Jet,
    LatentProcess, Occurs, Params, Simulate, Spec,
};
use crate::error::ParamError;
use crate::process::sampler::{normal, Sampler};
use crate::process::ParamDomain;
use crate::process::StartMode;

/// `AR1(phi, sigma2)`: may repeat (`k*AR1()`), not with GM.
pub(crate) const AR1_SPEC: Spec = Spec {
    name: "AR1",
    syntax: "AR1()",
    params: Params::Fixed(
        &[
            ("phi", ParamDomain::UnitInterval),
            ("sigma2", ParamDomain::Variance),
        ],
        (1, 0),
    ),
    orders: None,
    occurs: Occurs::Repeats,
    build: |_, v, _| Ok(Ar1::new(v[0], v[1])?.into()),
    role: Role::Correlated,
    transforms: |_, preset| vec![preset.unit_coefficient(), ParamTransform::Log],
    chain: Some(|_| ChainSlot::Phi),
    draw: |d, _, given, out| draw_markov(d, false, given, out),
    unit_shapes: |levels, _| unit_shapes(levels, |phi| phi),
    markov: Some(Markov {
        ar1: |v, _| Ar1 {
            phi: v[0],
            sigma2: v[1],
        },
        from_ar1: |a, _| Some(vec![a.phi, a.sigma2]),
        correlation_time_s: |v, freq_hz| {
            let phi = v[0];
            if phi > 0.0 {
                -1.0 / (elementary::log(phi) * freq_hz)
            } else {
                0.0
            }
        },
        forms: ar1_forms,
    }),
    physical: |v, freq_hz, u| markov_physical(v, freq_hz, u, ar1_forms),
    ..BASE
};

/// `GM(beta, sigma2_gm)` at the model's sampling rate: may repeat (`k*GM()`), not with AR1.
pub(crate) const GM_SPEC: Spec = Spec {
    name: "GM",
    syntax: "GM()",
    params: Params::Fixed(
        &[
            ("beta", ParamDomain::Rate),
            ("sigma2_gm", ParamDomain::Variance),
        ],
        (0, 0),
    ),
    orders: None,
    occurs: Occurs::Repeats,
    build: |_, v, freq_hz| Ok(Gm::new(v[0], v[1], freq_hz)?.into()),
    role: Role::Correlated,
    reparametrises: Some(ProcessKind::Ar1),
    needs_rate: true,
    transforms: |_, _| vec![ParamTransform::Log, ParamTransform::Log],
    chain: Some(ChainSlot::Beta),
    draw: |d, _, given, out| draw_markov(d, true, given, out),
    unit_shapes: |levels, freq_hz| unit_shapes(levels, |phi| -elementary::log(phi) * freq_hz),
    markov: Some(Markov {
        ar1: |v, freq_hz| {
            Gm {
                beta: v[0],
                sigma2_gm: v[1],
                freq_hz,
            }
            .to_ar1()
        },
        from_ar1: |a, freq_hz| {
            let gm = a.to_gm(freq_hz).ok()?;
            Some(vec![gm.beta, gm.sigma2_gm])
        },
        correlation_time_s: |v, _| 1.0 / v[0],
        forms: gm_forms,
    }),
    physical: |v, freq_hz, u| markov_physical(v, freq_hz, u, gm_forms),
    ..BASE
};

/// docs/methods.md §4.3: `(phi, sigma2, beta, sigma2_gm)` of an AR1 `[phi, sigma2]`.
fn ar1_forms(v: &[f64], freq_hz: f64) -> (f64, f64, f64, f64) {
    let dt = 1.0 / freq_hz;
    let (a, b) = (v[0], v[1]);
    (a, b, -elementary::log(a) / dt, b / (1.0 - a * a))
}

/// docs/methods.md §4.3: `(phi, sigma2, beta, sigma2_gm)` of a GM `[beta, sigma2_gm]`.
fn gm_forms(v: &[f64], freq_hz: f64) -> (f64, f64, f64, f64) {
    let dt = 1.0 / freq_hz;
    let (a, b) = (v[0], v[1]);
    (
        elementary::exp(-a * dt),
        -b * elementary::expm1(-2.0 * a * dt),
        a,
        b,
    )
}

/// The physical read-off of an AR1 or GM (docs/methods.md §14) from its two forms
/// (`forms`): correlation time `1 / beta`, stationary standard deviation `sqrt(sigma2_gm)`
/// and driving-noise density `sqrt(2 beta sigma2_gm)`; none without both values.
fn markov_physical(v: &[f64], freq_hz: f64, u: &str, forms: MarkovForms) -> Vec<Physical> {
    if v.len() < 2 {
        return Vec::new();
    }
    let (_, _, beta, sigma2_gm) = forms(v, freq_hz);
    vec![
        ("correlation_time", 1.0 / beta, "s".to_string()),
        ("gm_std", sigma2_gm.sqrt(), u.to_string()),
        (
            "driving_noise_density",
            (2.0 * beta * sigma2_gm).sqrt(),
            format!("{u}*sqrt(Hz)"),
        ),
    ]
}

/// The unit shapes of a correlated kind for `crate::fit::revive`: correlation lengths
/// `2^((m - 2) / 2)` samples, 0.5 to `2^(J + 1)`, the first parameter from `phi` by `first`.
fn unit_shapes(levels: usize, first: impl Fn(f64) -> f64) -> Vec<UnitShape> {
    (0..=2 * levels + 4)
        .map(|m| {
            let length = elementary::pow(2f64, (m as f64 - 2.0) / 2.0);
            let phi = elementary::exp(-1.0 / length);
            (vec![first(phi), 1.0], (|t| t) as fn(f64) -> f64)
        })
        .collect()
}

/// docs/methods.md §6.3 condition 1: `phi = (1 - sqrt(1 - 3U)) / 5` for `U` in `[0, 1/3]`
/// (0 at `U = 0`, 0.2 at `U = 1/3`).
pub(crate) fn condition1_phi(u: f64) -> f64 {
    (1.0 - (1.0 - 3.0 * u).max(0.0).sqrt()) / 5.0
}

/// docs/methods.md §6.3 condition 3: `phi = last_phi + (0.999995 - last_phi) sqrt(1 - 3U)` for `U`
/// in `[0, 1/3]`.
pub(crate) fn condition3_phi(u: f64, last_phi: f64) -> f64 {
    last_phi + (PHI_MAX - last_phi) * (1.0 - 3.0 * u).max(0.0).sqrt()
}

/// docs/methods.md §6.3 for an AR1 (`gm` false) or a GM: the `phi` of the component's
/// condition (1: fast, 2: in (0.9, PHI_MAX), 3+: above the last), a variance share of the
/// total (all of it for the first, up to 1% for the others); GM converted from the AR1 draw
/// with the rate; given values kept.
fn draw_markov(d: &mut Draw<'_>, gm: bool, g: &[Option<f64>], theta: &mut Vec<f64>) {
    d.condition += 1;
    let freq_hz = d.ctx.freq_hz;
    let given_phi = g[0].map(|v| if gm { elementary::exp(-v / freq_hz) } else { v });
    let phi = given_phi.unwrap_or_else(|| match d.condition {
        1 => condition1_phi(d.unif(0.0, 1.0 / 3.0)),
        2 => {
            let lo = d.last_phi.max(0.9);
            d.unif(lo, PHI_MAX)
        }
        _ => {
            let u = d.unif(0.0, 1.0 / 3.0);
            condition3_phi(u, d.last_phi)
        }
    });
    let v = 1.0 - phi * phi;
    let st = d.ctx.sigma2_t;
    let sigma2 = if d.condition == 1 {
        d.unif(st * v / 2.0, st * v)
    } else {
        d.unif(0.0, 0.01 * st * v)
    };
    d.last_phi = phi;
    if gm {
        theta.push(g[0].unwrap_or(-elementary::log(phi) * freq_hz));
        theta.push(g[1].unwrap_or(sigma2 / v));
    } else {
        theta.push(phi);
        theta.push(g[1].unwrap_or(sigma2));
    }
}

/// Upper end of the AR1 phi draws (docs/methods.md §6.3).
pub(crate) const PHI_MAX: f64 = 0.999995;

/// Below this `x = m L = -m ln(phi)` the series of the module doc is used: there the closed form
/// loses about `-2 log10(x)` digits, the series (terms bounded by `1.5^k/k!`) none.
const SERIES_BELOW_X: f64 = 0.5;
/// Series terms of `G`: at `t = (1+2m) L <= 1.5` the omitted term is below `1.5^40/40! ~ 1e-41`.
const G_TERMS: usize = 40;
/// Series terms of `(1 - e^{-L})/L` for `L < 0.5`: omitted term below `0.5^20/21! ~ 2e-26`.
const E_TERMS: usize = 20;

/// First-order autoregression `x_t = phi x_{t-1} + w_t`, `Var w_t = sigma2`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Ar1 {
    /// Autoregressive coefficient, `|phi| < 1`.
    pub(crate) phi: f64,
    /// Innovation variance per sample.
    pub(crate) sigma2: f64,
}

impl Ar1 {
    /// Autoregressive coefficient, `|phi| < 1`.
    pub fn phi(&self) -> f64 {
        self.phi
    }
    /// Innovation variance per sample.
    pub fn sigma2(&self) -> f64 {
        self.sigma2
    }
}

/// Gauss–Markov process: an AR1 parametrised by its inverse correlation time `beta` (1/s) and
/// stationary variance `sigma2_gm` at sampling rate `freq_hz` (docs/methods.md §4.3).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Gm {
    /// Inverse correlation time in 1/s, `> 0`.
    pub(crate) beta: f64,
    /// Stationary variance, `> 0`.
    pub(crate) sigma2_gm: f64,
    /// Sampling rate in Hz, `> 0`.
    pub(crate) freq_hz: f64,
}

impl Gm {
    /// Inverse correlation time in 1/s, `> 0`.
    pub fn beta(&self) -> f64 {
        self.beta
    }
    /// Stationary variance, `> 0`.
    pub fn sigma2_gm(&self) -> f64 {
        self.sigma2_gm
    }
    /// Sampling rate in Hz, `> 0`.
    pub fn freq_hz(&self) -> f64 {
        self.freq_hz
    }
}

impl Ar1 {
    /// Builds an AR1.
    ///
    /// # Errors
    /// [`ParamError`] naming `phi` unless `|phi| < 1` (stationarity), or `sigma2` unless finite
    /// and `> 0`.
    pub fn new(phi: f64, sigma2: f64) -> Result<Self, ParamError> {
        check_unit("phi", phi, "|phi| < 1 for a stationary AR1")?;
        check_positive("sigma2", sigma2)?;
        Ok(Self { phi, sigma2 })
    }

    /// docs/methods.md §4.3: the Gauss–Markov parametrisation at `freq_hz`:
    /// `beta = -ln(phi) freq`, `sigma2_gm = sigma2 / (1 - phi^2)`.
    ///
    /// # Errors
    /// [`ParamError`] naming `phi` unless `0 < phi < 1` (a GM has positive correlation), or
    /// `freq_hz` unless finite and `> 0`.
    pub(crate) fn to_gm(self, freq_hz: f64) -> Result<Gm, ParamError> {
        check_positive("freq_hz", freq_hz)?;
        if !(self.phi > 0.0 && self.phi < 1.0) {
            return Err(ParamError::new(
                "phi",
                self.phi,
                "0 < phi < 1 for a Gauss-Markov process",
            ));
        }
        let beta = -elementary::log(self.phi) * freq_hz;
        let sigma2_gm = self.sigma2 / ((1.0 - self.phi) * (1.0 + self.phi));
        Gm::new(beta, sigma2_gm, freq_hz)
    }
}

impl Gm {
    /// Builds a Gauss–Markov process.
    ///
    /// # Errors
    /// [`ParamError`] naming `beta`, `sigma2_gm` or `freq_hz` unless each is finite and `> 0`.
    pub fn new(beta: f64, sigma2_gm: f64, freq_hz: f64) -> Result<Self, ParamError> {
        check_positive("beta", beta)?;
        check_positive("sigma2_gm", sigma2_gm)?;
        check_positive("freq_hz", freq_hz)?;
        Ok(Self {
            beta,
            sigma2_gm,
            freq_hz,
        })
    }

    /// docs/methods.md §4.3: the equivalent per-sample AR1: `phi = exp(-beta dt)`,
    /// `sigma2 = sigma2_gm (1 - exp(-2 beta dt))`, `dt = 1/freq_hz`.
    pub(crate) fn to_ar1(self) -> Ar1 {
        let l = self.beta / self.freq_hz;
        Ar1 {
            phi: elementary::exp(-l),
            sigma2: self.sigma2_gm * -elementary::expm1(-2.0 * l),
        }
    }
}

/// docs/methods.md §4.2 (AR1 row), stable form of the module doc, at half-width `m`.
///
/// `lag` is `L = -ln(phi)` when known exactly (GM); otherwise it is computed from `phi` when
/// `phi > 0`. For `phi <= 0` the closed form has no cancellation and is used as written.
pub(crate) fn ar1_wv_jet<const N: usize, const H: bool>(
    phi: Jet<N, H>,
    lag: Option<Jet<N, H>>,
    sigma2: Jet<N, H>,
    m: f64,
) -> Jet<N, H> {
    let lag = match lag {
        Some(l) => Some(l),
        None if phi.v > 0.0 => Some(-phi.ln()),
        None => None,
    };
    let Some(l) = lag else {
        // phi <= 0: B = m (1 - phi^2) - phi (1 - a)(3 - a), all in phi.
        let a = phi.powi(m as i32);
        let b = one_minus(phi * phi) * m - phi * one_minus(a) * (-a + 3.0);
        let d = one_minus(phi).powi(3) * (phi + 1.0) * (2.0 * m * m);
        return sigma2 * b / d;
    };
    let x = m * l.v;
    if x < SERIES_BELOW_X {
        sigma2 * series_g(l, m) * series_r(l) / (2.0 * m * m)
    } else {
        let one_m_phi = -(-l).exp_m1();
        let phi_e = (-l).exp();
        let one_m_a = -(-l * m).exp_m1();
        let one_m_phi2 = -(-l * 2.0).exp_m1();
        let b = one_m_phi2 * m - phi_e * one_m_a * (one_m_a + 2.0);
        let d = one_m_phi.powi(3) * (phi_e + 1.0) * (2.0 * m * m);
        sigma2 * b / d
    }
}

/// `G(L) = B / L^3` as the series of the module doc, evaluated in `t = (1+2m) L` so that no
/// power overflows: `G = sum_k d_k t^{k-3}`,
/// `d_k = (-1)^k (1+2m)^3 / k! * (4 r1^k - 1 - m r2^k - 3 r0^k)` with `r1 = (1+m)/(1+2m)`,
/// `r2 = 2/(1+2m)`, `r0 = 1/(1+2m)`.
fn series_g<const N: usize, const H: bool>(l: Jet<N, H>, m: f64) -> Jet<N, H> {
    let q = 1.0 + 2.0 * m;
    let d = g_coefficients_at(m);
    let d = &*d;
    let t = l * q;
    // Truncate where the terms, divided by t^2, fall below 1e-17 of the leading one: the value,
    // first and second derivatives then all keep their full precision (each derivative in t
    // costs at most a factor k / t on the neglected terms).
    let tv = t.v.abs();
    let mut last = G_TERMS - 1;
    let mut tk = 1.0;
    for (k, dk) in d.iter().enumerate() {
        if k >= 4 && (dk * tk).abs() <= 1e-17 * d[0].abs() * tv * tv {
            last = k;
            break;
        }
        tk *= tv;
    }
    // Horner from the highest kept term.
    let mut acc = Jet::c(d[last]);
    for k in (0..last).rev() {
        acc = acc * t + d[k];
    }
    acc
}

/// Levels whose coefficients [`g_coefficients_at`] keeps: half-widths `m = 2^0 .. 2^63`.
const G_TABLE_LEVELS: usize = 64;

/// The coefficients of [`g_coefficients`] at every level's half-width, computed once: the
/// same operations, so the same bits, without their dozens of multiplications and a division
/// per term on every evaluation (the series branch was most of an AR1's implied WV in the
/// starting-value search).
static G_TABLE: std::sync::OnceLock<Vec<[f64; G_TERMS]>> = std::sync::OnceLock::new();

/// The [`G_TERMS`] coefficients of [`g_coefficients`] at `m`: from [`G_TABLE`] when `m` is a
/// level's half-width `2^e`, `e < G_TABLE_LEVELS`, else computed.
fn g_coefficients_at(m: f64) -> std::borrow::Cow<'static, [f64; G_TERMS]> {
    let bits = m.to_bits();
    let exponent = (bits >> 52) as i64 - 1023;
    let power_of_two = m > 0.0 && bits & ((1u64 << 52) - 1) == 0;
    if power_of_two && (0..G_TABLE_LEVELS as i64).contains(&exponent) {
        let table = G_TABLE.get_or_init(|| {
            (0..G_TABLE_LEVELS)
                .map(|e| computed_g_coefficients(f64::from_bits((e as u64 + 1023) << 52)))
                .collect()
        });
        std::borrow::Cow::Borrowed(&table[exponent as usize])
    } else {
        std::borrow::Cow::Owned(computed_g_coefficients(m))
    }
}

/// [`g_coefficients`] collected.
fn computed_g_coefficients(m: f64) -> [f64; G_TERMS] {
    let mut d = [0.0; G_TERMS];
    for (dk, c) in d.iter_mut().zip(g_coefficients(m)) {
        *dk = c;
    }
    d
}

/// The coefficients `d_0, d_1, ...` ([`G_TERMS`] of them) of the series of [`series_g`].
fn g_coefficients(m: f64) -> impl Iterator<Item = f64> {
    let q = 1.0 + 2.0 * m;
    let (r0, r1, r2) = (1.0 / q, (1.0 + m) / q, 2.0 / q);
    let q3 = q * q * q;
    let (mut fact, mut p0, mut p1, mut p2) = (1.0, 1.0, 1.0, 1.0);
    (1..G_TERMS + 3).filter_map(move |k| {
        fact *= k as f64;
        p0 *= r0;
        p1 *= r1;
        p2 *= r2;
        (k >= 3).then(|| {
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            sign * q3 / fact * (4.0 * p1 - 1.0 - m * p2 - 3.0 * p0)
        })
    })
}

/// `R(L) = 1 / (E(L)^3 (1 + e^{-L}))`, `E(L) = (1 - e^{-L})/L = sum_k (-L)^k/(k+1)!`.
fn series_r<const N: usize, const H: bool>(l: Jet<N, H>) -> Jet<N, H> {
    let mut coef = [0.0; E_TERMS];
    let mut fact = 1.0;
    for (k, c) in coef.iter_mut().enumerate() {
        fact *= (k + 1) as f64;
        *c = if k % 2 == 0 { 1.0 } else { -1.0 } / fact;
    }
    let mut e = Jet::c(coef[E_TERMS - 1]);
    for k in (0..E_TERMS - 1).rev() {
        e = e * l + coef[k];
    }
    (e.powi(3) * ((-l).exp() + 1.0)).recip()
}

/// Plain-`f64` twin of [`ar1_wv_jet`] over all levels at once, added into `out` (level `j`
/// at `out[j-1]`): the constants of the closed form and `R(L)` are computed once, and
/// `1 - phi^m` follows the exact recurrence `1 - phi^{2m} = (1 - phi^m)(2 - (1 - phi^m))`
/// (no cancellation, a few ulps over 60 levels), so a level costs a handful of flops; the
/// series of `G` stops at its first term below `1e-17` of the sum. Needs `phi > 0`.
pub(crate) fn ar1_add_wv(phi: f64, lag: Option<f64>, sigma2: f64, out: &mut [f64]) {
    let l = lag.unwrap_or_else(|| -elementary::log(phi));
    let phi_e = elementary::exp(-l);
    let one_m_phi = -elementary::expm1(-l);
    let one_m_phi2 = -elementary::expm1(-2.0 * l);
    let d0 = one_m_phi * one_m_phi * one_m_phi * (phi_e + 1.0) * 2.0;
    let mut r_series = f64::NAN;
    let mut one_m_a = one_m_phi;
    let mut m = 1.0;
    for o in out.iter_mut() {
        let x = m * l;
        *o += if x < SERIES_BELOW_X {
            if r_series.is_nan() {
                r_series = series_r(Jet::<0>::c(l)).v;
            }
            sigma2 * series_g_f64(l, m) * r_series / (2.0 * m * m)
        } else {
            let b = one_m_phi2 * m - phi_e * one_m_a * (one_m_a + 2.0);
            sigma2 * b / (d0 * m * m)
        };
        one_m_a *= 2.0 - one_m_a;
        m *= 2.0;
    }
}

/// [`series_g`] in plain `f64`, summed forward and stopped at the first term below `1e-17` of
/// the sum (at most [`G_TERMS`] terms).
fn series_g_f64(l: f64, m: f64) -> f64 {
    let t = l * (1.0 + 2.0 * m);
    let mut tp = 1.0;
    let mut acc = 0.0;
    for (k, &d) in g_coefficients_at(m).iter().enumerate() {
        let term = d * tp;
        acc += term;
        if k > 2 && term.abs() <= 1e-17 * acc.abs() {
            break;
        }
        tp *= t;
    }
    acc
}

/// AR1 spectral density `sigma2 / ((1-phi)^2 + 4 phi sin^2(pi f))` (docs/methods.md §1.9), the same
/// as `sigma2 / (1 - 2 phi cos 2 pi f + phi^2)` without its cancellation at `f = 0`.
pub(crate) fn ar1_spectrum(one_m_phi: f64, phi: f64, sigma2: f64, f: f64) -> f64 {
    let s = elementary::sin(std::f64::consts::PI * f);
    sigma2 / (one_m_phi * one_m_phi + 4.0 * phi * s * s)
}

impl Ar1 {
    fn jets<const H: bool>(&self, levels: usize) -> Vec<Jet<2, H>> {
        jet_levels([self.phi, self.sigma2], levels, |v, m| {
            ar1_wv_jet(v[0], None, v[1], m)
        })
    }
}

impl LatentProcess for Ar1 {
    fn name(&self) -> &'static str {
        AR1_SPEC.name
    }
    fn param_names(&self) -> Vec<&'static str> {
        AR1_SPEC.fixed_names()
    }
    fn params(&self) -> Vec<f64> {
        vec![self.phi, self.sigma2]
    }
    fn wv(&self, levels: usize) -> Vec<f64> {
        let mut out = vec![0.0; levels];
        self.add_wv(&mut out);
        out
    }
    fn add_wv(&self, out: &mut [f64]) {
        if self.phi > 0.0 {
            ar1_add_wv(self.phi, None, self.sigma2, out);
        } else {
            let jets = jet_levels::<0, false>([], out.len(), |_, m| {
                ar1_wv_jet(Jet::c(self.phi), None, Jet::c(self.sigma2), m)
            });
            for (o, j) in out.iter_mut().zip(jets) {
                *o += j.v;
            }
        }
    }
    fn jacobian(&self, levels: usize) -> Vec<Vec<f64>> {
        jets_jacobian(&self.jets::<false>(levels))
    }
    fn write_jacobian(&self, levels: usize, a: &mut [f64], stride: usize, col: usize) {
        super::write_jets_jacobian(&self.jets::<false>(levels), a, stride, col);
    }
    fn hessian(&self, levels: usize) -> Vec<Vec<Vec<f64>>> {
        jets_hessian(&self.jets::<true>(levels))
    }
    fn spectral_density(&self, f: f64) -> Option<f64> {
        Some(ar1_spectrum(1.0 - self.phi, self.phi, self.sigma2, f))
    }
}

impl Gm {
    /// Jets in `(beta, sigma2_gm)` through the exact conversion of §4.3 (chain rule included).
    fn jets<const H: bool>(&self, levels: usize) -> Vec<Jet<2, H>> {
        let dt = 1.0 / self.freq_hz;
        jet_levels([self.beta, self.sigma2_gm], levels, |v, m| {
            let l = v[0] * dt;
            let phi = (-l).exp();
            let sigma2 = v[1] * -(-l * 2.0).exp_m1();
            ar1_wv_jet(phi, Some(l), sigma2, m)
        })
    }
}

impl LatentProcess for Gm {
    fn name(&self) -> &'static str {
        GM_SPEC.name
    }
    fn param_names(&self) -> Vec<&'static str> {
        GM_SPEC.fixed_names()
    }
    fn params(&self) -> Vec<f64> {
        vec![self.beta, self.sigma2_gm]
    }
    fn wv(&self, levels: usize) -> Vec<f64> {
        let mut out = vec![0.0; levels];
        self.add_wv(&mut out);
        out
    }
    fn add_wv(&self, out: &mut [f64]) {
        let l = self.beta / self.freq_hz;
        let sigma2 = self.sigma2_gm * -elementary::expm1(-2.0 * l);
        ar1_add_wv(elementary::exp(-l), Some(l), sigma2, out);
    }
    fn jacobian(&self, levels: usize) -> Vec<Vec<f64>> {
        jets_jacobian(&self.jets::<false>(levels))
    }
    fn write_jacobian(&self, levels: usize, a: &mut [f64], stride: usize, col: usize) {
        super::write_jets_jacobian(&self.jets::<false>(levels), a, stride, col);
    }
    fn hessian(&self, levels: usize) -> Vec<Vec<Vec<f64>>> {
        jets_hessian(&self.jets::<true>(levels))
    }
    fn spectral_density(&self, f: f64) -> Option<f64> {
        let l = self.beta / self.freq_hz;
        let ar = self.to_ar1();
        Some(ar1_spectrum(-elementary::expm1(-l), ar.phi, ar.sigma2, f))
    }
}

/// docs/methods.md §10.1: `x_t = phi x_{t-1} + w_t`, `w ~ N(0, sigma2)`, evaluated four samples at
/// a time so that the recursion's latency is paid once per four: within the block of samples
/// `4k .. 4k + 3`, `x_{4k+i} = phi^(i+1) x_{4k-1} + a_i` with `a_0 = w_{4k}` and
/// `a_i = phi a_{i-1} + w_{4k+i}`, the partial sums `a` not depending on the block's start.
/// Blocks are fixed by the sample index, not by the chunks asked for, so any chunking gives the
/// same bits.
#[derive(Debug, Clone)]
pub(crate) struct Ar1Sampler {
    rng: SimRng,
    /// `phi, phi^2, phi^3, phi^4`.
    powers: [f64; 4],
    sd: f64,
    /// `x` before the current block.
    start: f64,
    /// The partial sum `a` of the current block.
    partial: f64,
    /// Position in the current block, 0..4.
    at: usize,
}

impl Ar1Sampler {
    /// The sampler from `x` (the value before the first sample).
    pub(crate) fn new(rng: SimRng, phi: f64, sd: f64, x: f64) -> Self {
        let p2 = phi * phi;
        Self {
            rng,
            powers: [phi, p2, p2 * phi, p2 * p2],
            sd,
            start: x,
            partial: 0.0,
            at: 0,
        }
    }

    /// The next value, one sample at a time (the same operations as a whole block).
    #[inline]
    fn one(&mut self) -> f64 {
        let w = self.sd * normal(&mut self.rng);
        self.partial = if self.at == 0 {
            w
        } else {
            self.powers[0] * self.partial + w
        };
        let x = self.powers[self.at] * self.start + self.partial;
        self.at += 1;
        if self.at == 4 {
            self.start = x;
            self.at = 0;
        }
        x
    }

    /// The next `out.len()` values, each given to `emit`.
    #[inline]
    fn run(&mut self, out: &mut [f64], emit: impl Fn(&mut f64, f64)) {
        let mut rest = out;
        while self.at != 0 && !rest.is_empty() {
            let (o, tail) = rest.split_first_mut().expect("not empty");
            emit(o, self.one());
            rest = tail;
        }
        let [phi, p2, p3, p4] = self.powers;
        let mut quads = rest.chunks_exact_mut(4);
        for q in &mut quads {
            let w0 = self.sd * normal(&mut self.rng);
            let w1 = self.sd * normal(&mut self.rng);
            let w2 = self.sd * normal(&mut self.rng);
            let w3 = self.sd * normal(&mut self.rng);
            let a1 = phi * w0 + w1;
            let a2 = phi * a1 + w2;
            let a3 = phi * a2 + w3;
            let x = self.start;
            emit(&mut q[0], phi * x + w0);
            emit(&mut q[1], p2 * x + a1);
            emit(&mut q[2], p3 * x + a2);
            self.start = p4 * x + a3;
            emit(&mut q[3], self.start);
        }
        for o in quads.into_remainder() {
            emit(o, self.one());
        }
    }
}

impl Sampler for Ar1Sampler {
    fn add(&mut self, out: &mut [f64]) {
        self.run(out, |o, v| *o += v);
    }
    fn store(&mut self, out: &mut [f64]) {
        self.run(out, |o, v| *o = v);
    }
    fn clone_box(&self) -> Box<dyn Sampler> {
        Box::new(self.clone())
    }
}

impl Simulate for Ar1 {
    fn covariance_part(&self) -> Result<CovariancePart, ParamError> {
        let r0 = self.sigma2 / ((1.0 - self.phi) * (1.0 + self.phi));
        Ok(CovariancePart::Autoregressive {
            phi: self.phi,
            r0,
            r1: self.phi * r0,
        })
    }
    /// [`StartMode::Stationary`]: `x_{-1} ~ N(0, sigma2 / (1 - phi^2))` is drawn first, so
    /// every kept value is stationary; [`StartMode::Zero`]: `x_{-1} = 0` (the package's
    /// `x_0 = 0`, dropped).
    fn sampler(&self, mut rng: SimRng, start: StartMode) -> Result<Box<dyn Sampler>, ParamError> {
        let (phi, sigma2) = (self.phi, self.sigma2);
        let x = if start == StartMode::Stationary {
            (sigma2 / (1.0 - phi * phi)).sqrt() * normal(&mut rng)
        } else {
            0.0
        };
        Ok(Box::new(Ar1Sampler::new(rng, phi, sigma2.sqrt(), x)))
    }
}

impl Simulate for Gm {
    fn covariance_part(&self) -> Result<CovariancePart, ParamError> {
        let a = self.to_ar1();
        let r0 = a.sigma2 / ((1.0 - a.phi) * (1.0 + a.phi));
        Ok(CovariancePart::Autoregressive {
            phi: a.phi,
            r0,
            r1: a.phi * r0,
        })
    }
    /// Simulated as its exact per-sample AR1 ([`Gm::to_ar1`], docs/methods.md §4.3).
    fn sampler(&self, rng: SimRng, start: StartMode) -> Result<Box<dyn Sampler>, ParamError> {
        self.to_ar1().sampler(rng, start)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cached coefficients are the computed ones, bit for bit, at every level's half-width;
    /// another `m` is computed.
    #[test]
    fn g_table_is_the_computed_coefficients() {
        for e in 0..G_TABLE_LEVELS {
            let m = f64::from_bits((e as u64 + 1023) << 52);
            assert_eq!(m, 2f64.powi(e as i32));
            let cached = g_coefficients_at(m);
            assert!(matches!(cached, std::borrow::Cow::Borrowed(_)));
            let computed = computed_g_coefficients(m);
            assert_eq!(
                cached.map(f64::to_bits),
                computed.map(f64::to_bits),
                "m = 2^{e}"
            );
        }
        for m in [3.0, 0.5, 2f64.powi(64), 1.5] {
            let at = g_coefficients_at(m);
            assert!(matches!(at, std::borrow::Cow::Owned(_)), "{m}");
            assert_eq!(
                at.map(f64::to_bits),
                computed_g_coefficients(m).map(f64::to_bits)
            );
        }
    }

    #[test]
    fn condition_phi_ranges() {
        assert_eq!(condition1_phi(0.0), 0.0);
        assert!((condition1_phi(1.0 / 3.0) - 0.2).abs() < 1e-15);
        for k in 0..=100 {
            let u = k as f64 / 300.0;
            let p1 = condition1_phi(u);
            assert!((0.0..=0.2 + 1e-15).contains(&p1), "{p1}");
            let p3 = condition3_phi(u, 0.9);
            assert!((0.9..=PHI_MAX).contains(&p3), "{p3}");
        }
        assert!((condition3_phi(0.0, 0.9) - PHI_MAX).abs() < 1e-15);
        assert!((condition3_phi(1.0 / 3.0, 0.9) - 0.9).abs() < 1e-15);
    }

    /// The blocks of four give the recursion `x_t = phi x_{t-1} + w_t` on the same draws, to
    /// rounding (each value is a few operations off the one-step path: 1e-13 relative to the
    /// process's scale), in any chunking.
    #[test]
    fn blocked_ar1_is_the_recursion() {
        for &phi in &[-0.9, 0.5, 0.999, 1.0 - 1e-7] {
            let sd = 0.3;
            let rng = crate::process::sampler::stream(7, 0);
            let mut blocked = Ar1Sampler::new(rng.clone(), phi, sd, 1.5);
            let mut out = vec![0.0; 1003];
            let (head, tail) = out.split_at_mut(5);
            blocked.store(head);
            blocked.store(tail);
            let (mut r, mut x) = (rng, 1.5f64);
            let scale = sd / (1.0 - phi * phi).sqrt() + 1.5;
            for (t, v) in out.iter().enumerate() {
                x = phi * x + sd * normal(&mut r);
                assert!(
                    (v - x).abs() <= 1e-13 * scale,
                    "phi {phi}, t {t}: {v} vs {x}"
                );
            }
        }
    }

    /// The plain-f64 level loop agrees with the jet evaluation (the reference of the §4 tests)
    /// over phi from 0.01 to 1 - 1e-9 and 40 levels, both branches and the switch between
    /// them: relative 1e-13 (the recurrence adds a few ulps per level; the series truncation
    /// is below 1e-17).
    #[test]
    fn f64_level_loop_matches_the_jets() {
        for &phi in &[
            0.01,
            0.3,
            0.5,
            0.9,
            0.99,
            0.999,
            0.99999,
            1.0 - 1e-7,
            1.0 - 1e-9,
        ] {
            for &sigma2 in &[1e-12, 1.0] {
                let levels = 40;
                let jets = jet_levels::<0, false>([], levels, |_, m| {
                    ar1_wv_jet(Jet::c(phi), None, Jet::c(sigma2), m)
                });
                let mut out = vec![0.0; levels];
                ar1_add_wv(phi, None, sigma2, &mut out);
                for (j, (a, b)) in out.iter().zip(&jets).enumerate() {
                    let rel = (a - b.v).abs() / b.v.abs();
                    assert!(rel < 1e-13, "phi {phi} level {}: {a} vs {}", j + 1, b.v);
                }
            }
        }
        // GM: through the exact lag
        let gm = Gm::new(0.25, 7.08e-9, 250.0).unwrap();
        let fast = gm.wv(22);
        let slow: Vec<f64> = gm.jets::<true>(22).iter().map(|j| j.v).collect();
        for (a, b) in fast.iter().zip(&slow) {
            assert!((a / b - 1.0).abs() < 1e-13, "{a} vs {b}");
        }
    }
}
