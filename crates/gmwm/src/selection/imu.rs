//! WIC selection on every axis of an IMU recording (docs/methods.md §8.6 `auto.imu`).

use super::{ModelSelection, SelectionError, Wic};
use crate::imu::{Imu, Sensor};
use rayon::prelude::*;
use serde::Serialize;
use std::fmt;

/// The selection on one axis.
///
/// Wire format: `axis` (tag such as `gyro_x`), `sensor` (`Gyroscope`, `Accelerometer`,
/// `Other`), `label` (axis label, e.g. `X`) and `selection` ([`ModelSelection`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisSelection {
    /// Axis tag, e.g. `gyro_x` (the column name for [`Sensor::Other`]).
    pub axis: String,
    /// Sensor type.
    pub sensor: Sensor,
    /// Axis label, e.g. `X`.
    pub label: String,
    /// The selection.
    pub selection: ModelSelection,
}

/// The selection on every axis of an IMU, in the IMU's axis order (gyroscopes first).
///
/// Wire format: `freq_hz` and `axes` ([`AxisSelection`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImuSelection {
    /// Sampling rate in Hz.
    pub freq_hz: f64,
    /// One selection per axis.
    pub axes: Vec<AxisSelection>,
}

impl fmt::Display for ImuSelection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, a) in self.axes.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            writeln!(f, "{} ({} {})", a.axis, a.sensor, a.label)?;
            writeln!(f, "{}", a.selection)?;
        }
        Ok(())
    }
}

/// docs/methods.md §8.6 `auto.imu`: runs `wic` on every axis of `imu` in parallel (each axis is
/// deterministic given the seed, so the result does not depend on the thread count) and tags
/// each result by sensor and axis.
///
/// Cost: one [`Wic::select`] per axis.
///
/// # Errors
/// [`SelectionError::Axis`] naming the first axis (in axis order) whose selection failed.
pub fn auto_imu(imu: &Imu, wic: &Wic) -> Result<ImuSelection, SelectionError> {
    let freq_hz = imu.freq_hz();
    let axes = imu
        .axes()
        .par_iter()
        .map(|a| {
            let axis = a.tag();
            match wic.select(a.values(), freq_hz) {
                Ok(selection) => Ok(AxisSelection {
                    axis,
                    sensor: a.sensor(),
                    label: a.info.axis.clone(),
                    selection,
                }),
                Err(e) => Err(SelectionError::Axis {
                    axis,
                    source: Box::new(e),
                }),
            }
        })
        .collect::<Vec<_>>()
        .into_iter()
        .collect::<Result<Vec<_>, _>>()?;
    Ok(ImuSelection { freq_hz, axes })
}
