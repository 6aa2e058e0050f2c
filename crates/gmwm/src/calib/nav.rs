//! From the per-axis read-off to the one set of values a navigation filter takes (docs/methods.md
//! §14.4): which axis speaks for a sensor triad, and how conservative the values are.

use super::export::{NavNoise, SensorNoise};
use super::horizon::HorizonBound;
use super::pipeline::{AxisCalibration, CalibrationReport, Estimate, EstimateStatus};
use crate::error::ParamError;
use crate::units::{SignalKind, SignalUnit};
use serde::Serialize;
use std::str::FromStr;

/// Which axis (or combination) speaks for a sensor triad.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum AxisPolicy {
    /// The largest value over the axes, per key (default: a filter tuned to the worst axis
    /// never trusts any axis more than it deserves).
    #[default]
    Worst,
    /// The root mean square over the axes (the density of the mean variance).
    Mean,
    /// One set per axis letter (x, y, z): gyroscope and accelerometer of the same axis.
    PerAxis,
}

crate::names::named_values!(AxisPolicy, "axis policy", {
    Worst => "worst",
    Mean => "mean",
    PerAxis => "per-axis",
}, derive(Display));

impl FromStr for AxisPolicy {
    type Err = ParamError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "worst" => Ok(Self::Worst),
            "mean" => Ok(Self::Mean),
            "per-axis" | "per_axis" => Ok(Self::PerAxis),
            _ => Err(ParamError::new(
                "axis policy",
                s,
                "one of worst, mean, per-axis",
            )),
        }
    }
}

/// How conservative the exported values are.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
#[serde(rename_all = "kebab-case", tag = "kind", content = "factor")]
pub enum Adjustment {
    /// The estimates (default).
    #[default]
    Estimate,
    /// The upper ends of the intervals (the estimate where an interval is missing, said in a
    /// comment): cruder than [`Adjustment::Horizon`], it widens by the estimation error, not
    /// by what the model has beyond white noise and a random walk.
    Conservative,
    /// The estimates multiplied by a factor (the folklore of VIO tuning; cruder than
    /// [`Adjustment::Horizon`], which computes the factors).
    Inflate(f64),
    /// The white-noise + random-walk pair bounding each axis' model up to this horizon, s
    /// ([`AxisCalibration::horizon_bound`]): its Allan variance and integrated-error variance
    /// are at least the model's up to the horizon, with the least inflation.
    Horizon(f64),
}

impl Adjustment {
    /// Checks an inflation factor: finite and at least 1.
    ///
    /// # Errors
    /// [`ParamError`] for a factor that is not finite or below 1.
    pub fn inflate(factor: f64) -> Result<Self, ParamError> {
        if factor.is_finite() && factor >= 1.0 {
            Ok(Self::Inflate(factor))
        } else {
            Err(ParamError::new(
                "inflate",
                factor,
                "a factor >= 1 (2 doubles every noise density and random walk)",
            ))
        }
    }

    /// Checks a horizon: finite and positive, in seconds (whether it spans a sample is
    /// checked against the rate by [`AxisCalibration::horizon_bound`]).
    ///
    /// # Errors
    /// [`ParamError`] for a horizon that is not finite and positive.
    pub fn horizon(seconds: f64) -> Result<Self, ParamError> {
        if seconds.is_finite() && seconds > 0.0 {
            Ok(Self::Horizon(seconds))
        } else {
            Err(ParamError::new(
                "horizon",
                seconds,
                "a mission length in seconds > 0 (600 for ten minutes)",
            ))
        }
    }

    fn apply(self, e: &Estimate, missing: &mut Vec<String>, key: &str) -> f64 {
        match self {
            // the horizon's values are the axis' bound, taken before this is reached
            Self::Estimate | Self::Horizon(_) => e.value,
            Self::Inflate(k) => k * e.value,
            Self::Conservative => e.ci_high.unwrap_or_else(|| {
                missing.push(key.to_string());
                e.value
            }),
        }
    }
}

/// One exported set with the axes it stands for (`label` empty, or `x`/`y`/`z` per axis).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NavSet {
    /// Axis label of a per-axis set, empty otherwise.
    pub label: String,
    /// The values and their comments.
    pub noise: NavNoise,
}

impl CalibrationReport {
    /// The navigation-filter values under `policy` and `adjustment` (docs/methods.md §14.4): the
    /// noise density from each axis's white-noise read-off, the random walk from its random-walk
    /// read-off, the Gauss–Markov keys from its dominant correlated term. One set, or one per
    /// axis letter with [`AxisPolicy::PerAxis`].
    pub fn nav_sets(
        &self,
        policy: AxisPolicy,
        adjustment: Adjustment,
        rostopic: Option<&str>,
    ) -> Vec<NavSet> {
        let groups: Vec<(String, Vec<&AxisCalibration>)> = match policy {
            AxisPolicy::PerAxis => {
                let mut letters: Vec<String> = Vec::new();
                for a in &self.axes {
                    let l = a.axis.to_ascii_lowercase();
                    if !letters.contains(&l) {
                        letters.push(l);
                    }
                }
                letters
                    .into_iter()
                    .map(|l| {
                        let axes = self
                            .axes
                            .iter()
                            .filter(|a| a.axis.eq_ignore_ascii_case(&l))
                            .collect();
                        (l, axes)
                    })
                    .collect()
            }
            _ => vec![(String::new(), self.axes.iter().collect())],
        };
        groups
            .into_iter()
            .map(|(label, axes)| {
                let mut comments = vec![format!(
                    "written by gmwm calibrate from {} ({} samples at {} Hz, {:.0} s); continuous-time SI values",
                    self.name.as_deref().unwrap_or("a recording"),
                    self.samples,
                    self.freq_hz,
                    self.duration_s
                )];
                let mut missing = Vec::new();
                let gyroscope = triad(
                    &axes,
                    SignalKind::Gyroscope,
                    policy,
                    adjustment,
                    &mut comments,
                    &mut missing,
                );
                let accelerometer = triad(
                    &axes,
                    SignalKind::Accelerometer,
                    policy,
                    adjustment,
                    &mut comments,
                    &mut missing,
                );
                comments.push(match adjustment {
                    Adjustment::Estimate => "values: the GMWM estimates".to_string(),
                    Adjustment::Conservative => format!(
                        "values: upper ends of the {:.0}% intervals (--conservative)",
                        100.0 * (1.0 - self.alpha)
                    ),
                    Adjustment::Inflate(k) => format!(
                        "values: noise densities and random walks are the estimates x {k} (--inflate {k})"
                    ),
                    Adjustment::Horizon(t) => format!(
                        "values: per axis the white noise + random walk with the least inflation whose Allan variance (1/f to {t} s) and integrated-error variance (angle or velocity, up to {t} s from a known bias) are at least the fitted model's (--horizon {t})"
                    ),
                });
                if !missing.is_empty() {
                    missing.sort();
                    missing.dedup();
                    comments.push(format!(
                        "no interval for {}: the estimate is written instead of an upper bound",
                        missing.join(", ")
                    ));
                }
                NavSet {
                    label,
                    noise: NavNoise {
                        update_rate_hz: self.freq_hz,
                        rostopic: rostopic.map(str::to_string),
                        gyroscope,
                        accelerometer,
                        comments,
                    },
                }
            })
            .collect()
    }
}

/// One axis' horizon pair in words: its inflation over the estimates and its margin at `T`.
fn horizon_comment(column: &str, b: &HorizonBound) -> String {
    let times = |f: Option<f64>| f.map_or("(no estimate)".to_string(), |f| format!("x {f:.3}"));
    format!(
        "{column}: horizon bound {} s: noise density {}, random walk {} over the estimates; integrated-error variance at {} s {:.2}x the model's; touches {}",
        b.horizon_s,
        times(b.noise_inflation),
        times(b.random_walk_inflation),
        b.horizon_s,
        b.excess_at_horizon,
        b.binding
    )
}

/// Combines the axes of one kind into one [`SensorNoise`].
fn triad(
    axes: &[&AxisCalibration],
    kind: SignalKind,
    policy: AxisPolicy,
    adjustment: Adjustment,
    comments: &mut Vec<String>,
    missing: &mut Vec<String>,
) -> SensorNoise {
    let of_kind: Vec<&AxisCalibration> = axes
        .iter()
        .copied()
        .filter(|a| a.kind == Some(kind) && a.unit == SignalUnit::si(kind).symbol())
        .collect();
    let name = match kind {
        SignalKind::Gyroscope => "gyroscope",
        SignalKind::Accelerometer => "accelerometer",
    };
    if of_kind.is_empty() {
        return SensorNoise::default();
    }
    // the horizon's pair per axis (computed by the calibration, else here)
    let bounds: Vec<Option<HorizonBound>> = of_kind
        .iter()
        .map(|a| match adjustment {
            Adjustment::Horizon(t) => {
                let bound = match &a.horizon {
                    Some(b) if b.horizon_s == t => Ok(b.clone()),
                    _ => a.horizon_bound(t),
                };
                match bound {
                    Ok(b) => {
                        comments.push(horizon_comment(&a.column, &b));
                        Some(b)
                    }
                    Err(e) => {
                        comments.push(format!(
                            "{}: no horizon bound ({e}); its estimates are written",
                            a.column
                        ));
                        None
                    }
                }
            }
            _ => None,
        })
        .collect();
    let mut pick = |key: &str,
                    get: &dyn Fn(&AxisCalibration) -> Option<&Estimate>,
                    bounded: &dyn Fn(&HorizonBound) -> f64| {
        let values: Vec<(&str, f64, &str)> = of_kind
            .iter()
            .zip(&bounds)
            .filter_map(|(a, bound)| match bound {
                Some(b) => Some((a.column.as_str(), bounded(b), "the horizon bound")),
                None => get(a).map(|e| {
                    (
                        a.column.as_str(),
                        adjustment.apply(e, missing, &format!("{name}_{key}")),
                        e.source.as_str(),
                    )
                }),
            })
            .collect();
        if values.is_empty() {
            return None;
        }
        match policy {
            AxisPolicy::Mean => {
                let ms = values.iter().map(|v| v.1 * v.1).sum::<f64>() / values.len() as f64;
                let cols: Vec<&str> = values.iter().map(|v| v.0).collect();
                comments.push(format!(
                    "{name}_{key}: root mean square over {} ({})",
                    cols.join(", "),
                    values[0].2
                ));
                Some(ms.sqrt())
            }
            _ => {
                let worst = values.iter().max_by(|a, b| a.1.total_cmp(&b.1))?;
                comments.push(format!(
                    "{name}_{key}: {} ({}){}",
                    worst.0,
                    worst.2,
                    if values.len() > 1 {
                        ", the largest of the axes"
                    } else {
                        ""
                    }
                ));
                Some(worst.1)
            }
        }
    };
    let noise_density = pick("noise_density", &|a| a.noise_density.as_ref(), &|b| {
        b.noise_density
    });
    let random_walk = pick("random_walk", &|a| a.random_walk.as_ref(), &|b| {
        b.random_walk
    });
    // the Gauss–Markov bias (correlation time, sigma, driving density) comes from one axis:
    // the one with the largest bias sigma, all three from its bias term
    let gm = of_kind
        .iter()
        .filter_map(|a| a.gauss_markov_bias.as_ref().map(|g| (a, g)))
        .max_by(|a, b| a.1.sigma.value.total_cmp(&b.1.sigma.value));
    let (bias_correlation_time_s, bias_sigma, bias_driving_density) = match gm {
        Some((a, g)) => {
            comments.push(format!(
                "{name} Gauss-Markov bias: {} (its slowest correlated term: T = {:.4e} s, sigma = {:.4e} {}){}",
                a.column,
                g.correlation_time.value,
                g.sigma.value,
                g.sigma.unit,
                if g.correlation_time.status == EstimateStatus::Undetermined {
                    "; T is not determined at this recording's length (gmwm plan): the random walk exported is the effective one, which counts this term, so a filter that also carries it counts it twice, on the safe side (docs/methods.md §20)"
                } else {
                    ""
                }
            ));
            let pick = |e: &Estimate| match adjustment {
                Adjustment::Conservative => e.ci_high.unwrap_or(e.value),
                _ => e.value,
            };
            (
                Some(g.correlation_time.value),
                Some(pick(&g.sigma)),
                Some(pick(&g.driving_density)),
            )
        }
        None => (None, None, None),
    };
    SensorNoise {
        noise_density,
        random_walk,
        bias_correlation_time_s,
        bias_sigma,
        bias_driving_density,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_policy_from_str() {
        assert_eq!(
            "Per-Axis".parse::<AxisPolicy>().unwrap(),
            AxisPolicy::PerAxis
        );
        assert!("best".parse::<AxisPolicy>().is_err());
        assert!(Adjustment::inflate(0.5).is_err());
        assert!(Adjustment::inflate(f64::NAN).is_err());
        assert_eq!(Adjustment::inflate(2.0).unwrap(), Adjustment::Inflate(2.0));
    }
}
