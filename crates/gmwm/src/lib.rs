//! # gmwm — stochastic error calibration of inertial sensors
//!
//! The engine of the gmwm platform: wavelet transforms, the wavelet variance (classical and
//! robust), Allan and Hadamard variances, IMU data readers, latent error models estimated by the
//! Generalized Method of Wavelet Moments with their inference and selection, and the
//! calibration pipeline that turns a recording into a navigation filter's parameters.
//!
//! Conventions, stated once:
//! - scales are labelled `tau_j = 2^j` samples (`2^j / freq_hz` seconds), the package label of
//!   docs/methods.md §0.1; Allan cluster lengths `m` are in samples, and `AV(m) = 2 WV(tau = 2m)`
//!   (§3.4);
//! - every variance is a variance, never a standard deviation, in the squared unit of the data;
//! - section numbers such as "§1.7" refer to the methods reference of this repository,
//!   `docs/methods.md`: the formulas, defaults and test values, section by section.
//!
//! ```
//! use gmwm::{wavelet_variance, WvOptions};
//! // ramp x_t = t + 1: Haar MODWT WV 0.25 at tau = 2, 1.0 at tau = 4 (docs/methods.md §1.10)
//! let x: Vec<f64> = (1..=8).map(f64::from).collect();
//! let wv = wavelet_variance(&x, 1.0, &WvOptions { levels: Some(2), ..WvOptions::default() }).unwrap();
//! assert!((wv.wv()[0] - 0.25).abs() < 1e-12 && (wv.wv()[1] - 1.0).abs() < 1e-12);
//! ```
#![deny(missing_docs)]

// Unit tests that exercise crate-internal kernels are written against `gmwm::` paths, like the
// integration tests they were moved from.
#[cfg(test)]
extern crate self as gmwm;

pub mod calib;
pub mod document;
pub mod error;
pub mod fit;
pub mod imu;
pub mod inference;
pub(crate) mod math;
pub mod model;
pub mod monitor;
pub mod names;
pub mod process;
pub mod progress;
pub mod selection;
pub mod shared;
pub mod sim;
pub mod units;
pub mod variance;
pub mod wavelet;

// The engine's tests against reference data, properties and Monte Carlo; they reach the
// crate-internal kernels, so they live inside the crate (the public API has its own test,
// `tests/public_api.rs`).
#[cfg(test)]
mod tests;

pub use error::{InputError, ParamError, SeriesError};
pub use fit::{FitError, Gmwm, GmwmFit, Weighting, Weights};
pub use selection::{auto_imu, ModelSelection, SelectionError, Wic};
pub use variance::allan::{allan_variance, AllanKind, AllanOptions, AllanVariance, AvConvention};
pub use variance::robust::{RobustConvention, RobustOptions};
#[cfg(test)]
pub(crate) use variance::wv::HaarWvAccumulator;
pub use variance::wv::{wavelet_variance, WaveletVariance, WvOptions};
pub use wavelet::{Transform, WaveletFilter};

/// Any error the engine can return.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Reading or parsing an input file failed.
    #[error(transparent)]
    Read(#[from] crate::imu::ReadError),
    /// A series is unusable for the requested computation.
    #[error(transparent)]
    Series(#[from] SeriesError),
    /// A parameter or option has an impossible value.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// A model text could not be parsed or breaks a model rule (docs/methods.md §0.2).
    #[error(transparent)]
    ModelParse(#[from] crate::model::ModelParseError),
    /// A model breaks a rule of docs/methods.md §0.2 or has an invalid value.
    #[error(transparent)]
    Model(#[from] crate::model::ModelError),
    /// A GMWM fit could not be set up or evaluated (docs/methods.md §5).
    #[error(transparent)]
    Fit(#[from] crate::fit::FitError),
    /// A WIC model selection could not be set up or run (docs/methods.md §8).
    #[error(transparent)]
    Selection(#[from] crate::selection::SelectionError),
    /// Calibrating a recording failed.
    #[error(transparent)]
    Calibration(#[from] crate::calib::CalibError),
    /// A navigation-stack file could not be rendered.
    #[error(transparent)]
    Export(#[from] crate::calib::export::ExportError),
}

impl From<InputError> for Error {
    fn from(e: InputError) -> Self {
        match e {
            InputError::Series(e) => Error::Series(e),
            InputError::Param(e) => Error::Param(e),
            InputError::Model(e) => Error::Model(e),
        }
    }
}
