//! Random walk (METHODS §0.2, §4.2, §10.1).

use crate::sim::sampler::SimRng;
use serde::{Deserialize, Serialize};

use super::{
    add_scaled, check_positive, half_widths, LatentProcess, Occurs, Params, Simulate, Spec,
};
use crate::error::ParamError;
use crate::model::ParamDomain;
use crate::sim::sampler::{normal, Sampler};
use crate::sim::StartMode;

/// `RW(gamma2)`: may appear once in a model.
pub(crate) const SPEC: Spec = Spec {
    name: "RW",
    syntax: "RW()",
    params: Params::Fixed(&[("gamma2", ParamDomain::Variance)], (0, 0)),
    orders: None,
    occurs: Occurs::Once,
    build: |_, v, _| Ok(Rw::new(v[0])?.into()),
};

/// Random walk: cumulative sum of white noise with increment variance `gamma2`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Rw {
    /// Increment variance.
    pub gamma2: f64,
}

impl Rw {
    /// Builds the process.
    ///
    /// # Errors
    /// [`ParamError`] naming `gamma2` unless it is finite and > 0.
    pub fn new(gamma2: f64) -> Result<Self, ParamError> {
        check_positive("gamma2", gamma2)?;
        Ok(Self { gamma2 })
    }
}

/// METHODS §4.2: `nu2 = gamma2 (tau^2 + 2) / (12 tau)`, `tau = 2m`.
fn unit_wv(m: f64) -> f64 {
    let tau = 2.0 * m;
    (tau * tau + 2.0) / (12.0 * tau)
}

impl LatentProcess for Rw {
    fn name(&self) -> &'static str {
        SPEC.name
    }
    fn param_names(&self) -> Vec<&'static str> {
        SPEC.fixed_names()
    }
    fn params(&self) -> Vec<f64> {
        vec![self.gamma2]
    }
    fn wv(&self, levels: usize) -> Vec<f64> {
        half_widths(levels)
            .map(|m| self.gamma2 * unit_wv(m))
            .collect()
    }
    fn add_wv(&self, out: &mut [f64]) {
        add_scaled(out, self.gamma2, unit_wv);
    }
    fn jacobian(&self, levels: usize) -> Vec<Vec<f64>> {
        half_widths(levels).map(|m| vec![unit_wv(m)]).collect()
    }
    fn hessian(&self, levels: usize) -> Vec<Vec<Vec<f64>>> {
        half_widths(levels).map(|_| vec![vec![0.0]]).collect()
    }
    fn spectral_density(&self, f: f64) -> Option<f64> {
        let s = (std::f64::consts::PI * f).sin();
        Some(self.gamma2 / (4.0 * s * s))
    }
}

/// METHODS §10.1: `x_t = sum_{i=0}^{t} w_i`, `w ~ N(0, gamma2)` (the first value is `w_0`,
/// not 0), evaluated four samples at a time as the AR1 with `phi = 1`: within the block of
/// samples `4k .. 4k + 3`, `x_{4k+i} = x_{4k-1} + (w_{4k} + ... + w_{4k+i})`, so the running
/// sum's latency is paid once per four. Blocks are fixed by the sample index, not by the chunks
/// asked for, so any chunking gives the same bits.
#[derive(Debug, Clone)]
struct RwSampler {
    rng: SimRng,
    sd: f64,
    /// The level before the current block.
    start: f64,
    /// The sum of the current block's innovations so far.
    partial: f64,
    /// Position in the current block, 0..4.
    at: usize,
}

impl RwSampler {
    /// The next value, one sample at a time (the same operations as a whole block).
    #[inline]
    fn one(&mut self) -> f64 {
        let w = self.sd * normal(&mut self.rng);
        self.partial = if self.at == 0 { w } else { self.partial + w };
        let x = self.start + self.partial;
        self.at += 1;
        if self.at == 4 {
            self.start = x;
            self.at = 0;
        }
        x
    }

    /// The next `out.len()` values, each given to `emit`.
    #[inline]
    fn run(&mut self, out: &mut [f64], emit: impl Fn(&mut f64, f64)) {
        let mut rest = out;
        while self.at != 0 && !rest.is_empty() {
            let (o, tail) = rest.split_first_mut().expect("not empty");
            emit(o, self.one());
            rest = tail;
        }
        let mut quads = rest.chunks_exact_mut(4);
        for q in &mut quads {
            let w0 = self.sd * normal(&mut self.rng);
            let w1 = self.sd * normal(&mut self.rng);
            let w2 = self.sd * normal(&mut self.rng);
            let w3 = self.sd * normal(&mut self.rng);
            let a1 = w0 + w1;
            let a2 = a1 + w2;
            let a3 = a2 + w3;
            let x = self.start;
            emit(&mut q[0], x + w0);
            emit(&mut q[1], x + a1);
            emit(&mut q[2], x + a2);
            self.start = x + a3;
            emit(&mut q[3], self.start);
        }
        for o in quads.into_remainder() {
            emit(o, self.one());
        }
    }
}

impl Sampler for RwSampler {
    fn add(&mut self, out: &mut [f64]) {
        self.run(out, |o, v| *o += v);
    }
    fn store(&mut self, out: &mut [f64]) {
        self.run(out, |o, v| *o = v);
    }
    fn clone_box(&self) -> Box<dyn Sampler> {
        Box::new(self.clone())
    }
}

impl Simulate for Rw {
    fn check(&self) -> Result<(), ParamError> {
        Self::new(self.gamma2).map(drop)
    }
    fn sampler(&self, rng: SimRng, _: StartMode) -> Result<Box<dyn Sampler>, ParamError> {
        Ok(Box::new(RwSampler {
            rng,
            sd: self.gamma2.sqrt(),
            start: 0.0,
            partial: 0.0,
            at: 0,
        }))
    }
}
