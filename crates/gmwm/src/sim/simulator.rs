//! Streaming, seeded simulation of a sum of independent processes (docs/methods.md §10.1–§10.2).
//!
//! A [`Simulator`] holds one small state per component (the last `p` values and `q`
//! innovations of an ARMA, the last uniform of QN, the level of RW, the time of DR), built by
//! the component's [`Process`] (each process says how it is simulated, next to its implied
//! WV), and one xoshiro256++ stream per component, derived from `(seed, component index)`. Because
//! no stream is shared, the output depends only on the seed and the sample index: splitting
//! `n` samples across any number of [`Simulator::fill`] calls gives the same bits, and so does
//! drawing the components separately with [`Simulator::fill_components`] and adding them in
//! model order.
//!
//! The processes are those of [`crate::process`], validated by their constructors; GM is
//! simulated as its exact AR1 at its sampling rate (docs/methods.md §4.3). Random streams cannot
//! match R's Mersenne Twister, so only the laws match the package (docs/methods.md §12).

use crate::error::ParamError;
#[cfg(test)]
use crate::process::qn::qn_value;
use crate::process::sampler::{stream, Sampler};
use crate::process::Process;
pub(crate) use crate::process::StartMode;

/// A streaming simulator of a sum of independent [`Process`]es (docs/methods.md §10.2,
/// `gen_model`).
///
/// Same seed, same bits, whatever the chunking of [`fill`](Self::fill) calls. `Send + Sync +
/// Clone`; a clone continues the same streams.
#[derive(Debug, Clone)]
pub struct Simulator {
    processes: Vec<Process>,
    #[cfg(test)]
    seed: u64,
    start: StartMode,
    samplers: Vec<Box<dyn Sampler>>,
}

impl Simulator {
    /// Prepares one stream per component, in [`StartMode::Stationary`]. The processes are
    /// valid: their constructors checked them and their fields are private.
    ///
    /// Cost: O(p^3) root finding per generic ARMA plus its burn-in (O(n0 (p + q))); O(1)
    /// otherwise.
    ///
    /// # Errors
    /// [`ParamError`] for an empty list, or a generic ARMA whose burn-in would exceed 10^8
    /// samples (AR root too close to the unit circle).
    pub fn new(processes: Vec<Process>, seed: u64) -> Result<Self, ParamError> {
        if processes.is_empty() {
            return Err(ParamError::new(
                "processes",
                "[]",
                "at least one process to simulate",
            ));
        }
        let start = StartMode::default();
        let samplers = build(&processes, seed, start)?;
        Ok(Self {
            processes,
            #[cfg(test)]
            seed,
            start,
            samplers,
        })
    }

    /// Chooses how AR parts start (docs/methods.md §10.1, §13.21) and restarts the simulation from
    /// its first sample (same seed). Cost: the burn-ins of generic ARMA components again.
    #[cfg(test)]
    pub(crate) fn with_start(mut self, mode: StartMode) -> Self {
        self.start = mode;
        // Validation and burn-in lengths do not depend on the mode beyond what `new` checked:
        // the R burn-in is shorter than the stationary one, so it cannot fail where that
        // succeeded.
        if let Ok(samplers) = build(&self.processes, self.seed, mode) {
            self.samplers = samplers;
        }
        self
    }

    /// The processes, in model order.
    pub fn processes(&self) -> &[Process] {
        &self.processes
    }

    /// The start mode in use.
    pub fn start(&self) -> StartMode {
        self.start
    }

    /// Writes the next `out.len()` samples of the sum of the components, added in model order.
    ///
    /// Cost: O(len (1 + p + q)) per call, no allocation.
    pub fn fill(&mut self, out: &mut [f64]) {
        // Blocks keep the running sum in cache while every component adds to it; the bits do
        // not depend on the block size (each component's stream is its own).
        for block in out.chunks_mut(FILL_BLOCK) {
            block.fill(0.0);
            for s in &mut self.samplers {
                s.add(block);
            }
        }
    }

    /// Writes the next samples of each component separately (docs/methods.md §10.2, `gen_lts`):
    /// `out[k]` receives the next `out[k].len()` values of component `k`. Adding the columns
    /// in model order reproduces [`fill`](Self::fill) bit for bit.
    ///
    /// # Errors
    /// [`ParamError`] when `out` has not one column per component or the columns differ in
    /// length (nothing is drawn then).
    pub fn fill_components(&mut self, out: &mut [Vec<f64>]) -> Result<(), ParamError> {
        if out.len() != self.samplers.len() {
            return Err(ParamError::new(
                "columns",
                out.len(),
                format!("one column per component ({})", self.samplers.len()),
            ));
        }
        let len = out.first().map_or(0, Vec::len);
        if let Some(bad) = out.iter().find(|c| c.len() != len) {
            return Err(ParamError::new(
                "column length",
                bad.len(),
                format!("every column as long as the first ({len})"),
            ));
        }
        for (s, col) in self.samplers.iter_mut().zip(out.iter_mut()) {
            s.store(col);
        }
        Ok(())
    }
}

/// Simulates `n` samples of the sum of `processes` from the stationary start (docs/methods.md
/// §10.2).
///
/// # Errors
/// As [`Simulator::new`], and for `n == 0`.
///
/// # Examples
/// ```
/// use gmwm::Dr;
/// use gmwm::sim::simulate;
/// let x = simulate(&[Dr::new(2.0).unwrap().into()], 4, 1).unwrap();
/// assert_eq!(x, vec![2.0, 4.0, 6.0, 8.0]); // docs/methods.md §10.3 test value
/// ```
#[cfg(test)]
pub(crate) fn simulate(processes: &[Process], n: usize, seed: u64) -> Result<Vec<f64>, ParamError> {
    if n == 0 {
        return Err(ParamError::new("n", n, "must be at least 1"));
    }
    let mut sim = Simulator::new(processes.to_vec(), seed)?;
    let mut x = vec![0.0; n];
    sim.fill(&mut x);
    Ok(x)
}

/// Seed of bootstrap replicate `replicate` under the master `seed`, so results do not depend
/// on thread count or scheduling (STYLE §4). Distinct replicates of one seed get distinct
/// seeds (the map is a bijection in `replicate`).
///
/// # Formula
/// SplitMix64 finaliser of `splitmix64(seed) XOR (replicate * 0x9E3779B97F4A7C15)`.
pub(crate) fn replicate_seed(seed: u64, replicate: u64) -> u64 {
    splitmix64(splitmix64(seed) ^ replicate.wrapping_mul(0x9E37_79B9_7F4A_7C15))
}

/// docs/methods.md §10.1 (QN): `x_t = sqrt(q2) (u_{t+1} - u_t)` for given `u_0..u_N` (`N + 1`
/// values give `N` samples; fewer than two give none). The deterministic path of the QN
/// simulator, exposed for the hand test values of docs/methods.md §10.3.
///
/// # Examples
/// ```
/// let s12 = 12f64.sqrt();
/// let x = gmwm::sim::quantisation_noise(1.0, &[0.0, s12, 0.0]);
/// assert!((x[0] - 3.4641016).abs() < 1e-7 && (x[1] + 3.4641016).abs() < 1e-7);
/// ```
#[cfg(test)]
pub(crate) fn quantisation_noise(q2: f64, u: &[f64]) -> Vec<f64> {
    let s = q2.sqrt();
    u.windows(2).map(|w| qn_value(s, w[0], w[1])).collect()
}

// ------------------------------------------------------------------------------------------
// Internals

/// SplitMix64 output function (Steele, Lea & Flood 2014).
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Samples per cache block of [`Simulator::fill`] (32 KiB of `f64`, an L1 data cache).
const FILL_BLOCK: usize = 4096;

/// One sampler per process, on stream `i` of `seed` for the `i`-th (initial draws first).
fn build(
    processes: &[Process],
    seed: u64,
    mode: StartMode,
) -> Result<Vec<Box<dyn Sampler>>, ParamError> {
    processes
        .iter()
        .enumerate()
        .map(|(i, p)| p.sampler(stream(seed, i), mode))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replicate_seed_is_distinct_per_replicate() {
        let seeds: std::collections::HashSet<u64> =
            (0..10_000).map(|r| replicate_seed(7, r)).collect();
        assert_eq!(seeds.len(), 10_000);
        assert_ne!(replicate_seed(7, 0), replicate_seed(8, 0));
    }
}
