//! The leaf errors of the engine: a series that cannot be analysed, a parameter with an
//! impossible value, a model that breaks a rule, and [`InputError`], the three together. They
//! name no module of the engine, so every module can return them; each stage's own error
//! (`ReadError`, `FitError`, `SelectionError`, `CalibError`, ...) holds them, and
//! [`enum@crate::Error`], in the crate root above every module, holds those.

use thiserror::Error;

/// A computation on data and a model could not run: the series, a parameter or the model is
/// unusable.
///
/// It is the error of the computations every stage builds on (wavelet and Allan variances,
/// implied wavelet variances, simulation, the bootstrap of V). The stage errors
/// ([`crate::fit::FitError`], [`crate::selection::SelectionError`],
/// [`crate::calib::CalibError`]) hold one; it holds none of them, so the error types are
/// siblings that all convert into [`enum@crate::Error`], never a loop.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum InputError {
    /// The series is unusable.
    #[error(transparent)]
    Series(#[from] SeriesError),
    /// A parameter or option has an impossible value.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// The model breaks a rule of docs/methods.md §0.2 or has an invalid value.
    #[error(transparent)]
    Model(#[from] ModelError),
}

/// `From<ParamError | SeriesError | ModelError>` for a stage error with an `Input(InputError)`
/// variant, so that `?` carries a leaf error into it.
macro_rules! input_error_from {
    ($stage:ident) => {
        impl From<$crate::ParamError> for $stage {
            fn from(e: $crate::ParamError) -> Self {
                $stage::Input(e.into())
            }
        }
        impl From<$crate::SeriesError> for $stage {
            fn from(e: $crate::SeriesError) -> Self {
                $stage::Input(e.into())
            }
        }
        impl From<$crate::error::ModelError> for $stage {
            fn from(e: $crate::error::ModelError) -> Self {
                $stage::Input(e.into())
            }
        }
    };
}
pub(crate) use input_error_from;

/// A model-rule violation (docs/methods.md §0.2) or an invalid component.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ModelError {
    /// A model needs at least one component.
    #[error("a model needs at least one component, e.g. WN() or 3*GM()+WN()")]
    Empty,
    /// WN, QN, RW or DR (or an ARMA kind) appears more than once.
    #[error(
        "{kind} appears {count} times but may appear at most once; only GM, AR1 and SIN may repeat \
         (docs/methods.md §0.2)"
    )]
    Repeated {
        /// The repeated kind.
        kind: String,
        /// How many times it appears.
        count: usize,
    },
    /// GM and AR1 in the same model.
    #[error(
        "GM and AR1 may not be mixed in one model (found {gm} GM and {ar1} AR1); use one of \
         them (docs/methods.md §0.2)"
    )]
    GmAr1Mixed {
        /// Number of GM components.
        gm: usize,
        /// Number of AR1 components.
        ar1: usize,
    },
    /// Two ARMA-family terms (MA1, ARMA11, AR(p), MA(q), ARMA(p,q)).
    #[error(
        "at most one ARMA-family term (MA1, ARMA11, AR(p), MA(q), ARMA(p,q)) per model, found \
         {first} and {second}; a sum of ARMAs is one ARMA of higher order"
    )]
    ArmaFamily {
        /// The first ARMA-family term.
        first: String,
        /// The second one.
        second: String,
    },
    /// An order of AR(p), MA(q) or ARMA(p,q) out of range.
    #[error("{kind}: order {order} is invalid: expected {expected}")]
    BadOrder {
        /// The kind with the bad order.
        kind: String,
        /// The offending order.
        order: usize,
        /// What would be valid.
        expected: &'static str,
    },
    /// A multiplier `k` in `k * gm()` outside 1..=`MAX_MULTIPLIER` (100).
    #[error("multiplier {k} is invalid: expected an integer from 1 to 100")]
    BadMultiplier {
        /// The multiplier given.
        k: usize,
    },
    /// A parameter value outside its basic domain (`ParamDomain`).
    #[error(
        "component {component} (0-based) {kind}: {name} = {value} is invalid: expected {expected}"
    )]
    BadParameter {
        /// 0-based component index in the model (0 for a standalone component).
        component: usize,
        /// Its kind.
        kind: String,
        /// The parameter name (docs/methods.md §0.2).
        name: String,
        /// The value given.
        value: f64,
        /// What would be valid.
        expected: &'static str,
    },
    /// A parameter name the kind does not have.
    #[error("{kind} has no parameter {name:?}; its parameters are {}", .valid.join(", "))]
    UnknownParameter {
        /// The kind.
        kind: String,
        /// The name given.
        name: String,
        /// The kind's parameter names.
        valid: Vec<String>,
    },
    /// A component whose `values` length differs from its kind's parameter count.
    #[error(
        "component {component} (0-based) {kind} has {found} values; {kind} has {expected} \
         parameters"
    )]
    WrongLength {
        /// 0-based component index.
        component: usize,
        /// Its kind.
        kind: String,
        /// `kind.n_params()`.
        expected: usize,
        /// `values.len()`.
        found: usize,
    },
    /// A parameter vector whose length differs from the model's parameter count.
    #[error("theta has {found} values; the model has {expected} parameters")]
    ThetaLength {
        /// `Model::n_params()`.
        expected: usize,
        /// Length given.
        found: usize,
    },
}

/// A series that cannot be analysed.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum SeriesError {
    /// No samples at all.
    #[error("series is empty")]
    Empty,
    /// Fewer samples than the computation needs.
    #[error("series has {n} samples; {what} needs at least {needed}")]
    TooShort {
        /// Number of samples given.
        n: usize,
        /// Minimum number of samples needed.
        needed: usize,
        /// What needed them (e.g. "one wavelet level").
        what: String,
    },
    /// A sample is NaN or infinite.
    #[error("sample {index} (0-based) is not a finite number ({value})")]
    NonFinite {
        /// 0-based index of the sample.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// The robust (biweight) scale equation has no root: the values are too dispersed (more
    /// than the breakdown fraction is contaminated), so the robust scale is undefined.
    #[error(
        "the biweight scale equation has no root: mean psi_c^2 never reaches a(c) = {a} (c = {c}); \
         too large a share of the coefficients is contaminated for the robust estimator"
    )]
    NoRobustScale {
        /// a(c), the target of the scale equation.
        a: f64,
        /// Tuning constant.
        c: f64,
    },
    /// A computed variance overflowed although every sample is finite.
    #[error(
        "the {what} is not finite although every sample is: squares of the data overflow \
         double precision (|x| near 1e154 or more); rescale the series"
    )]
    Overflow {
        /// Which quantity overflowed.
        what: String,
    },
    /// The samples differ so little that squared differences underflow double precision:
    /// every variance would be zero or subnormal noise.
    #[error(
        "the samples differ by at most {range:e}: squared differences underflow double \
         precision (below 1e-300); rescale the series"
    )]
    Underflow {
        /// `max - min` of the samples.
        range: f64,
    },
    /// Every sample has the same value: all variances are zero and nothing can be estimated.
    #[error("series is constant (every sample equals {value}); its variances are all zero")]
    Constant {
        /// The constant value.
        value: f64,
    },
}

/// A parameter or option with an impossible value.
#[derive(Debug, Error, Clone, PartialEq)]
#[error("invalid {name} = {value}: {expected}")]
pub struct ParamError {
    /// Parameter name as the user knows it (e.g. `eff`, `levels`, `alpha`).
    pub name: &'static str,
    /// The value given, as text.
    pub value: String,
    /// What would have been valid.
    pub expected: String,
}

impl ParamError {
    /// Builds a parameter error.
    pub fn new(name: &'static str, value: impl ToString, expected: impl Into<String>) -> Self {
        Self {
            name,
            value: value.to_string(),
            expected: expected.into(),
        }
    }
}

/// Samples whose range is below this have squared differences below 1e-300, near the end of
/// double precision (normal numbers stop at 2.2e-308).
pub(crate) const UNDERFLOW_RANGE: f64 = 1e-150;

/// Checks that a series is non-empty, finite and not constant (docs/methods.md §0.1 preconditions),
/// nor so flat that its squared differences underflow ([`UNDERFLOW_RANGE`]).
///
/// One vectorisable pass (min, max and a NaN-propagating probe); the offending index is looked
/// up only on failure.
///
/// # Errors
/// [`SeriesError::Empty`], [`SeriesError::TooShort`] (one sample),
/// [`SeriesError::NonFinite`] (first offending index), [`SeriesError::Constant`] or
/// [`SeriesError::Underflow`].
pub(crate) fn check_series(x: &[f64]) -> Result<(), SeriesError> {
    let first = *x.first().ok_or(SeriesError::Empty)?;
    if x.len() == 1 {
        // one sample is no series: say so rather than call it constant
        return Err(SeriesError::TooShort {
            n: 1,
            needed: 2,
            what: "a variance".into(),
        });
    }
    check_finite(x)?;
    let (lo, hi) = x
        .iter()
        .fold((first, first), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    if lo == hi {
        return Err(SeriesError::Constant { value: first });
    }
    if hi - lo < UNDERFLOW_RANGE {
        return Err(SeriesError::Underflow { range: hi - lo });
    }
    Ok(())
}

/// Checks a sampling rate: finite and positive (hertz).
///
/// # Errors
/// [`ParamError`] named `freq` (the CLI flag).
pub(crate) fn check_freq(freq_hz: f64) -> Result<(), ParamError> {
    if freq_hz.is_finite() && freq_hz > 0.0 {
        Ok(())
    } else {
        Err(ParamError::new(
            "freq",
            freq_hz,
            "must be a positive number of hertz",
        ))
    }
}

/// Checks that every value is finite (an empty slice passes).
///
/// # Errors
/// [`SeriesError::NonFinite`] with the first offending index.
pub(crate) fn check_finite(x: &[f64]) -> Result<(), SeriesError> {
    // v * 0 is 0 for finite v and NaN for NaN or +-inf; the sum is NaN iff one of them is.
    let mut acc = [0.0f64; 4];
    let mut quads = x.chunks_exact(4);
    for q in &mut quads {
        for k in 0..4 {
            acc[k] += q[k] * 0.0;
        }
    }
    let probe = acc.iter().sum::<f64>() + quads.remainder().iter().map(|v| v * 0.0).sum::<f64>();
    if probe.is_nan() {
        return Err(first_non_finite(x));
    }
    Ok(())
}

#[cold]
fn first_non_finite(x: &[f64]) -> SeriesError {
    let (index, &value) = x
        .iter()
        .enumerate()
        .find(|(_, v)| !v.is_finite())
        .expect("a non-finite value exists");
    SeriesError::NonFinite { index, value }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_series_rejects_bad_input() {
        assert_eq!(check_series(&[]), Err(SeriesError::Empty));
        assert_eq!(
            check_series(&[1.0, f64::NAN]).unwrap_err().to_string(),
            "sample 1 (0-based) is not a finite number (NaN)"
        );
        assert!(matches!(
            check_series(&[2.0, 2.0, 2.0]),
            Err(SeriesError::Constant { value }) if value == 2.0
        ));
        assert!(check_series(&[1.0, 2.0]).is_ok());
        // one sample is too short, not "constant"
        assert!(matches!(
            check_series(&[0.5]),
            Err(SeriesError::TooShort {
                n: 1,
                needed: 2,
                ..
            })
        ));
        // squared differences that underflow: refused, not variances of zero
        assert!(matches!(
            check_series(&[1e-300, -2e-300, 3e-300]),
            Err(SeriesError::Underflow { range }) if (range - 5e-300).abs() < 1e-310
        ));
        assert!(matches!(
            check_series(&[5e-324, 0.0]),
            Err(SeriesError::Underflow { .. })
        ));
        assert!(check_series(&[1e-140, 2e-140]).is_ok());
    }
}
