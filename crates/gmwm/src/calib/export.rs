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
//! density (docs/methods.md §14.2) when a GM bias is exported; [`SensorNoise::bias_sigma`] is
//! written as the turn-on sigma, and the stationary sd implied by the other two keys is stated in a
//! comment so the two can be compared.

use crate::error::ParamError;
use crate::units::STANDARD_GRAVITY;
use serde::Serialize;
use std::fmt;
use std::fmt::Write as _;
use std::str::FromStr;
use thiserror::Error;

/// Continuous-time SI noise of one sensor triad (docs/methods.md §14.2, §14.4).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct SensorNoise {
    /// White-noise density N: rad/s/√Hz or m/s²/√Hz.
    pub noise_density: Option<f64>,
    /// Random-walk density K (or a GM driving density): rad/s²/√Hz or m/s³/√Hz.
    pub random_walk: Option<f64>,
    /// Gauss–Markov bias correlation time, s.
    pub bias_correlation_time_s: Option<f64>,
    /// Gauss–Markov bias standard deviation: rad/s or m/s².
    pub bias_sigma: Option<f64>,
    /// Density of the noise driving the Gauss–Markov bias, `sqrt(2 sigma^2 / T)` (rad/s²/√Hz
    /// or m/s³/√Hz): the random walk of a bias that is a Gauss–Markov process (PX4).
    pub bias_driving_density: Option<f64>,
}

/// What a navigation filter needs, with provenance (docs/methods.md §14.4).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NavNoise {
    /// IMU rate, Hz.
    pub update_rate_hz: f64,
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

/// A navigation stack's noise file (docs/methods.md §14.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ExportFormat {
    /// Kalibr `imu.yaml`.
    Kalibr,
    /// OpenVINS `kalibr_imu_chain.yaml`.
    OpenVins,
    /// VINS-Fusion config (IMU block).
    Vins,
    /// ORB-SLAM3 settings (IMU block).
    OrbSlam3,
    /// PX4 SITL / Gazebo IMU plugin SDF fragment.
    Px4,
}

impl ExportFormat {
    /// Every format, in declaration order.
    pub const ALL: [ExportFormat; 5] = [
        ExportFormat::Kalibr,
        ExportFormat::OpenVins,
        ExportFormat::Vins,
        ExportFormat::OrbSlam3,
        ExportFormat::Px4,
    ];

    /// The CLI name: `"kalibr"`, `"openvins"`, `"vins"`, `"orbslam3"`, `"px4"`.
    pub fn name(self) -> &'static str {
        match self {
            ExportFormat::Kalibr => "kalibr",
            ExportFormat::OpenVins => "openvins",
            ExportFormat::Vins => "vins",
            ExportFormat::OrbSlam3 => "orbslam3",
            ExportFormat::Px4 => "px4",
        }
    }

    /// The conventional file name of the format (module table).
    pub fn default_file_name(self) -> &'static str {
        match self {
            ExportFormat::Kalibr => "imu.yaml",
            ExportFormat::OpenVins => "kalibr_imu_chain.yaml",
            ExportFormat::Vins => "vins_imu_config.yaml",
            ExportFormat::OrbSlam3 => "orbslam3_imu.yaml",
            ExportFormat::Px4 => "gazebo_imu_plugin.sdf",
        }
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
                let names: Vec<&str> = ExportFormat::ALL.iter().map(|f| f.name()).collect();
                ParamError::new("format", s, format!("one of {}", names.join(", ")))
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
fn sci(v: f64) -> String {
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
fn real(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{v:.1}")
    } else {
        format!("{v}")
    }
}

/// Which value of [`SensorNoise`] a key takes.
#[derive(Clone, Copy)]
enum Field {
    NoiseDensity,
    RandomWalk,
    BiasDrivingDensity,
    CorrelationTime,
    BiasSigma,
}

/// The keys of one format for one sensor, in file order, with their units.
struct Key {
    name: &'static str,
    field: Field,
    unit: &'static str,
    what: &'static str,
}

/// The checked value of a key.
fn value(format: ExportFormat, s: &SensorNoise, key: &Key) -> Result<f64, ExportError> {
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

const fn key(name: &'static str, field: Field, unit: &'static str, what: &'static str) -> Key {
    Key {
        name,
        field,
        unit,
        what,
    }
}

const KALIBR_ACCEL: [Key; 2] = [
    key(
        "accelerometer_noise_density",
        Field::NoiseDensity,
        "m/s^2/sqrt(Hz)",
        "white noise, continuous time",
    ),
    key(
        "accelerometer_random_walk",
        Field::RandomWalk,
        "m/s^3/sqrt(Hz)",
        "bias random walk (diffusion), continuous time",
    ),
];
const KALIBR_GYRO: [Key; 2] = [
    key(
        "gyroscope_noise_density",
        Field::NoiseDensity,
        "rad/s/sqrt(Hz)",
        "white noise, continuous time",
    ),
    key(
        "gyroscope_random_walk",
        Field::RandomWalk,
        "rad/s^2/sqrt(Hz)",
        "bias random walk (diffusion), continuous time",
    ),
];

/// A `# ` comment block of the caller's lines, then the format's own lines.
fn hash_comments(out: &mut String, noise: &NavNoise, own: &[String]) {
    for line in noise.comments.iter().chain(own).flat_map(|c| c.lines()) {
        let _ = writeln!(out, "# {line}");
    }
}

/// One `key: value  # [unit] what` line, with an indent.
fn yaml_line(out: &mut String, indent: &str, key: &str, value: &str, unit: &str, what: &str) {
    let head = format!("{indent}{key}: {value}");
    let _ = match (unit.is_empty(), what.is_empty()) {
        (true, true) => writeln!(out, "{head}"),
        (true, false) => writeln!(out, "{head:<48} # {what}"),
        _ => writeln!(out, "{head:<48} # [{unit}] {what}"),
    };
}

/// The topic, or a marked placeholder.
fn topic(noise: &NavNoise, placeholder: &'static str) -> (String, Option<String>) {
    match &noise.rostopic {
        Some(t) => (t.clone(), None),
        None => (
            placeholder.to_string(),
            Some(format!(
                "the IMU topic was not given: {placeholder} is a placeholder"
            )),
        ),
    }
}

fn check_rate(format: ExportFormat, noise: &NavNoise) -> Result<f64, ExportError> {
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

fn kalibr_like(format: ExportFormat, noise: &NavNoise) -> Result<String, ExportError> {
    let rate = check_rate(format, noise)?;
    let mut lines = Vec::new();
    for (sensor, keys) in [
        (&noise.accelerometer, &KALIBR_ACCEL),
        (&noise.gyroscope, &KALIBR_GYRO),
    ] {
        for k in keys {
            lines.push((k, value(format, sensor, k)?));
        }
    }
    let (rostopic, placeholder) = topic(noise, "/imu0");
    let mut own = vec![
        "IMU noise, continuous-time SI densities; the filter discretises them \
         at update_rate"
            .to_string(),
    ];
    own.extend(placeholder);
    let mut out = String::new();
    let indent = match format {
        ExportFormat::OpenVins => {
            out.push_str("%YAML:1.0\n");
            own.push(
                "OpenVINS kalibr_imu_chain.yaml; IMU intrinsics (Tw, Ta, R_IMUtoGYRO, \
                 R_IMUtoACC, Tg) are not estimated here: OpenVINS's defaults (identity, Tg zero) \
                 apply"
                    .to_string(),
            );
            "  "
        }
        _ => {
            own.push("Kalibr imu.yaml".to_string());
            ""
        }
    };
    hash_comments(&mut out, noise, &own);
    if format == ExportFormat::OpenVins {
        out.push_str("imu0:\n  T_i_b:\n");
        for row in 0..4 {
            let cells: Vec<&str> = (0..4)
                .map(|c| if c == row { "1.0" } else { "0.0" })
                .collect();
            let _ = writeln!(out, "    - [{}]", cells.join(", "));
        }
    }
    for (k, v) in lines {
        yaml_line(&mut out, indent, k.name, &sci(v), k.unit, k.what);
    }
    yaml_line(&mut out, indent, "rostopic", &rostopic, "", "");
    if format == ExportFormat::OpenVins {
        yaml_line(
            &mut out,
            indent,
            "time_offset",
            "0.0",
            "s",
            "IMU-camera time offset",
        );
    }
    yaml_line(
        &mut out,
        indent,
        "update_rate",
        &real(rate),
        "Hz",
        "IMU rate, used to discretise the densities",
    );
    if format == ExportFormat::OpenVins {
        yaml_line(
            &mut out,
            indent,
            "model",
            "calibrated",
            "",
            "no IMU intrinsics",
        );
    }
    Ok(out)
}

fn vins(noise: &NavNoise) -> Result<String, ExportError> {
    let format = ExportFormat::Vins;
    check_rate(format, noise)?;
    let keys = [
        (
            &noise.accelerometer,
            key(
                "acc_n",
                Field::NoiseDensity,
                "m/s^2/sqrt(Hz)",
                "accelerometer white-noise density",
            ),
        ),
        (
            &noise.gyroscope,
            key(
                "gyr_n",
                Field::NoiseDensity,
                "rad/s/sqrt(Hz)",
                "gyroscope white-noise density",
            ),
        ),
        (
            &noise.accelerometer,
            key(
                "acc_w",
                Field::RandomWalk,
                "m/s^3/sqrt(Hz)",
                "accelerometer bias random-walk density",
            ),
        ),
        (
            &noise.gyroscope,
            key(
                "gyr_w",
                Field::RandomWalk,
                "rad/s^2/sqrt(Hz)",
                "gyroscope bias random-walk density",
            ),
        ),
    ];
    let mut values = Vec::new();
    for (sensor, k) in &keys {
        values.push(value(format, sensor, k)?);
    }
    let (imu_topic, placeholder) = topic(noise, "/imu0");
    let mut own = vec![
        "VINS-Fusion IMU block: paste into the estimator config (cv::FileStorage YAML)".to_string(),
        format!(
            "acc_n, gyr_n, acc_w, gyr_w: continuous-time densities, the values \
             VINS users take from Kalibr; VINS's own comments call them standard deviations. \
             IMU rate {} Hz",
            real(noise.update_rate_hz)
        ),
        "g_norm: standard gravity; replace it with the local gravity magnitude if known"
            .to_string(),
    ];
    own.extend(placeholder);
    let mut out = String::from("%YAML:1.0\n");
    hash_comments(&mut out, noise, &own);
    yaml_line(&mut out, "", "imu", "1", "", "use the IMU");
    yaml_line(
        &mut out,
        "",
        "imu_topic",
        &format!("\"{imu_topic}\""),
        "",
        "",
    );
    for ((_, k), v) in keys.iter().zip(values) {
        yaml_line(&mut out, "", k.name, &sci(v), k.unit, k.what);
    }
    yaml_line(
        &mut out,
        "",
        "g_norm",
        &sci(STANDARD_GRAVITY),
        "m/s^2",
        "gravity magnitude",
    );
    Ok(out)
}

fn orbslam3(noise: &NavNoise) -> Result<String, ExportError> {
    let format = ExportFormat::OrbSlam3;
    let rate = check_rate(format, noise)?;
    let keys = [
        (
            &noise.gyroscope,
            key(
                "IMU.NoiseGyro",
                Field::NoiseDensity,
                "rad/s/sqrt(Hz)",
                "gyroscope white-noise density",
            ),
        ),
        (
            &noise.accelerometer,
            key(
                "IMU.NoiseAcc",
                Field::NoiseDensity,
                "m/s^2/sqrt(Hz)",
                "accelerometer white-noise density",
            ),
        ),
        (
            &noise.gyroscope,
            key(
                "IMU.GyroWalk",
                Field::RandomWalk,
                "rad/s^2/sqrt(Hz)",
                "gyroscope bias random-walk density",
            ),
        ),
        (
            &noise.accelerometer,
            key(
                "IMU.AccWalk",
                Field::RandomWalk,
                "m/s^3/sqrt(Hz)",
                "accelerometer bias random-walk density",
            ),
        ),
    ];
    let mut values = Vec::new();
    for (sensor, k) in &keys {
        values.push(value(format, sensor, k)?);
    }
    let own = vec![
        "ORB-SLAM3 IMU block: paste into the settings file; continuous-time densities \
         (ORB-SLAM3 multiplies the noise by sqrt(IMU.Frequency) and divides the walk by it)"
            .to_string(),
        "IMU.Frequency is a real, as settings with File.version \"1.0\" require; pre-1.0 \
         settings read it as an integer"
            .to_string(),
    ];
    let mut out = String::from("%YAML:1.0\n");
    hash_comments(&mut out, noise, &own);
    for ((_, k), v) in keys.iter().zip(values) {
        yaml_line(&mut out, "", k.name, &sci(v), k.unit, k.what);
    }
    yaml_line(&mut out, "", "IMU.Frequency", &real(rate), "Hz", "IMU rate");
    Ok(out)
}

/// An XML comment: `--` may not occur inside one, so it is spaced out.
fn xml_comment(out: &mut String, indent: &str, text: &str) {
    let mut t = text.replace("--", "- -");
    while t.contains("--") {
        t = t.replace("--", "- -");
    }
    if t.ends_with('-') {
        t.push(' ');
    }
    let _ = writeln!(out, "{indent}<!-- {t} -->");
}

/// Escapes text for an XML element.
fn xml_text(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn px4(noise: &NavNoise) -> Result<String, ExportError> {
    let format = ExportFormat::Px4;
    let rate = check_rate(format, noise)?;
    let sensors = [
        (
            "gyroscope",
            &noise.gyroscope,
            [
                key(
                    "gyroscopeNoiseDensity",
                    Field::NoiseDensity,
                    "rad/s/sqrt(Hz)",
                    "white-noise density",
                ),
                key(
                    "gyroscopeRandomWalk",
                    Field::BiasDrivingDensity,
                    "rad/s^2/sqrt(Hz)",
                    "density of the noise driving the GM bias",
                ),
                key(
                    "gyroscopeBiasCorrelationTime",
                    Field::CorrelationTime,
                    "s",
                    "GM bias correlation time",
                ),
                key(
                    "gyroscopeTurnOnBiasSigma",
                    Field::BiasSigma,
                    "rad/s",
                    "sd of the constant turn-on bias; written from the GM bias sd",
                ),
            ],
            "rad/s",
        ),
        (
            "accelerometer",
            &noise.accelerometer,
            [
                key(
                    "accelerometerNoiseDensity",
                    Field::NoiseDensity,
                    "m/s^2/sqrt(Hz)",
                    "white-noise density",
                ),
                key(
                    "accelerometerRandomWalk",
                    Field::BiasDrivingDensity,
                    "m/s^3/sqrt(Hz)",
                    "density of the noise driving the GM bias",
                ),
                key(
                    "accelerometerBiasCorrelationTime",
                    Field::CorrelationTime,
                    "s",
                    "GM bias correlation time",
                ),
                key(
                    "accelerometerTurnOnBiasSigma",
                    Field::BiasSigma,
                    "m/s^2",
                    "sd of the constant turn-on bias; written from the GM bias sd",
                ),
            ],
            "m/s^2",
        ),
    ];
    let mut body = Vec::new();
    let mut implied = Vec::new();
    for (name, sensor, keys, unit) in &sensors {
        let mut vals = Vec::new();
        for k in keys {
            vals.push(value(format, sensor, k)?);
        }
        implied.push(format!(
            "{name}: stationary sd of the plugin's GM bias = RandomWalk x sqrt(T/2) = {} {unit} \
             (compare TurnOnBiasSigma = {})",
            sci(vals[1] * (vals[2] / 2.0).sqrt()),
            sci(vals[3])
        ));
        body.push((keys, vals));
    }
    let (imu_topic, placeholder) = topic(noise, "/imu");
    let mut out = String::new();
    let mut own = vec![
        "PX4 SITL / Gazebo IMU plugin (libgazebo_imu_plugin.so): paste into the model SDF; \
         set linkName to the model's IMU link"
            .to_string(),
        format!(
            "continuous-time SI values, measured at {} Hz; the plugin \
             discretises them at its own step",
            real(rate)
        ),
        "bias: Gauss-Markov b' = -b/T + w, w of density RandomWalk, T = BiasCorrelationTime; \
         TurnOnBiasSigma: sd of a constant bias drawn once per run"
            .to_string(),
    ];
    own.extend(implied);
    own.extend(placeholder);
    for line in noise.comments.iter().chain(&own).flat_map(|c| c.lines()) {
        xml_comment(&mut out, "", line);
    }
    out.push_str("<plugin name=\"gazebo_imu_plugin\" filename=\"libgazebo_imu_plugin.so\">\n");
    out.push_str("  <robotNamespace></robotNamespace>\n");
    out.push_str("  <linkName>imu_link</linkName>\n");
    let _ = writeln!(out, "  <imuTopic>{}</imuTopic>", xml_text(&imu_topic));
    for (keys, vals) in body {
        for (k, v) in keys.iter().zip(vals) {
            xml_comment(&mut out, "  ", &format!("[{}] {}", k.unit, k.what));
            let _ = writeln!(out, "  <{0}>{1}</{0}>", k.name, sci(v));
        }
    }
    out.push_str("</plugin>\n");
    Ok(out)
}

/// docs/methods.md §14.4: renders the noise file of a navigation stack (keys, units and layout in
/// the module doc).
///
/// # Errors
/// [`ExportError::Missing`] naming the key of a value the format needs (all formats need both
/// noise densities and random walks; PX4 also the bias correlation times and sigmas);
/// [`ExportError::Invalid`] for a value or rate that is not a positive finite number.
pub fn render(format: ExportFormat, noise: &NavNoise) -> Result<String, ExportError> {
    match format {
        ExportFormat::Kalibr | ExportFormat::OpenVins => kalibr_like(format, noise),
        ExportFormat::Vins => vins(noise),
        ExportFormat::OrbSlam3 => orbslam3(noise),
        ExportFormat::Px4 => px4(noise),
    }
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

    #[test]
    fn xml_comments_never_hold_a_double_dash() {
        let mut s = String::new();
        xml_comment(&mut s, "", "a --- b --");
        assert!(!s[4..s.len() - 4].contains("--"), "{s}");
    }
}
