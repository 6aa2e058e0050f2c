//! A latent process shared by several axes (paper §IV-A; docs/methods.md §15): `x_i = V + U_i`,
//! estimated from the axes' wavelet variances and their wavelet cross-covariances, with
//! intervals for every parameter and a test of "no shared process".
//!
//! # Model (docs/methods.md §15.2)
//! `P >= 2` series of one length `N` (e.g. a gyro triad) are `x_i = V + U_i`, `V` the shared
//! process (a [`Model`], e.g. `GM()`) and `U_i` the axis-specific processes (one model text for
//! every axis, each axis with its own parameters, e.g. `WN()+RW()`), all independent. With `nu_P`
//! the implied Haar WV of a process (docs/methods.md §4), at every level `j`:
//!
//! `nu2_i(j) = nu_V(j; theta_V) + nu_{U_i}(j; theta_i)`,  `c_ik(j) = nu_V(j; theta_V)`  (`i < k`)
//!
//! since `W_i = W_V + W_{U_i}` and the cross terms have mean zero. A per-axis loading
//! (`x_i = l_i V + U_i`) is not implemented: with three axes it is identified (`c_ik = l_i l_k
//! nu_V`), but the sign of each loading is not, and the gyro triads seen so far need no loading.
//!
//! # Estimator (docs/methods.md §15.4)
//! The moments `m = (nu2_hat_1, .., nu2_hat_P, c_hat_12, c_hat_13, ..)`, `(P + P(P-1)/2) J`
//! values (`crate::variance::cross`), are fitted at once by GMWM (docs/methods.md §5.1) with a
//! diagonal `Omega`, by the one Levenberg–Marquardt optimiser on the stacked objective:
//! 1. **stage 1**, proxy weights: `Var nu2_hat_i(j) ~ 2 nu2_hat_i(j)^2 / eta_j` (the chi-square
//!    law of §1.7) and `Var c_hat_ik(j) ~ (nu2_hat_i(j) nu2_hat_k(j) + c_hat_ik(j)^2) / eta_j`
//!    (Isserlis with every coefficient autocorrelation equal to one common `rho_j(h)`, and
//!    `sum_h rho_j(h)^2 / M_j ~ 1 / eta_j` as for the WV);
//! 2. **stage 2**, `Omega = diag(V(theta_1))^{-1}` with `V` the exact covariance of the stacked
//!    moments at the stage-1 estimate (`crate::variance::cross`), refitted from it.
//!
//! Starting values, stage 1 run from each, the lowest objective kept: (a) `V` fitted alone
//! (docs/methods.md §5.5, its own start search) to the mean cross-covariance over the pairs
//! (levels where it is not positive floored at `1e-3` of the smallest WV there), each `U_i` to
//! its WV less that; (b) the same `V`, each `U_i` fitted to its whole WV; (c) for each axis `i`,
//! the `V` part of the model `V + U_i` fitted to axis `i` alone (the fits of the test under H0),
//! with every axis's `U` part of its own such fit. A start from (a) or (b) alone ends in a local
//! minimum (the shared GM turned into white noise) in about a quarter of simulated triads. Several AR1/GM in one
//! block are parametrised one by one (docs/methods.md §5.3, `PhiOrder::Free`) and sorted
//! afterwards (§5.6).
//!
//! # Inference (docs/methods.md §15.5)
//! The sandwich of docs/methods.md §7.1 on the stacked moments, `Psi = H V H'`,
//! `H = (A' Omega A)^+ A' Omega`, with `A` the Jacobian of the stacked implied moments and `V`
//! their exact covariance at the estimate; intervals on the scales of §7.2. The shared process's
//! implied WV gets the pointwise band `nu_V(j) exp(+- z sd_j / nu_V(j))`, `sd_j^2 = a_j' Psi_VV
//! a_j` (delta method on the log scale).
//!
//! # Test of "no shared process" (docs/methods.md §15.6)
//! `H0: c_ik(j) = 0` at every level and pair. Under H0 the axes are independent, each fitted
//! alone with the model `V + U_i` (GMWM, §5); by §15.3 with no shared component, different pairs
//! are uncorrelated and `Sigma_ik = Cov(c_hat_ik)` (over the levels) is the `J x J` block
//! `T(U_i', U_k')` of the fitted axis models. The statistic
//!
//! `T = sum_{i<k} c_hat_ik' Sigma_ik^{-1} c_hat_ik  ~  chi2(df = #pairs x #levels)`
//!
//! uses the levels with `eta_j >= 10` only ([`SharedOptions::test_min_eta`]): `c_hat_ik(j)` is a
//! mean of about `eta_j` independent products of two normals (excess kurtosis 6), so its law is
//! near-normal only when `eta_j` is not small. Its size is checked by Monte Carlo
//! (`crates/gmwm/src/tests/shared.rs`).

use crate::error::{InputError, ParamError};
use crate::fit::objective::Stack;
use crate::fit::optimize::minimize;
use crate::fit::FitError as Error;
use crate::fit::{
    Convergence, Gmwm, GmwmFit, LmOptions, Objective, Parametrisation, PhiOrder, StartInputs,
    TransformPreset,
};
use crate::inference::asymptotic::{sandwich, wald_interval, z_value, IntervalScale, ZConvention};
use crate::inference::ParameterInference;
use crate::math::elementary;
use crate::model::{Component, Model};
use crate::process::{spec, Process, Role};
use crate::variance::cross::{axis_pairs, stacked_moment_covariance, wavelet_cross_covariance};
use crate::variance::wv::{default_levels, wavelet_variance, WaveletVariance, WvOptions};
use crate::wavelet::{Transform, WaveletFilter};
use nalgebra::DMatrix;
use serde::Serialize;
use std::fmt;

/// Settings of [`fit_shared`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SharedOptions {
    /// Levels `J`; default `None`: the Haar default of docs/methods.md §1.6.
    pub levels: Option<usize>,
    /// Significance level of the intervals; default 0.05 (§7.2).
    pub alpha: f64,
    /// Seed of the starting-value searches; default 1337 (§5.7).
    pub seed: u64,
    /// Draws of each starting-value search; default 2000 (each block is a small model).
    pub draws: usize,
    /// Smallest `eta_j` (§1.7) of a level used by the test of no shared process; default 10
    /// (module docs).
    pub test_min_eta: f64,
}

impl Default for SharedOptions {
    fn default() -> Self {
        Self {
            levels: None,
            alpha: 0.05,
            seed: 1337,
            draws: 2000,
            test_min_eta: 10.0,
        }
    }
}

/// One estimated parameter of a shared-process fit: the inference on it (standard error from
/// the sandwich of §15.5; `None` for a component collapsed to its boundary, no influence on the
/// moments, or when the exact covariance is not available) and the block it belongs to.
///
/// Wire format: `block`, then the fields of [`ParameterInference`] (`name`, `estimate`, `se`,
/// `ci_low`, `ci_high`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SharedParameter {
    /// `shared` or the axis name.
    pub block: String,
    /// The parameter (label e.g. `GM[0].beta`; GM as `beta` 1/s, `sigma2_gm`).
    #[serde(flatten)]
    pub parameter: ParameterInference,
}

/// The test of "no shared process" (module docs, docs/methods.md §15.6).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NoSharedTest {
    /// `T = sum_pairs c' Sigma^{-1} c`.
    pub statistic: f64,
    /// Degrees of freedom: pairs x levels used.
    pub df: usize,
    /// `P(chi2(df) > T)`.
    pub p_value: f64,
    /// Levels `j` used (those with `eta_j >= test_min_eta`).
    pub levels: Vec<usize>,
    /// The model fitted to each axis alone under H0.
    pub(crate) null_models: Vec<String>,
}

/// The cross-covariance of one pair of axes with its standard errors.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CrossCovariance {
    /// First axis.
    pub a: String,
    /// Second axis.
    pub b: String,
    /// `c_hat_ab(j)`.
    pub values: Vec<f64>,
    /// Standard deviation of `c_hat_ab(j)` at the fitted model (§15.3).
    pub sd: Vec<f64>,
}

/// Result of [`fit_shared`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SharedFit {
    /// Axis names.
    pub axes: Vec<String>,
    /// Samples per axis.
    pub n: usize,
    /// Sampling rate (Hz).
    pub freq_hz: f64,
    /// Significance level of the intervals.
    pub alpha: f64,
    /// Scales `2^j / freq_hz` (s).
    pub tau_s: Vec<f64>,
    /// Equivalent degrees of freedom per level (§1.7).
    pub eta: Vec<f64>,
    /// The shared model with its estimates.
    pub shared_model: String,
    /// Each axis's specific model with its estimates.
    pub(crate) specific_models: Vec<String>,
    /// Every parameter: the shared ones first, then axis by axis.
    pub parameters: Vec<SharedParameter>,
    /// Each axis's WV.
    pub wv: Vec<Vec<f64>>,
    /// The pairwise cross-covariances.
    pub cross: Vec<CrossCovariance>,
    /// The shared process's implied WV `nu_V(j)` at the estimate.
    pub shared_wv: Vec<f64>,
    /// Lower end of its pointwise `1 - alpha` band (`None` without a covariance).
    pub shared_wv_low: Vec<Option<f64>>,
    /// Upper end of its pointwise `1 - alpha` band.
    pub shared_wv_high: Vec<Option<f64>>,
    /// Each axis's implied WV `nu_V + nu_{U_i}`.
    pub implied_wv: Vec<Vec<f64>>,
    /// Final stacked objective `Q`.
    pub objective: f64,
    /// How the final minimisation ended.
    pub convergence: Convergence,
    /// The test of no shared process.
    pub test: NoSharedTest,
}

impl SharedFit {
    /// The shared process's parameters.
    #[cfg(test)]
    pub(crate) fn shared_parameters(&self) -> impl Iterator<Item = &SharedParameter> {
        self.parameters.iter().filter(|p| p.block == "shared")
    }
}

fn refuse_drift(model: &Model, which: &'static str) -> Result<(), ParamError> {
    if model.kinds().iter().any(|&k| spec(k).role == Role::Drift) {
        return Err(ParamError::new(
            which,
            model.to_string(),
            "no DR term in a shared-process fit (a drift is a mean, not a covariance)",
        ));
    }
    Ok(())
}

/// The model `V + U_i` of one axis alone, when the union is a valid model (e.g. `GM()+WN()+RW()`);
/// otherwise `U_i` (two white noises, say, add up to one).
fn union_model(shared: &Model, specific: &Model) -> Model {
    let comps: Vec<Component> = shared
        .without_values()
        .components()
        .iter()
        .chain(specific.without_values().components())
        .cloned()
        .collect();
    Model::new(comps).unwrap_or_else(|_| specific.without_values())
}

/// Most series one shared-process fit takes: `P + P(P-1)/2` moment blocks, an exact
/// covariance of their fourth power in size and time (16 axes: 136 blocks; an IMU array of
/// four triads is 12).
pub(crate) const MAX_SERIES: usize = 16;

/// Fits the shared-process model `x_i = V + U_i` (module docs, docs/methods.md §15) to the
/// `axes` (name, samples) at `freq_hz`.
///
/// ```
/// use gmwm::Model;
/// use gmwm::{fit_shared, SharedOptions};
/// use gmwm::simulate_model;
/// let v = simulate_model(&Model::parse("AR1(phi=0.99, sigma2=0.02)").unwrap(), 8192, 1.0, 1).unwrap();
/// let axes: Vec<Vec<f64>> = (0..3u64)
///     .map(|i| {
///         let u = simulate_model(&Model::parse("WN(sigma2=1)").unwrap(), 8192, 1.0, 10 + i).unwrap();
///         v.iter().zip(&u).map(|(a, b)| a + b).collect()
///     })
///     .collect();
/// let named: Vec<(&str, &[f64])> = vec![("x", &axes[0]), ("y", &axes[1]), ("z", &axes[2])];
/// let fit = fit_shared(&named, 1.0, &"AR1()".parse().unwrap(), &"WN()".parse().unwrap(),
///     &SharedOptions::default()).unwrap();
/// assert!(fit.test.p_value < 0.01); // the shared AR1 is detected
/// ```
///
/// # Errors
/// [`ParamError`] for fewer than two axes or more than 16, axes of different lengths, a DR term or a rate that
/// is not positive; as [`wavelet_variance`] for a series with non-finite values or too short
/// for the levels; [`FitError`](crate::FitError) (e.g. `TooFewLevels`) when the series is too short for the
/// model; a [`ParamError`] from the exact covariance for a term it does not cover.
pub fn fit_shared(
    axes: &[(&str, &[f64])],
    freq_hz: f64,
    shared: &Model,
    specific: &Model,
    opts: &SharedOptions,
) -> Result<SharedFit, Error> {
    let p = axes.len();
    if p < 2 {
        return Err(ParamError::new(
            "axes",
            p,
            "at least 2 series for a shared process (e.g. --columns gyro_x,gyro_y,gyro_z)",
        )
        .into());
    }
    if p > MAX_SERIES {
        return Err(ParamError::new(
            "axes",
            p,
            format!(
                "at most {MAX_SERIES} series for a shared process: the stacked moments grow \
                 as the square of the count and their covariance as its fourth power \
                 (choose the axes with --columns)"
            ),
        )
        .into());
    }
    if !(freq_hz.is_finite() && freq_hz > 0.0) {
        return Err(ParamError::new("freq", freq_hz, "a positive number of hertz").into());
    }
    let n = axes[0].1.len();
    if let Some((name, x)) = axes.iter().find(|(_, x)| x.len() != n) {
        return Err(ParamError::new(
            "axes",
            format!("{name} with {} samples", x.len()),
            format!("as many samples as {} ({n})", axes[0].0),
        )
        .into());
    }
    refuse_drift(shared, "--shared")?;
    refuse_drift(specific, "--model")?;
    let levels = opts
        .levels
        .unwrap_or_else(|| default_levels(n, Transform::Modwt, WaveletFilter::Haar));
    if levels == 0 {
        return Err(InputError::from(crate::SeriesError::TooShort {
            n,
            needed: 4,
            what: "a shared-process fit (Haar WV levels)".into(),
        })
        .into());
    }
    // each axis alone carries V + U_i (the fits of the starts and of the test): as many
    // levels as their parameters (docs/methods.md §5.7)
    let params = shared.n_params() + specific.n_params();
    if params > levels {
        return Err(crate::fit::FitError::TooFewLevels { params, levels });
    }
    let wv_opts = WvOptions {
        levels: Some(levels),
        alpha: opts.alpha,
        ..WvOptions::default()
    };
    let wvs: Vec<WaveletVariance> = axes
        .iter()
        .map(|(_, x)| wavelet_variance(x, freq_hz, &wv_opts))
        .collect::<Result<_, _>>()?;
    let pairs = axis_pairs(p);
    let cross: Vec<Vec<f64>> = pairs
        .iter()
        .map(|&(a, b)| wavelet_cross_covariance(axes[a].1, axes[b].1, levels))
        .collect::<Result<_, _>>()?;
    let eta = wvs[0].eta().to_vec();
    let moments: Vec<f64> = wvs
        .iter()
        .flat_map(|w| w.wv().iter().copied())
        .chain(cross.iter().flatten().copied())
        .collect();
    // stage-1 proxy variances (module docs)
    let mut proxy = Vec::with_capacity(moments.len());
    for w in &wvs {
        proxy.extend(w.wv().iter().zip(&eta).map(|(v, e)| 2.0 * v * v / e));
    }
    for (&(a, b), c) in pairs.iter().zip(&cross) {
        for j in 0..levels {
            let (na, nb) = (wvs[a].wv()[j], wvs[b].wv()[j]);
            proxy.push((na * nb + c[j] * c[j]) / eta[j]);
        }
    }
    let omega1: Vec<f64> = proxy.iter().map(|v| 1.0 / v).collect();

    // blocks: shared, then one per axis; moments rows: axis i = shared + U_i, pairs = shared
    let shared_t = shared.without_values();
    let spec_t = specific.without_values();
    let mut blocks = vec![shared_t.clone()];
    blocks.extend(std::iter::repeat(spec_t.clone()).take(p));
    let rows: Vec<Vec<usize>> = (0..p)
        .map(|i| vec![0, i + 1])
        .chain(pairs.iter().map(|_| vec![0]))
        .collect();
    let stack = Stack {
        blocks: blocks.clone(),
        levels: vec![levels; rows.len()],
        rows,
    };
    let param_of =
        |m: &Model| Parametrisation::new(m, TransformPreset::Imu, PhiOrder::Free, freq_hz);
    let mut labelled = vec![("shared", param_of(&shared_t)?)];
    for (name, _) in axes {
        labelled.push((name, param_of(&spec_t)?));
    }
    let param = Parametrisation::concat(&labelled).ok_or_else(|| {
        ParamError::new(
            "model",
            "ordered AR1/GM chain",
            "scalar transforms (internal)",
        )
    })?;

    // starting values (module docs)
    let gmwm = |m: &Model| {
        Gmwm::new(m.without_values())
            .with_seed(opts.seed)
            .with_draws(opts.draws)
            .with_phi_order(PhiOrder::Free)
    };
    let floor_of = |j: usize| wvs.iter().map(|w| w.wv()[j]).fold(f64::INFINITY, f64::min) * 1e-3;
    let mean_cross: Vec<f64> = (0..levels)
        .map(|j| {
            let m = cross.iter().map(|c| c[j]).sum::<f64>() / cross.len() as f64;
            m.max(floor_of(j))
        })
        .collect();
    let as_wv = |values: &[f64]| {
        WaveletVariance::assemble(
            n,
            freq_hz,
            &wv_opts,
            values,
            None,
            wvs[0].n_coefficients().to_vec(),
            eta.clone(),
        )
    };
    let shared_start = gmwm(&shared_t)
        .fit_from_wv(&as_wv(&mean_cross), StartInputs { n, range: 0.0 })?
        .theta()
        .to_vec();
    let mut starts: Vec<Vec<f64>> = vec![shared_start.clone(), shared_start];
    let mut alone = Vec::with_capacity(p);
    for (i, w) in wvs.iter().enumerate() {
        let less: Vec<f64> = w
            .wv()
            .iter()
            .zip(&mean_cross)
            .map(|(v, c)| (v - c).max(0.05 * v))
            .collect();
        let inputs = StartInputs::from_series(axes[i].1);
        let a = gmwm(&spec_t).fit_from_wv(&as_wv(&less), inputs)?;
        let b = gmwm(&spec_t).fit_from_wv(w, inputs)?;
        starts[0].extend_from_slice(a.theta());
        starts[1].extend_from_slice(b.theta());
        alone.push(b);
    }
    // each axis fitted alone with V + U_i (also the fits of the test under H0): the shared
    // block of axis i's fit with every axis's own U_i
    let union = union_model(shared, specific);
    let null_fits: Vec<GmwmFit> = wvs
        .iter()
        .zip(axes)
        .map(|(w, (_, x))| {
            Gmwm::new(union.clone())
                .with_seed(opts.seed)
                .with_draws(opts.draws)
                .fit_from_wv(w, StartInputs::from_series(x))
        })
        .collect::<Result<_, _>>()?;
    let (nv, nu) = (shared_t.n_params(), spec_t.n_params());
    if union.n_params() == nv + nu {
        for from in &null_fits {
            let mut s = from.theta()[..nv].to_vec();
            for f in &null_fits {
                s.extend_from_slice(&f.theta()[nv..]);
            }
            starts.push(s);
        }
    }
    let lm = LmOptions::default();
    let obj1 =
        Objective::stacked_moments(stack.clone(), param.clone(), &moments, &omega1, freq_hz)?;
    let mut best: Option<crate::fit::optimize::Minimum> = None;
    let mut last_err = None;
    for s in &starts {
        let attempt = param
            .to_u_restart(s)
            .and_then(|u0| minimize(&obj1, &u0, &lm));
        match attempt {
            Ok(m) if best.as_ref().map_or(true, |b| m.objective < b.objective) => best = Some(m),
            Ok(_) => {}
            Err(e) => last_err = Some(e),
        }
    }
    let stage1 = match (best, last_err) {
        (Some(b), _) => b,
        (None, Some(e)) => return Err(e),
        (None, None) => unreachable!("at least one start"),
    };
    let processes = |theta: &[f64]| -> Result<(Vec<Process>, Vec<Vec<Process>>), Error> {
        let offs = stack.offsets();
        let block = |b: usize| -> Result<Vec<Process>, Error> {
            let m = blocks[b].with_values(&theta[offs[b]..offs[b] + blocks[b].n_params()])?;
            Ok(m.processes(freq_hz)?)
        };
        Ok((block(0)?, (1..=p).map(block).collect::<Result<_, _>>()?))
    };
    let (sv, uv) = processes(&stage1.theta)?;
    let v1 = stacked_moment_covariance(&sv, &uv, n, levels)?;
    // a component collapsed at stage 1 (e.g. phi rounding to 1) can leave V without a finite
    // diagonal: such a moment keeps its proxy weight
    let omega2: Vec<f64> = (0..moments.len())
        .map(|r| {
            let x = v1[(r, r)];
            if x.is_finite() && x > 0.0 {
                1.0 / x
            } else {
                omega1[r]
            }
        })
        .collect();
    let obj2 =
        Objective::stacked_moments(stack.clone(), param.clone(), &moments, &omega2, freq_hz)?;
    let fin = minimize(&obj2, &stage1.u, &lm)?;
    let theta = fin.theta.clone();

    // inference at the estimate (module docs)
    let (sv, uv) = processes(&theta)?;
    let v = stacked_moment_covariance(&sv, &uv, n, levels)?;
    let np = theta.len();
    let rows_n = moments.len();
    let mut implied = vec![0.0; rows_n];
    let mut a_flat = vec![0.0; rows_n * np];
    obj2.implied(&theta, &mut implied, Some(&mut a_flat))?;
    let a = DMatrix::from_row_slice(rows_n, np, &a_flat);
    // inactive parameters (a component collapsed to its boundary: its whitened, relative
    // influence below INACTIVE_INFLUENCE) get no standard error; the sandwich runs on the others
    let scale = moments
        .iter()
        .zip(&omega2)
        .map(|(m, w)| w * m * m)
        .sum::<f64>()
        .sqrt();
    let active: Vec<usize> = (0..np)
        .filter(|&k| {
            let col = (0..rows_n)
                .map(|r| omega2[r] * a[(r, k)] * a[(r, k)])
                .sum::<f64>()
                .sqrt();
            let infl = col * theta[k].abs();
            infl.is_finite() && infl > INACTIVE_INFLUENCE * scale
        })
        .collect();
    let mut psi = DMatrix::from_element(np, np, f64::NAN);
    if v.iter().all(|x| x.is_finite()) && !active.is_empty() {
        let a_act = DMatrix::from_fn(rows_n, active.len(), |r, k| a[(r, active[k])]);
        let omega = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(omega2.clone()));
        if let Ok(sw) = sandwich(&a_act, &omega, &v) {
            for (i, &ki) in active.iter().enumerate() {
                for (l, &kl) in active.iter().enumerate() {
                    psi[(ki, kl)] = sw.psi[(i, l)];
                }
            }
        }
    }
    let z = z_value(opts.alpha, ZConvention::TwoSided)?;
    let mut parameters = Vec::with_capacity(np);
    let offs = stack.offsets();
    for (b, model) in blocks.iter().enumerate() {
        let label = if b == 0 { "shared" } else { axes[b - 1].0 };
        let mut at = offs[b];
        for c in model.components() {
            for (k, name) in c.kind.param_names().iter().enumerate() {
                let var = psi[(at, at)];
                let se = (var.is_finite() && var >= 0.0).then(|| var.sqrt());
                let (lo, hi) = match se {
                    Some(se) => {
                        let (lo, hi) = wald_interval(
                            theta[at],
                            se,
                            z,
                            c.kind.param_domain(k),
                            IntervalScale::Transformed,
                        );
                        (Some(lo), Some(hi))
                    }
                    None => (None, None),
                };
                parameters.push(SharedParameter {
                    block: label.to_string(),
                    parameter: ParameterInference {
                        name: format!("{}.{name}", c.kind.base_name()),
                        estimate: theta[at],
                        se,
                        ci_low: lo,
                        ci_high: hi,
                    },
                });
                at += 1;
            }
        }
    }
    // the shared WV and its band: rows of the first cross block are nu_V
    let first_cross = p * levels;
    let mut shared_wv = Vec::with_capacity(levels);
    let (mut band_lo, mut band_hi) = (Vec::new(), Vec::new());
    for j in 0..levels {
        let r = first_cross + j;
        let nu = implied[r];
        let mut var = 0.0;
        for k in 0..nv {
            for l in 0..nv {
                var += a[(r, k)] * psi[(k, l)] * a[(r, l)];
            }
        }
        let rel = var.max(0.0).sqrt() / nu;
        shared_wv.push(nu);
        let ok = rel.is_finite() && var.is_finite();
        band_lo.push(ok.then(|| nu * elementary::exp(-z * rel)));
        band_hi.push(ok.then(|| nu * elementary::exp(z * rel)));
    }
    let implied_wv = (0..p)
        .map(|i| implied[i * levels..(i + 1) * levels].to_vec())
        .collect();
    let cross_out = pairs
        .iter()
        .zip(&cross)
        .enumerate()
        .map(|(k, (&(ia, ib), c))| CrossCovariance {
            a: axes[ia].0.to_string(),
            b: axes[ib].0.to_string(),
            values: c.clone(),
            sd: (0..levels)
                .map(|j| {
                    let r = (p + k) * levels + j;
                    v[(r, r)].max(0.0).sqrt()
                })
                .collect(),
        })
        .collect();
    let test = no_shared_test(&wvs, &cross, &null_fits, &alone, opts, n, levels)?;
    let with_values = |b: usize| -> Result<String, Error> {
        let m = blocks[b].with_values(&theta[offs[b]..offs[b] + blocks[b].n_params()])?;
        Ok(m.to_string())
    };
    Ok(SharedFit {
        axes: axes.iter().map(|(n, _)| n.to_string()).collect(),
        n,
        freq_hz,
        alpha: opts.alpha,
        tau_s: wvs[0].tau_s().to_vec(),
        eta,
        shared_model: with_values(0)?,
        specific_models: (1..=p).map(with_values).collect::<Result<_, _>>()?,
        parameters,
        wv: wvs.iter().map(|w| w.wv().to_vec()).collect(),
        cross: cross_out,
        shared_wv,
        shared_wv_low: band_lo,
        shared_wv_high: band_hi,
        implied_wv,
        objective: fin.objective,
        convergence: fin.convergence,
        test,
    })
}

/// Relative eigenvalue cut-off of [`quadratic_form`]: the exact covariance of the
/// cross-covariances over neighbouring coarse levels is nearly singular (a random walk makes
/// them move together) and is known to about `1e-10` relative (quadrature, polarisation), so
/// directions with a smaller eigenvalue of the correlation matrix carry no information.
const EIGEN_CUTOFF: f64 = 1e-9;

/// A parameter whose whitened influence on the moments for a unit relative change
/// (`|theta_k| ||sqrt(Omega) A_k||`) is below this fraction of the whitened moments' norm has
/// collapsed to its boundary (as `crate::fit::active` for one series) and gets no standard error.
const INACTIVE_INFLUENCE: f64 = 1e-7;

/// `c' Sigma^+ c` on the correlation scale (eigenvalues below [`EIGEN_CUTOFF`] times the
/// largest dropped) and the rank used, the degrees of freedom of its chi-square law.
fn quadratic_form(sigma: &DMatrix<f64>, c: &nalgebra::DVector<f64>) -> (f64, usize) {
    let d: Vec<f64> = (0..c.len())
        .map(|i| sigma[(i, i)].max(0.0).sqrt())
        .collect();
    if d.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
        return (0.0, 0);
    }
    let r = DMatrix::from_fn(c.len(), c.len(), |i, j| sigma[(i, j)] / (d[i] * d[j]));
    let z = nalgebra::DVector::from_fn(c.len(), |i, _| c[i] / d[i]);
    let eig = r.symmetric_eigen();
    let max = eig.eigenvalues.max();
    let mut t = 0.0;
    let mut rank = 0;
    for (k, &l) in eig.eigenvalues.iter().enumerate() {
        if l > EIGEN_CUTOFF * max {
            let q = eig.eigenvectors.column(k).dot(&z);
            t += q * q / l;
            rank += 1;
        }
    }
    (t, rank)
}

/// The test of no shared process (module docs, docs/methods.md §15.6).
#[allow(clippy::too_many_arguments)]
fn no_shared_test(
    wvs: &[WaveletVariance],
    cross: &[Vec<f64>],
    null_fits: &[GmwmFit],
    alone: &[GmwmFit],
    opts: &SharedOptions,
    n: usize,
    levels: usize,
) -> Result<NoSharedTest, Error> {
    let covariance = |fits: &[GmwmFit]| -> Result<(DMatrix<f64>, Vec<String>), Error> {
        let mut procs = Vec::with_capacity(fits.len());
        let mut names = Vec::with_capacity(fits.len());
        for (fit, w) in fits.iter().zip(wvs) {
            names.push(fit.model().to_string());
            procs.push(fit.model().processes(w.freq_hz())?);
        }
        Ok((stacked_moment_covariance(&[], &procs, n, levels)?, names))
    };
    // a component of V + U_i that collapsed in an axis's fit (a GM with phi rounding to 0 or
    // 1) can leave its exact covariance without finite entries: then U_i alone, fitted to the
    // axis, gives the null covariance
    let (v0, null_models) = match covariance(null_fits) {
        Ok((v, names)) if v.iter().all(|x| x.is_finite()) => (v, names),
        _ => covariance(alone)?,
    };
    let used: Vec<usize> = (0..levels)
        .filter(|&j| wvs[0].eta()[j] >= opts.test_min_eta)
        .collect();
    let p = null_fits.len();
    let mut statistic = 0.0;
    let mut df = 0;
    for (k, c) in cross.iter().enumerate() {
        let base = (p + k) * levels;
        let sigma = DMatrix::from_fn(used.len(), used.len(), |r, s| {
            v0[(base + used[r], base + used[s])]
        });
        let cv = nalgebra::DVector::from_iterator(used.len(), used.iter().map(|&j| c[j]));
        let (t, rank) = quadratic_form(&sigma, &cv);
        statistic += t;
        df += rank;
    }
    let p_value = if df == 0 {
        1.0
    } else {
        statrs::function::gamma::gamma_ur(df as f64 / 2.0, statistic / 2.0)
    };
    Ok(NoSharedTest {
        statistic,
        df,
        p_value,
        levels: used.iter().map(|j| j + 1).collect(),
        null_models,
    })
}

impl fmt::Display for SharedFit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "shared process across {} ({} samples at {} Hz, {} levels)",
            self.axes.join(", "),
            self.n,
            self.freq_hz,
            self.tau_s.len()
        )?;
        writeln!(f, "shared:   {}", self.shared_model)?;
        for (a, m) in self.axes.iter().zip(&self.specific_models) {
            writeln!(f, "{a}: {m}")?;
        }
        let pct = 100.0 * (1.0 - self.alpha);
        writeln!(
            f,
            "\n{:<10} {:<16} {:>13} {:>11} {:>13} {:>13}",
            "block",
            "parameter",
            "estimate",
            "SE",
            format!("{pct:.0}% low"),
            format!("{pct:.0}% high")
        )?;
        let opt = |v: Option<f64>, w: usize| match v {
            Some(v) => format!("{v:>w$.5e}"),
            None => format!("{:>w$}", "-"),
        };
        for p in &self.parameters {
            writeln!(
                f,
                "{:<10} {:<16} {:>13.5e} {} {} {}",
                p.block,
                p.parameter.name,
                p.parameter.estimate,
                opt(p.parameter.se, 11),
                opt(p.parameter.ci_low, 13),
                opt(p.parameter.ci_high, 13)
            )?;
        }
        writeln!(
            f,
            "\nno shared process: T = {:.4} on {} df (levels {}..{}), p-value {:.4}",
            self.test.statistic,
            self.test.df,
            self.test.levels.first().copied().unwrap_or(0),
            self.test.levels.last().copied().unwrap_or(0),
            self.test.p_value
        )?;
        write!(f, "{}", self.convergence)
    }
}
