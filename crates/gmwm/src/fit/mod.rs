//! GMWM estimation (docs/methods.md §5): parameter transforms (§5.3), weighting matrices (§5.2),
//! the objective with its analytic gradient (§5.1, §5.4) and a Levenberg–Marquardt optimiser.
//!
//! The optimiser works on unconstrained parameters `u`; [`Parametrisation`] maps them to the
//! model's `theta` (original parametrisation, GM in `(beta, sigma2_gm)`), [`Weights`] holds the
//! diagonal of Omega, `Objective` evaluates `Q(u)` and its whitened residuals, and
//! a crate-internal Levenberg–Marquardt routine (options `LmOptions`) runs the optimiser from
//! a given start; [`Gmwm`] ties them together,
//! and [`Gmwm::fit`] runs the two-stage pipeline from generated starting values ([`start`], §6). Non-convergence is reported in
//! [`Convergence`], never hidden.

pub(crate) mod active;
pub(crate) mod augment;
pub(crate) mod auto;
pub(crate) mod canonical;
pub(crate) mod covariate;
mod estimates;
pub(crate) mod gmwm;
pub(crate) mod objective;
pub(crate) mod optimize;
pub(crate) mod pooled;
pub(crate) mod report;
pub(crate) mod revive;
pub(crate) mod start;
pub(crate) mod transform;
pub(crate) mod weights;

#[cfg(test)]
mod tests_groundwork;

pub(crate) use canonical::Reading;
pub(crate) use canonical::{CanonicalModel, CanonicalTerm, SEPARATION_LIMIT};
pub use covariate::{
    covariate_level, covariate_windows, dependences, CovariateFit, CovariateRecording, Dependence,
};
pub use estimates::FitEstimates;
pub use gmwm::{Gmwm, GmwmFit};
pub(crate) use objective::Objective;
pub(crate) use optimize::minimize;
pub(crate) use optimize::LmOptions;
pub use optimize::{Convergence, StopReason};
pub use pooled::{FitRecording, PooledFit, PooledRecording};
pub(crate) use report::Ar1GmForms;
pub use report::{NavParameter, ParameterEstimate};
#[cfg(test)]
pub(crate) use start::starting_values;
pub use start::StartInputs;
pub(crate) use start::StartOptions;

pub(crate) use transform::{Parametrisation, PhiOrder, TransformPreset};

pub use augment::Augment;
pub(crate) use transform::ParamTransform;
pub(crate) use weights::FullWeights;
pub use weights::{Weighting, Weights};

use crate::wavelet::WaveletFilter;
use thiserror::Error;

/// Why a fit could not be set up or evaluated.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum FitError {
    /// A parameter value lies outside the domain of its transform (docs/methods.md §5.3).
    #[error("parameter {index} ({name}) = {value} is outside the domain of its transform: expected {expected}")]
    OutOfDomain {
        /// 0-based index in theta.
        index: usize,
        /// Parameter label, e.g. `GM[0].beta` (component index in brackets).
        name: String,
        /// The value given.
        value: f64,
        /// The valid domain.
        expected: &'static str,
    },
    /// With ordered AR1/GM components the phis must be strictly decreasing in model order.
    #[error(
        "AR1/GM components {first} and {second} (0-based) are not in strictly decreasing phi \
         order (phi {phi_first} then {phi_second}); sort them with \
         Parametrisation::canonical_order or use PhiOrder::Free"
    )]
    PhiNotOrdered {
        /// Component index of the earlier term.
        first: usize,
        /// Component index of the later term.
        second: usize,
        /// phi of the earlier term.
        phi_first: f64,
        /// phi of the later term.
        phi_second: f64,
    },
    /// A vector has the wrong length.
    #[error("{what} has {found} values; expected {expected}")]
    Length {
        /// Which vector (e.g. "theta", "u", "weights").
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Length given.
        found: usize,
    },
    /// A level's weight cannot be formed: its CI width or variance is zero or not finite
    /// (e.g. a robust level without a scale, or the last level of a power-of-two series).
    #[error(
        "level {level}: {what} = {value} gives no usable weight (it must be finite and > 0); \
         drop this level by fitting fewer levels"
    )]
    BadWeight {
        /// 1-based level.
        level: usize,
        /// What was inverted ("CI width", "diag variance").
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// An empirical wavelet variance is missing or not finite.
    #[error("level {level}: the empirical wavelet variance {value} is not a finite number > 0; fit fewer levels")]
    BadWv {
        /// 1-based level.
        level: usize,
        /// The value.
        value: f64,
    },
    /// More parameters than levels: the model is not identified (docs/methods.md §5.7).
    #[error("the model has {params} parameters but only {levels} levels are fitted; use a smaller model or more levels")]
    TooFewLevels {
        /// Number of parameters.
        params: usize,
        /// Number of levels.
        levels: usize,
    },
    /// The implied WV cannot be evaluated at the start.
    #[error("the starting values cannot be evaluated: {0}")]
    BadStart(#[source] crate::InputError),
    /// The implied WV at the start is not finite (e.g. an enormous variance overflowed).
    #[error("level {level}: the implied wavelet variance at the start is {value}; choose a smaller start")]
    NonFiniteStart {
        /// 1-based level.
        level: usize,
        /// The implied WV there.
        value: f64,
    },
    /// The wavelet variance was computed with another filter than Haar: every implied WV of
    /// docs/methods.md §4 is the Haar WV (§1.8), so a fit, a selection or an inference on it would
    /// silently be wrong.
    #[error(
        "the wavelet variance uses the {filter} filter, but every model's implied wavelet \
         variance is the Haar one (docs/methods.md §1.8, §4): fit, select and infer on a Haar \
         wavelet variance (other filters are for display only)"
    )]
    NotHaar {
        /// The filter of the WV.
        filter: WaveletFilter,
    },
    /// Too few recordings for a multi-recording computation (docs/methods.md §5.11, §7.7).
    #[error("{found} recording(s) given; this needs at least {needed}")]
    TooFewRecordings {
        /// Needed.
        needed: usize,
        /// Given.
        found: usize,
    },
    /// A recording's sampling rate differs from the first one's by more than
    /// [`crate::imu::read::RATE_TOLERANCE`]: the model's parameters are per sample.
    #[error(
        "recording {recording} is sampled at {rate} Hz but recording 1 at {first_rate} Hz:          a pooled fit needs one rate (the model's parameters are per sample); resample or          fit them separately"
    )]
    RateMismatch {
        /// 1-based recording.
        recording: usize,
        /// Its rate.
        rate: f64,
        /// The first recording's rate.
        first_rate: f64,
    },
    /// A recording's WV uses another estimator (classical/robust, transform) than the first.
    #[error("recording {recording}: its wavelet variance uses other settings (robust, transform) than recording 1's; pool WVs of one estimator")]
    EstimatorMismatch {
        /// 1-based recording.
        recording: usize,
    },
    /// A recording has fewer levels than the model has parameters.
    #[error(
        "recording {recording} ({n} samples) has {levels} wavelet-variance levels, fewer than          the model's {params} parameters: it is too short for this model"
    )]
    RecordingTooShort {
        /// 1-based recording.
        recording: usize,
        /// Its length.
        n: usize,
        /// Its levels.
        levels: usize,
        /// Parameters (plus one for a robust WV).
        params: usize,
    },
    /// A computation the fit builds on could not run: the series, a parameter or the model is
    /// unusable.
    #[error(transparent)]
    Input(#[from] crate::InputError),
}

crate::error::input_error_from!(FitError);

/// Refuses a wavelet variance with another filter than Haar ([`FitError::NotHaar`]).
///
/// # Errors
/// [`FitError::NotHaar`].
pub(crate) fn check_haar(filter: WaveletFilter) -> Result<(), FitError> {
    if filter == WaveletFilter::Haar {
        Ok(())
    } else {
        Err(FitError::NotHaar { filter })
    }
}
