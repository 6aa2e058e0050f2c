//! Robust Haar MODWT wavelet variance of an in-memory series, Exact convention (docs/methods.md
//! §2.1, §2.4 "Port"): the windowed solver of
//! [`robust_scale_long`](crate::variance::robust::robust_scale_long) with every level's pass
//! folded into one pyramid over the data ([`haar_pass`]).
//!
//! 1. A strided subsample (~8 Ki values) of every level's coefficients, from prefix sums of the
//!    series (it only locates the root; rounding there does not reach the result), solved by
//!    [`robust_scale`] per level, in parallel: the root `s_sub`.
//! 2. One pyramid pass feeds each level's coefficients to a [`PowerAccumulator`] for the
//!    window `[s_sub / 1.1, s_sub 1.1]`; the root is then found on the window.
//! 3. Levels whose window missed the root get a slid window and another pass (only they are
//!    accumulated); after three tries, or when a level is shorter than
//!    [`LONG_MIN`](crate::variance::robust::LONG_MIN), the level's coefficients are collected
//!    and [`robust_scale`] decides — the direct route, same root.

use crate::error::{InputError, SeriesError};
use crate::math::elementary;
use crate::math::sum::NeumaierSum;
use crate::variance::haar::{haar_pass, LevelSink};
use crate::variance::robust::{
    a_of_c, robust_scale, window_around, PowerAccumulator, RobustConvention, WindowOutcome,
    LONG_MIN, SUBSAMPLE, WINDOW_SLIDES,
};

/// What the pass does with one level.
#[derive(Clone)]
enum LevelState {
    /// Nothing (solved already).
    Idle,
    /// Power sums and the values that may cross `|r| = c` on a window `[lo, hi]`.
    Window(PowerAccumulator, f64, f64),
    /// Every coefficient (scaled to `W_{j,t}`), for the direct route.
    Collect(Vec<f64>),
}

/// One sink per part or tile of the pass: a state per level.
struct RobustSink(Vec<LevelState>);

impl LevelSink for RobustSink {
    const COEFFICIENTS: bool = true;

    fn add_square_sum(&mut self, _j: usize, _sum: f64) {
        unreachable!("the robust sink takes coefficients")
    }

    fn push(&mut self, j: usize, w: &[f64]) {
        match &mut self.0[j - 1] {
            LevelState::Idle => {}
            LevelState::Window(acc, _, _) => acc.push(w),
            LevelState::Collect(all) => {
                let scale = elementary::exp2(-(j as f64));
                all.extend(w.iter().map(|v| v * scale));
            }
        }
    }

    fn merge(&mut self, later: &Self) {
        for (a, b) in self.0.iter_mut().zip(&later.0) {
            match (a, b) {
                (LevelState::Window(x, _, _), LevelState::Window(y, _, _)) => x.merge(y),
                (LevelState::Collect(x), LevelState::Collect(y)) => x.extend_from_slice(y),
                _ => {}
            }
        }
    }
}

/// Per level `j = 1..=levels` of `x - offset`: the classical WV (mean of `W_{j,t}^2`,
/// docs/methods.md §1.5), the robust variance `s^2` (docs/methods.md §2.1, Exact convention; `Err`
/// as [`robust_scale`]) and the number of kept coefficients.
pub(crate) fn haar_robust_levels(
    x: &[f64],
    levels: usize,
    offset: f64,
    c: f64,
) -> Vec<(f64, Result<f64, InputError>, usize)> {
    use rayon::prelude::*;
    let n = x.len();
    let a = a_of_c(c);
    let kept: Vec<usize> = (1..=levels).map(|j| n + 1 - (1usize << j)).collect();
    // 1. subsample roots
    let prefix = prefix_sums(x, offset);
    let starts: Vec<Option<f64>> = (1..=levels)
        .into_par_iter()
        .map(|j| {
            let m = kept[j - 1];
            if m < LONG_MIN {
                return None;
            }
            let sub = subsample(&prefix, j, m / SUBSAMPLE);
            match robust_scale(&sub, c, RobustConvention::Exact) {
                Ok(s2) if s2 > 0.0 && s2.is_finite() => Some(s2.sqrt()),
                _ => None,
            }
        })
        .collect();
    drop(prefix);
    let mut states: Vec<LevelState> = starts
        .iter()
        .zip(1..)
        .map(|(start, j)| match start {
            Some(s) => {
                let (lo, hi) = window_around(*s);
                let scale2 = elementary::exp2(-2.0 * j as f64);
                LevelState::Window(PowerAccumulator::new(c, lo, hi, scale2), lo, hi)
            }
            None => LevelState::Collect(Vec::new()),
        })
        .collect();
    let mut results: Vec<Option<(f64, Result<f64, InputError>)>> =
        (0..levels).map(|_| None).collect();
    for round in 0..=WINDOW_SLIDES {
        if states.iter().all(|s| matches!(s, LevelState::Idle)) {
            break;
        }
        if round == WINDOW_SLIDES {
            // last resort: the direct route on the collected coefficients
            for st in &mut states {
                if matches!(st, LevelState::Window(..)) {
                    *st = LevelState::Collect(Vec::new());
                }
            }
        }
        let template = RobustSink(states.clone());
        let pass = haar_pass(x, levels, offset, || template_clone(&template));
        let mut next = Vec::with_capacity(levels);
        for (j, st) in (1..=levels).zip(pass.0) {
            next.push(match st {
                LevelState::Idle => LevelState::Idle,
                LevelState::Collect(w) => {
                    let classical = mean_square(&w);
                    results[j - 1] =
                        Some((classical, robust_scale(&w, c, RobustConvention::Exact)));
                    LevelState::Idle
                }
                LevelState::Window(acc, lo, hi) => {
                    let scale2 = elementary::exp2(-2.0 * j as f64);
                    match acc.finish() {
                        None => LevelState::Collect(Vec::new()),
                        Some(window) => {
                            let classical = window.mean_square();
                            match window.solve(a, lo, hi) {
                                Ok(WindowOutcome::Root(s2)) => {
                                    results[j - 1] = Some((classical, Ok(s2)));
                                    LevelState::Idle
                                }
                                Ok(WindowOutcome::Slide(lo, hi)) => LevelState::Window(
                                    PowerAccumulator::new(c, lo, hi, scale2),
                                    lo,
                                    hi,
                                ),
                                Err(e) => {
                                    results[j - 1] = Some((classical, Err(e)));
                                    LevelState::Idle
                                }
                            }
                        }
                    }
                }
            });
        }
        states = next;
    }
    results
        .into_iter()
        .zip(kept)
        .map(|(r, m)| {
            let (classical, robust) =
                r.unwrap_or((f64::NAN, Err(SeriesError::NoRobustScale { a, c }.into())));
            (classical, robust, m)
        })
        .collect()
}

fn template_clone(t: &RobustSink) -> RobustSink {
    RobustSink(t.0.clone())
}

/// Compensated mean of squares.
fn mean_square(w: &[f64]) -> f64 {
    let mut s = NeumaierSum::default();
    for block in w.chunks(4096) {
        s.add(block.iter().map(|v| v * v).sum());
    }
    s.total() / w.len() as f64
}

/// `P[k] = sum_{i < k} (x_i - offset)`.
fn prefix_sums(x: &[f64], offset: f64) -> Vec<f64> {
    let mut p = Vec::with_capacity(x.len() + 1);
    let mut running = 0.0;
    p.push(0.0);
    for &v in x {
        running += v - offset;
        p.push(running);
    }
    p
}

/// Every `stride`-th boundary-free level-`j` coefficient (the `step_by(stride)` subsample of
/// [`robust_scale_long`](crate::variance::robust::robust_scale_long)), from prefix sums:
/// `W_{j,t} = ((P_{t+1} - P_{t+1-h}) - (P_{t+1-h} - P_{t+1-2h})) / 2^j`, `h = 2^{j-1}`.
fn subsample(prefix: &[f64], j: usize, stride: usize) -> Vec<f64> {
    let n = prefix.len() - 1;
    let h = 1usize << (j - 1);
    let scale = elementary::exp2(-(j as f64));
    ((2 * h - 1)..n)
        .step_by(stride.max(1))
        .map(|t| {
            let newer = prefix[t + 1] - prefix[t + 1 - h];
            let older = prefix[t + 1 - h] - prefix[t + 1 - 2 * h];
            (newer - older) * scale
        })
        .collect()
}
