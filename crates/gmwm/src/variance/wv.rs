//! Wavelet variance: classical (docs/methods.md §1.5, paper eq. 1) and robust (§2), with chi-square
//! confidence intervals (§1.7), for the MODWT (default) and the DWT with any filter of §1.8.
//!
//! The Haar MODWT classical WV — the one every later step of the platform uses — is computed by
//! `HaarWvAccumulator`, a streaming O(N·J) pass that never stores the coefficients and can
//! consume its input in chunks.

use crate::error::{check_finite, check_freq, check_series, InputError, ParamError, SeriesError};
use crate::math::elementary;
use crate::math::special::trigamma;
use crate::math::sum::NeumaierSum;
use crate::variance::ci::{check_alpha, eta3, interval_unchecked};
use crate::variance::haar::haar_square_sums;
use crate::variance::haar_robust::haar_robust_levels;
use crate::variance::robust::{robust_ci, robust_scale, RobustConvention, RobustOptions};
use crate::wavelet::{
    dwt_boundary, modwt_boundary, Dwt, Modwt, Transform, WaveletFilter, MAX_LEVELS,
};
use serde::{Deserialize, Serialize};
use std::fmt;

/// Options of [`wavelet_variance`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WvOptions {
    /// Transform; default MODWT, the package default and the only one with exact implied WV.
    pub transform: Transform,
    /// Wavelet filter; default Haar, the filter every implied-WV formula of docs/methods.md §4
    /// assumes.
    pub filter: WaveletFilter,
    /// Number of levels J; `None` chooses [`default_levels`].
    pub levels: Option<usize>,
    /// Confidence level of the intervals; default 0.05 (95% intervals), as the package.
    pub alpha: f64,
    /// Robust (Tukey biweight M-) estimation when `Some` (docs/methods.md §2).
    pub robust: Option<RobustOptions>,
}

impl Default for WvOptions {
    fn default() -> Self {
        Self {
            transform: Transform::Modwt,
            filter: WaveletFilter::Haar,
            levels: None,
            alpha: 0.05,
            robust: None,
        }
    }
}

/// The wavelet variance of one series across levels `j = 1..J`, with its confidence intervals.
///
/// Wire format (`Serialize`): equal-length arrays `tau` (scale `2^j` in samples), `tau_s`
/// (seconds), `wv`, `ci_low`, `ci_high`, `n_coefficients` (kept coefficients `M_j`) and `eta`
/// (equivalent degrees of freedom), plus the settings that produced them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WaveletVariance {
    /// Length of the series.
    pub(crate) n: usize,
    /// Sampling rate in Hz (labels `tau_s` only).
    pub(crate) freq_hz: f64,
    /// Transform used.
    pub(crate) transform: Transform,
    /// Filter used.
    pub(crate) filter: WaveletFilter,
    /// Confidence level of the intervals.
    pub(crate) alpha: f64,
    /// Robust options, `None` for the classical estimator.
    pub(crate) robust: Option<RobustOptions>,
    /// Scale `tau_j = 2^j` in samples (docs/methods.md §0.1).
    pub(crate) tau: Vec<f64>,
    /// Scale in seconds, `2^j / freq_hz`.
    pub(crate) tau_s: Vec<f64>,
    /// Wavelet variance `nu2_j`.
    pub(crate) wv: Vec<f64>,
    /// Lower confidence bound.
    pub(crate) ci_low: Vec<f64>,
    /// Upper confidence bound.
    pub(crate) ci_high: Vec<f64>,
    /// Number of boundary-free coefficients `M_j` behind each estimate.
    pub(crate) n_coefficients: Vec<usize>,
    /// Equivalent degrees of freedom of the chi-square interval.
    pub(crate) eta: Vec<f64>,
    /// Soft problems met on the way (the affected values are NaN, `null` in JSON).
    pub(crate) warnings: Vec<WvWarning>,
}

/// Read access to the results; the fields are the engine's own.
impl WaveletVariance {
    /// Length of the series.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Sampling rate in Hz (labels `tau_s` only).
    pub fn freq_hz(&self) -> f64 {
        self.freq_hz
    }

    /// Transform used.
    pub fn transform(&self) -> Transform {
        self.transform
    }

    /// Filter used.
    pub fn filter(&self) -> WaveletFilter {
        self.filter
    }

    /// Confidence level of the intervals.
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// Robust options, `None` for the classical estimator.
    pub fn robust(&self) -> Option<RobustOptions> {
        self.robust
    }

    /// Scale `tau_j = 2^j` in samples (docs/methods.md §0.1).
    pub fn tau(&self) -> &[f64] {
        &self.tau
    }

    /// Scale in seconds, `2^j / freq_hz`.
    pub fn tau_s(&self) -> &[f64] {
        &self.tau_s
    }

    /// Wavelet variance `nu2_j`.
    pub fn wv(&self) -> &[f64] {
        &self.wv
    }

    /// Lower confidence bound.
    pub fn ci_low(&self) -> &[f64] {
        &self.ci_low
    }

    /// Upper confidence bound.
    pub fn ci_high(&self) -> &[f64] {
        &self.ci_high
    }

    /// Number of boundary-free coefficients `M_j` behind each estimate.
    pub(crate) fn n_coefficients(&self) -> &[usize] {
        &self.n_coefficients
    }

    /// Equivalent degrees of freedom of the chi-square interval.
    pub fn eta(&self) -> &[f64] {
        &self.eta
    }

    /// Soft problems met on the way (the affected values are NaN, `null` in JSON).
    pub fn warnings(&self) -> &[WvWarning] {
        &self.warnings
    }
}

/// A soft problem of a wavelet-variance computation: the result exists, some levels are missing.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum WvWarning {
    /// The robust scale equation has no root at this level (too large a share of contaminated
    /// coefficients, e.g. a level whose filter spans several outliers); its WV and CI are NaN.
    NoRobustScale {
        /// 1-based level.
        level: usize,
    },
}

impl fmt::Display for WvWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            WvWarning::NoRobustScale { level } => write!(
                f,
                "level {level}: the robust scale is undefined (the biweight scale equation has no root: \
                 too many contaminated or exactly-zero coefficients, or an efficiency too low); \
                 its wavelet variance is left missing — try the classical estimator or fewer levels"
            ),
        }
    }
}

impl WaveletVariance {
    /// Number of levels J.
    pub fn levels(&self) -> usize {
        self.wv.len()
    }

    /// The options that computed this WV (its transform, filter, level count, alpha and
    /// robust settings): what a bootstrap replicate of it is computed with.
    pub fn options(&self) -> WvOptions {
        WvOptions {
            transform: self.transform,
            filter: self.filter,
            levels: Some(self.levels()),
            alpha: self.alpha,
            robust: self.robust,
        }
    }

    /// The first `levels` levels (every per-level vector cut together).
    ///
    /// # Errors
    /// [`ParamError`] naming `levels` unless it is in `1..=self.levels()`.
    pub fn truncated(mut self, levels: usize) -> Result<Self, ParamError> {
        if levels == 0 || levels > self.levels() {
            return Err(ParamError::new(
                "levels",
                levels,
                format!("in 1..={}", self.levels()),
            ));
        }
        for v in [
            &mut self.tau,
            &mut self.tau_s,
            &mut self.wv,
            &mut self.ci_low,
            &mut self.ci_high,
            &mut self.eta,
        ] {
            v.truncate(levels);
        }
        self.n_coefficients.truncate(levels);
        Ok(self)
    }

    /// The variance of `ln nu2_hat_j` at each level: the noise of each estimate on the log
    /// scale of its plot, whatever the level's size.
    ///
    /// # Formula
    /// For the classical estimator `eta_j nu2_hat_j / nu2_j` is approximately chi-square with
    /// `eta_j` degrees of freedom (the approximation behind the intervals, docs/methods.md §1.7),
    /// and the log of a chi-square variable with `eta` degrees of freedom has variance
    /// `psi'(eta / 2)` (the trigamma function): `2 / eta` for large `eta`, 1.64 at
    /// `eta = 2`, 4.93 at `eta = 1`. The robust estimator's is `1 / eff` times larger (the
    /// factor by which its intervals widen, docs/methods.md §2.5).
    ///
    /// ```
    /// use gmwm::{wavelet_variance, WvOptions};
    /// let x: Vec<f64> = (0..4096).map(|t| ((t * 7919) % 101) as f64).collect();
    /// let wv = wavelet_variance(&x, 1.0, &WvOptions::default()).unwrap();
    /// let v = wv.log_variance();
    /// // level 1 keeps 4095 coefficients, eta = 2047.5: about 2 / eta
    /// assert!((v[0] * wv.eta()[0] / 2.0 - 1.0).abs() < 1e-3);
    /// ```
    pub fn log_variance(&self) -> Vec<f64> {
        let widen = self.robust.map_or(1.0, |r| 1.0 / r.eff());
        self.eta
            .iter()
            .map(|&e| trigamma(e / 2.0) * widen)
            .collect()
    }

    /// The WV of the series times `sqrt(factor)` (a unit conversion): estimates and interval
    /// ends times `factor`, counts and degrees of freedom unchanged.
    pub(crate) fn scaled(&self, factor: f64) -> Self {
        let times = |v: &[f64]| v.iter().map(|x| x * factor).collect();
        Self {
            wv: times(&self.wv),
            ci_low: times(&self.ci_low),
            ci_high: times(&self.ci_high),
            ..self.clone()
        }
    }

    /// Assembles the result from per-level estimates and counts: scales, chi-square intervals
    /// (docs/methods.md §1.7) and, for robust estimates, the robust intervals of §2.5.
    pub(crate) fn assemble(
        n: usize,
        freq_hz: f64,
        opts: &WvOptions,
        classical: &[f64],
        robust: Option<&[f64]>,
        n_coefficients: Vec<usize>,
        eta: Vec<f64>,
    ) -> Self {
        let levels = classical.len();
        let tau: Vec<f64> = (1..=levels).map(|j| elementary::exp2(j as f64)).collect();
        let tau_s = tau.iter().map(|t| t / freq_hz).collect();
        let mut wv = Vec::with_capacity(levels);
        let mut ci_low = Vec::with_capacity(levels);
        let mut ci_high = Vec::with_capacity(levels);
        let mut lowest: Option<f64> = None;
        for (i, (&nu_c, &e)) in classical.iter().zip(&eta).enumerate() {
            let (lo_c, hi_c) = interval_unchecked(nu_c, e, opts.alpha);
            match (robust, opts.robust) {
                (Some(r), Some(ro)) => {
                    let (lo, hi) = robust_ci(r[i], nu_c, lo_c, hi_c, ro.eff(), lowest);
                    if lo.is_finite() {
                        lowest = Some(lowest.map_or(lo, |l| l.min(lo)));
                    }
                    wv.push(r[i]);
                    ci_low.push(lo);
                    ci_high.push(hi);
                }
                _ => {
                    wv.push(nu_c);
                    ci_low.push(lo_c);
                    ci_high.push(hi_c);
                }
            }
        }
        Self {
            n,
            freq_hz,
            transform: opts.transform,
            filter: opts.filter,
            alpha: opts.alpha,
            robust: opts.robust,
            tau,
            tau_s,
            wv,
            ci_low,
            ci_high,
            n_coefficients,
            eta,
            warnings: Vec::new(),
        }
    }
}

impl fmt::Display for WaveletVariance {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let kind = match self.robust {
            Some(r) => format!("robust (eff {}, {})", r.eff(), r.convention()),
            None => "classical".to_string(),
        };
        writeln!(
            f,
            "{} wavelet variance, {} {}, N = {}, {:.0}% CI",
            kind,
            self.transform,
            self.filter,
            self.n,
            100.0 * (1.0 - self.alpha)
        )?;
        writeln!(
            f,
            "{:>5} {:>10} {:>12} {:>13} {:>13} {:>13}",
            "level", "tau", "tau_s", "wv", "ci_low", "ci_high"
        )?;
        for j in 0..self.levels() {
            writeln!(
                f,
                "{:>5} {:>10} {:>12.6} {:>13.6e} {:>13.6e} {:>13.6e}",
                j + 1,
                self.tau[j],
                self.tau_s[j],
                self.wv[j],
                self.ci_low[j],
                self.ci_high[j]
            )?;
        }
        Ok(())
    }
}

/// Default number of levels (docs/methods.md §1.6, port recommendation): the largest J with
/// `2^J <= N` whose last level keeps at least two boundary-free coefficients. For the Haar MODWT
/// this is `floor(log2 N)` (the package's default), minus one when N is a power of two — where
/// the package's last level is NaN (§13.1). For the DWT, J is also limited by the number of
/// times N can be halved exactly (§1.4). Returns 0 when not even one level fits.
pub fn default_levels(n: usize, transform: Transform, filter: WaveletFilter) -> usize {
    let mut j = 0;
    while j < MAX_LEVELS && level_fits(n, j + 1, transform, filter, 2) {
        j += 1;
    }
    j
}

/// Kept (boundary-free) coefficient count of level `j` (docs/methods.md §1.3, §1.4), `None` when
/// the level does not exist for this length.
pub(crate) fn kept_count(
    n: usize,
    j: usize,
    transform: Transform,
    filter: WaveletFilter,
) -> Option<usize> {
    let width = 1usize.checked_shl(j as u32)?;
    if width > n {
        return None;
    }
    match transform {
        Transform::Modwt => n.checked_sub(modwt_boundary(filter.len(), j)),
        Transform::Dwt => {
            if n % width != 0 {
                return None;
            }
            (n / width).checked_sub(dwt_boundary(filter.len(), j))
        }
    }
}

fn level_fits(
    n: usize,
    j: usize,
    transform: Transform,
    filter: WaveletFilter,
    min_kept: usize,
) -> bool {
    kept_count(n, j, transform, filter).is_some_and(|k| k >= min_kept)
}

/// Validates a requested level count against the series length.
pub(crate) fn check_levels(n: usize, levels: usize, opts: &WvOptions) -> Result<(), InputError> {
    if levels == 0 || levels > MAX_LEVELS {
        return Err(
            ParamError::new("levels", levels, format!("must be in 1..={MAX_LEVELS}")).into(),
        );
    }
    for j in 1..=levels {
        if !level_fits(n, j, opts.transform, opts.filter, 1) {
            let what = match opts.transform {
                Transform::Dwt if (1usize << j.min(63)) <= n => {
                    return Err(ParamError::new(
                        "levels",
                        levels,
                        format!(
                            "a {levels}-level DWT needs N divisible by 2^{levels}; N = {n} allows at most {} levels (or use the MODWT)",
                            default_levels(n, Transform::Dwt, opts.filter)
                        ),
                    )
                    .into())
                }
                _ => format!("level {j} of a {} {} transform", opts.filter, opts.transform),
            };
            let needed = match opts.transform {
                Transform::Modwt => modwt_boundary(opts.filter.len(), j) + 1,
                Transform::Dwt => 1usize << j.min(63),
            };
            return Err(SeriesError::TooShort { n, needed, what }.into());
        }
    }
    Ok(())
}

/// Wavelet variance of `x` sampled at `freq_hz`, docs/methods.md §1.5 (classical) or §2 (robust),
/// with chi-square intervals (§1.7; robust intervals §2.5).
///
/// The classical Haar MODWT path is a streaming O(N·J) pass (`HaarWvAccumulator`); other
/// filters and the DWT go through the transform (`Modwt`, `Dwt`) and keep O(N·J) memory.
/// The DWT estimate is normalised to the MODWT scale (`mean(W^2) / 2^j`), unlike the package's
/// raw mean which is `2^j` times larger (§13.3); its equivalent degrees of freedom are the
/// number of kept DWT coefficients (independent for white noise), not `M_j / 2^j`.
///
/// # Errors
/// Empty, non-finite or constant series ([`SeriesError`]); bad `alpha`, `levels`, `freq_hz` or
/// robust efficiency ([`ParamError`]); a series too short for the requested levels.
pub fn wavelet_variance(
    x: &[f64],
    freq_hz: f64,
    opts: &WvOptions,
) -> Result<WaveletVariance, InputError> {
    if x.len() == 1 {
        return Err(SeriesError::TooShort {
            n: 1,
            needed: 2,
            what: "one level of the wavelet variance".into(),
        }
        .into());
    }
    let n = x.len();
    // Checks that do not read the data first; a series error still takes precedence over them.
    let params = (|| -> Result<usize, InputError> {
        check_alpha(opts.alpha)?;
        check_freq(freq_hz)?;
        // With no level keeping two coefficients, ask for one so that check_levels reports the
        // precise reason.
        let levels = opts
            .levels
            .unwrap_or_else(|| default_levels(n, opts.transform, opts.filter).max(1));
        check_levels(n, levels, opts)?;
        Ok(levels)
    })();
    let levels = match params {
        Ok(levels) => levels,
        Err(e) => {
            check_series(x)?;
            return Err(e);
        }
    };

    if opts.robust.is_none()
        && opts.transform == Transform::Modwt
        && opts.filter == WaveletFilter::Haar
    {
        // The data are checked inside the pass (a non-finite sample makes the sums NaN), so
        // the series is read once.
        return haar_wv_in_memory(x, levels, freq_hz, opts.alpha);
    }
    check_series(x)?;

    if let (Some(r), Transform::Modwt, WaveletFilter::Haar) =
        (opts.robust, opts.transform, opts.filter)
    {
        if r.convention() == RobustConvention::Exact {
            return haar_robust_in_memory(x, levels, freq_hz, opts);
        }
    }

    let coefs = match opts.transform {
        Transform::Modwt => Modwt::new(opts.filter, levels)?.transform(x)?,
        Transform::Dwt => Dwt::new(opts.filter, levels)?.transform(x)?,
    };
    let c = opts.robust.map(|r| r.tuning_constant());
    // Levels are independent once the transform is done: the robust solves (the expensive
    // part, O(n) per fixed-point step) run in parallel across levels.
    use rayon::prelude::*;
    let per_level: Vec<(f64, Option<f64>, usize)> = (1..=levels)
        .into_par_iter()
        .map(|j| {
            let kept = coefs.kept(j);
            let scale = match opts.transform {
                Transform::Modwt => 1.0,
                Transform::Dwt => elementary::exp2(j as f64),
            };
            let robust = match (c, opts.robust) {
                (Some(c), Some(r)) => match robust_scale(kept, c, r.convention()) {
                    Ok(s2) => Some(s2 / scale),
                    Err(InputError::Series(SeriesError::NoRobustScale { .. })) => Some(f64::NAN),
                    Err(e) => return Err(e),
                },
                _ => None,
            };
            Ok((mean_square(kept) / scale, robust, kept.len()))
        })
        .collect::<Result<_, InputError>>()?;
    from_levels(n, freq_hz, opts, &per_level)
}

/// The result from per-level `(classical, robust, kept)` estimates: refuses a non-finite
/// classical value, turns NaN robust levels into [`WvWarning::NoRobustScale`], and sets the
/// degrees of freedom (eta3 for the MODWT, the kept count for the DWT).
fn from_levels(
    n: usize,
    freq_hz: f64,
    opts: &WvOptions,
    per_level: &[(f64, Option<f64>, usize)],
) -> Result<WaveletVariance, InputError> {
    let classical: Vec<f64> = per_level.iter().map(|l| l.0).collect();
    check_finite_result(&classical, "wavelet variance")?;
    let robust: Vec<f64> = per_level.iter().filter_map(|l| l.1).collect();
    let warnings = robust
        .iter()
        .zip(1..)
        .filter(|(v, _)| v.is_nan())
        .map(|(_, level)| WvWarning::NoRobustScale { level })
        .collect();
    let counts: Vec<usize> = per_level.iter().map(|l| l.2).collect();
    let eta = counts
        .iter()
        .zip(1..)
        .map(|(&kept, j)| match opts.transform {
            Transform::Modwt => eta3(kept, j),
            Transform::Dwt => (kept as f64).max(1.0),
        })
        .collect();
    let robust = opts.robust.map(|_| robust.as_slice());
    let mut result = WaveletVariance::assemble(n, freq_hz, opts, &classical, robust, counts, eta);
    result.warnings = warnings;
    Ok(result)
}

/// Robust (Exact convention) Haar MODWT WV of an in-memory series (docs/methods.md §2, §2.5): the
/// coefficients level by level ([`for_each_haar_level`], the pyramid of the classical pass with
/// the mean of the first block removed) and the robust scale of each by [`robust_scale_long`],
/// the next level's transform overlapping the current level's solve. `x` has been checked.
fn haar_robust_in_memory(
    x: &[f64],
    levels: usize,
    freq_hz: f64,
    opts: &WvOptions,
) -> Result<WaveletVariance, InputError> {
    let n = x.len();
    let r = opts.robust.expect("robust options");
    let c = r.tuning_constant();
    let head = &x[..n.min(crate::variance::haar::BLOCK)];
    let offset = head.iter().sum::<f64>() / head.len() as f64;
    let per_level = haar_robust_levels(x, levels, offset, c)
        .into_iter()
        .map(|(classical, robust, kept)| {
            let robust = match robust {
                Ok(s2) => s2,
                Err(InputError::Series(SeriesError::NoRobustScale { .. })) => f64::NAN,
                Err(e) => return Err(e),
            };
            Ok((classical, Some(robust), kept))
        })
        .collect::<Result<Vec<_>, InputError>>()?;
    from_levels(n, freq_hz, opts, &per_level)
}

/// Refuses non-finite estimates from finite data (overflowing squares): never silent numbers.
pub(crate) fn check_finite_result(values: &[f64], what: &str) -> Result<(), SeriesError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(SeriesError::Overflow { what: what.into() })
    }
}

/// Sum with four independent accumulators (vectorisable; blocks are then combined with a
/// compensated sum by the caller).
#[inline(always)]
pub(crate) fn sum_plain(x: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let mut quads = x.chunks_exact(4);
    for q in &mut quads {
        for k in 0..4 {
            acc[k] += q[k];
        }
    }
    let tail: f64 = quads.remainder().iter().sum();
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// Mean of squares with a compensated accumulation of block sums.
fn mean_square(x: &[f64]) -> f64 {
    let mut s = NeumaierSum::default();
    for block in x.chunks(BLOCK) {
        s.add(sum_squares(block));
    }
    s.total() / x.len() as f64
}

/// Block length of the streaming pass: 4096 doubles (32 KiB) per buffer keeps the working set
/// of one level in L1/L2 while amortising the per-block bookkeeping.
pub(crate) const BLOCK: usize = 4096;

/// Sum of squares with four independent accumulators (lets the compiler vectorise; the partial
/// sums of one block are then combined with a compensated sum by the caller).
#[inline(always)]
pub(crate) fn sum_squares(x: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let mut quads = x.chunks_exact(4);
    for q in &mut quads {
        acc[0] += q[0] * q[0];
        acc[1] += q[1] * q[1];
        acc[2] += q[2] * q[2];
        acc[3] += q[3] * q[3];
    }
    let tail: f64 = quads.remainder().iter().map(|v| v * v).sum();
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// Streaming Haar MODWT classical wavelet variance (docs/methods.md §1.2 pyramid, §1.3, §1.5).
///
/// Feed the series in chunks of any size with [`push`](Self::push), then [`finish`](Self::finish).
/// Level j keeps a ring of the last `2^{j-1}` values of the level-(j-1) scaling coefficients,
/// so memory is `8 · 2^J` bytes whatever N and the chunk sizes; time is O(N·J).
///
/// Numerical care: a constant offset (the mean of the first 2048 samples, as
/// [`wavelet_variance`] takes it) is subtracted before the pyramid — the Haar wavelet filter
/// annihilates constants, so this changes nothing mathematically but keeps an accelerometer's
/// −1 g bias from eating digits — and the squared coefficients are summed per block of 4096
/// samples (blocks fixed by the sample index, so any chunking gives the same bits), block sums
/// then added with Neumaier's compensated sum.
///
/// # Formula
/// `V_{j,t} = (V_{j-1,t} + V_{j-1,t-m}) / 2`, `W_{j,t} = (V_{j-1,t} - V_{j-1,t-m}) / 2`,
/// `m = 2^{j-1}`; coefficients with `t < 2^j - 1` (boundary) are skipped.
#[derive(Debug, Clone)]
pub(crate) struct HaarWvAccumulator {
    levels: usize,
    /// First level run through the pyramid: 1, except for the upper half of a level split
    /// ([`upper_part`](Self::upper_part)), fed with the scaling coefficients of the level below.
    low: usize,
    /// Last level run through the pyramid: `levels`, except in a part of a split pass
    /// ([`for_part`](Self::for_part)) whose end comes before the first kept coefficient of the
    /// levels above (their sums stay zero there).
    active: usize,
    offset: Option<f64>,
    n: u64,
    first: Option<f64>,
    /// The lag rings one after the other: level j's `2^{j-1}` values start at `2^{j-1} - 1`
    /// ([`ring_span`]) less `2^{low-1} - 1`.
    rings: Vec<f64>,
    pos: Vec<usize>,
    sums: Vec<NeumaierSum>,
    scratch_in: Vec<f64>,
    scratch_out: Vec<f64>,
    /// Samples pushed but not yet run through the pyramid: blocks start at multiples of
    /// [`BLOCK`] in the series, whatever the chunks, so the roundings do not depend on them.
    pending: Vec<f64>,
    /// Running sums of [`prime`](Self::prime), one a level (empty once the part runs).
    priming: Vec<f64>,
    /// With `Some`, the scaling coefficients of the last level run, block after block, for the
    /// upper half of a level split.
    emitted: Option<Vec<f64>>,
    /// The samples pushed are known to be finite (checked where they were read).
    checked: bool,
    /// The series starts with this accumulator (no priming): until a level's ring has wrapped
    /// once, its lags lie before the start and are the pyramid's zeros, so the large rings
    /// ([`haar_level`]'s second case) are written before they are ever read, and need no
    /// zeroing (fresh pages are then faulted in once, as they are first written).
    fresh: bool,
}

/// Levels whose ring is read within a block ([`haar_level`]'s first case, `2^{j-1} <= BLOCK`):
/// the only rings a fresh accumulator must zero.
const SMALL_RING_LEVELS: usize = 13;

/// Zeroes the rings of levels `low..=active.min(SMALL_RING_LEVELS)` in `rings` (which starts with
/// level `low`'s).
fn zero_small_rings(rings: &mut [f64], low: usize, active: usize) {
    let top = active.min(SMALL_RING_LEVELS);
    if top >= low {
        let base = ring_span(low).start;
        rings[..ring_span(top).end - base].fill(0.0);
    }
}

/// Where level j's lag ring (`2^{j-1}` values) lies in [`HaarWvAccumulator`]'s ring storage.
#[inline]
fn ring_span(j: usize) -> std::ops::Range<usize> {
    (1usize << (j - 1)) - 1..(1usize << j) - 1
}

/// Samples per lane block of [`HaarWvAccumulator::prime`]: the running sums of the levels whose
/// ring holds at least this many values run four interleaved chains over blocks of this length,
/// aligned on the level's span (which history reads must respect, see
/// [`PRIME_ALIGN`]).
pub(crate) const PRIME_BLOCK: usize = 2048;

/// History reads of [`HaarWvAccumulator::prime`] end at `t0 - k · PRIME_ALIGN`: a multiple of
/// [`PRIME_BLOCK`], so that no lane block straddles two of them.
pub(crate) const PRIME_ALIGN: usize = 1 << 16;

impl HaarWvAccumulator {
    /// A new accumulator for `levels` levels; the offset is the mean of the first block of
    /// samples (as [`wavelet_variance`] takes it, so the two agree to the last bits).
    ///
    /// # Errors
    /// [`ParamError`] when `levels` is 0 or above [`MAX_LEVELS`].
    #[cfg(test)]
    pub(crate) fn new(levels: usize) -> Result<Self, ParamError> {
        if levels == 0 || levels > MAX_LEVELS {
            return Err(ParamError::new(
                "levels",
                levels,
                format!("must be in 1..={MAX_LEVELS}"),
            ));
        }
        Ok(Self {
            levels,
            low: 1,
            active: levels,
            offset: None,
            n: 0,
            first: None,
            // zeros never read but for the small rings (see `fresh`): calloc'd pages that are
            // faulted in as they are first written
            rings: vec![0.0; (1usize << levels) - 1],
            pos: vec![0; levels],
            sums: vec![NeumaierSum::default(); levels],
            scratch_in: Vec::with_capacity(BLOCK),
            scratch_out: Vec::with_capacity(BLOCK),
            pending: Vec::with_capacity(BLOCK),
            priming: Vec::new(),
            emitted: None,
            checked: false,
            fresh: true,
        })
    }

    /// A new accumulator that subtracts `offset` (e.g. the series mean) from every sample.
    ///
    /// # Errors
    /// As [`new`](Self::new); also when `offset` is not finite.
    #[cfg(test)]
    pub(crate) fn with_offset(levels: usize, offset: f64) -> Result<Self, ParamError> {
        if !offset.is_finite() {
            return Err(ParamError::new("offset", offset, "must be finite"));
        }
        let mut acc = Self::new(levels)?;
        acc.offset = Some(offset);
        Ok(acc)
    }

    /// An accumulator for the part `[t0, end)` of a series split in time (a split pass adds
    /// the parts' sums in order with [`append`](Self::append)): it subtracts `offset` (the
    /// series', the mean of its first 2048 samples), numbers its samples from `t0`, runs only
    /// the levels with a kept coefficient before `end` and keeps its rings in `storage` (a
    /// buffer of an earlier part, reused: its length does not matter). Unless `t0 = 0`, the
    /// rings must then be filled by [`prime`](Self::prime) with the samples before `t0`.
    ///
    /// `t0` must be a multiple of 4096 (the blocks of the sums start at multiples of 4096 in
    /// the series).
    pub(crate) fn for_part(
        levels: usize,
        offset: f64,
        t0: usize,
        end: usize,
        storage: Vec<f64>,
    ) -> Result<Self, ParamError> {
        Self::for_part_capped(levels, offset, t0, end, storage, levels)
    }

    /// [`for_part`](Self::for_part) running at most `ring_levels` levels through the pyramid:
    /// the levels above are left to the caller, who adds their sums with
    /// [`add_level_sum`](Self::add_level_sum).
    pub(crate) fn for_part_capped(
        levels: usize,
        offset: f64,
        t0: usize,
        end: usize,
        mut storage: Vec<f64>,
        ring_levels: usize,
    ) -> Result<Self, ParamError> {
        debug_assert!(t0 % BLOCK == 0 && t0 < end);
        if levels == 0 || levels > MAX_LEVELS {
            return Err(ParamError::new(
                "levels",
                levels,
                format!("must be in 1..={MAX_LEVELS}"),
            ));
        }
        // level j's first kept coefficient is at t = 2^j - 1
        let active = (1..=levels.min(ring_levels))
            .take_while(|&j| (1usize << j) <= end)
            .count();
        let len = (1usize << active) - 1;
        if t0 == 0 {
            // only the small rings are read before they are written (see `fresh`): the old
            // values may stay, and new storage is calloc'd, untouched
            if storage.capacity() < len {
                storage = vec![0.0; len];
            } else {
                storage.resize(len, 0.0);
            }
            zero_small_rings(&mut storage, 1, active);
        } else {
            // prime writes every value but those whose windows lie wholly before the series
            // start, which are zero (prime only sees samples from 0 on)
            storage.resize(len, 0.0);
            for j in 1..=active {
                let before_start = (1usize << j).saturating_sub(t0).min(1 << (j - 1));
                let span = ring_span(j);
                storage[span.start..span.start + before_start].fill(0.0);
            }
        }
        Ok(Self {
            levels,
            low: 1,
            active,
            offset: Some(offset),
            n: t0 as u64,
            first: None,
            rings: storage,
            pos: vec![0; levels],
            sums: vec![NeumaierSum::default(); levels],
            scratch_in: Vec::with_capacity(BLOCK),
            scratch_out: Vec::with_capacity(BLOCK),
            pending: Vec::with_capacity(BLOCK),
            priming: if t0 == 0 {
                Vec::new()
            } else {
                vec![0.0; active]
            },
            emitted: None,
            checked: false,
            fresh: t0 == 0,
        })
    }

    /// The upper half of a level split of the part `[0, end)` of a series (a part that needs no
    /// priming): levels `low..` (up to `ring_levels`, and those with a kept coefficient before
    /// `end`), run on the level-`(low - 1)` scaling coefficients that the lower half, made by
    /// [`for_part_capped`](Self::for_part_capped) with `ring_levels = low - 1` and told to
    /// [`emit`](Self::emit) them, hands out block by block
    /// ([`take_emitted`](Self::take_emitted)), pushed in order. The two halves run in parallel
    /// on consecutive chunks, and together ([`append_upper`](Self::append_upper) once both
    /// are closed) compute exactly, bit for bit, what one accumulator would have.
    pub(crate) fn upper_part(
        levels: usize,
        end: usize,
        low: usize,
        ring_levels: usize,
    ) -> Result<Self, ParamError> {
        let mut upper = Self::for_part_capped(levels, 0.0, 0, end, Vec::new(), low - 1)?;
        let active = (1..=levels.min(ring_levels))
            .take_while(|&j| (1usize << j) <= end)
            .count();
        debug_assert!(low >= 2 && low <= active);
        // the rings of levels low..=active: calloc'd, the small ones zeroed (see `fresh`)
        let mut rings = vec![0.0; ring_span(active).end - ring_span(low).start];
        zero_small_rings(&mut rings, low, active);
        upper.rings = rings;
        upper.low = low;
        upper.active = active;
        Ok(upper)
    }

    /// Skips the check for non-finite samples: the caller checked them when it read them.
    pub(crate) fn trust_finite(&mut self) {
        self.checked = true;
    }

    /// Makes the lower half of a level split hand out the scaling coefficients of its last level
    /// ([`upper_part`](Self::upper_part)).
    pub(crate) fn emit(&mut self) {
        self.emitted = Some(Vec::new());
    }

    /// The scaling coefficients run so far by the lower half of a level split, replacing them
    /// by `reuse` (emptied).
    pub(crate) fn take_emitted(&mut self, mut reuse: Vec<f64>) -> Vec<f64> {
        reuse.clear();
        match &mut self.emitted {
            Some(e) => std::mem::replace(e, reuse),
            None => reuse,
        }
    }

    /// Adds the sums of the upper half of a level split (closed) to the lower half's.
    pub(crate) fn append_upper(&mut self, upper: &Self) {
        for (a, b) in self.sums[upper.low - 1..]
            .iter_mut()
            .zip(&upper.sums[upper.low - 1..])
        {
            a.add(b.total());
        }
    }

    /// Fills the rings of a [`for_part`](Self::for_part) accumulator from the samples before
    /// its start `t0`: `values` are the samples from `start` on. Calls come in time order and
    /// cover `[t0 - 2^L, t0)` (from 0 when `t0 < 2^L`), `L` the levels run; every call but the
    /// first starts, and every call ends, at `t0` minus a multiple of [`PRIME_ALIGN`], so the
    /// result depends on the samples alone, not on how they are read.
    ///
    /// Level j's ring holds `V_{j-1,t}` for `t` in `[t0 - m, t0)`, `m = 2^{j-1}`: the mean of
    /// the `m` samples up to `t` (zero before the series start), which a running sum over the
    /// last `2^j` samples gives directly, O(2^j) instead of running the pyramid over them. The
    /// running sum of each level starts at its own span, so it stays of the size of the
    /// level's windows. Levels with at least [`PRIME_BLOCK`] values run it in blocks of that
    /// length, each as four interleaved chains started from the block's quarter totals.
    pub(crate) fn prime(&mut self, start: usize, values: &[f64]) {
        let t0 = self.n as usize;
        // in pieces ending at t0 - k PRIME_ALIGN (the scratch stays small)
        let end = start + values.len();
        let mut from = start;
        while from < end {
            let to = (t0 - (t0 - from - 1) / PRIME_ALIGN * PRIME_ALIGN).min(end);
            self.prime_piece(from, &values[from - start..to - start]);
            from = to;
        }
    }

    fn prime_piece(&mut self, start: usize, values: &[f64]) {
        let t0 = self.n as usize;
        let offset = self.offset.unwrap_or(0.0);
        debug_assert!(start + values.len() <= t0);
        let mut y = std::mem::take(&mut self.scratch_in);
        y.clear();
        y.extend(values.iter().map(|&v| v - offset));
        debug_assert!(self.low == 1, "prime before a level split");
        prime_levels(&mut self.rings, &mut self.priming, t0, start, &y);
        self.scratch_in = y;
    }

    /// Appends the sums of the accumulator of the next part of a split pass (flushed), whose
    /// rings are no longer needed.
    pub(crate) fn append(&mut self, later: &Self) {
        debug_assert!(later.pending.is_empty() && self.pending.is_empty());
        for (a, b) in self.sums.iter_mut().zip(&later.sums) {
            a.add(b.total());
        }
        self.n = later.n;
    }

    /// Adds `sum` (of squared wavelet coefficients) to level `j` (1-based): the levels a split
    /// pass computes without the pyramid.
    pub(crate) fn add_level_sum(&mut self, j: usize, sum: f64) {
        self.sums[j - 1].add(sum);
    }

    /// Levels run through the pyramid.
    pub(crate) fn active_levels(&self) -> usize {
        self.active
    }

    /// Runs the pending samples of a part through the pyramid (the part's last block may be
    /// partial only at the series end) and hands back the ring storage for the next part.
    pub(crate) fn close_part(&mut self) -> Result<Vec<f64>, SeriesError> {
        self.flush()?;
        self.priming = Vec::new();
        // a closed part keeps its sums only: a 10^9-sample pass holds 239 of them until they
        // are added in order
        self.pending = Vec::new();
        self.scratch_in = Vec::new();
        self.scratch_out = Vec::new();
        Ok(std::mem::take(&mut self.rings))
    }

    /// Feeds the next chunk of the series.
    ///
    /// # Errors
    /// [`SeriesError::NonFinite`] with the global 0-based index of the first NaN/Inf sample; the
    /// accumulator is then unusable for a meaningful result.
    ///
    /// The samples run through the pyramid in blocks that start at multiples of 4096 samples in
    /// the series, so any chunking gives the same bits; a non-finite sample is reported by the
    /// push (or [`finish`](Self::finish)) that completes its block.
    pub(crate) fn push(&mut self, chunk: &[f64]) -> Result<(), SeriesError> {
        let mut rest = chunk;
        if !self.pending.is_empty() {
            let take = (BLOCK - self.pending.len()).min(rest.len());
            self.pending.extend_from_slice(&rest[..take]);
            rest = &rest[take..];
            if self.pending.len() < BLOCK {
                return Ok(());
            }
            self.flush()?;
        }
        let whole = rest.len() / BLOCK * BLOCK;
        for block in rest[..whole].chunks(BLOCK) {
            self.push_block(block)?;
        }
        self.pending.extend_from_slice(&rest[whole..]);
        Ok(())
    }

    /// Runs the pending samples through the pyramid (a partial block only at the end).
    fn flush(&mut self) -> Result<(), SeriesError> {
        let pending = std::mem::take(&mut self.pending);
        let result = self.push_block(&pending);
        self.pending = pending;
        self.pending.clear();
        result
    }

    fn push_block(&mut self, block: &[f64]) -> Result<(), SeriesError> {
        let Some(&head) = block.first() else {
            return Ok(());
        };
        // the mean of the series' first samples, computed as `haar_wv_in_memory` does
        let offset = *self.offset.get_or_insert_with(|| {
            let head = &block[..block.len().min(crate::variance::haar::BLOCK)];
            head.iter().sum::<f64>() / head.len() as f64
        });
        self.first.get_or_insert(head);
        let mut input = std::mem::take(&mut self.scratch_in);
        let mut output = std::mem::take(&mut self.scratch_out);
        if !self.checked {
            if let Err(e) = check_finite(block) {
                self.scratch_in = input;
                self.scratch_out = output;
                return Err(match e {
                    SeriesError::NonFinite { index, value } => SeriesError::NonFinite {
                        index: self.n as usize + index,
                        value,
                    },
                    other => other,
                });
            }
        }
        input.clear();
        input.extend(block.iter().map(|&v| v - offset));
        output.resize(input.len(), 0.0);
        self.pyramid_block(&mut input, &mut output);
        if let Some(e) = &mut self.emitted {
            e.extend_from_slice(&input);
        }
        self.n += block.len() as u64;
        self.scratch_in = input;
        self.scratch_out = output;
        Ok(())
    }

    /// Finishes the pass: wavelet variance with chi-square intervals (docs/methods.md §1.5, §1.7).
    ///
    /// # Errors
    /// [`SeriesError`] when nothing was pushed, the series is constant, or it is too short for
    /// the levels requested; [`ParamError`] for a bad `freq_hz` or `alpha`.
    pub(crate) fn finish(
        mut self,
        freq_hz: f64,
        alpha: f64,
    ) -> Result<WaveletVariance, InputError> {
        check_alpha(alpha)?;
        check_freq(freq_hz)?;
        self.flush()?;
        let n = self.n as usize;
        // Level-1 coefficients are halved differences of consecutive samples: they are all zero
        // exactly when the series is constant.
        match self.first {
            None => return Err(SeriesError::Empty.into()),
            Some(value) if self.sums[0].total() == 0.0 => {
                return Err(SeriesError::Constant { value }.into())
            }
            _ => {}
        }
        let opts = WvOptions {
            levels: Some(self.levels),
            alpha,
            ..WvOptions::default()
        };
        check_levels(n, self.levels, &opts)?;
        let mut wv = Vec::with_capacity(self.levels);
        let mut counts = Vec::with_capacity(self.levels);
        let mut eta = Vec::with_capacity(self.levels);
        for (j, sum) in (1..=self.levels).zip(&self.sums) {
            let kept = n + 1 - (1usize << j);
            wv.push(sum.total() / kept as f64);
            counts.push(kept);
            eta.push(eta3(kept, j));
        }
        check_finite_result(&wv, "wavelet variance")?;
        Ok(WaveletVariance::assemble(
            n, freq_hz, &opts, &wv, None, counts, eta,
        ))
    }
}

impl HaarWvAccumulator {
    /// The pyramid over the next block: `input` holds `V_{low-1}` (the demeaned samples for
    /// `low = 1`) and ends holding the last level's `V`; `output` is scratch. Level j
    /// (`low..=active`) reads `V_{j-1}` and its ring and adds its squared boundary-free
    /// coefficients to its sum.
    fn pyramid_block(&mut self, input: &mut Vec<f64>, output: &mut Vec<f64>) {
        let t0 = self.n;
        let base = ring_span(self.low).start;
        let levels = self.low - 1..self.active;
        let pos = &mut self.pos[levels.clone()];
        let sums = &mut self.sums[levels];
        for (j, (pos, sum)) in (self.low..).zip(pos.iter_mut().zip(sums.iter_mut())) {
            // First boundary-free coefficient of level j is at t = 2^j - 1.
            let first_valid = (1u64 << j) - 1;
            let skip = first_valid.saturating_sub(t0).min(input.len() as u64) as usize;
            let span = ring_span(j);
            let ring = &mut self.rings[span.start - base..span.end - base];
            // a block wholly in the ring's first wrap (its end is a multiple of BLOCK, as is
            // 2^{j-1} in haar_level's second case, so a block is wholly in it or wholly out)
            let first_wrap = self.fresh && t0 + input.len() as u64 <= 1u64 << (j - 1);
            let s = haar_level(input, output, ring, pos, skip, first_wrap);
            sum.add(s);
            std::mem::swap(input, output);
        }
    }
}

crate::variance::simd::multiversion! {
    /// The priming of every level's ring ([`HaarWvAccumulator::prime`]) by demeaned samples `y`
    /// from sample `start` on, for a part starting at `t0`; `running` holds each level's
    /// running sum.
    fn prime_levels(rings: &mut [f64], running: &mut [f64], t0: usize, start: usize, y: &[f64])
        => prime_levels_impl
}

#[inline(always)]
fn prime_levels_impl(rings: &mut [f64], running: &mut [f64], t0: usize, start: usize, y: &[f64]) {
    let end = start + y.len();
    for (j, run) in (1..).zip(running.iter_mut()) {
        let m = 1usize << (j - 1);
        // the level's span [t0 - 2m, t0): o = s - (t0 - 2m) numbers its samples
        let base = t0 as isize - 2 * m as isize;
        let lo = (start as isize).max(base).max(0);
        let hi = end as isize;
        if lo >= hi {
            continue;
        }
        let ring = &mut rings[ring_span(j)];
        let inv = 1.0 / m as f64;
        let ys = &y[(lo - start as isize) as usize..(hi - start as isize) as usize];
        let o0 = (lo - base) as usize;
        if m < PRIME_BLOCK {
            for (o, &v) in (o0..).zip(ys) {
                *run += v;
                prime_slot(ring, o, m, *run, inv);
            }
            continue;
        }
        debug_assert!(o0 % PRIME_BLOCK == 0 && ys.len() % PRIME_BLOCK == 0);
        for (b, block) in ys.chunks(PRIME_BLOCK).enumerate() {
            let o = o0 + b * PRIME_BLOCK;
            if block.len() < PRIME_BLOCK {
                // only for reads that break the alignment contract
                for (o, &v) in (o..).zip(block) {
                    *run += v;
                    prime_slot(ring, o, m, *run, inv);
                }
                continue;
            }
            *run = prime_block(ring, o, m, *run, inv, block);
        }
    }
}

/// One step of [`HaarWvAccumulator::prime`] for level j (`m = 2^{j-1}`): `run` is the running
/// sum up to sample `o` of the level's span (numbered from `t0 - 2m`). The first half stores
/// it; the second half turns the stored sum `m` samples back into the window mean.
#[inline(always)]
fn prime_slot(ring: &mut [f64], o: usize, m: usize, run: f64, inv: f64) {
    if o < m {
        ring[o] = run;
    } else {
        ring[o - m] = (run - ring[o - m]) * inv;
    }
}

/// [`prime_slot`] over a block of [`PRIME_BLOCK`] samples (starting at span index `o0`, wholly
/// in one half of the span): four chains, one per quarter, started from the running sum plus
/// the quarter totals. Returns the running sum after the block (the start plus the totals).
#[inline(always)]
fn prime_block(ring: &mut [f64], o0: usize, m: usize, run: f64, inv: f64, ys: &[f64]) -> f64 {
    const Q: usize = PRIME_BLOCK / 4;
    let q: [&[f64]; 4] = [
        &ys[..Q],
        &ys[Q..2 * Q],
        &ys[2 * Q..3 * Q],
        &ys[3 * Q..PRIME_BLOCK],
    ];
    let totals = q.map(sum_plain);
    let mut s = [0.0; 4];
    s[0] = run;
    for l in 1..4 {
        s[l] = s[l - 1] + totals[l - 1];
    }
    let after = s[3] + totals[3];
    if o0 < m {
        let (r0, rest) = ring[o0..o0 + PRIME_BLOCK].split_at_mut(Q);
        let (r1, rest) = rest.split_at_mut(Q);
        let (r2, r3) = rest.split_at_mut(Q);
        for i in 0..Q {
            s[0] += q[0][i];
            s[1] += q[1][i];
            s[2] += q[2][i];
            s[3] += q[3][i];
            r0[i] = s[0];
            r1[i] = s[1];
            r2[i] = s[2];
            r3[i] = s[3];
        }
    } else {
        let (r0, rest) = ring[o0 - m..o0 - m + PRIME_BLOCK].split_at_mut(Q);
        let (r1, rest) = rest.split_at_mut(Q);
        let (r2, r3) = rest.split_at_mut(Q);
        for i in 0..Q {
            s[0] += q[0][i];
            s[1] += q[1][i];
            s[2] += q[2][i];
            s[3] += q[3][i];
            r0[i] = (s[0] - r0[i]) * inv;
            r1[i] = (s[1] - r1[i]) * inv;
            r2[i] = (s[2] - r2[i]) * inv;
            r3[i] = (s[3] - r3[i]) * inv;
        }
    }
    after
}

/// Haar MODWT WV of an in-memory series ([`haar_square_sums`]: the pyramid of
/// [`HaarWvAccumulator`] with the same roundings, blocked and split in time and phase), for
/// valid parameters and `x.len() >= 2`.
///
/// The data checks of [`check_series`] are folded in: a constant series is found by a scan that
/// stops at the first differing sample, a non-finite sample turns the sums into NaN and
/// [`check_series`] then names it. The offset removed before the pyramid (docs/methods.md §1.5 is
/// unchanged by any constant offset) is the mean of the first [`BLOCK`](crate::variance::haar::BLOCK)
/// samples, the series' level where it starts, so no extra pass over the data is needed. Falls
/// back to the streaming pass when the kernel's window sums or squares overflow (data near
/// `f64::MAX`), so that edge keeps the accumulator's behaviour.
fn haar_wv_in_memory(
    x: &[f64],
    levels: usize,
    freq_hz: f64,
    alpha: f64,
) -> Result<WaveletVariance, InputError> {
    let first = x[0];
    if first.is_finite() && x.iter().all(|&v| v == first) {
        return Err(SeriesError::Constant { value: first }.into());
    }
    let head = &x[..x.len().min(crate::variance::haar::BLOCK)];
    let offset = head.iter().sum::<f64>() / head.len() as f64;
    let sums = haar_square_sums(x, levels, offset);
    if !sums.iter().all(|s| s.is_finite()) {
        check_series(x)?;
        return haar_wv_parallel(x, levels, freq_hz, alpha);
    }
    if sums.iter().all(|&s| s < f64::MIN_POSITIVE) {
        // zero or subnormal at every level from non-constant data: squares underflowed
        check_series(x)?;
    }
    let n = x.len();
    let opts = WvOptions {
        levels: Some(levels),
        alpha,
        ..WvOptions::default()
    };
    check_levels(n, levels, &opts)?;
    let mut wv = Vec::with_capacity(levels);
    let mut counts = Vec::with_capacity(levels);
    let mut eta = Vec::with_capacity(levels);
    for (j, sum) in (1..=levels).zip(&sums) {
        let kept = n + 1 - (1usize << j);
        wv.push(sum / kept as f64);
        counts.push(kept);
        eta.push(eta3(kept, j));
    }
    check_finite_result(&wv, "wavelet variance")?;
    Ok(WaveletVariance::assemble(
        n, freq_hz, &opts, &wv, None, counts, eta,
    ))
}

/// Smallest part of a split Haar pass ([`part_len`]): `2^22` samples.
pub(crate) const PART_MIN: usize = 1 << 22;

/// Samples per part of a split Haar pass: parts start at multiples of this length, a function
/// of the level count (and of `min`, [`PART_MIN`] but in tests) alone, never of the thread
/// count or of how the data are read, so the result is the same on any number of threads:
/// `min`, or `2^{J-2}` when larger (more than 24 levels), since each part after the first
/// primes its rings from the `2^J` samples before it, which this keeps to four parts' worth.
/// `min` is a power of two of at least 4096 samples.
pub(crate) fn part_len(levels: usize, min: usize) -> usize {
    debug_assert!(min.is_power_of_two() && min >= BLOCK);
    min.max(1usize << levels.saturating_sub(2).min(usize::BITS as usize - 2))
}

/// Haar MODWT WV of an in-memory series, split in time ([`part_len`]) across the rayon pool:
/// each part's rings are primed from the samples before it ([`HaarWvAccumulator::prime`]),
/// the per-level sums are then added in part order, so the result does not depend on the
/// thread count. `x` has been checked (finite, not constant) by the caller.
fn haar_wv_parallel(
    x: &[f64],
    levels: usize,
    freq_hz: f64,
    alpha: f64,
) -> Result<WaveletVariance, InputError> {
    haar_wv_split(x, levels, freq_hz, alpha, PART_MIN)
}

/// [`haar_wv_parallel`] with parts of [`part_len`]`(levels, min_part)` samples.
fn haar_wv_split(
    x: &[f64],
    levels: usize,
    freq_hz: f64,
    alpha: f64,
    min_part: usize,
) -> Result<WaveletVariance, InputError> {
    use rayon::prelude::*;
    let n = x.len();
    let head = &x[..n.min(crate::variance::haar::BLOCK)];
    let offset = head.iter().sum::<f64>() / head.len() as f64;
    let part = part_len(levels, min_part);
    let partial: Vec<HaarWvAccumulator> = (0..n.div_ceil(part))
        .into_par_iter()
        .map(|p| {
            let (t0, t1) = (p * part, ((p + 1) * part).min(n));
            let mut acc = HaarWvAccumulator::for_part(levels, offset, t0, t1, Vec::new())?;
            if t0 > 0 {
                let history = t0.saturating_sub(1usize << acc.active);
                acc.prime(history, &x[history..t0]);
            }
            acc.push(&x[t0..t1])?;
            acc.close_part()?;
            Ok(acc)
        })
        .collect::<Result<_, InputError>>()?;
    let mut parts = partial.into_iter();
    let mut total = parts.next().expect("at least one part");
    for part in parts {
        total.append(&part);
    }
    total.finish(freq_hz, alpha)
}

/// One Haar pyramid level over a block: reads `V_{j-1}` from `input`, writes `V_j` to `output`,
/// updates the lag ring (length `m = 2^{j-1}`, oldest value at `*pos`), and returns the sum of
/// squared wavelet coefficients from index `skip` on. With `first_wrap` (only for `m > b`), the
/// block's lags all lie before the series start: zeros, not read from the ring (which is
/// written all the same), with the same roundings.
#[inline(always)]
fn haar_level(
    input: &[f64],
    output: &mut [f64],
    ring: &mut [f64],
    pos: &mut usize,
    skip: usize,
    first_wrap: bool,
) -> f64 {
    let m = ring.len();
    let b = input.len();
    let mut ss = 0.0;
    if m <= b {
        // Lags of the first m samples come from the ring (oldest first, from *pos); the rest
        // from the block itself.
        let (newer, older) = ring.split_at(*pos);
        let split = older.len();
        ss += level_span(&input[..split], older, &mut output[..split], skip);
        ss += level_span(
            &input[split..m],
            newer,
            &mut output[split..m],
            skip.saturating_sub(split),
        );
        let (head, body) = output.split_at_mut(m);
        let _ = head;
        ss += level_span(&input[m..], &input[..b - m], body, skip.saturating_sub(m));
        ring.copy_from_slice(&input[b - m..]);
        *pos = 0;
    } else {
        // The ring holds every lag: at most two contiguous segments since b < m. Each value
        // read from the ring is replaced by the new one in the same pass.
        let mut i = 0;
        while i < b {
            let run = (m - *pos).min(b - i);
            let span = if first_wrap {
                level_span_fresh
            } else {
                level_span_ring
            };
            ss += span(
                &input[i..i + run],
                &mut ring[*pos..*pos + run],
                &mut output[i..i + run],
                skip.saturating_sub(i),
            );
            i += run;
            *pos = (*pos + run) % m;
        }
    }
    ss
}

crate::variance::simd::multiversion! {
    /// `output = (new + old) / 2`; returns the sum of `((new - old) / 2)^2` over indices
    /// `>= skip`.
    fn level_span(new: &[f64], old: &[f64], output: &mut [f64], skip: usize) -> f64
        => level_span_impl
}

#[inline(always)]
fn level_span_impl(new: &[f64], old: &[f64], output: &mut [f64], skip: usize) -> f64 {
    let skip = skip.min(new.len());
    let (new_skip, new_kept) = new.split_at(skip);
    let (old_skip, old_kept) = old.split_at(skip);
    let (out_skip, out_kept) = output.split_at_mut(skip);
    for ((o, &v), &u) in out_skip.iter_mut().zip(new_skip).zip(old_skip) {
        *o = 0.5 * (v + u);
    }
    let mut acc = [0.0f64; 4];
    let mut outs = out_kept.chunks_exact_mut(4);
    let mut news = new_kept.chunks_exact(4);
    let mut olds = old_kept.chunks_exact(4);
    for ((o, v), u) in (&mut outs).zip(&mut news).zip(&mut olds) {
        for k in 0..4 {
            o[k] = 0.5 * (v[k] + u[k]);
            let w = v[k] - u[k];
            acc[k] += w * w;
        }
    }
    let mut tail = 0.0;
    for ((o, &v), &u) in outs
        .into_remainder()
        .iter_mut()
        .zip(news.remainder())
        .zip(olds.remainder())
    {
        *o = 0.5 * (v + u);
        tail += (v - u) * (v - u);
    }
    0.25 * ((acc[0] + acc[1]) + (acc[2] + acc[3]) + tail)
}

crate::variance::simd::multiversion! {
    /// [`level_span`] with the old values taken from a ring segment, each replaced by the new
    /// value (the same roundings, one pass over the segment instead of a read and a copy).
    fn level_span_ring(new: &[f64], ring: &mut [f64], output: &mut [f64], skip: usize) -> f64
        => level_span_ring_impl::<false>
}

crate::variance::simd::multiversion! {
    /// [`level_span_ring`] where every old value is a zero before the series start: the ring is
    /// written, not read (the same roundings as reading zeros from it).
    fn level_span_fresh(new: &[f64], ring: &mut [f64], output: &mut [f64], skip: usize) -> f64
        => level_span_ring_impl::<true>
}

/// Both ring kernels: the old value is the ring's, or 0 when `FRESH` (the ring is then only
/// written); a constant parameter, so each instance is its own loop.
#[inline(always)]
fn level_span_ring_impl<const FRESH: bool>(
    new: &[f64],
    ring: &mut [f64],
    output: &mut [f64],
    skip: usize,
) -> f64 {
    let old = |r: &f64| if FRESH { 0.0 } else { *r };
    let skip = skip.min(new.len());
    let (new_skip, new_kept) = new.split_at(skip);
    let (ring_skip, ring_kept) = ring.split_at_mut(skip);
    let (out_skip, out_kept) = output.split_at_mut(skip);
    for ((o, &v), r) in out_skip.iter_mut().zip(new_skip).zip(ring_skip) {
        *o = 0.5 * (v + old(r));
        *r = v;
    }
    let mut acc = [0.0f64; 4];
    let mut outs = out_kept.chunks_exact_mut(4);
    let mut news = new_kept.chunks_exact(4);
    let mut rings = ring_kept.chunks_exact_mut(4);
    for ((o, v), r) in (&mut outs).zip(&mut news).zip(&mut rings) {
        for k in 0..4 {
            let u = old(&r[k]);
            o[k] = 0.5 * (v[k] + u);
            let w = v[k] - u;
            acc[k] += w * w;
            r[k] = v[k];
        }
    }
    let mut tail = 0.0;
    for ((o, &v), r) in outs
        .into_remainder()
        .iter_mut()
        .zip(news.remainder())
        .zip(rings.into_remainder())
    {
        let u = old(r);
        *o = 0.5 * (v + u);
        tail += (v - u) * (v - u);
        *r = v;
    }
    0.25 * ((acc[0] + acc[1]) + (acc[2] + acc[3]) + tail)
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)] // per-level arrays compared by index
mod tests {
    use super::*;

    /// Values of docs/methods.md §1.10 are given to 7 significant digits.
    const METHODS_TOL: f64 = 5e-7;

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs().max(1e-300)
    }

    /// Direct Haar MODWT WV by the closed form of §1.2: the oracle of the streaming pass.
    fn naive_haar_wv(x: &[f64], levels: usize) -> Vec<f64> {
        (1..=levels)
            .map(|j| {
                let m = 1usize << (j - 1);
                let ts = (2 * m - 1)..x.len();
                let count = ts.len() as f64;
                ts.map(|t| {
                    let newer: f64 = x[t + 1 - m..=t].iter().sum::<f64>() / m as f64;
                    let older: f64 = x[t + 1 - 2 * m..=t - m].iter().sum::<f64>() / m as f64;
                    (0.5 * (newer - older)).powi(2)
                })
                .sum::<f64>()
                    / count
            })
            .collect()
    }

    #[test]
    fn haar_wv_matches_methods_1_10() {
        let x: Vec<f64> = (1..=8).map(f64::from).collect();
        // The package returns NaN at level 3 (one coefficient dropped, §13.1); we keep it.
        let wv = wavelet_variance(
            &x,
            1.0,
            &WvOptions {
                levels: Some(3),
                ..Default::default()
            },
        )
        .unwrap();
        assert!(rel(wv.wv[0], 0.25) < 1e-14 && rel(wv.wv[1], 1.0) < 1e-14);
        assert_eq!(wv.n_coefficients, vec![7, 5, 1]);
        assert!(
            rel(wv.wv[2], 4.0) < 1e-14,
            "level 3 keeps W = (mean(5..8) - mean(1..4))/2 = 2"
        );
        assert!(rel(wv.ci_low[0], 0.08526516) < METHODS_TOL);
        assert!(rel(wv.ci_high[1], 271.909147) < METHODS_TOL);
        let y = [1.0, 3.0, 2.0, 5.0, 4.0, 6.0, 8.0, 7.0];
        let wv = wavelet_variance(
            &y,
            1.0,
            &WvOptions {
                levels: Some(2),
                ..Default::default()
            },
        )
        .unwrap();
        assert!(rel(wv.wv[0], 6.0 / 7.0) < 1e-14 && rel(wv.wv[1], 1.05) < 1e-14);
    }

    #[test]
    fn dwt_wv_is_normalised_to_the_modwt_scale() {
        // docs/methods.md §1.10 DWT values: the package's raw means (0.5, 4.0) and (2.25, 4.25) are
        // 2^j times the MODWT-scale WV (§13.3); we divide by 2^j.
        for (x, raw) in [
            ((1..=8).map(f64::from).collect::<Vec<_>>(), [0.5, 4.0]),
            (vec![1.0, 3.0, 2.0, 5.0, 4.0, 6.0, 8.0, 7.0], [2.25, 4.25]),
        ] {
            let o = WvOptions {
                transform: Transform::Dwt,
                levels: Some(2),
                ..Default::default()
            };
            let wv = wavelet_variance(&x, 1.0, &o).unwrap();
            assert!(rel(wv.wv[0], raw[0] / 2.0) < 1e-14 && rel(wv.wv[1], raw[1] / 4.0) < 1e-14);
            assert_eq!(wv.eta, vec![4.0, 2.0]);
        }
    }

    #[test]
    fn overlapping_allan_variance_is_twice_the_wv() {
        // docs/methods.md §3.4: AV(m = 2^{j-1}) = 2 WV_j over the same index set, exactly
        let x: Vec<f64> = (0..3000)
            .map(|i| ((i * 7919) % 1013) as f64 * 0.01 - 9.81)
            .collect();
        let wv = wavelet_variance(&x, 1.0, &WvOptions::default()).unwrap();
        let av = crate::allan_variance(&x, 1.0, &crate::AllanOptions::default()).unwrap();
        for j in 0..wv.levels() {
            assert_eq!(av.tau[j], wv.tau[j] / 2.0);
            assert!(rel(av.avar[j], 2.0 * wv.wv[j]) < 1e-12, "level {}", j + 1);
            assert!(rel(av.ci_low[j], 2.0 * wv.ci_low[j]) < 1e-12);
        }
    }

    #[test]
    fn default_levels_follow_methods_1_6() {
        assert_eq!(
            default_levels(1_000_000, Transform::Modwt, WaveletFilter::Haar),
            19
        );
        assert_eq!(
            default_levels(1024, Transform::Modwt, WaveletFilter::Haar),
            9
        );
        assert_eq!(default_levels(1000, Transform::Dwt, WaveletFilter::Haar), 3);
        assert_eq!(default_levels(1, Transform::Modwt, WaveletFilter::Haar), 0);
    }

    #[test]
    fn streaming_matches_naive_for_any_chunking() {
        let mut state = 12345u64;
        let x: Vec<f64> = (0..5000)
            .map(|i| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5 + 1e-3 * i as f64
            })
            .collect();
        let levels = 12;
        let oracle = naive_haar_wv(&x, levels);
        for chunk in [1, 3, 64, 4095, 4096, 5000] {
            let mut acc = HaarWvAccumulator::new(levels).unwrap();
            for c in x.chunks(chunk) {
                acc.push(c).unwrap();
            }
            let wv = acc.finish(1.0, 0.05).unwrap();
            for j in 0..levels {
                assert!(
                    rel(wv.wv[j], oracle[j]) < 1e-11,
                    "chunk {chunk} level {}",
                    j + 1
                );
            }
        }
    }

    /// A biased random walk plus noise: every level carries signal, the offset matters.
    fn walk(n: usize, seed: u64) -> Vec<f64> {
        let mut state = seed;
        let mut level = 0.0;
        (0..n)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let u = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                level += 0.01 * u;
                -9.81 + level + u
            })
            .collect()
    }

    #[test]
    fn split_pass_is_the_same_on_any_thread_count_and_matches_one_stream() {
        // parts of 2^14 samples: 2^16 + 12345 samples make five parts, the last partial, and
        // the 16 levels reach back over several parts
        let n = (1 << 16) + 12_345;
        let x = walk(n, 99);
        let levels = default_levels(n, Transform::Modwt, WaveletFilter::Haar);
        let mut acc = HaarWvAccumulator::new(levels).unwrap();
        acc.push(&x).unwrap();
        let one = acc.finish(1.0, 0.05).unwrap();
        let split = |threads: usize, min_part: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| haar_wv_split(&x, levels, 1.0, 0.05, min_part).unwrap())
        };
        let base = split(1, 1 << 14);
        for threads in [2, 3] {
            assert_eq!(split(threads, 1 << 14), base, "{threads} threads");
        }
        for j in 0..levels {
            // priming by running sums vs the pyramid differ by rounding only
            assert!(
                rel(base.wv[j], one.wv[j]) < 1e-12,
                "level {}: {} vs {}",
                j + 1,
                base.wv[j],
                one.wv[j]
            );
        }
        // one part: the single stream itself, bit for bit
        assert_eq!(split(2, 1 << 20).wv, one.wv);
        // the in-memory path agrees too
        let memory = wavelet_variance(&x, 1.0, &WvOptions::default()).unwrap();
        for j in 0..levels {
            assert!(rel(base.wv[j], memory.wv[j]) < 1e-12, "level {}", j + 1);
        }
    }

    #[test]
    fn priming_gives_the_rings_of_a_single_pass() {
        // integer data: the running sums and the pyramid's means are exact, so a primed part
        // continues exactly as one pass over the whole series does, whatever the reads
        let n = 3 * (1 << 14) + 777;
        let mut state = 7u64;
        let x: Vec<f64> = (0..n)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((state >> 40) % 1001) as f64 - 500.0
            })
            .collect();
        let levels = 15;
        let offset = x[..2048].iter().sum::<f64>() / 2048.0;
        let t0 = 2 * (1 << 14);
        let mut whole = HaarWvAccumulator::with_offset(levels, offset).unwrap();
        whole.push(&x[..t0]).unwrap();
        let mut part = HaarWvAccumulator::for_part(levels, offset, t0, n, vec![1.5; 7]).unwrap();
        let history = t0 - (1 << levels);
        // reads ending at t0 - k PRIME_ALIGN, the first one partial
        let mut start = history;
        while start < t0 {
            let end = (t0 - (t0 - start - 1) / PRIME_ALIGN * PRIME_ALIGN).min(t0);
            part.prime(start, &x[start..end]);
            start = end;
        }
        for j in 1..=levels {
            let span = ring_span(j);
            let pos = whole.pos[j - 1];
            let ring = &whole.rings[span.clone()];
            let oldest_first: Vec<f64> = ring[pos..].iter().chain(&ring[..pos]).copied().collect();
            assert_eq!(&part.rings[span], &oldest_first[..], "level {j}");
        }
    }

    #[test]
    fn bad_series_are_errors() {
        let o = WvOptions::default();
        assert!(matches!(
            wavelet_variance(&[], 1.0, &o),
            Err(InputError::Series(SeriesError::Empty))
        ));
        assert!(matches!(
            wavelet_variance(&[1.0, f64::INFINITY, 2.0], 1.0, &o),
            Err(InputError::Series(SeriesError::NonFinite { index: 1, .. }))
        ));
        assert!(matches!(
            wavelet_variance(&[3.0; 16], 1.0, &o),
            Err(InputError::Series(SeriesError::Constant { .. }))
        ));
        assert!(matches!(
            wavelet_variance(&[1.0], 1.0, &o),
            Err(InputError::Series(SeriesError::TooShort { .. }))
        ));
        let x = [1.0, 2.0, 4.0, 3.0];
        let too_many = WvOptions {
            levels: Some(3),
            ..o
        };
        assert!(matches!(
            wavelet_variance(&x, 1.0, &too_many),
            Err(InputError::Series(SeriesError::TooShort { .. }))
        ));
        assert!(matches!(
            wavelet_variance(&x, 0.0, &o),
            Err(InputError::Param(_))
        ));
        assert!(matches!(
            wavelet_variance(&x, 1.0, &WvOptions { alpha: 1.5, ..o }),
            Err(InputError::Param(_))
        ));
        // a non-finite sample is named by the push that completes its block, or by finish
        let mut acc = HaarWvAccumulator::new(2).unwrap();
        acc.push(&[1.0, f64::NAN]).unwrap();
        assert!(matches!(
            acc.finish(1.0, 0.05),
            Err(InputError::Series(SeriesError::NonFinite { index: 1, .. }))
        ));
        let mut acc = HaarWvAccumulator::new(2).unwrap();
        let mut x = vec![1.0; 3 * BLOCK];
        x[BLOCK + 7] = f64::INFINITY;
        acc.push(&x[..10]).unwrap();
        assert!(matches!(
            acc.push(&x[10..]),
            Err(SeriesError::NonFinite { index, .. }) if index == BLOCK + 7
        ));
    }
}
