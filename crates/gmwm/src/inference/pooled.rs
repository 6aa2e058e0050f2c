//! Inference on a multi-recording GMWM fit (docs/methods.md §5.11): the sandwich on the stacked
//! problem and the parametric bootstrap of the pooled estimate (module doc of the pooled fit,
//! "Inference").

use super::asymptotic::{sandwich, scales, z_value, ZConvention};
use super::{IntervalScale, ParameterInference};
use crate::fit::pooled::{FitRecording, PooledFit, POOLED_V_REPLICATES};
use crate::fit::{FitError, Gmwm, StartInputs, Weights};
use crate::model::Model;
use crate::progress::NoProgress;
use crate::sim::covariance::{wv_covariance, CovarianceMethod};
use crate::sim::{replicate_seed, Simulator};
use crate::variance::wv::wavelet_variance;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// The stacked matrices of a pooled fit ([`PooledFit::stacked`]).
pub(crate) struct Stacked {
    pub(crate) a: DMatrix<f64>,
    pub(crate) omega: DVector<f64>,
    pub(crate) v: DMatrix<f64>,
    pub(crate) hessian: Vec<Vec<Vec<f64>>>,
    pub(crate) implied: Vec<f64>,
    pub(crate) nu_hat: Vec<f64>,
}

impl PooledFit {
    /// docs/methods.md §5.11: the sandwich covariance `H V H'` on the stacked Jacobian, the
    /// block-diagonal weights and the block-diagonal exact covariance of the recordings' WVs at
    /// the pooled estimate (a bootstrap V of `POOLED_V_REPLICATES` replicates seeded with
    /// `seed` where the exact one does not cover the model), and the `1 - alpha` intervals of
    /// §7.2 on the transformed scale. Returns the parameters and the `p x p` covariance.
    ///
    /// # Errors
    /// [`FitError::Input`] for a bad `alpha`, a parameter without influence on the implied WV
    /// (a component fitted to nothing: fit the smaller model) or a failed covariance.
    pub fn sandwich(
        &self,
        alpha: f64,
        seed: u64,
    ) -> Result<(Vec<ParameterInference>, DMatrix<f64>), FitError> {
        let z = z_value(alpha, ZConvention::TwoSided)?;
        let st = self.stacked(&self.model, seed)?;
        let s = sandwich(&st.a, &DMatrix::from_diagonal(&st.omega), &st.v)?;
        Ok((self.intervals(&s.psi, z, alpha), s.psi))
    }

    /// The stacked matrices of the pooled problem at the estimate (module doc): `A` (sum J_k x
    /// p), the diagonal of `Omega`, the block-diagonal `V` of the WVs under `v_model` (exact,
    /// or a bootstrap of [`POOLED_V_REPLICATES`] seeded by `seed`), the stacked model Hessian
    /// (§4.6), the implied and the empirical WV.
    pub(crate) fn stacked(&self, v_model: &Model, seed: u64) -> Result<Stacked, FitError> {
        let p = self.theta.len();
        let jmax = self
            .inputs
            .iter()
            .map(FitRecording::levels)
            .max()
            .unwrap_or(0);
        let jac = self.model.jacobian(jmax, self.freq_hz)?;
        let hess = self.model.hessian(jmax, self.freq_hz)?;
        let implied = self.model.implied_wv(jmax, self.freq_hz)?.wv;
        let total: usize = self.inputs.iter().map(FitRecording::levels).sum();
        let mut a = DMatrix::zeros(total, p);
        let mut omega = DVector::zeros(total);
        let mut v = DMatrix::zeros(total, total);
        let mut hessian = Vec::with_capacity(total);
        let mut nu = Vec::with_capacity(total);
        let mut nu_hat = Vec::with_capacity(total);
        let mut at = 0;
        for (k, r) in self.inputs.iter().enumerate() {
            let j = r.levels();
            let vk = wv_covariance(
                v_model,
                r.n(),
                self.freq_hz,
                &r.wv.options(),
                CovarianceMethod::Auto,
                POOLED_V_REPLICATES,
                replicate_seed(seed, k as u64),
                &NoProgress,
            )?;
            v.view_mut((at, at), (j, j)).copy_from(&vk.v);
            for l in 0..j {
                omega[at + l] = r.weights.omega[l];
                for c in 0..p {
                    a[(at + l, c)] = jac[l][c];
                }
                hessian.push(hess[l].clone());
                nu.push(implied[l]);
                nu_hat.push(r.wv.wv[l]);
            }
            at += j;
        }
        Ok(Stacked {
            a,
            omega,
            v,
            hessian,
            implied: nu,
            nu_hat,
        })
    }

    /// Intervals of §7.2 from a covariance of the estimates.
    fn intervals(&self, psi: &DMatrix<f64>, z: f64, _alpha: f64) -> Vec<ParameterInference> {
        let g = scales(&self.model, IntervalScale::Transformed);
        (0..self.theta.len())
            .map(|k| {
                let se = psi[(k, k)].max(0.0).sqrt();
                let se_g = se * g[k].derivative(self.theta[k]).abs();
                let (lo, hi) = g[k].interval(self.theta[k], se_g, z);
                ParameterInference {
                    name: self.param_names[k].clone(),
                    estimate: self.theta[k],
                    se: Some(se),
                    ci_low: Some(lo),
                    ci_high: Some(hi),
                }
            })
            .collect()
    }

    /// docs/methods.md §5.11: the parametric bootstrap of the pooled estimate. Replicate `b`
    /// simulates every recording at its own length from the pooled estimate (recording `k` with
    /// the seed `replicate_seed(replicate_seed(seed, b), k)`), computes its WV with the
    /// recording's settings and fast weights, and refits the pooled objective from the
    /// estimate. Returns the replicate estimates (B x p, replicate order); the same for any
    /// thread count.
    ///
    /// # Errors
    /// [`FitError::Input`] for `replicates < 2`; errors of the simulation, the WVs and the fits.
    pub fn bootstrap(
        &self,
        gmwm: &Gmwm,
        replicates: usize,
        seed: u64,
    ) -> Result<Vec<Vec<f64>>, FitError> {
        if replicates < 2 {
            return Err(crate::ParamError::new(
                "bootstrap replicates",
                replicates,
                "must be at least 2",
            )
            .into());
        }
        let gmwm = gmwm.for_model(self.model.without_values());
        (0..replicates)
            .into_par_iter()
            .map(|b| {
                let recs =
                    simulate_recordings(&self.model, &self.inputs, replicate_seed(seed, b as u64))?;
                let fit = gmwm.fit_pooled_from(&recs, None, std::slice::from_ref(&self.theta))?;
                Ok(fit.estimates.theta)
            })
            .collect()
    }

    /// [`PooledFit::bootstrap`] summarised: per parameter the replicate SD and the §7.2
    /// interval with the SE of the transformed estimates (as the single-recording bootstrap
    /// inference, docs/methods.md §7.4).
    ///
    /// # Errors
    /// As [`PooledFit::bootstrap`]; [`FitError::Input`] for a bad `alpha`.
    pub fn bootstrap_inference(
        &self,
        gmwm: &Gmwm,
        replicates: usize,
        seed: u64,
        alpha: f64,
    ) -> Result<Vec<ParameterInference>, FitError> {
        let z = z_value(alpha, ZConvention::TwoSided)?;
        let est = self.bootstrap(gmwm, replicates, seed)?;
        let g = scales(&self.model, IntervalScale::Transformed);
        Ok((0..self.theta.len())
            .map(|k| {
                let raw: Vec<f64> = est.iter().map(|t| t[k]).collect();
                let tr: Vec<f64> = raw.iter().map(|&x| g[k].forward(x)).collect();
                let (lo, hi) = g[k].interval(self.theta[k], sd(&tr), z);
                ParameterInference {
                    name: self.param_names[k].clone(),
                    estimate: self.theta[k],
                    se: Some(sd(&raw)),
                    ci_low: Some(lo),
                    ci_high: Some(hi),
                }
            })
            .collect())
    }
}

/// Sample standard deviation (divisor n - 1).
fn sd(x: &[f64]) -> f64 {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

/// One parametric-bootstrap draw of K recordings from `model` (all values set): recording `k`
/// at its own length, seed `replicate_seed(seed, k)`, its WV with its own settings and fast
/// weights (diag weights when the originals are diag is not kept: fast, docs/methods.md §7.4).
pub(crate) fn simulate_recordings(
    model: &Model,
    like: &[FitRecording],
    seed: u64,
) -> Result<Vec<FitRecording>, FitError> {
    like.iter()
        .enumerate()
        .map(|(k, r)| {
            let mut sim =
                Simulator::for_model(model, r.wv.freq_hz, replicate_seed(seed, k as u64))?;
            let mut x = vec![0.0; r.n()];
            sim.fill(&mut x);
            let wv = wavelet_variance(&x, r.wv.freq_hz, &r.wv.options())?;
            let weights = Weights::fast(&wv)?;
            Ok(FitRecording {
                wv,
                weights,
                inputs: StartInputs::from_series(&x),
            })
        })
        .collect()
}
