//! `V`, the covariance of the wavelet-variance vector at a model's estimate, behind the
//! sandwich intervals, the J-test and the WIC optimism: computed exactly
//! ([`crate::variance::implied_cov`]) or estimated by the parametric bootstrap of docs/methods.md
//! §7.4.
//!
//! The bootstrap estimates the same matrix with Monte Carlo noise of about `sqrt(2/H)` per
//! entry (14% at the package's H = 100, 20% at the selection's 50), and costs `H` simulations
//! and WVs of the series' length: most of the time of `fit --inference`, `select` and
//! `calibrate` on long recordings, and minutes at 10^8 samples. The exact matrix costs a
//! fraction of a second at any length. [`CovarianceMethod::Auto`] (default) takes it whenever
//! the model's processes and the estimator are covered and falls back to the bootstrap
//! otherwise; [`CovarianceMethod::Bootstrap`] reproduces the package.

use super::bootstrap::{map_replicates, WvBootstrap};
use crate::error::InputError;
use crate::model::Model;
use crate::progress::Progress;
use crate::variance::implied_cov::exact_covariance_of;
use crate::variance::wv::WvOptions;
use crate::wavelet::{Transform, WaveletFilter};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicUsize, Ordering};

/// How `V` is obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CovarianceMethod {
    /// Exact when the model (WN, QN, RW, DR, AR1, GM, MA1, ARMA11 with `phi >= 0`) and the
    /// estimator (Haar MODWT) are covered, the bootstrap otherwise (default).
    #[default]
    Auto,
    /// Exact, or an error naming what is not covered.
    Exact,
    /// Parametric bootstrap (docs/methods.md §7.4), as the package.
    Bootstrap,
}

crate::names::named_values!(CovarianceMethod, "covariance", {
    Auto => "auto",
    Exact => "exact",
    Bootstrap => "bootstrap",
}, derive(FromStr, Display));

impl CovarianceMethod {
    /// Lower-case name, as on the command line and in JSON.
    pub fn name(&self) -> &'static str {
        crate::names::Named::name(*self)
    }
}

/// A covariance `V` of the WV vector and how it was obtained.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct WvCovariance {
    /// `J x J`.
    pub(crate) v: DMatrix<f64>,
    /// Replicates behind a bootstrap `V`; `None` for the exact one.
    pub(crate) replicates: Option<usize>,
}

impl WvCovariance {}

/// How a V was obtained: the bootstrap's replicates, or `None` for the exact V.
///
/// Wire format (flattened into the result that carries it): `v_method` (`"exact"` or
/// `"bootstrap"`) and `v_replicates` (null when exact).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct VSource(pub(crate) Option<usize>);

impl VSource {
    /// `"exact"` or `"bootstrap"`.
    pub(crate) fn method(&self) -> &'static str {
        match self.0 {
            None => "exact",
            Some(_) => "bootstrap",
        }
    }

    /// Replicates behind a bootstrap V; `None` when exact.
    pub(crate) fn replicates(&self) -> Option<usize> {
        self.0
    }
}

impl Serialize for VSource {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut st = s.serialize_struct("VSource", 2)?;
        st.serialize_field("v_method", self.method())?;
        st.serialize_field("v_replicates", &self.0)?;
        st.end()
    }
}

/// `V` of the WV (estimator `wv_opts`, whose `levels` must be set) of `n`-sample series drawn
/// from `model` (all values set) at `freq_hz`, by `method`; a bootstrap uses `replicates`
/// series seeded with `seed` and reports each to `progress`. The exact `V` of a robust WV is
/// the classical one over the efficiency (docs/methods.md §1.10).
///
/// # Errors
/// [`InputError`] for a model without values, a bad rate or levels; with
/// [`CovarianceMethod::Exact`], a process or estimator the formulas do not cover; with the
/// bootstrap, fewer than 2 replicates or a failed simulation.
// the bootstrap's own settings (replicates, seed, progress) sit beside the model's; a struct
// for them would be used by this function alone
#[allow(clippy::too_many_arguments)]
pub(crate) fn wv_covariance(
    model: &Model,
    n: usize,
    freq_hz: f64,
    wv_opts: &WvOptions,
    method: CovarianceMethod,
    replicates: usize,
    seed: u64,
    progress: &dyn Progress,
) -> Result<WvCovariance, InputError> {
    let levels = wv_opts.levels.ok_or_else(|| {
        crate::ParamError::new("levels", "none", "the number of levels of the WV")
    })?;
    if method != CovarianceMethod::Bootstrap {
        let exact =
            if wv_opts.transform != Transform::Modwt || wv_opts.filter != WaveletFilter::Haar {
                Err(crate::ParamError::new(
                    "wavelet",
                    format!("{} {}", wv_opts.filter.name(), wv_opts.transform.name()),
                    "the Haar MODWT for the exact WV covariance",
                )
                .into())
            } else {
                model
                    .processes(freq_hz)
                    .and_then(|p| Ok(exact_covariance_of(&p, n, levels)?))
            };
        match (exact, method) {
            (Ok(v), _) => {
                let v = match wv_opts.robust {
                    Some(r) => v / r.eff(),
                    None => v,
                };
                return Ok(WvCovariance {
                    v,
                    replicates: None,
                });
            }
            (Err(e), CovarianceMethod::Exact) => return Err(e),
            (Err(_), _) => {}
        }
    }
    if replicates < 2 {
        return Err(crate::ParamError::new(
            "replicates",
            replicates,
            "must be at least 2 for a covariance",
        )
        .into());
    }
    let done = AtomicUsize::new(0);
    progress.start(replicates);
    let samples = map_replicates(model, n, freq_hz, wv_opts, replicates, seed, |_, wv, _| {
        progress.advance(done.fetch_add(1, Ordering::Relaxed) + 1);
        Ok::<_, InputError>(wv.wv.clone())
    })?;
    Ok(WvCovariance {
        v: WvBootstrap::from_samples(&samples)?.cov,
        replicates: Some(replicates),
    })
}

/// `V` of a pooled WV (docs/methods.md §5.12, [`crate::variance::pooled`]): `sum_k D_k V_k D_k'`
/// with `V_k` the covariance of recording k's WV by [`wv_covariance`] at its own length and
/// levels (a bootstrap one seeded with `replicate_seed(seed, k)`) and `D_k` its weights. The
/// source is exact when every `V_k` is.
///
/// # Errors
/// As [`wv_covariance`].
pub(crate) fn pooled_wv_covariance(
    model: &Model,
    pooled: &crate::variance::pooled::PooledWv,
    method: CovarianceMethod,
    replicates: usize,
    seed: u64,
    progress: &dyn Progress,
) -> Result<WvCovariance, InputError> {
    let levels = pooled.wv().levels();
    let mut v = DMatrix::zeros(levels, levels);
    let mut simulated = None;
    for (k, part) in pooled.parts().iter().enumerate() {
        let vk = wv_covariance(
            model,
            part.n(),
            part.freq_hz(),
            &part.options(),
            method,
            replicates,
            crate::sim::replicate_seed(seed, k as u64),
            progress,
        )?;
        let w = pooled.weights(k);
        for a in 0..w.len() {
            for b in 0..w.len() {
                v[(a, b)] += w[a] * w[b] * vk.v[(a, b)];
            }
        }
        simulated = simulated.or(vk.replicates);
    }
    Ok(WvCovariance {
        v,
        replicates: simulated,
    })
}
