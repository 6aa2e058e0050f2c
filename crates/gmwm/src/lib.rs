//! # gmwm — stochastic error calibration of inertial sensors
//!
//! The engine of the gmwm platform: wavelet transforms, the wavelet variance (classical and
//! robust), Allan and Hadamard variances, IMU data readers, latent error models estimated by the
//! Generalized Method of Wavelet Moments with their inference and selection, and the
//! calibration pipeline that turns a recording into a navigation filter's parameters.
//!
//! Conventions, stated once:
//! - scales are labelled `tau_j = 2^j` samples (`2^j / freq_hz` seconds), the package label of
//!   docs/methods.md §0.1; Allan cluster lengths `m` are in samples, and `AV(m) = 2 WV(tau = 2m)`
//!   (§3.4);
//! - every variance is a variance, never a standard deviation, in the squared unit of the data;
//! - section numbers such as "§1.7" refer to the methods reference of this repository,
//!   `docs/methods.md`: the formulas, defaults and test values, section by section.
//!
//! Where to start (the items below are one flat list; these are the entry points):
//! - a recording to a navigation filter's parameters: [`Calibration`] ([`Calibration::open`]
//!   and [`Calibration::run_source`] for a file, several recordings or saved wavelet
//!   variances; [`Calibration::run`] for an [`Imu`] in memory), then
//!   [`CalibrationReport::nav_sets`] and [`render_export`] for the filter files;
//! - wavelet and Allan variances: [`wavelet_variance`], [`allan_variance`];
//! - a model fitted and judged: [`Model`], [`Gmwm`] ([`GmwmFit`]), [`infer`], [`auto_imu`]
//!   (the WIC selection, [`ModelSelection`]);
//! - reading files: [`Probe`], [`Recording`], [`read_table`]; the JSON the command line prints:
//!   [`document`].
//!
//! An item's documentation that points to its "module doc" means the comment at the top of the
//! item's source file (the `Source` link): the modules are private, their method notes are not.
//!
//! ```
//! use gmwm::{wavelet_variance, WvOptions};
//! // ramp x_t = t + 1: Haar MODWT WV 0.25 at tau = 2, 1.0 at tau = 4 (docs/methods.md §1.10)
//! let x: Vec<f64> = (1..=8).map(f64::from).collect();
//! let wv = wavelet_variance(&x, 1.0, &WvOptions { levels: Some(2), ..WvOptions::default() }).unwrap();
//! assert!((wv.wv()[0] - 0.25).abs() < 1e-12 && (wv.wv()[1] - 1.0).abs() < 1e-12);
//! ```
#![deny(missing_docs)]
#![warn(unreachable_pub)]

// Unit tests that exercise crate-internal kernels are written against `gmwm::` paths, like the
// integration tests they were moved from.
#[cfg(test)]
extern crate self as gmwm;

mod augmented;
mod calib;
pub mod document;
mod dynamics;
mod error;
mod fit;
mod imu;
mod inference;
mod math;
mod model;
mod monitor;
mod names;
mod process;
mod progress;
mod selection;
mod shared;
mod sim;
mod units;
mod variance;
mod wavelet;

// The engine's tests against reference data, properties and Monte Carlo; they reach the
// crate-internal kernels, so they live inside the crate (the public API has its own test,
// `tests/public_api.rs`).
#[cfg(test)]
mod tests;

// The public API, flat: the modules are private and every name a library user calls is
// re-exported here, grouped as the method reads (docs/architecture.md). `document` stays a
// module because its builders are named after the command whose JSON they make.

// Errors.
pub use error::{InputError, ModelError, ParamError, SeriesError};
pub use names::Named;
pub use progress::Progress;
pub use units::{DatasheetUnitError, Quantity, UnitForms};

// Wavelets, wavelet variances, Allan variances and spectra (docs/methods.md §1-§4).
pub use variance::allan::{allan_variance, AllanKind, AllanOptions, AllanVariance, AvConvention};
pub use variance::ci::{check_alpha, significance_level_problem};
pub use variance::psd::{welch_psd, Psd, BINNED_POINTS};
pub use variance::robust::{RobustConvention, RobustOptions};
#[cfg(test)]
pub(crate) use variance::wv::HaarWvAccumulator;
pub use variance::wv::{wavelet_variance, WaveletVariance, WvOptions, WvWarning};
pub use variance::{
    allan_from_wv, binary_columns_wv, binary_wavelet_variance, default_levels,
    gap_aware_wavelet_variance, is_wv_json, per_column, read_wv_json, select_series, GapAccount,
    GapLevel, GapPolicy, StreamedColumn,
};
pub use wavelet::{Transform, WaveletFilter};

// Latent models and their processes (§0.2, §2).
pub use model::{Component, ComponentWv, ImpliedWv, Model, ModelParseError, ParseErrorKind};
pub use process::{
    Ar1, Arma, Arma11, Dr, Flicker, Gm, LatentProcess, Ma1, Maf, Process, ProcessKind, Qn, Rw, Sin,
    StartMode, TransformPreset, Wn,
};
pub use sim::{simulate_model, DemoSensor, Simulator};

// GMWM fits, their inference and model selection (§5-§8).
pub use augmented::{
    augment_fit, fit_augmented, AugmentOptions, AugmentedFit, AugmentedJTest, AugmentedMoment,
    AugmentedParameter, AugmentedPhysical, DEFAULT_AUGMENT_REPLICATES,
};
pub use dynamics::{fit_ns_ar1, NsAr1, NsAr1Fit, NsAr1Options};
pub use fit::canonical::{CanonicalModel, CanonicalTerm, TermParameter};
pub use fit::transform::{Parametrisation, PhiOrder};
pub use fit::{
    covariate_level, covariate_windows, dependences, Augment, Convergence, CovariateFit,
    CovariateRecording, Dependence, FitError, FitEstimates, FitRecording, Gmwm, GmwmFit,
    NavParameter, ParameterEstimate, PooledFit, PooledRecording, StartInputs, StopReason,
    Weighting, Weights,
};
pub use inference::same_model::{
    compare_wvs, same_model_test_of, SameModelOptions, SameModelTest, ScaleContribution,
};
pub use inference::{
    infer, infer_with_progress, CoefficientInference, CovarianceMethod, CovariateInference,
    DependenceTest, Inference, InferenceOptions, ParameterInference, WvComparison,
};
pub use inference::{
    BootstrapGof, InferenceMethod, InferenceWarning, IntervalScale, JTest, VShape, ZConvention,
};
pub use selection::{
    auto_imu, select_pooled, AxisSelection, CandidateScore, ImuSelection, ModelSelection,
    OptimismConvention, OptimismMethod, PooledCandidate, PooledSelection, RowStatus,
    SelectionError, SelectionRow, SelectionRule, SelectionTable, Wic,
};
pub use shared::{
    fit_shared, CrossCovariance, NoSharedTest, SharedFit, SharedOptions, SharedParameter,
};

// Recordings: readers, writers, sidecars, ROS containers (docs/methods.md §10).
pub use imu::plausible::{raw_floats, ImplausibleFloats};
pub use imu::read::binary::ImuRecordType;
pub use imu::read::stream::{streams_from, StreamedTable};
pub use imu::read::{
    binary_layout, read_table, BinaryLayout, Column, ColumnSelector, HeaderMode, InputFormat,
    ReadOptions, ReadWarning, Table, TableFacts, RATE_TOLERANCE,
};
pub use imu::read::{binary_warnings, TimePolicy};
pub use imu::recording::{left_out_note, table_notes};
pub use imu::ros::{
    choose_topic, list_topics, read_imu_messages, read_ros_covariate, ImuMessages, RosContainer,
    RosCovariate, TopicInfo,
};
pub use imu::ros::{MessageError, RosError};
pub use imu::sidecar::sidecar_candidates;
pub use imu::write::{write_atomic, write_csv_header, write_csv_rows, write_sidecar, AtomicFile};
pub use imu::{
    find_sidecar, quote, quote_up_to, time_column_unit, Imu, OutputFormat, Probe, ReadError,
    Recording, RecordingOptions, RecordingSource, SampleAccount, Sensor, SensorInfo, SeriesWriter,
    Sidecar, SidecarColumn, TimeUnit, TimingReport,
};
pub use imu::{
    process_tag, remove_temporary_files, temporary_dir, track_temporary, untrack_temporary,
};
pub use imu::{Axis, ColumnSummary, Gap, NotASidecar, SidecarUnits, Tally, TimingWarning};
pub use units::{si_unit, NoiseTerm, SignalKind, SignalUnit};

// The calibration: a recording to a navigation filter's parameters (§14).
pub use calib::datasheet::{
    DatasheetError, DatasheetLine, DatasheetValue, DatasheetVerdict, TermComparison,
};
pub use calib::export::{render_export, ExportError, ExportFormat, NavNoise, SensorNoise};
pub use calib::ieee::{ieee_readoff, term_avar, CoefficientReadoff, IeeeReadoff};
pub use calib::streamed::{binary_file_columns, wv_account, wv_columns};
pub use calib::{
    spread_across, Audit, AuditQuantity, AuditStats, AxisAugmented, AxisCurves, BandValue,
    Contamination, CovariateCalibration, CovariateCalibrationOptions, CurvePoint, FitUses,
    FitVerdict, GaussMarkovBias, HorizonBound, Plan, PlanTarget, PlannedQuantity, PooledInput,
    RecordedAxis, ScaleFit, ScaleMiss, SpreadAcross, SpreadRow, PLAN_LENGTHS_S,
};
pub use calib::{
    Adjustment, AxisCalibration, AxisPolicy, CalibError, Calibration, CalibrationOptions,
    CalibrationReport, CalibrationSource, Datasheet, DatasheetComparison, Estimate, EstimateStatus,
    NavSet, DEFAULT_FULL_MODEL, DEFAULT_TOLERANCE, STREAM_FROM,
};
pub use monitor::{
    monitor_against, LevelOut, MonitorEvent, MonitorOptions, MonitorReport, MonitorWindow,
    Reference,
};

/// Any error the engine can return.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Reading or parsing an input file failed.
    #[error(transparent)]
    Read(#[from] crate::imu::ReadError),
    /// A series is unusable for the requested computation.
    #[error(transparent)]
    Series(#[from] SeriesError),
    /// A parameter or option has an impossible value.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// A model text could not be parsed or breaks a model rule (docs/methods.md §0.2).
    #[error(transparent)]
    ModelParse(#[from] crate::model::ModelParseError),
    /// A model breaks a rule of docs/methods.md §0.2 or has an invalid value.
    #[error(transparent)]
    Model(#[from] crate::model::ModelError),
    /// A GMWM fit could not be set up or evaluated (docs/methods.md §5).
    #[error(transparent)]
    Fit(#[from] crate::fit::FitError),
    /// A WIC model selection could not be set up or run (docs/methods.md §8).
    #[error(transparent)]
    Selection(#[from] crate::selection::SelectionError),
    /// Calibrating a recording failed.
    #[error(transparent)]
    Calibration(#[from] crate::calib::CalibError),
    /// A navigation-stack file could not be rendered.
    #[error(transparent)]
    Export(#[from] crate::calib::export::ExportError),
}

impl From<InputError> for Error {
    fn from(e: InputError) -> Self {
        match e {
            InputError::Series(e) => Error::Series(e),
            InputError::Param(e) => Error::Param(e),
            InputError::Model(e) => Error::Model(e),
        }
    }
}
