//! The augmented GMWM, GMWM+ (paper §IV-C; docs/methods.md §5.15): the wavelet variance stacked
//! with extra moments of the series ([`Augment`]: the mean and first autocovariances of its
//! differences), weighted by the inverse of their joint covariance.
//!
//! The estimator, in two steps:
//! 1. the GMWM fit of the model (the estimator's own weighting and starting values): `theta~`;
//! 2. the joint covariance `V+` of the moment vector `(nu2_hat, m_hat)` by the parametric
//!    bootstrap at `theta~` (`H` series of the observed length, the §7.4 bootstrap with the
//!    extra moments computed on each replicate), and the fit of the stacked moments from
//!    `theta~` with `Omega = (H - M - 2) / (H - 1) V+^{-1}`: the inverse of a sample covariance
//!    over-weights by `(H - 1) / (H - M - 2)` on average (Hartlap, Simon & Schneider 2007), and
//!    the factor removes that bias from the standard errors and the J-test.
//!
//! Inference: `Var(theta_hat) = (A' Omega A)^{-1}` (the efficient weighting), Wald intervals on
//! the scale of docs/methods.md §7.2 (log for variances, atanh for coefficients), and the
//! J-test `Q(theta_hat) ~ chi2(M - p)`.
//!
//! With [`Augment::none`] the same steps are the efficient two-step GMWM with a full bootstrap
//! `V` of the WV alone: comparing the two on the same replicates isolates what the extra moments
//! add (the study `tests::augmented::gmwm_plus_efficiency_study`).

use crate::fit::report::physical_parameters;
use crate::fit::{minimize, Augment, FitError, FitEstimates, FullWeights, Gmwm, GmwmFit};
use crate::fit::{Objective, Parametrisation};
use crate::inference::asymptotic::{sandwich, scales, z_value};
use crate::inference::{IntervalScale, ZConvention};
use crate::sim::bootstrap::{map_replicates, WvBootstrap};
use crate::variance::wv::WvOptions;
use crate::ParamError;
use nalgebra::DMatrix;
use serde::Serialize;
use statrs::distribution::{ChiSquared, ContinuousCDF};
use std::fmt;

/// Replicates of the joint covariance by default: enough that `H - M - 2` stays well above
/// the moment count of a 20-level WV with a few extra moments.
pub const DEFAULT_AUGMENT_REPLICATES: usize = 200;

/// Settings of a GMWM+ fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AugmentOptions {
    /// The extra moments.
    pub augment: Augment,
    /// Replicates `H` of the joint covariance (more than the moment count plus 2).
    pub replicates: usize,
    /// Seed of the bootstrap.
    pub seed: u64,
    /// Level of the intervals (two-sided).
    pub alpha: f64,
}

impl AugmentOptions {
    /// `augment` with the default replicates, seed 1 and 95% intervals.
    pub fn new(augment: Augment) -> Self {
        Self {
            augment,
            replicates: DEFAULT_AUGMENT_REPLICATES,
            seed: 1,
            alpha: 0.05,
        }
    }
}

/// One moment of the stacked vector: observed and implied at the GMWM+ estimate.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AugmentedMoment {
    /// `nu2[j]` for a WV level, or the extra moment's name (`mean_diff`, `acf_diff[h]`).
    pub name: String,
    /// Sample value (data unit squared per sample for the WV and autocovariances, data unit
    /// per sample for the mean).
    pub observed: f64,
    /// Implied by the GMWM+ estimate.
    pub implied: f64,
    /// Bootstrap standard deviation of the sample value.
    pub sd: f64,
}

/// One parameter: the GMWM estimate beside the GMWM+ one with its interval.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AugmentedParameter {
    /// Label, `KIND[component].name`.
    pub name: String,
    /// The GMWM estimate (step 1).
    pub gmwm: f64,
    /// The GMWM+ estimate.
    pub value: f64,
    /// Its standard error; `None` when the parameter is not identified at the estimate.
    pub se: Option<f64>,
    /// Interval bounds at the options' level.
    pub ci_low: Option<f64>,
    /// Upper bound.
    pub ci_high: Option<f64>,
}

/// A physical quantity of a GMWM+ fit (the table of `crate::fit::report`: white-noise density,
/// rate random-walk density, ...) beside its GMWM value, with the interval its parameter's
/// gives for one-parameter terms (the maps are monotone).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AugmentedPhysical {
    /// Process of the component.
    pub process: String,
    /// 0-based position of the component in the model.
    pub index: usize,
    /// Quantity, e.g. `white_noise_density`.
    pub name: &'static str,
    /// From the GMWM estimate.
    pub gmwm: f64,
    /// From the GMWM+ estimate.
    pub value: f64,
    /// Interval bounds (one-parameter terms with an interval).
    pub ci_low: Option<f64>,
    /// Upper bound.
    pub ci_high: Option<f64>,
    /// Unit, in terms of the data unit.
    pub unit: String,
}

/// The J-test of the stacked moments.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AugmentedJTest {
    /// `Q(theta_hat)` with the efficient weights.
    pub statistic: f64,
    /// `M - p`.
    pub df: usize,
    /// `P(chi2(df) > statistic)`; `None` when `df = 0`.
    pub p_value: Option<f64>,
}

/// The result of a GMWM+ fit.
///
/// Wire format: `augment` (e.g. `"mean,acf:3"`), `replicates`, `model` (text with the GMWM+
/// estimates), `objective`, `converged`, `parameters` (`name`, `gmwm`, `value`, `se`, `ci_low`,
/// `ci_high`), `moments` (`name`, `observed`, `implied`, `sd`), `j_test` (`statistic`, `df`,
/// `p_value`), `alpha`.
#[derive(Debug, Clone, PartialEq)]
pub struct AugmentedFit {
    base: GmwmFit,
    augment: Augment,
    replicates: usize,
    alpha: f64,
    estimates: FitEstimates,
    parameters: Vec<AugmentedParameter>,
    moments: Vec<AugmentedMoment>,
    j_test: AugmentedJTest,
    covariance: DMatrix<f64>,
}

impl AugmentedFit {
    /// The GMWM fit of step 1 (its WV and starting values), not part of the wire format.
    pub fn gmwm(&self) -> &GmwmFit {
        &self.base
    }

    /// The extra moments used.
    pub fn augment(&self) -> Augment {
        self.augment
    }

    /// The GMWM+ estimates (model, theta, objective, convergence).
    pub fn estimates(&self) -> &FitEstimates {
        &self.estimates
    }

    /// The parameters, GMWM beside GMWM+.
    pub fn parameters(&self) -> &[AugmentedParameter] {
        &self.parameters
    }

    /// The stacked moments.
    pub fn moments(&self) -> &[AugmentedMoment] {
        &self.moments
    }

    /// The J-test.
    pub fn j_test(&self) -> AugmentedJTest {
        self.j_test
    }

    /// The physical quantities of the GMWM+ estimates beside GMWM's (`unit`: the data unit's
    /// name, `u` when `None`).
    pub fn physical(&self, unit: Option<&str>) -> Vec<AugmentedPhysical> {
        let freq = self.estimates.freq_hz;
        let mut out = Vec::new();
        let mut k = 0;
        for (index, c) in self.estimates.model.components().iter().enumerate() {
            let n = c.kind.n_params();
            let at = |theta: &[f64]| physical_parameters(c.kind, index, theta, freq, unit);
            let plus = at(&self.estimates.theta[k..k + n]);
            let base = at(&self.base.theta()[k..k + n]);
            let p = &self.parameters[k];
            let bounds = match (n, p.ci_low, p.ci_high) {
                (1, Some(lo), Some(hi)) => Some((at(&[lo]), at(&[hi]))),
                _ => None,
            };
            for (i, (q, b)) in plus.into_iter().zip(base).enumerate() {
                let (ci_low, ci_high) = match &bounds {
                    Some((lo, hi)) => {
                        let (a, b) = (lo[i].value, hi[i].value);
                        (Some(a.min(b)), Some(a.max(b)))
                    }
                    None => (None, None),
                };
                out.push(AugmentedPhysical {
                    process: q.process,
                    index,
                    name: q.name,
                    gmwm: b.value,
                    value: q.value,
                    ci_low,
                    ci_high,
                    unit: q.unit,
                });
            }
            k += n;
        }
        out
    }

    /// `Var(theta_hat)`, `p x p` in model order.
    pub fn covariance(&self) -> &DMatrix<f64> {
        &self.covariance
    }
}

impl Serialize for AugmentedFit {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut st = s.serialize_struct("AugmentedFit", 9)?;
        st.serialize_field("augment", &self.augment.to_string())?;
        st.serialize_field("replicates", &self.replicates)?;
        st.serialize_field("model", &self.estimates.model)?;
        st.serialize_field("objective", &self.estimates.objective)?;
        st.serialize_field("converged", &self.estimates.convergence.converged)?;
        st.serialize_field("parameters", &self.parameters)?;
        st.serialize_field("moments", &self.moments)?;
        st.serialize_field("j_test", &self.j_test)?;
        st.serialize_field("alpha", &self.alpha)?;
        st.end()
    }
}

impl fmt::Display for AugmentedFit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let level = 100.0 * (1.0 - self.alpha);
        writeln!(
            f,
            "GMWM+ (augment {}; joint V from {} bootstrap series)",
            self.augment, self.replicates
        )?;
        writeln!(
            f,
            "  {:<18} {:>13} {:>13} {:>11} {:>27}",
            "parameter",
            "GMWM",
            "GMWM+",
            "SE",
            format!("{level:.0}% interval")
        )?;
        for p in &self.parameters {
            let se = p.se.map_or("-".to_string(), |x| format!("{x:.4e}"));
            let ci = match (p.ci_low, p.ci_high) {
                (Some(lo), Some(hi)) => format!("[{lo:.4e}, {hi:.4e}]"),
                _ => "-".to_string(),
            };
            writeln!(
                f,
                "  {:<18} {:>13.6e} {:>13.6e} {:>11} {:>27}",
                p.name, p.gmwm, p.value, se, ci
            )?;
        }
        let extra = self.augment.len();
        let m = self.moments.len();
        for mo in &self.moments[m - extra..] {
            writeln!(
                f,
                "  {:<18} observed {:>12.5e} (sd {:.2e}), implied {:>12.5e}",
                mo.name, mo.observed, mo.sd, mo.implied
            )?;
        }
        let j = self.j_test;
        match j.p_value {
            Some(p) => write!(
                f,
                "  J-test: Q = {:.3} on {} degrees of freedom, p {}",
                j.statistic,
                j.df,
                if p < 1e-16 {
                    "< 1e-16".to_string()
                } else {
                    format!("= {p:.3}")
                }
            ),
            None => write!(
                f,
                "  J-test: no degrees of freedom (as many moments as parameters)"
            ),
        }
    }
}

/// GMWM+ of `gmwm`'s model on the series `x` (module docs): the GMWM fit, the bootstrap joint
/// covariance of the WV and the extra moments at it, and the stacked fit.
///
/// ```
/// use gmwm::{fit_augmented, simulate_model, AugmentOptions, Gmwm, Model, WvOptions};
/// let truth = Model::parse("AR1(phi=0.9, sigma2=1)+WN(sigma2=2)").unwrap();
/// let x = simulate_model(&truth, 4096, 1.0, 3).unwrap();
/// let mut opts = AugmentOptions::new("acf:2".parse().unwrap());
/// opts.replicates = 60;
/// let fit = fit_augmented(&Gmwm::parse("AR1()+WN()").unwrap(), &x, 1.0, &WvOptions::default(), &opts)
///     .unwrap();
/// assert_eq!(fit.parameters().len(), 3);
/// assert!(fit.parameters().iter().all(|p| p.se.is_some()));
/// ```
///
/// # Errors
/// [`ParamError`] (as [`FitError::Input`]) when the model lacks what the moments need
/// ([`Augment::check_model`]), for too few replicates (`H <= M + 2`) or a series too short;
/// errors of the GMWM fit and the bootstrap.
pub fn fit_augmented(
    gmwm: &Gmwm,
    x: &[f64],
    freq_hz: f64,
    wv_opts: &WvOptions,
    opts: &AugmentOptions,
) -> Result<AugmentedFit, FitError> {
    opts.augment.check_model(gmwm.model())?;
    // the moments' own check (the series' length) before the fit's work
    opts.augment.sample(x)?;
    let base = gmwm.fit(x, freq_hz, wv_opts)?;
    augment_fit(gmwm, &base, x, opts)
}

/// Step 2 of the module docs from an existing GMWM fit `base` of the series `x` (its WV and
/// estimates; `gmwm` gives the transforms and optimiser settings): what [`fit_augmented`] does
/// after its GMWM fit, for a caller that holds one (the calibration's identified fit).
///
/// # Errors
/// As [`fit_augmented`]; [`FitError::Length`] when `base` carries no WV.
pub fn augment_fit(
    gmwm: &Gmwm,
    base: &GmwmFit,
    x: &[f64],
    opts: &AugmentOptions,
) -> Result<AugmentedFit, FitError> {
    opts.augment.check_model(base.model())?;
    let extra = opts.augment.sample(x)?;
    let freq_hz = base.freq_hz();
    let wv = base
        .empirical()
        .ok_or(FitError::Length {
            what: "stored WV",
            expected: 1,
            found: 0,
        })?
        .clone();
    let mut moments = wv.wv.clone();
    moments.extend_from_slice(&extra);
    let augment = opts.augment;
    let samples = map_replicates(
        base.model(),
        x.len(),
        freq_hz,
        &wv.options(),
        opts.replicates,
        opts.seed,
        |_, w, xs| {
            let mut v = w.wv.clone();
            v.extend(augment.sample(xs)?);
            Ok::<_, FitError>(v)
        },
    )?;
    let joint = WvBootstrap::from_samples(&samples)?;
    stacked_fit(gmwm, base, &moments, &joint.cov, opts)
}

/// Step 2 of the module docs from the GMWM fit `base`: `moments` (the WV, then the extra
/// ones) with their bootstrap covariance `v` over `opts.replicates` series.
pub(crate) fn stacked_fit(
    gmwm: &Gmwm,
    base: &GmwmFit,
    moments: &[f64],
    v: &DMatrix<f64>,
    opts: &AugmentOptions,
) -> Result<AugmentedFit, FitError> {
    let (m, h) = (moments.len(), opts.replicates);
    if h <= m + 2 {
        return Err(ParamError::new(
            "replicates",
            h,
            format!(
                "more than the moment count plus 2 ({}) for the joint covariance",
                m + 2
            ),
        )
        .into());
    }
    let hartlap = (h - m - 2) as f64 / (h - 1) as f64;
    let v_used = v / hartlap;
    let weights = FullWeights::from_covariance(&v_used)?;
    let model = base.model().without_values();
    let freq_hz = base.freq_hz();
    let (preset, phi_order, options) = gmwm.settings();
    let param = Parametrisation::new(&model, preset, phi_order, freq_hz)?;
    let start = Parametrisation::canonical_order(&model, base.theta())?;
    let u0 = param.to_u_restart(&start)?;
    let objective = Objective::augmented(
        &model,
        param.clone(),
        moments,
        opts.augment,
        &weights,
        freq_hz,
    )?;
    let min = minimize(&objective, &u0, &options)?;
    let theta = Parametrisation::canonical_order(&model, &min.theta)?;
    let p = theta.len();
    let mut implied = vec![0.0; m];
    let mut jac = vec![0.0; m * p];
    objective.implied(&theta, &mut implied, Some(&mut jac))?;
    let a = DMatrix::from_row_slice(m, p, &jac);
    let w = weights.whitening();
    let omega = w.transpose() * w;
    let z = z_value(opts.alpha, ZConvention::TwoSided)?;
    let g = scales(&model, IntervalScale::Transformed);
    let psi = sandwich(&a, &omega, &v_used).ok().map(|s| s.psi);
    let names = base.param_names().to_vec();
    let parameters = (0..p)
        .map(|k| {
            // a component fitted to nothing (GmwmFit::collapsed) sits on its boundary: no
            // Wald interval describes it
            let boundary = base.collapsed().contains(&names[k]);
            let se = psi
                .as_ref()
                .filter(|_| !boundary)
                .map(|s| s[(k, k)])
                .filter(|x| x.is_finite() && *x > 0.0)
                .map(f64::sqrt);
            let (lo, hi) = match se {
                Some(se) => {
                    let (lo, hi) = g[k].interval(theta[k], se * g[k].derivative(theta[k]).abs(), z);
                    (Some(lo), Some(hi))
                }
                None => (None, None),
            };
            AugmentedParameter {
                name: names[k].clone(),
                gmwm: base.theta()[k],
                value: theta[k],
                se,
                ci_low: lo,
                ci_high: hi,
            }
        })
        .collect();
    let levels = m - opts.augment.len();
    let moment_rows = (0..m)
        .map(|i| AugmentedMoment {
            name: if i < levels {
                format!("nu2[{}]", i + 1)
            } else {
                opts.augment.names()[i - levels].clone()
            },
            observed: moments[i],
            implied: implied[i],
            sd: v[(i, i)].max(0.0).sqrt(),
        })
        .collect();
    let df = m.saturating_sub(p);
    let p_value = (df > 0)
        .then(|| ChiSquared::new(df as f64).ok())
        .flatten()
        .map(|chi| chi.sf(min.objective));
    Ok(AugmentedFit {
        base: base.clone(),
        augment: opts.augment,
        replicates: h,
        alpha: opts.alpha,
        estimates: FitEstimates {
            model: model.with_values(&theta)?,
            theta,
            param_names: names,
            objective: min.objective,
            convergence: min.convergence,
            freq_hz,
        },
        parameters,
        moments: moment_rows,
        j_test: AugmentedJTest {
            statistic: min.objective,
            df,
            p_value,
        },
        covariance: psi.unwrap_or_else(|| DMatrix::from_element(p, p, f64::NAN)),
    })
}
