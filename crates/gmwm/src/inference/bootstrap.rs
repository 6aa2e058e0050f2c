//! Parametric bootstrap of a fit (docs/methods.md §7.4): each replicate simulates a new series of
//! the observed length from the fitted model, computes its WV with the observed settings and
//! refits. The WV part ([`map_replicates`], [`wv_bootstrap`], [`WvBootstrap`]) lives in
//! [`crate::sim::bootstrap`], which the fit's bootstrap weights use too, and is re-exported here.
//!
//! Replicate `r` uses the seed [`replicate_seed`]`(seed, r)`, so results do not depend on the
//! thread count or on the order in which rayon runs the replicates. Each worker thread reuses
//! one series buffer: memory is `threads x N` samples plus what the caller keeps per replicate.

use crate::error::ParamError;
use crate::fit::{FitError, Gmwm, GmwmFit, StartInputs, Weighting, Weights};
use crate::progress::Progress;
pub(crate) use crate::sim::bootstrap::map_replicates;
#[cfg(test)]
pub(crate) use crate::sim::bootstrap::wv_bootstrap;
use crate::sim::replicate_seed;
use crate::variance::wv::WvOptions;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The parametric bootstrap of a fit (the package's `all_bootstrapper`, docs/methods.md §7.4): per
/// replicate the refit from `theta_hat` and, optionally, the objective of a fresh two-stage fit.
///
/// Wire format: `replicates`, `theta_hat`, `estimates` (B x p, replicate order), `mean`, `sd`,
/// `v` (J x J), `cross_cov` (J x J), `objectives` (B values or null), `not_converged`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(crate) struct FitBootstrap {
    /// Number of replicates B.
    pub(crate) replicates: usize,
    /// The estimate the replicates were simulated from (model order).
    pub(crate) theta_hat: Vec<f64>,
    /// Replicate estimates `theta*_b` (refit from `theta_hat`, stage 2 only), B x p.
    pub(crate) estimates: Vec<Vec<f64>>,
    /// Mean of the replicate estimates.
    pub(crate) mean: Vec<f64>,
    /// Standard deviation of the replicate estimates (divisor B - 1).
    pub(crate) sd: Vec<f64>,
    /// `V = Cov(nu2_hat*)` (J x J, divisor B - 1).
    pub(crate) v: DMatrix<f64>,
    /// `C = Cov(nu2_hat*, nu2(theta*))` (J x J, divisor B - 1; row index the empirical WV
    /// level, column the implied one), the input of the WIC bootstrap optimism `2 tr(C Omega)`
    /// (docs/methods.md §8.3).
    pub(crate) cross_cov: DMatrix<f64>,
    /// Final objective of a fresh two-stage fit per replicate (the bootstrap GoF input), when
    /// asked.
    pub(crate) objectives: Option<Vec<f64>>,
    /// Replicate refits whose optimiser did not report convergence (kept in the summaries).
    pub(crate) not_converged: usize,
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
/// (`Diag`), else the fast weights (docs/methods.md §7.4: "its (classical or robust) WV, CI and
/// fast Omega"; a bootstrap weighting would nest a bootstrap in every replicate).
pub(crate) fn replicate_weighting(gmwm: &Gmwm) -> Weighting {
    if gmwm.weighting() == Weighting::Diag {
        Weighting::Diag
    } else {
        Weighting::Fast
    }
}

/// Settings of [`fit_bootstrap`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub(crate) struct FitBootstrapOptions {
    /// Replicates B (at least 2).
    pub(crate) replicates: usize,
    /// Master seed of the replicates.
    pub(crate) seed: u64,
    /// `Some(G)`: also fit each replicate from a fresh search with G draws (bootstrap GoF).
    pub(crate) gof_draws: Option<usize>,
}

/// docs/methods.md §7.4 `all_bootstrapper(B)`: simulates `replicates` series of length `n` from the
/// fitted model (rate `fit.freq_hz`), computes each one's WV with `wv_opts` (its `levels` is
/// set to the fit's J) and weights, and refits from `fit.theta` (stage 2 only). Components the
/// fit drove to the boundary are left out of the simulation and held there: the active
/// sub-model is refitted ([`GmwmFit::active_sub_model`]). With `gof_draws = Some(G)` each
/// replicate is also fitted from a fresh starting-value search with G draws (docs/methods.md §6,
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
/// [`FitError::Input`] with a [`ParamError`] for fewer than 2 replicates or `n == 0`; errors of
/// the simulation, the WV, the weights and the replicate fits (the first one met).
pub(crate) fn fit_bootstrap(
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
        return Err(ParamError::new(
            "replicates",
            replicates,
            "must be at least 2 for a bootstrap covariance",
        )
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
                    None => refit.estimates.theta,
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
