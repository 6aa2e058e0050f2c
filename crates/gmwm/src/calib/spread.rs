//! Several recordings of one sensor (docs/methods.md §19.2): the spread of N, B and K of each
//! axis across them, and a warning when the selected model or the source of K changes between
//! them — a sensor whose numbers move from one recording to the next by more than their
//! intervals, or whose random walk is a fitted term in one and a bound in another, needs a
//! longer or more controlled recording before its numbers go into a filter.

use serde::Serialize;

/// One axis of one recording, as read from its calibration document (`gmwm calibrate --json`).
#[derive(Debug, Clone, PartialEq)]
pub struct RecordedAxis {
    /// The recording's name.
    pub recording: String,
    /// The column.
    pub column: String,
    /// The canonical model.
    pub canonical_model: String,
    /// `(value, unit)` of N, B, K; B and K also when they are upper bounds (flagged).
    pub values: [Option<(f64, String, bool)>; 3],
    /// Where K comes from (`RW term`, an Allan bound, ...), with `upper bound` when it is one.
    pub random_walk_source: Option<String>,
}

impl RecordedAxis {
    /// The axes of a calibration document; empty when it has none.
    pub fn from_calibration(recording: &str, doc: &serde_json::Value) -> Vec<Self> {
        let Some(axes) = doc["axes"].as_array() else {
            return Vec::new();
        };
        axes.iter()
            .map(|a| {
                let value = |key: &str| {
                    let e = &a[key];
                    Some((
                        e["value"].as_f64()?,
                        e["unit"].as_str().unwrap_or("").to_string(),
                        e["status"].as_str() == Some("upper-bound"),
                    ))
                };
                let k = &a["random_walk"];
                Self {
                    recording: recording.to_string(),
                    column: a["column"].as_str().unwrap_or("?").to_string(),
                    canonical_model: a["canonical_model"].as_str().unwrap_or("?").to_string(),
                    values: [
                        value("noise_density"),
                        value("bias_instability"),
                        value("random_walk"),
                    ],
                    random_walk_source: k["source"].as_str().map(|s| {
                        if k["status"].as_str() == Some("upper-bound") && !s.contains("upper bound")
                        {
                            format!("upper bound ({s})")
                        } else {
                            s.to_string()
                        }
                    }),
                }
            })
            .collect()
    }
}

/// One quantity of one axis across the recordings.
///
/// Wire format: `column`, `quantity` (`N`, `B`, `K`), `unit`, `recordings` (that gave a
/// value), `bounds` (of them, upper bounds), `min`, `median`, `max`, `spread` (relative
/// standard deviation across the recordings).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpreadRow {
    /// The column.
    pub column: String,
    /// `N`, `B` or `K`.
    pub quantity: String,
    /// The unit.
    pub unit: String,
    /// Recordings with a value.
    pub recordings: usize,
    /// Of them, upper bounds.
    pub bounds: usize,
    /// Smallest value.
    pub min: f64,
    /// Median value.
    pub median: f64,
    /// Largest value.
    pub max: f64,
    /// Standard deviation over the mean.
    pub spread: f64,
}

/// The spread of N, B and K across recordings, with the warnings.
///
/// Wire format: `recordings`, `rows` ([`SpreadRow`]), `warnings`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpreadAcross {
    /// Recordings compared.
    pub recordings: usize,
    /// Per axis and quantity.
    pub rows: Vec<SpreadRow>,
    /// The model or the source of K changing between recordings, one line each.
    pub warnings: Vec<String>,
}

/// `value: recordings` groups of a per-recording text, most frequent first.
fn groups(items: &[(&str, &str)]) -> Vec<(String, Vec<String>)> {
    let mut out: Vec<(String, Vec<String>)> = Vec::new();
    for (recording, text) in items {
        match out.iter_mut().find(|(t, _)| t == text) {
            Some(g) => g.1.push(recording.to_string()),
            None => out.push((text.to_string(), vec![recording.to_string()])),
        }
    }
    out.sort_by_key(|g| std::cmp::Reverse(g.1.len()));
    out
}

fn described(groups: &[(String, Vec<String>)]) -> String {
    groups
        .iter()
        .map(|(t, r)| format!("{t} in {}", r.join(", ")))
        .collect::<Vec<_>>()
        .join("; ")
}

/// The spread across the recordings of `axes` (module doc), per column in first-seen order.
pub fn spread_across(axes: &[RecordedAxis]) -> SpreadAcross {
    let mut columns: Vec<&str> = Vec::new();
    let mut recordings: Vec<&str> = Vec::new();
    for a in axes {
        if !columns.contains(&a.column.as_str()) {
            columns.push(&a.column);
        }
        if !recordings.contains(&a.recording.as_str()) {
            recordings.push(&a.recording);
        }
    }
    let mut rows = Vec::new();
    let mut warnings = Vec::new();
    for column in columns {
        let of: Vec<&RecordedAxis> = axes.iter().filter(|a| a.column == column).collect();
        for (k, name) in ["N", "B", "K"].iter().enumerate() {
            let mut values: Vec<(f64, &str, bool)> = of
                .iter()
                .filter_map(|a| a.values[k].as_ref().map(|(v, u, b)| (*v, u.as_str(), *b)))
                .collect();
            if values.len() < 2 {
                continue;
            }
            values.sort_by(|a, b| a.0.total_cmp(&b.0));
            let n = values.len() as f64;
            let mean = values.iter().map(|v| v.0).sum::<f64>() / n;
            let sd = (values.iter().map(|v| (v.0 - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
            let median = if values.len() % 2 == 1 {
                values[values.len() / 2].0
            } else {
                0.5 * (values[values.len() / 2 - 1].0 + values[values.len() / 2].0)
            };
            rows.push(SpreadRow {
                column: column.to_string(),
                quantity: name.to_string(),
                unit: values[0].1.to_string(),
                recordings: values.len(),
                bounds: values.iter().filter(|v| v.2).count(),
                min: values[0].0,
                median,
                max: values[values.len() - 1].0,
                spread: sd / mean,
            });
        }
        let models: Vec<(&str, &str)> = of
            .iter()
            .map(|a| (a.recording.as_str(), a.canonical_model.as_str()))
            .collect();
        let model_groups = groups(&models);
        if model_groups.len() > 1 {
            warnings.push(format!(
                "{column}: the selected model changes between recordings: {}",
                described(&model_groups)
            ));
        }
        let sources: Vec<(&str, &str)> = of
            .iter()
            .map(|a| {
                (
                    a.recording.as_str(),
                    a.random_walk_source.as_deref().unwrap_or("no random walk"),
                )
            })
            .collect();
        let source_groups = groups(&sources);
        if source_groups.len() > 1 {
            warnings.push(format!(
                "{column}: K comes from different sources: {}",
                described(&source_groups)
            ));
        }
    }
    SpreadAcross {
        recordings: recordings.len(),
        rows,
        warnings,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axis(recording: &str, model: &str, n: f64, k: Option<(f64, bool)>) -> RecordedAxis {
        RecordedAxis {
            recording: recording.into(),
            column: "gyro_x".into(),
            canonical_model: model.into(),
            values: [
                Some((n, "rad/s/√Hz".into(), false)),
                None,
                k.map(|(v, b)| (v, "rad/s²/√Hz".into(), b)),
            ],
            random_walk_source: k.map(|(_, b)| {
                if b {
                    "upper bound (Allan)".to_string()
                } else {
                    "RW term".to_string()
                }
            }),
        }
    }

    #[test]
    fn spread_and_warnings() {
        let s = spread_across(&[
            axis("a", "WN()+RW()", 1.0, Some((2.0, false))),
            axis("b", "WN()+RW()", 3.0, Some((4.0, false))),
            axis("c", "AR1()+WN()", 2.0, Some((9.0, true))),
        ]);
        assert_eq!(s.recordings, 3);
        let n = &s.rows[0];
        assert_eq!(
            (n.quantity.as_str(), n.recordings, n.min, n.median, n.max),
            ("N", 3, 1.0, 2.0, 3.0)
        );
        assert!((n.spread - 0.5).abs() < 1e-12, "sd 1 over mean 2");
        let k = &s.rows[1];
        assert_eq!((k.quantity.as_str(), k.bounds), ("K", 1));
        assert_eq!(s.warnings.len(), 2, "{:?}", s.warnings);
        assert!(
            s.warnings[0].contains("WN()+RW() in a, b; AR1()+WN() in c"),
            "{}",
            s.warnings[0]
        );
        assert!(
            s.warnings[1].contains("upper bound (Allan) in c"),
            "{}",
            s.warnings[1]
        );
        // one recording: nothing to compare
        assert!(spread_across(&[axis("a", "WN()", 1.0, None)])
            .rows
            .is_empty());
    }
}
