//! Units of inertial signals and of their noise terms (METHODS §14.1, §14.2).
//!
//! This module owns unit parsing, SI factors, datasheet units and the continuous-to-discrete
//! forms; the discrete-to-continuous formulas of a fitted model live in
//! [`crate::fit::GmwmFit::navigation`].

use crate::error::ParamError;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Standard gravity `g_n` in m/s² (CGPM 1901, exact): the `g` of accelerometer units.
pub const STANDARD_GRAVITY: f64 = 9.80665;

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

impl SignalUnit {
    /// Whether the unit is a rate or a specific force.
    pub fn kind(self) -> SignalKind {
        todo!()
    }

    /// The SI unit of a kind: rad/s or m/s².
    pub fn si(kind: SignalKind) -> SignalUnit {
        todo!("{kind:?}")
    }

    /// The factor to SI: `value_si = value * to_si()`.
    pub fn to_si(self) -> f64 {
        todo!()
    }

    /// The ASCII symbol: `"rad/s"`, `"deg/s"`, `"deg/h"`, `"m/s^2"`, `"g"`, `"mg"`.
    pub fn symbol(self) -> &'static str {
        todo!()
    }
}

impl fmt::Display for SignalUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.symbol())
    }
}

impl FromStr for SignalUnit {
    type Err = ParamError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        todo!("{s}")
    }
}

/// A noise term of METHODS §14.2 in its continuous-time form.
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

/// A value with its unit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Quantity {
    /// The number.
    pub value: f64,
    /// Its unit.
    pub unit: String,
}

/// One noise term in every form a user may need.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UnitForms {
    /// Continuous-time SI (or data-unit) form.
    pub si: Quantity,
    /// Discrete form at the sampling rate, where one exists.
    pub discrete: Option<Quantity>,
    /// Datasheet form, where the sensor kind is known and one exists.
    pub datasheet: Option<Quantity>,
    /// The formulas used, e.g. `"°/√h = N × 180/π × 60"`.
    pub conversion: String,
}

/// METHODS §14.2: the continuous-time unit of a noise term.
pub fn si_unit(term: NoiseTerm, kind: Option<SignalKind>, data_unit: &str) -> String {
    todo!("{term:?} {kind:?} {data_unit}")
}

/// METHODS §14.2: a continuous-time value with its discrete and datasheet forms.
pub fn forms(
    term: NoiseTerm,
    kind: Option<SignalKind>,
    data_unit: &str,
    si_value: f64,
    freq_hz: f64,
) -> UnitForms {
    todo!("{term:?} {kind:?} {data_unit} {si_value} {freq_hz}")
}

/// METHODS §14.2: the datasheet form of a continuous SI value.
pub fn to_datasheet(term: NoiseTerm, kind: SignalKind, si_value: f64) -> Option<Quantity> {
    todo!("{term:?} {kind:?} {si_value}")
}

/// METHODS §14.2: the continuous SI value of a datasheet figure.
pub fn from_datasheet(term: NoiseTerm, kind: SignalKind, value: f64) -> Option<f64> {
    todo!("{term:?} {kind:?} {value}")
}
