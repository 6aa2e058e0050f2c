//! One entry point for inference on a GMWM fit (docs/methods.md §7.5, the package's
//! `summary(fit, inference = TRUE, ...)`): standard errors, confidence intervals and goodness
//! of fit, asymptotic or by parametric bootstrap.
//!
//! # Choices (documented deviations from the package)
//! - **V of the sandwich** (asymptotic mode): the *full* covariance of the WV vector at the
//!   fitted model, exact by default ([`crate::sim::covariance`]; the bootstrap's limit, without its
//!   Monte Carlo noise), or the parametric bootstrap with `H = 100` replicates
//!   ([`CovarianceMethod::Bootstrap`], and for models the exact formulas do not cover).
//!   Adjacent WV levels are strongly correlated, and the sandwich `H V H'` is linear in V, so
//!   the full bootstrap covariance is an unbiased estimate of the right matrix (its noise,
//!   ~`sqrt(2/H)` relative per entry, passes to `Psi` linearly). The package uses the
//!   diagonal bootstrap V when N > 1e4; [`VShape::Diagonal`] with the bootstrap reproduces that.
//! - **J-test V**: the statistic needs `V^{-1}`; the inverse of a sample covariance of H
//!   replicates of a J-vector is biased up by `(H - 1)/(H - J - 2)`, so a bootstrap V is
//!   scaled by the inverse Hartlap factor ([`super::gof::hartlap_factor`]) first; with
//!   `H <= J + 2` (or `J <= p`) no J-test is reported (`gof` is null).
//! - **Intervals**: two-sided `z = Phi^{-1}(1 - alpha/2)` and log/atanh scales by default
//!   ([`super::asymptotic`] module doc); GM parameters in `(beta, sigma2_gm)` with delta-method
//!   SEs.
//! - **Bootstrap mode**: `SE = sd(theta*)` (divisor B - 1); intervals on the same scale as the
//!   asymptotic ones with the SE of `g(theta*)` (natural scale: the package's `theta_hat +- z
//!   sd`); the J-test uses the V of the same B replicates; the bootstrap GoF p-value is the share
//!   of the B fresh-fit objectives strictly above the observed one, with a percentile interval
//!   from 1000 resamples (lower order statistic, as the package).

use super::asymptotic::{sandwich, scales, z_value, IntervalScale, ZConvention};
use super::bootstrap::{fit_bootstrap, FitBootstrapOptions};
use super::gof::{hartlap_factor, j_test, JTest};
use crate::error::ParamError;
use crate::fit::{FitError, Gmwm, GmwmFit};
use crate::progress::{NoProgress, Progress};
use crate::sim::covariance::{wv_covariance, CovarianceMethod, VSource};
use crate::variance::wv::WvOptions;
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::fmt;

/// Whether the asymptotic sandwich uses the full or the diagonal bootstrap V.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum VShape {
    /// The full J x J covariance (default, module doc).
    #[default]
    Full,
    /// Its diagonal (the package for N > 1e4).
    Diagonal,
}

/// Options of [`infer`] (docs/methods.md §7.5).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct InferenceOptions {
    /// Intervals are `1 - alpha` (default 0.05).
    pub alpha: f64,
    /// `Some(B)`: parametric-bootstrap inference with B replicates (§7.4); `None` (default):
    /// asymptotic sandwich (§7.1).
    pub bootstrap: Option<usize>,
    /// How the asymptotic mode's V is obtained (default [`CovarianceMethod::Auto`]: exact
    /// when the model is covered, `covariance`).
    pub v_method: CovarianceMethod,
    /// Replicates H of a bootstrap V of the asymptotic mode (default 100, as the package).
    pub v_replicates: usize,
    /// Full or diagonal V in the sandwich (default full).
    pub v_shape: VShape,
    /// Seed of every simulation (default 1342: the package seeds `summary` with `seed + 5`,
    /// seed 1337).
    pub seed: u64,
    /// z convention (default two-sided; `Package` reproduces the package's 90% intervals).
    pub z: ZConvention,
    /// Interval scale (default transformed: log/atanh).
    pub scale: IntervalScale,
    /// Starting-value draws G of the fresh per-replicate fits of the bootstrap GoF test
    /// (default `Some(10000)`, as the package); `None` skips that test. Bootstrap mode only.
    pub gof_draws: Option<usize>,
}

impl Default for InferenceOptions {
    fn default() -> Self {
        Self {
            alpha: 0.05,
            bootstrap: None,
            v_method: CovarianceMethod::Auto,
            v_replicates: 100,
            v_shape: VShape::Full,
            seed: 1342,
            z: ZConvention::TwoSided,
            scale: IntervalScale::Transformed,
            gof_draws: Some(10_000),
        }
    }
}

/// How the standard errors were obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum InferenceMethod {
    /// Sandwich covariance (docs/methods.md §7.1).
    Asymptotic,
    /// Parametric bootstrap (docs/methods.md §7.4).
    Bootstrap,
}

/// Inference on one parameter (original parametrisation, GM in `beta`, `sigma2_gm`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterInference {
    /// Label, `KIND[component].name`.
    pub name: String,
    /// The estimate.
    pub estimate: f64,
    /// Standard error (natural units); `None` for a parameter at the boundary
    /// ([`InferenceWarning::AtBoundary`]).
    pub se: Option<f64>,
    /// Lower interval end (`None` with `se`).
    pub ci_low: Option<f64>,
    /// Upper interval end (`None` with `se`).
    pub ci_high: Option<f64>,
}

/// The bootstrap goodness-of-fit test (docs/methods.md §7.4).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BootstrapGof {
    /// The observed objective `Q(theta_hat)`.
    pub objective: f64,
    /// Share of replicate objectives strictly above it.
    pub p_value: f64,
    /// Lower end of its resampling interval.
    pub ci_low: f64,
    /// Upper end.
    pub ci_high: f64,
    /// Replicates B.
    pub replicates: usize,
}

/// Soft problems of an inference run.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case", tag = "kind")]
#[non_exhaustive]
pub enum InferenceWarning {
    /// `A' Omega A` is numerically singular: the model is not locally identified at the
    /// estimate, and the pseudo-inverse drops directions (SEs are then too small).
    RankDeficient {
        /// Numerical rank.
        rank: usize,
        /// Parameters.
        params: usize,
    },
    /// Some bootstrap refits did not converge (kept in the summaries).
    NotConverged {
        /// How many.
        replicates: usize,
    },
    /// Components the fit drove to the boundary of the parameter space (a variance or drift
    /// of 0, `crate::fit::active`): their parameters get no standard error, and the others
    /// are inferred on the sub-model without them (same implied WV and objective).
    AtBoundary {
        /// The boundary parameters' labels.
        parameters: Vec<String>,
    },
    /// Parameters without influence on the implied WV at the estimate (a Jacobian column of
    /// exactly zero or non-finite Omega-norm: the edge of their domain, e.g. a GM `beta` so large
    /// that `phi` underflowed to 0, which makes the GM a white noise): no standard error; the
    /// canonical model (`canonical`) names what the component is. A column that
    /// is merely small stays in the sandwich, where a rank deficiency is reported instead.
    NoInfluence {
        /// The parameters' labels.
        parameters: Vec<String>,
    },
    /// No J-test: no degrees of freedom or too few replicates for a usable `V^{-1}`.
    NoJTest {
        /// Levels J.
        levels: usize,
        /// Parameters p.
        params: usize,
        /// Replicates behind V (`None`: exact).
        replicates: Option<usize>,
    },
}

impl fmt::Display for InferenceWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            InferenceWarning::RankDeficient { rank, params } => write!(
                f,
                "A' Omega A has rank {rank} < {params}: the model is not identified at the \
                 estimate; standard errors are understated (try a smaller model)"
            ),
            InferenceWarning::NotConverged { replicates } => {
                write!(f, "{replicates} bootstrap refits did not converge (kept)")
            }
            InferenceWarning::AtBoundary { parameters } => write!(
                f,
                "{} at the boundary (fitted to nothing): no standard error; the other \
                 parameters are inferred without {}",
                parameters.join(", "),
                if parameters.len() == 1 { "it" } else { "them" }
            ),
            InferenceWarning::NoInfluence { parameters } => {
                let (verb, whose) = if parameters.len() == 1 {
                    ("has", "its")
                } else {
                    ("have", "their")
                };
                write!(
                    f,
                    "{} {verb} no influence on the implied WV at the estimate (the edge of \
                     {whose} domain): no standard error; the canonical model names what the \
                     component is and the reduced model to fit for identified intervals",
                    parameters.join(", ")
                )
            }
            InferenceWarning::NoJTest {
                levels,
                params,
                replicates,
            } => match replicates {
                Some(h) => write!(
                    f,
                    "no J-test: it needs J > p ({levels} levels, {params} parameters) and more \
                     replicates than J + 2 ({h}); raise the replicates"
                ),
                None => write!(
                    f,
                    "no J-test: it needs more levels than parameters ({levels} levels, \
                     {params} parameters)"
                ),
            },
        }
    }
}

/// Inference on a GMWM fit (docs/methods.md §7).
///
/// Wire format: `method` ("asymptotic" | "bootstrap"), `alpha`, `z`, `z_convention`, `scale`,
/// `v_method` ("exact" | "bootstrap"), `v_replicates` (replicates behind V, null when exact),
/// `bootstrap_replicates` (B or null), `parameters`
/// (per parameter `name`, `estimate`, `se`, `ci_low`, `ci_high`), `covariance` (p x p rows;
/// null for a parameter at the boundary), `objective`, `gof` (`statistic`, `df`, `p_value`,
/// or null), `bootstrap_gof` (`objective`, `p_value`, `ci_low`, `ci_high`, `replicates`, or
/// null), `warnings`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Inference {
    /// Asymptotic or bootstrap.
    pub(crate) method: InferenceMethod,
    /// The `alpha` of the intervals (`1 - alpha` two-sided, `1 - 2 alpha` with the package z).
    pub(crate) alpha: f64,
    /// The normal quantile used.
    pub(crate) z: f64,
    /// Its convention.
    pub(crate) z_convention: ZConvention,
    /// Interval scale.
    pub(crate) scale: IntervalScale,
    /// How V was obtained: exact, or the replicates behind it (H, or B in bootstrap mode).
    #[serde(flatten)]
    pub(crate) v_source: VSource,
    /// B in bootstrap mode.
    pub(crate) bootstrap_replicates: Option<usize>,
    /// Per parameter, model order.
    pub(crate) parameters: Vec<ParameterInference>,
    /// Covariance of the estimates (sandwich `Psi` or bootstrap), rows; `None` in the rows and
    /// columns of a parameter at the boundary.
    pub(crate) covariance: Vec<Vec<Option<f64>>>,
    /// `Q(theta_hat)` of the fit.
    pub(crate) objective: f64,
    /// The J-test (docs/methods.md §7.3).
    pub(crate) gof: Option<JTest>,
    /// The bootstrap GoF test (docs/methods.md §7.4), when run.
    pub(crate) bootstrap_gof: Option<BootstrapGof>,
    /// Soft problems.
    pub(crate) warnings: Vec<InferenceWarning>,
}

/// Read access to the results; the fields are the engine's own.
impl Inference {
    /// Asymptotic or bootstrap.
    pub fn method(&self) -> InferenceMethod {
        self.method
    }

    /// The `alpha` of the intervals (`1 - alpha` two-sided, `1 - 2 alpha` with the package z).
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// The normal quantile used.
    pub fn z(&self) -> f64 {
        self.z
    }

    /// Interval scale.
    pub fn scale(&self) -> IntervalScale {
        self.scale
    }

    /// How V was obtained: `"exact"` or `"bootstrap"`.
    pub fn v_method(&self) -> &'static str {
        self.v_source.method()
    }

    /// Replicates behind the WV covariance V (H, or B in bootstrap mode); `None` when exact.
    pub fn v_replicates(&self) -> Option<usize> {
        self.v_source.replicates()
    }

    /// B in bootstrap mode.
    pub fn bootstrap_replicates(&self) -> Option<usize> {
        self.bootstrap_replicates
    }

    /// Per parameter, model order.
    pub fn parameters(&self) -> &[ParameterInference] {
        &self.parameters
    }

    /// Covariance of the estimates (sandwich `Psi` or bootstrap), rows; `None` in the rows and
    /// columns of a parameter at the boundary.
    pub fn covariance(&self) -> &[Vec<Option<f64>>] {
        &self.covariance
    }

    /// `Q(theta_hat)` of the fit.
    pub fn objective(&self) -> f64 {
        self.objective
    }

    /// The J-test (docs/methods.md §7.3).
    pub fn gof(&self) -> Option<&JTest> {
        self.gof.as_ref()
    }

    /// The bootstrap GoF test (docs/methods.md §7.4), when run.
    pub fn bootstrap_gof(&self) -> Option<&BootstrapGof> {
        self.bootstrap_gof.as_ref()
    }

    /// Soft problems.
    pub fn warnings(&self) -> &[InferenceWarning] {
        &self.warnings
    }
}

/// docs/methods.md §7.5: inference on `fit` (a fit by `gmwm` of a series of length `n`, WV computed
/// with `wv_opts`, whose `levels` is replaced by the fit's J) with `opts`.
///
/// Asymptotic mode: V from `opts.v_replicates` series simulated from the fitted model, the
/// sandwich with the fit's Omega and the analytic Jacobian, the J-test. Bootstrap mode:
/// `fit_bootstrap` with B replicates. See the module doc for the choices.
///
/// Cost: asymptotic, H x (simulation + WV) of length `n` plus one stage-2 fit; bootstrap, B x
/// (simulation + WV + stage-2 fit [+ G draws and a two-stage fit]).
///
/// # Errors
/// [`FitError::Input`] for a bad `alpha`, `n == 0` or fewer than 2 replicates; errors of the
/// simulation, the WV, the sandwich and the fits.
pub fn infer(
    gmwm: &Gmwm,
    fit: &GmwmFit,
    n: usize,
    wv_opts: &WvOptions,
    opts: &InferenceOptions,
) -> Result<Inference, FitError> {
    infer_with_progress(gmwm, fit, n, wv_opts, opts, &NoProgress)
}

/// [`infer`] reporting each finished replicate to `progress`.
///
/// # Errors
/// As [`infer`].
pub fn infer_with_progress(
    gmwm: &Gmwm,
    fit: &GmwmFit,
    n: usize,
    wv_opts: &WvOptions,
    opts: &InferenceOptions,
    progress: &dyn Progress,
) -> Result<Inference, FitError> {
    infer_impl(gmwm, fit, n, wv_opts, opts, progress, None)
}

/// Asymptotic inference on `fit` (docs/methods.md §7.1–§7.3) with a WV covariance `v` the caller
/// already has (e.g. the V of a model selection, at the full model's estimate, which nests
/// `fit`'s model), exact or from `v_replicates` bootstrap replicates: the sandwich and the
/// J-test without computing V again. `opts.bootstrap`, `opts.v_method` and
/// `opts.v_replicates` are ignored.
///
/// # Errors
/// As [`infer`]; [`FitError::Input`] if `v` is not `J x J` for the fit's `J` levels.
pub(crate) fn infer_with_covariance(
    gmwm: &Gmwm,
    fit: &GmwmFit,
    v: &DMatrix<f64>,
    v_replicates: Option<usize>,
    wv_opts: &WvOptions,
    opts: &InferenceOptions,
) -> Result<Inference, FitError> {
    let levels = fit.nu_hat.len();
    if v.nrows() != levels || v.ncols() != levels {
        return Err(ParamError::new(
            "v",
            format!("{} x {}", v.nrows(), v.ncols()),
            format!("a {levels} x {levels} covariance (one row per level of the fit)"),
        )
        .into());
    }
    let opts = InferenceOptions {
        bootstrap: None,
        ..*opts
    };
    infer_impl(
        gmwm,
        fit,
        0,
        wv_opts,
        &opts,
        &NoProgress,
        Some((v, v_replicates)),
    )
}

fn infer_impl(
    gmwm: &Gmwm,
    fit: &GmwmFit,
    n: usize,
    wv_opts: &WvOptions,
    opts: &InferenceOptions,
    progress: &dyn Progress,
    given_v: Option<(&DMatrix<f64>, Option<usize>)>,
) -> Result<Inference, FitError> {
    crate::fit::check_haar(wv_opts.filter)?;
    let z = z_value(opts.alpha, opts.z)?;
    let levels = fit.nu_hat.len();
    let p = fit.theta.len();
    let wv_opts = WvOptions {
        levels: Some(levels),
        ..*wv_opts
    };
    let g = scales(&fit.model, opts.scale);
    let mut warnings = Vec::new();
    // parameters of components at the boundary get no SE (crate::fit::active)
    let sub = fit.active_sub_model()?;
    let keep: Vec<usize> = match &sub {
        Some(s) => {
            warnings.push(InferenceWarning::AtBoundary {
                parameters: (0..p)
                    .filter(|k| !s.keep.contains(k))
                    .map(|k| fit.param_names[k].clone())
                    .collect(),
            });
            s.keep.clone()
        }
        None => (0..p).collect(),
    };
    // a parameter without influence on the implied WV at the estimate sits on the edge of
    // its domain (a GM beta so large that phi underflowed to 0: the GM is white noise); it
    // has no standard error either
    let jacobian = fit.model.jacobian(levels, fit.freq_hz)?;
    let no_influence: Vec<usize> = keep
        .iter()
        .copied()
        .filter(|&k| {
            let norm: f64 = (0..levels)
                .map(|j| fit.weights.omega[j] * jacobian[j][k] * jacobian[j][k])
                .sum();
            !(norm.is_finite() && norm > 0.0)
        })
        .collect();
    let keep: Vec<usize> = if no_influence.is_empty() {
        keep
    } else {
        warnings.push(InferenceWarning::NoInfluence {
            parameters: no_influence
                .iter()
                .map(|&k| fit.param_names[k].clone())
                .collect(),
        });
        keep.into_iter()
            .filter(|k| !no_influence.contains(k))
            .collect()
    };
    let q = keep.len();
    let (method, v, v_replicates, covariance, se, se_g, bootstrap_gof) = match opts.bootstrap {
        None => {
            let (v, h) = match given_v {
                Some((v, h)) => (v.clone(), h),
                None => {
                    let c = wv_covariance(
                        &fit.active_model()?,
                        n,
                        fit.freq_hz,
                        &wv_opts,
                        opts.v_method,
                        opts.v_replicates,
                        opts.seed,
                        progress,
                    )?;
                    (c.v, c.replicates)
                }
            };
            let v_sand = match opts.v_shape {
                VShape::Full => v.clone(),
                VShape::Diagonal => DMatrix::from_diagonal(&v.diagonal()),
            };
            let a = DMatrix::from_fn(levels, q, |i, k| jacobian[i][keep[k]]);
            let omega = DMatrix::from_diagonal(&DVector::from_column_slice(&fit.weights.omega));
            let s = sandwich(&a, &omega, &v_sand)?;
            if s.rank < q {
                warnings.push(InferenceWarning::RankDeficient {
                    rank: s.rank,
                    params: q,
                });
            }
            let psi = expand(&s.psi, &keep, p);
            let se: Vec<f64> = (0..p).map(|k| psi[(k, k)].max(0.0).sqrt()).collect();
            let se_g: Vec<f64> = (0..p)
                .map(|k| se[k] * g[k].derivative(fit.theta[k]).abs())
                .collect();
            let cov = rows(&psi);
            (InferenceMethod::Asymptotic, v, h, cov, se, se_g, None)
        }
        Some(b) => {
            let fb = fit_bootstrap(
                gmwm,
                fit,
                n,
                &wv_opts,
                &FitBootstrapOptions {
                    replicates: b,
                    seed: opts.seed,
                    gof_draws: opts.gof_draws,
                },
                progress,
            )?;
            if fb.not_converged > 0 {
                warnings.push(InferenceWarning::NotConverged {
                    replicates: fb.not_converged,
                });
            }
            let cov = DMatrix::from_fn(q, q, |i, k| {
                let (i, k) = (keep[i], keep[k]);
                fb.estimates
                    .iter()
                    .map(|t| (t[i] - fb.mean[i]) * (t[k] - fb.mean[k]))
                    .sum::<f64>()
                    / (b - 1) as f64
            });
            let cov = expand(&cov, &keep, p);
            let se_g = (0..p)
                .map(|k| {
                    let ys: Vec<f64> = fb.estimates.iter().map(|t| g[k].forward(t[k])).collect();
                    sd(&ys)
                })
                .collect();
            let gof = fb
                .objectives
                .as_ref()
                .map(|objs| bootstrap_gof(fit.objective, objs, opts.alpha, opts.seed));
            (
                InferenceMethod::Bootstrap,
                fb.v.clone(),
                Some(b),
                rows(&cov),
                fb.sd.clone(),
                se_g,
                gof,
            )
        }
    };
    // an exact V needs no correction of its inverse
    let factor = match v_replicates {
        Some(h) => hartlap_factor(h, levels),
        None => Some(1.0),
    };
    let gof = match factor {
        Some(f) if levels > q => Some(j_test(gmwm, fit, &(&v / f))?),
        _ => {
            warnings.push(InferenceWarning::NoJTest {
                levels,
                params: q,
                replicates: v_replicates,
            });
            None
        }
    };
    let parameters = (0..p)
        .map(|k| {
            let active = keep.contains(&k);
            let (ci_low, ci_high) = g[k].interval(fit.theta[k], se_g[k], z);
            ParameterInference {
                name: fit.param_names[k].clone(),
                estimate: fit.theta[k],
                se: active.then_some(se[k]),
                ci_low: active.then_some(ci_low),
                ci_high: active.then_some(ci_high),
            }
        })
        .collect();
    Ok(Inference {
        method,
        alpha: opts.alpha,
        z,
        z_convention: opts.z,
        scale: opts.scale,
        v_source: VSource(v_replicates),
        bootstrap_replicates: opts.bootstrap,
        parameters,
        covariance,
        objective: fit.objective,
        gof,
        bootstrap_gof,
        warnings,
    })
}

/// The p x p matrix with `m` (q x q) at the `keep` rows and columns and NaN elsewhere.
fn expand(m: &DMatrix<f64>, keep: &[usize], p: usize) -> DMatrix<f64> {
    let mut out = DMatrix::from_element(p, p, f64::NAN);
    for (i, &ki) in keep.iter().enumerate() {
        for (k, &kk) in keep.iter().enumerate() {
            out[(ki, kk)] = m[(i, k)];
        }
    }
    out
}

/// Rows of `m`, NaN (a parameter at the boundary, see [`expand`]) as `None`.
fn rows(m: &DMatrix<f64>) -> Vec<Vec<Option<f64>>> {
    (0..m.nrows())
        .map(|i| {
            m.row(i)
                .iter()
                .map(|&x| (!x.is_nan()).then_some(x))
                .collect()
        })
        .collect()
}

/// Sample standard deviation (divisor n - 1).
fn sd(x: &[f64]) -> f64 {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

/// Resamples of the bootstrap GoF p-value (docs/methods.md §7.4, as the package).
pub(crate) const GOF_RESAMPLES: usize = 1000;

/// docs/methods.md §7.4: bootstrap GoF p-value (share of `objectives` strictly above `observed`)
/// and its interval: [`GOF_RESAMPLES`] resamples with replacement of the objectives, each giving a
/// p-value, and their `alpha/2`, `1 - alpha/2` empirical quantiles (lower order statistic
/// `sorted[floor(q (R - 1))]`, no interpolation). Seeded by `seed`.
pub(crate) fn bootstrap_gof(
    observed: f64,
    objectives: &[f64],
    alpha: f64,
    seed: u64,
) -> BootstrapGof {
    let b = objectives.len();
    let share =
        |it: &mut dyn Iterator<Item = f64>| it.filter(|&o| o > observed).count() as f64 / b as f64;
    let p_value = share(&mut objectives.iter().copied());
    let mut rng = ChaCha8Rng::seed_from_u64(crate::sim::replicate_seed(seed, u64::MAX));
    let mut ps: Vec<f64> = (0..GOF_RESAMPLES)
        .map(|_| share(&mut (0..b).map(|_| objectives[rng.random_range(0..b)])))
        .collect();
    ps.sort_by(f64::total_cmp);
    let q = |prob: f64| ps[(prob * (GOF_RESAMPLES - 1) as f64).floor() as usize];
    BootstrapGof {
        objective: observed,
        p_value,
        ci_low: q(alpha / 2.0),
        ci_high: q(1.0 - alpha / 2.0),
        replicates: b,
    }
}

impl fmt::Display for Inference {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let level = match self.z_convention {
            ZConvention::TwoSided => 1.0 - self.alpha,
            ZConvention::Package => 1.0 - 2.0 * self.alpha,
        };
        let how = match (self.method, self.v_replicates()) {
            (InferenceMethod::Asymptotic, Some(h)) => {
                format!("asymptotic (sandwich, V from {h} bootstrap replicates)")
            }
            (InferenceMethod::Asymptotic, None) => {
                "asymptotic (sandwich, exact V at the estimate)".to_string()
            }
            (InferenceMethod::Bootstrap, _) => format!(
                "parametric bootstrap, {} replicates",
                self.bootstrap_replicates
                    .or(self.v_replicates())
                    .unwrap_or(0)
            ),
        };
        writeln!(
            f,
            "Inference: {how}; {:.0}% intervals (z = {:.6})",
            100.0 * level,
            self.z
        )?;
        writeln!(
            f,
            "{:<20} {:>14} {:>14} {:>14} {:>14}",
            "parameter", "estimate", "se", "ci_low", "ci_high"
        )?;
        let cell = |x: Option<f64>| x.map_or_else(|| "-".to_string(), |x| format!("{x:.5e}"));
        for p in &self.parameters {
            writeln!(
                f,
                "{:<20} {:>14.5e} {:>14} {:>14} {:>14}",
                p.name,
                p.estimate,
                cell(p.se),
                cell(p.ci_low),
                cell(p.ci_high)
            )?;
        }
        write!(f, "objective Q = {:e}", self.objective)?;
        match &self.gof {
            Some(g) => write!(f, "\n{g}")?,
            None => write!(f, "\nJ-test: not available")?,
        }
        if let Some(g) = &self.bootstrap_gof {
            write!(
                f,
                "\nbootstrap GoF: p-value = {:.4} ({:.4}, {:.4}), {} replicates",
                g.p_value, g.ci_low, g.ci_high, g.replicates
            )?;
        }
        for w in &self.warnings {
            write!(f, "\nwarning: {w}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bootstrap_gof_counts_strictly_larger() {
        let objs = [1.0, 2.0, 3.0, 4.0];
        let g = bootstrap_gof(2.0, &objs, 0.05, 1);
        assert_eq!(g.p_value, 0.5);
        assert!(g.ci_low <= g.p_value && g.p_value <= g.ci_high);
        assert!(g.ci_low >= 0.0 && g.ci_high <= 1.0);
        assert_eq!(bootstrap_gof(10.0, &objs, 0.05, 1).p_value, 0.0);
        assert_eq!(bootstrap_gof(10.0, &objs, 0.05, 1).ci_high, 0.0);
    }
}
