//! PX4 SITL / Gazebo IMU plugin SDF fragment (docs/methods.md §14.4).

use super::{check_rate, key, real, sci, topic, value, Field};
use super::{ExportError, ExportFormat, NavNoise, Stack};
use std::fmt::Write as _;

/// PX4 SITL / Gazebo IMU plugin SDF fragment.
pub(super) struct Px4;

impl Stack for Px4 {
    fn name(&self) -> &'static str {
        "px4"
    }
    fn file_name(&self) -> &'static str {
        "gazebo_imu_plugin.sdf"
    }
    fn render(&self, noise: &NavNoise) -> Result<String, ExportError> {
        px4(noise)
    }
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
    let format = ExportFormat::PX4;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn xml_comments_never_hold_a_double_dash() {
        let mut s = String::new();
        xml_comment(&mut s, "", "a --- b --");
        assert!(!s[4..s.len() - 4].contains("--"), "{s}");
    }
}
