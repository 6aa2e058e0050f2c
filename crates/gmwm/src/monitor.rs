//! Fault detection with the robust wavelet variance (paper §IV-C; docs/methods.md §16): a window
//! moves along a long recording, and a window whose robust WV leaves the band a calibrated model
//! predicts for a window of that length is flagged, with its times.
//!
//! # Windows (docs/methods.md §16.1)
//! Windows of `L` samples start at `0, s, 2s, ...` (`s` the step) while they fit in the series;
//! when the last one stops short of the end, one more window ends at the last sample. Window
//! `w` covers samples `[a_w, a_w + L)`, times `a_w / f` to `(a_w + L) / f` seconds from the first
//! sample.
//!
//! # Levels (docs/methods.md §16.2)
//! The levels `j` whose boundary-free coefficient count `M_j = L - 2^j + 1` gives at least
//! `MIN_ETA` equivalent degrees of freedom by §1.7 (`M_j / 2^j >= 8`): coarser levels are too
//! noisy in one window to show anything but gross faults (capped by `--levels`).
//!
//! # Band (docs/methods.md §16.3)
//! Under the model, the classical WV of a window at level `j` is approximately
//! `nu_j chi2(eta_j) / eta_j` (§1.7), with the equivalent degrees of freedom matched to the
//! model's exact variance for a window of `L` samples (`crate::variance::implied_cov`):
//!
//! `eta_j = 2 nu_j^2 / V_jj(L)`.
//!
//! The robust WV (§2) has the same centre at Gaussian data and `1 / eff` times the variance
//! (§1.10), so its law is taken as `nu_j chi2(eff eta_j) / (eff eta_j)`. Both estimators are
//! tested at each of the `k` levels: the robust one sees a change of the noise process (a step
//! in variance, a new correlated error) and ignores isolated outliers, the classical one sees the
//! outliers (a burst of spikes) too. Each of the `2k` tests gets the two-sided level
//! `alpha / (2k)` (Bonferroni), so a window of a series that follows the model is flagged with
//! probability at most `alpha`:
//!
//! `band_j = [nu_j q(alpha / (4k); r_j) / r_j,  nu_j q(1 - alpha / (4k); r_j) / r_j]`,
//! `r_j = eff eta_j` (robust) or `eta_j` (classical), `q` the chi-square quantile.
//!
//! The rate of false flags is per window (about `alpha` of the windows of a clean recording,
//! fewer since the levels are positively correlated), not per recording: over `W` windows expect
//! up to `alpha W` flags by chance. A model the exact covariance does not cover (a generic ARMA,
//! a negative AR coefficient) falls back to `eta_j` of §1.7 (`M_j / 2^j`), which the report says.
//!
//! # Against the calibration's WV (docs/methods.md §16.6)
//! The band above assumes the model is exact. A calibrated model that misfits its own
//! recording's WV by a few percent (real IMUs, where the J-test rejects) is outside the band of
//! long windows at the fine scales, whose equivalent degrees of freedom run to tens of
//! thousands, so nearly every window is flagged for the misfit, not for a fault.
//! [`monitor_against`] with [`Reference::Wv`] centres each band on the calibration's empirical
//! WV instead (the robust band on its robust WV, which on contaminated data lies below the
//! classical one) and widens it by that WV's own uncertainty: with `s2_j` the variance of
//! `ln nu2_hat_j` ([`WaveletVariance::log_variance`], `psi'(eta_j / 2) / eff`) and `2 / r` that
//! of a window's `ln WV`, the band uses the degrees of freedom `r' = 2 / (2 / r + s2_j)` of
//! their sum. The model still gives the shape of the
//! window's variance (`eta_j`). A window is then flagged when it differs from the calibrated
//! recording, whatever the model.
//!
//! # Rule (docs/methods.md §16.4)
//! A window is flagged when its robust or its classical WV leaves its band at one level or more;
//! each level out is reported with the estimator, its direction and its ratio to the model's WV
//! (classical out and robust in: outliers; robust out: the process changed). Adjacent or overlapping flagged
//! windows are merged into one event.

use crate::error::{InputError as Error, ParamError};
use crate::model::Model;
use crate::variance::ci::{check_alpha, chi_square_quantile};
use crate::variance::implied_cov::exact_wv_covariance;
use crate::variance::robust::RobustOptions;
use crate::variance::wv::{wavelet_variance, WaveletVariance, WvOptions};
use serde::Serialize;

/// Smallest equivalent degrees of freedom `M_j / 2^j` (§1.7) of a level the monitor tests.
pub(crate) const MIN_ETA: f64 = 8.0;

/// Settings of `monitor`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MonitorOptions {
    /// Window length `L` in samples; default 2^16 (11 min at 100 Hz: levels up to 2^12 samples).
    pub window: usize,
    /// Step between window starts in samples; default half a window.
    pub step: Option<usize>,
    /// Probability that a window of a series following the model is flagged (at most); default
    /// 0.01.
    pub alpha: f64,
    /// Robust estimator (§2); default `eff = 0.6`.
    pub robust: RobustOptions,
    /// Largest level tested; default `None` (every level with `M_j / 2^j >= MIN_ETA`).
    pub levels: Option<usize>,
}

impl Default for MonitorOptions {
    fn default() -> Self {
        Self {
            window: 1 << 16,
            step: None,
            alpha: 0.01,
            robust: RobustOptions::default(),
            levels: None,
        }
    }
}

/// One level of a window outside the band.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LevelOut {
    /// Level `j` (scale `2^j` samples).
    pub level: usize,
    /// `"robust"` (the robust WV left the robust band: the noise process changed) or
    /// `"classical"` (the classical WV left its band: outliers such as spikes, which the
    /// robust WV ignores).
    pub estimator: &'static str,
    /// `"high"` (above the band) or `"low"`.
    pub side: &'static str,
    /// The window's WV (of `estimator`) over the reference WV (the model's, or the
    /// calibration's).
    pub ratio: f64,
}

/// One window.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MonitorWindow {
    /// First sample (0-based).
    pub start: usize,
    /// One past the last sample.
    pub end: usize,
    /// `start / f` (s from the first sample).
    pub start_s: f64,
    /// `end / f` (s).
    pub end_s: f64,
    /// The window's robust WV at the tested levels.
    pub wv: Vec<f64>,
    /// The window's classical WV at the tested levels.
    pub(crate) classical_wv: Vec<f64>,
    /// Whether it leaves the band at some level.
    pub flagged: bool,
    /// The levels out of the band.
    pub out: Vec<LevelOut>,
}

/// A run of flagged windows (overlapping or adjacent), merged.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MonitorEvent {
    /// First sample of the first flagged window.
    pub start: usize,
    /// One past the last sample of the last one.
    pub end: usize,
    /// Seconds from the first sample.
    pub start_s: f64,
    /// Seconds from the first sample.
    pub end_s: f64,
    /// Flagged windows merged.
    pub windows: usize,
}

/// What each window's WV is compared with (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reference<'a> {
    /// The model's implied WV (docs/methods.md §16.3).
    Model,
    /// The calibration's empirical WVs with their degrees of freedom (docs/methods.md §16.6): for a
    /// model that misfits the recording it was calibrated on. The windows' classical WV is
    /// compared with `classical`, their robust WV with `robust` (at the levels where it is
    /// defined; elsewhere, or without it, with `classical`).
    Wv {
        /// The calibration's classical WV.
        classical: &'a WaveletVariance,
        /// Its robust WV (the contamination check's), if any.
        robust: Option<&'a WaveletVariance>,
    },
}

/// The centre of a band at each level and the variance of its logarithm (docs/methods.md
/// §16.6): `w`'s value and [`WaveletVariance::log_variance`] at the first `levels` levels,
/// `None` at a level where `w` has no positive finite value or degrees of freedom.
fn centre(w: &WaveletVariance, levels: usize) -> Vec<Option<(f64, f64)>> {
    let log_var = w.log_variance();
    (0..levels)
        .map(|j| {
            let (v, var) = (*w.wv().get(j)?, *log_var.get(j)?);
            (v.is_finite() && v > 0.0 && var.is_finite() && var > 0.0).then_some((v, var))
        })
        .collect()
}

/// Result of `monitor` for one series.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MonitorReport {
    /// The model (with values) the band comes from.
    pub model: String,
    /// What the windows are compared with: `"model"` (its implied WV) or `"calibration WV"`
    /// (the calibration's empirical WV, docs/methods.md §16.6).
    pub reference: &'static str,
    /// The centre of the classical WV's bands at the tested levels: the model's WV or the
    /// calibration's.
    pub(crate) reference_wv: Vec<f64>,
    /// The centre of the robust WV's bands: the model's WV or the calibration's robust WV.
    pub(crate) robust_reference_wv: Vec<f64>,
    /// Sampling rate (Hz).
    pub freq_hz: f64,
    /// Window length (samples).
    pub window: usize,
    /// Step (samples).
    pub step: usize,
    /// Probability bound of a false flag per window.
    pub alpha: f64,
    /// Level of each of the `2 k` tests of a window (`alpha / (2 k)`, Bonferroni).
    pub alpha_level: f64,
    /// Robust efficiency.
    pub eff: f64,
    /// Scales `2^j / f` of the tested levels (s).
    pub tau_s: Vec<f64>,
    /// The model's WV at those levels.
    pub(crate) model_wv: Vec<f64>,
    /// Equivalent degrees of freedom of a window's classical WV (§16.3), before the
    /// reference's own uncertainty (§16.6).
    pub eta: Vec<f64>,
    /// Band of the robust WV, lower ends.
    pub(crate) band_low: Vec<f64>,
    /// Band of the robust WV, upper ends.
    pub(crate) band_high: Vec<f64>,
    /// Band of the classical WV, lower ends.
    pub(crate) classical_band_low: Vec<f64>,
    /// Band of the classical WV, upper ends.
    pub(crate) classical_band_high: Vec<f64>,
    /// Whether `eta` comes from the exact covariance (`false`: §1.7's `M_j / 2^j`).
    pub(crate) exact_eta: bool,
    /// Every window.
    pub windows: Vec<MonitorWindow>,
    /// Merged runs of flagged windows.
    pub events: Vec<MonitorEvent>,
    /// Number of flagged windows.
    pub flagged: usize,
}

/// Runs the robust-WV monitor (module docs, docs/methods.md §16) over `x` sampled at `freq_hz`
/// against `model` (every value given, e.g. a calibration's estimate).
///
/// ```
/// use gmwm::Model;
/// use gmwm::monitor::{monitor, MonitorOptions};
/// use gmwm::simulate_model;
/// let model = Model::parse("WN(sigma2=1)").unwrap();
/// let mut x = simulate_model(&model, 1 << 15, 1.0, 1).unwrap();
/// for v in &mut x[20_000..21_000] { *v *= 3.0; } // a burst of extra noise
/// let opts = MonitorOptions { window: 4096, ..MonitorOptions::default() };
/// let r = monitor(&x, 1.0, &model, &opts).unwrap();
/// assert!(r.windows.iter().filter(|w| w.flagged).all(|w| w.start < 21_000 && w.end > 20_000));
/// assert!(r.flagged >= 1);
/// ```
///
/// # Errors
/// [`ParamError`] for a model without all its values, a window shorter than 16 samples or
/// longer than the series (naming `window`), a zero step, a bad `alpha`; as
/// [`wavelet_variance`] for a series with non-finite values.
#[cfg(test)]
pub(crate) fn monitor(
    x: &[f64],
    freq_hz: f64,
    model: &Model,
    opts: &MonitorOptions,
) -> Result<MonitorReport, Error> {
    monitor_against(x, freq_hz, model, Reference::Model, opts)
}

/// `monitor` with the windows compared with `reference` (module doc): the model's WV, or the
/// calibration's empirical WV (at the levels both the window and it have), the model then
/// giving the shape of a window's variance.
///
/// # Errors
/// As `monitor`; [`ParamError`] for a reference WV of another rate or with a level that is
/// not positive and finite.
pub fn monitor_against(
    x: &[f64],
    freq_hz: f64,
    model: &Model,
    reference: Reference<'_>,
    opts: &MonitorOptions,
) -> Result<MonitorReport, Error> {
    let (step, levels) = window_plan(x.len(), freq_hz, model, reference, opts)?;
    let big = opts.window;
    let implied = model.implied_wv(levels, freq_hz)?;
    let model_wv = implied.wv.clone();
    let (classical_ref, robust_ref) = reference_centres(reference, &model_wv)?;
    let (eta, exact_eta) = window_eta(model, big, freq_hz, &model_wv);
    let alpha_level = opts.alpha / (2 * levels) as f64;
    let classical_band = Band::of(&classical_ref, &eta, 1.0, alpha_level)?;
    let robust_band =
        Band::of(&robust_ref, &eta, opts.robust.eff(), alpha_level)?.ok_or_else(|| {
            ParamError::new(
                "model",
                model.to_string(),
                "a model with a positive finite WV variance at every tested level",
            )
        })?;
    let wv_opts = WvOptions {
        levels: Some(levels),
        robust: Some(opts.robust),
        ..WvOptions::default()
    };
    use rayon::prelude::*;
    let windows: Vec<MonitorWindow> = window_starts(x.len(), big, step)
        .par_iter()
        .map(|&a| {
            window_check(
                &x[a..a + big],
                a,
                freq_hz,
                &wv_opts,
                (&robust_band, &robust_ref.nu),
                (&classical_band, &classical_ref.nu),
            )
        })
        .collect::<Result<_, _>>()?;
    let events = events_of(&windows);
    let flagged = windows.iter().filter(|w| w.flagged).count();
    let classical_band = classical_band.unwrap_or_default();
    Ok(MonitorReport {
        model: model.to_string(),
        reference: match reference {
            Reference::Model => "model",
            Reference::Wv { .. } => "calibration WV",
        },
        reference_wv: classical_ref.nu,
        robust_reference_wv: robust_ref.nu,
        freq_hz,
        window: big,
        step,
        alpha: opts.alpha,
        alpha_level,
        eff: opts.robust.eff(),
        tau_s: implied.tau_s.clone(),
        model_wv,
        eta,
        band_low: robust_band.low,
        band_high: robust_band.high,
        classical_band_low: classical_band.low,
        classical_band_high: classical_band.high,
        exact_eta,
        windows,
        events,
        flagged,
    })
}

/// The checks of `monitor_against`'s inputs, and the window step and the number of levels
/// compared: those with `M_j / 2^j >= MIN_ETA` in a window, at most `opts.levels` and the
/// reference WV's.
fn window_plan(
    n: usize,
    freq_hz: f64,
    model: &Model,
    reference: Reference<'_>,
    opts: &MonitorOptions,
) -> Result<(usize, usize), Error> {
    check_alpha(opts.alpha)?;
    if !(freq_hz.is_finite() && freq_hz > 0.0) {
        return Err(ParamError::new("freq", freq_hz, "a positive number of hertz").into());
    }
    if !model.is_fully_specified() {
        return Err(ParamError::new(
            "model",
            model.to_string(),
            "every parameter given (a calibrated model)",
        )
        .into());
    }
    let big = opts.window;
    if big < 16 {
        return Err(ParamError::new("window", big, "at least 16 samples").into());
    }
    if big > n {
        return Err(ParamError::new(
            "window",
            big,
            format!("at most the recording's {n} samples"),
        )
        .into());
    }
    let step = opts.step.unwrap_or((big / 2).max(1));
    if step == 0 {
        return Err(ParamError::new("step", step, "at least 1 sample").into());
    }
    // levels with M_j / 2^j >= MIN_ETA
    let mut levels = (1..60)
        .take_while(|&j| {
            let t = (1usize << j) as f64;
            (big as f64 - t + 1.0) / t >= MIN_ETA
        })
        .last()
        .unwrap_or(0);
    if let Some(cap) = opts.levels {
        levels = levels.min(cap);
    }
    if levels == 0 {
        return Err(ParamError::new(
            "window",
            big,
            format!("a window long enough for one level with M_j / 2^j >= {MIN_ETA} (18 samples)"),
        )
        .into());
    }
    if let Reference::Wv { classical: w, .. } = reference {
        if ((w.freq_hz() - freq_hz) / freq_hz).abs() > 1e-6 {
            return Err(ParamError::new(
                "reference WV",
                format!("at {} Hz", w.freq_hz()),
                format!("the recording's rate, {freq_hz} Hz"),
            )
            .into());
        }
        levels = levels.min(w.levels());
    }
    Ok((step, levels))
}

/// A band's centre per level and the log-scale variance of that centre (0 for the model's
/// own WV, which is known; docs/methods.md §16.6).
struct Centres {
    nu: Vec<f64>,
    log_var: Vec<f64>,
}

/// The classical and the robust bands' centres: the model's WV, or the calibration's WVs at
/// the levels compared (the robust falling back to the classical where it has none).
fn reference_centres(
    reference: Reference<'_>,
    model_wv: &[f64],
) -> Result<(Centres, Centres), Error> {
    let levels = model_wv.len();
    let known = || Centres {
        nu: model_wv.to_vec(),
        log_var: vec![0.0; levels],
    };
    let Reference::Wv { classical, robust } = reference else {
        return Ok((known(), known()));
    };
    let c = centre(classical, levels);
    let r = robust.map(|r| centre(r, levels));
    let empty = || Centres {
        nu: Vec::with_capacity(levels),
        log_var: Vec::with_capacity(levels),
    };
    let (mut classical_ref, mut robust_ref) = (empty(), empty());
    for j in 0..levels {
        let Some((v, var)) = c[j] else {
            return Err(ParamError::new(
                "reference WV",
                format!("level {}", j + 1),
                "a positive finite value with positive degrees of freedom (eta)",
            )
            .into());
        };
        let (vr, var_r) = r.as_ref().and_then(|r| r[j]).unwrap_or((v, var));
        classical_ref.nu.push(v);
        classical_ref.log_var.push(var);
        robust_ref.nu.push(vr);
        robust_ref.log_var.push(var_r);
    }
    Ok((classical_ref, robust_ref))
}

/// The equivalent degrees of freedom of a window's WV per level under the model: exact
/// (`2 nu^2 / V_jj`, `true`) where the exact covariance covers the model, else `M_j / 2^j`.
fn window_eta(model: &Model, big: usize, freq_hz: f64, model_wv: &[f64]) -> (Vec<f64>, bool) {
    let levels = model_wv.len();
    match exact_wv_covariance(model, big, freq_hz, levels) {
        Ok(v) => (
            (0..levels)
                .map(|j| 2.0 * model_wv[j] * model_wv[j] / v[(j, j)])
                .collect(),
            true,
        ),
        Err(_) => (
            (1..=levels)
                .map(|j| {
                    let t = (1usize << j) as f64;
                    ((big as f64 - t + 1.0) / t).max(1.0)
                })
                .collect(),
            false,
        ),
    }
}

/// A band per level around a reference WV (docs/methods.md §16.6).
#[derive(Default)]
struct Band {
    low: Vec<f64>,
    high: Vec<f64>,
}

impl Band {
    /// The chi-square band at `alpha_level` on each side around `centres`, with the window's
    /// `eta` scaled by `eff` (the robust estimator's efficiency) and widened by the centre's own
    /// uncertainty; `None` where a level has no positive finite degrees of freedom (the
    /// classical band then checks no level).
    fn of(
        centres: &Centres,
        eta: &[f64],
        eff: f64,
        alpha_level: f64,
    ) -> Result<Option<Band>, Error> {
        let widened = |r: f64, var: f64| 2.0 / (2.0 / r + var);
        let mut band = Band::default();
        for (j, &nu) in centres.nu.iter().enumerate() {
            let e = widened(eff * eta[j], centres.log_var[j]);
            if !(e.is_finite() && e > 0.0) {
                return Ok(None);
            }
            band.low
                .push(nu * chi_square_quantile(alpha_level / 2.0, e)? / e);
            band.high
                .push(nu * chi_square_quantile(1.0 - alpha_level / 2.0, e)? / e);
        }
        Ok(Some(band))
    }
}

/// The windows' first samples: every `step`, plus one ending at the recording's end.
fn window_starts(n: usize, big: usize, step: usize) -> Vec<usize> {
    let mut starts: Vec<usize> = (0..)
        .map(|k| k * step)
        .take_while(|s| s + big <= n)
        .collect();
    if starts.last().is_some_and(|&s| s + big < n) {
        starts.push(n - big);
    }
    starts
}

/// One window's robust and classical WVs against their bands: the levels outside.
fn window_check(
    part: &[f64],
    start: usize,
    freq_hz: f64,
    wv_opts: &WvOptions,
    (robust_band, robust_nu): (&Band, &[f64]),
    (classical_band, classical_nu): (&Option<Band>, &[f64]),
) -> Result<MonitorWindow, Error> {
    let classical_opts = WvOptions {
        robust: None,
        ..*wv_opts
    };
    let values = wavelet_variance(part, freq_hz, wv_opts)?.wv().to_vec();
    let classical = wavelet_variance(part, freq_hz, &classical_opts)?
        .wv()
        .to_vec();
    let check = |estimator, v: &[f64], band: &Band, nu: &[f64]| {
        (0..band.low.len())
            .filter_map(|j| {
                let side = if v[j] > band.high[j] {
                    "high"
                } else if v[j] < band.low[j] {
                    "low"
                } else {
                    return None;
                };
                Some(LevelOut {
                    level: j + 1,
                    estimator,
                    side,
                    ratio: v[j] / nu[j],
                })
            })
            .collect::<Vec<_>>()
    };
    let mut out = check("robust", &values, robust_band, robust_nu);
    if let Some(band) = classical_band {
        out.extend(check("classical", &classical, band, classical_nu));
    }
    let end = start + part.len();
    Ok(MonitorWindow {
        start,
        end,
        start_s: start as f64 / freq_hz,
        end_s: end as f64 / freq_hz,
        wv: values,
        classical_wv: classical,
        flagged: !out.is_empty(),
        out,
    })
}

/// Flagged windows that overlap or touch, merged into events.
fn events_of(windows: &[MonitorWindow]) -> Vec<MonitorEvent> {
    let mut events: Vec<MonitorEvent> = Vec::new();
    for w in windows.iter().filter(|w| w.flagged) {
        match events.last_mut() {
            Some(e) if w.start <= e.end => {
                e.end = w.end;
                e.end_s = w.end_s;
                e.windows += 1;
            }
            _ => events.push(MonitorEvent {
                start: w.start,
                end: w.end,
                start_s: w.start_s,
                end_s: w.end_s,
                windows: 1,
            }),
        }
    }
    events
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inference::asymptotic::z_value;
    use crate::inference::ZConvention;
    use crate::math::special::trigamma;

    /// The figures docs/methods/multi-axis.md §16.6 gives for its choice of the centre's
    /// log-variance ([`WaveletVariance::log_variance`]) over a reading of the centre's
    /// interval, `(ln(hi / lo) / (2 z))^2`: on the classical WV the two agree within 4% at
    /// `eta = 1` and 0.4% at `eta = 7`; on the robust WV (eff 0.6, 4096 samples) the interval
    /// reading is half of it at the coarsest level, where the robust interval's lower end is
    /// clipped. And §16.3's robust window, chi-square with `eff eta` degrees of freedom, parts
    /// from `psi'(eta / 2) / eff` by 10% at `eta = 7` and a third at `eta = 2`.
    #[test]
    fn the_centre_variance_figures_of_the_docs() {
        let x: Vec<f64> = (0..4096u64)
            .map(|t| ((t.wrapping_mul(2_654_435_761) % 1009) as f64 - 504.0) / 291.0)
            .collect();
        let z = z_value(0.05, ZConvention::TwoSided).unwrap();
        let read_off = |w: &WaveletVariance, j: usize| {
            ((w.ci_high()[j] / w.ci_low()[j]).ln() / (2.0 * z)).powi(2)
        };
        let classical = wavelet_variance(&x, 100.0, &WvOptions::default()).unwrap();
        let v = classical.log_variance();
        for (j, eta, gap) in [(10, 1.0, 0.04), (8, 7.0, 0.004)] {
            assert!(
                (classical.eta()[j] - eta).abs() < 0.01,
                "{}",
                classical.eta()[j]
            );
            let ratio = read_off(&classical, j) / v[j];
            assert!((ratio - 1.0).abs() < gap, "eta {eta}: {ratio}");
        }
        let opts = WvOptions {
            robust: Some(RobustOptions::default()),
            ..WvOptions::default()
        };
        let robust = wavelet_variance(&x, 100.0, &opts).unwrap();
        let ratio = read_off(&robust, 10) / robust.log_variance()[10];
        assert!((ratio - 0.5).abs() < 0.02, "{ratio}");
        let eff = 0.6;
        for (eta, gap) in [(7.0, 0.10), (2.0, 0.33)] {
            let part = 1.0 - trigamma(eff * eta / 2.0) / (trigamma(eta / 2.0) / eff);
            assert!((part.abs() - gap).abs() < 0.015, "eta {eta}: {part}");
        }
    }
}
