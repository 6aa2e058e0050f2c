//! Calibration: from a recording to navigation-filter parameters.
pub(crate) mod audit;
pub(crate) mod augmented;
pub(crate) mod contamination;
pub(crate) mod covariate;
pub(crate) mod datasheet;
pub(crate) mod effective;
pub(crate) mod export;
pub(crate) mod horizon;
pub(crate) mod ieee;
pub(crate) mod nav;
pub(crate) mod pipeline;
pub(crate) mod plan;
pub(crate) mod pooled;
pub(crate) mod spread;
pub(crate) mod streamed;
pub(crate) mod verdict;

pub use audit::{Audit, AuditQuantity, AuditStats};
pub use augmented::AxisAugmented;
pub use contamination::{Contamination, FitUses};
pub use covariate::{
    AxisCurves, BandValue, CovariateCalibration, CovariateCalibrationOptions, CurvePoint,
};
pub use datasheet::{Datasheet, DatasheetComparison};
pub use horizon::HorizonBound;

#[cfg(test)]
pub(crate) use contamination::compare_classical_robust;
pub use nav::{Adjustment, AxisPolicy, NavSet};
pub use pipeline::{
    AxisCalibration, CalibError, Calibration, CalibrationOptions, CalibrationReport, Estimate,
    EstimateStatus, GaussMarkovBias, DEFAULT_FULL_MODEL,
};
pub use plan::{Plan, PlanTarget, PlannedQuantity, PLAN_LENGTHS_S};
pub use pooled::PooledInput;
pub use spread::{spread_across, RecordedAxis, SpreadAcross, SpreadRow};
#[cfg(test)]
pub(crate) use streamed::ROBUST_LEVELS;
pub use streamed::{CalibrationSource, STREAM_FROM};
pub use verdict::{FitVerdict, ScaleFit, ScaleMiss, DEFAULT_TOLERANCE};
