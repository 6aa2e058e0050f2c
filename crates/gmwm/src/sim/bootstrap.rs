//! Parametric bootstrap of the wavelet variance (docs/methods.md §7.4): nothing is resampled from
//! the data; each replicate simulates a new series of the observed length from a (fitted) model and
//! computes its WV with the observed settings.
//!
//! This is the part of the bootstrap that needs only a model, the simulator and the wavelet
//! variance, so that the fit (bootstrap weights, docs/methods.md §5.2) and inference (§7.4) both
//! build on it without depending on each other; `gmwm::inference` re-exports it.
//!
//! Replicate `r` uses the seed [`replicate_seed`]`(seed, r)`, so results do not depend on the
//! thread count or on the order in which rayon runs the replicates. Each worker thread reuses
//! one series buffer: memory is `threads x N` samples plus what the caller keeps per replicate.

use crate::error::{InputError, ParamError};
use crate::model::Model;
use crate::sim::{replicate_seed, Simulator};
use crate::variance::wv::{wavelet_variance, WaveletVariance, WvOptions};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use serde::Serialize;

/// Runs `f` on `replicates` parametric-bootstrap replicates of `model` (length `n`, rate
/// `freq_hz`, WV computed with `wv_opts`) in parallel, and returns the results in replicate
/// order. `f` gets the replicate index, its WV and its series.
///
/// # Errors
/// [`ParamError`] for `replicates == 0` or `n == 0`; errors of [`Simulator::for_model`] (a
/// model with unset or invalid values) and of [`wavelet_variance`]; the first error of `f`.
pub(crate) fn map_replicates<T, E, F>(
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
    E: From<InputError> + Send,
    F: Fn(usize, &WaveletVariance, &[f64]) -> Result<T, E> + Sync + Send,
{
    if replicates == 0 {
        return Err(InputError::from(ParamError::new(
            "replicates",
            replicates,
            "must be at least 1",
        ))
        .into());
    }
    if n == 0 {
        return Err(InputError::from(ParamError::new("n", n, "must be at least 1")).into());
    }
    // fail early (and once) on a model that cannot be simulated
    Simulator::for_model(model, freq_hz, seed).map_err(E::from)?;
    // one series buffer per thread at a time, reused: rayon calls a `map_init` closure once
    // per job split, and a fresh n-length buffer per split cost a page fault per 4 KiB (at
    // n = 1e8, 800 MB per replicate and most of the system time)
    let pool: std::sync::Mutex<Vec<Vec<f64>>> = std::sync::Mutex::new(Vec::new());
    (0..replicates)
        .into_par_iter()
        .map(|r| {
            let taken = pool.lock().map(|mut p| p.pop()).unwrap_or(None);
            let mut x = taken.unwrap_or_else(|| vec![0.0; n]);
            let result = (|| {
                let mut sim = Simulator::for_model(model, freq_hz, replicate_seed(seed, r as u64))?;
                sim.fill(&mut x);
                let wv = wavelet_variance(&x, freq_hz, wv_opts)?;
                f(r, &wv, &x)
            })();
            if let Ok(mut p) = pool.lock() {
                p.push(x);
            }
            result
        })
        .collect()
}

/// The bootstrap distribution summary of the WV vector (the package's `cov_bootstrapper`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(crate) struct WvBootstrap {
    /// Number of replicates H.
    pub(crate) replicates: usize,
    /// Replicate mean of the WV, per level.
    pub(crate) mean: Vec<f64>,
    /// Full J x J covariance of the replicate WV vectors (divisor H - 1).
    pub(crate) cov: DMatrix<f64>,
}

impl WvBootstrap {
    /// Mean and covariance (divisor `H - 1`, two-pass) of replicate WV vectors of equal length.
    ///
    /// # Errors
    /// [`ParamError`] when fewer than two vectors are given or their lengths differ.
    pub(crate) fn from_samples(samples: &[Vec<f64>]) -> Result<Self, InputError> {
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
    pub(crate) fn variances(&self) -> Vec<f64> {
        self.cov.diagonal().iter().copied().collect()
    }
}

/// docs/methods.md §7.4 `cov_bootstrapper(H)`: the covariance of the WV vector over `replicates`
/// series of length `n` simulated from `model` (all values set), each analysed with `wv_opts`
/// (set `levels` to the observed J so that every replicate has the same levels).
///
/// # Errors
/// As [`map_replicates`]; [`ParamError`] for fewer than 2 replicates.
pub(crate) fn wv_bootstrap(
    model: &Model,
    n: usize,
    freq_hz: f64,
    wv_opts: &WvOptions,
    replicates: usize,
    seed: u64,
) -> Result<WvBootstrap, InputError> {
    if replicates < 2 {
        return Err(ParamError::new(
            "replicates",
            replicates,
            "must be at least 2 for a covariance",
        )
        .into());
    }
    let samples = map_replicates(model, n, freq_hz, wv_opts, replicates, seed, |_, wv, _| {
        Ok::<_, InputError>(wv.wv.clone())
    })?;
    WvBootstrap::from_samples(&samples)
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
