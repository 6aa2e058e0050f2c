//! The JSON documents of the front ends: what `gmwm wv|avar|fit|select|calibrate --json`
//! print and what the Python package's `to_dict()` returns, built in one place so that the two
//! agree field for field.

use crate::augmented::AugmentedFit;
use crate::calib::{CalibrationReport, NavSet};
use crate::fit::{
    Ar1GmForms, CanonicalModel, CanonicalTerm, NavParameter, ParameterEstimate, Reading,
};
use crate::imu::SampleAccount;
use crate::inference::{Inference, JTest, VSource};
use crate::selection::{SelectionRow, SelectionRule};
use crate::{GmwmFit, ModelSelection};
use serde::Serialize;
use serde_json::Value;

/// A result tagged with the series (column) it belongs to; JSON flattens the result into it.
#[derive(Serialize)]
struct Named<'a, T> {
    name: &'a str,
    #[serde(flatten)]
    result: &'a T,
}

fn to_value<T: Serialize>(doc: &T) -> Value {
    // every document is plain data (numbers, strings, arrays): serialisation cannot fail;
    // non-finite numbers become null as in the CLI's JSON
    serde_json::to_value(doc).unwrap_or(Value::Null)
}

/// `{"series": [{"name": ..., <result fields>}, ...]}`: the document of `gmwm wv --json` and
/// `gmwm avar --json` (one entry per column).
pub fn series<T: Serialize>(items: &[(String, T)]) -> Value {
    #[derive(Serialize)]
    struct Doc<'a, T> {
        series: Vec<Named<'a, T>>,
    }
    to_value(&Doc {
        series: items
            .iter()
            .map(|(name, result)| Named { name, result })
            .collect(),
    })
}

/// A reading of a canonical model with its sentence.
#[derive(Serialize)]
struct CanonicalNote<'a> {
    #[serde(flatten)]
    reading: &'a Reading,
    message: String,
}

fn canonical_notes(canonical: &CanonicalModel) -> Vec<CanonicalNote<'_>> {
    canonical
        .readings
        .iter()
        .map(|reading| CanonicalNote {
            reading,
            message: reading.to_string(),
        })
        .collect()
}

/// One parameter: the estimate, plus its inference when asked.
#[derive(Serialize)]
struct ParameterReport {
    #[serde(flatten)]
    estimate: ParameterEstimate,
    #[serde(flatten)]
    inference: Option<ParameterInterval>,
}

#[derive(Serialize)]
struct ParameterInterval {
    se: Option<f64>,
    ci_low: Option<f64>,
    ci_high: Option<f64>,
}

#[derive(Serialize)]
struct FitReport<'a> {
    column: &'a str,
    model: String,
    objective: f64,
    converged: bool,
    parameters: Vec<ParameterReport>,
    #[serde(skip_serializing_if = "Option::is_none")]
    gof: Option<Option<JTest>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    inference: Option<&'a Inference>,
    ar1_gm: Vec<Ar1GmForms>,
    navigation: Vec<NavParameter>,
    canonical_model: String,
    reduced_model: String,
    canonical: &'a [CanonicalTerm],
    canonical_notes: Vec<CanonicalNote<'a>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    augmented: Option<&'a AugmentedFit>,
    fit: &'a GmwmFit,
}

/// One column's fit for [`fits`]: its name, the fit, its canonical reading and, when asked,
/// its inference.
pub struct FitItem<'a> {
    /// Column name.
    pub column: &'a str,
    /// The fit.
    pub fit: &'a GmwmFit,
    /// Its canonical model ([`GmwmFit::canonical`]).
    pub canonical: &'a CanonicalModel,
    /// Its inference, when asked.
    pub inference: Option<&'a Inference>,
    /// Its GMWM+ fit, when asked (`--augment`).
    pub augmented: Option<&'a AugmentedFit>,
}

/// `{"fits": [...]}`: the document of `gmwm fit --json`. Per column: `column`, `model`,
/// `objective`, `converged`, `parameters` (`{process, index, name, value, start[, se, ci_low,
/// ci_high]}`), `gof` and `inference` (with inference), `ar1_gm`, `navigation`,
/// `canonical_model`, `reduced_model`, `canonical`, `canonical_notes`, `augmented` (with
/// `--augment`: [`AugmentedFit`]'s wire format), `fit`.
pub fn fits(items: &[FitItem<'_>]) -> Value {
    #[derive(Serialize)]
    struct Doc<'a> {
        fits: Vec<FitReport<'a>>,
    }
    let fits = items
        .iter()
        .map(|it| {
            let fit = it.fit;
            FitReport {
                column: it.column,
                model: fit.model.to_string(),
                objective: fit.objective,
                converged: fit.convergence.converged,
                parameters: fit
                    .parameters()
                    .into_iter()
                    .enumerate()
                    .map(|(k, estimate)| ParameterReport {
                        estimate,
                        inference: it.inference.map(|i| {
                            let p = &i.parameters[k];
                            ParameterInterval {
                                se: p.se,
                                ci_low: p.ci_low,
                                ci_high: p.ci_high,
                            }
                        }),
                    })
                    .collect(),
                gof: it.inference.map(|i| i.gof.clone()),
                inference: it.inference,
                ar1_gm: fit.ar1_gm_forms(),
                navigation: fit.navigation(None),
                canonical_model: it.canonical.model.to_string(),
                reduced_model: it.canonical.reduced.to_string(),
                canonical: &it.canonical.terms,
                canonical_notes: canonical_notes(it.canonical),
                augmented: it.augmented,
                fit,
            }
        })
        .collect();
    to_value(&Doc { fits })
}

#[derive(Serialize)]
struct CandidateRow {
    model: String,
    canonical_model: String,
    objective: f64,
    optimism: f64,
    wic: f64,
    gof_p_value: Option<f64>,
    gof_p_value_upper_bound: bool,
}

#[derive(Serialize)]
struct SelectionReport<'a> {
    column: &'a str,
    selected: String,
    selected_canonical: String,
    canonical: &'a [CanonicalTerm],
    canonical_notes: Vec<CanonicalNote<'a>>,
    reason: String,
    rule: SelectionRule,
    #[serde(flatten)]
    v_source: VSource,
    rows: &'a [SelectionRow],
    candidates: Vec<CandidateRow>,
}

/// `{"selections": [...]}`: the document of `gmwm select --json`. Per column: `column`,
/// `selected`, `selected_canonical`, `canonical`, `canonical_notes`, `reason`, `rule`,
/// `v_method` (`exact` or `bootstrap`: how V was obtained), `v_replicates` (null when exact),
/// `rows` (one per canonical model, by WIC) and `candidates` (every candidate, by WIC).
pub fn selections(items: &[(String, ModelSelection)]) -> Value {
    #[derive(Serialize)]
    struct Doc<'a> {
        selections: Vec<SelectionReport<'a>>,
    }
    let selections = items
        .iter()
        .map(|(column, s)| SelectionReport {
            column,
            selected: s.selected.to_string(),
            selected_canonical: s.selected_canonical.model.to_string(),
            canonical: &s.selected_canonical.terms,
            canonical_notes: canonical_notes(&s.selected_canonical),
            reason: s.reason(),
            rule: s.rule,
            v_source: s.v_source,
            rows: &s.rows,
            candidates: s
                .candidates
                .iter()
                .map(|c| CandidateRow {
                    model: c.model.to_string(),
                    canonical_model: c.canonical_model.to_string(),
                    objective: c.objective,
                    optimism: c.optimism,
                    wic: c.wic,
                    gof_p_value: c.gof_p_value,
                    gof_p_value_upper_bound: c.gof_p_value_upper_bound,
                })
                .collect(),
        })
        .collect();
    to_value(&Doc { selections })
}

/// The document of `gmwm calibrate --json`: `file`, `notes` (what the reader noticed), `rows`
/// (the reader's [`SampleAccount`], when the samples came from a file), the
/// [`CalibrationReport`]'s fields, and `exported` (the navigation sets as written).
pub fn calibration(
    file: &std::path::Path,
    notes: &[String],
    rows: Option<&SampleAccount>,
    report: &CalibrationReport,
    exported: &[NavSet],
) -> Value {
    #[derive(Serialize)]
    struct Doc<'a> {
        file: &'a std::path::Path,
        notes: &'a [String],
        #[serde(skip_serializing_if = "Option::is_none")]
        rows: Option<&'a SampleAccount>,
        #[serde(flatten)]
        calibration: &'a CalibrationReport,
        exported: &'a [NavSet],
    }
    to_value(&Doc {
        file,
        notes,
        rows,
        calibration: report,
        exported,
    })
}
