//! The power spectral density of a series by Welch's method: the variance spread over
//! frequency, beside the wavelet variance's spread over scale. Vibration shows as a hump at its
//! frequency and the sensor's own anti-aliasing filter as the roll-off before `f_s / 2`, both of
//! which the WV smears over an octave.
//!
//! # Convention
//! One-sided density in unit²/Hz on `0 ..= f_s / 2`, so that its integral is the variance
//! (Parseval). White noise of sample variance `σ²` has the flat level `2 σ² / f_s`; with the
//! white-noise density `N` (unit/√Hz) the tool reports, `σ² = N² f_s` (docs/methods.md §14.2),
//! that level is `2 N²`, and the amplitude spectral density `√PSD` reads `√2 · N`.
//!
//! # Estimator
//! Segments of `L` samples (a power of two, `segment_length`), 50% overlap, a periodic Hann
//! window, the segment's mean removed before windowing; the squared moduli of the segments'
//! DFTs averaged and scaled by `1 / (f_s Σ w²)`, doubled for `0 < k < L/2` (P. D. Welch 1967,
//! IEEE Trans. Audio Electroacoust. AU-15(2), pp. 70–73, with the one-sided fold). Samples after
//! the last full segment are not used.
//!
//! Streaming: `Welch` takes the samples chunk by chunk (memory `O(L)` whatever the length);
//! [`welch_psd`] runs it over a slice without copying it.

use crate::error::{check_finite, check_freq, InputError, ParamError, SeriesError};
use crate::math::elementary;
use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};
use serde::Serialize;
use std::sync::Arc;

/// Shortest segment of the length rule: 256 samples give 128 frequencies, the fewest that still
/// show a hump apart from the filter's roll-off; a series shorter than this has no PSD.
pub(crate) const MIN_SEGMENT: usize = 256;
/// Longest segment of the length rule: 2^16 samples (1 MiB of complex buffer), a resolution of
/// `f_s / 65536` (0.0015 Hz at 100 Hz), far below where vibration and filters show; longer
/// segments would only add FFT cost on long recordings.
pub(crate) const MAX_SEGMENT: usize = 1 << 16;
/// The length rule aims at `N / L >= 8`, i.e. at least 15 overlapping segments, so that each
/// frequency's estimate averages enough segments (relative standard error about
/// `√(1.06 / 15) = 0.27`: Welch's variance factor `1 + 2 ρ(½)²` with `ρ(½) ≈ 0.167` for the
/// 50%-overlapped Hann window, Welch 1967 p. 72) while the
/// lowest frequency `f_s / L = 8 f_s / N` stays near the WV's coarsest scales.
pub(crate) const SEGMENTS_PER_LENGTH: usize = 8;
/// Points of the log-frequency binned PSD of figures and JSON ([`Psd::binned`]).
pub const BINNED_POINTS: usize = 100;

/// The segment length of a series of `n` samples: the largest power of two at most
/// `n / SEGMENTS_PER_LENGTH`, between `MIN_SEGMENT` and `MAX_SEGMENT`; `MIN_SEGMENT` when
/// `n` holds one such segment but not eight, and `None` when `n < MIN_SEGMENT`. The rate does
/// not change `L`; it sets the resolution `f_s / L`.
pub(crate) fn segment_length(n: usize) -> Option<usize> {
    if n < MIN_SEGMENT {
        return None;
    }
    let target = n / SEGMENTS_PER_LENGTH;
    let pow = if target == 0 {
        MIN_SEGMENT
    } else {
        1usize << target.ilog2()
    };
    Some(pow.clamp(MIN_SEGMENT, MAX_SEGMENT))
}

/// A power spectral density: one-sided, unit²/Hz, at increasing frequencies.
///
/// Wire format: `frequency_hz`, `density` (arrays of the same length), `unit` (of `density`,
/// e.g. `(rad/s)^2/Hz`), `freq_hz` (the sampling rate), `segment_length` (`L`), `segments`
/// (averaged), `resolution_hz` (`f_s / L`), `binned` (whether the values are log-frequency
/// bin means, [`Psd::binned`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Psd {
    frequency_hz: Vec<f64>,
    density: Vec<f64>,
    unit: String,
    freq_hz: f64,
    segment_length: usize,
    segments: usize,
    resolution_hz: f64,
    binned: bool,
}

impl Psd {
    /// Frequencies, Hz.
    pub fn frequency_hz(&self) -> &[f64] {
        &self.frequency_hz
    }

    /// One-sided densities, [`Psd::unit`].
    pub fn density(&self) -> &[f64] {
        &self.density
    }

    /// Unit of the density (`u^2/Hz` until `Psd::in_unit` names the data's).
    pub fn unit(&self) -> &str {
        &self.unit
    }

    /// Sampling rate, Hz.
    pub fn freq_hz(&self) -> f64 {
        self.freq_hz
    }

    /// Samples per segment `L`.
    pub fn segment_length(&self) -> usize {
        self.segment_length
    }

    /// Segments averaged.
    pub fn segments(&self) -> usize {
        self.segments
    }

    /// Frequency resolution `f_s / L`, Hz.
    pub fn resolution_hz(&self) -> f64 {
        self.resolution_hz
    }

    /// Whether the values are log-frequency bin means.
    #[cfg(test)]
    pub(crate) fn is_binned(&self) -> bool {
        self.binned
    }

    /// The same densities with their unit named after the data's: `(unit)^2/Hz`.
    pub(crate) fn in_unit(mut self, data_unit: &str) -> Self {
        self.unit = if data_unit.contains('/') || data_unit.contains('*') {
            format!("({data_unit})^2/Hz")
        } else {
            format!("{data_unit}^2/Hz")
        };
        self
    }

    /// The densities times `factor` (a unit conversion: `to_si²`).
    pub(crate) fn scaled(mut self, factor: f64) -> Self {
        self.density.iter_mut().for_each(|d| *d *= factor);
        self
    }

    /// At most `points` log-spaced bins from the first positive frequency `f_s / L` to the
    /// last below Nyquist: each bin's density the mean of the raw densities in it, at the mean
    /// of their frequencies; empty bins (at low frequencies, where the raw spacing is wider
    /// than a bin) are left out, so each raw frequency there is its own point. The mean-free
    /// DC value and the Nyquist value (a half-width bin, half the one-sided level) are not in
    /// it. For figures and JSON: ~100 points whatever `L`.
    pub fn binned(&self, points: usize) -> Psd {
        let points = points.max(1);
        // raw frequencies 1 .. L/2 - 1
        let members: Vec<(f64, f64)> = self
            .frequency_hz
            .iter()
            .zip(&self.density)
            .filter(|(f, _)| **f > 0.0 && **f < 0.5 * self.freq_hz * (1.0 - 1e-12))
            .map(|(&f, &d)| (f, d))
            .collect();
        let (mut frequency_hz, mut density) = (Vec::new(), Vec::new());
        if let (Some(first), Some(last)) = (members.first(), members.last()) {
            let (lo, hi) = (elementary::log(first.0), elementary::log(last.0));
            let span = (hi - lo).max(f64::MIN_POSITIVE);
            let mut sums = vec![(0.0, 0.0, 0usize); points];
            for &(f, d) in &members {
                let b = (((elementary::log(f) - lo) / span) * points as f64) as usize;
                let s = &mut sums[b.min(points - 1)];
                s.0 += f;
                s.1 += d;
                s.2 += 1;
            }
            for (f, d, m) in sums.into_iter().filter(|s| s.2 > 0) {
                frequency_hz.push(f / m as f64);
                density.push(d / m as f64);
            }
        }
        Psd {
            frequency_hz,
            density,
            binned: true,
            unit: self.unit.clone(),
            ..*self
        }
    }
}

impl std::fmt::Display for Psd {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "Welch PSD: {} segments of {} samples (Hann, 50% overlap), resolution {} Hz",
            self.segments, self.segment_length, self.resolution_hz
        )?;
        for (fr, d) in self.frequency_hz.iter().zip(&self.density) {
            writeln!(f, "{fr:>14.6e} Hz  {d:>14.6e} {}", self.unit)?;
        }
        Ok(())
    }
}

/// Welch's estimator fed chunk by chunk (module doc): memory `O(L)`, cost `O(N log L)`.
pub(crate) struct Welch {
    fft: Arc<dyn Fft<f64>>,
    window: Vec<f64>,
    /// `Σ w²`.
    window_power: f64,
    /// Samples not yet in a full segment (at most `L`).
    pending: Vec<f64>,
    buffer: Vec<Complex<f64>>,
    scratch: Vec<Complex<f64>>,
    /// Sum over segments of `|X_k|²`, `k = 0 ..= L/2`.
    power: Vec<f64>,
    segments: usize,
    /// Samples pushed (for the index of a non-finite one).
    seen: usize,
    freq_hz: f64,
}

impl std::fmt::Debug for Welch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Welch")
            .field("segment_length", &self.window.len())
            .field("segments", &self.segments)
            .field("freq_hz", &self.freq_hz)
            .finish()
    }
}

impl Welch {
    /// An estimator with segments of `segment_length` samples at `freq_hz`.
    ///
    /// # Errors
    /// [`ParamError`] for a segment length that is not a power of two of at least 8, or a rate
    /// that is not a positive number.
    pub(crate) fn new(segment_length: usize, freq_hz: f64) -> Result<Self, ParamError> {
        check_freq(freq_hz)?;
        if segment_length < 8 || !segment_length.is_power_of_two() {
            return Err(ParamError::new(
                "segment_length",
                segment_length,
                "a power of two of at least 8",
            ));
        }
        let l = segment_length;
        // periodic Hann: w_n = sin²(π n / L), whose 50%-overlapped copies sum to 1
        let window: Vec<f64> = (0..l)
            .map(|n| elementary::sin(std::f64::consts::PI * n as f64 / l as f64).powi(2))
            .collect();
        let window_power = window.iter().map(|w| w * w).sum();
        let fft = FftPlanner::new().plan_fft_forward(l);
        let scratch = vec![Complex::default(); fft.get_inplace_scratch_len()];
        Ok(Self {
            fft,
            window,
            window_power,
            pending: Vec::with_capacity(l),
            buffer: vec![Complex::default(); l],
            scratch,
            power: vec![0.0; l / 2 + 1],
            segments: 0,
            seen: 0,
            freq_hz,
        })
    }

    /// Takes the next samples of the series.
    ///
    /// # Errors
    /// [`SeriesError::NonFinite`] with the sample's 0-based index in the whole series.
    pub(crate) fn push(&mut self, x: &[f64]) -> Result<(), SeriesError> {
        if let Err(SeriesError::NonFinite { index, value }) = check_finite(x) {
            return Err(SeriesError::NonFinite {
                index: self.seen + index,
                value,
            });
        }
        self.seen += x.len();
        let l = self.window.len();
        let mut rest = x;
        while !rest.is_empty() {
            let take = (l - self.pending.len()).min(rest.len());
            self.pending.extend_from_slice(&rest[..take]);
            rest = &rest[take..];
            if self.pending.len() == l {
                self.segment();
                // 50% overlap: the second half starts the next segment
                self.pending.copy_within(l / 2.., 0);
                self.pending.truncate(l / 2);
            }
        }
        Ok(())
    }

    /// Marks a break in the series: the next samples pushed do not follow the previous ones,
    /// so no segment straddles the break (the samples since the last full segment are
    /// dropped).
    pub(crate) fn discontinue(&mut self) {
        self.pending.clear();
    }

    /// One full segment in `pending`: mean removed, windowed, transformed, accumulated.
    fn segment(&mut self) {
        let l = self.pending.len();
        let mean = self.pending.iter().sum::<f64>() / l as f64;
        for ((b, &x), &w) in self.buffer.iter_mut().zip(&self.pending).zip(&self.window) {
            *b = Complex::new((x - mean) * w, 0.0);
        }
        self.fft
            .process_with_scratch(&mut self.buffer, &mut self.scratch);
        for (p, b) in self.power.iter_mut().zip(&self.buffer) {
            *p += b.norm_sqr();
        }
        self.segments += 1;
    }

    /// The PSD of the samples pushed (module doc: one-sided, unit²/Hz).
    ///
    /// # Errors
    /// [`SeriesError::TooShort`] when fewer samples than one segment were pushed.
    pub(crate) fn finish(self) -> Result<Psd, SeriesError> {
        let l = self.window.len();
        if self.segments == 0 {
            return Err(if self.seen == 0 {
                SeriesError::Empty
            } else {
                SeriesError::TooShort {
                    n: self.seen,
                    needed: l,
                    what: "a Welch PSD (one segment)".into(),
                }
            });
        }
        let scale = 1.0 / (self.freq_hz * self.window_power * self.segments as f64);
        let half = l / 2;
        let density = self
            .power
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let fold = if k == 0 || k == half { 1.0 } else { 2.0 };
                fold * scale * p
            })
            .collect();
        let resolution_hz = self.freq_hz / l as f64;
        Ok(Psd {
            frequency_hz: (0..=half).map(|k| k as f64 * resolution_hz).collect(),
            density,
            unit: "u^2/Hz".to_string(),
            freq_hz: self.freq_hz,
            segment_length: l,
            segments: self.segments,
            resolution_hz,
            binned: false,
        })
    }
}

/// The Welch PSD of `x` sampled at `freq_hz` (module doc), segments of `L` samples: the largest
/// power of two at most `N / 8`, between 256 and 65536 (`segment_length`).
///
/// Cost: `O(N log L)` time, `O(L)` memory besides `x`.
///
/// # Errors
/// A rate that is not positive ([`ParamError`]); an empty series, one shorter than
/// `MIN_SEGMENT` samples, or a non-finite sample ([`SeriesError`]).
///
/// # Examples
/// ```
/// // a sinusoid of 12.5 Hz at 100 Hz: the PSD peaks there
/// let x: Vec<f64> = (0..4096).map(|t| (std::f64::consts::TAU * 0.125 * t as f64).sin()).collect();
/// let psd = gmwm::welch_psd(&x, 100.0).unwrap();
/// let peak = (0..psd.density().len()).max_by(|&a, &b| psd.density()[a].total_cmp(&psd.density()[b])).unwrap();
/// assert!((psd.frequency_hz()[peak] - 12.5).abs() <= psd.resolution_hz());
/// ```
pub fn welch_psd(x: &[f64], freq_hz: f64) -> Result<Psd, InputError> {
    check_freq(freq_hz)?;
    let l = segment_length(x.len()).ok_or_else(|| {
        if x.is_empty() {
            SeriesError::Empty
        } else {
            SeriesError::TooShort {
                n: x.len(),
                needed: MIN_SEGMENT,
                what: "a Welch PSD (one segment)".into(),
            }
        }
    })?;
    let mut welch = Welch::new(l, freq_hz)?;
    welch.push(x)?;
    Ok(welch.finish()?)
}
