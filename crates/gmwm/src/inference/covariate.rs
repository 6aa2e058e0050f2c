//! Inference on a fit whose parameters are functions of a covariate (docs/methods.md §5.13,
//! module doc of `crate::fit::covariate`): the sandwich covariance of the coefficients, their
//! intervals, the Wald tests of "no dependence" and the pointwise bands of each parameter.

use super::asymptotic::{sandwich, z_value, ZConvention};
use super::ParameterInference;
use crate::fit::covariate::CovariateFit;
use crate::fit::pooled::POOLED_V_REPLICATES;
use crate::fit::{FitError, FitRecording};
use crate::progress::NoProgress;
use crate::sim::covariance::{wv_covariance, CovarianceMethod};
use crate::sim::replicate_seed;
use crate::ParamError;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// One coefficient `c_it` of a [`CovariateFit`] with its Wald interval.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CoefficientInference {
    /// The parameter's label, e.g. `WN[0].sigma2`.
    pub parameter: String,
    /// The power of `(x - x0)` it multiplies (0: the value at `x0`, 1: the slope, 2: the
    /// curvature), on the parameter's transformed scale.
    pub power: usize,
    /// The estimate.
    pub estimate: f64,
    /// Its standard error.
    pub se: f64,
    /// Lower interval end.
    pub ci_low: f64,
    /// Upper interval end.
    pub ci_high: f64,
}

/// A Wald test that coefficients of degree >= 1 are all zero ("no dependence").
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DependenceTest {
    /// What is tested: `all` or a parameter's label.
    pub parameter: String,
    /// `W = b' Psi_bb^{-1} b`.
    pub statistic: f64,
    /// Degrees of freedom: the number of coefficients tested.
    pub df: usize,
    /// `P(chi2_df > W)`.
    pub p_value: f64,
}

/// The inference of a [`CovariateFit`] ([`CovariateFit::inference`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CovariateInference {
    /// `1 - alpha` is the intervals' nominal coverage.
    pub alpha: f64,
    /// Every coefficient, parameter by parameter, ascending power.
    pub coefficients: Vec<CoefficientInference>,
    /// The test of no dependence on the covariate at all; `None` when every parameter is
    /// constant.
    pub no_dependence: Option<DependenceTest>,
    /// The same test per parameter that has a dependence.
    pub per_parameter: Vec<DependenceTest>,
    /// The sandwich covariance of the coefficients (their order), as rows.
    #[serde(rename = "covariance", serialize_with = "rows")]
    pub(crate) psi: DMatrix<f64>,
    #[serde(skip)]
    z: f64,
    /// The WIC's optimism of the stacked fit, `2 tr((A' Omega A)^-1 A' Omega V Omega A)`: the
    /// fit's objective plus it is the Wavelet Information Criterion that chooses among
    /// dependence forms ([`CovariateInference::wic`]).
    pub optimism: f64,
}

impl CovariateFit {
    /// docs/methods.md §5.13: the sandwich covariance of the coefficients on the stacked
    /// problem, at the estimate (V exact, or a bootstrap of 100 replicates seeded with `seed`
    /// where the exact one does not cover the model), `1 - alpha` Wald intervals and the tests
    /// of no dependence.
    ///
    /// # Errors
    /// [`FitError::Input`] for a bad `alpha`, a coefficient without influence on the implied
    /// WVs or a failed covariance.
    pub fn inference(&self, alpha: f64, seed: u64) -> Result<CovariateInference, FitError> {
        let z = z_value(alpha, ZConvention::TwoSided)?;
        let layout = self.layout();
        let c = self.flat_coefficients();
        let q = c.len();
        let p = self.param_names.len();
        let total: usize = self.inputs.iter().map(FitRecording::levels).sum();
        let mut a = DMatrix::zeros(total, q);
        let mut omega = DVector::zeros(total);
        let mut v = DMatrix::zeros(total, total);
        let mut at = 0;
        for (k, (r, part)) in self.inputs.iter().zip(&self.recordings).enumerate() {
            let x = part.covariate;
            let u = layout.u_at(&c, x);
            let model = self.model_at(x)?;
            let jac = model.jacobian(r.levels(), self.freq_hz)?;
            let g = self.param.jacobian(&u)?;
            let pw = layout.powers(x);
            let vk = wv_covariance(
                &model,
                r.n(),
                self.freq_hz,
                &r.wv.options(),
                CovarianceMethod::Auto,
                POOLED_V_REPLICATES,
                replicate_seed(seed, k as u64),
                &NoProgress,
            )?;
            let j = r.levels();
            v.view_mut((at, at), (j, j)).copy_from(&vk.v);
            for l in 0..j {
                omega[at + l] = r.weights.omega[l];
                for (i, (d, &o)) in layout.dependence.iter().zip(&layout.offset).enumerate() {
                    // d nu_l / d u_i = sum_m A_lm d theta_m / d u_i
                    let dnu_du: f64 = (0..p).map(|m| jac[l][m] * g[m][i]).sum();
                    for t in 0..d.terms() {
                        a[(at + l, o + t)] = dnu_du * pw[t];
                    }
                }
            }
            at += j;
        }
        let psi = sandwich(&a, &DMatrix::from_diagonal(&omega), &v)?.psi;
        // the WIC's optimism (docs/methods.md §8.1) on the stacked problem:
        // 2 tr((A' Omega A)^-1 A' Omega V Omega A)
        let oa = DMatrix::from_fn(total, q, |l, j| omega[l] * a[(l, j)]);
        let bread = a.transpose() * &oa;
        let meat = oa.transpose() * &v * &oa;
        let tiny = 1e-12 * bread.amax();
        let optimism = bread
            .pseudo_inverse(tiny)
            .map(|b| 2.0 * (b * meat).trace())
            .unwrap_or(f64::NAN);
        let mut coefficients = Vec::with_capacity(q);
        for (i, (d, &o)) in layout.dependence.iter().zip(&layout.offset).enumerate() {
            for t in 0..d.terms() {
                let se = psi[(o + t, o + t)].max(0.0).sqrt();
                coefficients.push(CoefficientInference {
                    parameter: self.param_names[i].clone(),
                    power: t,
                    estimate: c[o + t],
                    se,
                    ci_low: c[o + t] - z * se,
                    ci_high: c[o + t] + z * se,
                });
            }
        }
        let test = |parameter: String, idx: &[usize]| -> Option<DependenceTest> {
            wald(&c, &psi, idx).map(|(statistic, p_value)| DependenceTest {
                parameter,
                statistic,
                df: idx.len(),
                p_value,
            })
        };
        let all = layout.slopes(None);
        let no_dependence = if all.is_empty() {
            None
        } else {
            test("all".into(), &all)
        };
        let per_parameter = (0..p)
            .filter_map(|i| {
                let idx = layout.slopes(Some(i));
                if idx.is_empty() {
                    None
                } else {
                    test(self.param_names[i].clone(), &idx)
                }
            })
            .collect();
        Ok(CovariateInference {
            alpha,
            coefficients,
            no_dependence,
            per_parameter,
            psi,
            z,
            optimism,
        })
    }
}

fn rows<S: serde::Serializer>(m: &DMatrix<f64>, s: S) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeSeq;
    let mut seq = s.serialize_seq(Some(m.nrows()))?;
    for r in m.row_iter() {
        seq.serialize_element(&r.iter().copied().collect::<Vec<f64>>())?;
    }
    seq.end()
}

/// The Wald statistic of `c[idx] = 0` under the covariance `psi` and its chi-squared p-value;
/// `None` when the block is singular.
fn wald(c: &[f64], psi: &DMatrix<f64>, idx: &[usize]) -> Option<(f64, f64)> {
    let n = idx.len();
    let b = DVector::from_fn(n, |i, _| c[idx[i]]);
    let s = DMatrix::from_fn(n, n, |i, j| psi[(idx[i], idx[j])]);
    let w = (b.transpose() * s.cholesky()?.inverse() * &b)[(0, 0)];
    let chi = ChiSquared::new(n as f64).ok()?;
    w.is_finite().then(|| (w, chi.sf(w)))
}

impl CovariateInference {
    /// The Wavelet Information Criterion of `fit` (the fit this inference is of): its stacked
    /// objective plus [`Self::optimism`]; the dependence form with the smallest is chosen.
    pub fn wic(&self, fit: &CovariateFit) -> f64 {
        fit.objective + self.optimism
    }

    /// The sandwich covariance of the coefficients (parameter by parameter, ascending power),
    /// as rows.
    pub fn covariance(&self) -> Vec<Vec<f64>> {
        self.psi
            .row_iter()
            .map(|r| r.iter().copied().collect())
            .collect()
    }

    /// docs/methods.md §5.13: each parameter at covariate value `x` with its pointwise
    /// `1 - alpha` band: the interval of `u_i(x)` mapped through the parameter's transform
    /// (`se` is the delta-method standard error in natural units).
    ///
    /// # Errors
    /// [`FitError::Input`] for a non-finite `x`.
    pub fn band(&self, fit: &CovariateFit, x: f64) -> Result<Vec<ParameterInference>, FitError> {
        if !x.is_finite() {
            return Err(ParamError::new("covariate value", x, "a finite number").into());
        }
        let layout = fit.layout();
        let c = fit.flat_coefficients();
        let u = layout.u_at(&c, x);
        let theta = fit.param.to_theta(&u)?;
        let g = fit.param.jacobian(&u)?;
        let pw = layout.powers(x);
        let mut out = Vec::with_capacity(u.len());
        for (i, (d, &o)) in layout.dependence.iter().zip(&layout.offset).enumerate() {
            let n = d.terms();
            let var: f64 = (0..n)
                .flat_map(|s| (0..n).map(move |t| (s, t)))
                .map(|(s, t)| pw[s] * pw[t] * self.psi[(o + s, o + t)])
                .sum();
            let se_u = var.max(0.0).sqrt();
            // each theta_i depends on u_i alone (free phi order): move u_i, read theta_i
            let mut lo = u.clone();
            let mut hi = u.clone();
            lo[i] -= self.z * se_u;
            hi[i] += self.z * se_u;
            let (a, b) = (fit.param.to_theta(&lo)?[i], fit.param.to_theta(&hi)?[i]);
            out.push(ParameterInference {
                name: fit.param_names[i].clone(),
                estimate: theta[i],
                se: Some(g[i][i].abs() * se_u),
                ci_low: Some(a.min(b)),
                ci_high: Some(a.max(b)),
            });
        }
        Ok(out)
    }
}
