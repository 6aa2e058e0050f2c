//! A sensor's datasheet beside its calibration (issue 28, item 6): the datasheet's noise
//! density N, bias instability B and random walk K read from text, compared with the measured
//! values, and drawn as the lines they imply on Allan-deviation and wavelet-variance figures.
//!
//! # Text
//! `KEY=VALUE UNIT` items separated by commas (or semicolons), e.g.
//! `"N=2 deg/sqrt(h), B=25 deg/h, N=0.2 m/s/sqrt(h), B=0.2 mg"`. Keys: `N` (white-noise
//! density: angle / velocity random walk), `B` (bias instability), `K` (rate / acceleration
//! random walk), case-insensitive. The unit's dimension says the sensor (an angle: gyroscope;
//! a length or g: accelerometer) and must be the key's ([`crate::units::datasheet_unit`]); an
//! item may start with `gyro:` or `accel:`, which is then checked against the unit. Each
//! sensor takes each key once.
//!
//! # Comparison
//! A measured value with its interval `[lo, hi]` against the datasheet value `D`: `inside`
//! when `lo <= D <= hi`, `above` when `D > hi` (the sensor is better than its datasheet),
//! `below` when `D < lo` (worse). A measured upper bound `U` (a term not detected, or B where
//! the Allan deviation shows no floor) is the interval `[0, U]`: `D > U` is `above`, else
//! `inside`. The ratio is measured / datasheet (a bound on it for an upper bound).
//!
//! # Lines
//! In the Allan deviation, each term alone (docs/methods.md §14.2, §14.3, through
//! [`crate::calib::ieee::term_avar`]): `σ(τ) = N/√τ`, `0.664 B`, `K √(τ/3)`. In the Haar wavelet
//! variance at scale `τ` (seconds), `ν²(τ) = AV(τ/2) / 2` (docs/methods.md §3.4,
//! `AV(T) = 2 WV(2T)`): `N²/τ`, `(0.664 B)²/2`, `K² τ/12`.

use crate::calib::ieee::{read_off_tau_s, term_avar};
use crate::units::{
    datasheet_examples, datasheet_unit, si_unit, DatasheetUnitError, NoiseTerm, SignalKind,
    SignalUnit,
};
use serde::Serialize;
use std::fmt;
use std::str::FromStr;

/// The keys of the datasheet text, with their terms.
const KEYS: [(&str, NoiseTerm); 3] = [
    ("N", NoiseTerm::NoiseDensity),
    ("B", NoiseTerm::BiasInstability),
    ("K", NoiseTerm::RandomWalk),
];

/// The key of a term.
fn key_of(term: NoiseTerm) -> &'static str {
    KEYS.iter()
        .find(|(_, t)| *t == term)
        .map_or("?", |(k, _)| k)
}

/// What a term is called in messages.
fn term_name(term: NoiseTerm) -> &'static str {
    match term {
        NoiseTerm::NoiseDensity => "noise density",
        NoiseTerm::BiasInstability => "bias instability",
        NoiseTerm::RandomWalk => "random walk",
        _ => "term",
    }
}

/// Why a datasheet text was refused; each names the item as given.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DatasheetError {
    /// No item at all.
    #[error("no item: give KEY=VALUE UNIT items separated by commas, e.g. \"N=2 deg/sqrt(h), B=25 deg/h\"")]
    Empty,
    /// An item without `=`.
    #[error("item {item:?}: no '=': write KEY=VALUE UNIT, e.g. N=2 deg/sqrt(h)")]
    NoEquals {
        /// The item.
        item: String,
    },
    /// A key other than N, B, K.
    #[error("item {item:?}: unknown key {key:?}: the keys are N (white-noise density), B (bias instability), K (random walk)")]
    UnknownKey {
        /// The item.
        item: String,
        /// The key given.
        key: String,
    },
    /// A prefix other than `gyro:` / `accel:`.
    #[error("item {item:?}: unknown sensor {prefix:?}: the prefixes are gyro: and accel:")]
    UnknownSensor {
        /// The item.
        item: String,
        /// The prefix given.
        prefix: String,
    },
    /// No number after `=`.
    #[error("item {item:?}: no number before the unit, e.g. {key}=2 {example}")]
    MissingNumber {
        /// The item.
        item: String,
        /// Its key.
        key: &'static str,
        /// A unit of the key.
        example: &'static str,
    },
    /// A number that is not finite and positive.
    #[error("item {item:?}: {value} is not a positive number: a noise coefficient is > 0")]
    NotPositive {
        /// The item.
        item: String,
        /// The value given.
        value: f64,
    },
    /// A number without a unit.
    #[error("item {item:?}: no unit after the number: {key} takes e.g. {examples}")]
    MissingUnit {
        /// The item.
        item: String,
        /// Its key.
        key: &'static str,
        /// Units of the key.
        examples: String,
    },
    /// A unit not understood.
    #[error("item {item:?}: unit {source}")]
    Unit {
        /// The item.
        item: String,
        /// Why.
        #[source]
        source: DatasheetUnitError,
    },
    /// A unit of another term than the key's (`N=25 deg/h`).
    #[error("item {item:?}: {unit} is a {found_name} ({found}) unit, not a {key_name} one: {key} takes {examples}")]
    WrongDimension {
        /// The item.
        item: String,
        /// The unit given.
        unit: String,
        /// The key.
        key: &'static str,
        /// What the key is.
        key_name: &'static str,
        /// The key of the unit's term.
        found: &'static str,
        /// What the unit's term is.
        found_name: &'static str,
        /// Units of the key for the unit's sensor.
        examples: &'static str,
    },
    /// A `gyro:` / `accel:` prefix that the unit contradicts.
    #[error("item {item:?}: {unit} is {kind} unit, the item says {prefix}")]
    SensorMismatch {
        /// The item.
        item: String,
        /// The unit given.
        unit: String,
        /// What the unit measures, with its article.
        kind: &'static str,
        /// The prefix.
        prefix: String,
    },
    /// A key given twice for one sensor.
    #[error("item {item:?}: the {kind} {key} is given twice")]
    Duplicate {
        /// The second item.
        item: String,
        /// The sensor.
        kind: &'static str,
        /// The key.
        key: &'static str,
    },
}

/// The sensor in words.
fn sensor(kind: SignalKind) -> &'static str {
    match kind {
        SignalKind::Gyroscope => "gyroscope",
        SignalKind::Accelerometer => "accelerometer",
    }
}

/// One datasheet value: a term of a sensor, as given and in continuous SI.
///
/// Wire format: `key` (`N`, `B`, `K`), `kind` (`gyro`, `accel`), `value` and `unit` as given,
/// `value_si` and `unit_si` (docs/methods.md §14.2).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DatasheetValue {
    /// `N`, `B` or `K`.
    pub key: &'static str,
    /// The term.
    #[serde(skip)]
    pub term: NoiseTerm,
    /// The sensor, from the unit's dimension.
    pub kind: SignalKind,
    /// The number as given.
    pub value: f64,
    /// The unit as given.
    pub unit: String,
    /// The value in continuous SI.
    pub value_si: f64,
    /// The continuous SI unit (`rad/s/√Hz`, ...).
    pub unit_si: String,
}

impl fmt::Display for DatasheetValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}={} {}", self.key, self.value, self.unit)
    }
}

/// A datasheet: N, B, K of a gyroscope and an accelerometer, each optional (module doc).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Datasheet {
    values: Vec<DatasheetValue>,
}

/// The number at the start of `text` and the rest: the longest prefix of number characters
/// that parses.
fn leading_number(text: &str) -> Option<(f64, &str)> {
    let end = text
        .char_indices()
        .find(|(_, c)| !(c.is_ascii_digit() || "+-.eE".contains(*c)))
        .map_or(text.len(), |(i, _)| i);
    (1..=end)
        .rev()
        .find_map(|k| text[..k].parse::<f64>().ok().map(|v| (v, &text[k..])))
}

impl FromStr for Datasheet {
    type Err = DatasheetError;

    /// Reads `KEY=VALUE UNIT` items (module doc).
    ///
    /// # Errors
    /// [`DatasheetError`] naming the first bad item.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let mut values: Vec<DatasheetValue> = Vec::new();
        for raw in s.split([',', ';']) {
            let item = raw.trim();
            if item.is_empty() {
                continue;
            }
            let owned = || item.to_string();
            let (head, rest) = item
                .split_once('=')
                .ok_or_else(|| DatasheetError::NoEquals { item: owned() })?;
            let (prefix, key_text) = match head.split_once(':') {
                Some((p, k)) => (Some(p.trim()), k.trim()),
                None => (None, head.trim()),
            };
            let prefix_kind = match prefix.map(str::to_ascii_lowercase).as_deref() {
                None => None,
                Some("gyro" | "gyroscope") => Some(SignalKind::Gyroscope),
                Some("accel" | "accelerometer") => Some(SignalKind::Accelerometer),
                Some(_) => {
                    return Err(DatasheetError::UnknownSensor {
                        item: owned(),
                        prefix: prefix.unwrap_or_default().to_string(),
                    })
                }
            };
            let (key, term) = KEYS
                .iter()
                .find(|(k, _)| k.eq_ignore_ascii_case(key_text))
                .copied()
                .ok_or_else(|| DatasheetError::UnknownKey {
                    item: owned(),
                    key: key_text.to_string(),
                })?;
            let example_kind = prefix_kind.unwrap_or(SignalKind::Gyroscope);
            let (value, unit_text) =
                leading_number(rest.trim()).ok_or_else(|| DatasheetError::MissingNumber {
                    item: owned(),
                    key,
                    example: datasheet_examples(term, example_kind)
                        .split(',')
                        .next()
                        .unwrap_or_default(),
                })?;
            if !(value.is_finite() && value > 0.0) {
                return Err(DatasheetError::NotPositive {
                    item: owned(),
                    value,
                });
            }
            let unit_text = unit_text.trim();
            if unit_text.is_empty() {
                return Err(DatasheetError::MissingUnit {
                    item: owned(),
                    key,
                    examples: match prefix_kind {
                        Some(k) => datasheet_examples(term, k).to_string(),
                        None => format!(
                            "{} (gyroscope) or {} (accelerometer)",
                            datasheet_examples(term, SignalKind::Gyroscope),
                            datasheet_examples(term, SignalKind::Accelerometer)
                        ),
                    },
                });
            }
            let unit = datasheet_unit(unit_text).map_err(|source| DatasheetError::Unit {
                item: owned(),
                source,
            })?;
            if unit.term != term {
                return Err(DatasheetError::WrongDimension {
                    item: owned(),
                    unit: unit_text.to_string(),
                    key,
                    key_name: term_name(term),
                    found: key_of(unit.term),
                    found_name: term_name(unit.term),
                    examples: datasheet_examples(term, unit.kind),
                });
            }
            if let Some(p) = prefix_kind.filter(|p| *p != unit.kind) {
                return Err(DatasheetError::SensorMismatch {
                    item: owned(),
                    unit: unit_text.to_string(),
                    kind: match unit.kind {
                        SignalKind::Gyroscope => "a gyroscope",
                        SignalKind::Accelerometer => "an accelerometer",
                    },
                    prefix: format!("{}:", p.name()),
                });
            }
            if values.iter().any(|v| v.kind == unit.kind && v.term == term) {
                return Err(DatasheetError::Duplicate {
                    item: owned(),
                    kind: sensor(unit.kind),
                    key,
                });
            }
            values.push(DatasheetValue {
                key,
                term,
                kind: unit.kind,
                value,
                unit: unit_text.to_string(),
                value_si: value * unit.to_si,
                unit_si: si_unit(term, Some(unit.kind), ""),
            });
        }
        if values.is_empty() {
            return Err(DatasheetError::Empty);
        }
        Ok(Datasheet { values })
    }
}

impl fmt::Display for Datasheet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let items: Vec<String> = self.values.iter().map(ToString::to_string).collect();
        f.write_str(&items.join(", "))
    }
}

/// A measured value to compare with a datasheet value, continuous SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Measured {
    /// The value (the bound itself for an upper bound).
    pub(crate) value: f64,
    /// Its interval, when it has one.
    pub(crate) interval: Option<(f64, f64)>,
    /// Whether `value` is only an upper bound (the interval `[0, value]`).
    pub(crate) upper_bound: bool,
}

/// Where the datasheet value lies against the measured interval (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum DatasheetVerdict {
    /// Inside the measured interval (for an upper bound: at or below it).
    Inside,
    /// Above the interval: the sensor is better than its datasheet.
    Above,
    /// Below the interval: the sensor is worse than its datasheet.
    Below,
    /// The measured value has no interval: no verdict.
    NoInterval,
    /// The axis has no measured value of the term.
    NotMeasured,
}

/// One datasheet value against the measured one.
///
/// Wire format: `key`, `value`, `unit` (as given), `value_si`, `unit_si`, `measured_si`,
/// `ci_low_si`, `ci_high_si` (null without interval; `ci_low_si` 0 for an upper bound),
/// `upper_bound` (the measured value is a bound), `measured` (in the datasheet's unit),
/// `ratio` (measured / datasheet), `verdict` (`inside`, `above`, `below`, `no-interval`,
/// `not-measured`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TermComparison {
    /// `N`, `B` or `K`.
    pub key: &'static str,
    /// The datasheet value as given.
    pub value: f64,
    /// Its unit as given.
    pub unit: String,
    /// The datasheet value in continuous SI.
    pub value_si: f64,
    /// The SI unit.
    pub unit_si: String,
    /// The measured value, SI.
    pub measured_si: Option<f64>,
    /// Lower end of the measured interval, SI (0 for an upper bound).
    pub ci_low_si: Option<f64>,
    /// Upper end, SI.
    pub ci_high_si: Option<f64>,
    /// Whether the measured value is only an upper bound.
    pub upper_bound: bool,
    /// The measured value in the datasheet's unit.
    pub measured: Option<f64>,
    /// Measured / datasheet.
    pub ratio: Option<f64>,
    /// Where the datasheet value lies against the measured interval.
    pub verdict: DatasheetVerdict,
}

impl TermComparison {
    /// The verdict in words, e.g. `"datasheet above the interval: better than specified"`.
    pub fn verdict_text(&self) -> &'static str {
        match (self.verdict, self.upper_bound) {
            (DatasheetVerdict::Inside, false) => "datasheet inside the interval: as specified",
            (DatasheetVerdict::Inside, true) => "datasheet within the bound: consistent",
            (DatasheetVerdict::Above, false) => {
                "datasheet above the interval: better than specified"
            }
            (DatasheetVerdict::Above, true) => "datasheet above the bound: better than specified",
            (DatasheetVerdict::Below, _) => "datasheet below the interval: worse than specified",
            (DatasheetVerdict::NoInterval, _) => "no measured interval: no verdict",
            (DatasheetVerdict::NotMeasured, _) => "not measured on this axis",
        }
    }

    /// An SI value of the term in the datasheet's unit.
    pub fn in_datasheet_unit(&self, si: f64) -> f64 {
        si * self.value / self.value_si
    }
}

/// An axis' datasheet comparison: N, B, K where the datasheet gives them for its sensor.
///
/// Wire format: `N`, `B`, `K`, each a [`TermComparison`] (absent when the datasheet has none).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DatasheetComparison {
    /// Noise density.
    #[serde(rename = "N", skip_serializing_if = "Option::is_none")]
    pub n: Option<TermComparison>,
    /// Bias instability.
    #[serde(rename = "B", skip_serializing_if = "Option::is_none")]
    pub b: Option<TermComparison>,
    /// Random walk.
    #[serde(rename = "K", skip_serializing_if = "Option::is_none")]
    pub k: Option<TermComparison>,
}

impl DatasheetComparison {
    /// The comparisons present, in the order N, B, K.
    pub fn terms(&self) -> impl Iterator<Item = &TermComparison> {
        [&self.n, &self.b, &self.k].into_iter().flatten()
    }

    /// The lines of the datasheet values on figures in SI (the calibration's unit).
    pub fn lines(&self) -> Vec<DatasheetLine> {
        self.terms()
            .filter_map(|t| {
                let term = KEYS.iter().find(|(k, _)| *k == t.key)?.1;
                Some(DatasheetLine::new(
                    t.key, term, t.value_si, t.value, &t.unit,
                ))
            })
            .collect()
    }
}

/// The comparison of one datasheet value with a measured one (module doc).
fn compare_one(v: &DatasheetValue, measured: Option<Measured>) -> TermComparison {
    let to_sheet = v.value / v.value_si;
    let d = v.value_si;
    let interval = measured.and_then(|m| {
        if m.upper_bound {
            Some((0.0, m.value))
        } else {
            m.interval
        }
    });
    let verdict = match (measured, interval) {
        (None, _) => DatasheetVerdict::NotMeasured,
        (Some(_), None) => DatasheetVerdict::NoInterval,
        (Some(_), Some((lo, hi))) => {
            if d > hi {
                DatasheetVerdict::Above
            } else if d < lo {
                DatasheetVerdict::Below
            } else {
                DatasheetVerdict::Inside
            }
        }
    };
    TermComparison {
        key: v.key,
        value: v.value,
        unit: v.unit.clone(),
        value_si: d,
        unit_si: v.unit_si.clone(),
        measured_si: measured.map(|m| m.value),
        ci_low_si: interval.map(|i| i.0),
        ci_high_si: interval.map(|i| i.1),
        upper_bound: measured.is_some_and(|m| m.upper_bound),
        measured: measured.map(|m| m.value * to_sheet),
        ratio: measured.map(|m| m.value / d),
        verdict,
    }
}

impl Datasheet {
    /// Every value, in the order given.
    pub fn values(&self) -> &[DatasheetValue] {
        &self.values
    }

    /// Whether the datasheet gives a value for the sensor.
    pub fn has(&self, kind: SignalKind) -> bool {
        self.values.iter().any(|v| v.kind == kind)
    }

    fn value(&self, kind: SignalKind, term: NoiseTerm) -> Option<&DatasheetValue> {
        self.values
            .iter()
            .find(|v| v.kind == kind && v.term == term)
    }

    /// The comparison of the `kind` values with the measured N, B, K (SI); `None` when the
    /// datasheet has no value for the sensor.
    pub(crate) fn compare(
        &self,
        kind: SignalKind,
        n: Option<Measured>,
        b: Option<Measured>,
        k: Option<Measured>,
    ) -> Option<DatasheetComparison> {
        if !self.has(kind) {
            return None;
        }
        let one = |term, m| self.value(kind, term).map(|v| compare_one(v, m));
        Some(DatasheetComparison {
            n: one(NoiseTerm::NoiseDensity, n),
            b: one(NoiseTerm::BiasInstability, b),
            k: one(NoiseTerm::RandomWalk, k),
        })
    }

    /// The error model the `kind` values state, in continuous SI at `freq_hz`, for planning a
    /// recording (docs/methods.md §18): `N` as `WN(sigma2 = N^2 f)`, `B` as flicker
    /// `FN(b2 = B^2)` (whose Allan floor is exactly `0.664 B`, IEEE 952's convention), `K` as
    /// `RW(gamma2 = K^2 / f)`; with the conversion in words. `None` without a value for the
    /// sensor.
    pub fn model_for(&self, kind: SignalKind, freq_hz: f64) -> Option<(crate::Model, String)> {
        let mut components = Vec::new();
        let mut said = Vec::new();
        for (term, text) in [
            (NoiseTerm::BiasInstability, "FN"),
            (NoiseTerm::NoiseDensity, "WN"),
            (NoiseTerm::RandomWalk, "RW"),
        ] {
            let Some(v) = self.value(kind, term) else {
                continue;
            };
            let x = v.value_si;
            let (component, conversion) = match text {
                "FN" => (format!("FN(b2={:e})", x * x), "b2 = B^2"),
                "WN" => (
                    format!("WN(sigma2={:e})", x * x * freq_hz),
                    "sigma2 = N^2 f",
                ),
                _ => (
                    format!("RW(gamma2={:e})", x * x / freq_hz),
                    "gamma2 = K^2 / f",
                ),
            };
            said.push(format!(
                "{v} = {} {}: {conversion}",
                crate::model::format_value(x),
                v.unit_si
            ));
            components.push(component);
        }
        if components.is_empty() {
            return None;
        }
        let model = components.join("+").parse().ok()?;
        Some((
            model,
            format!("datasheet at {freq_hz} Hz: {}", said.join("; ")),
        ))
    }

    /// The lines of the values of `unit`'s sensor on a figure of data in `unit`, in that unit
    /// (`value_si / unit.to_si()`: N, B and K all scale with the signal).
    pub fn lines(&self, unit: SignalUnit) -> Vec<DatasheetLine> {
        self.values
            .iter()
            .filter(|v| v.kind == unit.kind())
            .map(|v| DatasheetLine::new(v.key, v.term, v.value_si / unit.to_si(), v.value, &v.unit))
            .collect()
    }
}

/// One datasheet value as the line it implies on a figure (module doc), in the figure's unit.
#[derive(Debug, Clone, PartialEq)]
pub struct DatasheetLine {
    /// `N`, `B` or `K`.
    pub key: &'static str,
    term: NoiseTerm,
    /// The coefficient in the figure's unit (continuous time).
    pub(crate) coefficient: f64,
    /// The legend entry: `datasheet N = 2 deg/sqrt(h)`.
    pub label: String,
}

impl DatasheetLine {
    fn new(key: &'static str, term: NoiseTerm, coefficient: f64, value: f64, unit: &str) -> Self {
        Self {
            key,
            term,
            coefficient,
            label: format!("datasheet {key} = {} {unit}", shown(value)),
        }
    }

    /// The Allan deviation of the term alone at cluster time `tau_s` (module doc).
    pub fn adev(&self, tau_s: f64) -> f64 {
        term_avar(self.term, self.coefficient, tau_s).map_or(f64::NAN, f64::sqrt)
    }

    /// The Haar wavelet variance of the term alone at scale `tau_s` (seconds):
    /// `AV(τ/2) / 2` (docs/methods.md §3.4; module doc).
    pub fn wv(&self, tau_s: f64) -> f64 {
        term_avar(self.term, self.coefficient, tau_s / 2.0).map_or(f64::NAN, |av| av / 2.0)
    }

    /// The cluster time at which the datasheet value is read off the Allan deviation (1 s for
    /// N, 3 s for K); `None` for the flat B.
    pub fn at_tau_s(&self) -> Option<f64> {
        read_off_tau_s(self.term)
    }
}

/// A datasheet number as written back: up to 6 significant digits, no trailing zeros.
fn shown(v: f64) -> String {
    let s = format!("{v}");
    if s.len() <= 8 {
        s
    } else {
        format!("{v:.6e}")
    }
}
