//! Allan, modified Allan and Hadamard variances (METHODS §3). STUB: owned by the Allan helper.

use crate::error::Error;
use serde::{Deserialize, Serialize};

/// Which variance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AllanKind {
    /// Maximal-overlap Allan variance (§3.2).
    #[default]
    Overlapping,
    /// Non-overlapping Allan variance (§3.1).
    NonOverlapping,
    /// Modified Allan variance (§3.6).
    Modified,
    /// Overlapping Hadamard variance (§3.5).
    Hadamard,
    /// Non-overlapping Hadamard variance (§3.5).
    HadamardNonOverlapping,
}

/// Textbook estimators (default) or the package's (§13.8–§13.10).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AvConvention {
    /// Textbook.
    #[default]
    Textbook,
    /// R package gmwm.
    Package,
}

/// Options.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AllanOptions {
    /// Kind.
    pub kind: AllanKind,
    /// CI level.
    pub alpha: f64,
    /// Convention.
    pub convention: AvConvention,
}

impl Default for AllanOptions {
    fn default() -> Self {
        Self {
            kind: AllanKind::Overlapping,
            alpha: 0.05,
            convention: AvConvention::Textbook,
        }
    }
}

/// Result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AllanVariance {
    /// Kind.
    pub kind: AllanKind,
    /// Samples.
    pub n: usize,
    /// Rate.
    pub freq_hz: f64,
    /// CI level.
    pub alpha: f64,
    /// Cluster lengths in samples.
    pub tau: Vec<f64>,
    /// Cluster lengths in seconds.
    pub tau_s: Vec<f64>,
    /// Variance.
    pub avar: Vec<f64>,
    /// Deviation.
    pub adev: Vec<f64>,
    /// CI lower bound (variance scale).
    pub ci_low: Vec<f64>,
    /// CI upper bound (variance scale).
    pub ci_high: Vec<f64>,
}

/// Computes it.
pub fn allan_variance(_x: &[f64], _freq_hz: f64, _opts: &AllanOptions) -> Result<AllanVariance, Error> {
    unimplemented!()
}
