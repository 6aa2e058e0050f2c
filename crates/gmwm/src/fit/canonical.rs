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
//! equivalent degrees of freedom of docs/methods.md §1.7, `psi'` the trigamma function). At one
//! level `delta` is the number of standard errors of `ln nu2_hat_j` between the two curves; over
//! the levels it adds them in quadrature, treating the levels as independent (adjacent Haar
//! levels are positively correlated, so it leans towards "separable"). Two fits whose
//! separation is at most 2 ([`SEPARATION_LIMIT`], a heuristic limit: two standard errors in
//! quadrature) are treated as ones the data cannot tell apart. It is a distance, not a test:
//! failing to separate two fits is not evidence that they are equal.
//!
//! # The rules, in order
//! 1. **Fitted to nothing**: a component at the boundary (`crate::fit::active`) or whose removal
//!    moves the implied WV by at most `NEGLIGIBLE_SEPARATION` (a hundredth of a standard
//!    error) is dropped.
//! 2. **Tested reductions** (each refitted on the same WV and weights from the obvious start,
//!    and accepted when the refit is not separable from the fitted model, `delta <= 2`; the
//!    closest first, repeated until none passes):
//!    - an AR1/GM whose WV **rises over every observed scale** (its own WV still grows at the
//!      last level) replaced by a random walk with `gamma2 = sigma2` (for `tau << L` the AR1's
//!      increments are its innovations), merged into the model's RW if it has one;
//!    - an AR1/GM whose WV **falls over every observed scale** (its own WV already falls at the
//!      first level) replaced by white noise `sigma2 / (1 - phi)^2`, the level of its spectrum
//!      at low frequency, merged into the model's WN if it has one;
//!    - **two AR1/GMs adjacent in correlation time** merged into one that keeps their total
//!      stationary variance `s` and long-run variance `l = sum sigma2_k / (1 - phi_k)^2`:
//!      `phi = (l - s) / (l + s)`, `sigma2 = s (1 - phi^2)` (exact for equal phis);
//!    - a **drift** replaced by a random walk (`gamma2 = 3 omega^2 tau_J / 4`, equal WVs at the
//!      last scale; dropped if the model has a RW): the stochastic one of the two is what a
//!      navigation filter models (a deterministic drift is what a longer or
//!      temperature-controlled recording resolves).
//!
//!    The model left after rules 1 and 2 is the *reduced* model: the smallest one whose fit
//!    the data cannot tell from the fitted model's ([`CanonicalModel::reduced`]).
//!
//!    An AR1/GM that rises over every observed scale but is separable from a random walk is kept,
//!    with a note that its correlation time lies beyond the recording and is poorly determined.
//!    In practice that does not happen: such an AR1 bends only over the last octaves, where
//!    the WV has a few degrees of freedom (`eta_j ~ N / 2^j`), so even its noise-free WV is
//!    about one standard error from the best random walk's (a 2^15-sample recording and a
//!    correlation length of 5000 samples: tests/canonical.rs). A correlation time beyond the
//!    recording is not measured by it.
//! 3. **White at the sampling rate** (a reading, not an equivalence): an AR1/GM of the reduced
//!    model whose correlation time is below the sampling interval (`T < 1/f`, `phi < 1/e`;
//!    `phi <= 0` included) has its WV peak at or below the first scale, and its lag-one
//!    correlation (at most `1/e`) is gone after a few samples. When rule 2 could not replace it
//!    by white noise, its shape at the first scales is real (typically the sensor's own
//!    anti-alias or decimation filter, e.g. `phi = 0.16` on the ADIS16405 gyroscopes at 100
//!    Hz), and the fit keeps it; but a navigation filter, a Kalibr file or a datasheet reads
//!    such a process as white noise with its low-frequency density `sqrt(sigma2 / (1 -
//!    phi)^2 / f)`, which is what the angle or velocity random walk is (the Allan deviation at
//!    1 s agrees, tests/canonical.rs). The canonical model reports it so, and the reading says
//!    how far that white noise's WV is from the fitted one at the first scales.
//!
//! The result, [`CanonicalModel`], lists the canonical terms in a fixed order (AR1/GM by
//! decreasing correlation time, then WN, QN, RW, DR, then any ARMA-family term as fitted), each
//! with its values and physical read-off ([`NavParameter`]), the readings that led there, the
//! reduced model and the separation of its refit from the fitted WV.
//!
//! Worked example: the test `tests::examples::example_canonical`.

use super::active::active_components;
use super::report::{physical_parameters, significant, NavParameter};
use super::{FitError, Gmwm, GmwmFit, PhiOrder};
use crate::math::elementary;
use crate::model::{Component, ImpliedWv, Model, ProcessKind};
use crate::process::{kind_of, spec, Ar1, Role};
use serde::Serialize;
use std::fmt;

/// Two fits whose implied WVs are at most this many standard errors of the WV apart (the
/// separation of the module doc) cannot be told apart by the data.
pub(crate) const SEPARATION_LIMIT: f64 = 2.0;

/// A component whose removal moves the implied WV by at most this separation (a hundredth of a
/// standard error of the WV, summed over the levels) is fitted to nothing, whether or not the
/// optimiser reached the boundary ([`NEGLIGIBLE_WV_SHARE`](super::NEGLIGIBLE_WV_SHARE) is that
/// numerical test).
pub(crate) const NEGLIGIBLE_SEPARATION: f64 = 0.01;

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
                        sum += elementary::log(t / rest).powi(2) / v;
                    } else if x.abs() > 0.0 {
                        empties = true;
                    }
                }
                empties || sum.sqrt() > NEGLIGIBLE_SEPARATION
            }
        })
        .collect()
}

/// The separation of two implied WVs (module doc): `sqrt(sum_j ln(a_j / b_j)^2 /
/// log_variance_j)`. Levels where either value is not a positive finite number are skipped.
///
/// Worked example: the test `tests::examples::example_canonical_wv_separation`.
pub(crate) fn wv_separation(a: &[f64], b: &[f64], log_variance: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .zip(log_variance)
        .filter(|((x, y), v)| x.is_finite() && y.is_finite() && **x > 0.0 && **y > 0.0 && **v > 0.0)
        .map(|((x, y), v)| elementary::log(x / y).powi(2) / v)
        .sum::<f64>()
        .sqrt()
}

/// One parameter of a canonical term (docs/methods.md §0.2 name, per-sample value).
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
/// read-off: `process`, `index` (this term's 0-based position in the canonical model), `name`,
/// `value`, `unit`), `from` (0-based positions of the fitted components it stands for).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CanonicalTerm {
    /// Process name.
    pub process: String,
    /// The kind.
    #[serde(skip)]
    pub kind: ProcessKind,
    /// Values in docs/methods.md §0.2 order.
    pub parameters: Vec<TermParameter>,
    /// Physical read-off (data unit `u`).
    pub physical: Vec<NavParameter>,
    /// Fitted components (0-based, model order of the fit) this term stands for.
    pub from: Vec<usize>,
}

/// Why a fitted component reads differently in the canonical model (module doc, rules 1–3).
///
/// Wire format: tagged by `kind` (kebab-case), with the fields below; `component(s)` are 0-based
/// positions in the fitted model, times in seconds, `separation` in standard errors of the WV
/// (module doc). The `Display` text is the reading in words.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
#[non_exhaustive]
pub(crate) enum Reading {
    /// Rule 1: fitted to nothing (at the boundary or negligible), dropped.
    AtBoundary {
        /// Component.
        component: usize,
        /// Its process name.
        process: String,
    },
    /// Rule 2: falls over every observed scale and is not separable from white noise.
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
    /// Rule 2: rises over every observed scale and is not separable from a random walk.
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
    /// Rule 2: rises over every observed scale but is separable from a random walk: kept (a
    /// note; the term is as fitted).
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
    /// Rule 2: correlation times too close to be separated: merged into one.
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
    /// Rule 2: a drift not separable from a random walk at this length.
    DriftAsRandomWalk {
        /// Component.
        component: usize,
        /// Separation of the refit with a random walk instead.
        separation: f64,
    },
    /// Rule 3: correlation time below the sampling interval, reported as white noise with its
    /// low-frequency density although its WV differs from white noise's at the first scales.
    WhiteAtSamplingRate {
        /// Component.
        component: usize,
        /// Its process name.
        process: String,
        /// Its correlation time.
        correlation_time_s: f64,
        /// The sampling interval `1 / f`.
        sampling_interval_s: f64,
        /// Separation of the reduced fit's WV with this component read as white noise from
        /// the reduced fit's WV (more than the limit: rule 2 did not merge it).
        separation: f64,
    },
}

impl Reading {
    /// Whether the reading is a note only (the term is reported as fitted).
    pub(crate) fn is_note(&self) -> bool {
        matches!(self, Reading::CorrelationBeyondRecording { .. })
    }

    /// Whether `other` reads the same kind of thing of the same process (values aside): two
    /// fits of one model, such as the WIC's selection and the calibration's refinement of it,
    /// say it once.
    pub(crate) fn same_subject(&self, other: &Reading) -> bool {
        fn process(r: &Reading) -> &str {
            match r {
                Reading::AtBoundary { process, .. }
                | Reading::WhiteAtObservedScales { process, .. }
                | Reading::RandomWalkAtObservedScales { process, .. }
                | Reading::CorrelationBeyondRecording { process, .. }
                | Reading::Merged { process, .. }
                | Reading::WhiteAtSamplingRate { process, .. } => process,
                Reading::DriftAsRandomWalk { .. } => "DR",
            }
        }
        std::mem::discriminant(self) == std::mem::discriminant(other)
            && process(self) == process(other)
    }

    fn set_separation(&mut self, d: f64) {
        match self {
            Reading::WhiteAtObservedScales { separation, .. }
            | Reading::RandomWalkAtObservedScales { separation, .. }
            | Reading::CorrelationBeyondRecording { separation, .. }
            | Reading::Merged { separation, .. }
            | Reading::DriftAsRandomWalk { separation, .. }
            | Reading::WhiteAtSamplingRate { separation, .. } => *separation = d,
            Reading::AtBoundary { .. } => {}
        }
    }
}

impl fmt::Display for Reading {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Reading::AtBoundary { component, process } => write!(
                f,
                "{process}[{component}] is fitted to nothing (its share of the WV is below a \
                 hundredth of a standard error): left out"
            ),
            Reading::WhiteAtObservedScales {
                component,
                process,
                correlation_time_s,
                separation,
            } => write!(
                f,
                "{process}[{component}] (correlation time {} s) falls over every observed scale \
                 and the WV cannot tell it from white noise (separation {separation:.2}): \
                 reported as WN",
                short(*correlation_time_s),
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
                 over every observed scale and the WV cannot tell it from a random walk \
                 (separation {separation:.2}): reported as RW",
                short(*correlation_time_s),
                short(*longest_scale_s),
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
                 longest observed scale {} s) but the WV shows its bend (separation \
                 {separation:.2} from a random walk): kept as correlated noise, its correlation \
                 time poorly determined (a longer recording fixes it)",
                short(*correlation_time_s),
                short(*longest_scale_s),
            ),
            Reading::Merged {
                components,
                process,
                correlation_times_s,
                separation,
            } => {
                let names: Vec<String> = components
                    .iter()
                    .map(|c| format!("{process}[{c}]"))
                    .collect();
                let times: Vec<String> = correlation_times_s.iter().map(|t| short(*t)).collect();
                write!(
                    f,
                    "{} (correlation times {} s) are too close for the WV to tell apart \
                     (separation {separation:.2} from one {process}): merged into one",
                    names.join(" and "),
                    times.join(", "),
                )
            }
            Reading::DriftAsRandomWalk {
                component,
                separation,
            } => write!(
                f,
                "DR[{component}] and a random walk cannot be told apart at this recording's \
                 length (separation {separation:.2}): both fit; the random walk, which a \
                 navigation filter models, is reported (a longer or temperature-controlled \
                 recording resolves a drift)"
            ),
            Reading::WhiteAtSamplingRate {
                component,
                process,
                correlation_time_s,
                sampling_interval_s,
                separation,
            } => write!(
                f,
                "{process}[{component}] has a correlation time of {} s, below the sampling \
                 interval ({} s): it is reported as white noise with its low-frequency density \
                 (the angle/velocity random walk a navigation filter uses); its fitted shape at \
                 the first scales, {separation:.1} standard errors from pure white noise's, is \
                 sub-sample correlation (e.g. the sensor's own filter), which the fit keeps",
                short(*correlation_time_s),
                short(*sampling_interval_s),
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
/// ([`CanonicalTerm`]), `readings` (`Reading`), `reduced` (the reduced model, guess mode),
/// `separation` (of the reduced model's refit from the fitted WV; 0 when nothing was
/// refitted), `objective` (of that refit; the fit's own when nothing was refitted) and
/// `implied_wv` (of that refit).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CanonicalModel {
    /// The canonical model in guess mode (its term list).
    pub model: Model,
    /// Its terms in canonical order.
    pub terms: Vec<CanonicalTerm>,
    /// What was read differently from the fit, and why.
    pub(crate) readings: Vec<Reading>,
    /// The reduced model (rules 1 and 2, guess mode): the smallest model whose fit the data
    /// cannot tell from the fitted model's; fit it for identified estimates and intervals.
    pub reduced: Model,
    /// Separation of the reduced model's refit from the fitted WV.
    pub(crate) separation: f64,
    /// Objective of the reduced model's fit.
    pub objective: f64,
    /// Implied WV of the reduced model's fit (a component read as white noise by rule 3 keeps
    /// its fitted shape here).
    pub implied_wv: Vec<f64>,
}

impl CanonicalModel {
    /// Whether the canonical model is the fitted model, term for term (notes aside).
    pub(crate) fn is_as_fitted(&self) -> bool {
        self.readings.iter().all(Reading::is_note)
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

    /// The first term of a role (the white noise, the random walk, ...).
    pub(crate) fn term_of(&self, role: Role) -> Option<&CanonicalTerm> {
        self.terms.iter().find(|t| spec(t.kind).role == role)
    }

    /// The value of the physical quantity `name` of the term of a role.
    pub(crate) fn physical_of(&self, role: Role, name: &str) -> Option<f64> {
        self.term_of(role)?
            .physical
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.value)
    }

    /// Number of correlated-noise terms (AR1/GM).
    #[cfg(test)]
    pub(crate) fn correlated_terms(&self) -> usize {
        self.terms
            .iter()
            .filter(|t| spec(t.kind).role == Role::Correlated)
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

    /// The per-sample AR1 form of a correlated part (docs/methods.md §4.3).
    fn ar1(&self, freq_hz: f64) -> Option<Ar1> {
        let markov = spec(self.kind()).markov?;
        Some((markov.ar1)(&self.values(), freq_hz))
    }

    /// Correlation time in seconds of a correlated part: `1 / beta` for a GM (exact even
    /// where phi underflows), `-1 / (f ln phi)` for an AR1 (0 for `phi <= 0`).
    fn correlation_time_s(&self, freq_hz: f64) -> Option<f64> {
        let markov = spec(self.kind()).markov?;
        Some((markov.correlation_time_s)(&self.values(), freq_hz))
    }

    /// What the part is to a navigation filter.
    fn role(&self) -> Role {
        spec(self.kind()).role
    }

    /// Rule 3: the correlation time is below the sampling interval.
    fn white_at_sampling_rate(&self, freq_hz: f64) -> bool {
        self.correlation_time_s(freq_hz)
            .is_some_and(|t| t < 1.0 / freq_hz)
    }
}

/// A correlated part of `kind` with the AR1 form `ar1` (GM through docs/methods.md §4.3).
fn part_from_ar1(kind: ProcessKind, ar1: Ar1, freq_hz: f64, from: Vec<usize>) -> Option<Part> {
    let values = (spec(kind).markov?.from_ar1)(ar1, freq_hz)?;
    Some(Part {
        component: Component::new(kind, values.into_iter().map(Some).collect()).ok()?,
        from,
    })
}

/// Long-run variance `sigma2 / (1 - phi)^2`: the white noise an AR1 is at scales far beyond
/// its correlation length (the level of its spectrum at low frequency).
pub(crate) fn long_run_variance(ar1: Ar1) -> f64 {
    ar1.sigma2 / ((1.0 - ar1.phi) * (1.0 - ar1.phi))
}

/// Adds a one-parameter term of a role (white noise, random walk) to `parts`: to the existing
/// one's value, or as a new part.
fn add_single(parts: &mut Vec<Part>, role: Role, value: f64, from: &[usize]) -> Option<()> {
    let kind = kind_of(role);
    match parts.iter_mut().find(|p| p.kind() == kind) {
        Some(p) => {
            let v = p.values()[0] + value;
            p.component = Component::new(kind, vec![Some(v)]).ok()?;
            p.from.extend_from_slice(from);
            p.from.sort_unstable();
        }
        None => parts.push(Part {
            component: Component::new(kind, vec![Some(value)]).ok()?,
            from: from.to_vec(),
        }),
    }
    Some(())
}

/// A candidate reduction (rule 2): the working model it leads to and its reading (whose
/// separation is filled in once measured).
struct Reduction {
    parts: Vec<Part>,
    reading: Reading,
    /// For a random-walk replacement: the rising part's position (its separation is kept for
    /// the note when the replacement fails).
    rising: Option<usize>,
}

/// The state of the canonicalisation: the working model, its implied WV and objective.
struct State {
    parts: Vec<Part>,
    implied: ImpliedWv,
    objective: f64,
}

impl GmwmFit {
    /// The canonical model of this fit with the default `SEPARATION_LIMIT` (module doc).
    ///
    /// Cost: one implied WV, plus one stage-2 refit per tried reduction (a drift, a slow or fast
    /// AR1/GM, or a pair of adjacent AR1/GMs), a few milliseconds each.
    ///
    /// # Errors
    /// As `GmwmFit::canonical_with`.
    pub fn canonical(&self) -> Result<CanonicalModel, FitError> {
        self.canonical_with(SEPARATION_LIMIT)
    }

    /// [`GmwmFit::canonical`] with another separation limit (0 accepts only exact
    /// reductions).
    ///
    /// # Errors
    /// [`FitError::Input`] with a [`crate::ParamError`] for a limit that is not a finite
    /// number >= 0, or for a fit without an empirical WV (a bare [`Gmwm::fit_weighted`]: the
    /// separation is measured in the noise of that WV); errors of the refits' set-up. A refit
    /// that fails to converge only makes its reduction fail the test.
    pub(crate) fn canonical_with(&self, limit: f64) -> Result<CanonicalModel, FitError> {
        if !(limit.is_finite() && limit >= 0.0) {
            return Err(crate::ParamError::new(
                "separation limit",
                limit,
                "a finite number of standard errors >= 0",
            )
            .into());
        }
        let Some(wv) = &self.empirical else {
            return Err(crate::ParamError::new(
                "fit",
                "without an empirical wavelet variance",
                "a fit that carries its WV (Gmwm::fit, fit_from_wv, fit_series, fit_wv): the \
                 separation is measured in that WV's noise",
            )
            .into());
        };
        let log_variance = wv.log_variance();
        let levels = self.nu_hat.len();
        let freq = self.freq_hz;
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
                    )?,
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
            model_of(&parts)?.implied_wv(levels, freq)?
        };
        let mut state = State {
            parts,
            implied,
            objective: self.objective,
        };
        let mut separation = 0.0;
        // rule 2, closest first; the separations of the rising parts' failed replacements in
        // the last round are the notes'
        let rising_separation = loop {
            let mut best: Option<(f64, State, Reading)> = None;
            let mut rising = Vec::new();
            for r in self.reductions(&state) {
                let d = match self.refit(r.parts, &log_variance)? {
                    Some(next) => {
                        let d = wv_separation(&self.implied_wv.wv, &next.implied.wv, &log_variance);
                        if d <= limit && best.as_ref().map_or(true, |b| d < b.0) {
                            let mut reading = r.reading;
                            reading.set_separation(d);
                            best = Some((d, next, reading));
                        }
                        d
                    }
                    None => f64::INFINITY,
                };
                if let Some(k) = r.rising {
                    rising.push((k, d));
                }
            }
            let Some((d, next, reading)) = best else {
                break rising;
            };
            readings.push(reading);
            separation = d;
            state = next;
        };
        let longest_scale_s = self.longest_scale_s();
        for (k, d) in rising_separation {
            let p = &state.parts[k];
            readings.push(Reading::CorrelationBeyondRecording {
                component: p.from[0],
                process: p.kind().name(),
                correlation_time_s: p.correlation_time_s(freq).unwrap_or(f64::NAN),
                longest_scale_s,
                separation: d,
            });
        }
        // rule 3 and the terms
        let mut terms_parts: Vec<Part> = Vec::new();
        for (k, p) in state.parts.iter().enumerate() {
            match p.ar1(freq) {
                Some(ar1) if p.white_at_sampling_rate(freq) => {
                    let sigma2 = long_run_variance(ar1);
                    // the reduced fit's WV with this component read as white noise
                    let read: Vec<f64> = (0..levels)
                        .map(|j| {
                            state.implied.wv[j] - state.implied.processes[k].wv[j]
                                + sigma2 / state.implied.tau[j]
                        })
                        .collect();
                    readings.push(Reading::WhiteAtSamplingRate {
                        component: p.from[0],
                        process: p.kind().name(),
                        correlation_time_s: p.correlation_time_s(freq).unwrap_or(f64::NAN),
                        sampling_interval_s: 1.0 / freq,
                        separation: wv_separation(&state.implied.wv, &read, &log_variance),
                    });
                    add_single(&mut terms_parts, Role::WhiteNoise, sigma2, &p.from)
                        .ok_or_else(|| bad_value("white noise", sigma2))?;
                }
                _ if p.role() == Role::WhiteNoise => {
                    add_single(&mut terms_parts, Role::WhiteNoise, p.values()[0], &p.from)
                        .ok_or_else(|| bad_value("white noise", p.values()[0]))?;
                }
                _ => terms_parts.push(p.clone()),
            }
        }
        // a component rule 2 read as white noise or a random walk stands in that term even when
        // a later refit moved its share into another part and dropped the merged one
        for r in &readings {
            let (role, c) = match *r {
                Reading::WhiteAtObservedScales { component, .. } => (Role::WhiteNoise, component),
                Reading::RandomWalkAtObservedScales { component, .. } => {
                    (Role::RandomWalk, component)
                }
                _ => continue,
            };
            if let Some(p) = terms_parts.iter_mut().find(|p| p.role() == role) {
                if !p.from.contains(&c) {
                    p.from.push(c);
                    p.from.sort_unstable();
                }
            }
        }
        let terms_parts = canonical_order(terms_parts, freq);
        let guess =
            |parts: &[Part]| Model::new(parts.iter().map(|p| Component::guess(p.kind())).collect());
        let model = guess(&terms_parts)?;
        let reduced = guess(&canonical_order(state.parts.clone(), freq))?;
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
                    physical: physical_parameters(p.kind(), i, &theta, freq, None),
                    from: p.from.clone(),
                }
            })
            .collect();
        Ok(CanonicalModel {
            model,
            terms,
            readings,
            reduced,
            separation,
            objective: state.objective,
            implied_wv: state.implied.wv,
        })
    }

    /// The longest observed scale `2^J / f` in seconds.
    fn longest_scale_s(&self) -> f64 {
        elementary::exp2(self.nu_hat.len() as f64) / self.freq_hz
    }

    /// The reductions of rule 2 that apply to `state` (module doc).
    fn reductions(&self, state: &State) -> Vec<Reduction> {
        let f = self.freq_hz;
        let parts = &state.parts;
        let mut out = Vec::new();
        let correlated: Vec<(usize, Ar1)> = parts
            .iter()
            .enumerate()
            .filter_map(|(k, p)| p.ar1(f).map(|a| (k, a)))
            .collect();
        let longest_scale_s = self.longest_scale_s();
        for &(k, ar1) in &correlated {
            let p = &parts[k];
            let (component, process) = (p.from[0], p.kind().name());
            let correlation_time_s = p.correlation_time_s(f).unwrap_or(f64::NAN);
            if rises_everywhere(&state.implied, k) {
                let mut next = parts.clone();
                next.remove(k);
                if add_single(&mut next, Role::RandomWalk, ar1.sigma2, &p.from).is_some() {
                    out.push(Reduction {
                        parts: next,
                        reading: Reading::RandomWalkAtObservedScales {
                            component,
                            process: process.clone(),
                            correlation_time_s,
                            longest_scale_s,
                            separation: f64::NAN,
                        },
                        rising: Some(k),
                    });
                }
            }
            if falls_everywhere(&state.implied, k) {
                let mut next = parts.clone();
                next.remove(k);
                if add_single(&mut next, Role::WhiteNoise, long_run_variance(ar1), &p.from)
                    .is_some()
                {
                    out.push(Reduction {
                        parts: next,
                        reading: Reading::WhiteAtObservedScales {
                            component,
                            process,
                            correlation_time_s,
                            separation: f64::NAN,
                        },
                        rising: None,
                    });
                }
            }
        }
        // adjacent pairs in correlation time
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
            let reading = Reading::Merged {
                components: part.from.clone(),
                process: parts[i].kind().name(),
                correlation_times_s: [&parts[i], &parts[k]]
                    .iter()
                    .map(|p| p.correlation_time_s(f).unwrap_or(f64::NAN))
                    .collect(),
                separation: f64::NAN,
            };
            next.push(part);
            out.push(Reduction {
                parts: next,
                reading,
                rising: None,
            });
        }
        if let Some(k) = parts.iter().position(|p| p.role() == Role::Drift) {
            let omega = parts[k].values()[0];
            let tau_last = elementary::exp2(self.nu_hat.len() as f64);
            let mut next = parts.clone();
            let from = next.remove(k).from;
            let has_rw = next.iter().any(|p| p.role() == Role::RandomWalk);
            let gamma2 = 0.75 * omega * omega * tau_last;
            let ok = if has_rw {
                Some(())
            } else {
                add_single(&mut next, Role::RandomWalk, gamma2, &from)
            };
            if ok.is_some() && (has_rw || gamma2 > 0.0) {
                out.push(Reduction {
                    parts: next,
                    reading: Reading::DriftAsRandomWalk {
                        component: from[0],
                        separation: f64::NAN,
                    },
                    rising: None,
                });
            }
        }
        out
    }

    /// Refits the working model `parts` (stage 2 from its values, the fit's WV, weights and
    /// transforms, AR1/GMs ordered); `None` when the start is not a valid model or the refit
    /// fails to converge. Components the refit fits to nothing (rule 1) are dropped.
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
                    )?,
                    from: p.from,
                });
            }
            at += n;
        }
        if next.is_empty() {
            return Ok(None);
        }
        let objective = fit.objective;
        let implied = if next.len() == fit.model.n_components() {
            fit.implied_wv
        } else {
            model_of(&next)?.implied_wv(self.nu_hat.len(), self.freq_hz)?
        };
        Ok(Some(State {
            parts: next,
            implied,
            objective,
        }))
    }
}

fn bad_value(what: &str, value: f64) -> FitError {
    crate::ParamError::new(
        "canonical model",
        value,
        format!("a positive finite {what} variance"),
    )
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
fn model_of(parts: &[Part]) -> Result<Model, crate::model::ModelError> {
    Model::new(parts.iter().map(|p| p.component.clone()).collect())
}

/// Canonical term order: by role ([`Role`]: correlated terms by decreasing correlation time
/// (phi decreasing), then WN, QN, FN, RW, DR, then anything else), within a role by the kind's
/// rank (vibration lines by frequency), else in the given order.
fn canonical_order(mut parts: Vec<Part>, freq_hz: f64) -> Vec<Part> {
    let phi = |p: &Part| p.ar1(freq_hz).map_or(0.0, |a| a.phi);
    let rank = |p: &Part| (spec(p.kind()).rank)(&p.values());
    parts.sort_by(|a, b| {
        a.role()
            .cmp(&b.role())
            .then_with(|| phi(b).total_cmp(&phi(a)))
            .then_with(|| rank(a).total_cmp(&rank(b)))
    });
    parts
}
