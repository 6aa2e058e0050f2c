//! Parameters as the optimiser sees them: the scalar transforms of docs/methods.md §5.3 and the
//! slot a correlated process holds in the ordered chain of several AR1/GM components
//! (`crate::fit::transform`'s module doc). Each process declares which of them its parameters
//! use ([`Spec`](super::Spec)); the fit reads them from there.

use crate::math::elementary;
use serde::{Deserialize, Serialize};

/// Logistic function `1 / (1 + e^{-u})`, evaluated without overflow for either sign of `u`.
pub(crate) fn logistic(u: f64) -> f64 {
    if u >= 0.0 {
        1.0 / (1.0 + elementary::exp(-u))
    } else {
        let e = elementary::exp(u);
        e / (1.0 + e)
    }
}

/// One scalar transform `theta = g(u)` (docs/methods.md §5.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub(crate) enum ParamTransform {
    /// `u = theta`.
    Identity,
    /// `u = ln theta`, theta in (0, inf): variances, GM beta.
    Log,
    /// `u = ln(theta / (1 - theta))`, theta in (0, 1).
    Logit,
    /// Pseudo-logit `u = ln((1 + theta) / (1 - theta))`, theta in (-1, 1); inverse
    /// `2 / (1 + e^{-u}) - 1`.
    PseudoLogit,
    /// Logit2 `u = ln((theta + 2) / (2 - theta))`, theta in (-2, 2); inverse `4 / (1 + e^{-u}) - 2`.
    Logit2,
    /// `u = ln |theta|`, inverse `e^u`: the DR slope, whose sign is lost (the estimate is >= 0).
    LogAbs,
    /// Logit on (0, 1/2): `u = ln(theta / (1/2 - theta))`, inverse `logistic(u) / 2`: a
    /// frequency in cycles per sample below Nyquist (the SIN `omega`).
    LogitHalf,
}

impl ParamTransform {
    /// The open domain of theta, in words (for error messages).
    pub(crate) fn domain(self) -> &'static str {
        match self {
            ParamTransform::Identity => "a finite number",
            ParamTransform::Log => "a finite number > 0",
            ParamTransform::Logit => "a number in (0, 1)",
            ParamTransform::PseudoLogit => "a number in (-1, 1)",
            ParamTransform::Logit2 => "a number in (-2, 2)",
            ParamTransform::LogAbs => "a finite non-zero number",
            ParamTransform::LogitHalf => "a number in (0, 1/2)",
        }
    }

    /// docs/methods.md §5.3: `u = g^{-1}(theta)`; `None` when theta is outside the open domain.
    pub(crate) fn to_u(self, theta: f64) -> Option<f64> {
        if !theta.is_finite() {
            return None;
        }
        let u = match self {
            ParamTransform::Identity => theta,
            ParamTransform::Log if theta > 0.0 => elementary::log(theta),
            ParamTransform::Logit if theta > 0.0 && theta < 1.0 => {
                elementary::log(theta / (1.0 - theta))
            }
            ParamTransform::PseudoLogit if theta.abs() < 1.0 => 2.0 * elementary::atanh(theta),
            ParamTransform::Logit2 if theta.abs() < 2.0 => {
                elementary::log((theta + 2.0) / (2.0 - theta))
            }
            ParamTransform::LogAbs if theta != 0.0 => elementary::log(theta.abs()),
            ParamTransform::LogitHalf if theta > 0.0 && theta < 0.5 => {
                elementary::log(theta / (0.5 - theta))
            }
            _ => return None,
        };
        u.is_finite().then_some(u)
    }

    /// `theta` moved just inside the domain when it lies exactly on its closed edge (an
    /// estimate whose `u` ran off to +-inf rounds onto it: a variance or drift of 0, a phi of
    /// 0 or 1); other values unchanged. See `Parametrisation::to_u_restart` (`crate::fit::transform`).
    pub(crate) fn inside(self, theta: f64) -> f64 {
        let e = RESTART_EDGE;
        match self {
            ParamTransform::Log | ParamTransform::LogAbs if theta == 0.0 => f64::MIN_POSITIVE,
            ParamTransform::Logit if theta == 0.0 => e,
            ParamTransform::Logit if theta == 1.0 => 1.0 - e,
            ParamTransform::PseudoLogit if theta.abs() == 1.0 => theta * (1.0 - e),
            ParamTransform::Logit2 if theta.abs() == 2.0 => theta * (1.0 - e),
            ParamTransform::LogitHalf if theta == 0.0 => 0.5 * e,
            ParamTransform::LogitHalf if theta == 0.5 => 0.5 * (1.0 - e),
            _ => theta,
        }
    }

    /// docs/methods.md §5.3: `theta = g(u)`.
    pub(crate) fn to_theta(self, u: f64) -> f64 {
        match self {
            ParamTransform::Identity => u,
            ParamTransform::Log | ParamTransform::LogAbs => elementary::exp(u),
            ParamTransform::Logit => logistic(u),
            // 2 logistic(u) - 1 = tanh(u / 2), without the cancellation near u = 0
            ParamTransform::PseudoLogit => elementary::tanh(0.5 * u),
            ParamTransform::Logit2 => 2.0 * elementary::tanh(0.5 * u),
            ParamTransform::LogitHalf => 0.5 * logistic(u),
        }
    }

    /// `d theta / d u` at `u`.
    pub(crate) fn dtheta_du(self, u: f64) -> f64 {
        let s = || logistic(u) * logistic(-u);
        match self {
            ParamTransform::Identity => 1.0,
            ParamTransform::Log | ParamTransform::LogAbs => elementary::exp(u),
            ParamTransform::Logit => s(),
            ParamTransform::PseudoLogit => 2.0 * s(),
            ParamTransform::Logit2 => 4.0 * s(),
            ParamTransform::LogitHalf => 0.5 * s(),
        }
    }
}

/// Relative distance from the edge of its domain at which an estimate on the edge restarts
/// (`Parametrisation::to_u_restart` (`crate::fit::transform`)): a phi of 0 restarts at 1e-9, of 1 at 1 - 1e-9.
pub(crate) const RESTART_EDGE: f64 = 1e-9;

/// Which table of docs/methods.md §5.3 to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TransformPreset {
    /// model.type "imu" (the package default since 2020, §5.7): AR1/GM `phi` in (0, 1).
    #[default]
    Imu,
    /// model.type "ssm": AR1 `phi` in (-1, 1); ARMA coefficients of order > 1 in (-2, 2).
    Ssm,
}

impl TransformPreset {
    /// The transform of a coefficient in (-1, 1) of an AR1 or MA1 under this preset
    /// (docs/methods.md §5.3): logit on (0, 1) for the IMU preset, pseudo-logit for SSM.
    pub(crate) fn unit_coefficient(self) -> ParamTransform {
        match self {
            TransformPreset::Imu => ParamTransform::Logit,
            TransformPreset::Ssm => ParamTransform::PseudoLogit,
        }
    }
}

/// What a correlated process's first parameter is in the ordered chain of docs/methods.md §5.3
/// (`crate::fit::transform`'s module doc): the chain works on `c = 1 - phi`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum ChainSlot {
    /// The AR1 `phi` itself.
    Phi,
    /// The GM `beta` at this rate (Hz): `phi = exp(-beta / freq)`.
    Beta(f64),
}

impl ChainSlot {
    /// `1 - phi` of a slot holding `v` (exact for GM: `-expm1(-beta / freq)`).
    pub(crate) fn complement(self, v: f64) -> f64 {
        match self {
            ChainSlot::Phi => 1.0 - v,
            ChainSlot::Beta(freq) => -elementary::expm1(-v / freq),
        }
    }

    /// The slot's value at `c = 1 - phi`, and its derivative in `c`.
    pub(crate) fn value(self, c: f64) -> (f64, f64) {
        match self {
            ChainSlot::Phi => (1.0 - c, -1.0),
            ChainSlot::Beta(freq) => (-freq * elementary::log1p(-c), freq / (1.0 - c)),
        }
    }

    /// `phi` of a slot holding `v`.
    pub(crate) fn phi(self, v: f64) -> f64 {
        match self {
            ChainSlot::Phi => v,
            ChainSlot::Beta(freq) => elementary::exp(-v / freq),
        }
    }

    /// The lower end of `phi` under `preset`: a GM's `phi` lies in (0, 1) whatever the preset,
    /// an AR1's follows it.
    pub(crate) fn lower(self, preset: TransformPreset) -> f64 {
        match (self, preset) {
            (ChainSlot::Phi, TransformPreset::Ssm) => -1.0,
            _ => 0.0,
        }
    }

    /// The domain of the slot's value in words, for a chain whose `1 - phi` spans `width`.
    pub(crate) fn domain(self, width: f64) -> &'static str {
        match self {
            ChainSlot::Phi if width > 1.0 => "phi in (-1, 1)",
            ChainSlot::Phi => "phi in (0, 1)",
            ChainSlot::Beta(_) => "beta > 0 with exp(-beta / freq) not rounding to 0 or 1",
        }
    }

    /// Sort key of a start before the chain: `phi` decreasing is `beta` increasing.
    pub(crate) fn order_key(self, v: f64) -> f64 {
        match self {
            ChainSlot::Phi => v,
            ChainSlot::Beta(_) => -v,
        }
    }
}
