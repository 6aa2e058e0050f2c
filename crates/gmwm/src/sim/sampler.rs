//! The simulation state of one process (docs/methods.md §10.1), as the simulator drives it.
//!
//! A process says how it is simulated in its own module (`crate::process::*`): it implements
//! [`Step`] on a small state (its xoshiro256++ stream, its last values) and builds that state,
//! initial draws first, in [`Simulate::sampler`](crate::process::Simulate::sampler). The
//! blanket [`Sampler`] impl turns a step into a loop over a chunk, so the simulator dispatches
//! once per chunk (a virtual call), never per sample, and each loop is monomorphised with its
//! step inlined.

use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;
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

/// The generator of every simulated innovation: xoshiro256++ (Blackman and Vigna), a
/// 256-bit state, period 2^256 - 1, equidistributed in 4 dimensions and portable (the same
/// stream on every platform). Independent component streams are 2^128-step jumps apart. It
/// replaced ChaCha8, whose cryptographic strength a Monte Carlo does not need, at a third of
/// the cost per normal draw (1.5 ns against 4.5 ns on the CI machine), which is what the
/// bootstrap of V spends its time on.
pub(crate) type SimRng = Xoshiro256PlusPlus;

/// A standard normal draw.
#[inline]
pub(crate) fn normal(rng: &mut SimRng) -> f64 {
    rng.sample(StandardNormal)
}

/// A `U(0, 1)` draw.
#[inline]
pub(crate) fn uniform(rng: &mut SimRng) -> f64 {
    rng.random::<f64>()
}

/// The stream of component `index`: xoshiro256++ seeded from `seed` (through SplitMix64),
/// then jumped `index` times by 2^128 steps, so the components' streams never overlap.
pub(crate) fn stream(seed: u64, index: usize) -> SimRng {
    let mut rng = SimRng::seed_from_u64(seed);
    for _ in 0..index {
        rng.jump();
    }
    rng
}
