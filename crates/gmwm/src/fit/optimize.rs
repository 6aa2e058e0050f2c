//! Minimising the GMWM objective over `u` (docs/methods.md §5.4): Levenberg–Marquardt on the
//! whitened residuals `r_j = sqrt(omega_j) (nu2_hat_j - nu2_j(theta(u)))` with the analytic
//! Jacobian.
//!
//! The package minimises `Q` with R's conjugate gradients (100 iterations, numerical gradient),
//! which often stops short; §5.4 allows any method reaching a lower objective. `Q` is a sum of
//! squares, so Levenberg–Marquardt (Marquardt's diagonal scaling, Nielsen's damping update;
//! Madsen, Nielsen & Tingleff, "Methods for non-linear least squares problems", 2004, §3.2)
//! converges quadratically on small-residual fits and robustly elsewhere.

use super::objective::Eval;
use super::{FitError, Objective, ParamTransform};
use serde::{Deserialize, Serialize};
use std::fmt;

/// Why the optimiser stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[non_exhaustive]
pub enum StopReason {
    /// The residuals vanish to rounding: `Q <= zero_tolerance * sum_j omega_j nu2_hat_j^2`.
    ZeroResidual,
    /// Every column of the Jacobian is orthogonal to the residuals to within
    /// `gradient_tolerance` (cosine of the angle; scale-free first-order optimality).
    GradientTolerance,
    /// The step in `u` fell below `step_tolerance (|u| + step_tolerance)`.
    StepTolerance,
    /// Actual and predicted relative reductions of `Q` both fell below `function_tolerance`.
    FunctionTolerance,
    /// The iteration limit was reached first: **not converged**.
    MaxIterations,
    /// The evaluation limit was reached first: **not converged**.
    MaxEvaluations,
    /// Trial steps kept failing (no reduction of `Q`, or an invalid model) until the damping
    /// made them vanish, away from a stationary point (gradient cosine above
    /// `1e-4`): **not converged**.
    Stalled,
}

impl StopReason {
    /// Whether this reason means convergence.
    pub(crate) fn is_converged(self) -> bool {
        !matches!(
            self,
            StopReason::MaxIterations | StopReason::MaxEvaluations | StopReason::Stalled
        )
    }
}

impl fmt::Display for StopReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            StopReason::ZeroResidual => "residuals vanish",
            StopReason::GradientTolerance => "gradient tolerance reached",
            StopReason::StepTolerance => "step tolerance reached",
            StopReason::FunctionTolerance => "objective reduction below tolerance",
            StopReason::MaxIterations => "iteration limit reached (not converged)",
            StopReason::MaxEvaluations => "evaluation limit reached (not converged)",
            StopReason::Stalled => "steps vanished away from a stationary point (not converged)",
        })
    }
}

/// How an optimisation ended; non-convergence is data, never hidden.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Convergence {
    /// Accepted steps.
    pub(crate) iterations: usize,
    /// Evaluations of the implied WV (each with its Jacobian).
    pub(crate) evaluations: usize,
    /// Why it stopped.
    pub reason: StopReason,
    /// `reason.is_converged()`.
    pub converged: bool,
}

impl fmt::Display for Convergence {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} after {} iterations, {} evaluations",
            self.reason, self.iterations, self.evaluations
        )
    }
}

/// Options of the Levenberg–Marquardt optimiser ([`crate::Gmwm::with_options`]); the defaults suit the GMWM problem (a few to ~20 parameters).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub(crate) struct LmOptions {
    /// Maximum accepted steps; default 2000 (LM typically needs 10–200 here, more when a
    /// component slowly fades to zero; the package's CG
    /// stops at 100).
    pub(crate) max_iterations: usize,
    /// Maximum evaluations; default 20000 (ten trials per step leave the damping exhausted).
    pub(crate) max_evaluations: usize,
    /// Gradient cosine tolerance; default 1e-10 (MINPACK's `gtol` measure, scale-free).
    pub(crate) gradient_tolerance: f64,
    /// Relative step tolerance in `u`; default 1e-12 (theta then moves by ~1e-12 relative).
    pub(crate) step_tolerance: f64,
    /// Relative reduction tolerance of `Q`; default 1e-15 (a few ulps of `Q`).
    pub(crate) function_tolerance: f64,
    /// Relative residual size treated as exact zero; default 1e-28 (residuals ~1e-14 of the
    /// whitened WV, i.e. rounding).
    pub(crate) zero_tolerance: f64,
}

impl Default for LmOptions {
    fn default() -> Self {
        Self {
            max_iterations: 2000,
            max_evaluations: 20000,
            gradient_tolerance: 1e-10,
            step_tolerance: 1e-12,
            function_tolerance: 1e-15,
            zero_tolerance: 1e-28,
        }
    }
}

/// Initial damping relative to the largest diagonal of `J'J` (Madsen et al. suggest 1e-6 to 1
/// depending on trust in the start; 1e-3 is their default).
const INITIAL_DAMPING: f64 = 1e-3;
/// Floor of Marquardt's scaling relative to the largest diagonal of `J'J`, so that a parameter
/// without influence (zero column) still gets a damped, finite step.
const SCALE_FLOOR: f64 = 1e-20;

/// Accepted steps between refreshes of Marquardt's scaling (the running maximum of the
/// curvature goes stale when a component fades by decades, and the steps crawl) and of the
/// damping.
const REFRESH_EVERY: usize = 50;

/// Restarts of the scaling and damping allowed when the steps vanish away from a stationary
/// point, before the fit is reported [`StopReason::Stalled`].
const MAX_RESTARTS: usize = 3;

/// Gradient cosine above which a step-tolerance stop that followed rejected trials counts as
/// [`StopReason::Stalled`]. At a true minimum the cosine is rounding noise (below ~1e-7 in the
/// tests, where `Q` is known to ~1e-16 relative); 1e-4 leaves three decades of margin.
pub(crate) const STALL_COSINE: f64 = 1e-4;

/// Influence below which a log-scale parameter whose descent direction points to zero counts
/// as collapsed onto its boundary (theta -> 0, u -> -inf); likewise a bounded coefficient
/// (logit-type transform or a link of the ordered phi chain) whose descent pushes `u` on
/// towards either infinity (phi -> 0 or phi -> 1, where `dtheta/du` vanishes). Its whitened
/// Jacobian column in `u` (for a variance `sqrt(omega) theta dnu2/dtheta`, the component's
/// whole whitened WV) is at most this fraction of the residual norm, so moving it on to the
/// edge changes `Q` by at most `2e-7` relative. Such a minimum is a boundary (KKT) point: the
/// gradient there is not zero and the parameter would crawl towards its edge for thousands
/// of steps, so while it stays collapsed it is held fixed, the first-order test runs over the
/// other parameters (the fit reports its component, `GmwmFit::collapsed`). It is released as
/// soon as the gradient points back inside.
pub(crate) const COLLAPSE_INFLUENCE: f64 = 1e-7;

/// A least-squares problem [`minimize`] solves: whitened residuals and their Jacobian in the
/// unconstrained parameters `u`. The GMWM objective ([`Objective`]) is one; the fit whose
/// parameters are functions of a covariate (`super::covariate`) is another, on the
/// coefficients of those functions.
pub(crate) trait LeastSquares {
    /// Number of parameters p.
    fn n_params(&self) -> usize;
    /// Number of residuals.
    fn levels(&self) -> usize;
    /// A fresh evaluation buffer.
    fn buffer(&self) -> Eval;
    /// Residuals at `u` (and their Jacobian when `with_jacobian`) into `ev`.
    fn evaluate(
        &self,
        u: &[f64],
        ev: &mut Eval,
        with_jacobian: bool,
    ) -> Result<(), crate::InputError>;
    /// The sum of squares at a zero model: the scale of `Q`.
    fn scale(&self) -> f64;
    /// Where each parameter's boundary lies in `u`.
    fn edges(&self) -> Vec<Edge>;
}

impl LeastSquares for Objective {
    fn n_params(&self) -> usize {
        Objective::n_params(self)
    }
    fn levels(&self) -> usize {
        Objective::levels(self)
    }
    fn buffer(&self) -> Eval {
        Objective::buffer(self)
    }
    fn evaluate(
        &self,
        u: &[f64],
        ev: &mut Eval,
        with_jacobian: bool,
    ) -> Result<(), crate::InputError> {
        Objective::evaluate(self, u, ev, with_jacobian)
    }
    fn scale(&self) -> f64 {
        Objective::scale(self)
    }
    fn edges(&self) -> Vec<Edge> {
        self.parametrisation()
            .transforms()
            .iter()
            .map(|t| Edge::of(*t))
            .collect()
    }
}

/// Where a parameter's boundary lies in `u` (see [`COLLAPSE_INFLUENCE`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Edge {
    /// Unbounded (identity transform): never collapses.
    Free,
    /// Log scale: the boundary theta = 0 is u -> -inf.
    Zero,
    /// A bounded coefficient (logit-type, or a link of the ordered phi chain): u -> -inf and
    /// u -> +inf are both edges (e.g. phi -> 0 and phi -> 1).
    Both,
}

impl Edge {
    /// The edge of a parameter with transform `t` (`None`: a link of the ordered phi chain).
    pub(crate) fn of(t: Option<ParamTransform>) -> Self {
        match t {
            Some(ParamTransform::Log | ParamTransform::LogAbs) => Edge::Zero,
            Some(ParamTransform::Identity) => Edge::Free,
            // logit-type transforms, and None: a link of the ordered phi chain
            _ => Edge::Both,
        }
    }
}

/// Indices of the collapsed parameters (see [`COLLAPSE_INFLUENCE`]) at `ev` (`u` its point):
/// negligible influence and a descent direction that pushes `u` on towards its edge.
fn collapsed_params(ev: &Eval, u: &[f64], levels: usize, p: usize, edge: &[Edge]) -> Vec<usize> {
    let r_norm = sum_sq(&ev.r[..levels]).sqrt();
    (0..p)
        .filter(|&k| {
            if edge[k] == Edge::Free {
                return false;
            }
            let (mut col, mut g) = (0.0, 0.0);
            for j in 0..levels {
                let v = ev.jac[j * p + k];
                col += v * v;
                g += v * ev.r[j];
            }
            let outwards = match edge[k] {
                Edge::Zero => g >= 0.0,
                _ => g * u[k] <= 0.0,
            };
            outwards && col.sqrt() <= COLLAPSE_INFLUENCE * r_norm
        })
        .collect()
}

/// The minimiser found by [`minimize`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct Minimum {
    /// Unconstrained parameters at the end.
    pub(crate) u: Vec<f64>,
    /// Model parameters `theta(u)` (original parametrisation).
    pub(crate) theta: Vec<f64>,
    /// `Q` at the end (docs/methods.md §5.1).
    pub(crate) objective: f64,
    /// Implied WV at the end.
    pub(crate) implied_wv: Vec<f64>,
    /// How it ended.
    pub(crate) convergence: Convergence,
}

/// Cholesky solve of the symmetric positive definite `m x = b` (row-major n x n), in place in
/// `b`; `false` if `m` is not numerically positive definite.
fn cholesky_solve(m: &mut [f64], b: &mut [f64], n: usize) -> bool {
    for i in 0..n {
        for j in 0..=i {
            let mut s = m[i * n + j];
            for k in 0..j {
                s -= m[i * n + k] * m[j * n + k];
            }
            if i == j {
                if !(s > 0.0 && s.is_finite()) {
                    return false;
                }
                m[i * n + i] = s.sqrt();
            } else {
                m[i * n + j] = s / m[j * n + j];
            }
        }
    }
    for i in 0..n {
        let s = b[i] - (0..i).map(|k| m[i * n + k] * b[k]).sum::<f64>();
        b[i] = s / m[i * n + i];
    }
    for i in (0..n).rev() {
        let s = b[i] - (i + 1..n).map(|k| m[k * n + i] * b[k]).sum::<f64>();
        b[i] = s / m[i * n + i];
    }
    b.iter().all(|v| v.is_finite())
}

fn sum_sq(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

/// docs/methods.md §5.4: minimises `Q(u)` of `objective` from `u0` by Levenberg–Marquardt.
///
/// Each iteration forms `J'J` and `J'r` (O(J p^2)), solves the damped normal equations
/// `(J'J + mu D) h = -J'r` by Cholesky and evaluates the implied WV and its Jacobian once per
/// trial step. A trial at which theta is not a valid model (e.g. a variance underflowing to 0)
/// counts as a failed step. The result always says how it ended ([`Convergence`]).
///
/// # Errors
/// [`FitError::Length`] if `u0` has the wrong length; [`FitError::BadStart`] if theta(u0) is not
/// a valid model; [`FitError::NonFiniteStart`] if its implied WV overflows.
pub(crate) fn minimize(
    objective: &impl LeastSquares,
    u0: &[f64],
    opts: &LmOptions,
) -> Result<Minimum, FitError> {
    let p = objective.n_params();
    let levels = objective.levels();
    if u0.len() != p {
        return Err(FitError::Length {
            what: "u",
            expected: p,
            found: u0.len(),
        });
    }
    let mut cur = objective.buffer();
    let mut trial = objective.buffer();
    let mut u = u0.to_vec();
    objective
        .evaluate(&u, &mut cur, true)
        .map_err(FitError::BadStart)?;
    if let Some(j) = cur.r.iter().position(|v| !v.is_finite()) {
        return Err(FitError::NonFiniteStart {
            level: j + 1,
            value: cur.nu[j],
        });
    }
    let mut evaluations = 1;
    let mut iterations = 0;
    // sum_j omega_j nu2_hat_j^2: the objective of theta with zero implied WV
    let scale_q = objective.scale();
    let mut q = sum_sq(&cur.r);
    let mut a = vec![0.0; p * p];
    let mut g = vec![0.0; p];
    let mut d = vec![0.0f64; p];
    let mut m = vec![0.0; p * p];
    let mut h = vec![0.0; p];
    let mut u_new = vec![0.0; p];
    let mut mu = f64::NAN;
    let mut nu = 2.0;
    let mut restarts = 0;
    let edge = objective.edges();
    let finish =
        |reason: StopReason, u: Vec<f64>, ev: &Eval, q: f64, it: usize, evals: usize| Minimum {
            u,
            theta: ev.theta.clone(),
            objective: q,
            implied_wv: ev.nu.clone(),
            convergence: Convergence {
                iterations: it,
                evaluations: evals,
                reason,
                converged: reason.is_converged(),
            },
        };
    loop {
        if q <= opts.zero_tolerance * scale_q {
            return Ok(finish(
                StopReason::ZeroResidual,
                u,
                &cur,
                q,
                iterations,
                evaluations,
            ));
        }
        normal_equations(&cur, levels, p, &mut a, &mut g);
        let r_norm = q.sqrt();
        let collapsed = collapsed_params(&cur, &u, levels, p, &edge);
        for &k in &collapsed {
            for l in 0..p {
                a[k * p + l] = 0.0;
                a[l * p + k] = 0.0;
            }
            g[k] = 0.0;
        }
        // a curvature that is not a number (an implied WV whose derivatives overflow) is no
        // stationary point: the cosine is then infinite, and the damping decides below
        let cosine = (0..p)
            .filter(|&k| (a[k * p + k] > 0.0 || a[k * p + k].is_nan()) && !collapsed.contains(&k))
            .map(|k| match g[k].abs() / (a[k * p + k].sqrt() * r_norm) {
                c if c.is_nan() => f64::INFINITY,
                c => c,
            })
            .fold(0.0, f64::max);
        if cosine <= opts.gradient_tolerance {
            return Ok(finish(
                StopReason::GradientTolerance,
                u,
                &cur,
                q,
                iterations,
                evaluations,
            ));
        }
        if iterations >= opts.max_iterations {
            return Ok(finish(
                StopReason::MaxIterations,
                u,
                &cur,
                q,
                iterations,
                evaluations,
            ));
        }
        let a_max = (0..p).map(|k| a[k * p + k]).fold(0.0, f64::max);
        let refresh = iterations > 0 && iterations % REFRESH_EVERY == 0;
        for k in 0..p {
            let kept = if refresh { 0.0 } else { d[k] };
            d[k] = kept.max(a[k * p + k]).max(SCALE_FLOOR * a_max);
        }
        if refresh {
            mu = INITIAL_DAMPING;
            nu = 2.0;
        }
        if mu.is_nan() {
            mu = INITIAL_DAMPING;
        }
        // inner loop: raise the damping until a step reduces Q
        let mut rejected = false;
        loop {
            if evaluations >= opts.max_evaluations {
                return Ok(finish(
                    StopReason::MaxEvaluations,
                    u,
                    &cur,
                    q,
                    iterations,
                    evaluations,
                ));
            }
            m.copy_from_slice(&a);
            for k in 0..p {
                m[k * p + k] += mu * d[k];
                h[k] = -g[k];
            }
            if !cholesky_solve(&mut m, &mut h, p) {
                mu *= nu;
                nu *= 2.0;
                // a system no damping makes solvable (a non-finite curvature: an implied WV
                // whose derivatives overflow) would raise it forever without an evaluation;
                // once the damping overflows, the step has vanished
                if !mu.is_finite() {
                    return Ok(finish(
                        StopReason::Stalled,
                        u,
                        &cur,
                        q,
                        iterations,
                        evaluations,
                    ));
                }
                continue;
            }
            let h_norm = sum_sq(&h).sqrt();
            let u_norm = sum_sq(&u).sqrt();
            if h_norm <= opts.step_tolerance * (u_norm + opts.step_tolerance) {
                let stalled = rejected && cosine > STALL_COSINE;
                if stalled && restarts < MAX_RESTARTS {
                    // Marquardt's scaling keeps the largest curvature seen; a parameter whose
                    // column has since shrunk by decades (a component fading towards zero)
                    // is then damped to a standstill. Restart the scaling and the damping.
                    restarts += 1;
                    for k in 0..p {
                        d[k] = a[k * p + k].max(SCALE_FLOOR * a_max);
                    }
                    mu = INITIAL_DAMPING;
                    nu = 2.0;
                    rejected = false;
                    continue;
                }
                let reason = if stalled {
                    StopReason::Stalled
                } else {
                    StopReason::StepTolerance
                };
                return Ok(finish(reason, u, &cur, q, iterations, evaluations));
            }
            for k in 0..p {
                u_new[k] = u[k] + h[k];
            }
            evaluations += 1;
            // a trial needs only the residuals; the Jacobian is formed at accepted points
            let ok = objective.evaluate(&u_new, &mut trial, false).is_ok();
            let q_new = if ok { sum_sq(&trial.r) } else { f64::INFINITY };
            // predicted reduction of Q by the linear model: h'(mu D h - g)
            let predicted: f64 = (0..p).map(|k| h[k] * (mu * d[k] * h[k] - g[k])).sum();
            let actual = q - q_new;
            let rho = actual / predicted;
            if q_new.is_finite()
                && rho > 0.0
                && objective.evaluate(&u_new, &mut trial, true).is_ok()
            {
                std::mem::swap(&mut cur, &mut trial);
                std::mem::swap(&mut u, &mut u_new);
                let old_q = q;
                q = q_new;
                iterations += 1;
                mu *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
                nu = 2.0;
                if actual <= opts.function_tolerance * old_q
                    && predicted <= opts.function_tolerance * old_q
                {
                    return Ok(finish(
                        StopReason::FunctionTolerance,
                        u,
                        &cur,
                        q,
                        iterations,
                        evaluations,
                    ));
                }
                break;
            }
            rejected = true;
            mu *= nu;
            nu *= 2.0;
        }
    }
}

/// `A = J'J` and `g = J'r` (row-major J).
fn normal_equations(ev: &Eval, levels: usize, p: usize, a: &mut [f64], g: &mut [f64]) {
    a.fill(0.0);
    g.fill(0.0);
    for j in 0..levels {
        let row = &ev.jac[j * p..(j + 1) * p];
        for k in 0..p {
            g[k] += row[k] * ev.r[j];
            for l in 0..=k {
                a[k * p + l] += row[k] * row[l];
            }
        }
    }
    for k in 0..p {
        for l in 0..k {
            a[l * p + k] = a[k * p + l];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Residuals `u - 1` (finite everywhere) whose Jacobian is not a number: the curvature no
    /// damping makes positive definite (found by the `wv_fit` fuzz target: a deep-level ARMA
    /// whose derivatives overflowed hung the optimiser raising the damping forever).
    struct NanCurvature {
        /// Every column not a number (else the second only).
        all: bool,
    }

    impl LeastSquares for NanCurvature {
        fn n_params(&self) -> usize {
            2
        }
        fn levels(&self) -> usize {
            3
        }
        fn buffer(&self) -> Eval {
            Eval {
                theta: vec![0.0; 2],
                dtheta: vec![0.0; 4],
                r: vec![0.0; 3],
                jac: vec![0.0; 6],
                nu: vec![0.0; 3],
            }
        }
        fn evaluate(
            &self,
            u: &[f64],
            ev: &mut Eval,
            with_jacobian: bool,
        ) -> Result<(), crate::InputError> {
            ev.theta.copy_from_slice(u);
            for (j, r) in ev.r.iter_mut().enumerate() {
                *r = u[j % 2] - 1.0;
            }
            ev.nu.copy_from_slice(&ev.r);
            if with_jacobian {
                // d r_j / d u_0 = [j even]; d r_j / d u_1 not a number
                for (j, row) in ev.jac.chunks_exact_mut(2).enumerate() {
                    row[0] = match (self.all, j % 2) {
                        (true, _) => f64::NAN,
                        (false, 0) => 1.0,
                        (false, _) => 0.0,
                    };
                    row[1] = f64::NAN;
                }
            }
            Ok(())
        }
        fn scale(&self) -> f64 {
            3.0
        }
        fn edges(&self) -> Vec<Edge> {
            vec![Edge::Free; 2]
        }
    }

    #[test]
    fn a_curvature_no_damping_repairs_stops_the_fit() {
        // one column not a number, then all: neither is a stationary point, and the damping
        // gives up without evaluating (it raised the damping forever before)
        for all in [false, true] {
            let min = minimize(&NanCurvature { all }, &[0.0, 0.0], &LmOptions::default()).unwrap();
            assert_eq!(min.convergence.reason, StopReason::Stalled, "all {all}");
            assert!(!min.convergence.converged);
            assert_eq!(min.convergence.evaluations, 1);
        }
    }

    #[test]
    fn cholesky_solves_spd_and_rejects_indefinite() {
        let mut m = vec![4.0, 2.0, 2.0, 3.0];
        let mut b = vec![2.0, 1.0];
        assert!(cholesky_solve(&mut m, &mut b, 2));
        assert!((b[0] - 0.5).abs() < 1e-15 && b[1].abs() < 1e-15);
        let mut m = vec![1.0, 2.0, 2.0, 1.0];
        let mut b = vec![1.0, 1.0];
        assert!(!cholesky_solve(&mut m, &mut b, 2));
    }
}
