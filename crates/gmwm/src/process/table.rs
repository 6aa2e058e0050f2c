//! The one table of processes: what the model language, validation, the implied WV and the
//! simulator know of each [`ProcessKind`].
//!
//! Each kind's facts are declared once, in its own module next to its struct, as a [`Spec`]:
//! its name in the model language, its parameters with their domains (docs/methods.md §0.2), how
//! often it may appear in a model, and its constructor (which validates). The implied WV and its
//! derivatives are the struct's [`LatentProcess`](super::LatentProcess) impl, its simulation
//! its [`Simulate`](super::Simulate) impl. [`spec`] is the only map from a kind to its facts:
//! the parser, the metadata methods of [`ProcessKind`], [`Component::process`] and the
//! simulator read it instead of matching on kinds.
//!
//! A new process is its module (struct, validating `new`, `LatentProcess`, `Simulate`,
//! `SPEC`), its variant in [`ProcessKind`] and in the `processes!` list of [`super::Process`],
//! and one line of the table below.
//!
//! [`Component::process`]: crate::model::Component::process

use super::{ar1, arma, arma11, dr, ma1, qn, rw, wn, Process};
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
    /// Any number of times (`k*GM()`), but two repeating kinds may not be mixed.
    Repeats,
    /// At most one term of the whole ARMA family (a sum of ARMAs is an ARMA).
    ArmaFamily,
}

/// Declares the table: one line per kind, `pattern => example kind, spec`.
macro_rules! table {
    ($($pat:pat => $example:expr, $spec:expr;)*) => {
        /// The facts of `kind`.
        pub(crate) fn spec(kind: ProcessKind) -> &'static Spec {
            match kind {
                $($pat => &$spec,)*
            }
        }

        /// Every kind once, in table order (the order of lists in messages); order kinds with
        /// example orders.
        pub(crate) const KINDS: &[ProcessKind] = &[$($example),*];
    };
}

table! {
    ProcessKind::Wn => ProcessKind::Wn, wn::SPEC;
    ProcessKind::Qn => ProcessKind::Qn, qn::SPEC;
    ProcessKind::Rw => ProcessKind::Rw, rw::SPEC;
    ProcessKind::Dr => ProcessKind::Dr, dr::SPEC;
    ProcessKind::Ar1 => ProcessKind::Ar1, ar1::AR1_SPEC;
    ProcessKind::Gm => ProcessKind::Gm, ar1::GM_SPEC;
    ProcessKind::Ma1 => ProcessKind::Ma1, ma1::SPEC;
    ProcessKind::Arma11 => ProcessKind::Arma11, arma11::SPEC;
    ProcessKind::Ar(_) => ProcessKind::Ar(1), arma::AR_SPEC;
    ProcessKind::Ma(_) => ProcessKind::Ma(1), arma::MA_SPEC;
    ProcessKind::Arma(..) => ProcessKind::Arma(1, 1), arma::ARMA_SPEC;
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
}
