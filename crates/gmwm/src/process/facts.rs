//! What the engine knows of each [`ProcessKind`]: its [`Spec`], declared once in the kind's
//! own module next to its struct, and read through `spec` (the one table, in `process/mod.rs`)
//! by every stage instead of matching on kinds:
//!
//! - the model language and the model's rules: name, parameters with their domains
//!   (docs/methods.md §0.2), orders, how often it may appear, which kind it reparametrises, its
//!   validating constructor;
//! - the fit: the transforms of its parameters (§5.3), its slot in the ordered chain, its
//!   starting values (§6.3), the shapes a fit driven to zero is revived along;
//! - the read-off: its [`Role`] for a navigation filter and in the canonical order, its
//!   first-order Markov form (AR1, GM), its physical parameters (§14).
//!
//! The implied WV and its derivatives are the struct's [`LatentProcess`](super::LatentProcess)
//! impl; its simulation and its part of the exact covariance of the WV its
//! [`Simulate`](super::Simulate) impl.
//!
//! A new process is its module (struct, validating `new`, `LatentProcess`, `Simulate`, a
//! `SPEC` whose optional facts default to [`BASE`]), its `mod` line and one row of the table in
//! `process/mod.rs`.

use super::draw::Draw;
use super::param::{ChainSlot, ParamTransform, TransformPreset};
use super::{spec, Ar1, Process, KINDS};
use crate::error::ParamError;
use crate::process::{ParamDomain, ProcessKind};

/// The facts of one process kind (see the module docs).
pub(crate) struct Spec {
    /// The name in the model language, without orders: `"WN"`, `"AR"`.
    pub(crate) name: &'static str,
    /// How the kind is written in lists and suggestions: `"WN()"`, `"AR(p)"`.
    pub(crate) syntax: &'static str,
    /// The parameters, in `theta` order (docs/methods.md §0.2).
    pub(crate) params: Params,
    /// The orders written after the name (`AR(p)`, `ARMA(p,q)`); `None` for the other kinds.
    pub(crate) orders: Option<Orders>,
    /// How often the kind may appear in one model (docs/methods.md §0.2).
    pub(crate) occurs: Occurs,
    /// The validated process from every value, in parameter order; `freq_hz` converts GM
    /// (docs/methods.md §4.3) and is unused otherwise. The kind gives the orders of an order kind.
    pub(crate) build: fn(ProcessKind, &[f64], f64) -> Result<Process, ParamError>,
    /// What the term is to a navigation filter: which canonical read-off it gives.
    pub(crate) role: Role,
    /// The kind this one reparametrises (GM: AR1 at a sampling rate, docs/methods.md §4.3): the
    /// two may not be mixed in one model.
    pub(crate) reparametrises: Option<ProcessKind>,
    /// Whether its parameters need the sampling rate (GM's `beta` is per second).
    pub(crate) needs_rate: bool,
    /// The scalar transforms of its parameters under a preset (docs/methods.md §5.3), in
    /// `theta` order.
    pub(crate) transforms: fn(ProcessKind, TransformPreset) -> Vec<ParamTransform>,
    /// Its first parameter's slot in the ordered chain of correlated components at a rate
    /// (`crate::fit::transform`), for AR1 and GM.
    pub(crate) chain: Option<fn(f64) -> ChainSlot>,
    /// Its starting values (docs/methods.md §6.3): pushes one value per parameter, a given
    /// value kept as given.
    pub(crate) draw: fn(&mut Draw<'_>, ProcessKind, &[Option<f64>], &mut Vec<f64>),
    /// The unit shapes a fit driven to zero may be revived along
    /// (`crate::fit::revive`); none by default.
    pub(crate) unit_shapes: fn(usize, f64) -> Vec<UnitShape>,
    /// Its first-order Markov form, for a correlated kind (AR1, GM).
    pub(crate) markov: Option<Markov>,
    /// Its physical read-off at a rate, the data unit named `unit` (docs/methods.md §14):
    /// `(name, value, unit)`; none by default.
    pub(crate) physical: fn(&[f64], f64, &str) -> Vec<Physical>,
    /// Its place among the terms of its role in the canonical model, ascending, from its values
    /// (a repeated kind's terms in a fixed order, e.g. vibration lines by frequency); `0` by
    /// default (the fitted order kept).
    pub(crate) rank: fn(&[f64]) -> f64,
}

/// What a term is to a navigation filter, in the canonical model's order (docs/methods.md
/// §14): a correlated (Gauss–Markov) term, white noise (N), quantisation (Q), flicker (B), a
/// random walk (K), a drift (R), a periodic term, anything else.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Role {
    /// A first-order Markov process: AR1, GM.
    Correlated,
    /// White noise: the noise density N.
    WhiteNoise,
    /// Quantisation noise: Q.
    Quantization,
    /// Flicker (1/f) noise: the bias instability B; contributes to neither N nor K.
    Flicker,
    /// A random walk: K.
    RandomWalk,
    /// A deterministic drift: R.
    Drift,
    /// A periodic term (a vibration line, SIN): no N, K or B, a physical read-off of its
    /// frequency and amplitude.
    Periodic,
    /// No navigation read-off (the ARMA family).
    Other,
}

/// The first-order Markov form of a correlated kind, from its parameter values at a rate.
#[derive(Clone, Copy)]
pub(crate) struct Markov {
    /// The per-sample AR1 (docs/methods.md §4.3).
    pub(crate) ar1: fn(&[f64], f64) -> Ar1,
    /// The kind's values of an AR1 (`None` where the kind cannot hold it).
    pub(crate) from_ar1: fn(Ar1, f64) -> Option<Vec<f64>>,
    /// Correlation time in seconds.
    pub(crate) correlation_time_s: fn(&[f64], f64) -> f64,
    /// `(phi, sigma2, beta, sigma2_gm)`: both forms (docs/methods.md §4.3).
    pub(crate) forms: MarkovForms,
}

/// `(phi, sigma2, beta, sigma2_gm)` of a correlated kind's values at a rate.
pub(crate) type MarkovForms = fn(&[f64], f64) -> (f64, f64, f64, f64);

/// One physical read-off of a term: name, value, unit.
pub(crate) type Physical = (&'static str, f64, String);

/// A unit-scale parameter vector (scale parameter last) and the map from the WV multiplier
/// `t` to the scale parameter.
pub(crate) type UnitShape = (Vec<f64>, fn(f64) -> f64);

/// The defaults of the optional facts, for `..Spec::BASE` in a kind's declaration.
pub(crate) const BASE: Spec = Spec {
    name: "",
    syntax: "",
    params: Params::Fixed(&[], (0, 0)),
    orders: None,
    occurs: Occurs::Once,
    build: |_, _, _| Err(ParamError::new("process", "", "a kind of the table")),
    role: Role::Other,
    reparametrises: None,
    needs_rate: false,
    transforms: |_, _| Vec::new(),
    chain: None,
    draw: |_, _, _, _| {},
    unit_shapes: |_, _| Vec::new(),
    markov: None,
    physical: |_, _, _| Vec::new(),
    rank: |_| 0.0,
};

/// The one-parameter kind of a role (white noise, random walk, ...): the first in the table.
///
/// # Panics
/// If the table has no such kind (a broken invariant of the table; its test checks every
/// role the engine asks for).
pub(crate) fn kind_of(role: Role) -> ProcessKind {
    KINDS
        .iter()
        .copied()
        .find(|&k| spec(k).role == role)
        .expect("the table has a kind of every role the engine reads off")
}

/// The parameters of a kind.
pub(crate) enum Params {
    /// A fixed list of `(name, domain)`, and the ARMA orders `(p, q)` the kind is a special case
    /// of (`(1, 0)` for AR1, `(0, 0)` for a non-ARMA kind).
    Fixed(&'static [(&'static str, ParamDomain)], (usize, usize)),
    /// `ar1..arp`, `ma1..maq` (any finite value), then `sigma2` (a variance), with the orders
    /// of the kind.
    Arma,
}

/// The orders an order kind takes after its name (`AR(p)`, `MA(q)`, `ARMA(p,q)`).
pub(crate) struct Orders {
    /// Whether the AR order `p` is written.
    pub(crate) ar: bool,
    /// Whether the MA order `q` is written (after `p` when both are).
    pub(crate) ma: bool,
    /// The lowest valid order (the highest is [`MAX_ORDER`](crate::model::MAX_ORDER)).
    pub(crate) min: usize,
    /// What a bad order should be, for [`ModelError::BadOrder`](crate::model::ModelError).
    pub(crate) expected: &'static str,
    /// What is expected when every order is 0 (only reachable when `min` is 0).
    pub(crate) all_zero: &'static str,
    /// An example for messages: `"AR(2)"`.
    pub(crate) example: &'static str,
    /// The kind with orders `(p, q)` (an unwritten order is 0).
    pub(crate) make: fn(usize, usize) -> ProcessKind,
}

impl Orders {
    /// The written orders of `(p, q)`: `[p]`, `[q]` or `[p, q]`.
    pub(crate) fn written(&self, (p, q): (usize, usize)) -> impl Iterator<Item = usize> {
        [(self.ar, p), (self.ma, q)]
            .into_iter()
            .filter_map(|(w, v)| w.then_some(v))
    }
}

/// How often a kind may appear in one model (docs/methods.md §0.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Occurs {
    /// At most once (identifiability): WN, QN, RW, DR.
    Once,
    /// Any number of times (`k*GM()`, `2*SIN()`); a kind and the kind it reparametrises (GM
    /// and AR1) may not be mixed.
    Repeats,
    /// At most one term of the whole ARMA family (a sum of ARMAs is an ARMA).
    ArmaFamily,
}

impl Spec {
    /// The parameter names of a fixed kind, as `&'static str` (for
    /// [`LatentProcess::param_names`](super::LatentProcess::param_names)); empty for an order
    /// kind.
    pub(crate) fn fixed_names(&self) -> Vec<&'static str> {
        match self.params {
            Params::Fixed(list, _) => list.iter().map(|(n, _)| *n).collect(),
            Params::Arma => Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table maps every listed kind back to itself, and names are unique.
    #[test]
    fn table_is_consistent() {
        let mut names = std::collections::HashSet::new();
        for &kind in KINDS {
            let s = spec(kind);
            assert!(names.insert(s.name), "{} twice", s.name);
            if let Some(o) = &s.orders {
                let (p, q) = kind.orders();
                assert_eq!((o.make)(p, q), kind);
            }
        }
    }

    /// Every kind declares one transform per parameter under both presets, its starting-value
    /// draw gives one value per parameter, and its physical read-off and Markov form exist
    /// exactly for the kinds whose role says so: a new process that forgets a fact fails here,
    /// not in a fit.
    #[test]
    fn every_kind_declares_its_facts() {
        use super::super::draw::{Dominance, Draw, DrawContext};
        use super::super::param::TransformPreset;
        use rand::SeedableRng;
        let ctx = DrawContext {
            wv: vec![0.5, 0.3, 0.1, 0.06, 0.03],
            sigma2_t: 1.0,
            n: 1000.0,
            range: 0.01,
            freq_hz: 100.0,
            dom: Dominance::Wn,
            only_wn: false,
            only_qn: false,
            wv_min: 1e-3,
        };
        for &kind in KINDS.iter().chain(&[ProcessKind::Arma(2, 1)]) {
            let s = spec(kind);
            let n = kind.n_params();
            for preset in [TransformPreset::Imu, TransformPreset::Ssm] {
                assert_eq!((s.transforms)(kind, preset).len(), n, "{kind} transforms");
            }
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
            let mut draw = Draw {
                ctx: &ctx,
                rng: &mut rng,
                condition: 1,
                last_phi: 0.0,
            };
            let mut theta = Vec::new();
            (s.draw)(&mut draw, kind, &vec![None; n], &mut theta);
            assert_eq!(theta.len(), n, "{kind} draw");
            assert!(theta.iter().all(|v| v.is_finite()), "{kind} draw {theta:?}");
            assert_eq!(
                s.markov.is_some(),
                s.role == Role::Correlated,
                "{kind} Markov form"
            );
            assert_eq!(
                s.chain.is_some(),
                s.role == Role::Correlated,
                "{kind} chain slot"
            );
            let physical = (s.physical)(&theta, 100.0, "u");
            assert_eq!(
                physical.is_empty(),
                s.role == Role::Other,
                "{kind} physical read-off"
            );
        }
    }
}
