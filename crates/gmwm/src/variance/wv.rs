//! Wavelet variance: classical (METHODS §1.5, paper eq. 1) and robust (§2), with chi-square
//! confidence intervals (§1.7), for the MODWT (default) and the DWT with any filter of §1.8.
//!
//! The Haar MODWT classical WV — the one every later step of the platform uses — is computed by
//! [`HaarWvAccumulator`], a streaming O(N·J) pass that never stores the coefficients and can
//! consume its input in chunks.

use crate::error::{check_finite, check_freq, check_series, InputError, ParamError, SeriesError};
use crate::math::special::trigamma;
use crate::math::sum::NeumaierSum;
use crate::variance::ci::{check_alpha, eta3, interval_unchecked};
use crate::variance::haar::haar_square_sums;
use crate::variance::haar_robust::haar_robust_levels;
use crate::variance::robust::{
    robust_ci, robust_scale, tuning_constant, RobustConvention, RobustOptions,
};
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
    /// Wavelet filter; default Haar, the filter every implied-WV formula of METHODS §4 assumes.
    pub filter: WaveletFilter,
    /// Number of levels J; `None` chooses [`default_levels`].
    pub levels: Option<usize>,
    /// Confidence level of the intervals; default 0.05 (95% intervals), as the package.
    pub alpha: f64,
    /// Robust (Tukey biweight M-) estimation when `Some` (METHODS §2).
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
    /// Scale `tau_j = 2^j` in samples (METHODS §0.1).
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

    /// Scale `tau_j = 2^j` in samples (METHODS §0.1).
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
    pub fn n_coefficients(&self) -> &[usize] {
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
    /// `eta_j` degrees of freedom (the approximation behind the intervals, METHODS §1.7), and
    /// the log of a chi-square variable with `eta` degrees of freedom has variance
    /// `psi'(eta / 2)` (the trigamma function): `2 / eta` for large `eta`, 1.64 at
    /// `eta = 2`, 4.93 at `eta = 1`. The robust estimator's is `1 / eff` times larger (the
    /// factor by which its intervals widen, METHODS §2.5).
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
        let widen = self.robust.map_or(1.0, |r| 1.0 / r.eff);
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
    /// (METHODS §1.7) and, for robust estimates, the robust intervals of §2.5.
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
        let tau: Vec<f64> = (1..=levels).map(|j| (j as f64).exp2()).collect();
        let tau_s = tau.iter().map(|t| t / freq_hz).collect();
        let mut wv = Vec::with_capacity(levels);
        let mut ci_low = Vec::with_capacity(levels);
        let mut ci_high = Vec::with_capacity(levels);
        let mut lowest: Option<f64> = None;
        for (i, (&nu_c, &e)) in classical.iter().zip(&eta).enumerate() {
            let (lo_c, hi_c) = interval_unchecked(nu_c, e, opts.alpha);
            match (robust, opts.robust) {
                (Some(r), Some(ro)) => {
                    let (lo, hi) = robust_ci(r[i], nu_c, lo_c, hi_c, ro.eff, lowest);
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
            Some(r) => format!("robust (eff {}, {})", r.eff, r.convention),
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

/// Default number of levels (METHODS §1.6, port recommendation): the largest J with
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

/// Kept (boundary-free) coefficient count of level `j` (METHODS §1.3, §1.4), `None` when the
/// level does not exist for this length.
pub fn kept_count(
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
fn check_levels(n: usize, levels: usize, opts: &WvOptions) -> Result<(), InputError> {
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

/// Wavelet variance of `x` sampled at `freq_hz`, METHODS §1.5 (classical) or §2 (robust), with
/// chi-square intervals (§1.7; robust intervals §2.5).
///
/// The classical Haar MODWT path is a streaming O(N·J) pass ([`HaarWvAccumulator`]); other
/// filters and the DWT go through the transform ([`Modwt`], [`Dwt`]) and keep O(N·J) memory.
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
        if let Some(r) = opts.robust {
            RobustOptions::new(r.eff, r.convention)?;
        }
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
        if r.convention == RobustConvention::Exact {
            return haar_robust_in_memory(x, levels, freq_hz, opts);
        }
    }

    let coefs = match opts.transform {
        Transform::Modwt => Modwt::new(opts.filter, levels)?.transform(x)?,
        Transform::Dwt => Dwt::new(opts.filter, levels)?.transform(x)?,
    };
    let c = opts
        .robust
        .map(|r| tuning_constant(r.eff, r.convention))
        .transpose()?;
    // Levels are independent once the transform is done: the robust solves (the expensive
    // part, O(n) per fixed-point step) run in parallel across levels.
    use rayon::prelude::*;
    let per_level: Vec<(f64, Option<f64>, usize)> = (1..=levels)
        .into_par_iter()
        .map(|j| {
            let kept = coefs.kept(j);
            let scale = match opts.transform {
                Transform::Modwt => 1.0,
                Transform::Dwt => (j as f64).exp2(),
            };
            let robust = match (c, opts.robust) {
                (Some(c), Some(r)) => match robust_scale(kept, c, r.convention) {
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

/// Robust (Exact convention) Haar MODWT WV of an in-memory series (METHODS §2, §2.5): the
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
    let c = tuning_constant(r.eff, r.convention)?;
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

/// Compensated mean.
fn mean(x: &[f64]) -> f64 {
    let mut s = NeumaierSum::default();
    for block in x.chunks(BLOCK) {
        s.add(sum_plain(block));
    }
    s.total() / x.len() as f64
}

/// Sum with four independent accumulators (vectorisable; blocks are then combined with a
/// compensated sum by the caller).
#[inline]
fn sum_plain(x: &[f64]) -> f64 {
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
const BLOCK: usize = 4096;

/// Sum of squares with four independent accumulators (lets the compiler vectorise; the partial
/// sums of one block are then combined with a compensated sum by the caller).
#[inline]
fn sum_squares(x: &[f64]) -> f64 {
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

/// Streaming Haar MODWT classical wavelet variance (METHODS §1.2 pyramid, §1.3, §1.5).
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
pub struct HaarWvAccumulator {
    levels: usize,
    offset: Option<f64>,
    n: u64,
    first: Option<f64>,
    rings: Vec<Vec<f64>>,
    pos: Vec<usize>,
    sums: Vec<NeumaierSum>,
    scratch_in: Vec<f64>,
    scratch_out: Vec<f64>,
    /// Samples pushed but not yet run through the pyramid: blocks start at multiples of
    /// [`BLOCK`] in the series, whatever the chunks, so the roundings do not depend on them.
    pending: Vec<f64>,
}

impl HaarWvAccumulator {
    /// A new accumulator for `levels` levels; the offset is the mean of the first block of
    /// samples (as [`wavelet_variance`] takes it, so the two agree to the last bits).
    ///
    /// # Errors
    /// [`ParamError`] when `levels` is 0 or above [`MAX_LEVELS`].
    pub fn new(levels: usize) -> Result<Self, ParamError> {
        if levels == 0 || levels > MAX_LEVELS {
            return Err(ParamError::new(
                "levels",
                levels,
                format!("must be in 1..={MAX_LEVELS}"),
            ));
        }
        Ok(Self {
            levels,
            offset: None,
            n: 0,
            first: None,
            rings: (1..=levels).map(|j| vec![0.0; 1usize << (j - 1)]).collect(),
            pos: vec![0; levels],
            sums: vec![NeumaierSum::default(); levels],
            scratch_in: Vec::with_capacity(BLOCK),
            scratch_out: Vec::with_capacity(BLOCK),
            pending: Vec::with_capacity(BLOCK),
        })
    }

    /// A new accumulator that subtracts `offset` (e.g. the series mean) from every sample.
    ///
    /// # Errors
    /// As [`new`](Self::new); also when `offset` is not finite.
    pub fn with_offset(levels: usize, offset: f64) -> Result<Self, ParamError> {
        if !offset.is_finite() {
            return Err(ParamError::new("offset", offset, "must be finite"));
        }
        let mut acc = Self::new(levels)?;
        acc.offset = Some(offset);
        Ok(acc)
    }

    /// An accumulator positioned after `history` (the samples before its first push), with
    /// every ring primed directly: the Haar `V_{j-1,t}` is the moving average of the last
    /// `2^{j-1}` samples (zero before the start), so level j's ring is filled by one sliding
    /// window in O(2^j) instead of running the pyramid over the history.
    fn primed(levels: usize, offset: f64, history: &[f64]) -> Result<Self, ParamError> {
        let mut acc = Self::with_offset(levels, offset)?;
        let t0 = history.len();
        let Some(&head) = history.first() else {
            return Ok(acc);
        };
        acc.n = t0 as u64;
        acc.first = Some(head);
        // Prefix sums of the demeaned history over the last 2^J samples (all any ring needs):
        // prefix[k] = sum of the first k of them; samples before the series start count as 0.
        let span = t0.min(1usize << levels);
        let base = t0 - span;
        let mut prefix = Vec::with_capacity(span + 1);
        let mut running = 0.0;
        prefix.push(0.0);
        for &v in &history[base..] {
            running += v - offset;
            prefix.push(running);
        }
        for (ring, j) in acc.rings.iter_mut().zip(1..) {
            let m = 1usize << (j - 1);
            // ring[k] = V_{j-1, t} for t = t0 - m + k: mean of samples t - m + 1 ..= t
            for (k, slot) in ring.iter_mut().enumerate() {
                let Some(t) = (t0 + k).checked_sub(m) else {
                    continue; // before the series start: the pyramid's zero ring
                };
                let end = t + 1 - base;
                let start = (t + 1).saturating_sub(m).max(base) - base;
                *slot = (prefix[end] - prefix[start]) / m as f64;
            }
        }
        Ok(acc)
    }

    /// Number of samples pushed so far.
    pub fn n(&self) -> u64 {
        self.n + self.pending.len() as u64
    }

    /// Number of levels.
    pub fn levels(&self) -> usize {
        self.levels
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
    pub fn push(&mut self, chunk: &[f64]) -> Result<(), SeriesError> {
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
        input.clear();
        input.extend(block.iter().map(|&v| v - offset));
        output.resize(input.len(), 0.0);
        let t0 = self.n;
        for j in 1..=self.levels {
            // First boundary-free coefficient of level j is at t = 2^j - 1.
            let first_valid = (1u64 << j) - 1;
            let skip = first_valid.saturating_sub(t0).min(input.len() as u64) as usize;
            let ring = &mut self.rings[j - 1];
            let s = haar_level(&input, &mut output, ring, &mut self.pos[j - 1], skip);
            self.sums[j - 1].add(s);
            std::mem::swap(&mut input, &mut output);
        }
        self.n += block.len() as u64;
        self.scratch_in = input;
        self.scratch_out = output;
        Ok(())
    }

    /// Finishes the pass: wavelet variance with chi-square intervals (METHODS §1.5, §1.7).
    ///
    /// # Errors
    /// [`SeriesError`] when nothing was pushed, the series is constant, or it is too short for
    /// the levels requested; [`ParamError`] for a bad `freq_hz` or `alpha`.
    pub fn finish(mut self, freq_hz: f64, alpha: f64) -> Result<WaveletVariance, InputError> {
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

/// Haar MODWT WV of an in-memory series ([`haar_square_sums`]: the pyramid of
/// [`HaarWvAccumulator`] with the same roundings, blocked and split in time and phase), for
/// valid parameters and `x.len() >= 2`.
///
/// The data checks of [`check_series`] are folded in: a constant series is found by a scan that
/// stops at the first differing sample, a non-finite sample turns the sums into NaN and
/// [`check_series`] then names it. The offset removed before the pyramid (METHODS §1.5 is
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

/// Series shorter than this run on one thread: below it the split does not pay.
const PARALLEL_MIN_LEN: usize = 1 << 18;

/// Haar MODWT WV of an in-memory series, split in time across the rayon pool: each part's rings
/// are primed from the samples before it ([`HaarWvAccumulator::primed`]), the per-level sums
/// are then added in part order, so the result does not depend on scheduling. `x` has been
/// checked (finite, not constant) by the caller.
fn haar_wv_parallel(
    x: &[f64],
    levels: usize,
    freq_hz: f64,
    alpha: f64,
) -> Result<WaveletVariance, InputError> {
    use rayon::prelude::*;
    let n = x.len();
    let offset = mean(x);
    let parts = if n >= PARALLEL_MIN_LEN {
        rayon::current_num_threads().clamp(1, n / (PARALLEL_MIN_LEN / 4))
    } else {
        1
    };
    let bounds: Vec<usize> = (0..=parts).map(|p| p * n / parts).collect();
    let partial: Vec<HaarWvAccumulator> = (0..parts)
        .into_par_iter()
        .map(|p| {
            let mut acc = HaarWvAccumulator::primed(levels, offset, &x[..bounds[p]])?;
            acc.push(&x[bounds[p]..bounds[p + 1]])?;
            acc.flush()?;
            Ok(acc)
        })
        .collect::<Result<_, InputError>>()?;
    let mut parts = partial.into_iter();
    let mut total = parts.next().expect("at least one part");
    for part in parts {
        for (a, b) in total.sums.iter_mut().zip(&part.sums) {
            a.add(b.total());
        }
        total.n = part.n;
    }
    total.finish(freq_hz, alpha)
}

/// One Haar pyramid level over a block: reads `V_{j-1}` from `input`, writes `V_j` to `output`,
/// updates the lag ring (length `m = 2^{j-1}`, oldest value at `*pos`), and returns the sum of
/// squared wavelet coefficients from index `skip` on.
#[inline]
fn haar_level(
    input: &[f64],
    output: &mut [f64],
    ring: &mut [f64],
    pos: &mut usize,
    skip: usize,
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
        // The ring holds every lag: at most two contiguous segments since b < m.
        let mut i = 0;
        while i < b {
            let run = (m - *pos).min(b - i);
            let seg = &mut ring[*pos..*pos + run];
            ss += level_span(
                &input[i..i + run],
                seg,
                &mut output[i..i + run],
                skip.saturating_sub(i),
            );
            seg.copy_from_slice(&input[i..i + run]);
            i += run;
            *pos = (*pos + run) % m;
        }
    }
    ss
}

/// `output = (new + old) / 2`; returns the sum of `((new - old) / 2)^2` over indices `>= skip`.
#[inline]
fn level_span(new: &[f64], old: &[f64], output: &mut [f64], skip: usize) -> f64 {
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

#[cfg(test)]
#[allow(clippy::needless_range_loop)] // per-level arrays compared by index
mod tests {
    use super::*;

    /// Values of METHODS §1.10 are given to 7 significant digits.
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
        // METHODS §1.10 DWT values: the package's raw means (0.5, 4.0) and (2.25, 4.25) are 2^j
        // times the MODWT-scale WV (§13.3); we divide by 2^j.
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
        // METHODS §3.4: AV(m = 2^{j-1}) = 2 WV_j over the same index set, exactly
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

    #[test]
    fn parallel_split_matches_one_stream() {
        let n = PARALLEL_MIN_LEN + 12_345;
        let mut state = 99u64;
        let x: Vec<f64> = (0..n)
            .map(|i| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                -9.81 + (state >> 11) as f64 / (1u64 << 53) as f64 + 1e-6 * (i % 977) as f64
            })
            .collect();
        let levels = default_levels(n, Transform::Modwt, WaveletFilter::Haar);
        let mut acc = HaarWvAccumulator::with_offset(levels, mean(&x)).unwrap();
        acc.push(&x).unwrap();
        let one = acc.finish(1.0, 0.05).unwrap();
        for threads in [2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let split = pool.install(|| wavelet_variance(&x, 1.0, &WvOptions::default()).unwrap());
            for j in 0..levels {
                // priming by sliding sums vs the pyramid differ by rounding only
                assert!(
                    rel(split.wv[j], one.wv[j]) < 1e-12,
                    "{threads} threads, level {}",
                    j + 1
                );
            }
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
