//! Identifiable components and the canonical model of a fit: what each fitted component is at
//! the scales the wavelet variance observed.
//!
//! A Haar WV observes the scales `tau_j = 2^j` samples, `j = 1..J` (`2^j / f` seconds at the
//! sampling rate `f`). A latent process is identified by the WV only through the shape it
//! gives the WV over those scales, and three shapes can be mimicked by the others:
//!
//! - an AR1/GM with correlation length `L = -1 / ln(phi)` samples (correlation time
//!   `T = L / f`) has a WV bump that peaks near `tau = 3.75 L` (3.0 at `L = 2`, 3.75 at
//!   `L = 100`): when `L` is short against the first scale its WV falls over every observed
//!   scale like a white noise's, when it is long against the last scale it rises over every
//!   observed scale like a random walk's;
//! - two AR1/GMs whose bumps lie too close together give a WV that one AR1/GM reproduces;
//! - a drift (`nu2 ~ tau^2`) and a random walk (`nu2 ~ tau`) differ only at the last few
//!   scales, which a short recording measures poorly.
//!
//! # How far apart two WVs are: the separation
//! Two implied WVs `a` and `b` are compared in units of the noise of the empirical WV they
//! were fitted to, on the log scale where that noise has the same law at every level:
//!
//! ```text
//! delta(a, b) = sqrt( sum_j ln(a_j / b_j)^2 / Var(ln nu2_hat_j) ),
//! Var(ln nu2_hat_j) = psi'(eta_j / 2)      (x 1/eff for the robust WV)
//! ```
//!
//! ([`WaveletVariance::log_variance`](crate::WaveletVariance::log_variance): `eta_j` are the
//! equivalent degrees of freedom of METHODS §1.7, `psi'` the trigamma function). For nested
//! models fitted with efficient weights `delta^2` is, to first order, the drop in the
//! objective between them (a chi-square statistic); the levels are treated as independent
//! (adjacent Haar levels are positively correlated, so `delta` leans towards "separable").
//! Two fits are **not separable** when `delta <= 2` ([`SEPARATION_LIMIT`]): they differ by
//! less than two standard errors of the WV (an equivalence at about the 5% level for one
//! parameter).
//!
//! # The rules, in order
//! 1. **At the boundary**: a component fitted to nothing (`crate::fit::active`) is dropped.
//! 2. **White at the sampling rate** (a reading, no refit): an AR1/GM whose correlation time is
//!    below the sampling interval (`T < 1/f`, i.e. `phi < 1/e`; `phi <= 0` included) decorrelates
//!    within one sample and its WV peaks at or below the first scale; a filter running at `f`
//!    sees white noise. It is read as white noise of variance `sigma2 / (1 - phi)^2`, the level
//!    of its spectrum at low frequency: the density that governs every scale of one sample and
//!    more (its fitted shape at the first scale is the sensor's own sub-sample filtering, which
//!    the fit keeps). A GM with `beta -> infinity` (`phi = 0`) reads as white noise `sigma2_gm`.
//! 3. **Tested reductions** (each refitted on the same WV and weights from the obvious start,
//!    and accepted when the refit is not separable from the fitted model, `delta <= 2`; the
//!    closest first, repeated until none passes):
//!    - an AR1/GM whose WV **rises over every observed scale** (its own WV still grows at the
//!      last level) replaced by a random walk with `gamma2 = sigma2` (for `tau << L` the AR1's
//!      increments are its innovations), merged into the model's RW if it has one;
//!    - an AR1/GM whose WV **falls over every observed scale** (and `T >= 1/f`) replaced by white
//!      noise `sigma2 / (1 - phi)^2`;
//!    - **two AR1/GMs adjacent in correlation time** merged into one that keeps their total
//!      stationary variance `s` and long-run variance `l = sum sigma2_k / (1 - phi_k)^2`:
//!      `phi = (l - s) / (l + s)`, `sigma2 = s (1 - phi^2)` (exact for equal phis);
//!    - a **drift** replaced by a random walk (`gamma2 = 3 omega^2 tau_J / 4`, equal WVs at the
//!      last scale; dropped if the model has a RW): the two cannot be separated at this length,
//!      and the stochastic one is what a navigation filter models (a deterministic drift is what
//!      a longer or temperature-controlled recording resolves).
//!
//!    An AR1/GM that rises over every observed scale but is separable from a random walk is kept,
//!    with a note that its correlation time lies beyond the recording and is poorly determined.
//!    In practice that does not happen: such an AR1 bends only over the last octaves, where
//!    the WV has a few degrees of freedom (`eta_j ~ N / 2^j`), so even its noise-free WV is
//!    about one standard error from the best random walk's (a 2^15-sample recording and a
//!    correlation length of 5000 samples: tests/canonical.rs). A correlation time beyond the
//!    recording is not measured by it.
//!
//! The result, [`CanonicalModel`], lists the canonical terms in a fixed order (AR1/GM by
//! decreasing correlation time, then WN, QN, RW, DR, then any ARMA-family term as fitted), each
//! with its values and physical read-off ([`NavParameter`]), the readings that led there, and
//! the separation of the canonical model's WV from the fitted one.
//!
//! ```
//! use gmwm::fit::{Gmwm, Weights};
//! use gmwm::model::Model;
//! // white noise and a random walk, fitted with a third component: an AR1 whose correlation
//! // time (0.5 samples) is below the sampling interval
//! let truth = Model::parse("AR1(phi=0.135, sigma2=0.3)+WN(sigma2=1)+RW(gamma2=1e-4)").unwrap();
//! let nu = truth.implied_wv(14, 100.0).unwrap().wv;
//! let fit = Gmwm::new(truth.without_values())
//!     .fit_weighted(&nu, Weights::flattening(&nu).unwrap(), 100.0, &[0.135, 0.3, 1.0, 1e-4])
//!     .unwrap();
//! let canonical = fit.canonical().unwrap();
//! assert_eq!(canonical.model.to_string(), "WN()+RW()");
//! let wn = &canonical.terms[0];
//! // 0.3 / (1 - 0.135)^2 + 1
//! assert!((wn.parameters[0].value / (0.3 / 0.865f64.powi(2) + 1.0) - 1.0).abs() < 1e-6);
//! ```

use super::active::active_components;
use super::report::{physical_parameters, significant, NavParameter};
use super::{FitError, Gmwm, GmwmFit, PhiOrder};
use crate::model::{Component, ImpliedWv, Model, ProcessKind};
use crate::process::{Ar1, Gm};
use serde::Serialize;
use std::fmt;

/// Two fits whose implied WVs are at most this many standard errors of the WV apart (the
/// separation of the module doc) cannot be told apart by the data.
pub const SEPARATION_LIMIT: f64 = 2.0;

/// A component whose removal moves the implied WV by at most this separation (a hundredth of a
/// standard error of the WV, summed over the levels) is fitted to nothing, whether or not the
/// optimiser reached the boundary ([`NEGLIGIBLE_WV_SHARE`](super::NEGLIGIBLE_WV_SHARE) is that
/// numerical test).
pub const NEGLIGIBLE_SEPARATION: f64 = 0.01;

/// Per component of `implied`, whether it contributes: it passes the numerical test of
/// `crate::fit::active` and removing it moves the implied WV by more than
/// [`NEGLIGIBLE_SEPARATION`] (a component whose removal leaves a level without WV always
/// contributes).
fn contributing(implied: &ImpliedWv, log_variance: &[f64]) -> Vec<bool> {
    active_components(implied)
        .into_iter()
        .zip(&implied.processes)
        .map(|(active, c)| {
            active && {
                let mut sum = 0.0;
                let mut empties = false;
                for ((t, x), v) in implied.wv.iter().zip(&c.wv).zip(log_variance) {
                    let rest = t - x;
                    if rest > 0.0 && *t > 0.0 && *v > 0.0 {
                        sum += (t / rest).ln().powi(2) / v;
                    } else if x.abs() > 0.0 {
                        empties = true;
                    }
                }
                empties || sum.sqrt() > NEGLIGIBLE_SEPARATION
            }
        })
        .collect()
}

/// METHODS-style separation of two implied WVs (module doc): `sqrt(sum_j ln(a_j / b_j)^2 /
/// log_variance_j)`. Levels where either value is not a positive finite number are skipped.
///
/// ```
/// use gmwm::fit::canonical::wv_separation;
/// // one level, a factor e apart, log-variance 0.25 (sd 0.5): two standard errors
/// let d = wv_separation(&[1.0], &[std::f64::consts::E], &[0.25]);
/// assert!((d - 2.0).abs() < 1e-12);
/// ```
pub fn wv_separation(a: &[f64], b: &[f64], log_variance: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .zip(log_variance)
        .filter(|((x, y), v)| x.is_finite() && y.is_finite() && **x > 0.0 && **y > 0.0 && **v > 0.0)
        .map(|((x, y), v)| (x / y).ln().powi(2) / v)
        .sum::<f64>()
        .sqrt()
}

/// One parameter of a canonical term (METHODS §0.2 name, per-sample value).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TermParameter {
    /// Name (`sigma2`, `phi`, `beta`, `gamma2`, ...).
    pub name: String,
    /// Value (per sample; GM in `beta` 1/s and `sigma2_gm`).
    pub value: f64,
}

/// One term of a canonical model.
///
/// Wire format: `process` (`WN`, `AR1`, ...), `parameters` (`name`, `value`), `physical` (the
/// read-off: `name`, `value`, `unit`), `from` (0-based positions of the fitted components it
/// stands for).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CanonicalTerm {
    /// Process name.
    pub process: String,
    /// The kind.
    #[serde(skip)]
    pub kind: ProcessKind,
    /// Values in METHODS §0.2 order.
    pub parameters: Vec<TermParameter>,
    /// Physical read-off (data unit `u`).
    pub physical: Vec<NavParameter>,
    /// Fitted components (0-based, model order of the fit) this term stands for.
    pub from: Vec<usize>,
}

/// Why a fitted component reads differently in the canonical model (module doc, rules 1–3).
///
/// Wire format: tagged by `kind` (kebab-case), with the fields below; `component(s)` are 0-based
/// positions in the fitted model, times in seconds.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
#[non_exhaustive]
pub enum Reading {
    /// Rule 1: fitted to nothing (at the boundary or negligible), dropped.
    AtBoundary {
        /// Component.
        component: usize,
        /// Its process name.
        process: String,
    },
    /// Rule 2: correlation time below the sampling interval, read as white noise.
    WhiteAtSamplingRate {
        /// Component.
        component: usize,
        /// Its process name.
        process: String,
        /// Its correlation time.
        correlation_time_s: f64,
        /// The sampling interval `1 / f`.
        sampling_interval_s: f64,
    },
    /// Rule 3: falls over every observed scale and is not separable from white noise.
    WhiteAtObservedScales {
        /// Component.
        component: usize,
        /// Its process name.
        process: String,
        /// Its correlation time.
        correlation_time_s: f64,
        /// Separation of the refit with white noise instead.
        separation: f64,
    },
    /// Rule 3: rises over every observed scale and is not separable from a random walk.
    RandomWalkAtObservedScales {
        /// Component.
        component: usize,
        /// Its process name.
        process: String,
        /// Its correlation time.
        correlation_time_s: f64,
        /// The longest observed scale `2^J / f`.
        longest_scale_s: f64,
        /// Separation of the refit with a random walk instead.
        separation: f64,
    },
    /// Rule 3: rises over every observed scale but is separable from a random walk: kept.
    CorrelationBeyondRecording {
        /// Component.
        component: usize,
        /// Its process name.
        process: String,
        /// Its correlation time.
        correlation_time_s: f64,
        /// The longest observed scale.
        longest_scale_s: f64,
        /// Separation of the refit with a random walk instead.
        separation: f64,
    },
    /// Rule 3: correlation times too close to be separated: merged into one.
    Merged {
        /// The components.
        components: Vec<usize>,
        /// Their process name.
        process: String,
        /// Their correlation times.
        correlation_times_s: Vec<f64>,
        /// Separation of the refit with one component instead.
        separation: f64,
    },
    /// Rule 3: a drift not separable from a random walk at this length.
    DriftAsRandomWalk {
        /// Component.
        component: usize,
        /// Separation of the refit with a random walk instead.
        separation: f64,
    },
}

impl fmt::Display for Reading {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Reading::AtBoundary { component, process } => write!(
                f,
                "{process}[{component}] is fitted to nothing (its share of the WV is below a hundredth of a \
                 standard error): left out"
            ),
            Reading::WhiteAtSamplingRate {
                component,
                process,
                correlation_time_s,
                sampling_interval_s,
            } => write!(
                f,
                "{process}[{component}] has a correlation time of {} s, below the sampling \
                 interval ({} s): it is white noise at the sampling rate and is reported as WN \
                 with its low-frequency level sigma2 / (1 - phi)^2",
                short(*correlation_time_s),
                short(*sampling_interval_s)
            ),
            Reading::WhiteAtObservedScales {
                component,
                process,
                correlation_time_s,
                separation,
            } => write!(
                f,
                "{process}[{component}] (correlation time {} s) falls over every observed scale \
                 and the WV cannot separate it from white noise (separation {:.2} <= \
                 {SEPARATION_LIMIT}): reported as WN",
                short(*correlation_time_s),
                separation
            ),
            Reading::RandomWalkAtObservedScales {
                component,
                process,
                correlation_time_s,
                longest_scale_s,
                separation,
            } => write!(
                f,
                "{process}[{component}] (correlation time {} s, longest observed scale {} s) rises \
                 over every observed scale and the WV cannot separate it from a random walk \
                 (separation {:.2} <= {SEPARATION_LIMIT}): reported as RW",
                short(*correlation_time_s),
                short(*longest_scale_s),
                separation
            ),
            Reading::CorrelationBeyondRecording {
                component,
                process,
                correlation_time_s,
                longest_scale_s,
                separation,
            } => write!(
                f,
                "{process}[{component}] rises over every observed scale (correlation time {} s, \
                 longest observed scale {} s) but the WV shows its bend (separation {:.2} from a \
                 random walk): kept as correlated noise, its correlation time poorly determined \
                 (a longer recording fixes it)",
                short(*correlation_time_s),
                short(*longest_scale_s),
                separation
            ),
            Reading::Merged {
                components,
                process,
                correlation_times_s,
                separation,
            } => {
                let names: Vec<String> =
                    components.iter().map(|c| format!("{process}[{c}]")).collect();
                let times: Vec<String> = correlation_times_s.iter().map(|t| short(*t)).collect();
                write!(
                    f,
                    "{} (correlation times {} s) are too close for the WV to separate \
                     (separation {:.2} <= {SEPARATION_LIMIT} from one {process}): merged into one",
                    names.join(" and "),
                    times.join(", "),
                    separation
                )
            }
            Reading::DriftAsRandomWalk {
                component,
                separation,
            } => write!(
                f,
                "DR[{component}] and a random walk cannot be separated at this recording's length \
                 (separation {:.2} <= {SEPARATION_LIMIT}): both fit; the random walk, which a \
                 navigation filter models, is reported (a longer or temperature-controlled \
                 recording resolves a drift)",
                separation
            ),
        }
    }
}

/// Four significant digits ([`significant`]).
fn short(v: f64) -> String {
    significant(v, 4)
}

/// The canonical model of a fit (module doc).
///
/// Wire format: `model` (guess-mode text such as `AR1()+WN()+RW()`), `terms`
/// ([`CanonicalTerm`]), `readings` ([`Reading`], each with its `message`), `separation` (of the
/// canonical model's WV from the fitted one; 0 when nothing was refitted) and `objective` (of
/// the canonical refit; the fit's own when nothing was refitted).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CanonicalModel {
    /// The canonical model in guess mode (its term list).
    pub model: Model,
    /// Its terms in canonical order.
    pub terms: Vec<CanonicalTerm>,
    /// What was read differently from the fit, and why.
    pub readings: Vec<Reading>,
    /// Separation of the canonical model's implied WV from the fit's.
    pub separation: f64,
    /// Objective of the fit behind the canonical model.
    pub objective: f64,
    /// Implied WV of the fit behind the canonical model (a fast AR1 read as white noise keeps
    /// its fitted shape here).
    pub implied_wv: Vec<f64>,
}

impl CanonicalModel {
    /// Whether the canonical model is the fitted model, term for term.
    pub fn is_as_fitted(&self) -> bool {
        self.readings.is_empty()
    }

    /// The canonical model with its values.
    ///
    /// # Errors
    /// [`crate::model::ModelError`] if a value left its domain (it cannot: every term's values
    /// come from a valid fit).
    pub fn estimate(&self) -> Result<Model, crate::model::ModelError> {
        Model::new(
            self.terms
                .iter()
                .map(|t| Component {
                    kind: t.kind,
                    values: t.parameters.iter().map(|p| Some(p.value)).collect(),
                })
                .collect(),
        )
    }

    /// The term of this kind (the first, for AR1/GM).
    pub fn term(&self, kind: ProcessKind) -> Option<&CanonicalTerm> {
        self.terms.iter().find(|t| t.kind == kind)
    }

    /// The value of the physical quantity `name` (e.g. `white_noise_density`) of the term of
    /// `kind`, if the model has one.
    pub fn physical(&self, kind: ProcessKind, name: &str) -> Option<f64> {
        self.term(kind)?
            .physical
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.value)
    }

    /// Number of correlated-noise terms (AR1/GM).
    pub fn correlated_terms(&self) -> usize {
        self.terms
            .iter()
            .filter(|t| matches!(t.kind, ProcessKind::Ar1 | ProcessKind::Gm))
            .count()
    }
}

impl fmt::Display for CanonicalModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "canonical model: {}", self.model)?;
        if self.is_as_fitted() {
            write!(f, " (as fitted)")?;
        }
        for t in &self.terms {
            let values: Vec<String> = t
                .physical
                .iter()
                .map(|p| format!("{} {} {}", p.name, short(p.value), p.unit))
                .collect();
            if !values.is_empty() {
                write!(f, "\n  {:<5} {}", t.process, values.join(", "))?;
            }
        }
        for r in &self.readings {
            write!(f, "\n  note: {r}")?;
        }
        Ok(())
    }
}

/// A component of the working model with the fitted components it stands for.
#[derive(Debug, Clone)]
struct Part {
    component: Component,
    from: Vec<usize>,
}

impl Part {
    fn kind(&self) -> ProcessKind {
        self.component.kind
    }

    fn values(&self) -> Vec<f64> {
        self.component
            .values
            .iter()
            .map(|v| v.unwrap_or(f64::NAN))
            .collect()
    }
}

/// The per-sample AR1 form of an AR1/GM part.
fn ar1_of(part: &Part, freq_hz: f64) -> Option<Ar1> {
    let v = part.values();
    match part.kind() {
        ProcessKind::Ar1 => Some(Ar1 {
            phi: v[0],
            sigma2: v[1],
        }),
        ProcessKind::Gm => Some(
            Gm {
                beta: v[0],
                sigma2_gm: v[1],
                freq_hz,
            }
            .to_ar1(),
        ),
        _ => None,
    }
}

/// An AR1/GM part of `kind` with the AR1 form `ar1` (GM through METHODS §4.3).
fn part_from_ar1(kind: ProcessKind, ar1: Ar1, freq_hz: f64, from: Vec<usize>) -> Option<Part> {
    let values = match kind {
        ProcessKind::Gm => {
            let gm = ar1.to_gm(freq_hz).ok()?;
            vec![gm.beta, gm.sigma2_gm]
        }
        _ => vec![ar1.phi, ar1.sigma2],
    };
    Some(Part {
        component: Component::new(kind, values.into_iter().map(Some).collect()).ok()?,
        from,
    })
}

/// Correlation time in seconds of an AR1 form (0 for `phi <= 0`).
fn correlation_time(ar1: Ar1, freq_hz: f64) -> f64 {
    if ar1.phi > 0.0 {
        -1.0 / (ar1.phi.ln() * freq_hz)
    } else {
        0.0
    }
}

/// Rule 2: the correlation time is below the sampling interval (`phi < 1/e`).
fn white_at_sampling_rate(ar1: Ar1) -> bool {
    ar1.phi < (-1.0f64).exp()
}

/// Long-run variance `sigma2 / (1 - phi)^2`: the white noise an AR1 is at scales far beyond
/// its correlation length.
fn long_run_variance(ar1: Ar1) -> f64 {
    ar1.sigma2 / ((1.0 - ar1.phi) * (1.0 - ar1.phi))
}

fn single(kind: ProcessKind, value: f64, from: Vec<usize>) -> Option<Part> {
    Some(Part {
        component: Component::new(kind, vec![Some(value)]).ok()?,
        from,
    })
}

/// Adds a one-parameter term (WN, RW) to `parts`: to the existing one's value, or as a new part.
fn add_single(parts: &mut Vec<Part>, kind: ProcessKind, value: f64, from: &[usize]) -> Option<()> {
    match parts.iter_mut().find(|p| p.kind() == kind) {
        Some(p) => {
            let v = p.values()[0] + value;
            p.component = Component::new(kind, vec![Some(v)]).ok()?;
            p.from.extend_from_slice(from);
            p.from.sort_unstable();
        }
        None => parts.push(single(kind, value, from.to_vec())?),
    }
    Some(())
}

/// A candidate reduction (rule 3) and its reading once accepted.
struct Reduction {
    parts: Vec<Part>,
    reading: Box<dyn Fn(f64) -> Reading>,
}

/// The state of the canonicalisation: the working model, its implied WV and objective.
struct State {
    parts: Vec<Part>,
    implied: ImpliedWv,
    objective: f64,
}

impl GmwmFit {
    /// The canonical model of this fit with the default [`SEPARATION_LIMIT`] (module doc).
    ///
    /// Cost: one implied WV, plus one stage-2 refit per tried reduction (a drift, a slow or fast
    /// AR1/GM, or a pair of adjacent AR1/GMs), a few milliseconds each.
    ///
    /// # Errors
    /// Errors of the refits' set-up ([`FitError`]); a refit that fails to converge only makes
    /// its reduction fail the test.
    pub fn canonical(&self) -> Result<CanonicalModel, FitError> {
        self.canonical_with(SEPARATION_LIMIT)
    }

    /// [`GmwmFit::canonical`] with another separation limit (0 accepts only exact
    /// reductions).
    ///
    /// # Errors
    /// As [`GmwmFit::canonical`].
    pub fn canonical_with(&self, limit: f64) -> Result<CanonicalModel, FitError> {
        let levels = self.nu_hat.len();
        let log_variance = self.log_variance();
        let mut readings = Vec::new();
        // rule 1
        let active = contributing(&self.implied_wv, &log_variance);
        let keep_all = !active.iter().any(|&a| a);
        let mut at = 0;
        let mut parts = Vec::new();
        for (i, (c, &a)) in self.model.components().iter().zip(&active).enumerate() {
            let n = c.kind.n_params();
            if a || keep_all {
                parts.push(Part {
                    component: Component::new(
                        c.kind,
                        self.theta[at..at + n].iter().map(|&v| Some(v)).collect(),
                    )
                    .map_err(crate::Error::from)?,
                    from: vec![i],
                });
            } else {
                readings.push(Reading::AtBoundary {
                    component: i,
                    process: c.kind.name(),
                });
            }
            at += n;
        }
        let implied = if parts.len() == self.model.n_components() {
            self.implied_wv.clone()
        } else {
            model_of(&parts)?.implied_wv(levels, self.freq_hz)?
        };
        let mut state = State {
            parts,
            implied,
            objective: self.objective,
        };
        let mut separation = 0.0;
        // rule 3, closest first
        loop {
            let mut best: Option<(f64, State, Reading)> = None;
            for r in self.reductions(&state) {
                let Some(next) = self.refit(r.parts, &log_variance)? else {
                    continue;
                };
                let d = wv_separation(&self.implied_wv.wv, &next.implied.wv, &log_variance);
                if d <= limit && best.as_ref().map_or(true, |b| d < b.0) {
                    best = Some((d, next, (r.reading)(d)));
                }
            }
            let Some((d, next, reading)) = best else {
                break;
            };
            readings.push(reading);
            separation = d;
            state = next;
        }
        // rule 3, the kept slow ones: a note
        let longest_scale_s = self.longest_scale_s();
        for (k, p) in state.parts.iter().enumerate() {
            if let Some(ar1) = ar1_of(p, self.freq_hz) {
                if !white_at_sampling_rate(ar1) && rises_everywhere(&state.implied, k) {
                    let mut replaced = state.parts.clone();
                    replaced.remove(k);
                    let d = add_single(&mut replaced, ProcessKind::Rw, ar1.sigma2, &[])
                        .map(|_| replaced)
                        .map(|parts| self.refit(parts, &log_variance))
                        .transpose()?
                        .flatten()
                        .map_or(f64::INFINITY, |s| {
                            wv_separation(&self.implied_wv.wv, &s.implied.wv, &log_variance)
                        });
                    readings.push(Reading::CorrelationBeyondRecording {
                        component: p.from[0],
                        process: p.kind().name(),
                        correlation_time_s: correlation_time(ar1, self.freq_hz),
                        longest_scale_s,
                        separation: d,
                    });
                }
            }
        }
        // rule 2 and the terms
        let mut terms_parts: Vec<Part> = Vec::new();
        for p in &state.parts {
            match ar1_of(p, self.freq_hz) {
                Some(ar1) if white_at_sampling_rate(ar1) => {
                    readings.push(Reading::WhiteAtSamplingRate {
                        component: p.from[0],
                        process: p.kind().name(),
                        correlation_time_s: correlation_time(ar1, self.freq_hz),
                        sampling_interval_s: 1.0 / self.freq_hz,
                    });
                    add_single(
                        &mut terms_parts,
                        ProcessKind::Wn,
                        long_run_variance(ar1),
                        &p.from,
                    )
                    .ok_or_else(|| bad_value("white noise", long_run_variance(ar1)))?;
                }
                _ if p.kind() == ProcessKind::Wn => {
                    add_single(&mut terms_parts, ProcessKind::Wn, p.values()[0], &p.from)
                        .ok_or_else(|| bad_value("white noise", p.values()[0]))?;
                }
                _ => terms_parts.push(p.clone()),
            }
        }
        let terms_parts = canonical_order(terms_parts, self.freq_hz);
        let model = Model::new(
            terms_parts
                .iter()
                .map(|p| Component::guess(p.kind()))
                .collect(),
        )
        .map_err(crate::Error::from)?;
        let terms = terms_parts
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let theta = p.values();
                CanonicalTerm {
                    process: p.kind().name(),
                    kind: p.kind(),
                    parameters: p
                        .kind()
                        .param_names()
                        .into_iter()
                        .zip(&theta)
                        .map(|(name, &value)| TermParameter { name, value })
                        .collect(),
                    physical: physical_parameters(p.kind(), i, &theta, self.freq_hz, None),
                    from: p.from.clone(),
                }
            })
            .collect();
        Ok(CanonicalModel {
            model,
            terms,
            readings,
            separation,
            objective: state.objective,
            implied_wv: state.implied.wv,
        })
    }

    /// Variance of the log of the empirical WV per level (module doc); from the CI widths
    /// when the fit carries no empirical WV (a bare [`Gmwm::fit_weighted`]): `V_jj` is then
    /// the weighting's variance proxy, read as `(2 z_{0.975})^2 Var(nu2_hat_j)`.
    fn log_variance(&self) -> Vec<f64> {
        match &self.empirical {
            Some(wv) => wv.log_variance(),
            None => self
                .weights
                .v
                .iter()
                .zip(&self.nu_hat)
                .map(|(v, nu)| v / (nu * nu * 4.0 * 1.959_963_984_540_054f64.powi(2)))
                .collect(),
        }
    }

    /// The longest observed scale `2^J / f` in seconds.
    fn longest_scale_s(&self) -> f64 {
        (self.nu_hat.len() as f64).exp2() / self.freq_hz
    }

    /// The reductions of rule 3 that apply to `state` (module doc).
    fn reductions(&self, state: &State) -> Vec<Reduction> {
        let f = self.freq_hz;
        let parts = &state.parts;
        let mut out = Vec::new();
        let correlated: Vec<(usize, Ar1)> = parts
            .iter()
            .enumerate()
            .filter_map(|(k, p)| ar1_of(p, f).map(|a| (k, a)))
            .filter(|(_, a)| !white_at_sampling_rate(*a))
            .collect();
        let longest_scale_s = self.longest_scale_s();
        for &(k, ar1) in &correlated {
            let p = &parts[k];
            let (component, process) = (p.from[0], p.kind().name());
            let correlation_time_s = correlation_time(ar1, f);
            if rises_everywhere(&state.implied, k) {
                let mut next = parts.clone();
                next.remove(k);
                if add_single(&mut next, ProcessKind::Rw, ar1.sigma2, &p.from).is_some() {
                    let process = process.clone();
                    out.push(Reduction {
                        parts: next,
                        reading: Box::new(move |separation| Reading::RandomWalkAtObservedScales {
                            component,
                            process: process.clone(),
                            correlation_time_s,
                            longest_scale_s,
                            separation,
                        }),
                    });
                }
            }
            if falls_everywhere(&state.implied, k) {
                let mut next = parts.clone();
                next.remove(k);
                if add_single(&mut next, ProcessKind::Wn, long_run_variance(ar1), &p.from).is_some()
                {
                    out.push(Reduction {
                        parts: next,
                        reading: Box::new(move |separation| Reading::WhiteAtObservedScales {
                            component,
                            process: process.clone(),
                            correlation_time_s,
                            separation,
                        }),
                    });
                }
            }
        }
        // adjacent pairs in correlation time (the parts are kept in phi-decreasing order)
        let mut by_phi = correlated.clone();
        by_phi.sort_by(|a, b| b.1.phi.total_cmp(&a.1.phi));
        for w in by_phi.windows(2) {
            let ((i, a), (k, b)) = (w[0], w[1]);
            let s = a.sigma2 / (1.0 - a.phi * a.phi) + b.sigma2 / (1.0 - b.phi * b.phi);
            let l = long_run_variance(a) + long_run_variance(b);
            let phi = (l - s) / (l + s);
            let merged = Ar1 {
                phi,
                sigma2: s * (1.0 - phi * phi),
            };
            let mut from = parts[i].from.clone();
            from.extend_from_slice(&parts[k].from);
            from.sort_unstable();
            let Some(part) = part_from_ar1(parts[i].kind(), merged, f, from) else {
                continue;
            };
            let mut next: Vec<Part> = parts
                .iter()
                .enumerate()
                .filter(|(j, _)| *j != i && *j != k)
                .map(|(_, p)| p.clone())
                .collect();
            let components = part.from.clone();
            next.push(part);
            let times = vec![correlation_time(a, f), correlation_time(b, f)];
            let process = parts[i].kind().name();
            out.push(Reduction {
                parts: next,
                reading: Box::new(move |separation| Reading::Merged {
                    components: components.clone(),
                    process: process.clone(),
                    correlation_times_s: times.clone(),
                    separation,
                }),
            });
        }
        if let Some(k) = parts.iter().position(|p| p.kind() == ProcessKind::Dr) {
            let omega = parts[k].values()[0];
            let tau_last = (self.nu_hat.len() as f64).exp2();
            let mut next = parts.clone();
            let from = next.remove(k).from;
            let has_rw = next.iter().any(|p| p.kind() == ProcessKind::Rw);
            let gamma2 = 0.75 * omega * omega * tau_last;
            let ok = if has_rw {
                Some(())
            } else {
                add_single(&mut next, ProcessKind::Rw, gamma2, &from)
            };
            if ok.is_some() && (has_rw || gamma2 > 0.0) {
                let component = from[0];
                out.push(Reduction {
                    parts: next,
                    reading: Box::new(move |separation| Reading::DriftAsRandomWalk {
                        component,
                        separation,
                    }),
                });
            }
        }
        out
    }

    /// Refits the working model `parts` (stage 2 from its values, the fit's WV, weights and
    /// transforms, AR1/GMs ordered); `None` when the start is not a valid model or the refit
    /// fails to converge. Components the refit drives to the boundary are dropped.
    fn refit(&self, parts: Vec<Part>, log_variance: &[f64]) -> Result<Option<State>, FitError> {
        let parts = canonical_order(parts, self.freq_hz);
        let Ok(model) = model_of(&parts) else {
            return Ok(None);
        };
        let start: Vec<f64> = parts.iter().flat_map(Part::values).collect();
        let gmwm = Gmwm::new(model.without_values())
            .with_preset(self.preset)
            .with_phi_order(PhiOrder::Ordered);
        let fit = match gmwm.fit_weighted(&self.nu_hat, self.weights.clone(), self.freq_hz, &start)
        {
            Ok(fit) if fit.convergence.converged => fit,
            Ok(_)
            | Err(FitError::OutOfDomain { .. })
            | Err(FitError::PhiNotOrdered { .. })
            | Err(FitError::BadStart(_))
            | Err(FitError::NonFiniteStart { .. }) => return Ok(None),
            Err(e) => return Err(e),
        };
        // the ordered chain keeps the start's order: the parts map one to one
        let active = contributing(&fit.implied_wv, log_variance);
        let mut at = 0;
        let mut next = Vec::with_capacity(parts.len());
        for ((p, c), a) in parts.into_iter().zip(fit.model.components()).zip(&active) {
            let n = c.kind.n_params();
            if *a {
                next.push(Part {
                    component: Component::new(
                        c.kind,
                        fit.theta[at..at + n].iter().map(|&v| Some(v)).collect(),
                    )
                    .map_err(crate::Error::from)?,
                    from: p.from,
                });
            }
            at += n;
        }
        if next.is_empty() {
            return Ok(None);
        }
        let implied = if next.len() == fit.model.n_components() {
            fit.implied_wv
        } else {
            model_of(&next)?.implied_wv(self.nu_hat.len(), self.freq_hz)?
        };
        Ok(Some(State {
            parts: next,
            implied,
            objective: fit.objective,
        }))
    }
}

fn bad_value(what: &str, value: f64) -> FitError {
    crate::Error::from(crate::ParamError::new(
        "canonical model",
        value,
        format!("a positive finite {what} variance"),
    ))
    .into()
}

/// Whether component `k`'s own implied WV still grows at the last level (so, the AR1/GM WV
/// being unimodal in scale, at every level).
fn rises_everywhere(implied: &ImpliedWv, k: usize) -> bool {
    let wv = &implied.processes[k].wv;
    let j = wv.len();
    j >= 2 && wv[j - 1] > wv[j - 2]
}

/// Whether component `k`'s own implied WV already falls at the first level.
fn falls_everywhere(implied: &ImpliedWv, k: usize) -> bool {
    let wv = &implied.processes[k].wv;
    wv.len() >= 2 && wv[1] < wv[0]
}

/// The model of the parts, with their values.
fn model_of(parts: &[Part]) -> Result<Model, crate::Error> {
    Ok(Model::new(
        parts.iter().map(|p| p.component.clone()).collect(),
    )?)
}

/// Canonical term order: AR1/GM by decreasing correlation time (phi decreasing), then WN, QN,
/// RW, DR, then anything else in the given order.
fn canonical_order(mut parts: Vec<Part>, freq_hz: f64) -> Vec<Part> {
    let rank = |p: &Part| match p.kind() {
        ProcessKind::Ar1 | ProcessKind::Gm => 0,
        ProcessKind::Wn => 1,
        ProcessKind::Qn => 2,
        ProcessKind::Rw => 3,
        ProcessKind::Dr => 4,
        _ => 5,
    };
    let phi = |p: &Part| ar1_of(p, freq_hz).map_or(0.0, |a| a.phi);
    parts.sort_by(|a, b| {
        rank(a)
            .cmp(&rank(b))
            .then_with(|| phi(b).total_cmp(&phi(a)))
    });
    parts
}
