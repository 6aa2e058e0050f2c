//! Latent error models: an ordered sum of stochastic process components (docs/methods.md §0.2).
//!
//! A [`Model`] is what the GMWM estimator fits: for example `3*GM()+WN()+QN()+RW()`, three
//! Gauss–Markov processes plus white noise, quantisation noise and a random walk. Its parameter
//! vector `theta` is the concatenation of the components' parameters in model order, with the
//! names and order of docs/methods.md §0.2 ([`ProcessKind::param_names`]).
//!
//! Two ways to build one, both validated by the same rules ([`Model::new`]):
//! - text, as users of the R package write it: [`Model::parse`] / [`str::parse`], grammar in
//!   [`parse`](mod@parse);
//! - components directly: `Model::new(vec![Component::guess(ProcessKind::Wn)])`.
//!
//! The crate's own tests also build models with free functions and operators,
//! `(3 * gm() + wn() + qn() + rw()).build()` (`builder.rs`, compiled for tests only).
//!
//! # Guess mode and user values (docs/methods.md §0.3)
//! Every parameter value is optional ([`Component::values`] holds `Option<f64>`). A component
//! without values is in *guess mode*: the estimator computes its starting values (docs/methods.md
//! §6). **Deviation from the package (docs/methods.md §13.20):** in a partly specified model such
//! as `AR1(phi=0.9, sigma2=0.1)+WN()` the missing values stay `None` here, and the estimator fills
//! them from its own starting values; the package instead starts them at fixed placeholders
//! (WN at 3, ...), which is rarely what the user meant.
//!
//! # Rules (docs/methods.md §0.2, plus one of ours)
//! - `GM`, `AR1` and `SIN` may repeat (`k*GM()`), but GM and AR1 may not be mixed in one model;
//! - `WN`, `QN`, `RW`, `DR` appear at most once each (identifiability);
//! - **at most one ARMA-family term** (`MA1`, `ARMA11`, `AR(p)`, `MA(q)`, `ARMA(p,q)`): two such
//!   terms are not identifiable from one another by the wavelet variance (a sum of ARMAs is an
//!   ARMA). The R package has no such rule; it is gmwm's own;
//! - orders: `AR(p)`, `MA(q)` need an order from 1 to `MAX_ORDER`; `ARMA(p,q)` needs
//!   `p + q >= 1`, each at most `MAX_ORDER`;
//! - every given value is finite and in its basic domain ([`ParamDomain`]).
//!
//! Worked example: the test `tests::examples::example_model_builder`.

#[cfg(test)]
mod builder;
pub(crate) mod parse;
mod realize;

#[cfg(test)]
pub(crate) use builder::{
    ar, ar1, ar1_with, ar_with, arma, arma11_with, arma_with, dr, dr_with, gm, gm_with, ma, ma1,
    qn, rw, wn, wn_with, ModelSpec,
};
pub use parse::{ModelParseError, ParseErrorKind};
pub use realize::{ComponentWv, ImpliedWv};

pub(crate) use crate::error::ModelError;
pub(crate) use crate::process::MAX_ORDER;
pub(crate) use crate::process::{ParamDomain, ProcessKind};

use crate::process::{spec, Occurs, KINDS};
use std::fmt;

/// Largest multiplier `k` accepted in `k*GM()` / `k*AR1()` (and by `k * gm()`).
///
/// A guard against absurd allocations from typos; the package's largest automatic search
/// (docs/methods.md §8.4) uses 3 GMs, and more than a handful is never identifiable.
pub(crate) const MAX_MULTIPLIER: usize = 100;

/// One term of a model: a process kind and its (optional) parameter values (docs/methods.md
/// §0.2–§0.3).
///
/// `values` has one entry per parameter of `kind`, in [`ProcessKind::param_names`] order; `None`
/// means "not given" (the estimator chooses the starting value). The fields are public for
/// reading and pattern matching; a component built by hand is checked when it enters a
/// [`Model`] (or by [`Component::new`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Component {
    /// The process.
    pub kind: ProcessKind,
    /// One optional value per parameter, `values.len() == kind.n_params()`.
    pub values: Vec<Option<f64>>,
}

impl Component {
    /// A component in guess mode: no value given (docs/methods.md §0.3).
    ///
    /// The kind's orders are not checked here (see `ProcessKind::check_orders`); a bad order
    /// is reported when the component enters a [`Model`].
    pub fn guess(kind: ProcessKind) -> Component {
        let n = kind.n_params().min(2 * MAX_ORDER + 1);
        Component {
            kind,
            values: vec![None; n],
        }
    }

    /// A validated component with the given optional values.
    ///
    /// # Errors
    /// [`ModelError::BadOrder`], [`ModelError::WrongLength`] or [`ModelError::BadParameter`]
    /// (with `component` 0).
    pub fn new(kind: ProcessKind, values: Vec<Option<f64>>) -> Result<Component, ModelError> {
        let c = Component { kind, values };
        c.check(0)?;
        Ok(c)
    }

    /// Sets the parameter called `name` (ASCII case-insensitive, docs/methods.md §0.2 names) to
    /// `value`, e.g. `ar1().with("phi", 0.9)?`.
    ///
    /// # Errors
    /// [`ModelError::UnknownParameter`] (with the valid names) or [`ModelError::BadParameter`]
    /// when `value` is outside the parameter's `ParamDomain`.
    pub fn with(mut self, name: &str, value: f64) -> Result<Component, ModelError> {
        let index = self
            .kind
            .param_index(name)
            .ok_or_else(|| ModelError::UnknownParameter {
                kind: self.kind.name(),
                name: name.to_string(),
                valid: self.kind.param_names(),
            })?;
        check_value(0, self.kind, index, value)?;
        if let Some(slot) = self.values.get_mut(index) {
            *slot = Some(value);
        }
        Ok(self)
    }

    /// Whether no value is given (guess mode, docs/methods.md §0.3).
    pub(crate) fn is_guess(&self) -> bool {
        self.values.iter().all(Option::is_none)
    }

    /// Whether every value is given.
    pub fn is_fully_specified(&self) -> bool {
        self.values.iter().all(Option::is_some)
    }

    /// Checks orders, length and values; `component` is the index reported in errors.
    fn check(&self, component: usize) -> Result<(), ModelError> {
        self.kind.check_orders()?;
        if self.values.len() != self.kind.n_params() {
            return Err(ModelError::WrongLength {
                component,
                kind: self.kind.name(),
                expected: self.kind.n_params(),
                found: self.values.len(),
            });
        }
        for (index, v) in self.values.iter().enumerate() {
            if let Some(v) = *v {
                check_value(component, self.kind, index, v)?;
            }
        }
        Ok(())
    }
}

/// Checks one value against its [`ParamDomain`].
pub(crate) fn check_value(
    component: usize,
    kind: ProcessKind,
    index: usize,
    value: f64,
) -> Result<(), ModelError> {
    let domain = kind.param_domain(index).unwrap_or(ParamDomain::Finite);
    if domain.contains(value) {
        Ok(())
    } else {
        Err(ModelError::BadParameter {
            component,
            kind: kind.name(),
            name: kind.param_names().get(index).cloned().unwrap_or_default(),
            value,
            expected: domain.expected(),
        })
    }
}

impl fmt::Display for Component {
    /// Canonical text: `WN()`, `AR(2)`, `AR1(phi=0.9, sigma2=0.1)`, `ARMA(2,1)(ar1=0.5)`; only
    /// the given values are written, by name, in the shortest text that parses back to the same
    /// bits (`format_value`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let has_orders = spec(self.kind).orders.is_some();
        f.write_str(&self.kind.name())?;
        if has_orders && self.is_guess() {
            return Ok(());
        }
        f.write_str("(")?;
        let names = self.kind.param_names();
        let mut first = true;
        for (name, v) in names.iter().zip(&self.values) {
            if let Some(v) = v {
                if !first {
                    f.write_str(", ")?;
                }
                first = false;
                write!(f, "{name}={}", format_value(*v))?;
            }
        }
        f.write_str(")")
    }
}

/// The canonical text of a parameter value: Rust's shortest round-tripping `{}` for ordinary
/// magnitudes, `{:e}` (also shortest round-tripping) for `0 < |v| < 1e-4` and `|v| >= 1e6`.
///
/// `format_value(v).parse::<f64>()` returns exactly `v` (same bits, including `-0`).
///
/// Worked example: the test `tests::examples::example_format_value`.
pub(crate) fn format_value(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && (!(1e-4..1e6).contains(&a)) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// A validated latent error model: an ordered, non-empty sum of components obeying the rules of
/// docs/methods.md §0.2.
///
/// Its `Display` is the canonical text, which [`Model::parse`] reads back to an equal model
/// (bitwise-equal values); serde (de)serialises a model as that string.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    components: Vec<Component>,
}

/// Checks every component and the model rules; on failure also returns the index of the
/// component the error points at (for the parser's column).
pub(crate) fn validate(components: &[Component]) -> Result<(), (usize, ModelError)> {
    if components.is_empty() {
        return Err((0, ModelError::Empty));
    }
    for (i, c) in components.iter().enumerate() {
        c.check(i).map_err(|e| (i, e))?;
    }
    // WN, QN, RW, DR (the kinds that occur once) at most once, checked in table order: report
    // at the second occurrence.
    for &kind in KINDS.iter().filter(|&&k| spec(k).occurs == Occurs::Once) {
        let at: Vec<usize> = (0..components.len())
            .filter(|&i| components[i].kind == kind)
            .collect();
        if at.len() > 1 {
            return Err((
                at[1],
                ModelError::Repeated {
                    kind: kind.name(),
                    count: at.len(),
                },
            ));
        }
    }
    // a kind and the kind it reparametrises (GM, AR1) are not mixed
    let count = |kind: ProcessKind| components.iter().filter(|c| c.kind == kind).count();
    let mixed = KINDS.iter().find_map(|&kind| {
        let base = spec(kind).reparametrises?;
        let (n, m) = (count(kind), count(base));
        (n > 0 && m > 0).then_some((kind, base, n, m))
    });
    if let Some((kind, base, gm, ar1)) = mixed {
        // point at the first component of whichever of the two kinds came second
        let pair = |c: &&Component| c.kind == kind || c.kind == base;
        let first = components.iter().find(pair).map(|c| c.kind);
        let at = components
            .iter()
            .position(|c| pair(&c) && Some(c.kind) != first)
            .unwrap_or(0);
        return Err((at, ModelError::GmAr1Mixed { gm, ar1 }));
    }
    let arma: Vec<usize> = (0..components.len())
        .filter(|&i| components[i].kind.is_arma_family())
        .collect();
    if arma.len() > 1 {
        let (first, second) = (components[arma[0]].kind, components[arma[1]].kind);
        let err = if first == second {
            ModelError::Repeated {
                kind: first.name(),
                count: arma
                    .iter()
                    .filter(|&&i| components[i].kind == first)
                    .count(),
            }
        } else {
            ModelError::ArmaFamily {
                first: first.name(),
                second: second.name(),
            }
        };
        return Err((arma[1], err));
    }
    Ok(())
}

impl Model {
    /// A model from its components, in order, validated against the rules of docs/methods.md §0.2
    /// (module docs).
    ///
    /// # Errors
    /// [`ModelError::Empty`], [`ModelError::Repeated`], [`ModelError::GmAr1Mixed`],
    /// [`ModelError::ArmaFamily`], [`ModelError::BadOrder`], [`ModelError::WrongLength`] or
    /// [`ModelError::BadParameter`].
    pub fn new(components: Vec<Component>) -> Result<Model, ModelError> {
        validate(&components).map_err(|(_, e)| e)?;
        Ok(Model { components })
    }

    /// Parses the text language of the R package, e.g. `"3*GM()+WN()+QN()+RW()"` or
    /// `"AR1(phi=0.9, sigma2=0.1)+WN()"`; grammar in docs/methods.md §0.2.
    ///
    /// # Errors
    /// [`ModelParseError`] with the byte offset and column of the offending character; a
    /// model-rule violation is [`ParseErrorKind::Rule`] pointing at the offending term.
    pub fn parse(text: &str) -> Result<Model, ModelParseError> {
        parse::parse_model(text)
    }

    /// The components in model order.
    pub fn components(&self) -> &[Component] {
        &self.components
    }

    /// Number of components (a `k*GM()` term counts k times).
    pub fn n_components(&self) -> usize {
        self.components.len()
    }

    /// Number of parameters, the length of `theta` (docs/methods.md §0.2).
    pub fn n_params(&self) -> usize {
        self.components.iter().map(|c| c.kind.n_params()).sum()
    }

    /// `(component index, parameter name)` for each entry of `theta`, in order (docs/methods.md
    /// §0.2).
    pub fn param_names(&self) -> Vec<(usize, String)> {
        self.components
            .iter()
            .enumerate()
            .flat_map(|(i, c)| c.kind.param_names().into_iter().map(move |n| (i, n)))
            .collect()
    }

    /// Whether no value is given anywhere: the estimator computes all starting values
    /// (docs/methods.md §0.3).
    pub fn is_guess_mode(&self) -> bool {
        self.components.iter().all(Component::is_guess)
    }

    /// Whether every value is given.
    pub fn is_fully_specified(&self) -> bool {
        self.components.iter().all(Component::is_fully_specified)
    }

    /// The flattened `theta` in model order, `None` where no value is given.
    pub fn values(&self) -> Vec<Option<f64>> {
        self.components
            .iter()
            .flat_map(|c| c.values.iter().copied())
            .collect()
    }

    /// The same structure with every value set from `theta` (model order, docs/methods.md §0.2).
    ///
    /// # Errors
    /// [`ModelError::ThetaLength`] or [`ModelError::BadParameter`].
    pub fn with_values(&self, theta: &[f64]) -> Result<Model, ModelError> {
        if theta.len() != self.n_params() {
            return Err(ModelError::ThetaLength {
                expected: self.n_params(),
                found: theta.len(),
            });
        }
        let mut rest = theta;
        let mut components = Vec::with_capacity(self.components.len());
        for (i, c) in self.components.iter().enumerate() {
            let (mine, tail) = rest.split_at(c.kind.n_params());
            rest = tail;
            for (index, &v) in mine.iter().enumerate() {
                check_value(i, c.kind, index, v)?;
            }
            components.push(Component {
                kind: c.kind,
                values: mine.iter().map(|&v| Some(v)).collect(),
            });
        }
        Ok(Model { components })
    }

    /// The same structure in guess mode (every value `None`).
    pub fn without_values(&self) -> Model {
        Model {
            components: self
                .components
                .iter()
                .map(|c| Component::guess(c.kind))
                .collect(),
        }
    }

    /// How many components have exactly this kind (`AR(2)` and `AR(3)` differ).
    pub fn count(&self, kind: ProcessKind) -> usize {
        self.components.iter().filter(|c| c.kind == kind).count()
    }

    /// The kinds in model order.
    pub fn kinds(&self) -> Vec<ProcessKind> {
        self.components.iter().map(|c| c.kind).collect()
    }

    /// Whether `other` has the same terms, in any order and whatever their values
    /// (`ARMA(2,1)+WN()` and `WN()+ARMA(2,1)` do; `AR(2)` and `AR(3)` do not).
    ///
    /// ```
    /// use gmwm::Model;
    /// let a: Model = "AR1(phi=0.9, sigma2=1)+WN()+AR1()".parse().unwrap();
    /// assert!(a.same_terms(&"WN()+2*AR1()".parse().unwrap()));
    /// assert!(!a.same_terms(&"WN()+AR1()".parse().unwrap()));
    /// let ar2: Model = "AR(2)+WN()".parse().unwrap();
    /// assert!(ar2.same_terms(&"WN()+AR(2)".parse().unwrap()));
    /// assert!(!ar2.same_terms(&"WN()+AR(3)".parse().unwrap()));
    /// ```
    pub fn same_terms(&self, other: &Model) -> bool {
        self.components.len() == other.components.len()
            && self
                .components
                .iter()
                .all(|c| self.count(c.kind) == other.count(c.kind))
    }
}

impl fmt::Display for Model {
    /// Canonical text: components joined by `+`; consecutive identical value-less GM/AR1
    /// components collapse to `k*GM()`, k at most `MAX_MULTIPLIER` (a longer run is split, so
    /// that the text parses back); values by name ([`Component`]'s `Display`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut i = 0;
        let mut first = true;
        while i < self.components.len() {
            let c = &self.components[i];
            let mut run = 1;
            if c.kind.may_repeat() && c.is_guess() {
                while run < MAX_MULTIPLIER && self.components.get(i + run) == Some(c) {
                    run += 1;
                }
            }
            if !first {
                f.write_str("+")?;
            }
            first = false;
            if run > 1 {
                write!(f, "{run}*")?;
            }
            write!(f, "{c}")?;
            i += run;
        }
        Ok(())
    }
}

impl std::str::FromStr for Model {
    type Err = ModelParseError;

    fn from_str(s: &str) -> Result<Model, ModelParseError> {
        Model::parse(s)
    }
}

impl TryFrom<Vec<Component>> for Model {
    type Error = ModelError;

    fn try_from(components: Vec<Component>) -> Result<Model, ModelError> {
        Model::new(components)
    }
}

impl serde::Serialize for Model {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> serde::Deserialize<'de> for Model {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Model, D::Error> {
        let text = String::deserialize(d)?;
        Model::parse(&text).map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn param_names_follow_methods_0_2() {
        assert_eq!(ProcessKind::Gm.param_names(), ["beta", "sigma2_gm"]);
        assert_eq!(
            ProcessKind::Arma(2, 1).param_names(),
            ["ar1", "ar2", "ma1", "sigma2"]
        );
        assert_eq!(ProcessKind::Ma(3).n_params(), 4);
        assert_eq!(ProcessKind::Arma(2, 1).name(), "ARMA(2,1)");
    }

    #[test]
    fn component_new_accepts_and_rejects() {
        assert!(Component::new(ProcessKind::Wn, vec![Some(1.0)]).is_ok());
        assert!(Component::new(ProcessKind::Wn, vec![Some(-1.0)]).is_err());
        assert!(Component::new(ProcessKind::Wn, vec![]).is_err());
        assert!(Component::new(ProcessKind::Ar(0), vec![None]).is_err());
        assert!(Component::new(ProcessKind::Dr, vec![Some(-3.0)]).is_ok());
        assert!(Component::new(ProcessKind::Ar1, vec![Some(1.0), None]).is_err());
    }

    #[test]
    fn format_value_round_trips() {
        for v in [
            0.1, -0.0, 7.08e-9, 1e300, 5e-324, 123456.789, 1e6, 9.99e-5, 1e-4,
        ] {
            assert_eq!(
                format_value(v).parse::<f64>().unwrap().to_bits(),
                v.to_bits()
            );
        }
    }
}
