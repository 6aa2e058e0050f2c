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

use super::allan::{package_error, AllanKind, AllanVariance, AvConvention};
use super::ci::eta3;
use super::robust::RobustOptions;
use super::wv::{kept_count, WaveletVariance};
use crate::error::ParamError;
use crate::imu::read::{sniff, ColumnSelector, Content};
use crate::imu::{escape_name, quote, ReadError};
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

/// True when `path` looks like a WV JSON: extension `.json`, or content that is a JSON object
/// (`sniff`: first non-blank character `{`), whatever the name; the test the CLI uses to
/// choose between a recording and a precomputed WV. A file that cannot be read is not one (the
/// reader then reports why).
pub fn is_wv_json(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
        || matches!(sniff(path), Ok(Content::Json))
}

/// The series of a WV JSON picked by name or 1-based index, in the order given (all of them
/// when `selectors` is empty).
///
/// # Errors
/// [`ReadError::UnknownSeries`] for a name the file does not have,
/// [`ReadError::SeriesOutOfRange`] for an index outside `1..=series.len()`.
pub fn select_series(
    path: &Path,
    series: Vec<(String, WaveletVariance)>,
    selectors: &[ColumnSelector],
) -> Result<Vec<(String, WaveletVariance)>, ReadError> {
    if selectors.is_empty() {
        return Ok(series);
    }
    let names: Vec<String> = series.iter().map(|(n, _)| n.clone()).collect();
    selectors
        .iter()
        .map(|sel| {
            let k = match sel {
                ColumnSelector::Index(i) if (1..=series.len()).contains(i) => i - 1,
                ColumnSelector::Index(i) => {
                    return Err(ReadError::SeriesOutOfRange {
                        path: path.to_path_buf(),
                        index: *i,
                        count: series.len(),
                    })
                }
                ColumnSelector::Name(n) => {
                    names
                        .iter()
                        .position(|m| m == n)
                        .ok_or_else(|| ReadError::UnknownSeries {
                            path: path.to_path_buf(),
                            name: n.clone(),
                            available: names.clone(),
                        })?
                }
            };
            Ok(series[k].clone())
        })
        .collect()
}

/// docs/methods.md §3.4, the overlapping Allan variance from the classical Haar MODWT WV:
/// `AV(m) = 2 nu2(tau = 2m)` at cluster lengths `m = tau / 2`, exact for the estimators over
/// the same index set (the textbook overlapping AV of
/// [`allan_variance`](crate::allan_variance) with every `N - 2m + 1` term); the interval is the
/// WV's chi-square interval times 2 and the edf its eta3 (as `allan_variance` computes them),
/// `terms` the WV's coefficient counts, `error` the package's `1 / sqrt(2 (N/m - 1))`.
///
/// # Errors
/// [`ParamError`] `wavelet variance` for a robust, non-Haar or DWT wavelet variance, for which
/// the identity does not hold.
pub fn allan_from_wv(wv: &WaveletVariance) -> Result<AllanVariance, ParamError> {
    let what = if wv.robust.is_some() {
        Some("robust".to_string())
    } else if wv.filter != WaveletFilter::Haar {
        Some(format!("filter {:?}", wv.filter).to_lowercase())
    } else if wv.transform != Transform::Modwt {
        Some(format!("transform {:?}", wv.transform).to_lowercase())
    } else {
        None
    };
    if let Some(what) = what {
        return Err(ParamError::new(
            "wavelet variance",
            what,
            "the classical Haar MODWT one, which gives the Allan variance by AV(m) = 2 WV(2m) \
             (docs/methods.md §3.4)",
        ));
    }
    let tau: Vec<f64> = wv.tau.iter().map(|t| t / 2.0).collect();
    let avar: Vec<f64> = wv.wv.iter().map(|v| 2.0 * v).collect();
    Ok(AllanVariance {
        kind: AllanKind::Overlapping,
        convention: AvConvention::Textbook,
        n: wv.n,
        freq_hz: wv.freq_hz,
        alpha: wv.alpha,
        tau_s: tau.iter().map(|m| m / wv.freq_hz).collect(),
        adev: avar.iter().map(|v| v.sqrt()).collect(),
        ci_low: wv.ci_low.iter().map(|v| 2.0 * v).collect(),
        ci_high: wv.ci_high.iter().map(|v| 2.0 * v).collect(),
        adev_ci_low: wv.ci_low.iter().map(|v| (2.0 * v).sqrt()).collect(),
        adev_ci_high: wv.ci_high.iter().map(|v| (2.0 * v).sqrt()).collect(),
        edf: wv.eta.clone(),
        terms: wv.n_coefficients.clone(),
        error: tau
            .iter()
            .map(|&m| package_error(wv.n, m as usize))
            .collect(),
        tau,
        avar,
    })
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
    let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
        // serde may quote the file's text unescaped: escaped to one line
        bad(format!("not valid JSON: {}", escape_name(&e.to_string())))
    })?;
    if !value.is_object() {
        return Err(bad(format!(
            "the document is {}, not an object with a \"series\" array as `gmwm wv --json` \
             writes (a recording is CSV/TSV text or raw binary, not JSON)",
            json_kind(&value)
        )));
    }
    let doc: FileDoc =
        serde_json::from_value(value).map_err(|e| bad(escape_name(&e.to_string())))?;
    let series = doc
        .series
        .ok_or_else(|| bad("no \"series\" array at the top level".into()))?;
    if series.is_empty() {
        return Err(bad("the \"series\" array is empty".into()));
    }
    let mut out = Vec::with_capacity(series.len());
    for (i, s) in series.into_iter().enumerate() {
        let name = s.name.clone().unwrap_or_default();
        let at = |what: &str| format!("series[{i}] ({}): {what}", quote(&name));
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

/// What a JSON value is, for a message: `an array`, `a string`, ...
fn json_kind(v: &serde_json::Value) -> &'static str {
    match v {
        serde_json::Value::Null => "null",
        serde_json::Value::Bool(_) => "a boolean",
        serde_json::Value::Number(_) => "a number",
        serde_json::Value::String(_) => "a string",
        serde_json::Value::Array(a) if a.is_empty() => "an empty array",
        serde_json::Value::Array(_) => "an array",
        serde_json::Value::Object(_) => "an object",
    }
}
