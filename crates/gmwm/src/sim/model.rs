//! Simulating a model (docs/methods.md §10.2): the latent processes of a fully specified [`Model`]
//! (validated by their constructors, GM at the model's sampling rate, §4.3) summed by one
//! [`Simulator`].

use super::Simulator;
use crate::error::InputError;
use crate::model::Model;

impl Simulator {
    /// A streaming simulator of a fully specified model at `freq_hz` (same seed, same bits,
    /// whatever the chunking of [`Simulator::fill`]).
    ///
    /// # Errors
    /// A model that is not fully specified or has invalid values ([`Model::processes`]).
    pub fn for_model(model: &Model, freq_hz: f64, seed: u64) -> Result<Self, InputError> {
        Ok(Simulator::new(model.processes(freq_hz)?, seed)?)
    }
}

/// Simulates `n` samples of a fully specified model at `freq_hz` (docs/methods.md §10.2).
///
/// # Errors
/// As [`Simulator::for_model`]; `n` must be at least 1.
pub fn simulate_model(
    model: &Model,
    n: usize,
    freq_hz: f64,
    seed: u64,
) -> Result<Vec<f64>, InputError> {
    if n == 0 {
        return Err(crate::error::ParamError::new("n", n, "must be at least 1").into());
    }
    let mut sim = Simulator::for_model(model, freq_hz, seed)?;
    let mut x = Vec::new();
    if x.try_reserve_exact(n).is_err() {
        return Err(crate::error::ParamError::new(
            "n",
            n,
            "too many samples to hold in memory (stream with `gmwm simulate -o FILE` instead)",
        )
        .into());
    }
    x.resize(n, 0.0);
    sim.fill(&mut x);
    Ok(x)
}
