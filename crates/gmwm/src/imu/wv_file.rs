//! Reading a wavelet variance computed elsewhere: the JSON that `gmwm wv --json` writes, or a
//! hand-made file with the same minimal shape, so that a WV can be fitted again and again
//! without the series (the issue-4 contract of `gmwm fit`).
//!
//! Required: `series`, an array of objects with `name`, `n` (series length), `tau` (dyadic
//! scales `2, 4, 8, ...` in samples), `wv`, `ci_low`, `ci_high` (equal lengths; `null` is read
//! as a missing value). The rate is the caller's, else a top-level `freq_hz`, else the series'
//! own `freq_hz`. Optional per series: `transform`, `filter`, `alpha`, `robust`,
//! `n_coefficients`, `eta` (as `gmwm wv --json` writes them; defaults: Haar MODWT, alpha 0.05,
//! classical, counts and eta3 degrees of freedom recomputed from `n`).

use super::ReadError;
use crate::variance::ci::eta3;
use crate::variance::robust::RobustOptions;
use crate::variance::wv::{kept_count, WaveletVariance};
use crate::wavelet::{Transform, WaveletFilter};
use serde::Deserialize;
use std::path::Path;

#[derive(Deserialize)]
struct FileDoc {
    freq_hz: Option<f64>,
    series: Option<Vec<SeriesDoc>>,
}

#[derive(Deserialize)]
struct SeriesDoc {
    name: Option<String>,
    n: Option<f64>,
    freq_hz: Option<f64>,
    tau: Option<Vec<f64>>,
    wv: Option<Vec<Option<f64>>>,
    ci_low: Option<Vec<Option<f64>>>,
    ci_high: Option<Vec<Option<f64>>>,
    transform: Option<Transform>,
    filter: Option<WaveletFilter>,
    alpha: Option<f64>,
    robust: Option<RobustOptions>,
    n_coefficients: Option<Vec<usize>>,
    eta: Option<Vec<f64>>,
}

/// True when `path` looks like a WV JSON (extension `.json`), the test `gmwm fit` uses to
/// choose between a recording and a precomputed WV.
pub fn is_wv_json(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
}

/// Reads every series of a WV JSON file (see the module doc); `freq_hz` overrides the file's
/// rate. Names are returned with each WV.
///
/// # Errors
/// [`ReadError::Io`] when the file cannot be read; [`ReadError::WvJson`] naming the series
/// and field when the JSON is malformed, a required field is missing, lengths differ, `n` is
/// not a whole number >= 2, the scales are not `2, 4, 8, ...`, a scale does not fit in `n`
/// samples, or no positive finite rate is known.
pub fn read_wv_json(
    path: &Path,
    freq_hz: Option<f64>,
) -> Result<Vec<(String, WaveletVariance)>, ReadError> {
    let bad = |reason: String| ReadError::WvJson {
        path: path.to_path_buf(),
        reason,
    };
    let text = std::fs::read_to_string(path).map_err(|source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let doc: FileDoc = serde_json::from_str(&text).map_err(|e| bad(e.to_string()))?;
    let series = doc
        .series
        .ok_or_else(|| bad("no \"series\" array at the top level".into()))?;
    if series.is_empty() {
        return Err(bad("the \"series\" array is empty".into()));
    }
    let mut out = Vec::with_capacity(series.len());
    for (i, s) in series.into_iter().enumerate() {
        let name = s.name.clone().unwrap_or_default();
        let at = |what: &str| format!("series[{i}] ({name}): {what}");
        let need = |field: &'static str| bad(at(&format!("missing \"{field}\"")));
        if name.is_empty() {
            return Err(bad(format!("series[{i}]: missing \"name\"")));
        }
        let n = s.n.ok_or_else(|| need("n"))?;
        if !(n.is_finite() && n >= 2.0 && n.fract() == 0.0 && n < 9.0e15) {
            return Err(bad(at(&format!(
                "n = {n} is not a whole number of samples >= 2"
            ))));
        }
        let n = n as usize;
        let freq = freq_hz.or(doc.freq_hz).or(s.freq_hz).ok_or_else(|| {
            bad(at(
                "no sampling rate: pass --freq or add a top-level \"freq_hz\"",
            ))
        })?;
        if !(freq.is_finite() && freq > 0.0) {
            return Err(bad(at(&format!("freq_hz = {freq} is not a positive rate"))));
        }
        let tau = s.tau.ok_or_else(|| need("tau"))?;
        let num = |v: Option<Vec<Option<f64>>>, field: &'static str| {
            v.map(|v| {
                v.into_iter()
                    .map(|x| x.unwrap_or(f64::NAN))
                    .collect::<Vec<f64>>()
            })
            .ok_or_else(|| need(field))
        };
        let wv = num(s.wv, "wv")?;
        let ci_low = num(s.ci_low, "ci_low")?;
        let ci_high = num(s.ci_high, "ci_high")?;
        if tau.is_empty() {
            return Err(bad(at("\"tau\" is empty")));
        }
        for (field, len) in [
            ("wv", wv.len()),
            ("ci_low", ci_low.len()),
            ("ci_high", ci_high.len()),
        ] {
            if len != tau.len() {
                return Err(bad(at(&format!(
                    "\"{field}\" has {len} values but \"tau\" has {}",
                    tau.len()
                ))));
            }
        }
        for (k, &t) in tau.iter().enumerate() {
            let expected = 2f64.powi(k as i32 + 1);
            if t != expected {
                return Err(bad(at(&format!(
                    "tau[{k}] = {t}, expected {expected}: the fit needs the dyadic scales 2, 4, 8, ... in samples, from the first"
                ))));
            }
        }
        let transform = s.transform.unwrap_or(Transform::Modwt);
        let filter = s.filter.unwrap_or(WaveletFilter::Haar);
        let levels = tau.len();
        let mut counts = Vec::with_capacity(levels);
        for j in 1..=levels {
            let c = kept_count(n, j, transform, filter)
                .filter(|&c| c > 0)
                .ok_or_else(|| {
                    bad(at(&format!(
                        "level {j} (tau {}) does not fit in n = {n} samples",
                        tau[j - 1]
                    )))
                })?;
            counts.push(c);
        }
        let n_coefficients = match s.n_coefficients {
            Some(c) if c.len() == levels => c,
            _ => counts,
        };
        let eta = match s.eta {
            Some(e) if e.len() == levels => e,
            _ => n_coefficients
                .iter()
                .enumerate()
                .map(|(j, &m)| eta3(m, j + 1))
                .collect(),
        };
        let alpha = s.alpha.unwrap_or(0.05);
        if !(alpha.is_finite() && alpha > 0.0 && alpha < 1.0) {
            return Err(bad(at(&format!("alpha = {alpha} is not in (0, 1)"))));
        }
        out.push((
            name,
            WaveletVariance {
                n,
                freq_hz: freq,
                transform,
                filter,
                alpha,
                robust: s.robust,
                tau_s: tau.iter().map(|t| t / freq).collect(),
                tau,
                wv,
                ci_low,
                ci_high,
                n_coefficients,
                eta,
                warnings: Vec::new(),
            },
        ));
    }
    Ok(out)
}
