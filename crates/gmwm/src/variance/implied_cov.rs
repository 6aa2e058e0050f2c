//! The covariance matrix `V` of the classical Haar MODWT wavelet variance implied by a model,
//! computed exactly instead of by simulation.
//!
//! `V_jk = Cov(nu2_hat_j, nu2_hat_k)` over series of length `N` drawn from the model is what the
//! parametric bootstrap of docs/methods.md §7.4 (`cov_bootstrapper`) estimates with `H` replicates;
//! this module gives its value as `H -> infinity`, with no Monte Carlo error, in `O(J^2)` work
//! independent of `N` (about 0.1 s at `N = 10^8`, `J = 26`, where 50 replicates take minutes).
//!
//! # Formulas
//! Let `S_t = x_0 + ... + x_t` and, at level `j` (`L_j = 2^j`, `H_j = L_j / 2`), the Haar MODWT
//! coefficient `W_{j,t} = (S_t - 2 S_{t-H_j} + S_{t-L_j}) / L_j` (the recent half-window's sum
//! minus the older one's, over `L_j`; kept for `t = L_j - 1 .. N - 1`, so `M_j = N - L_j + 1`
//! coefficients, docs/methods.md §1.3). The estimator is `nu2_hat_j = (1/M_j) sum_t W_{j,t}^2`.
//!
//! 1. **Covariance of the coefficients.** Write `Cov(S_x, S_y) = K(y - x) + f(x) + g(y)`: the
//!    weights `(1, -2, 1)` sum to zero, so `f` and `g` drop out and, with `A_j = {0, H_j, L_j}`,
//!
//!    `gamma_jk(h) = Cov(W_{j,t}, W_{k,t+h}) = (1 / (L_j L_k)) sum_{a in A_j} sum_{b in A_k} c_a c_b K(h + a - b)`.
//!
//!    `K` of a sum of independent processes is the sum of theirs:
//!    - stationary `x` with `G(n) = Var(S_{t+n} - S_t)`: `K(n) = -G(|n|)/2`, since
//!      `Cov(S_x, S_y) = (Var S_x + Var S_y - G(|y - x|)) / 2`;
//!    - WN(`sigma2`): `G(n) = sigma2 n`;
//!    - ARMA(1,1) with `r_0 = Var x_t`, `r_h = r_1 phi^{h-1}` (AR1: `r_1 = phi r_0`,
//!      `r_0 = sigma2 / (1 - phi^2)`; MA1: `phi = 0`, `r_0 = sigma2 (1 + theta^2)`,
//!      `r_1 = sigma2 theta`): `G(n) = n r_0 + 2 sum_{h=1}^{n-1} (n - h) r_h
//!      = n r_0 + 2 r_1 q(n) / (1 - phi)^2` with `q(n) = n (1 - phi) - (1 - phi^n)`;
//!    - RW(`gamma2`), `x_t = w_0 + ... + w_t`: for `x <= y`,
//!      `Cov(S_x, S_y) = gamma2 sum_{m=1}^{x+1} m (m + y - x)`, a cubic whose part that is not a
//!      product of a function of one index and a polynomial of degree <= 1 in the other (those
//!      are removed by the weights) is `K(n) = gamma2 (|n|^3 - |n|) / 12`;
//!    - QN(`q2`), `x_t = sqrt(q2) (u_{t+1} - u_t)`: `S_t = sqrt(q2) (u_{t+1} - u_0)`, so
//!      `K(n) = q2 [n = 0]`;
//!    - DR(`omega`) is deterministic: it adds no covariance but a mean `mu_j = omega L_j / 4`
//!      to every coefficient.
//!
//!    Checks: `gamma_jj(0)` is the implied WV of docs/methods.md §4.2 for each process (tested).
//! 2. **Covariance of the squares.** For `W = mu + Z` with `Z` a linear process in independent
//!    innovations `xi_u` (fourth cumulant `kappa_u`, zero third cumulant),
//!    `Cov(W_a^2, W_b^2) = 2 Cov(Z_a, Z_b)^2 + 4 mu_a mu_b Cov(Z_a, Z_b) + sum_u alpha_a(u)^2 alpha_b(u)^2 kappa_u`.
//!    Only QN is not Gaussian: its `u` are `sqrt(12) U(0, 1)`, `kappa = -1.2`, and
//!    `W_{j,t}` puts `sqrt(q2) (1, -2, 1) / L_j` on `u_{t+1}, u_{t+1-H_j}, u_{t+1-L_j}`, so two
//!    coefficients at lag `h` share one `u` for each `(a, b)` with `b - a = h`.
//! 3. **Sum over the coefficients.** With `n_jk(h)` the number of kept pairs `(t, t + h)`
//!    (`t` kept at level j, `t + h` at level k),
//!
//!    `V_jk = (1 / (M_j M_k)) sum_h n_jk(h) [2 gamma_jk(h)^2 + 4 mu_j mu_k gamma_jk(h)]
//!           - (1.2 q2^2 / (M_j M_k L_j^2 L_k^2)) sum_{a, b} n_jk(b - a) c_a^2 c_b^2`.
//!
//!    Between the breakpoints (`h = b - a`, where an argument of `K` changes sign, and the
//!    kinks of `n_jk`) the summand is a polynomial (WN, RW) plus exponentials (AR1, GM,
//!    ARMA(1,1) with `phi >= 0`), so each piece is summed directly near its ends and in the
//!    middle by the Euler–Maclaurin formula with Gauss–Legendre quadrature on panels that
//!    widen geometrically from the ends. Outside `-L_j < h <= L_k` only the exponentials remain.
//!
//! Assumptions, as in the bootstrap it replaces: the series is the model (Gaussian innovations,
//! QN's uniform ones, AR processes from their stationary law); a robust WV's covariance is taken
//! as the classical one over the efficiency (docs/methods.md §1.10). Generic ARMA(p, q) and
//! negative autoregressive coefficients are not covered: [`exact_wv_covariance`] says so and the
//! callers simulate instead.

use crate::error::{InputError, ParamError};
use crate::math::elementary;
use crate::model::Model;
use crate::process::{CovariancePart, Process};
use nalgebra::DMatrix;
use rayon::prelude::*;

/// Points summed one by one at each end of a piece before the quadrature takes over.
const DIRECT: i64 = 48;
/// 10-point Gauss–Legendre nodes on [-1, 1] (positive half) and their weights.
const GL_NODES: [f64; 5] = [
    0.148_874_338_981_631_2,
    0.433_395_394_129_247_2,
    0.679_409_568_299_024_4,
    0.865_063_366_688_984_5,
    0.973_906_528_517_171_7,
];
const GL_WEIGHTS: [f64; 5] = [
    0.295_524_224_714_752_87,
    0.269_266_719_309_996_35,
    0.219_086_362_515_982_04,
    0.149_451_349_150_580_6,
    0.066_671_344_308_688_14,
];

/// One stationary autoregressive-type part: `G(n) = n r0 + 2 r1 q(n) / (1 - phi)^2`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Autoregressive {
    phi: f64,
    r0: f64,
    r1: f64,
    /// `1 - phi`
    eps: f64,
    /// `ln(phi)` (for `phi > 0`)
    ln_phi: f64,
    /// `(1 - phi) + ln(phi)`, accurate for `phi` near 1
    d: f64,
}

impl Autoregressive {
    /// The part of `gamma(0) = r0`, `gamma(h) = r1 phi^(h - 1)`, `phi` in (-1, 1).
    pub(crate) fn new(phi: f64, r0: f64, r1: f64) -> Self {
        let eps = 1.0 - phi;
        let ln_phi = if phi > 0.0 {
            elementary::log1p(-eps)
        } else {
            f64::NEG_INFINITY
        };
        // eps + ln(1 - eps) = -sum_{k >= 2} eps^k / k: the series for small eps avoids the
        // cancellation (terms below 1e-17 of the first after 18 terms at eps = 0.1)
        let d = if eps < 0.1 {
            let mut term = eps;
            let mut s = 0.0;
            for k in 2..40 {
                term *= eps;
                s -= term / k as f64;
                if term < 1e-18 * eps * eps {
                    break;
                }
            }
            s
        } else {
            eps + ln_phi
        };
        Self {
            phi,
            r0,
            r1,
            eps,
            ln_phi,
            d,
        }
    }

    /// `q(n) / (1 - phi)^2`, `q(n) = n (1 - phi) - (1 - phi^n)`, for real `n >= 0`.
    fn q_over_eps2(&self, n: f64) -> f64 {
        if self.eps >= 0.1 {
            let pn = if self.phi == 0.0 {
                if n == 0.0 {
                    1.0
                } else {
                    0.0
                }
            } else if self.phi < 0.0 {
                // an integer power of a negative base (n is a whole number of samples)
                elementary::pow(self.phi, n)
            } else {
                elementary::exp(n * self.ln_phi)
            };
            return (n * self.eps - (1.0 - pn)) / (self.eps * self.eps);
        }
        // q = (expm1(y) - y) + n d with y = n ln(phi): both terms are of order (n eps)^2 and
        // neither cancels the other badly (ratio 1/n)
        let y = n * self.ln_phi;
        let e = if y.abs() < 0.1 {
            // y^2/2 + y^3/6 + ...: terms below 1e-18 of the first after 14 terms
            let mut term = y * y / 2.0;
            let mut s = term;
            for k in 3..20 {
                term *= y / k as f64;
                s += term;
                if term.abs() < 1e-18 * s.abs() {
                    break;
                }
            }
            s
        } else {
            elementary::expm1(y) - y
        };
        (e + n * self.d) / (self.eps * self.eps)
    }

    /// `G(n) = Var(x_1 + ... + x_n) = n r0 + 2 r1 q(n) / (1 - phi)^2`, `n >= 0`.
    pub(crate) fn increment_variance(&self, n: f64) -> f64 {
        n * self.r0 + 2.0 * self.r1 * self.q_over_eps2(n)
    }

    /// `Var(S_n - n x_0)`, the sum of `n` samples relative to the value before them:
    /// `G(n) + n^2 r0 - 2 n Cov(S_n, x_0)`, `Cov(S_n, x_0) = r1 (1 - phi^n) / (1 - phi)`. For
    /// `phi` near 1 the terms nearly cancel (the result is of order `(1 - phi) n^3 r0`): the
    /// relative error is about `1e-16 / ((1 - phi) n)`, 1e-11 at a correlation time of 10^5
    /// samples.
    pub(crate) fn held_sum_variance(&self, n: f64) -> f64 {
        let geometric = if self.phi > 0.0 {
            -elementary::expm1(n * self.ln_phi) / self.eps
        } else {
            (1.0 - elementary::pow(self.phi, n)) / self.eps
        };
        self.increment_variance(n) + n * n * self.r0 - 2.0 * n * self.r1 * geometric
    }

    /// `K(n) = -G(|n|) / 2`.
    fn k(&self, n: f64) -> f64 {
        -0.5 * self.increment_variance(n.abs())
    }

    /// `(phi^half - 1) / (1 - phi)`: the factor of
    /// [`second_difference_with`](Self::second_difference_with) that depends on the level
    /// only, computed once per pair of levels.
    fn half_factor(&self, half: f64) -> f64 {
        elementary::expm1(half * self.ln_phi) / self.eps
    }

    /// `K(m) - 2 K(m + half) + K(m + 2 half)` for `m >= 0` given `e =`
    /// [`half_factor`](Self::half_factor)`(half)`: the linear part of `K` drops out, leaving
    /// `-(r1 / (1 - phi)^2) phi^m (1 - phi^half)^2`, without cancellation.
    fn second_difference_with(&self, e: f64, m: f64) -> f64 {
        -self.r1 * elementary::pow(self.phi, m) * e * e
    }
}

/// The refusal of a negative `phi`: the closed-form sums between breakpoints assume a
/// non-alternating autocovariance.
fn negative_phi(phi: f64) -> ParamError {
    ParamError::new(
        "phi",
        phi,
        "phi >= 0 for the exact WV covariance (a negative autoregression alternates in sign; --covariance auto or bootstrap simulates V)",
    )
}

/// The processes of a model reduced to what the covariance needs.
#[derive(Debug, Clone, Default)]
struct Parts {
    /// Sum of the WN variances.
    wn: f64,
    /// Sum of the RW innovation variances.
    rw: f64,
    /// Sum of the QN `q2`.
    qn: f64,
    /// Sum of the DR slopes.
    dr: f64,
    autoregressive: Vec<Autoregressive>,
}

impl Parts {
    fn of(processes: &[Process]) -> Result<Self, ParamError> {
        let mut parts = Parts::default();
        for p in processes {
            match p.covariance_part()? {
                CovariancePart::White(sigma2) => parts.wn += sigma2,
                CovariancePart::RandomWalk(gamma2) => parts.rw += gamma2,
                CovariancePart::Quantization(q2) => parts.qn += q2,
                CovariancePart::Drift(omega) => parts.dr += omega,
                CovariancePart::Autoregressive { phi, r0, r1 } => {
                    if phi < 0.0 {
                        return Err(negative_phi(phi));
                    }
                    parts.autoregressive.push(Autoregressive::new(phi, r0, r1))
                }
            }
        }
        Ok(parts)
    }

    /// The smooth part of `K` (QN's `q2 [n = 0]` is handled apart).
    fn k(&self, n: f64) -> f64 {
        let a = n.abs();
        let mut k = -0.5 * self.wn * a + self.rw * (a * a * a - a) / 12.0;
        for p in &self.autoregressive {
            k += p.k(a);
        }
        k
    }

    /// `D(y) = K(y) - 2 K(y + half) + K(y + 2 half)`, the level's filter applied to `K`.
    ///
    /// When the three points are on one side of 0 it is taken in closed form: the differences
    /// of values of `K` as large as `L_k^3` would otherwise lose every digit of a result of
    /// order `half^2 L_k` (a fine level paired with a coarse one). Across 0 the points are
    /// within `2 half` of it and the values of `K` are small enough to difference directly.
    ///
    /// `factors` holds each autoregressive part's [`Autoregressive::half_factor`] at `half`.
    fn second_difference(&self, half: f64, y: f64, factors: &[f64]) -> f64 {
        let (lo, hi) = (y, y + 2.0 * half);
        if lo < 0.0 && hi > 0.0 {
            return self.k(lo) - 2.0 * self.k(y + half) + self.k(hi);
        }
        // distance of the nearest point and of the middle one from 0
        let (near, centre) = if lo >= 0.0 {
            (lo, y + half)
        } else {
            (-hi, -(y + half))
        };
        // WN: linear, so 0; RW: (n^3 - n) / 12 differences to 6 half^2 centre / 12
        let mut d = self.rw * half * half * centre / 2.0;
        for (p, &e) in self.autoregressive.iter().zip(factors) {
            d += p.second_difference_with(e, near);
        }
        d
    }
}

/// One pair of levels `(j, k)`.
struct Pair<'a> {
    parts: &'a Parts,
    /// `1 / (L_j L_k)`
    scale: f64,
    mu2: f64,
    n: i64,
    lj: i64,
    lk: i64,
    /// Each autoregressive part's [`Autoregressive::half_factor`] at level j's half-width.
    factors: Vec<f64>,
}

impl Pair<'_> {
    /// `gamma_jk(h)` without QN, for real `h`: level k's filter applied to level j's `D`.
    fn gamma(&self, h: f64) -> f64 {
        let half = (self.lj / 2) as f64;
        let hk = (self.lk / 2) as f64;
        let d = |b: f64| self.parts.second_difference(half, h - b, &self.factors);
        (d(0.0) - 2.0 * d(hk) + d(2.0 * hk)) * self.scale
    }

    /// Number of kept pairs `(t, t + h)`, as a real-valued piecewise-linear function.
    fn count(&self, h: f64) -> f64 {
        let hi = (self.n - 1) as f64 - h.max(0.0);
        let lo = ((self.lj - 1) as f64).max((self.lk - 1) as f64 - h);
        (hi - lo + 1.0).max(0.0)
    }

    fn summand(&self, h: f64) -> f64 {
        let g = self.gamma(h);
        self.count(h) * (2.0 * g * g + 4.0 * self.mu2 * g)
    }

    /// `sum_{h = p}^{q - 1}` of the summand, smooth on `[p, q - 1]`.
    fn piece(&self, p: i64, q: i64) -> f64 {
        let f = |h: f64| self.summand(h);
        if q - p <= 2 * DIRECT + 8 {
            return (p..q).map(|h| f(h as f64)).sum();
        }
        let mut s: f64 = (p..p + DIRECT)
            .chain(q - DIRECT..q)
            .map(|h| f(h as f64))
            .sum();
        // Euler–Maclaurin on [a, b] (integers): integral + ends / 2 + (f'(b) - f'(a)) / 12
        // - (f'''(b) - f'''(a)) / 720, derivatives by central differences inside the piece
        let (a, b) = ((p + DIRECT) as f64, (q - DIRECT - 1) as f64);
        let d1 = |x: f64| (f(x + 1.0) - f(x - 1.0)) / 2.0;
        let d3 = |x: f64| (f(x + 2.0) - 2.0 * f(x + 1.0) + 2.0 * f(x - 1.0) - f(x - 2.0)) / 2.0;
        s += 0.5 * (f(a) + f(b)) + (d1(b) - d1(a)) / 12.0 - (d3(b) - d3(a)) / 720.0;
        s + graded_integral(&f, a, b)
    }
}

/// `int_a^b f` by 10-point Gauss–Legendre on panels whose widths double from each end
/// (48, 96, ...) to the middle: exact for polynomials of degree <= 19 and accurate for the
/// exponentials of an autoregression wherever they decay (near an end the panels are short).
fn graded_integral(f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    let mid = 0.5 * (a + b);
    let mut cuts = vec![a];
    let mut w = DIRECT as f64;
    while a + w < mid {
        cuts.push(a + w);
        w *= 2.0;
    }
    let mut right: Vec<f64> = Vec::new();
    let mut w = DIRECT as f64;
    while b - w > mid {
        right.push(b - w);
        w *= 2.0;
    }
    cuts.push(mid);
    cuts.extend(right.into_iter().rev());
    cuts.push(b);
    cuts.windows(2)
        .map(|c| {
            let (lo, hi) = (c[0], c[1]);
            let (m, r) = (0.5 * (lo + hi), 0.5 * (hi - lo));
            r * GL_NODES
                .iter()
                .zip(GL_WEIGHTS)
                .map(|(&x, w)| w * (f(m - r * x) + f(m + r * x)))
                .sum::<f64>()
        })
        .sum()
}

impl<'a> Pair<'a> {
    /// Levels `j` and `k` of `n`-sample series.
    fn new(parts: &'a Parts, n: usize, j: usize, k: usize) -> Self {
        let (lj, lk) = (1_i64 << j, 1_i64 << k);
        Pair {
            parts,
            scale: 1.0 / (lj as f64 * lk as f64),
            mu2: parts.dr * parts.dr * (lj as f64) * (lk as f64) / 16.0,
            n: n as i64,
            lj,
            lk,
            factors: parts
                .autoregressive
                .iter()
                .map(|p| p.half_factor((lj / 2) as f64))
                .collect(),
        }
    }

    /// `(a - b, c_a c_b)` for `a in A_j`, `b in A_k` (module docs, step 1).
    fn taps(&self) -> [(i64, f64); 9] {
        let tap = |l: i64| [(0_i64, 1.0), (l / 2, -2.0), (l, 1.0)];
        let mut taps = [(0_i64, 0.0); 9];
        for (i, (a, ca)) in tap(self.lj).into_iter().enumerate() {
            for (m, (b, cb)) in tap(self.lk).into_iter().enumerate() {
                taps[3 * i + m] = (a - b, ca * cb);
            }
        }
        taps
    }
}

/// `V_jk` for one pair of levels (module docs, step 3).
fn pair_covariance(parts: &Parts, n: usize, j: usize, k: usize) -> f64 {
    let pair = Pair::new(parts, n, j, k);
    let (n, lj, lk) = (pair.n, pair.lj, pair.lk);
    let taps = pair.taps();
    // pairs exist for h in [lk - n, n - lj]; only the exponentials reach beyond -lj < h <= lk
    let (mut lo, mut hi) = (lk - n, n - lj);
    if parts.autoregressive.is_empty() {
        lo = lo.max(-lj);
        hi = hi.min(lk);
    }
    let mut cuts: Vec<i64> = taps.iter().map(|&(d, _)| -d).collect();
    cuts.extend([0, lk - lj, lo, hi + 1]);
    cuts.retain(|&c| c >= lo && c <= hi + 1);
    cuts.sort_unstable();
    cuts.dedup();
    let mut total: f64 = cuts.windows(2).map(|c| pair.piece(c[0], c[1])).sum();
    // QN: a spike q2 c_a c_b / (L_j L_k) in gamma at h = b - a, and the fourth cumulant there
    if parts.qn > 0.0 {
        let mut spikes: Vec<(i64, f64, f64)> = Vec::new();
        for &(d, w) in &taps {
            let h = -d;
            let g = parts.qn * w * pair.scale;
            // c_a^2 c_b^2 = w^2
            let kappa = -1.2 * parts.qn * parts.qn * w * w * pair.scale * pair.scale;
            match spikes.iter_mut().find(|s| s.0 == h) {
                Some(s) => {
                    s.1 += g;
                    s.2 += kappa;
                }
                None => spikes.push((h, g, kappa)),
            }
        }
        for (h, spike, kappa) in spikes {
            if h < lo || h > hi {
                continue;
            }
            let (hf, g) = (h as f64, pair.gamma(h as f64));
            let c = pair.count(hf);
            let with = g + spike;
            total += c * (2.0 * (with * with - g * g) + 4.0 * pair.mu2 * spike + kappa);
        }
    }
    total / ((n - lj + 1) as f64 * (n - lk + 1) as f64)
}

/// `V`, the `levels x levels` covariance of the classical Haar MODWT WV of series of length
/// `n` drawn from `processes` (module docs); the pairs of levels in parallel.
///
/// # Errors
/// [`ParamError`] for a process the formulas do not cover (generic ARMA, a negative
/// autoregressive coefficient), or levels the series cannot hold (`2^levels > n`).
pub(crate) fn exact_covariance_of(
    processes: &[Process],
    n: usize,
    levels: usize,
) -> Result<DMatrix<f64>, ParamError> {
    let parts = Parts::of(processes)?;
    if levels == 0 || levels > 62 || (1_u128 << levels) > n as u128 {
        return Err(ParamError::new(
            "levels",
            levels,
            format!("between 1 and log2(n) = {} levels", n.max(1).ilog2()),
        ));
    }
    let pairs: Vec<(usize, usize)> = (1..=levels)
        .flat_map(|j| (j..=levels).map(move |k| (j, k)))
        .collect();
    let values: Vec<f64> = pairs
        .par_iter()
        .map(|&(j, k)| pair_covariance(&parts, n, j, k))
        .collect();
    let mut v = DMatrix::zeros(levels, levels);
    for (&(j, k), value) in pairs.iter().zip(values) {
        v[(j - 1, k - 1)] = value;
        v[(k - 1, j - 1)] = value;
    }
    Ok(v)
}

/// The exact covariance matrix `V` (`levels x levels`) of the classical Haar MODWT wavelet
/// variance of `n`-sample series drawn from `model` (all values set) at `freq_hz`: the limit of
/// the parametric bootstrap of docs/methods.md §7.4 as its replicates grow, without simulating
/// (module docs give the formulas). Divide by the efficiency for a robust WV.
///
/// Worked example: the test `tests::examples::example_implied_cov_exact_wv_covariance`.
///
/// # Errors
/// [`InputError`] for a model without values or a bad rate; [`ParamError`] (as `InputError`)
/// for a process the formulas do not cover (generic ARMA, a negative autoregressive
/// coefficient) or more levels than the series holds.
pub(crate) fn exact_wv_covariance(
    model: &Model,
    n: usize,
    freq_hz: f64,
    levels: usize,
) -> Result<DMatrix<f64>, InputError> {
    let processes = model.processes(freq_hz)?;
    Ok(exact_covariance_of(&processes, n, levels)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Model;

    fn processes(text: &str, freq: f64) -> Vec<Process> {
        Model::parse(text).unwrap().processes(freq).unwrap()
    }

    /// `V` by brute force: the coefficient vectors as explicit linear maps of the innovations
    /// (Gaussian, so `Cov(W_a^2, W_b^2) = 2 Cov(W_a, W_b)^2` plus the drift's term), from the
    /// series' covariance matrix built sample by sample; independent of `K` and the quadrature.
    fn brute_force(sigma: &DMatrix<f64>, drift: f64, n: usize, levels: usize) -> DMatrix<f64> {
        let coef = |j: usize, t: usize| {
            let (l, h) = (1usize << j, 1usize << (j - 1));
            let mut w = vec![0.0; n];
            for u in 0..l {
                w[t - u] = if u < h { 1.0 } else { -1.0 } / l as f64;
            }
            w
        };
        let mut v = DMatrix::zeros(levels, levels);
        let coefs: Vec<Vec<Vec<f64>>> = (1..=levels)
            .map(|j| ((1 << j) - 1..n).map(|t| coef(j, t)).collect())
            .collect();
        let proj: Vec<Vec<Vec<f64>>> = coefs
            .iter()
            .map(|cs| {
                cs.iter()
                    .map(|c| {
                        let cv = DMatrix::from_row_slice(1, n, c) * sigma;
                        cv.iter().copied().collect()
                    })
                    .collect()
            })
            .collect();
        for j in 0..levels {
            for k in 0..levels {
                let mu = |l: usize| drift * (1 << (l + 1)) as f64 / 4.0;
                let mut s = 0.0;
                for (a, pa) in proj[j].iter().enumerate() {
                    for b in &coefs[k] {
                        let g: f64 = pa.iter().zip(b).map(|(x, y)| x * y).sum();
                        s += 2.0 * g * g + 4.0 * mu(j) * mu(k) * g;
                    }
                    let _ = a;
                }
                v[(j, k)] = s / (coefs[j].len() * coefs[k].len()) as f64;
            }
        }
        v
    }

    fn toeplitz(n: usize, r: impl Fn(usize) -> f64) -> DMatrix<f64> {
        DMatrix::from_fn(n, n, |s, t| r(s.abs_diff(t)))
    }

    fn assert_close(a: &DMatrix<f64>, b: &DMatrix<f64>, rel: f64) {
        let scale = a.iter().map(|x| x.abs()).fold(0.0, f64::max);
        for (x, y) in a.iter().zip(b.iter()) {
            assert!(
                (x - y).abs() <= rel * scale.max(f64::MIN_POSITIVE),
                "{x} vs {y}\n{a}\n{b}"
            );
        }
    }

    #[test]
    fn matches_brute_force_for_each_gaussian_process() {
        let n = 96;
        let levels = 5;
        let (phi, s2) = (0.93_f64, 0.7);
        let cases: Vec<(&str, DMatrix<f64>, f64)> = vec![
            (
                "WN(sigma2=2)",
                toeplitz(n, |h| if h == 0 { 2.0 } else { 0.0 }),
                0.0,
            ),
            (
                "RW(gamma2=0.3)",
                DMatrix::from_fn(n, n, |s, t| 0.3 * (s.min(t) + 1) as f64),
                0.0,
            ),
            (
                "AR1(phi=0.93, sigma2=0.7)",
                toeplitz(n, |h| s2 * phi.powi(h as i32) / (1.0 - phi * phi)),
                0.0,
            ),
            (
                "MA1(theta=-0.4, sigma2=1.5)",
                toeplitz(n, |h| match h {
                    0 => 1.5 * (1.0 + 0.16),
                    1 => -0.4 * 1.5,
                    _ => 0.0,
                }),
                0.0,
            ),
            (
                "WN(sigma2=1)+DR(omega=0.05)",
                toeplitz(n, |h| if h == 0 { 1.0 } else { 0.0 }),
                0.05,
            ),
        ];
        for (text, sigma, drift) in cases {
            let exact = exact_covariance_of(&processes(text, 1.0), n, levels).unwrap();
            let brute = brute_force(&sigma, drift, n, levels);
            assert_close(&exact, &brute, 1e-11);
        }
    }

    #[test]
    fn arma11_matches_brute_force() {
        let n = 80;
        let (phi, theta, s2) = (0.8_f64, 0.5_f64, 1.3_f64);
        let r0 = s2 * (1.0 + 2.0 * phi * theta + theta * theta) / (1.0 - phi * phi);
        let r1 = s2 * (1.0 + phi * theta) * (phi + theta) / (1.0 - phi * phi);
        let sigma = toeplitz(n, |h| {
            if h == 0 {
                r0
            } else {
                r1 * phi.powi(h as i32 - 1)
            }
        });
        let exact = exact_covariance_of(
            &processes("ARMA11(phi=0.8, theta=0.5, sigma2=1.3)", 1.0),
            n,
            4,
        )
        .unwrap();
        assert_close(&exact, &brute_force(&sigma, 0.0, n, 4), 1e-11);
    }

    #[test]
    fn quadrature_matches_the_direct_sum() {
        // long pieces go through the quadrature; a direct sum over every lag is the reference
        let n = 1 << 15;
        for text in [
            "AR1(phi=0.999, sigma2=1e-4)+WN(sigma2=1)+RW(gamma2=1e-6)",
            "AR1(phi=0.6, sigma2=1)+AR1(phi=0.99999, sigma2=1e-6)+QN(q2=0.3)+DR(omega=1e-4)",
        ] {
            let parts = Parts::of(&processes(text, 1.0)).unwrap();
            for (j, k) in [(1, 1), (1, 13), (5, 9), (12, 13), (13, 13)] {
                let fast = pair_covariance(&parts, n, j, k);
                let pair = Pair::new(&parts, n, j, k);
                let (lj, lk, taps) = (pair.lj, pair.lk, pair.taps());
                let mut direct = 0.0;
                for h in lk - n as i64..=n as i64 - lj {
                    let mut g = pair.gamma(h as f64);
                    let mut kappa = 0.0;
                    for &(d, w) in &taps {
                        if -d == h {
                            g += parts.qn * w * pair.scale;
                            kappa += -1.2 * parts.qn.powi(2) * w * w * pair.scale.powi(2);
                        }
                    }
                    direct += pair.count(h as f64) * (2.0 * g * g + 4.0 * pair.mu2 * g + kappa);
                }
                let direct = direct / ((n as i64 - lj + 1) * (n as i64 - lk + 1)) as f64;
                assert!(
                    (fast - direct).abs() <= 1e-9 * direct.abs(),
                    "{text} ({j}, {k}): {fast} vs {direct}"
                );
            }
        }
    }

    #[test]
    fn fine_and_coarse_levels_of_a_long_random_walk() {
        // K of RW reaches L^3 ~ 1e18 here while V_{1,20} is of order 1/N: differencing K
        // naively would lose every digit. Reference: W_{1,t} = w_t / 2, so gamma_{1,k}(h) is
        // half the weight of w_t in W_{k,t+h}, counted exactly.
        let n: i64 = 1 << 22;
        let k = 20;
        let (l, half) = (1_i64 << k, 1_i64 << (k - 1));
        let weight = |t: i64, s: i64| {
            let recent = (s - t.max(s - half + 1) + 1).clamp(0, half);
            let older = (s - half - t.max(s - l + 1) + 1).clamp(0, half);
            (recent - older) as f64 / l as f64
        };
        let mut sum = 0.0;
        for h in (l - n)..=(n - 2) {
            // any t with both coefficients kept gives the same gamma; count the pairs
            let t = (1_i64).max(l - 1 - h);
            let g = 0.5 * weight(t, t + h);
            let count = ((n - 1).min(n - 1 - h) - (1_i64).max(l - 1 - h) + 1).max(0) as f64;
            sum += count * 2.0 * g * g;
        }
        let want = sum / ((n - 1) * (n - l + 1)) as f64;
        let v = exact_covariance_of(&processes("RW(gamma2=1)", 1.0), n as usize, k).unwrap();
        assert!(
            (v[(0, k - 1)] - want).abs() <= 1e-10 * want,
            "{} vs {want}",
            v[(0, k - 1)]
        );
    }

    /// The simulator's own replicates (uniform QN, stationary AR1 start, drift) against the
    /// formula, entry by entry: `B` replicates give each variance with a relative SE of about
    /// `sqrt((2 + excess kurtosis) / B)`, under 4% here, so 15% is about 4 SE.
    #[test]
    fn matches_the_simulated_bootstrap() {
        use crate::sim::bootstrap::wv_bootstrap;
        use crate::variance::wv::WvOptions;
        let b = 3000;
        for (text, levels) in [
            ("QN(q2=1)", 3),
            (
                "AR1(phi=0.95, sigma2=0.1)+WN(sigma2=1)+QN(q2=0.2)+RW(gamma2=1e-4)+DR(omega=2e-3)",
                7,
            ),
        ] {
            let model = Model::parse(text).unwrap();
            let n = 2048;
            let opts = WvOptions {
                levels: Some(levels),
                ..WvOptions::default()
            };
            let boot = wv_bootstrap(&model, n, 1.0, &opts, b, 99).unwrap().cov;
            let exact = exact_wv_covariance(&model, n, 1.0, levels).unwrap();
            for j in 0..levels {
                let r = boot[(j, j)] / exact[(j, j)];
                assert!((r - 1.0).abs() < 0.15, "{text} level {}: ratio {r}", j + 1);
                for k in 0..j {
                    let corr = |v: &DMatrix<f64>| v[(j, k)] / (v[(j, j)] * v[(k, k)]).sqrt();
                    assert!(
                        (corr(&boot) - corr(&exact)).abs() < 0.1,
                        "{text} ({}, {}): {} vs {}",
                        j + 1,
                        k + 1,
                        corr(&boot),
                        corr(&exact)
                    );
                }
            }
        }
    }

    #[test]
    fn diagonal_lag_zero_is_the_implied_wv() {
        // gamma_jj(0) is the process's WV at tau = 2^j (docs/methods.md §4.2)
        for text in [
            "WN(sigma2=2)",
            "RW(gamma2=0.5)",
            "QN(q2=0.7)",
            "AR1(phi=0.999999, sigma2=1e-6)",
            "AR1(phi=0.3, sigma2=2)",
            "GM(beta=0.01, sigma2_gm=4)",
            "ARMA11(phi=0.9, theta=-0.3, sigma2=1)",
        ] {
            let model = Model::parse(text).unwrap();
            let ps = model.processes(100.0).unwrap();
            let parts = Parts::of(&ps).unwrap();
            let implied = model.implied_wv(20, 100.0).unwrap().wv;
            for j in 1..=20 {
                let l = 1_i64 << j;
                let mut g = 0.0;
                for (a, ca) in [(0_i64, 1.0), (l / 2, -2.0), (l, 1.0)] {
                    for (b, cb) in [(0_i64, 1.0), (l / 2, -2.0), (l, 1.0)] {
                        g += ca * cb * parts.k((a - b) as f64);
                        if a == b {
                            g += ca * cb * parts.qn;
                        }
                    }
                }
                g /= (l * l) as f64;
                let want = implied[j - 1];
                assert!(
                    (g - want).abs() <= 1e-8 * want,
                    "{text} level {j}: {g} vs {want}"
                );
            }
        }
    }

    #[test]
    fn white_noise_level_one_closed_form() {
        // W_{1,t} = (x_t - x_{t-1}) / 2: Var = 1/2, lag-1 covariance -1/4, so
        // Var(nu2_hat_1) = (2/M^2) (M (1/4) + 2 (M - 1) (1/16)) = (3M - 1) / (4 M^2)
        let v = exact_covariance_of(&processes("WN(sigma2=1)", 1.0), 1001, 2).unwrap();
        let m = 1000.0;
        let want = (3.0 * m - 1.0) / (4.0 * m * m);
        assert!(
            (v[(0, 0)] - want).abs() < 1e-14 * want,
            "{} vs {want}",
            v[(0, 0)]
        );
    }

    #[test]
    fn refuses_what_it_does_not_cover() {
        assert!(exact_covariance_of(&processes("AR1(phi=-0.5, sigma2=1)", 1.0), 100, 3).is_err());
        let ar2 = Model::new(vec![crate::model::ar_with(&[0.5, 0.2], 1.0).unwrap()])
            .unwrap()
            .processes(1.0)
            .unwrap();
        assert!(exact_covariance_of(&ar2, 100, 3).is_err());
        assert!(exact_covariance_of(&processes("WN(sigma2=1)", 1.0), 100, 7).is_err());
        assert!(exact_covariance_of(&processes("WN(sigma2=1)", 1.0), 128, 7).is_ok());
    }
}
