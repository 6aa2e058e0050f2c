//! Leaving a false boundary point: an active-set step for components fitted to nothing.
//!
//! The optimiser works on log-scaled variances (docs/methods.md §5.3). A variance that a poor start
//! drives towards zero reaches values like 1e-30 within a few steps; its component then has no
//! measurable influence ([`COLLAPSE_INFLUENCE`](super::optimize::COLLAPSE_INFLUENCE)) and,
//! in log coordinates, no usable gradient either, even when the data need it back: the fit
//! stops at a boundary point that is not a constrained minimum (the Karush–Kuhn–Tucker
//! condition `dQ/dtheta_k >= 0` fails in the natural scale). Seen on `2*AR1()+WN()+RW()`
//! fitted to AR1+WN+RW data: in one fit in five the RW (or the true AR1) was lost and `Q`
//! stayed ~30 times above the fit that keeps it.
//!
//! After each minimisation, every inactive component (implied WV below
//! [`NEGLIGIBLE_WV_SHARE`](super::NEGLIGIBLE_WV_SHARE) of the model's at every level) is tried back at its best size: the
//! WV is linear in the scale parameter (WN `sigma2`, QN `q2`, RW `gamma2`, DR `omega^2`, AR1
//! `sigma2` and GM `sigma2_gm` at a fixed phi or beta), so with `s` the component's WV at unit
//! scale and `r = nu2(theta) - nu2_hat`, the best size is `t = -s' Omega r / s' Omega s` and
//! the objective falls by about `(s' Omega r)^2 / s' Omega s` when `s' Omega r < 0` (exactly
//! so but for the component's own negligible WV, which `r` still contains). AR1/GM shapes are
//! tried on a grid of correlation lengths `2^((m - 2) / 2)` samples, m = 0 ..= 2J + 4 (0.5 to
//! `2^(J + 1)`), which covers every level; the ARMA family is not revived. The largest fall
//! above [`REVIVAL_MIN_GAIN`] of `Q` gives the start of a new minimisation, kept only if it
//! ends lower; at most [`MAX_REVIVALS`] times per fit.

use super::active::active_components;
use super::FitError;
use crate::model::{Component, ImpliedWv, Model, ProcessKind};
use crate::process::{spec, UnitShape};

/// Revivals per fit at most (each one a further minimisation).
pub(crate) const MAX_REVIVALS: usize = 3;

/// Smallest relative fall of the objective that revives a component. Below it the boundary
/// point is a minimum for every practical purpose.
pub(crate) const REVIVAL_MIN_GAIN: f64 = 1e-6;

/// A start with the inactive component of `fitted` whose return lowers the objective most
/// (see the module docs), or `None` when none lowers it by more than [`REVIVAL_MIN_GAIN`] of
/// `q`. `theta` is in `fitted`'s order and `implied` its implied WV; `omega` the diagonal
/// weights.
pub(crate) fn revival_start(
    fitted: &Model,
    theta: &[f64],
    implied: &ImpliedWv,
    nu_hat: &[f64],
    omega: &[f64],
    freq_hz: f64,
    q: f64,
) -> Result<Option<Vec<f64>>, FitError> {
    let levels = nu_hat.len();
    let r: Vec<f64> = implied.wv.iter().zip(nu_hat).map(|(a, b)| a - b).collect();
    let mut best: Option<(f64, usize, Vec<f64>)> = None;
    let mut at = 0;
    let active = active_components(implied);
    for (c, active) in fitted.components().iter().zip(active) {
        let k = c.kind.n_params();
        if !active {
            for (unit, scale) in unit_shapes(c.kind, levels, freq_hz) {
                let one = Model::new(vec![Component::new(
                    c.kind,
                    unit.iter().copied().map(Some).collect(),
                )?])?;
                let s = one.implied_wv(levels, freq_hz)?.wv;
                let (mut sr, mut ss) = (0.0, 0.0);
                for l in 0..levels {
                    sr += omega[l] * s[l] * r[l];
                    ss += omega[l] * s[l] * s[l];
                }
                if !(sr < 0.0 && ss > 0.0 && ss.is_finite()) {
                    continue;
                }
                let gain = sr * sr / ss;
                if gain > REVIVAL_MIN_GAIN * q && best.as_ref().map_or(true, |b| gain > b.0) {
                    let t = -sr / ss;
                    let mut values = unit.clone();
                    values[k - 1] = scale(t);
                    best = Some((gain, at, values));
                }
            }
        }
        at += k;
    }
    Ok(best.map(|(_, at, values)| {
        let mut start = theta.to_vec();
        start[at..at + values.len()].copy_from_slice(&values);
        start
    }))
}

/// The unit shapes of a component kind ([`Spec::unit_shapes`](crate::process::Spec)); none
/// for the ARMA family (not revived).
fn unit_shapes(kind: ProcessKind, levels: usize, freq_hz: f64) -> Vec<UnitShape> {
    (spec(kind).unit_shapes)(levels, freq_hz)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model(text: &str) -> Model {
        Model::parse(text).unwrap()
    }

    #[test]
    fn a_lost_random_walk_comes_back_at_its_exact_size() {
        // nu_hat of WN(1) + RW(1e-3); the fit lost the RW (1e-30): r = -1e-3 s_RW, so the
        // best size is exactly 1e-3 whatever the weights
        let levels = 12;
        let nu_hat = model("WN(sigma2=1)+RW(gamma2=1e-3)")
            .implied_wv(levels, 1.0)
            .unwrap()
            .wv;
        let lost = model("WN(sigma2=1)+RW(gamma2=1e-30)");
        let omega: Vec<f64> = nu_hat.iter().map(|v| 1.0 / (v * v)).collect();
        let q: f64 = 1.0;
        let start = revival_start(
            &lost,
            &[1.0, 1e-30],
            &lost.implied_wv(levels, 1.0).unwrap(),
            &nu_hat,
            &omega,
            1.0,
            q,
        )
        .unwrap()
        .unwrap();
        assert_eq!(start[0], 1.0);
        assert!((start[1] / 1e-3 - 1.0).abs() < 1e-12, "{start:?}");
    }

    #[test]
    fn a_lost_ar1_comes_back_on_the_grid_and_a_true_boundary_stays() {
        // AR1 with correlation length 8 samples (m = 8 on the grid) and sigma2 = 0.5
        let levels = 12;
        let phi = (-1.0f64 / 8.0).exp();
        let truth = Model::new(vec![
            Component::new(ProcessKind::Ar1, vec![Some(phi), Some(0.5)]).unwrap(),
            Component::new(ProcessKind::Wn, vec![Some(1.0)]).unwrap(),
        ])
        .unwrap();
        let nu_hat = truth.implied_wv(levels, 1.0).unwrap().wv;
        let omega = vec![1.0; levels];
        let lost = model("AR1(phi=0.3, sigma2=1e-40)+WN(sigma2=1)");
        let start = revival_start(
            &lost,
            &[0.3, 1e-40, 1.0],
            &lost.implied_wv(levels, 1.0).unwrap(),
            &nu_hat,
            &omega,
            1.0,
            1.0,
        )
        .unwrap()
        .unwrap();
        assert!((start[0] / phi - 1.0).abs() < 1e-12, "{start:?}");
        assert!((start[1] / 0.5 - 1.0).abs() < 1e-9, "{start:?}");
        // at the truth with a superfluous RW at 1e-30: nothing to revive (the residual is 0)
        let sup = Model::new(vec![
            truth.components()[0].clone(),
            truth.components()[1].clone(),
            Component::new(ProcessKind::Rw, vec![Some(1e-30)]).unwrap(),
        ])
        .unwrap();
        let none = revival_start(
            &sup,
            &[phi, 0.5, 1.0, 1e-30],
            &sup.implied_wv(levels, 1.0).unwrap(),
            &nu_hat,
            &omega,
            1.0,
            1e-20,
        )
        .unwrap();
        assert!(none.is_none());
    }
}
