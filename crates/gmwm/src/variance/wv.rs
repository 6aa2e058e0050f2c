//! Wavelet variance (METHODS §1.5–§1.7). IN PROGRESS (lead).

use crate::error::Error;
use crate::variance::robust::RobustOptions;
use crate::wavelet::{Transform, WaveletFilter};
use serde::{Deserialize, Serialize};

/// Options.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WvOptions {
    /// Transform.
    pub transform: Transform,
    /// Filter.
    pub filter: WaveletFilter,
    /// Levels (None: default).
    pub levels: Option<usize>,
    /// CI level.
    pub alpha: f64,
    /// Robust estimation.
    pub robust: Option<RobustOptions>,
}

impl Default for WvOptions {
    fn default() -> Self {
        Self {
            transform: Transform::Modwt,
            filter: WaveletFilter::Haar,
            levels: None,
            alpha: 0.05,
            robust: None,
        }
    }
}

/// Result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WaveletVariance {
    /// Samples.
    pub n: usize,
    /// WV.
    pub wv: Vec<f64>,
}

/// Streaming Haar accumulator.
#[derive(Debug, Clone)]
pub struct HaarWvAccumulator {}

/// Computes the WV.
pub fn wavelet_variance(_x: &[f64], _freq_hz: f64, _opts: &WvOptions) -> Result<WaveletVariance, Error> {
    unimplemented!()
}
