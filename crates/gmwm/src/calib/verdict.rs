//! The verdict of a calibration: can the numbers be used? The selected model explains the
//! wavelet variance when, at every scale, its implied WV lies inside the empirical WV's
//! `1 - alpha` band **or** within a practical tolerance of it (default 10%).
//!
//! At 10^6 samples and more the first scales' band is a fraction of a percent wide and the
//! J-test (docs/methods.md §7.3) rejects every model a navigation filter could use (the paper
//! says so, §II); a 10% error in a noise variance is a 5% error in a filter's noise density,
//! below what a filter tuned by hand notices. So the band alone would call every real sensor a
//! misfit and hide the misfits that matter: the scales where the model is off by more than the
//! tolerance **and** outside the band. Those are listed, with the term that dominates the
//! implied WV there and the likely cause read from where and how the model misses. The J-test
//! stays as a detail.

use serde::Serialize;

use crate::fit::GmwmFit;
use crate::inference::Inference;
use crate::variance::wv::WaveletVariance;

/// The default practical tolerance of the verdict: 10% of the empirical WV.
pub const DEFAULT_TOLERANCE: f64 = 0.10;

/// Whether the selected model explains the data.
///
/// Wire format: `explains_wv` (inside the band or within `tolerance` at every scale),
/// `tolerance`, `levels`, `scales_missed`, `worst` (the furthest missed scale, or null),
/// `scales` (one [`ScaleFit`] per scale), `j_test_p_value` (null when V had too few
/// replicates), `levels_outside_band`, `max_relative_deviation` (over the scales outside the
/// band), `summary` (one line).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitVerdict {
    /// Whether the implied WV is inside the band or within the tolerance at every scale.
    pub explains_wv: bool,
    /// The practical tolerance, relative to the empirical WV.
    pub tolerance: f64,
    /// Number of scales.
    pub levels: usize,
    /// Scales neither inside the band nor within the tolerance.
    pub(crate) scales_missed: usize,
    /// The missed scale furthest from the empirical WV, with its likely cause.
    pub worst: Option<ScaleMiss>,
    /// Every scale: the empirical and implied WV and how far apart they are.
    pub scales: Vec<ScaleFit>,
    /// p-value of the J-test (docs/methods.md §7.3), a detail.
    pub(crate) j_test_p_value: Option<f64>,
    /// Scales where the implied WV lies outside the empirical WV's `1 - alpha` interval.
    pub(crate) levels_outside_band: usize,
    /// Largest `|implied / empirical - 1|` over the scales outside the band (0 when none is).
    pub(crate) max_relative_deviation: f64,
    /// The verdict in one line.
    pub summary: String,
}

/// One scale of the verdict.
///
/// Wire format: `tau_s`, `empirical`, `implied` (WV, squared analysis unit), `deviation`
/// (`implied / empirical - 1`), `inside_band`, `explained`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScaleFit {
    /// Scale, s.
    pub tau_s: f64,
    /// Empirical WV.
    pub empirical: f64,
    /// The model's implied WV.
    pub implied: f64,
    /// `implied / empirical - 1`.
    pub deviation: f64,
    /// Whether the implied WV is inside the empirical WV's band.
    pub(crate) inside_band: bool,
    /// Inside the band or within the tolerance.
    pub explained: bool,
}

/// The worst missed scale: where, by how much, the nearest term and the likely cause.
///
/// Wire format: `tau_s`, `deviation`, `nearest_term` (the component with the largest implied
/// WV there), `cause` (one of `sensor filter`, `hump`, `floor`, `long scales`, `overshoot`),
/// `hint` (what to try, one line).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScaleMiss {
    /// Scale, s.
    pub tau_s: f64,
    /// `implied / empirical - 1` there.
    pub deviation: f64,
    /// The component that dominates the implied WV there.
    pub(crate) nearest_term: String,
    /// The likely cause, a short name.
    pub cause: &'static str,
    /// What to try, one line.
    pub hint: &'static str,
}

/// The verdict of `fit` on `wv` at `tolerance` (module doc).
pub(crate) fn verdict(
    fit: &GmwmFit,
    wv: &WaveletVariance,
    inference: &Inference,
    alpha: f64,
    tolerance: f64,
) -> FitVerdict {
    let implied = &fit.implied_wv.wv;
    let levels = implied.len().min(wv.wv.len());
    let scales: Vec<ScaleFit> = (0..levels)
        .map(|j| {
            let deviation = implied[j] / wv.wv[j] - 1.0;
            let inside_band = implied[j] >= wv.ci_low[j] && implied[j] <= wv.ci_high[j];
            ScaleFit {
                tau_s: wv.tau_s[j],
                empirical: wv.wv[j],
                implied: implied[j],
                deviation,
                inside_band,
                explained: inside_band || deviation.abs() <= tolerance,
            }
        })
        .collect();
    let outside = scales.iter().filter(|s| !s.inside_band).count();
    let max_relative_deviation = scales
        .iter()
        .filter(|s| !s.inside_band && s.deviation.is_finite())
        .map(|s| s.deviation.abs())
        .fold(0.0, f64::max);
    let missed: Vec<usize> = (0..levels).filter(|&j| !scales[j].explained).collect();
    let worst = missed
        .iter()
        .copied()
        .max_by(|&a, &b| {
            let da = scales[a].deviation.abs();
            let db = scales[b].deviation.abs();
            da.total_cmp(&db)
        })
        .map(|j| miss_at(fit, &scales, j));
    let p = inference.gof.as_ref().map(|g| g.p_value);
    let summary = summary(levels, &missed, worst.as_ref(), tolerance, alpha, p);
    FitVerdict {
        explains_wv: missed.is_empty(),
        tolerance,
        levels,
        scales_missed: missed.len(),
        worst,
        scales,
        j_test_p_value: p,
        levels_outside_band: outside,
        max_relative_deviation,
        summary,
    }
}

/// Every missed scale of `verdict` with its dominant term and likely cause, the most deviant
/// first: what refinement may add a term for.
pub(crate) fn misses(fit: &GmwmFit, verdict: &FitVerdict) -> Vec<ScaleMiss> {
    let scales = &verdict.scales;
    let mut missed: Vec<usize> = (0..scales.len())
        .filter(|&j| !scales[j].explained)
        .collect();
    missed.sort_by(|&a, &b| {
        scales[b]
            .deviation
            .abs()
            .total_cmp(&scales[a].deviation.abs())
    });
    missed
        .into_iter()
        .map(|j| miss_at(fit, scales, j))
        .collect()
}

/// The missed scale `j`: the dominant term and the likely cause, read from where the scale
/// lies and the shape of the empirical WV around it.
fn miss_at(fit: &GmwmFit, scales: &[ScaleFit], j: usize) -> ScaleMiss {
    let levels = scales.len();
    let nearest_term = fit
        .implied_wv
        .processes
        .iter()
        .filter(|c| c.wv.len() > j)
        .max_by(|a, b| a.wv[j].total_cmp(&b.wv[j]))
        .map_or_else(String::new, |c| {
            // the term's name, without its values (the estimates are in the report)
            c.process.split('(').next().unwrap_or_default().to_string()
        });
    let d = scales[j].deviation;
    // the empirical WV's excess over the model, and its slope in log-log (a white noise falls
    // as 1/tau, a flicker floor is flat, a random walk rises)
    let excess = |k: usize| scales[k].empirical / scales[k].implied;
    let (cause, hint) = if j < 2 {
        (
            "sensor filter",
            "the sensor's own filter or sampling shapes the first scales; the noise density is the one a filter integrating over longer than these scales sees",
        )
    } else if j + 2 >= levels {
        (
            "long scales",
            "the longest scales rest on a few clusters; a drift or random walk the model lacks, or a longer recording",
        )
    } else if d > 0.0 {
        (
            "overshoot",
            "the model lies above a dip of the WV; fewer correlated terms, or a periodic term (SIN())",
        )
    } else if excess(j + 2).min(excess(j + 1)) - 1.0 < 0.5 * (excess(j) - 1.0) {
        // the excess falls by half within two octaves: a localised hump
        (
            "hump",
            "a hump the model lacks (vibration, a fan, a mains term): a periodic term (SIN())",
        )
    } else {
        // the excess persists over the longer scales: a floor the model lacks
        (
            "floor",
            "the model lies below the WV over a range of scales (a bias-instability floor): a flicker term (FN())",
        )
    };
    ScaleMiss {
        tau_s: scales[j].tau_s,
        deviation: d,
        nearest_term,
        cause,
        hint,
    }
}

/// The verdict in one line.
fn summary(
    levels: usize,
    missed: &[usize],
    worst: Option<&ScaleMiss>,
    tolerance: f64,
    alpha: f64,
    p: Option<f64>,
) -> String {
    let band = format!("{:.0}% band", 100.0 * (1.0 - alpha));
    let tol = format!("{:.0}%", 100.0 * tolerance);
    let j_test = match p {
        Some(p) if p >= alpha => format!("J-test p = {p:.3}"),
        Some(p) if p > 0.0 => format!("J-test p = {p:.1e}, a detail at this length"),
        Some(_) => "J-test p < 1e-300, a detail at this length".to_string(),
        None => "no J-test: too few replicates of V".to_string(),
    };
    match worst {
        None => format!("explains the WV: within {tol} or inside the {band} at all {levels} scales ({j_test})"),
        Some(w) => format!(
            "misfit at {} of {levels} scales: {:.0}% {} the WV at {} s, where {} dominates; likely {}: {} ({j_test})",
            missed.len(),
            100.0 * w.deviation.abs(),
            if w.deviation < 0.0 { "below" } else { "above" },
            crate::fit::report::significant(w.tau_s, 3),
            if w.nearest_term.is_empty() { "no term" } else { &w.nearest_term },
            w.cause,
            w.hint,
        ),
    }
}
