//! Simulating a model (METHODS §10.2): each component of a fully specified [`Model`] becomes a
//! [`Generator`] (GM through its exact AR1 at the sampling rate, §4.3) and the components are
//! summed by one [`Simulator`].

use super::{Generator, Simulator};
use crate::error::InputError;
use crate::model::Model;
use crate::process::Process;

impl From<&Process> for Generator {
    /// The per-sample generator of a latent process (GM is converted to its AR1).
    fn from(p: &Process) -> Self {
        match p {
            Process::Wn(w) => Generator::Wn { sigma2: w.sigma2 },
            Process::Qn(q) => Generator::Qn { q2: q.q2 },
            Process::Rw(r) => Generator::Rw { gamma2: r.gamma2 },
            Process::Dr(d) => Generator::Dr { omega: d.omega },
            Process::Ar1(a) => Generator::Ar1 {
                phi: a.phi,
                sigma2: a.sigma2,
            },
            Process::Gm(g) => {
                let a = g.to_ar1();
                Generator::Ar1 {
                    phi: a.phi,
                    sigma2: a.sigma2,
                }
            }
            Process::Ma1(m) => Generator::Ma1 {
                theta: m.theta,
                sigma2: m.sigma2,
            },
            Process::Arma11(a) => Generator::Arma11 {
                phi: a.phi,
                theta: a.theta,
                sigma2: a.sigma2,
            },
            Process::Arma(a) => Generator::Arma {
                ar: a.ar.clone(),
                ma: a.ma.clone(),
                sigma2: a.sigma2,
            },
        }
    }
}

impl Simulator {
    /// A streaming simulator of a fully specified model at `freq_hz` (same seed, same bits,
    /// whatever the chunking of [`Simulator::fill`]).
    ///
    /// # Errors
    /// A model that is not fully specified or has invalid values ([`Model::processes`]).
    pub fn for_model(model: &Model, freq_hz: f64, seed: u64) -> Result<Self, InputError> {
        let generators = model
            .processes(freq_hz)?
            .iter()
            .map(Generator::from)
            .collect();
        Ok(Simulator::new(generators, seed)?)
    }
}

/// Simulates `n` samples of a fully specified model at `freq_hz` (METHODS §10.2).
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
