//! Error models whose parameters follow the system's dynamics (paper §IV-B; docs/methods.md
//! §5.16): the non-stationary AR1 `y_t = rho_t y_{t-1} + eps_t`, `rho_t = m(Z_{t-1} beta)`, and
//! its generalisation to the innovation and white-noise variances, with the exact implied
//! wavelet variance given the covariate path, the estimator and a simulator.
//!
//! # The model ([`NsAr1`])
//! With a scalar covariate `z_t` (centred by the fit: `z_t - z_bar`, so that the intercepts are
//! the values at the recording's mean covariate):
//!
//! - `rho_t = tanh(beta0 + beta1 z_{t-1})`, `tanh` being the map `m` of the paper onto (-1, 1);
//! - `Var(eps_t) = exp(alpha0 + alpha1 z_{t-1})`;
//! - optionally a white noise `w_t` added to `y_t` with `Var(w_t) = exp(gamma0 + gamma1 z_t)`;
//! - `y_0` from the stationary law at `z_0`.
//!
//! # Implied WV given the covariate path (exact, `O(N J)`)
//! `E[nu2_hat_j]` over the coefficients of a stretch of the series is the mean of
//! `Var(W_{j,t})`, and `L_j^2 Var(W_{j,t}) = Var(B(t, D) - B(t - D, D))` for the block sums
//! `B(e, D) = y_{e-D+1} + ... + y_e`, `D = L_j / 2`. With `P_t = Var(y_t) = rho_t^2 P_{t-1} +
//! s_t` and, for `u < w`, `Cov(y_u, y_w) = P_u rho_{u+1} ... rho_w`, four arrays per block
//! length `D` describe every block:
//!
//! - `V_D(e) = Var(B(e, D))`, `c_D(e) = Cov(B(e, D), y_e)`;
//! - `g_D(s) = sum_{k=1}^{D} rho_{s+1} ... rho_{s+k}`, `Pi_D(s) = rho_{s+1} ... rho_{s+D}`;
//!
//! since `Cov(B(e, D), y_w) = c_D(e) rho_{e+1} ... rho_w` for `w > e`, the covariance of two
//! adjacent blocks is `c_D(e) g_D'(e)`. They start at `V_1 = c_1 = P`, `g_1(s) = Pi_1(s) =
//! rho_{s+1}` and double:
//!
//! `V_2D(e) = V_D(e - D) + V_D(e) + 2 c_D(e - D) g_D(e - D)`,
//! `c_2D(e) = c_D(e - D) Pi_D(e - D) + c_D(e)`,
//! `g_2D(s) = g_D(s) + Pi_D(s) g_D(s + D)`, `Pi_2D(s) = Pi_D(s) Pi_D(s + D)`,
//!
//! and `L^2 Var(W_{j,t}) = V_D(t) + V_D(t - D) - 2 c_D(t - D) g_D(t - D)`: one pass per level,
//! no simulation, no Monte Carlo error. The white noise adds `sum_{u in (t - L, t]} v_u / L^2`
//! (prefix sums). Checked against the brute-force covariance of the Haar filter over the
//! window (`implied_wv_matches_brute_force`) and the simulated mean WV.
//!
//! # Estimation
//! The recording is cut into `K` windows of equal length (docs/methods.md §5.13), each with its
//! classical Haar WV and fast weights; the estimate minimises the stacked objective
//! `sum_k (nu2_hat_k - nu2_k(theta | z))' Omega_k (nu2_hat_k - nu2_k(theta | z))` (the
//! `ns-gmwm` objective of SMAC-Group's follow-up, there without an estimator), where
//! `nu2_k(theta | z)` is the exact implied WV of window `k` given the whole covariate path (the
//! AR state carries across windows). Levenberg–Marquardt from the stationary AR1 + WN GMWM fit
//! (`beta0 = atanh(phi)`, `alpha0 = ln sigma2`, `gamma0 = ln sigma2_wn`, slopes 0), with the
//! Jacobian by central differences (step 1e-6), first with each window's fast weights, then
//! (step 2) with `Omega_k = diag(V_k)^{-1}` from the model's own covariance at the first
//! estimate and a refit: weights computed from the windows' noisy WVs correlate with the
//! moments' errors and bias the estimate (in the study, `beta0` by two standard errors). `V_k`
//! is the mean, over eight parts of the window, of the exact WV covariance of the stationary
//! AR1 + WN at the part's mean `rho` and variances (an approximation the study checks);
//! standard errors from the sandwich with the windows' WVs taken as independent.

use crate::fit::objective::Eval;
use crate::fit::optimize::{Edge, LeastSquares};
use crate::fit::{minimize, FitError, Gmwm, GmwmFit, LmOptions, Weights};
use crate::math::elementary;
use crate::process::sampler::{normal, SimRng};
use crate::variance::wv::{wavelet_variance, WvOptions};
use crate::{InputError, ParamError};
use rand::SeedableRng;
use serde::Serialize;
use std::fmt;
use std::ops::Range;

/// The non-stationary AR1 (module docs): `rho_t = tanh(beta[0] + beta[1] z_{t-1})`,
/// `Var(eps_t) = exp(alpha[0] + alpha[1] z_{t-1})`, and an optional white noise of variance
/// `exp(gamma[0] + gamma[1] z_t)`; `z` as the caller gives it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct NsAr1 {
    /// Intercept and slope of `atanh(rho)`.
    pub beta: [f64; 2],
    /// Intercept and slope of the log innovation variance.
    pub alpha: [f64; 2],
    /// Intercept and slope of the white noise's log variance; `None` for no white noise.
    pub gamma: Option<[f64; 2]>,
}

/// `rho_t`, the innovation variances `s_t` and the white variances `v_t` along a path.
type Paths = (Vec<f64>, Vec<f64>, Vec<f64>);

/// Parameter labels in [`NsAr1::theta`] order.
const NAMES: [&str; 6] = ["beta0", "beta1", "alpha0", "alpha1", "gamma0", "gamma1"];

impl NsAr1 {
    /// `[beta0, beta1, alpha0, alpha1 (, gamma0, gamma1)]`.
    pub fn theta(&self) -> Vec<f64> {
        let mut t = vec![self.beta[0], self.beta[1], self.alpha[0], self.alpha[1]];
        if let Some(g) = self.gamma {
            t.extend(g);
        }
        t
    }

    /// The inverse of [`NsAr1::theta`] (4 or 6 values).
    fn from_theta(t: &[f64]) -> Self {
        NsAr1 {
            beta: [t[0], t[1]],
            alpha: [t[2], t[3]],
            gamma: (t.len() == 6).then(|| [t[4], t[5]]),
        }
    }

    /// The labels of [`NsAr1::theta`].
    pub fn names(&self) -> Vec<&'static str> {
        NAMES[..if self.gamma.is_some() { 6 } else { 4 }].to_vec()
    }

    /// `rho_t` (index 0: the stationary start's, at `z_0`), innovation variances `s_t`, white
    /// variances `v_t` (zeros without white noise), after checking them.
    fn paths(&self, z: &[f64]) -> Result<Paths, ParamError> {
        let n = z.len();
        let at = |t: usize| z[t.saturating_sub(1)];
        let rho: Vec<f64> = (0..n)
            .map(|t| elementary::tanh(self.beta[0] + self.beta[1] * at(t)))
            .collect();
        let s: Vec<f64> = (0..n)
            .map(|t| elementary::exp(self.alpha[0] + self.alpha[1] * at(t)))
            .collect();
        let v: Vec<f64> = match self.gamma {
            Some(g) => z
                .iter()
                .map(|&x| elementary::exp(g[0] + g[1] * x))
                .collect(),
            None => vec![0.0; n],
        };
        if let Some(t) = (0..n)
            .find(|&t| !(rho[t].abs() < 1.0 && s[t].is_finite() && s[t] > 0.0 && v[t].is_finite()))
        {
            return Err(ParamError::new(
                "theta",
                format!("{:?}", self.theta()),
                format!(
                    "|rho_t| < 1 and finite positive variances along the covariate path (at \
                     sample {t}: rho = {}, innovation variance {}, white variance {})",
                    rho[t], s[t], v[t]
                ),
            ));
        }
        Ok((rho, s, v))
    }

    /// A series of the model along the covariate path `z` (one sample per value), seeded.
    ///
    /// # Errors
    /// [`ParamError`] when `rho_t` or a variance leaves its domain along the path.
    pub fn simulate(&self, z: &[f64], seed: u64) -> Result<Vec<f64>, ParamError> {
        let (rho, s, v) = self.paths(z)?;
        let mut rng = SimRng::seed_from_u64(seed);
        let mut out = Vec::with_capacity(z.len());
        let mut y = 0.0;
        for t in 0..z.len() {
            y = if t == 0 {
                (s[0] / ((1.0 - rho[0]) * (1.0 + rho[0]))).sqrt() * normal(&mut rng)
            } else {
                rho[t] * y + s[t].sqrt() * normal(&mut rng)
            };
            let w = if v[t] > 0.0 {
                v[t].sqrt() * normal(&mut rng)
            } else {
                0.0
            };
            out.push(y + w);
        }
        Ok(out)
    }

    /// The exact expected Haar MODWT WV (levels `1..=levels`) of each window (sample range)
    /// of a series along `z` (module docs): row `k` is window `k`'s.
    ///
    /// # Errors
    /// [`ParamError`] as [`NsAr1::simulate`], or a window out of range or too short for
    /// `levels`.
    pub fn implied_wv(
        &self,
        z: &[f64],
        windows: &[Range<usize>],
        levels: usize,
    ) -> Result<Vec<Vec<f64>>, ParamError> {
        let n = z.len();
        for w in windows {
            if w.end > n || w.end < w.start || (w.end - w.start) < (1usize << levels) {
                return Err(ParamError::new(
                    "window",
                    format!("{}..{}", w.start, w.end),
                    format!("a range inside the {n} samples, at least 2^{levels} long"),
                ));
            }
        }
        let (rho, s, v) = self.paths(z)?;
        let mut p = vec![0.0; n];
        p[0] = s[0] / ((1.0 - rho[0]) * (1.0 + rho[0]));
        for t in 1..n {
            p[t] = rho[t] * rho[t] * p[t - 1] + s[t];
        }
        // white noise: prefix sums of v
        let mut cum = vec![0.0; n + 1];
        for t in 0..n {
            cum[t + 1] = cum[t] + v[t];
        }
        // block arrays for D = 1; g and pi indexed by the block's start s (block (s, s + D]),
        // valid for s + D <= n - 1
        let mut big_v = p.clone();
        let mut c = p;
        let mut g: Vec<f64> = (0..n)
            .map(|s| rho.get(s + 1).copied().unwrap_or(0.0))
            .collect();
        let mut pi = g.clone();
        let mut out = vec![vec![0.0; levels]; windows.len()];
        let mut var_w = vec![0.0; n];
        for j in 1..=levels {
            let d = 1usize << (j - 1);
            let l = 2 * d;
            let l2 = (l * l) as f64;
            for t in l - 1..n {
                let ar = big_v[t] + big_v[t - d] - 2.0 * c[t - d] * g[t - d];
                var_w[t] = (ar + cum[t + 1] - cum[t + 1 - l]) / l2;
            }
            for (row, w) in out.iter_mut().zip(windows) {
                let first = w.start + l - 1;
                let count = w.end - first;
                row[j - 1] = var_w[first..w.end].iter().sum::<f64>() / count as f64;
            }
            if j == levels {
                break;
            }
            // double the block length: new arrays from the old ones (valid ranges shrink)
            let mut v2 = vec![0.0; n];
            let mut c2 = vec![0.0; n];
            for e in l - 1..n {
                v2[e] = big_v[e - d] + big_v[e] + 2.0 * c[e - d] * g[e - d];
                c2[e] = c[e - d] * pi[e - d] + c[e];
            }
            let mut g2 = vec![0.0; n];
            let mut pi2 = vec![0.0; n];
            for s in 0..n.saturating_sub(l) {
                g2[s] = g[s] + pi[s] * g[s + d];
                pi2[s] = pi[s] * pi[s + d];
            }
            big_v = v2;
            c = c2;
            g = g2;
            pi = pi2;
        }
        Ok(out)
    }
}

impl fmt::Display for NsAr1 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "rho_t = tanh({:.6} + {:.6} z), log sigma2_t = {:.6} + {:.6} z",
            self.beta[0], self.beta[1], self.alpha[0], self.alpha[1]
        )?;
        if let Some(g) = self.gamma {
            write!(f, ", log sigma2_wn = {:.6} + {:.6} z", g[0], g[1])?;
        }
        Ok(())
    }
}

/// How a non-stationary AR1 fit is set up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NsAr1Options {
    /// Windows of equal length the recording is cut into (at least 2).
    pub windows: usize,
    /// Whether the model has the white noise term.
    pub white_noise: bool,
    /// Whether the white noise's variance may depend on the covariate (`gamma1` free);
    /// otherwise `gamma1 = 0`.
    pub white_depends: bool,
    /// Whether the innovation variance may depend on the covariate (`alpha1` free).
    pub variance_depends: bool,
}

impl Default for NsAr1Options {
    fn default() -> Self {
        Self {
            windows: 8,
            white_noise: true,
            white_depends: false,
            variance_depends: true,
        }
    }
}

/// The result of [`fit_ns_ar1`].
///
/// Wire format: `model` (`beta`, `alpha`, `gamma`), `theta`, `names`, `se` (null for a fixed
/// parameter), `covariate_mean` (the centring `z_bar`: the model is in `z - z_bar`),
/// `covariate_range`, `objective`, `converged`, `windows`, `levels`, `stationary_objective` (the
/// same windowed objective at the stationary AR1 (+ WN) fit that ignores the covariate).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NsAr1Fit {
    /// The estimate (in the centred covariate).
    pub model: NsAr1,
    /// Its parameters and labels.
    pub theta: Vec<f64>,
    /// Labels of `theta`.
    pub names: Vec<&'static str>,
    /// Standard errors (module docs); `None` for a fixed parameter.
    pub se: Vec<Option<f64>>,
    /// `z_bar`.
    pub covariate_mean: f64,
    /// Smallest and largest centred covariate value (`z - z_bar`) of the recording.
    pub covariate_range: [f64; 2],
    /// The stacked objective at the estimate.
    pub objective: f64,
    /// Whether the optimiser converged.
    pub converged: bool,
    /// Windows and levels per window.
    pub windows: usize,
    /// Levels per window.
    pub levels: usize,
    /// The stacked objective of the stationary fit, evaluated as the same windowed objective
    /// (its model has the same implied WV in every window).
    pub stationary_objective: f64,
    /// The stationary AR1 + WN fit of the whole recording.
    #[serde(skip)]
    pub stationary: GmwmFit,
}

/// The stacked windowed objective (module docs).
struct NsObjective<'a> {
    z: &'a [f64],
    windows: Vec<Range<usize>>,
    levels: usize,
    nu_hat: Vec<f64>,
    sqrt_omega: Vec<f64>,
    /// Which of the six parameters are free (fixed ones keep `fixed`'s value).
    free: Vec<usize>,
    fixed: Vec<f64>,
}

impl NsObjective<'_> {
    fn model(&self, u: &[f64]) -> NsAr1 {
        let mut t = self.fixed.clone();
        for (&k, &x) in self.free.iter().zip(u) {
            t[k] = x;
        }
        NsAr1::from_theta(&t)
    }

    fn implied(&self, u: &[f64]) -> Result<Vec<f64>, ParamError> {
        Ok(self
            .model(u)
            .implied_wv(self.z, &self.windows, self.levels)?
            .concat())
    }
}

impl LeastSquares for NsObjective<'_> {
    fn n_params(&self) -> usize {
        self.free.len()
    }
    fn levels(&self) -> usize {
        self.nu_hat.len()
    }
    fn buffer(&self) -> Eval {
        let (m, p) = (self.nu_hat.len(), self.free.len());
        Eval {
            theta: vec![0.0; p],
            dtheta: Vec::new(),
            r: vec![0.0; m],
            jac: vec![0.0; m * p],
            nu: vec![0.0; m],
        }
    }
    fn evaluate(&self, u: &[f64], ev: &mut Eval, with_jacobian: bool) -> Result<(), InputError> {
        ev.theta.copy_from_slice(u);
        let nu = self.implied(u)?;
        for (i, r) in ev.r.iter_mut().enumerate() {
            *r = self.sqrt_omega[i] * (self.nu_hat[i] - nu[i]);
        }
        ev.nu.copy_from_slice(&nu);
        if with_jacobian {
            let p = u.len();
            let mut x = u.to_vec();
            for k in 0..p {
                let h = 1e-6 * u[k].abs().max(1e-3);
                x[k] = u[k] + h;
                let up = self.implied(&x)?;
                x[k] = u[k] - h;
                let down = self.implied(&x)?;
                x[k] = u[k];
                for i in 0..nu.len() {
                    ev.jac[i * p + k] = -self.sqrt_omega[i] * (up[i] - down[i]) / (2.0 * h);
                }
            }
        }
        Ok(())
    }
    fn scale(&self) -> f64 {
        self.nu_hat
            .iter()
            .zip(&self.sqrt_omega)
            .map(|(h, s)| (h * s).powi(2))
            .sum()
    }
    fn edges(&self) -> Vec<Edge> {
        vec![Edge::Free; self.free.len()]
    }
}

/// Fits the non-stationary AR1 (module docs) to the series `x` with the covariate `z` (one value
/// per sample) at `freq_hz`.
///
/// ```
/// use gmwm::{fit_ns_ar1, NsAr1, NsAr1Options};
/// let n = 1 << 14;
/// let z: Vec<f64> = (0..n).map(|t| (6.0 * std::f64::consts::PI * t as f64 / n as f64).sin()).collect();
/// let truth = NsAr1 { beta: [2.0, 0.6], alpha: [0.0, 0.0], gamma: Some([0.0, 0.0]) };
/// let x = truth.simulate(&z, 5).unwrap();
/// let fit = fit_ns_ar1(&x, &z, 1.0, &NsAr1Options::default()).unwrap();
/// assert!((fit.model.beta[1] - 0.6).abs() < 0.3);
/// ```
///
/// # Errors
/// [`ParamError`] (as [`FitError`]) for a covariate of another length, a non-finite or constant
/// covariate, windows too short for 4 levels; errors of the stationary fit.
pub fn fit_ns_ar1(
    x: &[f64],
    z: &[f64],
    freq_hz: f64,
    opts: &NsAr1Options,
) -> Result<NsAr1Fit, FitError> {
    let n = x.len();
    if z.len() != n {
        return Err(
            ParamError::new("covariate", z.len(), format!("one value per sample ({n})")).into(),
        );
    }
    if let Some(t) = z.iter().position(|v| !v.is_finite()) {
        return Err(
            ParamError::new("covariate", z[t], format!("finite values (sample {t})")).into(),
        );
    }
    let mean = z.iter().sum::<f64>() / n.max(1) as f64;
    let zc: Vec<f64> = z.iter().map(|v| v - mean).collect();
    let spread = zc.iter().map(|v| v * v).sum::<f64>() / n.max(1) as f64;
    if spread.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Err(ParamError::new(
            "covariate",
            mean,
            "a covariate that varies: a constant one cannot explain a dependence",
        )
        .into());
    }
    let k = opts.windows;
    let len = n / k.max(1);
    if k < 2 || len < 32 {
        return Err(ParamError::new(
            "windows",
            k,
            format!("at least 2 windows of at least 32 samples ({n} samples)"),
        )
        .into());
    }
    let windows: Vec<Range<usize>> = (0..k).map(|i| i * len..(i + 1) * len).collect();
    // levels: the windows' classical Haar WV, all at the same levels
    let levels = (len.ilog2() as usize).saturating_sub(1).max(1);
    let wv_opts = WvOptions {
        levels: Some(levels),
        ..WvOptions::default()
    };
    let mut nu_hat = Vec::with_capacity(k * levels);
    let mut sqrt_omega = Vec::with_capacity(k * levels);
    for w in &windows {
        let wv = wavelet_variance(&x[w.clone()], freq_hz, &wv_opts)?;
        let weights = Weights::fast(&wv)?;
        nu_hat.extend_from_slice(&wv.wv);
        sqrt_omega.extend(weights.omega.iter().map(|o| o.sqrt()));
    }
    // start: the stationary AR1 (+ WN) fit of the whole series
    let template = if opts.white_noise {
        "AR1()+WN()"
    } else {
        "AR1()"
    };
    let stationary = Gmwm::parse(template)
        .map_err(|e| ParamError::new("model", template, e.to_string()))?
        .fit(x, freq_hz, &WvOptions::default())?;
    let th = stationary.theta();
    let phi = th[0].clamp(-0.999_999, 0.999_999);
    let mut fixed = vec![
        elementary::atanh(phi),
        0.0,
        elementary::log(th[1].max(1e-300)),
        0.0,
    ];
    let mut free = vec![0, 1, 2];
    if opts.variance_depends {
        free.push(3);
    }
    if opts.white_noise {
        fixed.extend([elementary::log(th[2].max(1e-300)), 0.0]);
        free.push(4);
        if opts.white_depends {
            free.push(5);
        }
    }
    let objective = NsObjective {
        z: &zc,
        windows: windows.clone(),
        levels,
        nu_hat,
        sqrt_omega,
        free: free.clone(),
        fixed: fixed.clone(),
    };
    let u0: Vec<f64> = free.iter().map(|&i| fixed[i]).collect();
    let first = minimize(&objective, &u0, &LmOptions::default())?;
    // step 2: weights from the model's own V at the first estimate, not from the windows'
    // noisy WVs (fast weights correlate with the moments' errors and bias the estimate), then
    // the refit; the SEs use the same V
    let blocks = window_covariances(
        &objective.model(&first.theta),
        &zc,
        &windows,
        levels,
        freq_hz,
    );
    let (objective, min) = match &blocks {
        Some(blocks) => {
            let sqrt_omega = blocks
                .iter()
                .flat_map(|b| (0..levels).map(move |j| 1.0 / b[(j, j)].sqrt()))
                .collect();
            let reweighted = NsObjective {
                sqrt_omega,
                ..objective
            };
            let min = minimize(&reweighted, &first.theta, &LmOptions::default())?;
            (reweighted, min)
        }
        None => (objective, first),
    };
    let stationary_objective = {
        let mut ev = objective.buffer();
        objective.evaluate(&u0, &mut ev, false)?;
        ev.r.iter().map(|r| r * r).sum()
    };
    let model = objective.model(&min.theta);
    let se = match &blocks {
        Some(b) => standard_errors(&objective, &min.theta, b),
        None => vec![None; min.theta.len()],
    };
    let mut se_all = vec![None; fixed.len()];
    for (&i, s) in free.iter().zip(se) {
        se_all[i] = s;
    }
    Ok(NsAr1Fit {
        names: model.names(),
        theta: model.theta(),
        model,
        se: se_all,
        covariate_mean: mean,
        covariate_range: [
            zc.iter().copied().fold(f64::INFINITY, f64::min),
            zc.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        ],
        objective: min.objective,
        converged: min.convergence.converged,
        windows: k,
        levels,
        stationary_objective,
        stationary,
    })
}

/// Each window's WV covariance `V_k` (`levels x levels`): the mean over [`SUB_WINDOWS`] parts of
/// the window of the exact `V` of a series of the window's length from the stationary AR1
/// (+ WN) at the part's mean `rho` and variances under `model` (module docs); `None` when a
/// part's stationary model is outside the exact formulas' cover (a negative `rho`).
fn window_covariances(
    model: &NsAr1,
    z: &[f64],
    windows: &[Range<usize>],
    levels: usize,
    freq_hz: f64,
) -> Option<Vec<nalgebra::DMatrix<f64>>> {
    let (rho, s, v) = model.paths(z).ok()?;
    windows
        .iter()
        .map(|range| {
            let n = range.end - range.start;
            let part = n / SUB_WINDOWS;
            let mut sum = nalgebra::DMatrix::zeros(levels, levels);
            for i in 0..SUB_WINDOWS {
                let sub = range.start + i * part..range.start + (i + 1) * part;
                let mean = |x: &[f64]| x[sub.clone()].iter().sum::<f64>() / part as f64;
                let (r, s2, v2) = (mean(&rho), mean(&s), mean(&v));
                let text = if model.gamma.is_some() {
                    format!("AR1(phi={r}, sigma2={s2})+WN(sigma2={v2})")
                } else {
                    format!("AR1(phi={r}, sigma2={s2})")
                };
                let stationary = crate::model::Model::parse(&text).ok()?;
                sum += crate::variance::implied_cov::exact_wv_covariance(
                    &stationary,
                    n,
                    freq_hz,
                    levels,
                )
                .ok()?;
            }
            Some(sum / SUB_WINDOWS as f64)
        })
        .collect()
}

/// Parts of a window over which [`window_covariances`] averages the stationary `V`: the
/// covariance of a WV is convex in `rho` near 1, so the `V` at the window's mean `rho`
/// understates it when `rho` moves within the window (by half in the study).
const SUB_WINDOWS: usize = 8;

/// Sandwich standard errors of the free parameters with the windows' covariances `blocks`
/// (block-diagonal `V`, the windows taken as independent).
fn standard_errors(
    obj: &NsObjective<'_>,
    u: &[f64],
    blocks: &[nalgebra::DMatrix<f64>],
) -> Vec<Option<f64>> {
    use nalgebra::DMatrix;
    let p = u.len();
    let m = obj.nu_hat.len();
    let mut ev = obj.buffer();
    if obj.evaluate(u, &mut ev, true).is_err() {
        return vec![None; p];
    }
    // A = d nu / d u (the whitened Jacobian over -sqrt(omega))
    let a = DMatrix::from_fn(m, p, |i, k| -ev.jac[i * p + k] / obj.sqrt_omega[i]);
    let omega = DMatrix::from_fn(m, m, |i, k| {
        if i == k {
            obj.sqrt_omega[i] * obj.sqrt_omega[i]
        } else {
            0.0
        }
    });
    let mut big_v = DMatrix::zeros(m, m);
    for (w, block) in blocks.iter().enumerate() {
        let at = w * obj.levels;
        big_v
            .view_mut((at, at), (obj.levels, obj.levels))
            .copy_from(block);
    }
    match crate::inference::asymptotic::sandwich(&a, &omega, &big_v) {
        Ok(s) => (0..p)
            .map(|k| Some(s.psi[(k, k)]).filter(|x| *x > 0.0).map(f64::sqrt))
            .collect(),
        Err(_) => vec![None; p],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `Var(W_{j,t})` from the full covariance matrix of the window (O(L^2) per coefficient).
    fn brute_force(m: &NsAr1, z: &[f64], window: Range<usize>, levels: usize) -> Vec<f64> {
        let (rho, s, v) = m.paths(z).unwrap();
        let n = z.len();
        let mut p = vec![0.0; n];
        p[0] = s[0] / (1.0 - rho[0] * rho[0]);
        for t in 1..n {
            p[t] = rho[t] * rho[t] * p[t - 1] + s[t];
        }
        let cov = |u: usize, w: usize| {
            let (a, b) = (u.min(w), u.max(w));
            let c = p[a] * rho[a + 1..=b].iter().product::<f64>();
            c + if a == b { v[a] } else { 0.0 }
        };
        (1..=levels)
            .map(|j| {
                let l = 1usize << j;
                let h = l / 2;
                let ts: Vec<usize> = (window.start + l - 1..window.end).collect();
                ts.iter()
                    .map(|&t| {
                        let coef = |k: usize| if k < h { 1.0 } else { -1.0 } / l as f64;
                        let mut sum = 0.0;
                        for a in 0..l {
                            for b in 0..l {
                                sum += coef(a) * coef(b) * cov(t - a, t - b);
                            }
                        }
                        sum
                    })
                    .sum::<f64>()
                    / ts.len() as f64
            })
            .collect()
    }

    #[test]
    fn implied_wv_matches_brute_force() {
        let n = 300;
        let z: Vec<f64> = (0..n).map(|t| (t as f64 / 40.0).sin()).collect();
        let m = NsAr1 {
            beta: [1.5, 0.8],
            alpha: [0.2, -0.5],
            gamma: Some([-1.0, 0.7]),
        };
        let windows = [0..128, 100..300];
        let exact = m.implied_wv(&z, &windows, 5).unwrap();
        for (w, row) in windows.iter().zip(&exact) {
            let b = brute_force(&m, &z, w.clone(), 5);
            for (e, b) in row.iter().zip(&b) {
                assert!((e / b - 1.0).abs() < 1e-12, "{row:?} vs {b}");
            }
        }
    }

    #[test]
    fn implied_wv_of_a_constant_path_is_the_stationary_one() {
        let z = vec![0.3; 4096];
        let m = NsAr1 {
            beta: [2.0, 1.0],
            alpha: [-1.0, 2.0],
            gamma: Some([0.5, 0.0]),
        };
        let phi = (2.0f64 + 0.3).tanh();
        let s2 = (-1.0f64 + 0.6).exp();
        let stationary = crate::model::Model::parse(&format!(
            "AR1(phi={phi}, sigma2={s2})+WN(sigma2={})",
            0.5f64.exp()
        ))
        .unwrap();
        let levels = 8;
        let want = stationary.implied_wv(levels, 1.0).unwrap().wv;
        let whole = Range {
            start: 0,
            end: 4096,
        };
        let got = m
            .implied_wv(&z, std::slice::from_ref(&whole), levels)
            .unwrap();
        for (g, w) in got[0].iter().zip(&want) {
            assert!((g / w - 1.0).abs() < 1e-10, "{got:?} vs {want:?}");
        }
    }

    #[test]
    fn simulated_mean_wv_matches_the_implied_one() {
        let n = 2048;
        let z: Vec<f64> = (0..n)
            .map(|t| (6.0 * std::f64::consts::PI * t as f64 / n as f64).sin())
            .collect();
        let m = NsAr1 {
            beta: [2.0, 0.6],
            alpha: [0.0, 0.3],
            gamma: Some([0.0, 0.0]),
        };
        let windows = [0..1024, 1024..2048];
        let exact = m.implied_wv(&z, &windows, 6).unwrap();
        let reps = 400;
        let opts = WvOptions {
            levels: Some(6),
            ..WvOptions::default()
        };
        let mut mean = vec![vec![0.0; 6]; 2];
        for r in 0..reps {
            let x = m.simulate(&z, 100 + r).unwrap();
            for (row, w) in mean.iter_mut().zip(&windows) {
                let wv = wavelet_variance(&x[w.clone()], 1.0, &opts).unwrap();
                for (m, v) in row.iter_mut().zip(&wv.wv) {
                    *m += v / reps as f64;
                }
            }
        }
        // 400 replicates: the mean's relative SE is below 3% at these levels; 4 SE
        for k in 0..2 {
            for j in 0..6 {
                assert!(
                    (mean[k][j] / exact[k][j] - 1.0).abs() < 0.12,
                    "window {k} level {}: {} vs {}",
                    j + 1,
                    mean[k][j],
                    exact[k][j]
                );
            }
        }
    }

    #[test]
    fn refuses_what_it_cannot_fit() {
        let x = vec![0.0; 4096];
        let opts = NsAr1Options::default();
        let e = fit_ns_ar1(&x, &[1.0; 4096], 1.0, &opts)
            .unwrap_err()
            .to_string();
        assert!(e.contains("constant"), "{e}");
        let e = fit_ns_ar1(&x, &[1.0; 100], 1.0, &opts)
            .unwrap_err()
            .to_string();
        assert!(e.contains("one value per sample"), "{e}");
        let mut z = vec![0.0; 4096];
        z[7] = f64::NAN;
        let e = fit_ns_ar1(&x, &z, 1.0, &opts).unwrap_err().to_string();
        assert!(e.contains("sample 7"), "{e}");
    }
}
