//! Seeded simulation (METHODS §10).
//!
//! [`Simulator`] streams any sum of the processes of METHODS §10.1 over plain, per-sample
//! parameters ([`Generator`]); [`simulate_model`] and [`Simulator::for_model`] simulate a [`Model`](crate::model::Model);
//! [`DemoSensor`] is the known truth behind `gmwm demo`.
//! [`bootstrap`] simulates parametric-bootstrap replicates and their wavelet variances (METHODS §7.4).

pub mod bootstrap;
pub mod demo;
pub mod generator;
pub mod model;

pub use demo::{DemoSensor, DEMO_FREQ_HZ, DEMO_MODEL};
pub use generator::{
    ar_is_stationary, quantisation_noise, replicate_seed, simulate, Generator, Simulator, StartMode,
};
pub use model::simulate_model;
