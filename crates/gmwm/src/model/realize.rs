//! From a fully specified model to numbers: its latent processes (docs/methods.md §0.2, §4.3), its
//! implied Haar wavelet variance and the derivatives with respect to theta (§4.1–§4.6).

use super::{Component, Model};
use crate::error::{check_freq, InputError, ParamError};
use crate::math::elementary;
use crate::process::{spec, LatentProcess, Process};
use serde::Serialize;
use std::fmt;

impl Component {
    /// The latent process of a fully specified component; `freq_hz` converts GM to its AR1
    /// (docs/methods.md §4.3) and is otherwise unused.
    ///
    /// # Errors
    /// [`ParamError`] naming the first missing value, or the process constructor's error for an
    /// invalid one (e.g. a non-stationary AR polynomial).
    pub fn process(&self, freq_hz: f64) -> Result<Process, InputError> {
        let names = self.kind.param_names();
        let v: Vec<f64> = self
            .values
            .iter()
            .zip(&names)
            .map(|(v, name)| {
                v.ok_or_else(|| {
                    ParamError::new(
                        "model",
                        format!("{} without a value for {name}", self.kind.name()),
                        "a fully specified model, e.g. \"AR1(phi=0.9, sigma2=1)+WN(sigma2=0.5)\"",
                    )
                })
            })
            .collect::<Result<_, _>>()?;
        Ok((spec(self.kind).build)(self.kind, &v, freq_hz)?)
    }
}

impl Model {
    /// The latent processes of a fully specified model, in model order.
    ///
    /// # Errors
    /// As [`Component::process`].
    pub fn processes(&self, freq_hz: f64) -> Result<Vec<Process>, InputError> {
        check_freq(freq_hz)?;
        self.components()
            .iter()
            .map(|c| c.process(freq_hz))
            .collect()
    }

    /// Calls `f` with the latent process of each component at the values `theta` (model
    /// order) and the index in `theta` of its first parameter: what
    /// `self.with_values(theta)?.processes(freq_hz)?` gives, with the same checks and errors,
    /// without building a model or a vector (the objective evaluates it at every draw and
    /// every step of a fit).
    ///
    /// # Errors
    /// As [`Model::with_values`] and [`Model::processes`].
    pub(crate) fn for_each_process(
        &self,
        theta: &[f64],
        freq_hz: f64,
        mut f: impl FnMut(&Process, usize),
    ) -> Result<(), InputError> {
        check_freq(freq_hz)?;
        if theta.len() != self.n_params() {
            return Err(super::ModelError::ThetaLength {
                expected: self.n_params(),
                found: theta.len(),
            }
            .into());
        }
        let mut at = 0;
        for (i, c) in self.components().iter().enumerate() {
            let mine = &theta[at..at + c.kind.n_params()];
            for (index, &v) in mine.iter().enumerate() {
                super::check_value(i, c.kind, index, v)?;
            }
            f(&(spec(c.kind).build)(c.kind, mine, freq_hz)?, at);
            at += mine.len();
        }
        Ok(())
    }

    /// Implied Haar WV of the model and of each component at `tau_j = 2^j`, `j = 1..=levels`
    /// (docs/methods.md §4.1–§4.4; a sum of independent processes has the sum of their WVs).
    ///
    /// # Errors
    /// As [`Model::processes`]; `levels` must be in 1..=60.
    pub fn implied_wv(&self, levels: usize, freq_hz: f64) -> Result<ImpliedWv, InputError> {
        check_levels(levels)?;
        let processes = self.processes(freq_hz)?;
        let per: Vec<ComponentWv> = self
            .components()
            .iter()
            .zip(&processes)
            .map(|(c, p)| ComponentWv {
                process: c.to_string(),
                wv: p.wv(levels),
            })
            .collect();
        let wv = (0..levels)
            .map(|j| per.iter().map(|c| c.wv[j]).sum())
            .collect();
        let tau: Vec<f64> = (1..=levels).map(|j| elementary::exp2(j as f64)).collect();
        Ok(ImpliedWv {
            model: self.to_string(),
            freq_hz,
            tau_s: tau.iter().map(|t| t / freq_hz).collect(),
            tau,
            wv,
            processes: per,
        })
    }

    /// Jacobian of the implied WV with respect to theta (model order, original
    /// parametrisation: GM in (beta, sigma2_gm)), `[level][param]` (docs/methods.md §4.5).
    ///
    /// # Errors
    /// As [`Model::implied_wv`].
    pub fn jacobian(&self, levels: usize, freq_hz: f64) -> Result<Vec<Vec<f64>>, InputError> {
        check_levels(levels)?;
        let blocks: Vec<Vec<Vec<f64>>> = self
            .processes(freq_hz)?
            .iter()
            .map(|p| p.jacobian(levels))
            .collect();
        Ok((0..levels)
            .map(|j| blocks.iter().flat_map(|b| b[j].iter().copied()).collect())
            .collect())
    }

    /// docs/methods.md §4.6: second derivatives of the implied WV with respect to theta (model
    /// order, original parametrisation as [`Model::jacobian`]), `[level][param][param]`, symmetric.
    ///
    /// Block diagonal: the WV of a sum is the sum of the components' WVs, so a cross-component
    /// second derivative is zero. Each block is its process's [`LatentProcess::hessian`]; GM
    /// blocks are in `(beta, sigma2_gm)` (the process differentiates through the AR1
    /// conversion of §4.3, chain rule included).
    ///
    /// # Errors
    /// As [`Model::implied_wv`].
    pub(crate) fn hessian(
        &self,
        levels: usize,
        freq_hz: f64,
    ) -> Result<Vec<Vec<Vec<f64>>>, InputError> {
        check_levels(levels)?;
        let p = self.n_params();
        let mut out = vec![vec![vec![0.0; p]; p]; levels];
        let mut at = 0;
        for process in self.processes(freq_hz)? {
            let block = process.hessian(levels);
            let k = process.params().len();
            for (h, b) in out.iter_mut().zip(&block) {
                for r in 0..k {
                    h[at + r][at..at + k].copy_from_slice(&b[r][..k]);
                }
            }
            at += k;
        }
        Ok(out)
    }
}

fn check_levels(levels: usize) -> Result<(), ParamError> {
    if (1..=crate::wavelet::MAX_LEVELS).contains(&levels) {
        Ok(())
    } else {
        Err(ParamError::new(
            "levels",
            levels,
            format!("must be in 1..={}", crate::wavelet::MAX_LEVELS),
        ))
    }
}

/// Implied wavelet variance of a model and of each of its components.
///
/// Wire format: `model` (canonical text), `freq_hz`, equal-length `tau` (samples), `tau_s`,
/// `wv` (the model), and `processes`: one `{process, wv}` per component in model order.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImpliedWv {
    /// Canonical model text.
    pub model: String,
    /// Sampling rate in Hz.
    pub freq_hz: f64,
    /// Scales `2^j` in samples.
    pub tau: Vec<f64>,
    /// Scales in seconds.
    pub tau_s: Vec<f64>,
    /// Implied WV of the whole model.
    pub wv: Vec<f64>,
    /// Implied WV of each component.
    pub processes: Vec<ComponentWv>,
}

/// Implied WV of one component.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComponentWv {
    /// Canonical text of the component.
    pub process: String,
    /// Its implied WV.
    pub wv: Vec<f64>,
}

impl fmt::Display for ImpliedWv {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "implied wavelet variance of {} at {} Hz",
            self.model, self.freq_hz
        )?;
        write!(
            f,
            "{:>5} {:>10} {:>12} {:>13}",
            "level", "tau", "tau_s", "model"
        )?;
        for (i, _) in self.processes.iter().enumerate() {
            write!(f, " {:>13}", format!("[{}]", i + 1))?;
        }
        writeln!(f)?;
        for j in 0..self.wv.len() {
            write!(
                f,
                "{:>5} {:>10} {:>12.6} {:>13.6e}",
                j + 1,
                self.tau[j],
                self.tau_s[j],
                self.wv[j]
            )?;
            for p in &self.processes {
                write!(f, " {:>13.6e}", p.wv[j])?;
            }
            writeln!(f)?;
        }
        for (i, p) in self.processes.iter().enumerate() {
            writeln!(f, "[{}] {}", i + 1, p.process)?;
        }
        Ok(())
    }
}
