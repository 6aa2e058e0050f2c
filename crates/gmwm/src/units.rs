//! Units of inertial signals and of their noise terms (docs/methods.md §14.1, §14.2).
//!
//! This module owns unit parsing ([`SignalUnit`]), the SI factors, the datasheet units and
//! the continuous-to-discrete forms of each noise term ([`forms`]). The discrete-to-continuous
//! formulas of a fitted model (`N = sqrt(sigma2 / f)`, ...) live in one place,
//! [`crate::fit::GmwmFit::navigation`]; this module takes their results.
//!
//! # Continuous SI units (docs/methods.md §14.2), `u` the signal unit
//!
//! | term | gyroscope | accelerometer | data unit `u` |
//! |---|---|---|---|
//! | noise density N | rad/s/√Hz | m/s²/√Hz | u/√Hz |
//! | random walk K | rad/s²/√Hz | m/s³/√Hz | u/s/√Hz |
//! | bias instability B | rad/s | m/s² | u |
//! | quantization Q | rad | m/s | u·s |
//! | rate ramp R | rad/s² | m/s³ | u/s |
//! | GM sigma | rad/s | m/s² | u |
//! | GM correlation time | s | s | s |
//! | GM driving density | rad/s²/√Hz | m/s³/√Hz | u/s/√Hz |
//!
//! The GM driving density `sqrt(2 beta sigma2_gm)` has the unit of K (u²/s under the root), not
//! of N: it is the density of the white noise driving the bias derivative, and it tends to the
//! random-walk density K as the correlation time grows.
//!
//! # Datasheet units
//!
//! | term | gyroscope | accelerometer |
//! |---|---|---|
//! | N | °/√h (ARW) | m/s/√h (VRW) |
//! | K | °/h/√h | m/s/h/√h |
//! | B, GM sigma | °/h | mg |
//! | R | °/h² | — |
//! | GM correlation time | s | s |
//! | GM driving density | °/h/√h | m/s/h/√h |
//!
//! The accelerometer N is given as a velocity random walk in m/s/√h, the unit of IMU-module
//! datasheets (ADIS16405 and the other tactical/industrial units whose noise is characterised
//! by Allan variance); consumer accelerometer chips quote µg/√Hz instead, which
//! [`forms`] names in its `conversion` (`µg/√Hz = N / 9.80665e-6`). The accelerometer K is then
//! m/s/h/√h, the exact analogue of the gyroscope's °/h/√h (`× 3600 × 60`). Q has no common
//! datasheet unit and the accelerometer R none either: their datasheet form is `None`.

use crate::error::ParamError;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use std::fmt;
use std::str::FromStr;

/// Standard gravity `g_n` in m/s² (3rd CGPM 1901, exact): the `g` of accelerometer units.
pub(crate) const STANDARD_GRAVITY: f64 = 9.80665;

/// Seconds per hour: datasheet units are per hour or per root hour.
const SECONDS_PER_HOUR: f64 = 3600.0;
/// `sqrt(3600 s)`: one root hour in root seconds (`/√h = /√s / 60`).
const ROOT_SECONDS_PER_ROOT_HOUR: f64 = 60.0;
/// Degrees per radian.
const DEG_PER_RAD: f64 = 180.0 / PI;

/// What an inertial signal measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum SignalKind {
    /// Angular rate (serialised `"gyro"`).
    #[serde(rename = "gyro")]
    Gyroscope,
    /// Specific force (serialised `"accel"`).
    #[serde(rename = "accel")]
    Accelerometer,
}

impl SignalKind {
    /// The serde name: `"gyro"` or `"accel"`.
    pub fn name(self) -> &'static str {
        match self {
            SignalKind::Gyroscope => "gyro",
            SignalKind::Accelerometer => "accel",
        }
    }
}

impl fmt::Display for SignalKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The unit of an inertial signal's samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum SignalUnit {
    /// rad/s (SI angular rate).
    RadPerSecond,
    /// deg/s.
    DegreePerSecond,
    /// deg/h.
    DegreePerHour,
    /// m/s² (SI specific force).
    MeterPerSecond2,
    /// Standard gravity, 9.80665 m/s².
    StandardGravity,
    /// Milli-g, 9.80665e-3 m/s².
    MilliG,
}

/// What [`SignalUnit::from_str`] accepts, for its error message.
const VALID_UNITS: &str = "one of rad/s, deg/s, deg/h (gyroscope) or m/s^2, g, mg \
    (accelerometer); spellings such as rad s^-1, rad/sec, °/s, dps, °/h, dph, m/s2, m/s², \
    m s^-2 are accepted, and G / mG (gauss) are not g / mg";

impl SignalUnit {
    /// Every unit, in declaration order.
    pub const ALL: [SignalUnit; 6] = [
        SignalUnit::RadPerSecond,
        SignalUnit::DegreePerSecond,
        SignalUnit::DegreePerHour,
        SignalUnit::MeterPerSecond2,
        SignalUnit::StandardGravity,
        SignalUnit::MilliG,
    ];

    /// Whether the unit is a rate or a specific force.
    pub fn kind(self) -> SignalKind {
        match self {
            SignalUnit::RadPerSecond | SignalUnit::DegreePerSecond | SignalUnit::DegreePerHour => {
                SignalKind::Gyroscope
            }
            SignalUnit::MeterPerSecond2 | SignalUnit::StandardGravity | SignalUnit::MilliG => {
                SignalKind::Accelerometer
            }
        }
    }

    /// The SI unit of a kind: rad/s or m/s².
    pub(crate) fn si(kind: SignalKind) -> SignalUnit {
        match kind {
            SignalKind::Gyroscope => SignalUnit::RadPerSecond,
            SignalKind::Accelerometer => SignalUnit::MeterPerSecond2,
        }
    }

    /// docs/methods.md §14.2: the factor to SI, `value_si = value * to_si()` (π/180 for deg/s,
    /// π/180/3600 for deg/h, `STANDARD_GRAVITY` for g, 1e-3 of it for mg).
    pub fn to_si(self) -> f64 {
        match self {
            SignalUnit::RadPerSecond | SignalUnit::MeterPerSecond2 => 1.0,
            SignalUnit::DegreePerSecond => PI / 180.0,
            SignalUnit::DegreePerHour => PI / 180.0 / SECONDS_PER_HOUR,
            SignalUnit::StandardGravity => STANDARD_GRAVITY,
            SignalUnit::MilliG => STANDARD_GRAVITY * 1e-3,
        }
    }

    /// The ASCII symbol: `"rad/s"`, `"deg/s"`, `"deg/h"`, `"m/s^2"`, `"g"`, `"mg"`.
    pub fn symbol(self) -> &'static str {
        match self {
            SignalUnit::RadPerSecond => "rad/s",
            SignalUnit::DegreePerSecond => "deg/s",
            SignalUnit::DegreePerHour => "deg/h",
            SignalUnit::MeterPerSecond2 => "m/s^2",
            SignalUnit::StandardGravity => "g",
            SignalUnit::MilliG => "mg",
        }
    }
}

impl fmt::Display for SignalUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.symbol())
    }
}

/// Rewrites Unicode and long spellings to the ASCII forms [`match_unit`] knows. Letters keep
/// their case (metre `m` and milli `m` versus mega `M`, gravity `g` versus gauss `G`).
fn normalise(s: &str) -> String {
    let mut t = s
        .trim()
        .replace('°', "deg")
        .replace('²', "^2")
        .replace("⁻¹", "^-1")
        .replace("⁻²", "^-2")
        .replace(['·', '*'], " ");
    t = t.split_whitespace().collect::<Vec<_>>().join(" ");
    t
}

/// The unit of one normalised spelling, or `None`.
fn match_unit(t: &str) -> Option<SignalUnit> {
    // gravity units are case-sensitive: G and mG are gauss and milligauss
    match t {
        "g" | "g0" | "gn" => return Some(SignalUnit::StandardGravity),
        "mg" => return Some(SignalUnit::MilliG),
        _ => {}
    }
    let lower = t.to_ascii_lowercase();
    let mut l = lower.as_str().to_owned();
    for (from, to) in [
        ("degrees", "deg"),
        ("degree", "deg"),
        ("radians", "rad"),
        ("radian", "rad"),
        ("/second", "/s"),
        ("/sec", "/s"),
        ("/hour", "/h"),
        ("/hr", "/h"),
        (" sec^-", " s^-"),
        (" hr^-", " h^-"),
        (" s^-1", "/s"),
        (" h^-1", "/h"),
        (" s^-2", "/s^2"),
        ("/s/s", "/s^2"),
        ("/s2", "/s^2"),
    ] {
        l = l.replace(from, to);
    }
    match l.as_str() {
        "rad/s" => Some(SignalUnit::RadPerSecond),
        "deg/s" | "dps" => Some(SignalUnit::DegreePerSecond),
        "deg/h" | "dph" => Some(SignalUnit::DegreePerHour),
        // metre, not mega: the first letter keeps its case
        "m/s^2" if t.starts_with('m') => Some(SignalUnit::MeterPerSecond2),
        _ => None,
    }
}

impl FromStr for SignalUnit {
    type Err = ParamError;

    /// Parses a unit leniently but case-aware (see the module doc): `rad/s`, `rad s^-1`,
    /// `rad/sec`, `deg/s`, `°/s`, `dps`, `deg/h`, `°/h`, `dph`, `m/s^2`, `m/s2`, `m/s²`,
    /// `m s^-2`, `g`, `mg`. Text from the first `(`, `;` or `,` on is ignored, and when the whole does not
    /// parse its first word is tried, so sidecar strings such as
    /// `"deg/s (inferred: all values are multiples of 0.05 ...)"` parse.
    ///
    /// # Errors
    /// [`ParamError`] named `unit`, listing what is valid.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let head = s.split(['(', ';', ',']).next().unwrap_or_default();
        let t = normalise(head);
        let first = t.split_whitespace().next().unwrap_or_default();
        match_unit(&t)
            .or_else(|| match_unit(first))
            .ok_or_else(|| ParamError::new("unit", format!("{s:?}"), VALID_UNITS))
    }
}

/// A noise term of docs/methods.md §14.2 in its continuous-time form.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseTerm {
    /// White-noise density N (angle / velocity random walk).
    NoiseDensity,
    /// Random-walk density K (rate / acceleration random walk).
    RandomWalk,
    /// Bias instability B (IEEE flicker floor).
    BiasInstability,
    /// Quantization coefficient Q.
    Quantization,
    /// Rate ramp R.
    RateRamp,
    /// Gauss–Markov standard deviation `sqrt(sigma2_gm)`.
    GmSigma,
    /// Gauss–Markov correlation time `1 / beta`.
    GmCorrelationTime,
    /// Gauss–Markov driving-noise density `sqrt(2 beta sigma2_gm)`.
    GmDrivingDensity,
}

impl NoiseTerm {
    /// Every term, in declaration order.
    pub const ALL: [NoiseTerm; 8] = [
        NoiseTerm::NoiseDensity,
        NoiseTerm::RandomWalk,
        NoiseTerm::BiasInstability,
        NoiseTerm::Quantization,
        NoiseTerm::RateRamp,
        NoiseTerm::GmSigma,
        NoiseTerm::GmCorrelationTime,
        NoiseTerm::GmDrivingDensity,
    ];
}

/// A value with its unit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Quantity {
    /// The number.
    pub value: f64,
    /// Its unit.
    pub unit: String,
}

impl fmt::Display for Quantity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:.6e} {}", self.value, self.unit)
    }
}

/// One noise term in every form a user may need.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UnitForms {
    /// Continuous-time form, in SI (known sensor kind) or in the data unit.
    pub(crate) si: Quantity,
    /// Discrete form at the sampling rate, where one exists (docs/methods.md §14.2).
    pub discrete: Option<Quantity>,
    /// Datasheet form, where the sensor kind is known and one exists (module doc).
    pub datasheet: Option<Quantity>,
    /// The formulas used, e.g. `"discrete: sd = N × √f; datasheet °/√h: × 180/π × 60"`.
    pub conversion: String,
}

/// docs/methods.md §14.2: the continuous-time unit of a noise term: SI for a known sensor kind, in
/// terms of `data_unit` otherwise (module table; e.g. `"V/√Hz"`, `"V/s/√Hz"`).
pub fn si_unit(term: NoiseTerm, kind: Option<SignalKind>, data_unit: &str) -> String {
    let (u, per_s) = match kind {
        Some(SignalKind::Gyroscope) => ("rad/s", "rad/s²"),
        Some(SignalKind::Accelerometer) => ("m/s²", "m/s³"),
        None => ("", ""),
    };
    match (term, kind) {
        (NoiseTerm::GmCorrelationTime, _) => "s".to_string(),
        (NoiseTerm::NoiseDensity, Some(_)) => format!("{u}/√Hz"),
        (NoiseTerm::RandomWalk | NoiseTerm::GmDrivingDensity, Some(_)) => format!("{per_s}/√Hz"),
        (NoiseTerm::BiasInstability | NoiseTerm::GmSigma, Some(_)) => u.to_string(),
        (NoiseTerm::Quantization, Some(SignalKind::Gyroscope)) => "rad".to_string(),
        (NoiseTerm::Quantization, Some(SignalKind::Accelerometer)) => "m/s".to_string(),
        (NoiseTerm::RateRamp, Some(_)) => per_s.to_string(),
        (NoiseTerm::NoiseDensity, None) => format!("{data_unit}/√Hz"),
        (NoiseTerm::RandomWalk | NoiseTerm::GmDrivingDensity, None) => {
            format!("{data_unit}/s/√Hz")
        }
        (NoiseTerm::BiasInstability | NoiseTerm::GmSigma, None) => data_unit.to_string(),
        (NoiseTerm::Quantization, None) => format!("{data_unit}·s"),
        (NoiseTerm::RateRamp, None) => format!("{data_unit}/s"),
    }
}

/// A datasheet unit: `datasheet value = si value × factor`, with the unit and the factor as text.
struct Datasheet {
    factor: f64,
    unit: &'static str,
    formula: &'static str,
}

/// docs/methods.md §14.2 datasheet units (module table).
fn datasheet(term: NoiseTerm, kind: SignalKind) -> Option<Datasheet> {
    let d = |factor, unit, formula| {
        Some(Datasheet {
            factor,
            unit,
            formula,
        })
    };
    match (kind, term) {
        (_, NoiseTerm::GmCorrelationTime) => d(1.0, "s", "× 1"),
        (SignalKind::Gyroscope, NoiseTerm::NoiseDensity) => d(
            DEG_PER_RAD * ROOT_SECONDS_PER_ROOT_HOUR,
            "°/√h",
            "× 180/π × 60",
        ),
        (SignalKind::Gyroscope, NoiseTerm::RandomWalk | NoiseTerm::GmDrivingDensity) => d(
            DEG_PER_RAD * SECONDS_PER_HOUR * ROOT_SECONDS_PER_ROOT_HOUR,
            "°/h/√h",
            "× 180/π × 3600 × 60",
        ),
        (SignalKind::Gyroscope, NoiseTerm::BiasInstability | NoiseTerm::GmSigma) => {
            d(DEG_PER_RAD * SECONDS_PER_HOUR, "°/h", "× 180/π × 3600")
        }
        (SignalKind::Gyroscope, NoiseTerm::RateRamp) => d(
            DEG_PER_RAD * SECONDS_PER_HOUR * SECONDS_PER_HOUR,
            "°/h²",
            "× 180/π × 3600²",
        ),
        (SignalKind::Accelerometer, NoiseTerm::NoiseDensity) => {
            d(ROOT_SECONDS_PER_ROOT_HOUR, "m/s/√h", "× 60")
        }
        (SignalKind::Accelerometer, NoiseTerm::RandomWalk | NoiseTerm::GmDrivingDensity) => d(
            SECONDS_PER_HOUR * ROOT_SECONDS_PER_ROOT_HOUR,
            "m/s/h/√h",
            "× 3600 × 60",
        ),
        (SignalKind::Accelerometer, NoiseTerm::BiasInstability | NoiseTerm::GmSigma) => {
            d(1e3 / STANDARD_GRAVITY, "mg", "/ 9.80665e-3")
        }
        (_, NoiseTerm::Quantization) | (SignalKind::Accelerometer, NoiseTerm::RateRamp) => None,
    }
}

/// docs/methods.md §14.2: the datasheet form of a continuous SI value (units of the module doc);
/// `None` where the term has no datasheet unit (Q; the accelerometer R).
#[cfg(test)]
pub(crate) fn to_datasheet(term: NoiseTerm, kind: SignalKind, si_value: f64) -> Option<Quantity> {
    datasheet(term, kind).map(|d| Quantity {
        value: si_value * d.factor,
        unit: d.unit.to_string(),
    })
}

/// docs/methods.md §14.2: the continuous SI value of a datasheet figure (the inverse of
/// [`to_datasheet`]); `None` where the term has no datasheet unit.
#[cfg(test)]
pub(crate) fn from_datasheet(term: NoiseTerm, kind: SignalKind, value: f64) -> Option<f64> {
    datasheet(term, kind).map(|d| value / d.factor)
}

/// docs/methods.md §14.2: a continuous-time value (SI for a known `kind`, else in terms of
/// `data_unit`) with its discrete form at `freq_hz` and its datasheet form.
///
/// Discrete forms (what a discrete filter's Q matrix takes): white-noise sd per sample
/// `N √f`; bias random-walk increment sd per sample `K / √f`; quantization `√q2 = Q f`; drift
/// per sample `omega = R / f`; GM `phi = exp(-1 / (T f))`. B, the GM sigma (already a
/// per-sample sd) and the GM driving density (its discrete innovation also needs the sigma)
/// have none. A `freq_hz` that is not a positive finite number gives no discrete form.
pub(crate) fn forms(
    term: NoiseTerm,
    kind: Option<SignalKind>,
    data_unit: &str,
    si_value: f64,
    freq_hz: f64,
) -> UnitForms {
    let u = match kind {
        Some(SignalKind::Gyroscope) => "rad/s",
        Some(SignalKind::Accelerometer) => "m/s²",
        None => data_unit,
    };
    let f = freq_hz;
    let rate_ok = f.is_finite() && f > 0.0;
    let q = |value: f64, unit: String| Some(Quantity { value, unit });
    let (discrete, discrete_formula) = match term {
        _ if !rate_ok => (None, ""),
        NoiseTerm::NoiseDensity => (q(si_value * f.sqrt(), u.to_string()), "sd = N × √f"),
        NoiseTerm::RandomWalk => (
            q(si_value / f.sqrt(), format!("{u} per sample")),
            "increment sd = K / √f",
        ),
        NoiseTerm::Quantization => (q(si_value * f, u.to_string()), "√q2 = Q × f"),
        NoiseTerm::RateRamp => (q(si_value / f, format!("{u} per sample")), "omega = R / f"),
        NoiseTerm::GmCorrelationTime => (
            q((-1.0 / (si_value * f)).exp(), "1 (per sample)".to_string()),
            "phi = exp(-1 / (T f))",
        ),
        NoiseTerm::BiasInstability | NoiseTerm::GmSigma | NoiseTerm::GmDrivingDensity => (None, ""),
    };
    let sheet = kind.and_then(|k| datasheet(term, k).map(|d| (k, d)));
    let mut conversion = Vec::new();
    if !discrete_formula.is_empty() {
        conversion.push(format!("discrete: {discrete_formula}"));
    }
    if let Some((k, d)) = &sheet {
        conversion.push(format!("datasheet {}: {}", d.unit, d.formula));
        if *k == SignalKind::Accelerometer && term == NoiseTerm::NoiseDensity {
            conversion.push("or µg/√Hz: / 9.80665e-6".to_string());
        }
    }
    UnitForms {
        si: Quantity {
            value: si_value,
            unit: si_unit(term, kind, data_unit),
        },
        discrete,
        datasheet: sheet.map(|(_, d)| Quantity {
            value: si_value * d.factor,
            unit: d.unit.to_string(),
        }),
        conversion: conversion.join("; "),
    }
}

/// A datasheet unit read from text (`deg/sqrt(h)`, `ug/sqrt(Hz)`, `deg/h`, `mg`, ...): the
/// sensor and noise term its dimension says, and its factor to the continuous SI unit of the
/// module table.
///
/// The dimension decides: an angle (gyroscope) or a length (accelerometer) over time, with the
/// time exponent of the signal (rad/s, m/s²) times `√s` for a white-noise density N
/// (`°/√h = rad/s/√Hz` up to a factor), the signal itself for a bias instability B, and over
/// `√s` for a random-walk density K (`°/h/√h`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct DatasheetUnit {
    /// The sensor whose signal the unit is built on.
    pub(crate) kind: SignalKind,
    /// The noise term of the unit's dimension: noise density, bias instability or random walk.
    pub(crate) term: NoiseTerm,
    /// The factor to continuous SI: `value_si = value * to_si`.
    pub(crate) to_si: f64,
}

/// Why a datasheet unit was not understood.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DatasheetUnitError {
    /// A symbol that is not a unit (`furlong`) or an exponent that is not a number.
    #[error("{unit:?}: unknown symbol {symbol:?}; build the unit from deg, rad, m, g, mg, ug, \
             dps, dph, s, h, Hz with /, ^ and sqrt(), e.g. deg/sqrt(h), deg/h, m/s/sqrt(h), mg, ug/sqrt(Hz)")]
    Unknown {
        /// The unit as given.
        unit: String,
        /// The part not understood.
        symbol: String,
    },
    /// The unit measures neither an angle nor a length over time (`s`, `deg·m`).
    #[error(
        "{unit:?} is neither a gyroscope unit (an angle: deg, rad) nor an accelerometer \
             unit (a length or g: m, g, mg, ug)"
    )]
    NotInertial {
        /// The unit as given.
        unit: String,
    },
    /// An inertial unit whose time dimension is none of N, B, K (`deg` is a quantization,
    /// `deg/h^2` a rate ramp).
    #[error(
        "{unit:?} is a {kind} unit but not of a noise density (e.g. {n}), a bias \
             instability ({b}) or a random walk ({k})"
    )]
    NotNoiseTerm {
        /// The unit as given.
        unit: String,
        /// Its sensor.
        kind: SignalKind,
        /// An N unit of that sensor.
        n: &'static str,
        /// A B unit.
        b: &'static str,
        /// A K unit.
        k: &'static str,
    },
}

/// The datasheet units a user is shown for a term and sensor: the module table's, in ASCII.
pub(crate) fn datasheet_examples(term: NoiseTerm, kind: SignalKind) -> &'static str {
    match (kind, term) {
        (SignalKind::Gyroscope, NoiseTerm::NoiseDensity) => {
            "deg/sqrt(h), deg/s/sqrt(Hz), rad/s/sqrt(Hz)"
        }
        (SignalKind::Gyroscope, NoiseTerm::RandomWalk) => "deg/h/sqrt(h), rad/s^2/sqrt(Hz)",
        (SignalKind::Gyroscope, _) => "deg/h, deg/s, rad/s",
        (SignalKind::Accelerometer, NoiseTerm::NoiseDensity) => {
            "m/s/sqrt(h), ug/sqrt(Hz), m/s^2/sqrt(Hz)"
        }
        (SignalKind::Accelerometer, NoiseTerm::RandomWalk) => "m/s/h/sqrt(h), m/s^3/sqrt(Hz)",
        (SignalKind::Accelerometer, _) => "mg, ug, m/s^2",
    }
}

/// One symbol of a datasheet unit: exponents of angle, length and time, and its SI factor.
fn datasheet_symbol(symbol: &str) -> Option<([f64; 3], f64)> {
    let deg = PI / 180.0;
    let g = STANDARD_GRAVITY;
    let h = SECONDS_PER_HOUR;
    // gravity units are case-sensitive (G is gauss), as in `match_unit`
    Some(match symbol {
        "g" | "g0" | "gn" => ([0.0, 1.0, -2.0], g),
        "mg" => ([0.0, 1.0, -2.0], g * 1e-3),
        "ug" => ([0.0, 1.0, -2.0], g * 1e-6),
        "m" => ([0.0, 1.0, 0.0], 1.0),
        "mm" => ([0.0, 1.0, 0.0], 1e-3),
        _ => match symbol.to_ascii_lowercase().as_str() {
            "rad" => ([1.0, 0.0, 0.0], 1.0),
            "mrad" => ([1.0, 0.0, 0.0], 1e-3),
            "urad" => ([1.0, 0.0, 0.0], 1e-6),
            "deg" | "degree" | "degrees" => ([1.0, 0.0, 0.0], deg),
            "mdeg" => ([1.0, 0.0, 0.0], deg * 1e-3),
            "dps" => ([1.0, 0.0, -1.0], deg),
            "mdps" => ([1.0, 0.0, -1.0], deg * 1e-3),
            "dph" => ([1.0, 0.0, -1.0], deg / h),
            "s" | "sec" | "second" | "seconds" => ([0.0, 0.0, 1.0], 1.0),
            "min" => ([0.0, 0.0, 1.0], 60.0),
            "h" | "hr" | "hour" | "hours" => ([0.0, 0.0, 1.0], h),
            "hz" => ([0.0, 0.0, -1.0], 1.0),
            _ => return None,
        },
    })
}

/// An exponent: an integer, a decimal or a fraction `a/b`, in optional parentheses.
fn exponent(text: &str) -> Option<f64> {
    let t = text.trim().trim_start_matches('(').trim_end_matches(')');
    let v = match t.split_once('/') {
        Some((a, b)) => a.trim().parse::<f64>().ok()? / b.trim().parse::<f64>().ok()?,
        None => t.parse::<f64>().ok()?,
    };
    v.is_finite().then_some(v)
}

/// One factor of a datasheet unit (`deg`, `h^2`, `sqrt(Hz)`, `√h`, `s^(-1/2)`): its exponents
/// and SI factor.
fn datasheet_factor(factor: &str) -> Option<([f64; 3], f64)> {
    let (base, power) = if let Some(inner) = factor.strip_prefix("sqrt") {
        let inner = inner.trim();
        let inner = inner
            .strip_prefix('(')
            .and_then(|i| i.strip_suffix(')'))
            .unwrap_or(inner);
        (inner.trim(), 0.5)
    } else if let Some((b, e)) = factor.split_once('^') {
        (b.trim(), exponent(e)?)
    } else {
        (factor, 1.0)
    };
    if base.starts_with("sqrt") {
        let (dims, f) = datasheet_factor(base)?;
        return Some((dims.map(|d| d * power), f.powf(power)));
    }
    let (dims, f) = datasheet_symbol(base)?;
    Some((dims.map(|d| d * power), f.powf(power)))
}

/// docs/methods.md §14.2: reads a datasheet unit (`deg/sqrt(h)`, `°/√h`, `deg/h`, `mg`,
/// `ug/sqrt(Hz)`, `µg/√Hz`, `m/s/sqrt(h)`, `deg/h/sqrt(h)`, `rad/s/sqrt(Hz)`, `m/s^2/sqrt(Hz)`,
/// ...): factors joined by `/` (each divides) or spaces (each multiplies), each a symbol with
/// an optional exponent (`h^2`, `s^(-1/2)`) or under `sqrt()` / `√`. Symbols: deg, rad (and
/// mrad, urad, mdeg), dps, mdps, dph; m, g, mg, ug (case-sensitive: G is gauss); s, min, h, hr,
/// Hz. The dimension gives the sensor and the term ([`DatasheetUnit`]).
///
/// # Errors
/// [`DatasheetUnitError`]: an unknown symbol, a unit that is not inertial, or one of another
/// term (a quantization, a rate ramp).
pub(crate) fn datasheet_unit(text: &str) -> Result<DatasheetUnit, DatasheetUnitError> {
    let unit = text.trim().to_string();
    let t = normalise(&unit)
        .replace('√', "sqrt")
        .replace(['µ', 'μ'], "u")
        .replace(" /", "/")
        .replace("/ ", "/");
    let unknown = |symbol: &str| DatasheetUnitError::Unknown {
        unit: unit.clone(),
        symbol: symbol.to_string(),
    };
    // split at the slashes outside parentheses (an exponent may be a fraction: h^(1/2))
    let mut parts = vec![String::new()];
    let mut depth = 0i32;
    for c in t.chars() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            _ => {}
        }
        if c == '/' && depth == 0 {
            parts.push(String::new());
        } else if let Some(last) = parts.last_mut() {
            last.push(c);
        }
    }
    let mut dims = [0.0f64; 3];
    let mut to_si = 1.0f64;
    for (i, part) in parts.iter().enumerate() {
        let sign = if i == 0 { 1.0 } else { -1.0 };
        let factors: Vec<&str> = part.split_whitespace().collect();
        if factors.is_empty() {
            return Err(unknown(part));
        }
        for f in factors {
            let (d, k) = datasheet_factor(f).ok_or_else(|| unknown(f))?;
            for (a, b) in dims.iter_mut().zip(d) {
                *a += sign * b;
            }
            to_si *= k.powf(sign);
        }
    }
    let near = |a: f64, b: f64| (a - b).abs() < 1e-9;
    let kind = match (
        near(dims[0], 1.0),
        near(dims[1], 0.0),
        near(dims[0], 0.0),
        near(dims[1], 1.0),
    ) {
        (true, true, _, _) => SignalKind::Gyroscope,
        (_, _, true, true) => SignalKind::Accelerometer,
        _ => return Err(DatasheetUnitError::NotInertial { unit }),
    };
    // time exponent relative to the signal's (rad/s: -1, m/s²: -2)
    let signal = match kind {
        SignalKind::Gyroscope => -1.0,
        SignalKind::Accelerometer => -2.0,
    };
    let rel = dims[2] - signal;
    let term = if near(rel, 0.5) {
        NoiseTerm::NoiseDensity
    } else if near(rel, 0.0) {
        NoiseTerm::BiasInstability
    } else if near(rel, -0.5) {
        NoiseTerm::RandomWalk
    } else {
        return Err(DatasheetUnitError::NotNoiseTerm {
            unit,
            kind,
            n: datasheet_examples(NoiseTerm::NoiseDensity, kind),
            b: datasheet_examples(NoiseTerm::BiasInstability, kind),
            k: datasheet_examples(NoiseTerm::RandomWalk, kind),
        });
    };
    Ok(DatasheetUnit { kind, term, to_si })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_unit_parses_its_own_symbol() {
        for u in SignalUnit::ALL {
            assert_eq!(u.symbol().parse::<SignalUnit>().unwrap(), u);
            assert_eq!(SignalUnit::si(u.kind()).to_si(), 1.0);
        }
    }
}
