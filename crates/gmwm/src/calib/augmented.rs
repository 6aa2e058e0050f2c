//! `gmwm calibrate --augment`: GMWM+ (docs/methods.md §5.15) of every axis' identified model,
//! from the calibration's own fit, beside the calibration's estimates.
//!
//! The calibration's N, B, K and exports stay GMWM's: on the simulated truths of §5.15 the
//! extra moments change the RMSE by 0.97–1.04 against the efficient two-step GMWM, so GMWM+ is
//! offered as a second reading and, through its J-test, as a check that the model also
//! describes the short-lag autocovariances of the differences (a sensor's own filter shows
//! there first).

use super::pipeline::{CalibError, Calibration, CalibrationReport};
use crate::augmented::{augment_fit, AugmentOptions, AugmentedFit, AugmentedPhysical};
use crate::fit::Gmwm;
use crate::imu::Imu;
use rayon::prelude::*;
use serde::Serialize;

/// GMWM+ of one axis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisAugmented {
    /// Column name.
    pub column: String,
    /// The identified model refitted (its text, without values).
    pub model: String,
    /// The GMWM+ fit; `None` when it could not be made (`note` says why).
    pub fit: Option<AugmentedFit>,
    /// Its physical quantities beside the calibration's (data unit).
    pub physical: Vec<AugmentedPhysical>,
    /// Why no fit, in one line.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

impl Calibration {
    /// GMWM+ (`opts`) of the identified model of every gyroscope and accelerometer axis of
    /// `report`, from its identified fit and the samples of `imu` (the recording calibrated).
    /// An axis whose model the extra moments cannot describe, or whose fit fails, gets a note
    /// instead of a fit.
    ///
    /// # Errors
    /// [`CalibError`] when an axis of the report has no samples in `imu`.
    pub fn augmented(
        &self,
        imu: &Imu,
        report: &CalibrationReport,
        opts: &AugmentOptions,
    ) -> Result<Vec<AxisAugmented>, CalibError> {
        let mut work = Vec::new();
        for a in report.axes.iter().filter(|a| a.kind.is_some()) {
            let Some(axis) = imu.axes().iter().find(|x| x.column.name == a.column) else {
                return Err(crate::ParamError::new(
                    "column",
                    &a.column,
                    "a column of the recording calibrated (GMWM+ needs its samples)",
                )
                .into());
            };
            work.push((a, self.samples_in_si(a, &axis.column.values)?));
        }
        Ok(work
            .par_iter()
            .map(|(a, x)| {
                let template = a.fit.model().without_values();
                let gmwm = Gmwm::new(template.clone());
                let (fit, note) = match augment_fit(&gmwm, &a.fit, x, opts) {
                    Ok(fit) => (Some(fit), None),
                    Err(e) => (None, Some(format!("GMWM+ not run on {}: {e}", a.column))),
                };
                let physical = fit
                    .as_ref()
                    .map(|f| f.physical(Some(&a.unit)))
                    .unwrap_or_default();
                AxisAugmented {
                    column: a.column.clone(),
                    model: template.to_string(),
                    fit,
                    physical,
                    note,
                }
            })
            .collect())
    }
}
