//! IEEE Std 952 read-offs from the Allan deviation (METHODS §14.3).

use crate::error::ParamError;
use crate::variance::allan::AllanVariance;
use serde::Serialize;
use std::fmt;

/// One IEEE Std 952 coefficient read off the Allan deviation (METHODS §14.3).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Readoff {
    /// The coefficient, or `None` where its slope region holds fewer than two scales.
    pub value: Option<f64>,
    /// Lower confidence bound.
    pub ci_low: Option<f64>,
    /// Upper confidence bound.
    pub ci_high: Option<f64>,
    /// Cluster times (seconds) used.
    pub tau_s: Vec<f64>,
    /// Where the line is read, seconds: 1, √3, 3, √2, or the minimum's tau for B.
    pub at_tau_s: f64,
    /// How the value was obtained or why there is none.
    pub note: Option<String>,
}

/// The five IEEE Std 952 coefficients (METHODS §14.3), in the data unit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct IeeeReadoff {
    /// Angle / velocity random walk N (u/√Hz), −1/2 slope at 1 s.
    pub n: Readoff,
    /// Bias instability B (u), minimum / 0.664.
    pub b: Readoff,
    /// Rate random walk K (u/s/√Hz), +1/2 slope at 3 s.
    pub k: Readoff,
    /// Quantization Q (u·s), −1 slope at √3 s.
    pub q: Readoff,
    /// Rate ramp R (u/s), +1 slope at √2 s.
    pub r: Readoff,
}

impl fmt::Display for IeeeReadoff {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        todo!("{f:p}")
    }
}

/// METHODS §14.3: the IEEE Std 952 read-offs of an Allan variance.
///
/// # Errors
/// [`ParamError`] named `kind` unless `av` is an Allan variance (overlapping or not).
pub fn ieee_readoff(av: &AllanVariance) -> Result<IeeeReadoff, ParamError> {
    todo!("{}", av.n)
}
