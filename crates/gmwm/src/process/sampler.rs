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
use serde::{Deserialize, Serialize};
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

/// How the autoregressive components (AR1, GM, ARMA11, ARMA) start.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum StartMode {
    /// Default of the port (docs/methods.md §10.1): every sample follows the stationary law. AR1
    /// and ARMA11 draw their initial state exactly from it; a generic ARMA(p, q) runs a burn-in of
    /// `p + q + ceil(ln(1e-12) / ln(rho))` samples, `rho` the largest modulus of the inverse
    /// AR roots, so the leftover transient is below `1e-12` relative.
    #[default]
    Stationary,
    /// The package (docs/methods.md §10.1, §13.21): AR1 and ARMA11 start at `x = 0` (the first kept
    /// value is `w_1`, resp. `w_1 + theta w_0`); a generic ARMA follows R's `arima.sim`
    /// (first `q` MA outputs set to 0, AR recursion from zeros, burn-in
    /// `p + q + ceil(6 / ln(min root modulus))`). The burn-in innovations come first in the
    /// component's stream (R draws them after the kept ones); the law is the same.
    Zero,
}
