//! Robust wavelet variance (METHODS §2). STUB: owned by the robust helper.

use crate::error::{Error, ParamError};
use serde::{Deserialize, Serialize};

/// Which tuning constant and solver to use (METHODS §2.3–§2.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RobustConvention {
    /// Correct efficiency formula and a root-finder from a robust start (default).
    #[default]
    Exact,
    /// The R package's constant (with its §13.5 sign slip) and its Brent solver on [0, 2].
    Package,
}

/// Options of the robust estimator.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RobustOptions {
    /// Requested Gaussian efficiency in (0, 0.99].
    pub eff: f64,
    /// Convention.
    pub convention: RobustConvention,
}

impl RobustOptions {
    /// Validated constructor.
    pub fn new(eff: f64, convention: RobustConvention) -> Result<Self, ParamError> {
        Ok(Self { eff, convention })
    }
}

/// Tuning constant c for the requested efficiency (METHODS §2.3).
pub fn tuning_constant(_eff: f64, _convention: RobustConvention) -> Result<f64, ParamError> {
    unimplemented!()
}

/// Robust variance of zero-mean coefficients `y` (METHODS §2.4), returns s^2.
pub fn robust_scale(_y: &[f64], _c: f64, _convention: RobustConvention) -> Result<f64, Error> {
    unimplemented!()
}

/// Robust CI (METHODS §2.5).
pub fn robust_ci(
    _nu_r: f64,
    _nu_c: f64,
    _lo_c: f64,
    _hi_c: f64,
    _eff: f64,
    _lowest_previous: Option<f64>,
) -> (f64, f64) {
    unimplemented!()
}

impl std::fmt::Display for RobustConvention {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("exact")
    }
}
