//! The GMWM objective on the unconstrained parameters (docs/methods.md §5.1, §5.4).
//!
//! `Q(u) = sum_j omega_j (nu2_hat_j - nu2_j(theta(u)))^2 = sum_j r_j^2` with whitened residuals
//! `r_j = sqrt(omega_j) (nu2_hat_j - nu2_j)`. Wavelet variances span many decades (1e-6 to 1e-14
//! for an IMU), but with the fast or diag weights `sqrt(omega_j)` is about `1 / nu2_j` times a
//! level constant, so the whitened residuals are relative errors of order one and the
//! least-squares problem is well scaled; the transforms of §5.3 put every variance on a log scale.
//!
//! A full weighting `Omega = V^{-1}` ([`FullWeights`], e.g. the efficient weights of the J-test,
//! §7.3) whitens by a lower-triangular matrix instead: `r = W (nu2_hat - nu2)`, `W'W = Omega`.
//! The diagonal path is unchanged.

use super::augment::Augment;
use super::weights::FullWeights;
use super::{FitError, Parametrisation, Weights};
use crate::model::Model;
use crate::process::LatentProcess;

/// The objective of one fit: a model template, the target WV, the weights and the transforms.
#[derive(Debug, Clone)]
pub(crate) struct Objective {
    model: Model,
    param: Parametrisation,
    nu_hat: Vec<f64>,
    sqrt_omega: Vec<f64>,
    /// Row-major J x J lower-triangular whitening matrix of a full weighting; `sqrt_omega` is
    /// then unused.
    whitening: Option<Vec<f64>>,
    freq_hz: f64,
    /// A stacked layout of several WVs or moments ([`Stack`]); `model` is then the first
    /// block's template.
    stack: Option<Stack>,
    /// GMWM+: extra moments after the WV levels (`super::augment`, docs/methods.md §5.15).
    augment: Option<Augment>,
}

/// The stacked moments of a multi-series fit: `rows.len()` blocks of moments, block `r`
/// holding levels `1..=levels[r]` and modelled by the sum of the implied WVs of the model
/// blocks `rows[r]`; the parameter vector is the concatenation of the model blocks'
/// parameters. A pooled fit (`crate::fit::pooled`, docs/methods.md §5.11) is one model block
/// and one row per recording, each with its own levels; the shared-process estimator
/// (`crate::shared`) has a shared and a specific block per axis, and rows of equal length for
/// the axes' WVs and their cross-covariances.
#[derive(Debug, Clone)]
pub(crate) struct Stack {
    /// Model blocks (templates) in parameter order.
    pub(crate) blocks: Vec<Model>,
    /// Per block of moments, the model blocks whose implied WVs add up to it.
    pub(crate) rows: Vec<Vec<usize>>,
    /// Levels of each block of moments.
    pub(crate) levels: Vec<usize>,
}

impl Stack {
    /// Parameter offset of each model block.
    pub(crate) fn offsets(&self) -> Vec<usize> {
        let mut at = 0;
        self.blocks
            .iter()
            .map(|m| {
                let o = at;
                at += m.n_params();
                o
            })
            .collect()
    }

    /// Number of moments: the rows' levels summed.
    pub(crate) fn moments(&self) -> usize {
        self.levels.iter().sum()
    }
}

/// Residuals and their Jacobian at one `u` (reused buffers).
#[derive(Debug, Clone)]
pub(crate) struct Eval {
    /// theta(u).
    pub(crate) theta: Vec<f64>,
    /// d theta / d u, row-major p x p.
    pub(crate) dtheta: Vec<f64>,
    /// Whitened residuals, J.
    pub(crate) r: Vec<f64>,
    /// d r / d u, row-major J x p.
    pub(crate) jac: Vec<f64>,
    /// Implied WV nu2(theta), J.
    pub(crate) nu: Vec<f64>,
}

impl Objective {
    /// The objective of `model` (values ignored) against `nu2_hat` with weights `weights` at
    /// `freq_hz` (used by GM terms, docs/methods.md §4.3).
    ///
    /// # Errors
    /// [`FitError::Length`] when the weights, WV or parametrisation disagree in size;
    /// [`FitError::BadWv`] for a non-finite or non-positive `nu2_hat_j`;
    /// [`FitError::TooFewLevels`] when the model has more parameters than levels (§5.7).
    pub(crate) fn new(
        model: &Model,
        param: Parametrisation,
        nu_hat: &[f64],
        weights: &Weights,
        freq_hz: f64,
    ) -> Result<Self, FitError> {
        let sqrt_omega = weights.omega.iter().map(|w| w.sqrt()).collect();
        Self::build(model, param, nu_hat, sqrt_omega, None, freq_hz)
    }

    /// The objective of stacked moments (module [`Stack`]) with diagonal weights: unlike a WV,
    /// a moment may be zero or negative (a cross-covariance).
    ///
    /// # Errors
    /// [`FitError::Length`] when the sizes disagree; [`FitError::BadWv`] for a non-finite
    /// moment or weight; [`FitError::TooFewLevels`] with more parameters than moments.
    pub(crate) fn stacked_moments(
        stack: Stack,
        param: Parametrisation,
        moments: &[f64],
        omega: &[f64],
        freq_hz: f64,
    ) -> Result<Self, FitError> {
        let rows = stack.moments();
        let p: usize = stack.blocks.iter().map(Model::n_params).sum();
        for (what, found) in [("moments", moments.len()), ("weights", omega.len())] {
            if found != rows {
                return Err(FitError::Length {
                    what,
                    expected: rows,
                    found,
                });
            }
        }
        if param.n_params() != p {
            return Err(FitError::Length {
                what: "parametrisation",
                expected: p,
                found: param.n_params(),
            });
        }
        if let Some((j, &value)) = moments
            .iter()
            .zip(omega)
            .enumerate()
            .find(|(_, (m, w))| !(m.is_finite() && w.is_finite() && **w > 0.0))
            .map(|(j, (m, _))| (j, m))
        {
            // the level within its block of moments
            let mut level = j;
            for &l in &stack.levels {
                if level < l {
                    break;
                }
                level -= l;
            }
            return Err(FitError::BadWv {
                level: level + 1,
                value,
            });
        }
        if p > rows {
            return Err(FitError::TooFewLevels {
                params: p,
                levels: rows,
            });
        }
        Ok(Self {
            model: stack.blocks[0].without_values(),
            param,
            nu_hat: moments.to_vec(),
            sqrt_omega: omega.iter().map(|w| w.sqrt()).collect(),
            whitening: None,
            freq_hz,
            stack: Some(stack),
            augment: None,
        })
    }

    /// The objective with a full weighting `Omega = V^{-1}` (docs/methods.md §5.1 with a
    /// non-diagonal Omega, e.g. the efficient weights of §7.3): `Q = (nu2_hat - nu2)' Omega
    /// (nu2_hat - nu2)`, minimised through the whitened residuals `W (nu2_hat - nu2)`.
    ///
    /// # Errors
    /// As [`Objective::new`].
    pub(crate) fn with_full_weights(
        model: &Model,
        param: Parametrisation,
        nu_hat: &[f64],
        weights: &FullWeights,
        freq_hz: f64,
    ) -> Result<Self, FitError> {
        let w = weights.whitening();
        let n = w.nrows();
        let whitening = (0..n * n).map(|k| w[(k / n, k % n)]).collect();
        Self::build(model, param, nu_hat, vec![1.0; n], Some(whitening), freq_hz)
    }

    fn build(
        model: &Model,
        param: Parametrisation,
        nu_hat: &[f64],
        sqrt_omega: Vec<f64>,
        whitening: Option<Vec<f64>>,
        freq_hz: f64,
    ) -> Result<Self, FitError> {
        if sqrt_omega.len() != nu_hat.len() {
            return Err(FitError::Length {
                what: "weights",
                expected: nu_hat.len(),
                found: sqrt_omega.len(),
            });
        }
        if param.n_params() != model.n_params() {
            return Err(FitError::Length {
                what: "parametrisation",
                expected: model.n_params(),
                found: param.n_params(),
            });
        }
        if let Some((j, &value)) = nu_hat
            .iter()
            .enumerate()
            .find(|(_, v)| !(v.is_finite() && **v > 0.0))
        {
            return Err(FitError::BadWv {
                level: j + 1,
                value,
            });
        }
        if model.n_params() > nu_hat.len() {
            return Err(FitError::TooFewLevels {
                params: model.n_params(),
                levels: nu_hat.len(),
            });
        }
        Ok(Self {
            model: model.without_values(),
            param,
            nu_hat: nu_hat.to_vec(),
            sqrt_omega,
            whitening,
            freq_hz,
            stack: None,
            augment: None,
        })
    }

    /// The GMWM+ objective (docs/methods.md §5.15): the WV (its first levels of `moments`)
    /// followed by the `augment` moments, with a full weighting over all of them.
    ///
    /// # Errors
    /// As [`Objective::with_full_weights`]; [`FitError::Length`] when `moments` does not hold
    /// more than the extra moments or the weights are of another size.
    pub(crate) fn augmented(
        model: &Model,
        param: Parametrisation,
        moments: &[f64],
        augment: Augment,
        weights: &FullWeights,
        freq_hz: f64,
    ) -> Result<Self, FitError> {
        let total = moments.len();
        let levels = total.checked_sub(augment.len()).filter(|&j| j > 0);
        let (Some(levels), true) = (levels, weights.levels() == total) else {
            return Err(FitError::Length {
                what: "augmented moments",
                expected: weights.levels(),
                found: total,
            });
        };
        if let Some((i, &value)) = moments[levels..]
            .iter()
            .enumerate()
            .find(|(_, v)| !v.is_finite())
        {
            return Err(FitError::BadWv {
                level: levels + i + 1,
                value,
            });
        }
        let mut obj = Self::build(
            model,
            param,
            &moments[..levels],
            vec![1.0; levels],
            None,
            freq_hz,
        )?;
        let w = weights.whitening();
        obj.whitening = Some(
            (0..total * total)
                .map(|k| w[(k / total, k % total)])
                .collect(),
        );
        obj.nu_hat.extend_from_slice(&moments[levels..]);
        obj.sqrt_omega.resize(total, 1.0);
        obj.augment = Some(augment);
        Ok(obj)
    }

    /// The pooled objective of several WVs of the same model (docs/methods.md §5.11):
    /// `Q(theta) = sum_k (nu2_hat_k - nu2_(J_k)(theta))' Omega_k (nu2_hat_k - nu2_(J_k)(theta))`,
    /// one block per recording with its own levels `J_k` and weights. `blocks` gives each
    /// recording's WV and its whitening: `Err` a diagonal one (`sqrt(omega_j)`), `Ok` a full
    /// [`FullWeights`] (block `k` of a block-diagonal `W`). The least-squares problem is the
    /// concatenation of the blocks' whitened residuals, so the optimiser, the value and the
    /// gradient are those of one WV.
    ///
    /// # Errors
    /// As [`Objective::new`] on the concatenation; [`FitError::Length`] when a block's weights
    /// and WV differ in size or no block is given.
    pub(crate) fn stacked(
        model: &Model,
        param: Parametrisation,
        blocks: &[(&[f64], Result<&FullWeights, &Weights>)],
        freq_hz: f64,
    ) -> Result<Self, FitError> {
        if blocks.is_empty() {
            return Err(FitError::Length {
                what: "recordings",
                expected: 1,
                found: 0,
            });
        }
        let total: usize = blocks.iter().map(|(nu, _)| nu.len()).sum();
        let full = blocks.iter().any(|(_, w)| w.is_ok());
        let mut nu_hat = Vec::with_capacity(total);
        let mut sqrt_omega = Vec::with_capacity(total);
        let mut whitening = full.then(|| vec![0.0; total * total]);
        let mut at = 0;
        for (nu, w) in blocks {
            let j = nu.len();
            let levels = match w {
                Ok(f) => f.levels(),
                Err(d) => d.levels(),
            };
            if levels != j {
                return Err(FitError::Length {
                    what: "weights",
                    expected: j,
                    found: levels,
                });
            }
            nu_hat.extend_from_slice(nu);
            match (w, whitening.as_mut()) {
                (Ok(f), Some(big)) => {
                    let m = f.whitening();
                    for r in 0..j {
                        for c in 0..=r {
                            big[(at + r) * total + at + c] = m[(r, c)];
                        }
                    }
                    sqrt_omega.extend(std::iter::repeat(1.0).take(j));
                }
                (Err(d), Some(big)) => {
                    for r in 0..j {
                        big[(at + r) * total + at + r] = d.omega[r].sqrt();
                    }
                    sqrt_omega.extend(std::iter::repeat(1.0).take(j));
                }
                (Err(d), None) => sqrt_omega.extend(d.omega.iter().map(|w| w.sqrt())),
                (Ok(_), None) => unreachable!("a full block makes the whitening full"),
            }
            at += j;
        }
        let mut obj = Self::build(model, param, &nu_hat, sqrt_omega, whitening, freq_hz)?;
        obj.stack = Some(Stack {
            blocks: vec![model.without_values()],
            rows: vec![vec![0]; blocks.len()],
            levels: blocks.iter().map(|(nu, _)| nu.len()).collect(),
        });
        Ok(obj)
    }

    /// Number of levels J.
    pub(crate) fn levels(&self) -> usize {
        self.nu_hat.len()
    }

    /// Number of parameters p.
    pub(crate) fn n_params(&self) -> usize {
        self.param.n_params()
    }

    /// The transforms.
    pub(crate) fn parametrisation(&self) -> &Parametrisation {
        &self.param
    }

    /// The model template (no values).
    pub(crate) fn model(&self) -> &Model {
        &self.model
    }

    /// `sum_j omega_j nu2_hat_j^2`, the objective at a zero implied WV: the scale of `Q`.
    pub(crate) fn scale(&self) -> f64 {
        if self.whitening.is_some() {
            let mut r = vec![0.0; self.levels()];
            self.whiten(&self.nu_hat, &mut r);
            return r.iter().map(|v| v * v).sum();
        }
        self.nu_hat
            .iter()
            .zip(&self.sqrt_omega)
            .map(|(h, s)| (h * s).powi(2))
            .sum()
    }

    /// `out = W e` for the full weighting (lower-triangular `W`); `out = e` otherwise.
    fn whiten(&self, e: &[f64], out: &mut [f64]) {
        let n = e.len();
        match &self.whitening {
            Some(w) => {
                for (i, o) in out.iter_mut().enumerate() {
                    *o = (0..=i).map(|k| w[i * n + k] * e[k]).sum();
                }
            }
            None => out.copy_from_slice(e),
        }
    }

    /// Implied WV `nu2(theta)` and, if asked, its Jacobian `A` (row-major J x p, docs/methods.md
    /// §4.5, original parametrisation) into the given buffers.
    pub(crate) fn implied(
        &self,
        theta: &[f64],
        nu: &mut [f64],
        a: Option<&mut [f64]>,
    ) -> Result<(), crate::InputError> {
        let np = self.n_params();
        nu.fill(0.0);
        let mut a = a;
        if let Some(stack) = &self.stack {
            // each model block's implied WV (and Jacobian) once, at the deepest row's levels;
            // entry j of row r is the sum over the row's blocks at level j (Stack)
            let jmax = stack.levels.iter().copied().max().unwrap_or(0);
            let offsets = stack.offsets();
            let mut wv = vec![0.0; stack.blocks.len() * jmax];
            let mut jac: Vec<Vec<f64>> = Vec::with_capacity(stack.blocks.len());
            for (b, model) in stack.blocks.iter().enumerate() {
                let pb = model.n_params();
                let part = &theta[offsets[b]..offsets[b] + pb];
                let mut jb = vec![0.0; if a.is_some() { jmax * pb } else { 0 }];
                model.for_each_process(part, self.freq_hz, |p, col| {
                    p.add_wv(&mut wv[b * jmax..(b + 1) * jmax]);
                    if !jb.is_empty() {
                        for (j, row) in p.jacobian(jmax).iter().enumerate() {
                            jb[j * pb + col..j * pb + col + row.len()].copy_from_slice(row);
                        }
                    }
                })?;
                jac.push(jb);
            }
            if let Some(a) = a.as_deref_mut() {
                a.fill(0.0);
            }
            let mut i = 0;
            for (r, blocks) in stack.rows.iter().enumerate() {
                for j in 0..stack.levels[r] {
                    for &b in blocks {
                        nu[i] += wv[b * jmax + j];
                        if let Some(a) = a.as_deref_mut() {
                            let pb = stack.blocks[b].n_params();
                            let at = i * np + offsets[b];
                            a[at..at + pb].copy_from_slice(&jac[b][j * pb..(j + 1) * pb]);
                        }
                    }
                    i += 1;
                }
            }
            return Ok(());
        }
        let extra = self.augment.map_or(0, |g| g.len());
        let levels = self.levels() - extra;
        self.model.for_each_process(theta, self.freq_hz, |p, col| {
            p.add_wv(&mut nu[..levels]);
            if let Some(a) = a.as_deref_mut() {
                p.write_jacobian(levels, a, np, col);
            }
        })?;
        if let Some(augment) = &self.augment {
            let (model, freq) = (&self.model, self.freq_hz);
            match a {
                Some(a) => augment.implied_with_jacobian(
                    model,
                    theta,
                    freq,
                    &mut nu[levels..],
                    &mut a[levels * np..],
                )?,
                None => augment.implied(model, theta, freq, &mut nu[levels..])?,
            }
        }
        Ok(())
    }

    /// Whitened residuals at theta (original parametrisation): `sqrt(omega_j) (nu2_hat_j -
    /// nu2_j)`, or `W (nu2_hat - nu2)` with a full weighting; their squares sum to
    /// [`Objective::value_at_theta`].
    ///
    /// # Errors
    /// As [`Objective::value_at_theta`].
    pub(crate) fn residuals_at_theta(&self, theta: &[f64]) -> Result<Vec<f64>, FitError> {
        if theta.len() != self.n_params() {
            return Err(FitError::Length {
                what: "theta",
                expected: self.n_params(),
                found: theta.len(),
            });
        }
        let mut nu = vec![0.0; self.levels()];
        self.implied(theta, &mut nu, None)?;
        let e: Vec<f64> = self
            .nu_hat
            .iter()
            .zip(&nu)
            .zip(&self.sqrt_omega)
            .map(|((h, n), s)| s * (h - n))
            .collect();
        let mut r = vec![0.0; e.len()];
        self.whiten(&e, &mut r);
        Ok(r)
    }

    /// A fresh evaluation buffer.
    pub(crate) fn buffer(&self) -> Eval {
        let (j, p) = (self.levels(), self.n_params());
        Eval {
            theta: vec![0.0; p],
            dtheta: vec![0.0; p * p],
            r: vec![0.0; j],
            jac: vec![0.0; j * p],
            nu: vec![0.0; j],
        }
    }

    /// Whitened residuals at `u` (and their Jacobian when `with_jacobian`) into `ev`.
    /// `u` has length p (caller's invariant).
    ///
    /// `d r_j / d u_k = -sqrt(omega_j) sum_i A_ji d theta_i / d u_k` (docs/methods.md §5.4).
    pub(crate) fn evaluate(
        &self,
        u: &[f64],
        ev: &mut Eval,
        with_jacobian: bool,
    ) -> Result<(), crate::InputError> {
        let p = self.n_params();
        self.param.eval(
            u,
            &mut ev.theta,
            with_jacobian.then_some(&mut ev.dtheta[..]),
        );
        if with_jacobian {
            // A goes into jac first, then is multiplied by dtheta/du in place, row by row.
            self.implied(&ev.theta, &mut ev.nu, Some(&mut ev.jac))?;
            let mut row = vec![0.0; p];
            for j in 0..self.levels() {
                let a = &mut ev.jac[j * p..(j + 1) * p];
                for (k, out) in row.iter_mut().enumerate() {
                    *out = -self.sqrt_omega[j]
                        * (0..p).map(|i| a[i] * ev.dtheta[i * p + k]).sum::<f64>();
                }
                a.copy_from_slice(&row);
            }
            if let Some(w) = &self.whitening {
                // full weighting: jac <- W jac (sqrt_omega is all ones), column by column
                let levels = self.levels();
                let mut col = vec![0.0; levels];
                for k in 0..p {
                    for (i, c) in col.iter_mut().enumerate() {
                        *c = (0..=i).map(|m| w[i * levels + m] * ev.jac[m * p + k]).sum();
                    }
                    for (i, c) in col.iter().enumerate() {
                        ev.jac[i * p + k] = *c;
                    }
                }
            }
        } else {
            self.implied(&ev.theta, &mut ev.nu, None)?;
        }
        if self.whitening.is_some() {
            let e: Vec<f64> = self.nu_hat.iter().zip(&ev.nu).map(|(h, n)| h - n).collect();
            self.whiten(&e, &mut ev.r);
            return Ok(());
        }
        for (j, r) in ev.r.iter_mut().enumerate() {
            *r = self.sqrt_omega[j] * (self.nu_hat[j] - ev.nu[j]);
        }
        Ok(())
    }

    #[cfg(test)]
    fn check_u(&self, u: &[f64]) -> Result<(), FitError> {
        if u.len() == self.n_params() {
            Ok(())
        } else {
            Err(FitError::Length {
                what: "u",
                expected: self.n_params(),
                found: u.len(),
            })
        }
    }

    /// docs/methods.md §5.1, paper eq. (3): `Q = sum_j omega_j (nu2_hat_j - nu2_j(theta))^2` (with
    /// a full weighting `(nu2_hat - nu2)' Omega (nu2_hat - nu2)`) at theta
    /// (original parametrisation). No factor N.
    ///
    /// # Errors
    /// [`FitError::Length`]; [`FitError::Input`] when theta is not a valid model.
    #[cfg(test)]
    pub(crate) fn value_at_theta(&self, theta: &[f64]) -> Result<f64, FitError> {
        self.value_at_theta_in(theta, &mut Vec::new())
    }

    /// [`Objective::value_at_theta`] with the implied WV computed in `nu` (resized), so that
    /// a loop over many theta (the starting-value draws) allocates nothing per evaluation.
    pub(crate) fn value_at_theta_in(
        &self,
        theta: &[f64],
        nu: &mut Vec<f64>,
    ) -> Result<f64, FitError> {
        if theta.len() != self.n_params() {
            return Err(FitError::Length {
                what: "theta",
                expected: self.n_params(),
                found: theta.len(),
            });
        }
        nu.resize(self.levels(), 0.0);
        self.implied(theta, nu, None)?;
        if self.whitening.is_some() {
            let e: Vec<f64> = self
                .nu_hat
                .iter()
                .zip(nu.iter())
                .map(|(h, n)| h - n)
                .collect();
            let mut r = vec![0.0; self.levels()];
            self.whiten(&e, &mut r);
            return Ok(r.iter().map(|v| v * v).sum());
        }
        Ok(nu
            .iter()
            .zip(&self.nu_hat)
            .zip(&self.sqrt_omega)
            .map(|((n, h), s)| (s * (h - n)).powi(2))
            .sum())
    }

    /// docs/methods.md §5.1: `Q(theta(u))`.
    ///
    /// # Errors
    /// [`FitError::Length`]; [`FitError::Input`] when theta(u) is not a valid model (e.g. a
    /// transformed variance that underflowed to 0).
    #[cfg(test)]
    pub(crate) fn value(&self, u: &[f64]) -> Result<f64, FitError> {
        self.check_u(u)?;
        let mut ev = self.buffer();
        self.evaluate(u, &mut ev, false)?;
        Ok(ev.r.iter().map(|r| r * r).sum())
    }

    /// docs/methods.md §5.4: `grad_u Q = -2 sum_j omega_j r_j (A(theta) d theta / d u)_j` with the
    /// analytic A of §4.5 (GM with respect to `beta`, `sigma2_gm` at the rate).
    ///
    /// # Errors
    /// As [`Objective::value`].
    #[cfg(test)]
    pub(crate) fn gradient(&self, u: &[f64]) -> Result<Vec<f64>, FitError> {
        self.check_u(u)?;
        let p = self.n_params();
        let mut ev = self.buffer();
        self.evaluate(u, &mut ev, true)?;
        // with whitened r and J = dr/du: grad = 2 J' r
        Ok((0..p)
            .map(|k| {
                2.0 * (0..self.levels())
                    .map(|j| ev.jac[j * p + k] * ev.r[j])
                    .sum::<f64>()
            })
            .collect())
    }
}
