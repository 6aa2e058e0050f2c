//! Model selection on several recordings at once (docs/methods.md §5.11, §8): the WIC of each
//! candidate on the pooled criterion.
//!
//! Each candidate is fitted to all recordings ([`Gmwm::fit_pooled`]); its apparent loss is
//! `Q_pool(theta_hat)` and its optimism the asymptotic one of §8.2 (corrected form) on the
//! stacked matrices: `A` the stacked Jacobians, `Omega` and `V` block diagonal (independent
//! recordings; `V` exact at the **full** model's pooled estimate and each recording's `N_k`, as
//! the single-recording selection takes the full model's V), `D` from the stacked Hessians and
//! residuals. Because every matrix is block diagonal, `tr(Omega A dTheta V)` is the sum over
//! recordings of each block's share, with one `dTheta = (B + D)^+ A' Omega` of the pooled
//! problem. `WIC = Q_pool + optimism`; the selected candidate is the smallest WIC.
//!
//! Simpler than the single-recording [`super::Wic`]: candidates are not merged into canonical
//! rows and no one-standard-error rule is applied (the table shows the WIC differences; the
//! user chooses among near-equal rows).

use super::candidates::nested_candidates;
use super::optimism::{asymptotic_optimism, d_matrix, OptimismConvention};
use crate::fit::{FitError, FitRecording, Gmwm, PooledFit};
use nalgebra::DMatrix;
use rayon::prelude::*;
use serde::Serialize;

/// One candidate of a pooled selection.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PooledCandidate {
    /// The candidate's template (no values).
    pub candidate: String,
    /// Its pooled fit (model with the estimates).
    pub fitted: String,
    /// Number of parameters.
    pub params: usize,
    /// `Q_pool(theta_hat)`.
    pub objective: f64,
    /// Asymptotic optimism on the stacked matrices.
    pub optimism: f64,
    /// `objective + optimism`.
    pub wic: f64,
}

/// The result of [`select_pooled`]: candidates by increasing WIC, the first selected.
#[derive(Debug, Clone, Serialize)]
pub struct PooledSelection {
    /// Candidates, smallest WIC first.
    pub candidates: Vec<PooledCandidate>,
    /// The selected candidate's pooled fit.
    #[serde(skip)]
    pub selected: PooledFit,
}

/// docs/methods.md §5.11 with §8: the nested candidates of `gmwm`'s model (§8.4), each
/// fitted to all `recordings`, ranked by the pooled WIC (module doc); `seed` seeds a bootstrap
/// V where the exact one does not cover the full model.
///
/// # Errors
/// Errors of the candidates (§8.5 refusals, as [`FitError::Input`]), of the pooled fits and
/// of the full model's covariance.
pub fn select_pooled(
    gmwm: &Gmwm,
    recordings: &[FitRecording],
    seed: u64,
) -> Result<PooledSelection, FitError> {
    let full = gmwm.fit_pooled(recordings)?;
    let candidates = nested_candidates(gmwm.model())
        .map_err(|e| crate::ParamError::new("model", gmwm.model(), e.to_string()))?;
    let full_model = full.model().clone();
    let rows: Vec<(PooledCandidate, PooledFit)> = candidates
        .par_iter()
        .map(|c| {
            let fit = if c == gmwm.model() {
                full.clone()
            } else {
                gmwm.for_model(c.clone()).fit_pooled(recordings)?
            };
            let st = fit.stacked(&full_model, seed)?;
            let omega = DMatrix::from_diagonal(&st.omega);
            let d = d_matrix(&st.hessian, &omega, &st.implied, &st.nu_hat)?;
            let optimism =
                asymptotic_optimism(&st.a, &d, &omega, &st.v, OptimismConvention::Corrected)?;
            Ok((
                PooledCandidate {
                    candidate: c.to_string(),
                    fitted: fit.model().to_string(),
                    params: c.n_params(),
                    objective: fit.objective(),
                    optimism,
                    wic: fit.objective() + optimism,
                },
                fit,
            ))
        })
        .collect::<Result<_, FitError>>()?;
    let mut rows = rows;
    rows.sort_by(|a, b| a.0.wic.total_cmp(&b.0.wic));
    let selected = rows[0].1.clone();
    Ok(PooledSelection {
        candidates: rows.into_iter().map(|r| r.0).collect(),
        selected,
    })
}
