//! Seeded simulation (METHODS §10).
//!
//! [`Simulator`] streams any sum of the processes of METHODS §10.1 over plain, per-sample
//! parameters ([`Generator`]); [`DemoSensor`] is the small known truth behind `gmwm demo`.

pub mod demo;
pub mod generator;

pub use demo::DemoSensor;
pub use generator::{
    ar_is_stationary, quantisation_noise, replicate_seed, simulate, Generator, Simulator, StartMode,
};
