//! Inference on a GMWM fit (docs/methods.md §7): the parametric bootstrap of the wavelet variance
//! and of the fit (`bootstrap`, §7.4), and the covariance V of the WV, exact or bootstrapped
//! (`wv_covariance`, in `sim`), on which the bootstrap weighting (§5.2), the bootstrap
//! covariance of the estimates and the WIC optimism (§8) rest; the sandwich covariance and
//! intervals ([`asymptotic`], §7.1, §7.2, §7.6); the J-test ([`gof`], §7.3); and one entry
//! point, [`infer`] (`summary`, §7.5).

pub(crate) mod asymptotic;
pub(crate) mod bootstrap;
pub(crate) mod covariate;
pub(crate) mod gof;
mod pooled;
pub(crate) mod same_model;
pub(crate) mod summary;

pub(crate) use crate::progress::Progress;

pub(crate) use crate::progress::NoProgress;
pub use crate::sim::covariance::CovarianceMethod;
pub(crate) use crate::sim::covariance::VSource;
#[cfg(test)]
pub(crate) use asymptotic::z_value;
#[cfg(test)]
pub(crate) use asymptotic::{sandwich, wald_interval};
pub use asymptotic::{IntervalScale, ZConvention};
#[cfg(test)]
pub(crate) use bootstrap::wv_bootstrap;
pub use covariate::{CoefficientInference, CovariateInference, DependenceTest};
pub use gof::JTest;
pub use same_model::WvComparison;
pub(crate) use summary::infer_with_covariance;
pub use summary::{
    infer, infer_with_progress, BootstrapGof, Inference, InferenceMethod, InferenceOptions,
    InferenceWarning, ParameterInference, VShape,
};
