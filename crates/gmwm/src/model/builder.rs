//! Free functions and operators that build models in Rust code (docs/methods.md §0.2–§0.3).
//!
//! `wn()`, `gm()`, `ar(2)`, ... return a [`Component`] in guess mode; the `*_with` functions
//! return a validated component with every value given. `+` and `k *` cannot return a
//! `Result`, so they build an unvalidated [`ModelSpec`]; [`ModelSpec::build`] checks the rules:
//!
//! ```
//! use gmwm::model::{ar1_with, gm, qn, rw, wn, wn_with, ModelError};
//! let m = (3 * gm() + wn() + qn() + rw()).build().unwrap();
//! assert_eq!(m.n_components(), 6);
//! let partly = (ar1_with(0.9, 0.1).unwrap() + wn()).build().unwrap();
//! assert!(!partly.is_guess_mode() && !partly.is_fully_specified());
//! assert!(matches!((wn() + wn()).build(), Err(ModelError::Repeated { count: 2, .. })));
//! assert!(wn_with(-1.0).is_err()); // a variance is > 0
//! ```

use super::{Component, Model, ModelError, ProcessKind, MAX_MULTIPLIER};
use std::ops::{Add, Mul};

/// White noise in guess mode, `WN()`.
pub(crate) fn wn() -> Component {
    Component::guess(ProcessKind::Wn)
}

/// Quantisation noise in guess mode, `QN()`.
pub(crate) fn qn() -> Component {
    Component::guess(ProcessKind::Qn)
}

/// Random walk in guess mode, `RW()`.
pub(crate) fn rw() -> Component {
    Component::guess(ProcessKind::Rw)
}

/// Drift in guess mode, `DR()`.
pub(crate) fn dr() -> Component {
    Component::guess(ProcessKind::Dr)
}

/// AR1 in guess mode, `AR1()`.
pub(crate) fn ar1() -> Component {
    Component::guess(ProcessKind::Ar1)
}

/// Gauss–Markov in guess mode, `GM()`.
pub(crate) fn gm() -> Component {
    Component::guess(ProcessKind::Gm)
}

/// MA1 in guess mode, `MA1()`.
pub(crate) fn ma1() -> Component {
    Component::guess(ProcessKind::Ma1)
}

/// AR(p) in guess mode, `AR(p)`; the order is checked by [`ModelSpec::build`] / [`Model::new`].
pub(crate) fn ar(p: usize) -> Component {
    Component::guess(ProcessKind::Ar(p))
}

/// MA(q) in guess mode, `MA(q)`; the order is checked by [`ModelSpec::build`] / [`Model::new`].
pub(crate) fn ma(q: usize) -> Component {
    Component::guess(ProcessKind::Ma(q))
}

/// ARMA(p,q) in guess mode, `ARMA(p,q)`; the orders are checked by [`ModelSpec::build`] /
/// [`Model::new`].
#[cfg(test)]
pub(crate) fn arma(p: usize, q: usize) -> Component {
    Component::guess(ProcessKind::Arma(p, q))
}

fn given(
    kind: ProcessKind,
    values: impl IntoIterator<Item = f64>,
) -> Result<Component, ModelError> {
    Component::new(kind, values.into_iter().map(Some).collect())
}

/// `WN(sigma2)`.
///
/// # Errors
/// [`ModelError::BadParameter`] unless `sigma2` is a finite variance > 0.
pub(crate) fn wn_with(sigma2: f64) -> Result<Component, ModelError> {
    given(ProcessKind::Wn, [sigma2])
}

/// `DR(omega)`.
///
/// # Errors
/// [`ModelError::BadParameter`] unless `omega` is finite.
#[cfg(test)]
pub(crate) fn dr_with(omega: f64) -> Result<Component, ModelError> {
    given(ProcessKind::Dr, [omega])
}

/// `AR1(phi, sigma2)`.
///
/// # Errors
/// [`ModelError::BadParameter`] unless `phi` is in (-1, 1) and `sigma2` > 0 is finite.
pub(crate) fn ar1_with(phi: f64, sigma2: f64) -> Result<Component, ModelError> {
    given(ProcessKind::Ar1, [phi, sigma2])
}

/// `GM(beta, sigma2_gm)` (docs/methods.md §4.3).
///
/// # Errors
/// [`ModelError::BadParameter`] unless `beta` > 0 and `sigma2_gm` > 0 are finite.
#[cfg(test)]
pub(crate) fn gm_with(beta: f64, sigma2_gm: f64) -> Result<Component, ModelError> {
    given(ProcessKind::Gm, [beta, sigma2_gm])
}

/// `ARMA11(phi, theta, sigma2)`.
///
/// # Errors
/// [`ModelError::BadParameter`] unless `phi`, `theta` are in (-1, 1) and `sigma2` > 0 is finite.
#[cfg(test)]
pub(crate) fn arma11_with(phi: f64, theta: f64, sigma2: f64) -> Result<Component, ModelError> {
    given(ProcessKind::Arma11, [phi, theta, sigma2])
}

/// `AR(p)` with coefficients `ar` (p = `ar.len()`) and innovation variance `sigma2`.
///
/// # Errors
/// [`ModelError::BadOrder`] for an empty or too long `ar`; [`ModelError::BadParameter`] for a
/// non-finite coefficient or a bad `sigma2`.
#[cfg(test)]
pub(crate) fn ar_with(ar: &[f64], sigma2: f64) -> Result<Component, ModelError> {
    given(
        ProcessKind::Ar(ar.len()),
        ar.iter().copied().chain([sigma2]),
    )
}

/// `ARMA(p,q)` with coefficients `ar`, `ma` (R sign convention, docs/methods.md §0.2) and `sigma2`.
///
/// # Errors
/// As [`ar_with`]; `ARMA(0,0)` is rejected.
#[cfg(test)]
pub(crate) fn arma_with(ar: &[f64], ma: &[f64], sigma2: f64) -> Result<Component, ModelError> {
    given(
        ProcessKind::Arma(ar.len(), ma.len()),
        ar.iter().chain(ma).copied().chain([sigma2]),
    )
}

/// An unvalidated sum of terms `k * component`, built by `+` and `k *`; [`ModelSpec::build`]
/// (or `Model::try_from`) applies the rules of docs/methods.md §0.2.
///
/// Validation is deferred because operators cannot return a `Result`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ModelSpec {
    terms: Vec<(usize, Component)>,
}

impl ModelSpec {
    /// An empty spec (building it fails with [`ModelError::Empty`]).
    pub fn new() -> ModelSpec {
        ModelSpec::default()
    }

    /// Appends `k` copies of `component`.
    pub fn push(mut self, k: usize, component: Component) -> ModelSpec {
        self.terms.push((k, component));
        self
    }

    /// The terms as `(multiplier, component)` pairs, in order.
    pub fn terms(&self) -> &[(usize, Component)] {
        &self.terms
    }

    /// Expands the multipliers and validates the model.
    ///
    /// # Errors
    /// [`ModelError::BadMultiplier`] for `k = 0` or `k >` [`MAX_MULTIPLIER`], otherwise as
    /// [`Model::new`].
    pub fn build(self) -> Result<Model, ModelError> {
        let mut components = Vec::new();
        for (k, c) in self.terms {
            if k == 0 || k > MAX_MULTIPLIER {
                return Err(ModelError::BadMultiplier { k });
            }
            components.extend(std::iter::repeat(c).take(k));
        }
        Model::new(components)
    }
}

impl From<Component> for ModelSpec {
    fn from(c: Component) -> ModelSpec {
        ModelSpec::new().push(1, c)
    }
}

impl From<Model> for ModelSpec {
    fn from(m: Model) -> ModelSpec {
        ModelSpec {
            terms: m.components.into_iter().map(|c| (1, c)).collect(),
        }
    }
}

impl TryFrom<ModelSpec> for Model {
    type Error = ModelError;

    fn try_from(spec: ModelSpec) -> Result<Model, ModelError> {
        spec.build()
    }
}

impl<T: Into<ModelSpec>> Add<T> for ModelSpec {
    type Output = ModelSpec;

    fn add(mut self, rhs: T) -> ModelSpec {
        self.terms.extend(rhs.into().terms);
        self
    }
}

impl<T: Into<ModelSpec>> Add<T> for Component {
    type Output = ModelSpec;

    fn add(self, rhs: T) -> ModelSpec {
        ModelSpec::from(self) + rhs
    }
}

impl<T: Into<ModelSpec>> Add<T> for Model {
    type Output = ModelSpec;

    fn add(self, rhs: T) -> ModelSpec {
        ModelSpec::from(self) + rhs
    }
}

impl Mul<Component> for usize {
    type Output = ModelSpec;

    /// `k * gm()`: k copies of the component (k checked by [`ModelSpec::build`]).
    fn mul(self, rhs: Component) -> ModelSpec {
        ModelSpec::new().push(self, rhs)
    }
}
