//! The Welch PSD (`variance::psd`) against truths computed without it: the white-noise level
//! `2 σ² / f_s` of the true σ², Parseval's identity computed sample by sample, a sinusoid's
//! line and power, and a moving average's `|H(f)|²`; the segment rule, streaming and errors.

use crate::tests::common::white_noise;
use gmwm::variance::psd::{segment_length, welch_psd, Psd, Welch, BINNED_POINTS, MIN_SEGMENT};
use gmwm::{InputError, SeriesError};

const SEED: u64 = 20_261_127;

/// Relative standard error of a Welch estimate that averages `bins` adjacent frequencies of
/// `segments` 50%-overlapped Hann segments: each frequency's estimate has relative variance
/// `1.06 / K` (Welch's `1 + 2 ρ(½)²`, `ρ(½) = 0.167`), and adjacent Hann frequencies are
/// correlated, so `bins` of them count as about `bins / 1.5` independent ones (the Hann
/// window's equivalent noise bandwidth, 1.5 bins).
fn welch_se(segments: usize, bins: usize) -> f64 {
    (1.06 * 1.5 / (segments as f64 * bins as f64)).sqrt()
}

/// Monte-Carlo tolerances are this many standard errors: a fixed seed passes or fails for
/// good, and a wrong fold (factor 2) or window normalisation (`Σw` for `Σw²`: 33%) is
/// hundreds of standard errors away.
const Z: f64 = 5.0;

fn mean(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len() as f64
}

#[test]
fn psd_segment_length_follows_the_rule() {
    assert_eq!(segment_length(0), None);
    assert_eq!(segment_length(MIN_SEGMENT - 1), None);
    assert_eq!(segment_length(MIN_SEGMENT), Some(256));
    assert_eq!(segment_length(2047), Some(256));
    assert_eq!(segment_length(4096), Some(512));
    assert_eq!(segment_length(4096 * 8 - 1), Some(2048));
    assert_eq!(segment_length(1 << 30), Some(1 << 16));
}

#[test]
fn psd_white_noise_level_is_two_sigma2_over_f() {
    // N = 2^18 at 200 Hz: L = 2^15, 15 segments
    let (n, sigma2, f) = (1usize << 18, 4e-6, 200.0);
    let x = white_noise(n, sigma2, SEED);
    let psd = welch_psd(&x, f).unwrap();
    assert_eq!(psd.segment_length(), 1 << 15);
    assert_eq!(psd.segments(), 15);
    let level = 2.0 * sigma2 / f;
    let d = psd.density();
    let interior = &d[1..d.len() - 1];
    // the mean over every frequency is the window-weighted sample variance (Parseval): its
    // relative sd is sqrt(2 / N_eff), N_eff = 0.947 N for the overlapped Hann weights
    // (sin^4 + cos^4 ranges 0.5..1: efficiency 0.75^2 / 0.594)
    let se_all = (2.0 / (0.947 * n as f64)).sqrt();
    let r = mean(interior) / level;
    assert!((r - 1.0).abs() < Z * se_all, "mean level / (2 σ²/f) = {r}");
    // flat: each of 8 bands of frequencies at the level
    let band = interior.len() / 8;
    for (i, chunk) in interior.chunks(band).take(8).enumerate() {
        let r = mean(chunk) / level;
        let tol = Z * welch_se(psd.segments(), chunk.len());
        assert!((r - 1.0).abs() < tol, "band {i}: {r} (tolerance {tol})");
    }
    // the binned version too, and within the rule's limits
    let binned = psd.binned(BINNED_POINTS);
    assert!(binned.is_binned() && binned.frequency_hz().len() <= BINNED_POINTS);
    assert!(binned.frequency_hz().windows(2).all(|w| w[0] < w[1]));
    assert!(binned.frequency_hz()[0] > 0.0 && *binned.frequency_hz().last().unwrap() < f / 2.0);
    let top = binned.density().last().unwrap() / level;
    assert!((top - 1.0).abs() < 0.05, "top bin {top}");
}

/// `Σ_k P_k Δf` against the mean over segments of `Σ w² (x - mean)² / Σ w²`, summed sample by
/// sample without a transform.
fn windowed_mean_square(x: &[f64], l: usize) -> f64 {
    let w: Vec<f64> = (0..l)
        .map(|n| 0.5 - 0.5 * (std::f64::consts::TAU * n as f64 / l as f64).cos())
        .collect();
    let w2: f64 = w.iter().map(|v| v * v).sum();
    let mut total = 0.0;
    let mut segments = 0;
    let mut start = 0;
    while start + l <= x.len() {
        let seg = &x[start..start + l];
        let m = mean(seg);
        total += seg
            .iter()
            .zip(&w)
            .map(|(v, w)| (w * (v - m)).powi(2))
            .sum::<f64>()
            / w2;
        segments += 1;
        start += l / 2;
    }
    total / segments as f64
}

fn integral(psd: &Psd) -> f64 {
    psd.density().iter().sum::<f64>() * psd.resolution_hz()
}

/// An AR(1) with phi = 0.9 plus a sinusoid: coloured, with a line.
fn coloured(n: usize, seed: u64) -> Vec<f64> {
    let e = white_noise(n, 1.0, seed);
    let mut y = 0.0;
    e.iter()
        .enumerate()
        .map(|(t, e)| {
            y = 0.9 * y + e;
            y + 3.0 * (0.7 * t as f64).sin()
        })
        .collect()
}

#[test]
fn psd_parseval_integral_is_the_variance() {
    let f = 50.0;
    let x = coloured(100_000, SEED + 1);
    let psd = welch_psd(&x, f).unwrap();
    // exact identity (Parseval per segment): only rounding apart
    let direct = windowed_mean_square(&x, psd.segment_length());
    let rel = (integral(&psd) / direct - 1.0).abs();
    assert!(rel < 1e-10, "Parseval identity off by {rel}");
    // and about the sample variance: the integral weights samples by the overlapped Hann²
    // (0.5..1) and drops the 760 samples after the last segment; for this series (correlation
    // time 10 samples) the weighted and plain variances of the same data differ by well under
    // 1% (a sampling fluctuation of relative sd about 0.2%)
    let m = mean(&x);
    let var = x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (x.len() - 1) as f64;
    let rel = (integral(&psd) / var - 1.0).abs();
    assert!(
        rel < 0.01,
        "integral {} against variance {var}",
        integral(&psd)
    );
}

#[test]
fn psd_sinusoid_peaks_at_its_frequency_with_its_power() {
    // 13.37 Hz at 100 Hz, between two frequencies of the grid; amplitude 1, power 1/2
    let (f, f0, n) = (100.0, 13.37, 1usize << 16);
    let noise = white_noise(n, 0.01, SEED + 2);
    let x: Vec<f64> = noise
        .iter()
        .enumerate()
        .map(|(t, e)| (std::f64::consts::TAU * f0 * t as f64 / f + 0.3).sin() + e)
        .collect();
    let psd = welch_psd(&x, f).unwrap();
    let d = psd.density();
    let peak = (0..d.len()).max_by(|&a, &b| d[a].total_cmp(&d[b])).unwrap();
    let df = psd.resolution_hz();
    assert!(
        (psd.frequency_hz()[peak] - f0).abs() <= df,
        "peak at {} Hz, line at {f0} Hz, resolution {df} Hz",
        psd.frequency_hz()[peak]
    );
    // the Hann main lobe spans ±2 frequencies; ±4 hold all but the -31 dB side lobes, and the
    // noise in 9 frequencies adds 9 · 2 σ²/f · Δf = 2e-5
    let power: f64 = d[peak - 4..=peak + 4].iter().sum::<f64>() * df;
    assert!((power / 0.5 - 1.0).abs() < 0.01, "line power {power}");
}

#[test]
fn psd_moving_average_follows_its_gain() {
    // y_t = (x_t + ... + x_{t-3}) / 4: |H(f)|² = (sin(4πf/f_s) / (4 sin(πf/f_s)))², zeros at
    // f_s/4 and f_s/2
    let (n, sigma2, f) = (1usize << 20, 1.0, 400.0);
    let x = white_noise(n + 3, sigma2, SEED + 3);
    let y: Vec<f64> = x.windows(4).map(|w| w.iter().sum::<f64>() / 4.0).collect();
    let psd = welch_psd(&y, f).unwrap();
    let gain = |fr: f64| {
        let a = std::f64::consts::PI * fr / f;
        if a == 0.0 {
            1.0
        } else {
            ((4.0 * a).sin() / (4.0 * a.sin())).powi(2)
        }
    };
    let level = 2.0 * sigma2 / f;
    let group = 256;
    let (fr, d) = (psd.frequency_hz(), psd.density());
    let mut checked = 0;
    for start in (1..d.len() - group).step_by(group) {
        let idx = start..start + group;
        // away from the zeros, where the window's leakage dominates a vanishing gain
        if idx.clone().any(|k| gain(fr[k]) < 0.05) {
            continue;
        }
        let r = idx
            .clone()
            .map(|k| d[k] / (level * gain(fr[k])))
            .sum::<f64>()
            / group as f64;
        let tol = Z * welch_se(psd.segments(), group);
        assert!(
            (r - 1.0).abs() < tol,
            "{} Hz: ratio {r} (tolerance {tol})",
            fr[start]
        );
        checked += 1;
    }
    assert!(checked > 40, "{checked} groups checked");
    // and the zero at f_s/4 is deep: far below the level
    let quarter = d.len() / 2;
    assert!(d[quarter] < 1e-2 * level, "{}", d[quarter]);
}

#[test]
fn psd_streamed_in_chunks_equals_one_pass() {
    let x = coloured(20_000, SEED + 4);
    let l = segment_length(x.len()).unwrap();
    let mut whole = Welch::new(l, 10.0).unwrap();
    whole.push(&x).unwrap();
    let mut chunked = Welch::new(l, 10.0).unwrap();
    let mut rest: &[f64] = &x;
    let mut k = 1;
    while !rest.is_empty() {
        let take = (k * 37 % 1001).min(rest.len());
        chunked.push(&rest[..take]).unwrap();
        rest = &rest[take..];
        k += 1;
    }
    assert_eq!(whole.finish().unwrap(), chunked.finish().unwrap());
}

#[test]
fn psd_refuses_short_series_bad_rates_and_non_finite_samples() {
    let x = white_noise(MIN_SEGMENT - 1, 1.0, SEED);
    assert!(matches!(
        welch_psd(&x, 100.0),
        Err(InputError::Series(SeriesError::TooShort {
            n: 255,
            needed: 256,
            ..
        }))
    ));
    assert!(matches!(
        welch_psd(&[], 100.0),
        Err(InputError::Series(SeriesError::Empty))
    ));
    let x = white_noise(1024, 1.0, SEED);
    assert!(matches!(welch_psd(&x, 0.0), Err(InputError::Param(_))));
    assert!(matches!(welch_psd(&x, f64::NAN), Err(InputError::Param(_))));
    assert!(Welch::new(100, 1.0).is_err() && Welch::new(4, 1.0).is_err());
    // a NaN in the second chunk: its index in the whole series
    let mut w = Welch::new(256, 1.0).unwrap();
    w.push(&x[..300]).unwrap();
    let mut bad = x[300..400].to_vec();
    bad[7] = f64::NAN;
    assert!(matches!(
        w.push(&bad),
        Err(SeriesError::NonFinite { index: 307, .. })
    ));
    // fewer samples than one segment: an error, not an empty PSD
    let mut w = Welch::new(512, 1.0).unwrap();
    w.push(&x[..511]).unwrap();
    assert!(matches!(
        w.finish(),
        Err(SeriesError::TooShort { n: 511, .. })
    ));
    let msg = welch_psd(&x[..100], 1.0).unwrap_err().to_string();
    assert!(msg.contains("100 samples") && msg.contains("256"), "{msg}");
}

#[test]
fn psd_segment_mean_is_removed() {
    // an offset of 1000 (a bias, gravity on an accelerometer) changes nothing: each segment's
    // mean is removed before the window, so no DC leaks into the first frequencies through the
    // Hann window's main lobe (it would add 0.25 · 1000² · L / (f Σw²) at k = 1)
    let x = white_noise(1 << 14, 1.0, SEED + 5);
    let shifted: Vec<f64> = x.iter().map(|v| v + 1000.0).collect();
    let (a, b) = (
        welch_psd(&x, 10.0).unwrap(),
        welch_psd(&shifted, 10.0).unwrap(),
    );
    for (k, (p, q)) in a.density().iter().zip(b.density()).enumerate() {
        // rounding of x + 1000 (1e-13 of 1000) against a density of order 0.2
        assert!(
            (p - q).abs() <= 1e-8 * p.max(1e-3),
            "frequency {k}: {p} vs {q}"
        );
    }
}

/// The veto on vibration lines of the calibration's refinement (`calib::pipeline`): a sinusoid
/// at 7.3 Hz in white noise is a line near 7.3 Hz, and near its WV's hump frequency an octave
/// off; white noise alone has none at any frequency; a line far from `f0` does not count.
#[test]
fn spectral_line_is_found_where_a_sinusoid_is_and_nowhere_in_white_noise() {
    use gmwm::calib::pipeline::has_spectral_line;
    let (n, fs) = (1usize << 18, 100.0);
    let noise = white_noise(n, 1.0, 5);
    let line: Vec<f64> = noise
        .iter()
        .enumerate()
        .map(|(t, w)| w + 0.3 * (2.0 * std::f64::consts::PI * 7.3 * t as f64 / fs).sin())
        .collect();
    let with = welch_psd(&line, fs).unwrap().binned(BINNED_POINTS);
    let without = welch_psd(&noise, fs).unwrap().binned(BINNED_POINTS);
    for f0 in [7.3, 5.0, 12.0] {
        assert!(has_spectral_line(&with, f0), "line near {f0} Hz");
    }
    for f0 in [0.05, 0.5, 2.0, 7.3, 20.0, 40.0] {
        assert!(!has_spectral_line(&without, f0), "white noise at {f0} Hz");
    }
    assert!(!has_spectral_line(&with, 0.5), "a line 4 octaves away");
    // a fitted vibration frequency must lie on the line, not an octave off
    use gmwm::calib::pipeline::{spectral_line_within, LINE_MATCH};
    for f0 in [7.3, 6.5, 8.5] {
        assert!(
            spectral_line_within(&with, f0, LINE_MATCH),
            "{f0} Hz on the line"
        );
    }
    for f0 in [5.0, 10.0, 12.0] {
        assert!(
            !spectral_line_within(&with, f0, LINE_MATCH),
            "{f0} Hz off the line"
        );
    }
}

/// A break (`Welch::discontinue`) between two pieces: the PSD averages the pieces' own
/// segments, none across the break, so its power is the segment-weighted sum of the pieces'
/// (to rounding).
#[test]
fn welch_break_averages_the_pieces_segments() {
    let (l, f) = (256, 50.0);
    let a = white_noise(4 * l + 100, 1.0, SEED);
    let b: Vec<f64> = white_noise(6 * l, 1.0, SEED + 1)
        .iter()
        .map(|v| 3.0 * v + 100.0)
        .collect();
    let piece = |x: &[f64]| {
        let mut w = Welch::new(l, f).unwrap();
        w.push(x).unwrap();
        w.finish().unwrap()
    };
    let (pa, pb) = (piece(&a), piece(&b));
    let mut w = Welch::new(l, f).unwrap();
    w.push(&a).unwrap();
    w.discontinue();
    w.push(&b).unwrap();
    let both = w.finish().unwrap();
    assert_eq!(both.segments(), pa.segments() + pb.segments());
    for k in 0..both.density().len() {
        let want = (pa.density()[k] * pa.segments() as f64
            + pb.density()[k] * pb.segments() as f64)
            / both.segments() as f64;
        let got = both.density()[k];
        assert!(
            (got - want).abs() <= 1e-12 * want,
            "bin {k}: {got} vs {want}"
        );
    }
}
