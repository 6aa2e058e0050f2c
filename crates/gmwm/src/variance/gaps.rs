//! The wavelet variance of a recording with gaps in its time stamps (packet loss, a logger's
//! dropped buffers), docs/methods.md §1.14.
//!
//! Analysed as one contiguous series ([`GapPolicy::Contiguous`]), a recording with gaps has
//! every scale mislabelled by the missing samples and a jump across each hole (a random walk's
//! `g` missing steps in one). The gap-aware estimator ([`GapPolicy::Aware`], the default) puts
//! the samples on their time grid, the missing ones absent, and uses only what was observed.
//!
//! # Estimator (Mondal and Percival 2010, for the Haar filter)
//! The Haar MODWT coefficient of level `j` (`L = 2^j`, `H = L / 2`) is a filter whose taps sum
//! to zero, so its square is, at every `t`, a weighted sum of squared differences of the
//! samples it covers: `W_t^2 = -sum_{k >= 1} b_k sum_l (x_{t-l} - x_{t-l-k})^2 / ...` with
//! `b_k = sum_l h_l h_{l+k}` the filter's autocorrelation,
//!
//! ```text
//! b_k = (2H - 3k) / L^2  (1 <= k <= H),     b_k = -(L - k) / L^2  (H < k < L),
//! nu2_j = -sum_{k=1}^{L-1} b_k D_k,         D_k = E (x_{t+k} - x_t)^2,
//! ```
//!
//! for any process with stationary increments (white noise, random walk, AR/GM, flicker;
//! a drift's square cancels the same way). The gap-aware WV puts in `D_k` the mean of
//! `(x_{t+k} - x_t)^2` over the **pairs of observed samples** `k` steps apart on the time
//! grid: unbiased whatever the gaps, and with every observed pair in use, so a scale much
//! longer than the gaps keeps almost all its information (a window holding a gap still
//! counts through its observed pairs). White noise checks the weights: `D_k = 2 sigma2` and
//! `-sum b_k = 1 / (2L)` give `sigma2 / L`. The three sums behind every `D_k` (of the pairs,
//! of the products, of the squares against the pairs) are correlations of the grid's
//! series and its mask, computed together by FFT in `O(T log T)` for a grid of `T` samples.
//!
//! **Effective counts, interval, covariance.** Level `j` reports as its coefficients
//! `M_j^eff = (T - L + 1) f_j`, with `f_j` the observed fraction of the pairs it uses
//! (`|b_k|`-weighted), and the chi-square interval with `eta3(M_j^eff)` (§1.7); the fit takes
//! the WV covariance of a contiguous series of the observed length. A level with a lag no
//! observed pair spans (a gap as long as the recording) is left out.
//!
//! **Bounds.** The grid is at most [`MAX_GRID`] samples (three FFT buffers of twice that);
//! a longer one (a very long recording, or stamps claiming a gap of days) falls back to
//! pooling the gap-free segments' own WVs (only windows holding no gap; §5.12's pooling),
//! which loses the scales longer than the segments, and says so.
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

use crate::error::{InputError, ParamError, SeriesError};
use crate::imu::Gap;
use crate::variance::ci::eta3;
use crate::variance::pooled::PooledWv;
use crate::variance::wv::{
    default_levels, kept_count, wavelet_variance, WaveletVariance, WvOptions,
};
use crate::wavelet::{Transform, WaveletFilter};
use rayon::prelude::*;
use rustfft::num_complex::Complex;
use rustfft::FftPlanner;
use serde::Serialize;
use std::fmt;
use std::ops::Range;

/// Largest time grid (observed + missing samples) of the FFT estimator: 2^24 (three buffers
/// of 2^25 complex values, 1.5 GB); longer grids pool the gap-free segments instead.
pub(crate) const MAX_GRID: usize = 1 << 24;

/// A level keeps the windows without a gap alone while they are at least this share of the
/// contiguous series' (module docs).
pub(crate) const WINDOW_SHARE: f64 = 0.5;

/// How a recording's gaps in its time stamps enter the wavelet and Allan variances.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum GapPolicy {
    /// Only observed samples, on their time grid (module docs), the default.
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

/// How the gap-aware WV was computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum GapMethod {
    /// The windows without a gap at the first `window_levels` levels, every observed pair on
    /// the time grid beyond (module docs).
    ObservedPairs {
        /// Levels from the windows without a gap.
        window_levels: usize,
    },
    /// The gap-free segments' own WVs pooled (a grid beyond [`MAX_GRID`]).
    Segments,
}

/// What the gaps cost one series' wavelet variance (module docs).
///
/// Wire format: `gaps`, `missing` (samples the stamps say are missing), `method`
/// (`observed-pairs` or `segments`), `segments`, `longest` (samples of the longest gap-free
/// segment), `freq_hz`, `levels` ([`GapLevel`]: `tau_s`, `kept`, `contiguous`), `left_out`
/// (scales of the contiguous series the gap-aware WV lacks, s).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GapAccount {
    /// Gaps in the time stamps.
    pub gaps: usize,
    /// Samples missing in them.
    pub missing: usize,
    /// How the WV was computed.
    pub method: GapMethod,
    /// Gap-free segments.
    pub segments: usize,
    /// Samples of the longest segment.
    pub longest: usize,
    /// Sampling rate, Hz (for the lengths in seconds).
    pub freq_hz: f64,
    /// Per level of the gap-aware WV: its (effective) coefficients beside the contiguous
    /// series'.
    pub levels: Vec<GapLevel>,
    /// Scales (s) the contiguous series would have and the gap-aware WV lacks.
    pub left_out: Vec<f64>,
}

/// One level of a [`GapAccount`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GapLevel {
    /// Scale, s.
    pub tau_s: f64,
    /// Coefficients kept (effective: module docs).
    pub kept: usize,
    /// Coefficients a series of the grid's length without gaps would keep.
    pub contiguous: usize,
}

impl GapLevel {
    /// The fraction of the coefficients lost to the gaps.
    pub fn lost_fraction(&self) -> f64 {
        if self.contiguous == 0 {
            return 0.0;
        }
        (1.0 - self.kept as f64 / self.contiguous as f64).max(0.0)
    }
}

impl fmt::Display for GapAccount {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sig = crate::fit::report::significant;
        let plural =
            |n: usize, one: &'static str, many: &'static str| if n == 1 { one } else { many };
        write!(
            f,
            "gap-aware wavelet variance over {} {} ({} {} missing; longest gap-free stretch {} s), {}; \
             coefficients lost by scale:",
            self.gaps,
            plural(self.gaps, "gap", "gaps"),
            self.missing,
            plural(self.missing, "sample", "samples"),
            sig(self.longest as f64 / self.freq_hz, 4),
            match self.method {
                GapMethod::ObservedPairs { window_levels: 0 } =>
                    "from every pair of observed samples on the time grid".to_string(),
                GapMethod::ObservedPairs { window_levels } => format!(
                    "from the windows without a gap up to {} s, from every pair of observed samples on the time grid beyond",
                    sig(self.levels.get(window_levels - 1).map_or(f64::NAN, |l| l.tau_s), 3)
                ),
                GapMethod::Segments => "from the gap-free segments alone (the time grid is too long for the pair estimator)".to_string(),
            },
        )?;
        let parts: Vec<String> = self
            .levels
            .iter()
            .map(|l| format!(" {} s {:.1}%", sig(l.tau_s, 3), 100.0 * l.lost_fraction()))
            .collect();
        write!(f, "{}", parts.join(","))?;
        if let Some(first) = self.left_out.first() {
            write!(
                f,
                "; {} longer {} from {} s on left out",
                self.left_out.len(),
                plural(self.left_out.len(), "scale", "scales"),
                sig(*first, 3)
            )?;
        }
        write!(f, " (--gaps contiguous analyses the samples as one series)")
    }
}

/// The Haar filter autocorrelation `-b_k` of level `L` at lag `k` (module docs).
fn minus_b(k: usize, l: usize) -> f64 {
    let h = l / 2;
    let l2 = (l * l) as f64;
    if k <= h {
        (3 * k) as f64 / l2 - (2 * h) as f64 / l2
    } else {
        (l - k) as f64 / l2
    }
}

/// The gap-aware Haar MODWT WV of `x` on its time grid `grid` (module docs): its values,
/// effective counts and the grid's length.
fn observed_pairs_wv(
    x: &[f64],
    positions: &[usize],
    grid: usize,
    levels: usize,
) -> (Vec<f64>, Vec<f64>) {
    let size = (2 * grid).next_power_of_two();
    // the mean removed first: the sums then hold the fluctuations, not the offset
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    let mut mask = vec![Complex::new(0.0, 0.0); size];
    let mut y = vec![Complex::new(0.0, 0.0); size];
    let mut y2 = vec![Complex::new(0.0, 0.0); size];
    for (&p, &v) in positions.iter().zip(x) {
        let d = v - mean;
        mask[p].re = 1.0;
        y[p].re = d;
        y2[p].re = d * d;
    }
    let mut planner = FftPlanner::new();
    let forward = planner.plan_fft_forward(size);
    let inverse = planner.plan_fft_inverse(size);
    forward.process(&mut mask);
    forward.process(&mut y);
    forward.process(&mut y2);
    // y <- spectrum of sum_t (m_t y2_{t+k} + y2_t m_{t+k}) - 2 y_t y_{t+k}: the sum of the
    // squared differences over the observed pairs at lag k; y2 <- that of the pair count
    for ((m, a), b) in mask.iter().zip(y.iter_mut()).zip(y2.iter_mut()) {
        let squares = 2.0 * (m.conj() * *b).re;
        let products = 2.0 * a.norm_sqr();
        *a = Complex::new(squares - products, 0.0);
        *b = Complex::new(m.norm_sqr(), 0.0);
    }
    drop(mask);
    inverse.process(&mut y);
    inverse.process(&mut y2);
    let scale = 1.0 / size as f64;
    let longest_lag = 1usize << levels;
    let mut d = vec![f64::NAN; longest_lag];
    let mut share = vec![0.0; longest_lag];
    for k in 1..longest_lag.min(grid) {
        let pairs = (y2[k].re * scale).round();
        share[k] = pairs / (grid - k) as f64;
        if pairs > 0.0 {
            d[k] = (y[k].re * scale / pairs).max(0.0);
        }
    }
    let mut wv = Vec::with_capacity(levels);
    let mut fraction = Vec::with_capacity(levels);
    for j in 1..=levels {
        let l = 1usize << j;
        let (mut sum, mut weight, mut observed) = (0.0, 0.0, 0.0);
        for k in 1..l {
            let w = minus_b(k, l);
            sum += w * d[k];
            weight += w.abs();
            observed += w.abs() * share[k];
        }
        wv.push(sum);
        fraction.push(observed / weight);
    }
    (wv, fraction)
}

/// The segments' WVs pooled (the fallback of module docs): every segment of at least one
/// level, its WV with `opts` (a requested level count cut to what the segment holds).
fn segments_wv(
    x: &[f64],
    segments: &[Range<usize>],
    freq_hz: f64,
    opts: &WvOptions,
) -> Result<WaveletVariance, InputError> {
    let usable: Vec<&Range<usize>> = segments
        .iter()
        .filter(|s| default_levels(s.len(), opts.transform, opts.filter) > 0)
        .collect();
    if usable.is_empty() {
        return Err(SeriesError::TooShort {
            n: segments.iter().map(|s| s.len()).max().unwrap_or(0),
            needed: 3,
            what:
                "one level of the gap-aware wavelet variance: no gap-free segment holds 3 samples"
                    .into(),
        }
        .into());
    }
    let parts: Vec<WaveletVariance> = usable
        .par_iter()
        .map(|s| {
            let own = default_levels(s.len(), opts.transform, opts.filter);
            let levels = opts.levels.map_or(own, |l| l.min(own));
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
    let pooled = PooledWv::new(parts).map_err(|e: ParamError| InputError::from(e))?;
    Ok(pooled.wv)
}

/// The gap-aware wavelet variance of `x`, whose time stamps have `gaps` (as
/// [`TimingReport::gaps`](crate::TimingReport) gives them), and what the gaps cost it
/// (module docs). Its `n` is the samples observed.
///
/// # Errors
/// As [`wavelet_variance`]; a robust estimator or another transform or filter than the
/// classical Haar MODWT ([`ParamError`]: the estimator is the Haar one's); requested levels
/// beyond what the grid holds.
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
            "the classical Haar MODWT wavelet variance (the gap-aware estimator is that one's); analyse the samples as contiguous for another estimator",
        )
        .into());
    }
    crate::error::check_series(x)?;
    crate::variance::ci::check_alpha(opts.alpha)?;
    let n = x.len();
    let mut gaps: Vec<&Gap> = gaps.iter().filter(|g| g.row > 0 && g.row < n).collect();
    gaps.sort_by_key(|g| g.row);
    gaps.dedup_by_key(|g| g.row);
    let missing: usize = gaps.iter().fold(0usize, |m, g| m.saturating_add(g.missing));
    let grid = n.saturating_add(missing);
    let rows: Vec<usize> = gaps.iter().map(|g| g.row).collect();
    let segments = segments(n, &rows);
    let longest = segments.iter().map(|s| s.len()).max().unwrap_or(0);
    let contiguous_levels = opts.levels.unwrap_or_else(|| {
        default_levels(
            grid.min(usize::MAX / 2),
            Transform::Modwt,
            WaveletFilter::Haar,
        )
    });
    let (wv, method) = if grid <= MAX_GRID {
        let levels = opts.levels.unwrap_or(contiguous_levels);
        crate::variance::wv::check_levels(grid, levels, opts)?;
        let mut positions = Vec::with_capacity(n);
        let mut next = gaps.iter().peekable();
        let mut shift = 0;
        for i in 0..n {
            while let Some(g) = next.next_if(|g| g.row == i) {
                shift += g.missing;
            }
            positions.push(i + shift);
        }
        let (values, fraction) = observed_pairs_wv(x, &positions, grid, levels);
        // a level with a lag no observed pair spans has no estimate: it and the longer ones go
        let kept_levels = values.iter().position(|v| !v.is_finite()).unwrap_or(levels);
        if kept_levels == 0 {
            return Err(SeriesError::TooShort {
                n,
                needed: 3,
                what:
                    "one level of the gap-aware wavelet variance: no observed pair one step apart"
                        .into(),
            }
            .into());
        }
        if opts.levels.is_some() && kept_levels < levels {
            return Err(ParamError::new(
                "levels",
                levels,
                format!("at most {kept_levels}: longer scales have lags no pair of observed samples spans"),
            )
            .into());
        }
        let counts: Vec<usize> = (1..=kept_levels)
            .map(|j| {
                let all = kept_count(grid, j, Transform::Modwt, WaveletFilter::Haar).unwrap_or(0);
                ((all as f64 * fraction[j - 1]).round() as usize).max(1)
            })
            .collect();
        let eta = counts.iter().zip(1..).map(|(&m, j)| eta3(m, j)).collect();
        let mut values = values[..kept_levels].to_vec();
        let mut counts = counts;
        let mut eta: Vec<f64> = eta;
        // where most windows hold no gap, their coefficients alone (the segments' pooled WV)
        let windows = segments_wv(
            x,
            &segments,
            freq_hz,
            &WvOptions {
                levels: None,
                ..*opts
            },
        )
        .ok();
        let mut window_levels = 0;
        if let Some(w) = &windows {
            for j in 0..w.levels().min(kept_levels) {
                let all =
                    kept_count(grid, j + 1, Transform::Modwt, WaveletFilter::Haar).unwrap_or(0);
                if (w.n_coefficients()[j] as f64) < WINDOW_SHARE * all as f64 {
                    break;
                }
                values[j] = w.wv()[j];
                counts[j] = w.n_coefficients()[j];
                eta[j] = w.eta()[j];
                window_levels = j + 1;
            }
        }
        crate::variance::wv::check_finite_result(&values, "gap-aware wavelet variance")?;
        let wv = WaveletVariance::assemble(n, freq_hz, opts, &values, None, counts, eta);
        (wv, GapMethod::ObservedPairs { window_levels })
    } else {
        (
            segments_wv(x, &segments, freq_hz, opts)?,
            GapMethod::Segments,
        )
    };
    let levels = (1..=wv.levels())
        .map(|j| GapLevel {
            tau_s: wv.tau_s()[j - 1],
            kept: wv.n_coefficients()[j - 1],
            contiguous: kept_count(grid, j, Transform::Modwt, WaveletFilter::Haar).unwrap_or(0),
        })
        .collect();
    let left_out = (wv.levels() + 1..=contiguous_levels)
        .map(|j| (j as f64).exp2() / freq_hz)
        .collect();
    let account = GapAccount {
        gaps: gaps.len(),
        missing,
        method,
        segments: segments.len(),
        longest,
        freq_hz,
        levels,
        left_out,
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
    fn the_filter_weights_give_white_noise_its_variance() {
        // -sum_k b_k over 1..L equals 1 / (2L) at every level
        for j in 1..12 {
            let l = 1usize << j;
            let s: f64 = (1..l).map(|k| minus_b(k, l)).sum();
            assert!((s - 0.5 / l as f64).abs() < 1e-15, "level {j}: {s}");
        }
    }

    #[test]
    fn without_gaps_it_estimates_what_the_modwt_does() {
        // every pair observed: a different average of the same squared differences (all pairs
        // at each lag rather than those inside the kept windows), equal in expectation; on one
        // series the two agree within a fraction of the interval's half-width
        let m = Model::parse("WN(1)+RW(0.001)+AR1(0.99,0.1)").unwrap();
        let x = simulate_model(&m, 1 << 15, 100.0, 3).unwrap();
        let plain = wavelet_variance(&x, 100.0, &WvOptions::default()).unwrap();
        let (aware, account) =
            gap_aware_wavelet_variance(&x, &[], 100.0, &WvOptions::default()).unwrap();
        assert_eq!(account.gaps, 0);
        assert_eq!(aware.levels(), plain.levels());
        for j in 0..plain.levels() - 2 {
            let half = (plain.ci_high()[j] - plain.ci_low()[j]) / 2.0;
            assert!(
                (aware.wv()[j] - plain.wv()[j]).abs() < 0.35 * half,
                "level {}: {} vs {} (half-width {half})",
                j + 1,
                aware.wv()[j],
                plain.wv()[j]
            );
            assert_eq!(aware.n_coefficients()[j], plain.n_coefficients()[j]);
        }
    }

    #[test]
    fn a_gap_never_mixes_the_samples_across_it() {
        // a random walk with 4000 steps missing in the middle: the contiguous series holds a
        // jump of sd 63 sqrt(gamma2) there; the samples on their grid hold the walk as it was
        let m = Model::parse("WN(0.01)+RW(1)").unwrap();
        let full = simulate_model(&m, 12_000, 1.0, 5).unwrap();
        let x: Vec<f64> = full[..4000].iter().chain(&full[8000..]).copied().collect();
        let (aware, account) =
            gap_aware_wavelet_variance(&x, &[gap(4000, 4000)], 1.0, &WvOptions::default()).unwrap();
        let truth = wavelet_variance(&full, 1.0, &WvOptions::default()).unwrap();
        assert_eq!(account.missing, 4000);
        for j in 0..8 {
            assert!(
                aware.wv()[j] > truth.ci_low()[j] && aware.wv()[j] < truth.ci_high()[j],
                "level {}: {} outside [{}, {}]",
                j + 1,
                aware.wv()[j],
                truth.ci_low()[j],
                truth.ci_high()[j]
            );
        }
        // a lag of exactly 4000 has no observed pair: the levels needing it are left out
        assert_eq!(account.left_out.len(), 2, "{account}");
        assert!(account.levels[0].lost_fraction() > 0.3, "{account}");
        assert!(
            account.to_string().contains("4000 samples missing"),
            "{account}"
        );
    }

    #[test]
    fn other_estimators_and_hopeless_gaps_are_errors_naming_the_cause() {
        let x: Vec<f64> = (0..1000).map(|i| (i * 31 % 17) as f64).collect();
        let robust = WvOptions {
            robust: Some(crate::variance::robust::RobustOptions::default()),
            ..WvOptions::default()
        };
        let e = gap_aware_wavelet_variance(&x, &[gap(500, 3)], 1.0, &robust).unwrap_err();
        assert!(e.to_string().contains("classical Haar MODWT"), "{e}");
        // stamps claiming 10^12 missing samples: no grid of that size is allocated
        let (wv, account) = gap_aware_wavelet_variance(
            &x,
            &[gap(500, 1_000_000_000_000)],
            1.0,
            &WvOptions::default(),
        )
        .unwrap();
        assert_eq!(account.method, GapMethod::Segments);
        assert!(wv.levels() >= 1);
        let e = gap_aware_wavelet_variance(
            &x[..4],
            &[gap(2, 1_000_000_000_000)],
            1.0,
            &WvOptions::default(),
        )
        .unwrap_err();
        assert!(
            e.to_string()
                .contains("no gap-free segment holds 3 samples"),
            "{e}"
        );
    }
}
