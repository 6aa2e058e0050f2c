//! Starting values by random search (docs/methods.md §6, the IMU algorithm of paper Appendix C).
//!
//! `starting_values` draws G candidate parameter vectors following the §6.3 table, scores
//! each by the flattening objective `F` (§5.4) at the untransformed draw and keeps the draw
//! with the strictly smallest `F` (ties go to the lower draw index).
//!
//! Reproducibility: draw `g` uses its own `ChaCha8Rng` seeded with
//! `replicate_seed``(seed, g)`, and draws are evaluated in fixed batches of
//! 1000 draws, so the result does not depend on the number of rayon threads.
//!
//! Early stop (port, allowed by §6.4): after each batch the search stops when at least
//! `MIN_DRAWS` draws were made and the batch lowered the best `F` by no more than
//! 1e-6 (relative). The default G (`default_draws`) is 20000 for
//! `N <= 1e4`, else 100000 (the package uses 1e6 for long series; the early stop and the
//! stage-1/stage-2 optimisation make the larger count unnecessary).
//!
//! Port deviation (§0.3): in a partly specified model the values the user gave are kept as
//! given in every draw; only the missing (`None`) values are drawn.

use super::{FitError, Objective, Parametrisation, PhiOrder, TransformPreset, Weights};
use crate::math::elementary;
use crate::model::Model;
use crate::process::draw::{Draw, DrawContext};
pub(crate) use crate::process::Dominance;
use crate::process::{spec, Role};
use crate::sim::replicate_seed;
use crate::variance::wv::WaveletVariance;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// Draws evaluated together; the early-stop check runs after each batch.
pub(crate) const BATCH_DRAWS: usize = 1000;
/// The early stop is not considered before this many draws (five batches), so that a
/// lucky or unlucky first batch cannot end the search.
pub(crate) const MIN_DRAWS: usize = 5000;
/// A batch that improves the best `F` by at most this fraction counts as no improvement
/// (F is a sum of squared relative errors; 1e-6 of it is far below what stage 1 resolves).
pub(crate) const EARLY_STOP_REL: f64 = 1e-6;

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

/// docs/methods.md §6.2: slopes `ln(b / nu2_hat_1) / ln 4` for `b` in the level-2 CI bounds
/// `(lo2, hi2)`: both below -1/2 gives [`Dominance::Qn`], both above [`Dominance::Ar1`],
/// otherwise [`Dominance::Wn`] (also for non-finite inputs).
pub(crate) fn dominance(nu1: f64, lo2: f64, hi2: f64) -> Dominance {
    let s = |b: f64| elementary::log(b / nu1) / elementary::log(4f64);
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

/// [`one_draw`] into `theta` (cleared first), so that the search allocates nothing per draw:
/// each component draws its own parameters ([`Spec::draw`](crate::process::Spec)), the
/// correlated ones after the condition that white or quantisation noise dominating the first
/// scales sets.
fn draw_into(
    model: &Model,
    given: &[Option<f64>],
    ctx: &DrawContext,
    rng: &mut ChaCha8Rng,
    theta: &mut Vec<f64>,
) {
    theta.clear();
    let condition: u32 = match ctx.dom {
        Dominance::Wn => 1,
        Dominance::Qn => u32::from(rng.random::<f64>() < 0.75),
        Dominance::Ar1 => 0,
    };
    let mut draw = Draw {
        ctx,
        rng,
        condition,
        last_phi: 0.0,
    };
    let mut idx = 0;
    for comp in model.components() {
        let g = &given[idx..idx + comp.kind.n_params()];
        idx += g.len();
        (spec(comp.kind).draw)(&mut draw, comp.kind, g, theta);
    }
}

/// Settings of the search.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct StartOptions {
    /// RNG seed (the package's default is 1337).
    pub(crate) seed: u64,
    /// Number of draws G; `None` for [`default_draws`].
    pub(crate) draws: Option<usize>,
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
pub(crate) fn default_draws(n: usize) -> usize {
    if n <= 10_000 {
        20_000
    } else {
        100_000
    }
}

/// The result of the search.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub(crate) struct StartValues {
    /// The best draw, model order, original parametrisation (GM as `beta`, `sigma2_gm`).
    pub(crate) theta: Vec<f64>,
    /// Its flattening objective `F`.
    pub(crate) flattening: f64,
    /// Draws made (fewer than G after an early stop).
    pub(crate) draws: usize,
    /// The dominance found (§6.2).
    pub(crate) dominance: Dominance,
}

/// docs/methods.md §6: the best of up to G random draws for `model` (values it carries are kept)
/// given the empirical WV `wv` (estimate and CI) and `inputs`.
///
/// # Errors
/// [`FitError::BadWv`]/[`FitError::BadWeight`] for an unusable WV; [`FitError::TooFewLevels`];
/// [`FitError::NonFiniteStart`] when no draw has a finite `F`; errors of
/// [`Parametrisation::new`].
pub(crate) fn starting_values(
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
    // which navigation terms the model has (the ARMA family aside)
    let roles: Vec<Role> = model
        .kinds()
        .iter()
        .map(|&k| spec(k).role)
        .filter(|&r| r != Role::Other)
        .collect();
    let only = |role: Role| roles.contains(&role) && roles.iter().all(|&r| r == role);
    let ctx = DrawContext {
        wv: nu.to_vec(),
        sigma2_t,
        n: inputs.n.max(1) as f64,
        range: inputs.range,
        freq_hz,
        dom,
        only_wn: only(Role::WhiteNoise),
        only_qn: only(Role::Quantization),
        wv_min: nu.iter().copied().fold(f64::INFINITY, f64::min),
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
    fn dominance_hand_values() {
        assert_eq!(dominance(1.0, 0.2, 0.3), Dominance::Qn);
        assert_eq!(dominance(1.0, 0.4, 0.6), Dominance::Wn);
        assert_eq!(dominance(1.0, 0.6, 0.9), Dominance::Ar1);
        // exact WN ratio 1/2 inside the CI
        assert_eq!(dominance(1.0, 0.45, 0.55), Dominance::Wn);
        // non-finite input: no panic, WN
        assert_eq!(dominance(0.0, 0.4, 0.6), Dominance::Wn);
    }
}
