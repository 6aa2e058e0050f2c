//! Kalibr `imu.yaml` (docs/methods.md §14.4), and the writer OpenVINS's
//! `kalibr_imu_chain.yaml` shares ([`super::openvins`]).

use super::{check_rate, hash_comments, key, real, sci, topic, value, yaml_line, Field, Key};
use super::{ExportError, ExportFormat, NavNoise, Stack};
use std::fmt::Write as _;

/// Kalibr `imu.yaml`.
pub(super) struct Kalibr;

impl Stack for Kalibr {
    fn name(&self) -> &'static str {
        "kalibr"
    }
    fn file_name(&self) -> &'static str {
        "imu.yaml"
    }
    fn render(&self, noise: &NavNoise) -> Result<String, ExportError> {
        kalibr_like(ExportFormat::KALIBR, noise)
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

/// The Kalibr keys, for Kalibr itself or under OpenVINS's `imu0:`.
pub(super) fn kalibr_like(format: ExportFormat, noise: &NavNoise) -> Result<String, ExportError> {
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
    let openvins = format == ExportFormat::OPENVINS;
    let indent = if openvins {
        out.push_str("%YAML:1.0\n");
        own.push(
            "OpenVINS kalibr_imu_chain.yaml; IMU intrinsics (Tw, Ta, R_IMUtoGYRO, \
             R_IMUtoACC, Tg) are not estimated here: OpenVINS's defaults (identity, Tg zero) \
             apply"
                .to_string(),
        );
        "  "
    } else {
        own.push("Kalibr imu.yaml".to_string());
        ""
    };
    hash_comments(&mut out, noise, &own);
    if openvins {
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
    if openvins {
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
    if openvins {
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
