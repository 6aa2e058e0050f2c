//! The wavelet variance of a recording with gaps in its time stamps (packet loss, a logger's
//! dropped buffers), docs/methods.md §1.11.
//!
//! Analysed as one contiguous series ([`GapPolicy::Contiguous`]), a recording with gaps has
//! every window that spans a gap holding samples that were never adjacent in time: its scale
//! is mislabelled by the missing samples and a random walk's `g` missing steps become one
//! jump. The gap-aware WV ([`GapPolicy::Aware`], the default) takes, level by level:
//!
//! - **the windows without a gap** while they are at least [`WINDOW_SHARE`] of the windows a
//!   series of this many samples would have: each gap-free segment's own Haar MODWT WV, the
//!   segments pooled as recordings are (docs/methods.md §5.12, [`PooledWv`]: weights `eta_kj`,
//!   summed degrees of freedom). Unbiased under any model, and coherent (every coefficient is
//!   a complete window);
//! - beyond, where most windows hold a gap, **the samples spliced** across the gaps (the
//!   contiguous estimator at those levels): what is left there. Its bias is bounded by the
//!   share of samples lost at the scales it covers (a random walk's WV reads high by about
//!   that share), stated in the account.
//!
//! A third estimator, unbiased at every scale, was measured and set aside: the mean squared
//! difference over the pairs of observed samples at each lag of the filter (Mondal and
//! Percival 2010). Its pair sets differ from lag to lag, so the white noise, whose share
//! cancels across lags in a complete window, leaves noise of its own size: on an 11-minute
//! 100 Hz recording with 5% lost it put a gyroscope's K at 0.44 of the loss-free value where
//! the spliced samples gave 1.03.
//!
//! ```
//! use gmwm::{gap_aware_wavelet_variance, wavelet_variance, Gap, WvOptions};
//! let x: Vec<f64> = (0..4096).map(|i| ((i * 7919) % 1013) as f64).collect();
//! // 50 samples missing before sample 3000
//! let gap = Gap { row: 3000, line: None, time_s: 29.99, duration_s: 0.5, missing: 50 };
//! let (wv, account) = gap_aware_wavelet_variance(&x, &[gap], 100.0, &WvOptions::default()).unwrap();
//! assert_eq!(account.gaps, 1);
//! assert_eq!(wv.levels(), wavelet_variance(&x, 100.0, &WvOptions::default()).unwrap().levels());
//! assert!(account.to_string().starts_with("gap-aware wavelet variance over 1 gap"));
//! ```

use crate::error::{InputError, ParamError};
use crate::imu::Gap;
use crate::variance::pooled::PooledWv;
use crate::variance::wv::{
    default_levels, kept_count, wavelet_variance, WaveletVariance, WvOptions,
};
use crate::wavelet::{Transform, WaveletFilter};
use rayon::prelude::*;
use serde::Serialize;
use std::fmt;
use std::ops::Range;

/// A level takes the windows without a gap alone while they are at least this share of the
/// windows of a series of the same length (module docs).
pub(crate) const WINDOW_SHARE: f64 = 0.5;

/// How a recording's gaps in its time stamps enter the wavelet and Allan variances.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum GapPolicy {
    /// The windows without a gap where most windows have none (module docs), the default.
    #[default]
    Aware,
    /// The samples as one contiguous series, the gaps ignored (what earlier versions did).
    Contiguous,
}

crate::names::named_values!(GapPolicy, "gap policy", {
    Aware => "aware",
    Contiguous => "contiguous",
}, derive(FromStr, Display));

/// The gap-free segments of a series of `n` samples with gaps before the samples `gap_rows`
/// (0-based, the [`Gap::row`] of each): rows out of range or repeated are ignored.
pub(crate) fn segments(n: usize, gap_rows: &[usize]) -> Vec<Range<usize>> {
    let mut cuts: Vec<usize> = gap_rows
        .iter()
        .copied()
        .filter(|&r| r > 0 && r < n)
        .collect();
    cuts.sort_unstable();
    cuts.dedup();
    let mut out = Vec::with_capacity(cuts.len() + 1);
    let mut start = 0;
    for c in cuts.into_iter().chain(std::iter::once(n)) {
        out.push(start..c);
        start = c;
    }
    out
}

/// What the gaps cost one series' wavelet variance (module docs).
///
/// Wire format: `gaps`, `missing` (samples the stamps say are missing), `segments`,
/// `longest` (samples of the longest gap-free segment), `freq_hz`, `levels` ([`GapLevel`]:
/// `tau_s`, `kept`, `contiguous`, `spliced`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GapAccount {
    /// Gaps in the time stamps.
    pub gaps: usize,
    /// Samples missing in them.
    pub missing: usize,
    /// Gap-free segments.
    pub segments: usize,
    /// Samples of the longest segment.
    pub longest: usize,
    /// Sampling rate, Hz (for the lengths in seconds).
    pub freq_hz: f64,
    /// Per level of the gap-aware WV: its windows beside the contiguous series'.
    pub levels: Vec<GapLevel>,
}

/// One level of a [`GapAccount`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GapLevel {
    /// Scale, s.
    pub tau_s: f64,
    /// Windows without a gap.
    pub kept: usize,
    /// Windows of the samples as one series.
    pub contiguous: usize,
    /// Whether the level is the spliced samples' (most windows hold a gap).
    pub spliced: bool,
}

impl GapLevel {
    /// The share of the windows that hold a gap.
    pub fn lost_fraction(&self) -> f64 {
        if self.contiguous == 0 {
            return 0.0;
        }
        (1.0 - self.kept as f64 / self.contiguous as f64).max(0.0)
    }
}

impl fmt::Display for GapAccount {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sig = crate::math::significant;
        let plural = |n: usize, one: &'static str, many: &'static str| {
            if n == 1 {
                one
            } else {
                many
            }
        };
        write!(
            f,
            "gap-aware wavelet variance over {} {} ({} {} missing; longest gap-free stretch {} s); \
             windows holding a gap by scale:",
            self.gaps,
            plural(self.gaps, "gap", "gaps"),
            self.missing,
            plural(self.missing, "sample", "samples"),
            sig(self.longest as f64 / self.freq_hz, 4),
        )?;
        let parts: Vec<String> = self
            .levels
            .iter()
            .map(|l| format!(" {} s {:.1}%", sig(l.tau_s, 3), 100.0 * l.lost_fraction()))
            .collect();
        write!(f, "{};", parts.join(","))?;
        match self.levels.iter().position(|l| l.spliced) {
            None => write!(f, " every scale from the windows without a gap")?,
            Some(0) => write!(
                f,
                " most windows hold a gap at every scale: the samples spliced across the gaps, \
                 the scales read high by up to the share lost, {:.1}%, where a random walk \
                 dominates",
                100.0 * self.lost_share()
            )?,
            Some(k) => write!(
                f,
                " the windows without a gap up to {} s; from {} s on most hold a gap and the \
                 samples are spliced across the gaps, those scales reading high by up to the \
                 share lost, {:.1}%, where a random walk dominates",
                sig(self.levels[k - 1].tau_s, 3),
                sig(self.levels[k].tau_s, 3),
                100.0 * self.lost_share()
            )?,
        }
        write!(f, " (--gaps contiguous splices every scale)")
    }
}

impl GapAccount {
    /// The share of the recording's span whose samples are missing.
    pub fn lost_share(&self) -> f64 {
        let observed: usize = self.levels.first().map_or(0, |l| l.contiguous + 1);
        self.missing as f64 / (observed + self.missing).max(1) as f64
    }
}

/// The segments' WVs pooled: every segment of at least one level, its WV with `opts` (its
/// own default levels).
fn windows_wv(
    x: &[f64],
    segments: &[Range<usize>],
    freq_hz: f64,
    opts: &WvOptions,
) -> Result<Option<PooledWv>, InputError> {
    let usable: Vec<&Range<usize>> = segments
        .iter()
        .filter(|s| default_levels(s.len(), opts.transform, opts.filter) > 0)
        .collect();
    if usable.is_empty() {
        return Ok(None);
    }
    let parts: Vec<WaveletVariance> = usable
        .par_iter()
        .map(|s| {
            let levels = default_levels(s.len(), opts.transform, opts.filter);
            wavelet_variance(
                &x[(*s).clone()],
                freq_hz,
                &WvOptions {
                    levels: Some(levels),
                    ..*opts
                },
            )
        })
        .collect::<Result<_, InputError>>()?;
    Ok(Some(
        PooledWv::new(parts).map_err(|e: ParamError| InputError::from(e))?,
    ))
}

/// The gap-aware wavelet variance of `x`, whose time stamps have `gaps` (as
/// [`TimingReport::gaps`](crate::TimingReport) gives them), and what the gaps cost it
/// (module docs). Its levels are those of the samples as one series ([`WvOptions::levels`],
/// else [`default_levels`] of `x.len()`); its `n` the samples.
///
/// # Errors
/// As [`wavelet_variance`] on `x`; a robust estimator or another transform or filter than
/// the classical Haar MODWT ([`ParamError`]: the windows' pooling and its covariance are
/// that one's).
pub fn gap_aware_wavelet_variance(
    x: &[f64],
    gaps: &[Gap],
    freq_hz: f64,
    opts: &WvOptions,
) -> Result<(WaveletVariance, GapAccount), InputError> {
    if opts.robust.is_some()
        || opts.transform != Transform::Modwt
        || opts.filter != WaveletFilter::Haar
    {
        return Err(ParamError::new(
            "gaps",
            "aware",
            "the classical Haar MODWT wavelet variance; analyse the samples as contiguous for another estimator",
        )
        .into());
    }
    // the samples as one series: its errors first, its levels the WV's
    let mut wv = wavelet_variance(x, freq_hz, opts)?;
    let n = x.len();
    let mut gaps: Vec<&Gap> = gaps.iter().filter(|g| g.row > 0 && g.row < n).collect();
    gaps.sort_by_key(|g| g.row);
    gaps.dedup_by_key(|g| g.row);
    let rows: Vec<usize> = gaps.iter().map(|g| g.row).collect();
    let segments = segments(n, &rows);
    let windows = windows_wv(x, &segments, freq_hz, opts)?;
    let mut levels = Vec::with_capacity(wv.levels());
    let mut spliced = false;
    for j in 0..wv.levels() {
        let contiguous = kept_count(n, j + 1, Transform::Modwt, WaveletFilter::Haar).unwrap_or(0);
        let own = windows
            .as_ref()
            .map(PooledWv::wv)
            .filter(|w| j < w.levels());
        let kept = own.map_or(0, |w| w.n_coefficients[j]);
        spliced = spliced || (kept as f64) < WINDOW_SHARE * contiguous as f64;
        if let (false, Some(w)) = (spliced, own) {
            wv.wv[j] = w.wv[j];
            wv.ci_low[j] = w.ci_low[j];
            wv.ci_high[j] = w.ci_high[j];
            wv.eta[j] = w.eta[j];
            wv.n_coefficients[j] = kept;
        }
        levels.push(GapLevel {
            tau_s: wv.tau_s[j],
            kept,
            contiguous,
            spliced,
        });
    }
    let account = GapAccount {
        gaps: gaps.len(),
        missing: gaps.iter().fold(0usize, |m, g| m.saturating_add(g.missing)),
        segments: segments.len(),
        longest: segments.iter().map(|s| s.len()).max().unwrap_or(0),
        freq_hz,
        levels,
    };
    Ok((wv, account))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Model;
    use crate::sim::simulate_model;

    fn gap(row: usize, missing: usize) -> Gap {
        Gap {
            row,
            line: None,
            time_s: 0.0,
            duration_s: missing as f64,
            missing,
        }
    }

    #[test]
    fn segments_cover_the_series_once() {
        assert_eq!(segments(10, &[]), vec![0..10]);
        assert_eq!(segments(10, &[4, 4, 0, 12, 7]), vec![0..4, 4..7, 7..10]);
    }

    #[test]
    fn without_gaps_it_is_the_wavelet_variance() {
        let m = Model::parse("WN(1)+RW(0.001)").unwrap();
        let x = simulate_model(&m, 5000, 100.0, 3).unwrap();
        let plain = wavelet_variance(&x, 100.0, &WvOptions::default()).unwrap();
        let (aware, account) =
            gap_aware_wavelet_variance(&x, &[], 100.0, &WvOptions::default()).unwrap();
        assert_eq!(account.gaps, 0);
        assert!(account.levels.iter().all(|l| !l.spliced));
        for j in 0..plain.levels() {
            // one part pools to itself
            assert!((aware.wv()[j] - plain.wv()[j]).abs() <= 1e-12 * plain.wv()[j]);
            assert_eq!(aware.n_coefficients()[j], plain.n_coefficients()[j]);
        }
    }

    #[test]
    fn a_gap_never_mixes_the_samples_across_it() {
        // two white-noise stretches a step of 1e6 apart (a random walk's 4000 missing steps,
        // exaggerated): no window without a gap sees the step
        let m = Model::parse("WN(1)").unwrap();
        let a = simulate_model(&m, 4000, 1.0, 1).unwrap();
        let b: Vec<f64> = simulate_model(&m, 4000, 1.0, 2)
            .unwrap()
            .iter()
            .map(|v| v + 1e6)
            .collect();
        let x: Vec<f64> = a.iter().chain(&b).copied().collect();
        let (aware, account) =
            gap_aware_wavelet_variance(&x, &[gap(4000, 4000)], 1.0, &WvOptions::default()).unwrap();
        let contiguous = wavelet_variance(&x, 1.0, &WvOptions::default()).unwrap();
        assert_eq!(account.missing, 4000);
        // the step dominates every contiguous level; the gap-aware ones stay at white noise's
        // 2^-j up to the scales where most windows hold the gap (level 12: 4096 > 4000)
        for j in 0..11 {
            assert!(contiguous.wv()[j] > 100.0);
            assert!(!account.levels[j].spliced);
            if j >= 8 {
                // two segments of 4000 keep few windows of 512 samples and more: noisy
                continue;
            }
            let white = 0.5f64.powi(j as i32 + 1);
            assert!(
                (aware.wv()[j] / white - 1.0).abs() < 0.3,
                "level {}: {} against {white}",
                j + 1,
                aware.wv()[j]
            );
        }
        assert!(account.levels[11].spliced, "{account}");
        assert_eq!(account.levels[0].contiguous - account.levels[0].kept, 1);
        assert!(account.to_string().contains("spliced"), "{account}");
    }

    #[test]
    fn other_estimators_are_refused_and_huge_claimed_gaps_cost_nothing() {
        let x: Vec<f64> = (0..1000).map(|i| (i * 31 % 17) as f64).collect();
        let robust = WvOptions {
            robust: Some(crate::variance::robust::RobustOptions::default()),
            ..WvOptions::default()
        };
        let e = gap_aware_wavelet_variance(&x, &[gap(500, 3)], 1.0, &robust).unwrap_err();
        assert!(e.to_string().contains("classical Haar MODWT"), "{e}");
        // stamps claiming 10^18 missing samples: counted, nothing allocated for them
        let (wv, account) =
            gap_aware_wavelet_variance(&x, &[gap(500, 1 << 60)], 1.0, &WvOptions::default())
                .unwrap();
        assert!(wv.levels() >= 1);
        assert_eq!(account.missing, 1 << 60);
        assert!(account.lost_share() > 0.99);
        // every sample its own segment: every level spliced
        let rows: Vec<Gap> = (1..1000).map(|r| gap(r, 1)).collect();
        let (_, account) =
            gap_aware_wavelet_variance(&x, &rows, 1.0, &WvOptions::default()).unwrap();
        assert!(account.levels.iter().all(|l| l.spliced));
        assert!(account.to_string().contains("at every scale"), "{account}");
    }
}
