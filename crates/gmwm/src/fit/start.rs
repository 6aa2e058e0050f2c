//! Starting values by random search (docs/methods.md §6, the IMU algorithm of paper Appendix C).
//!
//! [`starting_values`] draws G candidate parameter vectors following the §6.3 table, scores
//! each by the flattening objective `F` (§5.4) at the untransformed draw and keeps the draw
//! with the strictly smallest `F` (ties go to the lower draw index).
//!
//! Reproducibility: draw `g` uses its own `ChaCha8Rng` seeded with
//! [`replicate_seed`]`(seed, g)`, and draws are evaluated in fixed batches of
//! 1000 draws, so the result does not depend on the number of rayon threads.
//!
//! Early stop (port, allowed by §6.4): after each batch the search stops when at least
//! [`MIN_DRAWS`] draws were made and the batch lowered the best `F` by no more than
//! 1e-6 (relative). The default G ([`default_draws`]) is 20000 for
//! `N <= 1e4`, else 100000 (the package uses 1e6 for long series; the early stop and the
//! stage-1/stage-2 optimisation make the larger count unnecessary).
//!
//! Port deviation (§0.3): in a partly specified model the values the user gave are kept as
//! given in every draw; only the missing (`None`) values are drawn.

use super::{FitError, Objective, Parametrisation, PhiOrder, TransformPreset, Weights};
use crate::model::{Model, ProcessKind};
use crate::sim::replicate_seed;
use crate::variance::wv::WaveletVariance;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// Draws evaluated together; the early-stop check runs after each batch.
pub(crate) const BATCH_DRAWS: usize = 1000;
/// The early stop is not considered before this many draws (five batches), so that a
/// lucky or unlucky first batch cannot end the search.
pub const MIN_DRAWS: usize = 5000;
/// A batch that improves the best `F` by at most this fraction counts as no improvement
/// (F is a sum of squared relative errors; 1e-6 of it is far below what stage 1 resolves).
pub(crate) const EARLY_STOP_REL: f64 = 1e-6;
/// Upper end of the AR1 phi draws (docs/methods.md §6.3).
pub(crate) const PHI_MAX: f64 = 0.999995;
/// AR coefficient bounds of the §6.5 ARMA draws (the package's constants).
const ARMA_LO: f64 = -0.99999999;
const ARMA_HI: f64 = 0.999999999;
/// Tries of the §6.5 stationarity rejection loop before falling back to zero AR
/// coefficients (the package loops without bound; a high order can make acceptance rare).
const ARMA_TRIES: usize = 1000;
/// Number of psi weights in the §6.5 ARMA variance scaling.
const PSI_TERMS: usize = 1000;

/// The non-WV inputs of the search (docs/methods.md §6.1).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StartInputs {
    /// Series length N (RW draws scale with `1 / N`).
    pub n: usize,
    /// `R = (max x - min x) / N` (DR draws); 0 when no series is at hand.
    pub range: f64,
}

impl StartInputs {
    /// N and R of a series (non-finite values are ignored in the range).
    pub fn from_series(x: &[f64]) -> Self {
        // eight independent lanes of compare-and-select vectorise (a NaN never wins a
        // comparison); an infinity falls back to the filtered pass
        let (mut lo8, mut hi8) = ([f64::INFINITY; 8], [f64::NEG_INFINITY; 8]);
        let chunks = x.chunks_exact(8);
        let rest = chunks.remainder();
        for c in chunks {
            for i in 0..8 {
                lo8[i] = if c[i] < lo8[i] { c[i] } else { lo8[i] };
                hi8[i] = if c[i] > hi8[i] { c[i] } else { hi8[i] };
            }
        }
        let mut lo = rest
            .iter()
            .chain(&lo8)
            .fold(f64::INFINITY, |a, &v| if v < a { v } else { a });
        let mut hi = rest
            .iter()
            .chain(&hi8)
            .fold(f64::NEG_INFINITY, |a, &v| if v > a { v } else { a });
        if lo == f64::NEG_INFINITY || hi == f64::INFINITY {
            (lo, hi) = x
                .iter()
                .filter(|v| v.is_finite())
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                    (lo.min(v), hi.max(v))
                });
        }
        let range = if x.is_empty() || hi < lo {
            0.0
        } else {
            (hi - lo) / x.len() as f64
        };
        Self { n: x.len(), range }
    }

    /// Inputs for a precomputed WV without the series: N from the WV, R = 0.
    pub fn from_wv(wv: &WaveletVariance) -> Self {
        Self {
            n: wv.n,
            range: 0.0,
        }
    }
}

/// Which process dominates the first scales (docs/methods.md §6.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Dominance {
    /// Quantisation noise (slope below -1/2 for both CI bounds).
    Qn,
    /// White noise (the CI straddles slope -1/2).
    Wn,
    /// A slow AR1 (slope above -1/2 for both CI bounds).
    Ar1,
}

/// docs/methods.md §6.2: slopes `ln(b / nu2_hat_1) / ln 4` for `b` in the level-2 CI bounds
/// `(lo2, hi2)`: both below -1/2 gives [`Dominance::Qn`], both above [`Dominance::Ar1`],
/// otherwise [`Dominance::Wn`] (also for non-finite inputs).
pub(crate) fn dominance(nu1: f64, lo2: f64, hi2: f64) -> Dominance {
    let s = |b: f64| (b / nu1).ln() / 4f64.ln();
    let (a, b) = (s(lo2), s(hi2));
    if !(a.is_finite() && b.is_finite()) {
        return Dominance::Wn;
    }
    if a.max(b) < -0.5 {
        Dominance::Qn
    } else if a.min(b) > -0.5 {
        Dominance::Ar1
    } else {
        Dominance::Wn
    }
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

/// `U(lo, hi)`; `lo` when the interval is empty or degenerate.
fn unif(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    if hi > lo {
        rng.random_range(lo..hi)
    } else {
        lo
    }
}

/// Levinson step-down: the AR polynomial `1 - sum a_i z^i` has all roots outside the unit
/// circle iff every partial autocorrelation has modulus < 1.
fn ar_stationary(a: &[f64]) -> bool {
    let mut cur = a.to_vec();
    while let Some(&k) = cur.last() {
        if k.is_nan() || k.abs() >= 1.0 {
            return false;
        }
        let m = cur.len() - 1;
        let d = 1.0 - k * k;
        cur = (0..m).map(|i| (cur[i] + k * cur[m - 1 - i]) / d).collect();
    }
    true
}

/// The increasing nested draw of §6.5, randomly permuted.
fn nested_draw(rng: &mut ChaCha8Rng, n: usize) -> Vec<f64> {
    let mut v = Vec::with_capacity(n);
    let mut lo = ARMA_LO;
    for _ in 0..n {
        let a = unif(rng, lo, ARMA_HI);
        v.push(a);
        lo = a;
    }
    // Fisher–Yates
    for i in (1..v.len()).rev() {
        let j = rng.random_range(0..=i);
        v.swap(i, j);
    }
    v
}

/// `1 + sum_{k=1}^{1000} psi_k^2` of `x_t = sum a_i x_{t-i} + e_t + sum m_j e_{t-j}`.
fn psi_norm(ar: &[f64], ma: &[f64]) -> f64 {
    let mut psi = vec![1.0];
    let mut total = 1.0;
    for k in 1..=PSI_TERMS {
        let mut v = if k <= ma.len() { ma[k - 1] } else { 0.0 };
        for (i, a) in ar.iter().enumerate().take(k) {
            v += a * psi[k - 1 - i];
        }
        psi.push(v);
        total += v * v;
        if !total.is_finite() {
            break;
        }
    }
    total
}

/// The summary of the WV the draws need.
#[derive(Debug, Clone, Copy)]
struct DrawContext {
    sigma2_t: f64,
    n: f64,
    range: f64,
    freq_hz: f64,
    dom: Dominance,
    only_wn: bool,
    only_qn: bool,
}

/// One draw (docs/methods.md §6.3) in model order, original parametrisation (GM converted from the
/// AR1 draw with the rate); given values are kept.
fn one_draw(
    model: &Model,
    given: &[Option<f64>],
    ctx: &DrawContext,
    rng: &mut ChaCha8Rng,
) -> Vec<f64> {
    let mut theta = Vec::with_capacity(given.len());
    draw_into(model, given, ctx, rng, &mut theta);
    theta
}

/// [`one_draw`] into `theta` (cleared first), so that the search allocates nothing per draw.
fn draw_into(
    model: &Model,
    given: &[Option<f64>],
    ctx: &DrawContext,
    rng: &mut ChaCha8Rng,
    theta: &mut Vec<f64>,
) {
    theta.clear();
    let st = ctx.sigma2_t;
    let mut c: u32 = match ctx.dom {
        Dominance::Wn => 1,
        Dominance::Qn => u32::from(rng.random::<f64>() < 0.75),
        Dominance::Ar1 => 0,
    };
    let mut last_phi: f64 = 0.0;
    let mut idx = 0;
    for comp in model.components() {
        let g = &given[idx..idx + comp.kind.n_params()];
        idx += g.len();
        match comp.kind {
            ProcessKind::Ar1 | ProcessKind::Gm => {
                c += 1;
                let is_gm = comp.kind == ProcessKind::Gm;
                let given_phi = g[0].map(|v| if is_gm { (-v / ctx.freq_hz).exp() } else { v });
                let phi = given_phi.unwrap_or_else(|| match c {
                    1 => condition1_phi(unif(rng, 0.0, 1.0 / 3.0)),
                    2 => unif(rng, last_phi.max(0.9), PHI_MAX),
                    _ => condition3_phi(unif(rng, 0.0, 1.0 / 3.0), last_phi),
                });
                let v = 1.0 - phi * phi;
                let sigma2 = if c == 1 {
                    unif(rng, st * v / 2.0, st * v)
                } else {
                    unif(rng, 0.0, 0.01 * st * v)
                };
                last_phi = phi;
                if is_gm {
                    theta.push(g[0].unwrap_or(-phi.ln() * ctx.freq_hz));
                    theta.push(g[1].unwrap_or(sigma2 / v));
                } else {
                    theta.push(phi);
                    theta.push(g[1].unwrap_or(sigma2));
                }
            }
            ProcessKind::Wn => theta.push(g[0].unwrap_or_else(|| {
                if ctx.only_wn || ctx.dom == Dominance::Wn {
                    unif(rng, st / 2.0, st)
                } else {
                    unif(rng, 1e-5 * st, 0.1 * st)
                }
            })),
            ProcessKind::Qn => theta.push(g[0].unwrap_or_else(|| {
                if ctx.only_qn || ctx.dom == Dominance::Qn {
                    unif(rng, st / 8.0, st / 3.0)
                } else {
                    unif(rng, 5e-6 * st, st / 100.0)
                }
            })),
            ProcessKind::Rw => {
                theta.push(g[0].unwrap_or_else(|| unif(rng, 1e-5 * st / ctx.n, st / ctx.n)))
            }
            ProcessKind::Dr => {
                theta.push(g[0].unwrap_or_else(|| unif(rng, ctx.range / 100.0, ctx.range / 2.0)))
            }
            ProcessKind::Ma1 => {
                // §6.5 port rule: theta ~ U(0, 1), sigma2 = sigma2_T / (1 + theta^2)
                let t = g[0].unwrap_or_else(|| unif(rng, 0.0, 1.0));
                theta.push(t);
                theta.push(g[1].unwrap_or(st / (1.0 + t * t)));
            }
            ProcessKind::Arma11
            | ProcessKind::Ar(_)
            | ProcessKind::Ma(_)
            | ProcessKind::Arma(..) => {
                let (p, q) = comp.kind.orders();
                let mut ar = nested_draw(rng, p);
                let mut tries = 1;
                while !ar_stationary(&ar) {
                    if tries >= ARMA_TRIES {
                        ar = vec![0.0; p];
                        break;
                    }
                    ar = nested_draw(rng, p);
                    tries += 1;
                }
                let ma = nested_draw(rng, q);
                for (k, a) in ar.iter_mut().enumerate() {
                    *a = g[k].unwrap_or(*a);
                }
                let mut ma = ma;
                for (k, m) in ma.iter_mut().enumerate() {
                    *m = g[p + k].unwrap_or(*m);
                }
                let s = g[p + q].unwrap_or(st / psi_norm(&ar, &ma));
                theta.extend_from_slice(&ar);
                theta.extend_from_slice(&ma);
                theta.push(s);
            }
        }
    }
}

/// Settings of the search.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StartOptions {
    /// RNG seed (the package's default is 1337).
    pub seed: u64,
    /// Number of draws G; `None` for [`default_draws`].
    pub draws: Option<usize>,
}

impl Default for StartOptions {
    fn default() -> Self {
        Self {
            seed: 1337,
            draws: None,
        }
    }
}

/// Default G: 20000 for `N <= 1e4`, else 100000 (see the module docs).
pub fn default_draws(n: usize) -> usize {
    if n <= 10_000 {
        20_000
    } else {
        100_000
    }
}

/// The result of the search.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct StartValues {
    /// The best draw, model order, original parametrisation (GM as `beta`, `sigma2_gm`).
    pub theta: Vec<f64>,
    /// Its flattening objective `F`.
    pub flattening: f64,
    /// Draws made (fewer than G after an early stop).
    pub draws: usize,
    /// The dominance found (§6.2).
    pub dominance: Dominance,
}

/// docs/methods.md §6: the best of up to G random draws for `model` (values it carries are kept)
/// given the empirical WV `wv` (estimate and CI) and `inputs`.
///
/// # Errors
/// [`FitError::BadWv`]/[`FitError::BadWeight`] for an unusable WV; [`FitError::TooFewLevels`];
/// [`FitError::NonFiniteStart`] when no draw has a finite `F`; errors of
/// [`Parametrisation::new`].
pub fn starting_values(
    model: &Model,
    wv: &WaveletVariance,
    inputs: &StartInputs,
    options: &StartOptions,
) -> Result<StartValues, FitError> {
    let nu = &wv.wv;
    let freq_hz = wv.freq_hz;
    let weights = Weights::flattening(nu)?;
    let template = model.without_values();
    let param = Parametrisation::new(&template, TransformPreset::Imu, PhiOrder::Free, freq_hz)?;
    let objective = Objective::new(&template, param, nu, &weights, freq_hz)?;
    let sigma2_t: f64 = nu.iter().sum();
    let dom = if nu.len() >= 2 {
        dominance(nu[0], wv.ci_low[1], wv.ci_high[1])
    } else {
        Dominance::Wn
    };
    let kinds = model.kinds();
    let has = |f: &dyn Fn(&ProcessKind) -> bool| kinds.iter().any(f);
    let ar_like = has(&|k| matches!(k, ProcessKind::Ar1 | ProcessKind::Gm));
    let rw = has(&|k| *k == ProcessKind::Rw);
    let dr = has(&|k| *k == ProcessKind::Dr);
    let wn = has(&|k| *k == ProcessKind::Wn);
    let qn = has(&|k| *k == ProcessKind::Qn);
    let ctx = DrawContext {
        sigma2_t,
        n: inputs.n.max(1) as f64,
        range: inputs.range,
        freq_hz,
        dom,
        only_wn: wn && !ar_like && !rw && !dr && !qn,
        only_qn: qn && !ar_like && !rw && !dr && !wn,
    };
    let given = model.values();
    let total = options
        .draws
        .unwrap_or_else(|| default_draws(inputs.n))
        .max(1);
    let mut best: Option<(f64, usize)> = None;
    let mut done = 0;
    while done < total {
        let end = (done + BATCH_DRAWS).min(total);
        let batch_best = (done..end)
            .into_par_iter()
            .map_init(
                || (Vec::new(), Vec::new()),
                |(theta, nu), g| {
                    let mut rng = ChaCha8Rng::seed_from_u64(replicate_seed(options.seed, g as u64));
                    draw_into(model, &given, &ctx, &mut rng, theta);
                    (g, objective.value_at_theta_in(theta, nu))
                },
            )
            .filter_map(|(g, value)| match value {
                Ok(f) if f.is_finite() => Some((f, g)),
                _ => None,
            })
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let previous = best.map(|b| b.0);
        if let Some(b) = batch_best {
            if best.map_or(true, |cur| b.0 < cur.0) {
                best = Some(b);
            }
        }
        done = end;
        if let (Some(prev), Some(cur)) = (previous, best) {
            if done >= MIN_DRAWS && prev - cur.0 <= EARLY_STOP_REL * prev {
                break;
            }
        }
    }
    let (flattening, g) = best.ok_or(FitError::NonFiniteStart {
        level: 1,
        value: f64::NAN,
    })?;
    let mut rng = ChaCha8Rng::seed_from_u64(replicate_seed(options.seed, g as u64));
    let theta = one_draw(model, &given, &ctx, &mut rng);
    Ok(StartValues {
        theta,
        flattening,
        draws: done,
        dominance: dom,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn range_ignores_non_finite_values() {
        let naive = |x: &[f64]| {
            let f: Vec<f64> = x.iter().copied().filter(|v| v.is_finite()).collect();
            let lo = f.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = f.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            if f.is_empty() {
                0.0
            } else {
                (hi - lo) / x.len() as f64
            }
        };
        let mut x: Vec<f64> = (0..37).map(|i| ((i * 7919) % 101) as f64 - 50.0).collect();
        assert_eq!(StartInputs::from_series(&x).range, naive(&x));
        x[3] = f64::NAN;
        x[30] = 1e9;
        assert_eq!(StartInputs::from_series(&x).range, naive(&x));
        x[11] = f64::INFINITY;
        x[35] = f64::NEG_INFINITY;
        assert_eq!(StartInputs::from_series(&x).range, naive(&x));
        assert_eq!(StartInputs::from_series(&[]).range, 0.0);
        assert_eq!(StartInputs::from_series(&[f64::NAN; 9]).range, 0.0);
    }

    #[test]
    fn stationarity_check() {
        assert!(ar_stationary(&[0.5]));
        assert!(!ar_stationary(&[1.2]));
        assert!(ar_stationary(&[0.5, 0.3]));
        assert!(!ar_stationary(&[0.6, 0.5]));
    }

    #[test]
    fn psi_of_ar1() {
        // AR1 with a = 0.5: sum psi_k^2 = 1 / (1 - 0.25)
        assert!((psi_norm(&[0.5], &[]) - 4.0 / 3.0).abs() < 1e-12);
        assert!((psi_norm(&[], &[0.5]) - 1.25).abs() < 1e-12);
    }

    #[test]
    fn dominance_hand_values() {
        assert_eq!(dominance(1.0, 0.2, 0.3), Dominance::Qn);
        assert_eq!(dominance(1.0, 0.4, 0.6), Dominance::Wn);
        assert_eq!(dominance(1.0, 0.6, 0.9), Dominance::Ar1);
        // exact WN ratio 1/2 inside the CI
        assert_eq!(dominance(1.0, 0.45, 0.55), Dominance::Wn);
        // non-finite input: no panic, WN
        assert_eq!(dominance(0.0, 0.4, 0.6), Dominance::Wn);
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
}
