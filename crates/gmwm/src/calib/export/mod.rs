//! Navigation-stack noise files (docs/methods.md §14.4).
//!
//! [`render`] writes the IMU noise block of five navigation stacks from one [`NavNoise`]
//! (continuous-time SI values). Every key's unit is stated in a comment beside it, and the
//! caller's provenance, axis-policy and inflation lines ([`NavNoise::comments`]) head the file
//! as comments. Numbers are written with 8 significant digits in exponent form with a signed
//! two-digit exponent (`1.0000000e-04`), which YAML 1.1 (Kalibr's PyYAML), OpenCV's
//! FileStorage (OpenVINS, VINS-Fusion, ORB-SLAM3) and SDF all read as floats (YAML 1.1 needs the
//! exponent sign).
//!
//! | format | file | keys (gyroscope; accelerometer alike) |
//! |---|---|---|
//! | Kalibr | `imu.yaml` | `gyroscope_noise_density`, `gyroscope_random_walk`, `rostopic`, `update_rate` |
//! | OpenVINS | `kalibr_imu_chain.yaml` | the Kalibr keys under `imu0:`, with `T_i_b`, `time_offset`, `model: calibrated` |
//! | VINS-Fusion | `vins_imu_config.yaml` | `gyr_n`, `gyr_w`, `acc_n`, `acc_w`, `g_norm`, `imu`, `imu_topic` |
//! | ORB-SLAM3 | `orbslam3_imu.yaml` | `IMU.NoiseGyro`, `IMU.GyroWalk`, `IMU.NoiseAcc`, `IMU.AccWalk`, `IMU.Frequency` |
//! | PX4 / Gazebo | `gazebo_imu_plugin.sdf` | `gyroscopeNoiseDensity`, `gyroscopeRandomWalk`, `gyroscopeBiasCorrelationTime`, `gyroscopeTurnOnBiasSigma` |
//!
//! The PX4/Gazebo IMU plugin models the bias as a first-order Gauss–Markov process driven by
//! white noise of density `*RandomWalk` with correlation time `*BiasCorrelationTime` (its
//! stationary sd is `RandomWalk × sqrt(T / 2)`), plus a constant turn-on bias of sd
//! `*TurnOnBiasSigma` drawn once per run. So for PX4 the random walk should be the GM driving
//! density (docs/methods.md §14.2) when a GM bias is exported; `SensorNoise::bias_sigma` is
//! written as the turn-on sigma, and the stationary sd implied by the other two keys is stated in a
//! comment so the two can be compared.

use crate::error::ParamError;
use serde::Serialize;
use std::fmt;
use std::fmt::Write as _;
use std::str::FromStr;
use thiserror::Error;

mod kalibr;
mod openvins;
mod orbslam3;
mod px4;
mod vins;

/// Continuous-time SI noise of one sensor triad (docs/methods.md §14.2, §14.4).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct SensorNoise {
    /// White-noise density N: rad/s/√Hz or m/s²/√Hz.
    pub noise_density: Option<f64>,
    /// Random-walk density K (or a GM driving density): rad/s²/√Hz or m/s³/√Hz.
    pub random_walk: Option<f64>,
    /// Gauss–Markov bias correlation time, s.
    pub(crate) bias_correlation_time_s: Option<f64>,
    /// Gauss–Markov bias standard deviation: rad/s or m/s².
    pub(crate) bias_sigma: Option<f64>,
    /// Density of the noise driving the Gauss–Markov bias, `sqrt(2 sigma^2 / T)` (rad/s²/√Hz
    /// or m/s³/√Hz): the random walk of a bias that is a Gauss–Markov process (PX4).
    pub(crate) bias_driving_density: Option<f64>,
}

/// What a navigation filter needs, with provenance (docs/methods.md §14.4).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NavNoise {
    /// IMU rate, Hz.
    pub(crate) update_rate_hz: f64,
    /// ROS topic of the IMU (Kalibr, OpenVINS, VINS-Fusion; PX4's `imuTopic`), if known;
    /// a placeholder marked as such is written otherwise.
    pub rostopic: Option<String>,
    /// Gyroscope noise.
    pub gyroscope: SensorNoise,
    /// Accelerometer noise.
    pub accelerometer: SensorNoise,
    /// Provenance, axis policy, inflation: rendered as comments, one per line.
    pub comments: Vec<String>,
}

/// What one navigation stack's noise file is: its name, its conventional file name, and how
/// it is written. One file per stack below this module, each listed once in
/// [`ExportFormat::ALL`].
pub(crate) trait Stack: Sync {
    /// The CLI name: `"kalibr"`, `"openvins"`, ...
    fn name(&self) -> &'static str;
    /// The conventional file name (module table).
    fn file_name(&self) -> &'static str;
    /// The file's text (docs/methods.md §14.4).
    fn render(&self, noise: &NavNoise) -> Result<String, ExportError>;
}

/// A navigation stack's noise file (docs/methods.md §14.4): one of [`ExportFormat::ALL`].
///
/// Serialised as its name; equal when the names are.
#[derive(Clone, Copy)]
pub struct ExportFormat(&'static dyn Stack);

impl ExportFormat {
    /// Kalibr `imu.yaml`.
    pub const KALIBR: ExportFormat = ExportFormat(&kalibr::Kalibr);
    /// OpenVINS `kalibr_imu_chain.yaml`.
    pub const OPENVINS: ExportFormat = ExportFormat(&openvins::OpenVins);
    /// VINS-Fusion config (IMU block).
    pub const VINS: ExportFormat = ExportFormat(&vins::Vins);
    /// ORB-SLAM3 settings (IMU block).
    pub const ORBSLAM3: ExportFormat = ExportFormat(&orbslam3::OrbSlam3);
    /// PX4 SITL / Gazebo IMU plugin SDF fragment.
    pub const PX4: ExportFormat = ExportFormat(&px4::Px4);

    /// Every format: the one list the CLI, the Python package and the docs take their names
    /// from.
    pub const ALL: [ExportFormat; 5] = [
        ExportFormat::KALIBR,
        ExportFormat::OPENVINS,
        ExportFormat::VINS,
        ExportFormat::ORBSLAM3,
        ExportFormat::PX4,
    ];

    /// The CLI name: `"kalibr"`, `"openvins"`, `"vins"`, `"orbslam3"`, `"px4"`.
    pub fn name(self) -> &'static str {
        self.0.name()
    }

    /// The conventional file name of the format (module table).
    pub fn default_file_name(self) -> &'static str {
        self.0.file_name()
    }

    /// The names of every format, joined by `", "` (for help and error texts).
    pub fn names() -> String {
        let names: Vec<&str> = ExportFormat::ALL.iter().map(|f| f.name()).collect();
        names.join(", ")
    }
}

impl PartialEq for ExportFormat {
    fn eq(&self, other: &Self) -> bool {
        self.name() == other.name()
    }
}

impl Eq for ExportFormat {}

impl std::hash::Hash for ExportFormat {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.name().hash(state)
    }
}

impl fmt::Debug for ExportFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "ExportFormat({})", self.name())
    }
}

impl Serialize for ExportFormat {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl fmt::Display for ExportFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ExportFormat {
    type Err = ParamError;

    /// Parses a CLI name, case-insensitively.
    ///
    /// # Errors
    /// [`ParamError`] named `format`, listing the valid names.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        ExportFormat::ALL
            .into_iter()
            .find(|f| f.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| {
                ParamError::new("format", s, format!("one of {}", ExportFormat::names()))
            })
    }
}

/// Why a noise file cannot be rendered.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum ExportError {
    /// A value the format needs is missing.
    #[error("{format} export needs {key}, which the noise values lack{hint}")]
    Missing {
        /// The format.
        format: ExportFormat,
        /// The key of the file that has no value.
        key: &'static str,
        /// Where such a value comes from (may be empty).
        hint: &'static str,
    },
    /// A value is not a positive finite number.
    #[error("{format} export: {key} = {value} is not a positive finite number")]
    Invalid {
        /// The format.
        format: ExportFormat,
        /// The key of the file.
        key: &'static str,
        /// The value given.
        value: f64,
    },
}

/// A number in the files' form: 8 significant digits, signed two-digit exponent (module doc).
pub(super) fn sci(v: f64) -> String {
    let s = format!("{v:.7e}");
    match s.split_once('e') {
        Some((mantissa, exp)) => {
            let (sign, digits) = match exp.strip_prefix('-') {
                Some(d) => ('-', d),
                None => ('+', exp),
            };
            format!("{mantissa}e{sign}{digits:0>2}")
        }
        None => s,
    }
}

/// A rate in Hz as a real with at least one decimal (`200.0`).
pub(super) fn real(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{v:.1}")
    } else {
        format!("{v}")
    }
}

/// Which value of [`SensorNoise`] a key takes.
#[derive(Clone, Copy)]
pub(super) enum Field {
    NoiseDensity,
    RandomWalk,
    BiasDrivingDensity,
    CorrelationTime,
    BiasSigma,
}

/// The keys of one format for one sensor, in file order, with their units.
pub(super) struct Key {
    name: &'static str,
    field: Field,
    unit: &'static str,
    what: &'static str,
}

/// The checked value of a key.
pub(super) fn value(format: ExportFormat, s: &SensorNoise, key: &Key) -> Result<f64, ExportError> {
    let (v, hint) = match key.field {
        Field::NoiseDensity => (s.noise_density, " (from the white-noise term)"),
        Field::RandomWalk => (
            s.random_walk,
            " (from a random-walk term, or the slowest GM's driving density)",
        ),
        Field::BiasDrivingDensity => (
            s.bias_driving_density,
            " (the driving density of a Gauss-Markov bias: the model has none; fit one with --model, e.g. AR1()+WN()+RW())",
        ),
        Field::CorrelationTime => (
            s.bias_correlation_time_s,
            " (from a Gauss-Markov term: the model has none; fit one with --model, e.g. AR1()+WN()+RW())",
        ),
        Field::BiasSigma => (s.bias_sigma, " (from a Gauss-Markov term)"),
    };
    let v = v.ok_or(ExportError::Missing {
        format,
        key: key.name,
        hint,
    })?;
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(ExportError::Invalid {
            format,
            key: key.name,
            value: v,
        })
    }
}

pub(super) const fn key(
    name: &'static str,
    field: Field,
    unit: &'static str,
    what: &'static str,
) -> Key {
    Key {
        name,
        field,
        unit,
        what,
    }
}

/// A `# ` comment block of the caller's lines, then the format's own lines.
pub(super) fn hash_comments(out: &mut String, noise: &NavNoise, own: &[String]) {
    for line in noise.comments.iter().chain(own).flat_map(|c| c.lines()) {
        // YAML allows no control characters but tab, even in a comment
        let _ = writeln!(out, "# {}", crate::imu::printable(line));
    }
}

/// One `key: value  # [unit] what` line, with an indent.
pub(super) fn yaml_line(
    out: &mut String,
    indent: &str,
    key: &str,
    value: &str,
    unit: &str,
    what: &str,
) {
    let head = format!("{indent}{key}: {value}");
    let _ = match (unit.is_empty(), what.is_empty()) {
        (true, true) => writeln!(out, "{head}"),
        (true, false) => writeln!(out, "{head:<48} # {what}"),
        _ => writeln!(out, "{head:<48} # [{unit}] {what}"),
    };
}

/// The topic, or a marked placeholder.
pub(super) fn topic(noise: &NavNoise, placeholder: &'static str) -> (String, Option<String>) {
    match &noise.rostopic {
        Some(t) => (yaml_scalar(t), None),
        None => (
            placeholder.to_string(),
            Some(format!(
                "the IMU topic was not given: {placeholder} is a placeholder"
            )),
        ),
    }
}

/// `text` as a YAML scalar: as is when it is a plain ROS name (letters, digits, `/_-.~`),
/// else double-quoted with `"`, `\\` and control characters escaped (a topic read from a bag
/// may hold anything).
fn yaml_scalar(text: &str) -> String {
    let plain = !text.is_empty()
        && text
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "/_-.~".contains(c))
        && !text.starts_with(['-', '~', '.']);
    if plain {
        return text.to_string();
    }
    let mut out = String::from("\"");
    for c in text.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => out.push_str(&format!("\\u{:04x}", u32::from(c))),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

pub(super) fn check_rate(format: ExportFormat, noise: &NavNoise) -> Result<f64, ExportError> {
    let f = noise.update_rate_hz;
    if f.is_finite() && f > 0.0 {
        Ok(f)
    } else {
        Err(ExportError::Invalid {
            format,
            key: "update_rate",
            value: f,
        })
    }
}

/// docs/methods.md §14.4: renders the noise file of a navigation stack (keys, units and layout in
/// the module doc).
///
/// # Errors
/// [`ExportError::Missing`] naming the key of a value the format needs (all formats need both
/// noise densities and random walks; PX4 also the bias correlation times and sigmas);
/// [`ExportError::Invalid`] for a value or rate that is not a positive finite number.
pub fn render_export(format: ExportFormat, noise: &NavNoise) -> Result<String, ExportError> {
    format.0.render(noise)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sci_writes_a_signed_two_digit_exponent() {
        assert_eq!(sci(1e-4), "1.0000000e-04");
        assert_eq!(sci(200.0), "2.0000000e+02");
        assert_eq!(sci(1.2345678912e-12), "1.2345679e-12");
        assert_eq!(sci(1e100), "1.0000000e+100");
        assert_eq!(real(200.0), "200.0");
        assert_eq!(real(99.5), "99.5");
    }
}
