//! VINS-Fusion config (IMU block) (docs/methods.md §14.4).

use super::{check_rate, hash_comments, key, real, sci, topic, value, yaml_line, Field};
use super::{ExportError, ExportFormat, NavNoise, Stack};
use crate::units::STANDARD_GRAVITY;

/// VINS-Fusion config (IMU block).
pub(super) struct Vins;

impl Stack for Vins {
    fn name(&self) -> &'static str {
        "vins"
    }
    fn file_name(&self) -> &'static str {
        "vins_imu_config.yaml"
    }
    fn render(&self, noise: &NavNoise) -> Result<String, ExportError> {
        vins(noise)
    }
}

fn vins(noise: &NavNoise) -> Result<String, ExportError> {
    let format = ExportFormat::VINS;
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
