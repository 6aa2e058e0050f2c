//! Flicker (1/f, bias-instability) noise `FN(b2)`: white noise of variance `b2` fractionally
//! integrated with `d = 1/2` (Hosking 1981, Kasdin 1995 power-law noise with alpha = 1).
//!
//! # The process
//! `x_t = (1 - B)^{-1/2} w_t = sum_{k>=0} psi_k w_{t-k}`, `w ~ N(0, b2)`,
//! `psi_k = Gamma(k + 1/2) / (Gamma(1/2) k!)`, with spectral density
//! `S(f) = b2 / |2 sin(pi f)|` (cycles per sample), i.e. `b2 / (2 pi |f|)` at low frequency: an
//! exact `1/f` law, one-sided `h_{-1} / f` with `h_{-1} = b2 / pi` in any time unit (the level of
//! a 1/f law does not depend on the sampling rate). At `d = 1/2` the process is not stationary
//! (its variance diverges like `ln t`) but its increments are (an FI(-1/2) process), so its
//! variogram `V(h) = (E (x_{t+h} - x_t)^2) / 2` is finite and the Haar WV, whose filter has a
//! vanishing moment, is exact and finite. Chosen over a frequency-truncated 1/f law because it
//! has a closed-form WV, no cut-off parameter and an exact (to ~1e-7) streaming simulation.
//!
//! # Implied WV (closed form, derived here)
//! `V(h) = int (1 - cos 2 pi f h) S(f) df = (2 b2 / pi) H(h)`, `H(n) = sum_{k=1}^{n} 1/(2k - 1)`
//! (the `d -> 1/2` limit of `gamma(0) (1 - rho(h))` of the FI(d) autocovariance). For a Haar
//! coefficient over `2m` samples, `nu2 = (F(2m) - 4 F(m)) / (4 m^2)` with
//! `F(n) = 2 sum_{h<n} (n - h) V(h) = (b2 / (2 pi)) ((4 n^2 - 1) H(n) - 3 n^2)`, so
//!
//! `nu2(tau = 2m) = b2 [(16 m^2 - 1) D(m) + 3 H(m)] / (8 pi m^2)`, `D(m) = H(2m) - H(m)`,
//!
//! a sum of positive terms (no cancellation). `nu2(2) = b2 / pi`; as `m -> inf`,
//! `D -> ln(2) / 2` and `nu2 -> b2 ln(2) / pi`, so the Allan variance `AV(m) = 2 nu2(2m)`
//! (docs/methods.md §3.4) has the floor `(2 ln 2 / pi) b2`: with the IEEE 952 convention
//! `sigma_floor = sqrt(2 ln 2 / pi) B = 0.664 B`, the bias instability is exactly `B = sqrt(b2)`
//! (in the data unit, at any rate). The discrete floor is approached from above: the Allan
//! deviation is 20% above it at a cluster of 1 sample, 7.4% at 2, 2.5% at 4, 0.77% at 8, 0.23%
//! at 16 and 0.07% at 32 (relative excess of `AV` ~ `(1.5 ln m + 2.8) / (8 ln(2) m^2)`).
//! `H` and `D` are summed directly for `m < 32`, else from the asymptotic series of the digamma
//! function `psi(x + 1/2) ~ ln x + 1/(24 x^2) - 7/(960 x^4) + 31/(8064 x^6) - 127/(30720 x^8)`
//! (`H(n) = (psi(n + 1/2) - psi(1/2)) / 2`), whose next term is below 1e-17 there.
//!
//! # Simulation
//! `psi_k = E[Phi^k]` for `Phi` arcsine-distributed on (0, 1) (the Beta integral
//! `psi_k = (1/pi) int_0^1 t^{k - 1/2} (1 - t)^{-1/2} dt`), so the process is a continuous
//! mixture of AR1 processes driven by the same innovations. With `t = e^{-s}`, `s = e^y`, the
//! trapezoidal rule in `y` (step `BANK_STEP`; the integrand is analytic in the strip
//! `|Im y| < pi/2`, so the error falls like `exp(-pi^2 / BANK_STEP)`, uniformly in `k`) gives a
//! bank of AR1 terms `v_i <- phi_i v_i + c_i w` with poles `s_i = e^{y_i}` from `BANK_S_MIN` to
//! `BANK_S_MAX`, plus one node that lumps the rule's nodes below `BANK_S_MIN` (their weight,
//! at their weighted mean pole; without it the bank's spectrum would be off by a relative
//! `~sqrt(BANK_S_MIN / f)`); `x = a_0 w + sum_i v_i` with `a_0 = 1 - sum c_i` makes
//! `psi_0 = 1` exact. Measured (test `flicker_bank_spectrum_is_one_over_f`): 75 nodes, the
//! bank's squared gain is `1 / |2 sin(pi f)|` to 2e-7 relative from `f = 1/2` down to
//! `f = 5e-12` cycles per sample, so the simulated law has the closed-form WV to that order at
//! every scale the engine reads. The stationary start draws the bank's state from its exact
//! stationary law (Cholesky of `Cov(v_i, v_j) = b2 c_i c_j / (1 - phi_i phi_j)`), so every
//! sample follows that law; [`StartMode::Zero`] starts the bank at 0 (the started process
//! `sum_{k<=t} psi_k w_{t-k}`, whose first samples lack the
//! slow past). Cost: 75 multiply-adds and one normal draw per sample.

use super::draw::Draw;
use super::{
    add_scaled, check_positive, half_widths, LatentProcess, Occurs, ParamTransform, Params,
    ProcessKind, Role, Simulate, Spec, BASE,
};
use crate::error::ParamError;
use crate::math::elementary;
use crate::process::sampler::{normal, Sampler, SimRng, Step};
use crate::process::ParamDomain;
use crate::process::StartMode;
use serde::Serialize;
use std::f64::consts::{LN_2, PI};

/// `FN(b2)`: may appear once in a model.
pub(crate) const SPEC: Spec = Spec {
    name: "FN",
    syntax: "FN()",
    params: Params::Fixed(&[("b2", ParamDomain::Variance)], (0, 0)),
    orders: None,
    occurs: Occurs::Once,
    build: |_, v, _| Ok(Flicker::new(v[0])?.into()),
    role: Role::Flicker,
    transforms: |_, _| vec![ParamTransform::Log],
    draw,
    unit_shapes: |_, _| vec![(vec![1.0], |t| t)],
    physical: |v, _, u| {
        vec![
            ("bias_instability", v[0].sqrt(), u.to_string()),
            (
                "allan_deviation_floor",
                (ALLAN_FLOOR_PER_B2 * v[0]).sqrt(),
                u.to_string(),
            ),
        ]
    },
    ..BASE
};

/// `2 ln(2) / pi`: the Allan variance floor of `FN(b2)` per unit `b2` (module doc), the square
/// of the IEEE 952 factor 0.664.
pub(crate) const ALLAN_FLOOR_PER_B2: f64 = 2.0 * LN_2 / PI;

/// Starting value: the flicker floor `nu2 = b2 ln(2) / pi` cannot exceed the smallest
/// empirical WV, so `b2` is drawn log-uniformly in `[1e-3, 1]` times `pi min_j nu2_j / ln 2`.
fn draw(d: &mut Draw<'_>, _: ProcessKind, given: &[Option<f64>], out: &mut Vec<f64>) {
    let floor = PI * d.ctx.wv_min / LN_2;
    out.push(given[0].unwrap_or_else(|| floor * elementary::pow(10f64, -3.0 * d.unif(0.0, 1.0))));
}

/// Flicker noise: white noise of variance `b2` fractionally integrated with `d = 1/2`; its
/// bias instability (IEEE 952) is `B = sqrt(b2)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Flicker {
    /// Innovation variance per sample, `B^2`.
    pub(crate) b2: f64,
}

impl Flicker {
    /// Builds the process.
    ///
    /// # Errors
    /// [`ParamError`] naming `b2` unless it is finite and > 0.
    pub fn new(b2: f64) -> Result<Self, ParamError> {
        check_positive("b2", b2)?;
        Ok(Self { b2 })
    }

    /// Innovation variance per sample, `B^2` (module doc).
    pub fn b2(&self) -> f64 {
        self.b2
    }

    /// The bias instability `B = sqrt(b2)` in the data unit (IEEE 952: the Allan deviation
    /// floor is `0.664 B`).
    pub fn bias_instability(&self) -> f64 {
        self.b2.sqrt()
    }
}

/// Below this half-width `H` and `D` are summed directly (at most 63 terms).
const DIRECT_BELOW: f64 = 32.0;

/// `r(x) = psi(x + 1/2) - ln x` from its asymptotic series, `x >= 32` (module doc).
fn digamma_half_rest(x: f64) -> f64 {
    let y = 1.0 / (x * x);
    y * (1.0 / 24.0 + y * (-7.0 / 960.0 + y * (31.0 / 8064.0 + y * (-127.0 / 30720.0))))
}

/// `H(n) = sum_{k=1}^{n} 1 / (2k - 1)`.
pub(crate) fn odd_harmonic(n: f64) -> f64 {
    if n < DIRECT_BELOW {
        (1..=n as u64).map(|k| 1.0 / (2 * k - 1) as f64).sum()
    } else {
        // psi(1/2) = -gamma - 2 ln 2
        0.5 * (elementary::log(n) + digamma_half_rest(n) + EULER_GAMMA + 2.0 * LN_2)
    }
}

/// `D(m) = H(2m) - H(m) = sum_{k=m+1}^{2m} 1 / (2k - 1)`, without cancellation.
fn odd_harmonic_difference(m: f64) -> f64 {
    if m < DIRECT_BELOW {
        let m = m as u64;
        (m + 1..=2 * m).map(|k| 1.0 / (2 * k - 1) as f64).sum()
    } else {
        0.5 * (LN_2 + digamma_half_rest(2.0 * m) - digamma_half_rest(m))
    }
}

/// Euler's constant.
const EULER_GAMMA: f64 = 0.577_215_664_901_532_9;

/// The implied Haar WV of `FN(1)` at `tau = 2m` (module doc):
/// `[(16 m^2 - 1) D(m) + 3 H(m)] / (8 pi m^2)`.
pub(crate) fn unit_wv(m: f64) -> f64 {
    ((16.0 * m * m - 1.0) * odd_harmonic_difference(m) + 3.0 * odd_harmonic(m)) / (8.0 * PI * m * m)
}

impl Flicker {
    /// `Var(sum_{t=1}^{n} (x_t - x_0))`, the sum of `n` samples relative to the value before
    /// them (a bias held at its start value): with the variogram `V(h) = (2 b2 / pi) H(h)`
    /// (module doc), `Cov(x_s - x_0, x_t - x_0) = V(s) + V(t) - V(|s - t|)` sums to
    /// `2 sum_{h=1}^{n} h V(h)`, and `sum_{h<=n} h H(h) = n (n + 1) H(n) / 2 - (n^2 - H(n)) / 8`
    /// (exchange the sums; `k (k - 1) / (2k - 1) = ((2k - 1) - 1 / (2k - 1)) / 4`), so
    ///
    /// `(4 b2 / pi) [n (n + 1) H(n) / 2 - (n^2 - H(n)) / 8]`, about `(b2 / pi) n^2 ln n`.
    pub(crate) fn held_sum_variance(&self, n: f64) -> f64 {
        let h = odd_harmonic(n);
        4.0 * self.b2 / PI * (0.5 * n * (n + 1.0) * h - (n * n - h) / 8.0)
    }
}

impl LatentProcess for Flicker {
    fn name(&self) -> &'static str {
        SPEC.name
    }
    fn param_names(&self) -> Vec<&'static str> {
        SPEC.fixed_names()
    }
    fn params(&self) -> Vec<f64> {
        vec![self.b2]
    }
    fn wv(&self, levels: usize) -> Vec<f64> {
        half_widths(levels).map(|m| self.b2 * unit_wv(m)).collect()
    }
    fn add_wv(&self, out: &mut [f64]) {
        add_scaled(out, self.b2, unit_wv);
    }
    fn jacobian(&self, levels: usize) -> Vec<Vec<f64>> {
        half_widths(levels).map(|m| vec![unit_wv(m)]).collect()
    }
    fn hessian(&self, levels: usize) -> Vec<Vec<Vec<f64>>> {
        half_widths(levels).map(|_| vec![vec![0.0]]).collect()
    }
    fn spectral_density(&self, f: f64) -> Option<f64> {
        Some(self.b2 / (2.0 * elementary::sin(PI * f).abs()))
    }
}

/// Step of the trapezoidal rule in `y = ln s` (module doc): 2e-7 measured.
const BANK_STEP: f64 = 0.5;
/// Slowest pole `s` (per sample) of the bank's regular nodes (module doc); slower ones are
/// lumped into one.
const BANK_S_MIN: f64 = 1e-14;
/// Fastest pole: `e^{-36}` ~ 2e-16 leaves only lag 0, which `a_0` makes exact.
const BANK_S_MAX: f64 = 36.0;

/// The bank of the module doc: `(s_i, c_i)` for every node, the lumped tail first.
pub(crate) fn bank() -> Vec<(f64, f64)> {
    let h = BANK_STEP;
    let lo = (elementary::log(BANK_S_MIN) / h).floor() as i64;
    let hi = (elementary::log(BANK_S_MAX) / h).ceil() as i64;
    // nodes s_k = s_lo e^{-k h}, k >= 1, where c = (h / pi) sqrt(s) to 1e-14: total weight
    // (h / pi) sqrt(s_lo) / (e^{h/2} - 1) at the weighted mean pole
    // s_lo (e^{h/2} - 1) / (e^{3h/2} - 1)
    let s_lo = elementary::exp(lo as f64 * h);
    let tail = (
        s_lo * elementary::expm1(0.5 * h) / elementary::expm1(1.5 * h),
        h / PI * s_lo.sqrt() / elementary::expm1(0.5 * h),
    );
    std::iter::once(tail)
        .chain((lo..=hi).map(|i| {
            let s = elementary::exp(i as f64 * h);
            // (h / pi) s e^{-s/2} (1 - e^{-s})^{-1/2}
            let c = h / PI * s * elementary::exp(-0.5 * s) / (-elementary::expm1(-s)).sqrt();
            (s, c)
        }))
        .collect()
}

/// The bank's state and coefficients (module doc). `decay[i] = 1 - phi_i`, exact for small `s`.
#[derive(Debug, Clone)]
struct FlickerSampler {
    rng: SimRng,
    sd: f64,
    a0: f64,
    decay: Vec<f64>,
    c: Vec<f64>,
    v: Vec<f64>,
}

impl Step for FlickerSampler {
    #[inline]
    fn step(&mut self) -> f64 {
        let w = self.sd * normal(&mut self.rng);
        let mut x = self.a0 * w;
        for ((v, d), c) in self.v.iter_mut().zip(&self.decay).zip(&self.c) {
            *v += c * w - d * *v;
            x += *v;
        }
        x
    }
}

/// The lower Cholesky factor of a symmetric positive semi-definite matrix (row-major, `n x n`);
/// a pivot that rounds to `<= 0` gives a zero column (the matrix's conditioning, ~1e8 here, is
/// far from that).
fn cholesky(a: &[f64], n: usize) -> Vec<f64> {
    let mut l = vec![0.0; n * n];
    for j in 0..n {
        let d = a[j * n + j] - (0..j).map(|k| l[j * n + k] * l[j * n + k]).sum::<f64>();
        if d <= 0.0 {
            continue;
        }
        let djj = d.sqrt();
        l[j * n + j] = djj;
        for i in j + 1..n {
            let s = a[i * n + j] - (0..j).map(|k| l[i * n + k] * l[j * n + k]).sum::<f64>();
            l[i * n + j] = s / djj;
        }
    }
    l
}

impl Simulate for Flicker {
    fn sampler(&self, mut rng: SimRng, start: StartMode) -> Result<Box<dyn Sampler>, ParamError> {
        let nodes = bank();
        let n = nodes.len();
        let sd = self.b2.sqrt();
        let decay: Vec<f64> = nodes.iter().map(|&(s, _)| -elementary::expm1(-s)).collect();
        let c: Vec<f64> = nodes.iter().map(|&(_, c)| c).collect();
        let a0 = 1.0 - c.iter().sum::<f64>();
        let v = match start {
            StartMode::Stationary => {
                // Cov(v_i, v_j) = c_i c_j / (1 - phi_i phi_j) per unit b2
                let mut cov = vec![0.0; n * n];
                for i in 0..n {
                    for j in 0..n {
                        let q = -elementary::expm1(-(nodes[i].0 + nodes[j].0));
                        cov[i * n + j] = c[i] * c[j] / q;
                    }
                }
                let l = cholesky(&cov, n);
                let xi: Vec<f64> = (0..n).map(|_| normal(&mut rng)).collect();
                (0..n)
                    .map(|i| sd * (0..=i).map(|k| l[i * n + k] * xi[k]).sum::<f64>())
                    .collect()
            }
            StartMode::Zero => vec![0.0; n],
        };
        Ok(Box::new(FlickerSampler {
            rng,
            sd,
            a0,
            decay,
            c,
            v,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `H` and `D`: the asymptotic series and the direct sums agree where both apply.
    #[test]
    fn flicker_series_match_direct_sums() {
        for m in [32u64, 48, 64, 100, 1000] {
            let direct_h: f64 = (1..=m).map(|k| 1.0 / (2 * k - 1) as f64).sum();
            let direct_d: f64 = (m + 1..=2 * m).map(|k| 1.0 / (2 * k - 1) as f64).sum();
            let (h, d) = (odd_harmonic(m as f64), odd_harmonic_difference(m as f64));
            assert!(
                (h - direct_h).abs() < 1e-14 * direct_h,
                "H({m}) {h} vs {direct_h}"
            );
            assert!(
                (d - direct_d).abs() < 1e-14 * direct_d,
                "D({m}) {d} vs {direct_d}"
            );
        }
    }

    /// Hand values: `nu2(2) = 1 / pi`, `nu2(4) = 0.8 / pi` (`[63 H(4) - 60 H(2)] / (32 pi)`),
    /// and the floor `ln(2) / pi`.
    #[test]
    fn flicker_wv_hand_values() {
        assert!((unit_wv(1.0) * PI - 1.0).abs() < 1e-15);
        assert!((unit_wv(2.0) * PI - 0.8).abs() < 1e-15);
        let far = unit_wv(2f64.powi(30));
        assert!((far * PI / LN_2 - 1.0).abs() < 1e-15, "{far}");
    }

    /// The bank reproduces the 1/f law: `|Psi(e^{i w})|^2 |2 sin(w / 2)| = 1` (the transfer
    /// function of `(1 - B)^{-1/2}`) to 3e-7 (2e-7 measured) from `w = pi 1e-11` to pi.
    #[test]
    fn flicker_bank_spectrum_is_one_over_f() {
        let nodes = bank();
        assert_eq!(nodes.len(), 75);
        let a0 = 1.0 - nodes.iter().map(|n| n.1).sum::<f64>();
        for k in 0..=110 {
            let w = PI * 10f64.powf(-0.1 * k as f64);
            // Psi = a0 + sum c_i / (1 - phi_i e^{-iw})
            let (mut re, mut im) = (a0, 0.0);
            for &(s, c) in &nodes {
                let phi = (-s).exp();
                let (dr, di) = (1.0 - phi * w.cos(), phi * w.sin());
                let den = dr * dr + di * di;
                re += c * dr / den;
                im -= c * di / den;
            }
            let ratio = (re * re + im * im) * 2.0 * (0.5 * w).sin();
            assert!((ratio - 1.0).abs() < 3e-7, "w {w:e}: {ratio}");
        }
    }
}
