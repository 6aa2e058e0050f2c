//! The simulation state of one process (METHODS §10.1), as the simulator drives it.
//!
//! A process says how it is simulated in its own module (`crate::process::*`): it implements
//! [`Step`] on a small state (its ChaCha8 stream, its last values) and builds that state,
//! initial draws first, in [`Simulate::sampler`](crate::process::Simulate::sampler). The
//! blanket [`Sampler`] impl turns a step into a loop over a chunk, so the simulator dispatches
//! once per chunk (a virtual call), never per sample, and each loop is monomorphised with its
//! step inlined.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use std::fmt;

/// One step of a process's recursion: the next value of its path.
pub(crate) trait Step: Clone + fmt::Debug + Send + Sync + 'static {
    /// The next value (draws from the process's own stream).
    fn step(&mut self) -> f64;
}

/// A running process as the simulator sees it: chunks of values, added or stored.
pub(crate) trait Sampler: fmt::Debug + Send + Sync {
    /// Adds the next `out.len()` values to `out`.
    fn add(&mut self, out: &mut [f64]);
    /// Writes the next `out.len()` values into `out`.
    fn store(&mut self, out: &mut [f64]);
    /// A copy that continues the same stream.
    fn clone_box(&self) -> Box<dyn Sampler>;
}

impl<S: Step> Sampler for S {
    #[inline]
    fn add(&mut self, out: &mut [f64]) {
        for o in out.iter_mut() {
            *o += self.step();
        }
    }
    #[inline]
    fn store(&mut self, out: &mut [f64]) {
        for o in out.iter_mut() {
            *o = self.step();
        }
    }
    fn clone_box(&self) -> Box<dyn Sampler> {
        Box::new(self.clone())
    }
}

impl Clone for Box<dyn Sampler> {
    fn clone(&self) -> Self {
        self.clone_box()
    }
}

/// A standard normal draw.
#[inline]
pub(crate) fn normal(rng: &mut ChaCha8Rng) -> f64 {
    rng.sample(StandardNormal)
}

/// A `U(0, 1)` draw.
#[inline]
pub(crate) fn uniform(rng: &mut ChaCha8Rng) -> f64 {
    rng.random::<f64>()
}

/// The stream of component `index`: ChaCha8 keyed by the seed, stream number = index.
pub(crate) fn stream(seed: u64, index: usize) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(index as u64);
    rng
}
