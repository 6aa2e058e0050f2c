//! Wavelet filters and transforms (METHODS §1.1–§1.4, §1.8).
//!
//! STUB: owned by the wavelet helper; replaced wholesale.

use crate::error::{Error, ParamError};
use serde::{Deserialize, Serialize};

/// Decimated or maximal-overlap transform.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Transform {
    /// Maximal-overlap DWT (METHODS §1.2), the default.
    #[default]
    Modwt,
    /// Decimated DWT (METHODS §1.4).
    Dwt,
}

/// Published scaling filters (METHODS §1.8).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum WaveletFilter {
    /// Haar (L = 2).
    #[default]
    Haar,
}

impl WaveletFilter {
    /// Lower-case name.
    pub fn name(&self) -> &'static str {
        "haar"
    }
    /// Length.
    pub fn len(&self) -> usize {
        2
    }
}
impl std::fmt::Display for WaveletFilter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
impl std::fmt::Display for Transform {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("modwt")
    }
}
/// n_j.
pub fn modwt_boundary(filter_len: usize, j: usize) -> usize {
    ((1usize << j) - 1) * (filter_len - 1)
}
/// DWT boundary.
pub fn dwt_boundary(_filter_len: usize, _j: usize) -> usize {
    0
}

/// Wavelet coefficients of every level, boundary coefficients included.
#[derive(Debug, Clone, PartialEq)]
pub struct WaveletCoefficients {
    /// `w[j-1]` = all coefficients of level j.
    pub w: Vec<Vec<f64>>,
    /// `boundary[j-1]` = number of leading boundary coefficients to drop at level j.
    pub boundary: Vec<usize>,
}

impl WaveletCoefficients {
    /// Kept (boundary-free) coefficients of level `j` (1-based).
    pub fn kept(&self, j: usize) -> &[f64] {
        &self.w[j - 1][self.boundary[j - 1]..]
    }
}

/// MODWT plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Modwt {
    filter: WaveletFilter,
    levels: usize,
}

impl Modwt {
    /// Plans a MODWT.
    pub fn new(filter: WaveletFilter, levels: usize) -> Result<Self, ParamError> {
        Ok(Self { filter, levels })
    }
    /// Runs it.
    pub fn transform(&self, _x: &[f64]) -> Result<WaveletCoefficients, Error> {
        unimplemented!("{:?}", self)
    }
}

/// DWT plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Dwt {
    filter: WaveletFilter,
    levels: usize,
}

impl Dwt {
    /// Plans a DWT.
    pub fn new(filter: WaveletFilter, levels: usize) -> Result<Self, ParamError> {
        Ok(Self { filter, levels })
    }
    /// Runs it.
    pub fn transform(&self, _x: &[f64]) -> Result<WaveletCoefficients, Error> {
        unimplemented!("{:?}", self)
    }
}
