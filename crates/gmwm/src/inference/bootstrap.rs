//! Parametric bootstrap of the wavelet variance (METHODS §7.4): nothing is resampled from the
//! data; each replicate simulates a new series of the observed length from a (fitted) model and
//! computes its WV with the observed settings.
//!
//! Replicate `r` uses the seed [`replicate_seed`]`(seed, r)`, so results do not depend on the
//! thread count or on the order in which rayon runs the replicates. Each worker thread reuses
//! one series buffer: memory is `threads x N` samples plus what the caller keeps per replicate.

use super::progress::Progress;
use crate::error::{Error, ParamError};
use crate::fit::{FitError, Gmwm, GmwmFit, StartInputs, Weighting, Weights};
use crate::model::Model;
use crate::sim::{replicate_seed, Simulator};
use crate::variance::wv::{wavelet_variance, WaveletVariance, WvOptions};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use serde::Serialize;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Runs `f` on `replicates` parametric-bootstrap replicates of `model` (length `n`, rate
/// `freq_hz`, WV computed with `wv_opts`) in parallel, and returns the results in replicate
/// order. `f` gets the replicate index, its WV and its series.
///
/// # Errors
/// [`ParamError`] for `replicates == 0` or `n == 0`; errors of [`Simulator::for_model`] (a
/// model with unset or invalid values) and of [`wavelet_variance`]; the first error of `f`.
pub fn map_replicates<T, E, F>(
    model: &Model,
    n: usize,
    freq_hz: f64,
    wv_opts: &WvOptions,
    replicates: usize,
    seed: u64,
    f: F,
) -> Result<Vec<T>, E>
where
    T: Send,
    E: From<Error> + Send,
    F: Fn(usize, &WaveletVariance, &[f64]) -> Result<T, E> + Sync + Send,
{
    if replicates == 0 {
        return Err(Error::from(ParamError::new(
            "replicates",
            replicates,
            "must be at least 1",
        ))
        .into());
    }
    if n == 0 {
        return Err(Error::from(ParamError::new("n", n, "must be at least 1")).into());
    }
    // fail early (and once) on a model that cannot be simulated
    Simulator::for_model(model, freq_hz, seed).map_err(E::from)?;
    (0..replicates)
        .into_par_iter()
        .map_init(
            || vec![0.0; n],
            |x, r| {
                let mut sim = Simulator::for_model(model, freq_hz, replicate_seed(seed, r as u64))?;
                sim.fill(x);
                let wv = wavelet_variance(x, freq_hz, wv_opts)?;
                f(r, &wv, x)
            },
        )
        .collect()
}

/// The bootstrap distribution summary of the WV vector (the package's `cov_bootstrapper`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WvBootstrap {
    /// Number of replicates H.
    pub replicates: usize,
    /// Replicate mean of the WV, per level.
    pub mean: Vec<f64>,
    /// Full J x J covariance of the replicate WV vectors (divisor H - 1).
    pub cov: DMatrix<f64>,
}

impl WvBootstrap {
    /// Mean and covariance (divisor `H - 1`, two-pass) of replicate WV vectors of equal length.
    ///
    /// # Errors
    /// [`ParamError`] when fewer than two vectors are given or their lengths differ.
    pub fn from_samples(samples: &[Vec<f64>]) -> Result<Self, Error> {
        let h = samples.len();
        if h < 2 {
            return Err(
                ParamError::new("replicates", h, "must be at least 2 for a covariance").into(),
            );
        }
        let j = samples[0].len();
        if let Some(bad) = samples.iter().position(|s| s.len() != j) {
            return Err(ParamError::new(
                "replicate",
                bad,
                "has a WV vector of a different length than replicate 0",
            )
            .into());
        }
        let mut mean = DVector::zeros(j);
        for s in samples {
            mean += DVector::from_column_slice(s);
        }
        mean /= h as f64;
        let mut cov = DMatrix::zeros(j, j);
        for s in samples {
            let d = DVector::from_column_slice(s) - &mean;
            cov.ger(1.0, &d, &d, 1.0);
        }
        cov /= (h - 1) as f64;
        Ok(Self {
            replicates: h,
            mean: mean.iter().copied().collect(),
            cov,
        })
    }

    /// The diagonal of the covariance (per-level bootstrap variances).
    pub fn variances(&self) -> Vec<f64> {
        self.cov.diagonal().iter().copied().collect()
    }
}

/// METHODS §7.4 `cov_bootstrapper(H)`: the covariance of the WV vector over `replicates`
/// series of length `n` simulated from `model` (all values set), each analysed with `wv_opts`
/// (set `levels` to the observed J so that every replicate has the same levels).
///
/// # Errors
/// As [`map_replicates`]; [`ParamError`] for fewer than 2 replicates.
pub fn wv_bootstrap(
    model: &Model,
    n: usize,
    freq_hz: f64,
    wv_opts: &WvOptions,
    replicates: usize,
    seed: u64,
) -> Result<WvBootstrap, Error> {
    if replicates < 2 {
        return Err(ParamError::new(
            "replicates",
            replicates,
            "must be at least 2 for a covariance",
        )
        .into());
    }
    let samples = map_replicates(model, n, freq_hz, wv_opts, replicates, seed, |_, wv, _| {
        Ok::<_, Error>(wv.wv.clone())
    })?;
    WvBootstrap::from_samples(&samples)
}

/// The parametric bootstrap of a fit (the package's `all_bootstrapper`, METHODS §7.4): per
/// replicate the refit from `theta_hat` and, optionally, the objective of a fresh two-stage fit.
///
/// Wire format: `replicates`, `theta_hat`, `estimates` (B x p, replicate order), `mean`, `sd`,
/// `v` (J x J), `cross_cov` (J x J), `objectives` (B values or null), `not_converged`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitBootstrap {
    /// Number of replicates B.
    pub replicates: usize,
    /// The estimate the replicates were simulated from (model order).
    pub theta_hat: Vec<f64>,
    /// Replicate estimates `theta*_b` (refit from `theta_hat`, stage 2 only), B x p.
    pub estimates: Vec<Vec<f64>>,
    /// Mean of the replicate estimates.
    pub mean: Vec<f64>,
    /// Standard deviation of the replicate estimates (divisor B - 1).
    pub sd: Vec<f64>,
    /// `V = Cov(nu2_hat*)` (J x J, divisor B - 1).
    pub v: DMatrix<f64>,
    /// `C = Cov(nu2_hat*, nu2(theta*))` (J x J, divisor B - 1; row index the empirical WV
    /// level, column the implied one), the input of the WIC bootstrap optimism `2 tr(C Omega)`
    /// (METHODS §8.3).
    pub cross_cov: DMatrix<f64>,
    /// Final objective of a fresh two-stage fit per replicate (the bootstrap GoF input), when
    /// asked.
    pub objectives: Option<Vec<f64>>,
    /// Replicate refits whose optimiser did not report convergence (kept in the summaries).
    pub not_converged: usize,
}

/// One replicate's kept numbers.
struct ReplicateFit {
    theta: Vec<f64>,
    nu_hat: Vec<f64>,
    implied: Vec<f64>,
    objective: Option<f64>,
    converged: bool,
}

/// The weighting the replicates use: the fit's when it can be formed from one replicate
/// (`Diag`), else the fast weights (METHODS §7.4: "its (classical or robust) WV, CI and fast
/// Omega"; a bootstrap weighting would nest a bootstrap in every replicate).
pub(crate) fn replicate_weighting(gmwm: &Gmwm) -> Weighting {
    if gmwm.weighting() == Weighting::Diag {
        Weighting::Diag
    } else {
        Weighting::Fast
    }
}

/// Settings of [`fit_bootstrap`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct FitBootstrapOptions {
    /// Replicates B (at least 2).
    pub replicates: usize,
    /// Master seed of the replicates.
    pub seed: u64,
    /// `Some(G)`: also fit each replicate from a fresh search with G draws (bootstrap GoF).
    pub gof_draws: Option<usize>,
}

/// METHODS §7.4 `all_bootstrapper(B)`: simulates `replicates` series of length `n` from the
/// fitted model (rate `fit.freq_hz`), computes each one's WV with `wv_opts` (its `levels` is
/// set to the fit's J) and weights, and refits from `fit.theta` (stage 2 only). Components the
/// fit drove to the boundary are left out of the simulation and held there: the active
/// sub-model is refitted ([`GmwmFit::active_sub_model`]). With `gof_draws = Some(G)` each
/// replicate is also fitted from a fresh starting-value search with G draws (METHODS §6,
/// seeded per replicate) and its final objective kept.
///
/// Replicate `r` simulates with [`replicate_seed`]`(seed, r)` and searches starting values with
/// `replicate_seed(seed + 1, r)`: results do not depend on the thread count. Memory: one series
/// buffer per thread plus `p + 2J + 1` numbers per replicate. `progress` hears of every finished
/// replicate.
///
/// Cost: B x (simulation + WV + one stage-2 fit [+ G draws and a two-stage fit]).
///
/// # Errors
/// [`FitError::Engine`] with a [`ParamError`] for fewer than 2 replicates or `n == 0`; errors of
/// the simulation, the WV, the weights and the replicate fits (the first one met).
pub fn fit_bootstrap(
    gmwm: &Gmwm,
    fit: &GmwmFit,
    n: usize,
    wv_opts: &WvOptions,
    settings: &FitBootstrapOptions,
    progress: &dyn Progress,
) -> Result<FitBootstrap, FitError> {
    let FitBootstrapOptions {
        replicates,
        seed,
        gof_draws,
    } = *settings;
    if replicates < 2 {
        return Err(Error::from(ParamError::new(
            "replicates",
            replicates,
            "must be at least 2 for a bootstrap covariance",
        ))
        .into());
    }
    let levels = fit.nu_hat.len();
    let opts = WvOptions {
        levels: Some(levels),
        ..*wv_opts
    };
    let weighting = replicate_weighting(gmwm);
    // components at the boundary are held there: refit the active sub-model (crate::fit::active)
    let sub = fit.active_sub_model()?;
    let (refitter, start) = match &sub {
        Some(s) => (gmwm.for_model(s.model.clone()), s.start.clone()),
        None => (gmwm.clone(), fit.theta.clone()),
    };
    let refitter = refitter.with_weighting(weighting);
    let mut searcher = gmwm.clone().with_weighting(weighting);
    if let Some(g) = gof_draws {
        searcher = searcher.with_draws(g);
    }
    searcher.given = vec![None; fit.theta.len()];
    let done = AtomicUsize::new(0);
    progress.start(replicates);
    let reps = map_replicates(
        &fit.active_model()?,
        n,
        fit.freq_hz,
        &opts,
        replicates,
        seed,
        |r, wv, x| -> Result<ReplicateFit, FitError> {
            let weights = Weights::new(weighting, wv, Some(x))?;
            let refit = refitter.fit_weighted(&wv.wv, weights, fit.freq_hz, &start)?;
            let objective = match gof_draws {
                Some(_) => {
                    let s = searcher
                        .clone()
                        .with_seed(replicate_seed(seed.wrapping_add(1), r as u64));
                    let f = if weighting == Weighting::Diag {
                        s.fit(x, fit.freq_hz, &opts)?
                    } else {
                        s.fit_from_wv(wv, StartInputs::from_series(x))?
                    };
                    Some(f.objective)
                }
                None => None,
            };
            progress.advance(done.fetch_add(1, Ordering::Relaxed) + 1);
            Ok(ReplicateFit {
                converged: refit.convergence.converged,
                theta: match &sub {
                    Some(s) => s.expand(&refit.theta, &fit.theta),
                    None => refit.theta,
                },
                nu_hat: wv.wv.clone(),
                implied: refit.implied_wv.wv,
                objective,
            })
        },
    )?;
    let b = reps.len();
    let p = fit.theta.len();
    let mean: Vec<f64> = (0..p)
        .map(|k| reps.iter().map(|r| r.theta[k]).sum::<f64>() / b as f64)
        .collect();
    let sd = (0..p)
        .map(|k| {
            let ss: f64 = reps.iter().map(|r| (r.theta[k] - mean[k]).powi(2)).sum();
            (ss / (b - 1) as f64).sqrt()
        })
        .collect();
    let mean_hat = column_means(reps.iter().map(|r| &r.nu_hat[..]), levels, b);
    let mean_imp = column_means(reps.iter().map(|r| &r.implied[..]), levels, b);
    let mut v = DMatrix::zeros(levels, levels);
    let mut cross = DMatrix::zeros(levels, levels);
    for r in &reps {
        let dh = DVector::from_column_slice(&r.nu_hat) - &mean_hat;
        let di = DVector::from_column_slice(&r.implied) - &mean_imp;
        v.ger(1.0, &dh, &dh, 1.0);
        cross.ger(1.0, &dh, &di, 1.0);
    }
    v /= (b - 1) as f64;
    cross /= (b - 1) as f64;
    let objectives = gof_draws.map(|_| reps.iter().filter_map(|r| r.objective).collect());
    Ok(FitBootstrap {
        replicates: b,
        theta_hat: fit.theta.clone(),
        not_converged: reps.iter().filter(|r| !r.converged).count(),
        estimates: reps.into_iter().map(|r| r.theta).collect(),
        mean,
        sd,
        v,
        cross_cov: cross,
        objectives,
    })
}

fn column_means<'a>(
    rows: impl Iterator<Item = &'a [f64]>,
    levels: usize,
    b: usize,
) -> DVector<f64> {
    let mut m = DVector::zeros(levels);
    for r in rows {
        m += DVector::from_column_slice(r);
    }
    m / b as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn covariance_of_known_samples() {
        let s = vec![vec![1.0, 2.0], vec![3.0, 2.0], vec![2.0, 5.0]];
        let b = WvBootstrap::from_samples(&s).unwrap();
        assert_eq!(b.mean, vec![2.0, 3.0]);
        // var(1,3,2) = 1, var(2,2,5) = 3, cov = ((-1)(-1) + (1)(-1) + 0*2)/2 = 0
        assert!((b.cov[(0, 0)] - 1.0).abs() < 1e-15);
        assert!((b.cov[(1, 1)] - 3.0).abs() < 1e-15);
        assert!(b.cov[(0, 1)].abs() < 1e-15);
        assert!(WvBootstrap::from_samples(&s[..1]).is_err());
    }

    #[test]
    fn replicates_do_not_depend_on_thread_count() {
        let m = Model::parse("AR1(phi=0.9, sigma2=1)+WN(sigma2=2)").unwrap();
        let opts = WvOptions {
            levels: Some(6),
            ..WvOptions::default()
        };
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| wv_bootstrap(&m, 500, 1.0, &opts, 16, 7).unwrap())
        };
        assert_eq!(run(1), run(2));
    }

    #[test]
    fn white_noise_bootstrap_variance_matches_theory() {
        // WN(sigma2 = 1), level 1 (tau = 2): nu2 = 1/2, and Var(nu2_hat) ~ 2 * nu2^2 / edf with
        // edf ~ 2M/3 for white noise at level 1 (Haar MODWT), M = N - 1.
        let m = Model::parse("WN(sigma2=1)").unwrap();
        let opts = WvOptions {
            levels: Some(3),
            ..WvOptions::default()
        };
        let n = 4000;
        let b = wv_bootstrap(&m, n, 1.0, &opts, 400, 11).unwrap();
        assert!((b.mean[0] - 0.5).abs() < 0.01, "{:?}", b.mean);
        let theory = 2.0 * 0.25 / (2.0 * (n - 1) as f64 / 3.0);
        // 400 replicates: the sample variance has relative SE sqrt(2/399) ~ 7%; 4 SE
        assert!(
            (b.cov[(0, 0)] / theory - 1.0).abs() < 0.28,
            "{} vs {theory}",
            b.cov[(0, 0)]
        );
    }
}
