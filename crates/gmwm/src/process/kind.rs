//! The kinds of latent process (docs/methods.md §0.2) and the basic domains of their
//! parameters: what the model language names, facts read from the one table of processes
//! ([`table`](super::table)).

use super::facts::{Occurs, Params};
use super::{spec, ProcessKind};
use crate::error::ModelError;
use std::fmt;

/// Largest order accepted for `AR(p)`, `MA(q)` and each order of `ARMA(p,q)`.
///
/// A guard against absurd allocations from typos such as `AR(20000000)`; IMU error models use
/// orders of 1 to 3, and the implied WV of docs/methods.md §4.4 becomes numerically meaningless
/// long before 100 lags.
pub(crate) const MAX_ORDER: usize = 100;

/// The basic domain of one parameter value, checked whenever a value is given (docs/methods.md §5.3
/// lists the transforms the optimiser applies on these domains).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub(crate) enum ParamDomain {
    /// A variance (`sigma2`, `sigma2_gm`, `q2`, `gamma2`): finite and > 0 (log transform).
    Variance,
    /// The GM `beta`: finite and > 0 (`phi = exp(-beta / freq)` lies in (0, 1), docs/methods.md
    /// §4.3).
    Rate,
    /// The AR1/MA1/ARMA11 coefficients `phi`, `theta`: in the open interval (-1, 1)
    /// (the pseudo-logit domain of docs/methods.md §5.3).
    UnitInterval,
    /// Any finite number: DR `omega` and the `AR(p)`/`MA(q)`/`ARMA(p,q)` coefficients
    /// (docs/methods.md §5.3 imposes no joint stationarity; the package's placeholders are -1
    /// and -2).
    Finite,
    /// A positive number that is not a variance (the SIN `amplitude`, data unit): finite and
    /// > 0 (log transform).
    Positive,
    /// A frequency in cycles per sample below Nyquist (the SIN `omega`): in the open interval
    /// (0, 1/2) (logit transform on (0, 1/2)).
    HalfCycle,
}

impl ParamDomain {
    /// Whether `value` lies in this domain.
    pub(crate) fn contains(self, value: f64) -> bool {
        match self {
            ParamDomain::Variance | ParamDomain::Rate | ParamDomain::Positive => {
                value.is_finite() && value > 0.0
            }
            ParamDomain::HalfCycle => value > 0.0 && value < 0.5,
            ParamDomain::UnitInterval => value > -1.0 && value < 1.0,
            ParamDomain::Finite => value.is_finite(),
        }
    }

    /// What a valid value looks like, for error messages.
    pub(crate) fn expected(self) -> &'static str {
        match self {
            ParamDomain::Variance => "a finite variance > 0",
            ParamDomain::Rate => "a finite rate > 0",
            ParamDomain::UnitInterval => "a value in the open interval (-1, 1)",
            ParamDomain::Finite => "a finite number",
            ParamDomain::Positive => "a finite number > 0",
            ParamDomain::HalfCycle => "a frequency in the open interval (0, 1/2) cycles per sample",
        }
    }
}

impl ProcessKind {
    /// The canonical name: `"WN"`, `"AR1"`, `"AR(2)"`, `"ARMA(2,1)"` (docs/methods.md §0.2).
    pub fn name(&self) -> String {
        let spec = spec(*self);
        match &spec.orders {
            None => spec.name.to_string(),
            Some(o) => {
                let orders: Vec<String> = o.written(self.orders()).map(|v| v.to_string()).collect();
                format!("{}({})", spec.name, orders.join(","))
            }
        }
    }

    /// The name without orders: `"AR"` for `AR(2)`, `"WN"` for `WN`.
    pub(crate) fn base_name(&self) -> &'static str {
        spec(*self).name
    }

    /// Parameter names in `theta` order (docs/methods.md §0.2): WN `sigma2`; QN `q2`; RW `gamma2`;
    /// DR `omega`; AR1 `phi, sigma2`; GM `beta, sigma2_gm`; MA1 `theta, sigma2`; ARMA11
    /// `phi, theta, sigma2`; AR(p) `ar1..arp, sigma2`; MA(q) `ma1..maq, sigma2`; ARMA(p,q)
    /// `ar1..arp, ma1..maq, sigma2`; SIN `amplitude, omega`.
    pub fn param_names(&self) -> Vec<String> {
        match spec(*self).params {
            Params::Fixed(list, _) => list.iter().map(|(n, _)| n.to_string()).collect(),
            Params::Arma => {
                let (p, q) = self.orders();
                (1..=p)
                    .map(|i| format!("ar{i}"))
                    .chain((1..=q).map(|i| format!("ma{i}")))
                    .chain(std::iter::once("sigma2".to_string()))
                    .collect()
            }
        }
    }

    /// Number of parameters, `param_names().len()`.
    pub fn n_params(&self) -> usize {
        match spec(*self).params {
            Params::Fixed(list, _) => list.len(),
            Params::Arma => {
                let (p, q) = self.orders();
                p.saturating_add(q).saturating_add(1)
            }
        }
    }

    /// The index of a parameter by name (ASCII case-insensitive), if the kind has it.
    pub(crate) fn param_index(&self, name: &str) -> Option<usize> {
        self.param_names()
            .iter()
            .position(|n| n.eq_ignore_ascii_case(name))
    }

    /// The basic domain of parameter `index` (see [`ParamDomain`]); `None` past the end.
    pub(crate) fn param_domain(&self, index: usize) -> Option<ParamDomain> {
        match spec(*self).params {
            Params::Fixed(list, _) => list.get(index).map(|(_, d)| *d),
            // coefficients are any finite number, the innovation variance comes last
            Params::Arma => match self.n_params() {
                n if index + 1 == n => Some(ParamDomain::Variance),
                n if index < n => Some(ParamDomain::Finite),
                _ => None,
            },
        }
    }

    /// The AR and MA orders `(p, q)` of the ARMA-family kinds; `(0, 0)` for the others except
    /// AR1 `(1, 0)`, MA1 `(0, 1)`, ARMA11 `(1, 1)`.
    pub(crate) fn orders(&self) -> (usize, usize) {
        match *self {
            ProcessKind::Ar(p) => (p, 0),
            ProcessKind::Ma(q) => (0, q),
            // the filter length, written as an MA order (a boxcar of L samples is an MA(L - 1))
            ProcessKind::Maf(l) => (0, l),
            ProcessKind::Arma(p, q) => (p, q),
            other => match spec(other).params {
                Params::Fixed(_, orders) => orders,
                Params::Arma => (0, 0),
            },
        }
    }

    /// Whether the kind may repeat in a model (`k*GM()`, `k*AR1()`; docs/methods.md §0.2).
    pub(crate) fn may_repeat(&self) -> bool {
        spec(*self).occurs == Occurs::Repeats
    }

    /// Whether the kind belongs to the ARMA family (MA1, ARMA11, AR(p), MA(q), ARMA(p,q)), of
    /// which a model holds at most one term.
    pub(crate) fn is_arma_family(&self) -> bool {
        spec(*self).occurs == Occurs::ArmaFamily
    }

    /// Checks the orders of `AR(p)`, `MA(q)`, `ARMA(p,q)` (1..=[`MAX_ORDER`], `p + q >= 1`).
    ///
    /// # Errors
    /// [`ModelError::BadOrder`].
    pub(crate) fn check_orders(&self) -> Result<(), ModelError> {
        let Some(o) = &spec(*self).orders else {
            return Ok(());
        };
        let bad = |order: usize, expected: &'static str| {
            Err(ModelError::BadOrder {
                kind: self.name(),
                order,
                expected,
            })
        };
        let (p, q) = self.orders();
        if let Some(order) = o.written((p, q)).find(|v| !(o.min..=MAX_ORDER).contains(v)) {
            return bad(order, o.expected);
        }
        if p == 0 && q == 0 {
            return bad(0, o.all_zero);
        }
        Ok(())
    }
}

impl fmt::Display for ProcessKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}
