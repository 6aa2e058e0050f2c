//! Navigation-stack noise files (METHODS §14.4).

use crate::error::ParamError;
use serde::Serialize;
use std::fmt;
use std::str::FromStr;
use thiserror::Error;

/// Continuous-time SI noise of one sensor triad (METHODS §14.2, §14.4).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct SensorNoise {
    /// White-noise density N (rad/s/√Hz or m/s²/√Hz).
    pub noise_density: Option<f64>,
    /// Random-walk density K (rad/s²/√Hz or m/s³/√Hz).
    pub random_walk: Option<f64>,
    /// Gauss–Markov bias correlation time, s.
    pub bias_correlation_time_s: Option<f64>,
    /// Gauss–Markov bias standard deviation (rad/s or m/s²).
    pub bias_sigma: Option<f64>,
}

/// What a navigation filter needs, with provenance.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NavNoise {
    /// IMU rate, Hz.
    pub update_rate_hz: f64,
    /// ROS topic of the IMU (Kalibr, OpenVINS), if known.
    pub rostopic: Option<String>,
    /// Gyroscope noise.
    pub gyroscope: SensorNoise,
    /// Accelerometer noise.
    pub accelerometer: SensorNoise,
    /// Provenance, axis policy, inflation: rendered as comments.
    pub comments: Vec<String>,
}

/// A navigation stack's noise file (METHODS §14.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ExportFormat {
    /// Kalibr `imu.yaml`.
    Kalibr,
    /// OpenVINS `kalibr_imu_chain.yaml`.
    OpenVins,
    /// VINS-Fusion config.
    Vins,
    /// ORB-SLAM3 settings.
    OrbSlam3,
    /// PX4 / Gazebo IMU plugin SDF fragment.
    Px4,
}

impl ExportFormat {
    /// The conventional file name of the format.
    pub fn default_file_name(self) -> &'static str {
        todo!()
    }
}

impl fmt::Display for ExportFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        todo!("{f:p}")
    }
}

impl FromStr for ExportFormat {
    type Err = ParamError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        todo!("{s}")
    }
}

/// Why a file cannot be rendered.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum ExportError {
    /// A value the format needs is missing.
    #[error("{format} needs {key}, which the noise values do not have")]
    Missing {
        /// The format.
        format: ExportFormat,
        /// The key.
        key: &'static str,
    },
}

/// METHODS §14.4: renders the noise file of a navigation stack.
///
/// # Errors
/// [`ExportError::Missing`] naming the key of a value the format needs.
pub fn render(format: ExportFormat, noise: &NavNoise) -> Result<String, ExportError> {
    todo!("{format:?} {noise:?}")
}
