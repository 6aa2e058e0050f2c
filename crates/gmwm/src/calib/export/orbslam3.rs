//! ORB-SLAM3 settings (IMU block) (docs/methods.md §14.4).

use super::{check_rate, hash_comments, key, real, sci, value, yaml_line, Field};
use super::{ExportError, ExportFormat, NavNoise, Stack};

/// ORB-SLAM3 settings (IMU block).
pub(super) struct OrbSlam3;

impl Stack for OrbSlam3 {
    fn name(&self) -> &'static str {
        "orbslam3"
    }
    fn file_name(&self) -> &'static str {
        "orbslam3_imu.yaml"
    }
    fn render(&self, noise: &NavNoise) -> Result<String, ExportError> {
        orbslam3(noise)
    }
}

fn orbslam3(noise: &NavNoise) -> Result<String, ExportError> {
    let format = ExportFormat::ORBSLAM3;
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
