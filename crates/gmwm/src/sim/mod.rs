//! Seeded simulation (docs/methods.md §10).
//!
//! [`Simulator`] streams any sum of the latent [`Process`](crate::process::Process)es of
//! docs/methods.md §10.1 (each process simulates itself, next to its implied WV);
//! [`simulate_model`] and [`Simulator::for_model`] simulate a [`Model`](crate::model::Model);
//! [`DemoSensor`] is the known truth behind `gmwm demo`.
//! `bootstrap` simulates parametric-bootstrap replicates and their wavelet variances
//! (docs/methods.md §7.4).

pub(crate) mod bootstrap;
pub(crate) mod covariance;
pub(crate) mod demo;
mod model;
mod simulator;

pub use demo::DemoSensor;

#[cfg(test)]
pub(crate) use demo::{DEMO_FREQ_HZ, DEMO_MODEL};
pub use model::simulate_model;
pub(crate) use simulator::replicate_seed;
pub use simulator::Simulator;
#[cfg(test)]
pub(crate) use simulator::{quantisation_noise, simulate, StartMode};
