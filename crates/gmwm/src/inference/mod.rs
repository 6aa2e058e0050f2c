//! Inference on a GMWM fit (METHODS §7): the parametric bootstrap of the wavelet variance
//! ([`bootstrap`], §7.4), on which the bootstrap weighting (§5.2), the bootstrap covariance
//! of the estimates and the WIC optimism (§8) rest, and the J-test ([`gof`], §7.3).

pub mod bootstrap;
pub mod gof;

pub use bootstrap::{map_replicates, wv_bootstrap, WvBootstrap};
pub use gof::{j_test, JTest};
