//! The calibration pipeline: per axis of an [`Imu`], the wavelet and Allan variances, the model
//! selected by WIC, the identified fit with inference, the canonical read-off in continuous
//! SI units with intervals, the IEEE Std 952 read-off and a verdict on the fit.

use super::audit::Audit;
use super::contamination::{compare_classical_robust, Contamination, FitUses};
use super::datasheet::{Datasheet, DatasheetComparison, Measured};
use super::horizon::HorizonBound;
use super::ieee::{ieee_readoff, IeeeReadoff};
use super::plan::Plan;
use super::verdict::{verdict, FitVerdict, DEFAULT_TOLERANCE};
use crate::fit::canonical::long_run_variance;
use crate::fit::{CanonicalModel, FitError, Gmwm, GmwmFit};
use crate::imu::{Imu, Sensor, SensorInfo};
use crate::inference::{
    infer_with_covariance, CovarianceMethod, Inference, InferenceOptions, Progress,
};
use crate::math::elementary;
use crate::model::Model;
use crate::process::{spec, Role};
use crate::selection::{ModelSelection, SelectionError, SelectionRule, Wic};
use crate::units::{forms, si_unit, NoiseTerm, SignalKind, SignalUnit, UnitForms};
use crate::variance::allan::{allan_variance, AllanOptions, AllanVariance};
use crate::variance::allan_from_wv;
use crate::variance::gaps::{gap_aware_wavelet_variance, GapAccount, GapPolicy};
use crate::variance::pooled::PooledWv;
use crate::variance::psd::{welch_psd, Psd, BINNED_POINTS};
use crate::variance::robust::RobustOptions;
use crate::variance::wv::{wavelet_variance, WaveletVariance, WvOptions};
use rayon::prelude::*;
use serde::Serialize;
use std::sync::atomic::{AtomicUsize, Ordering};
use thiserror::Error;

/// The full model whose sub-models are the candidates by default: three Gauss–Markov (AR1)
/// processes for the bias instability region, white noise, quantization noise, a random walk
/// and a drift (the R package's `auto.imu` set, 63 candidates).
pub const DEFAULT_FULL_MODEL: &str = "3*AR1()+WN()+QN()+RW()+DR()";

/// Relative step of the central differences of the delta-method intervals: the read-off
/// quantities are smooth powers and logarithms of the estimates, so `1e-5` relative keeps the
/// truncation error near `1e-10` and the rounding error near `1e-11` of the gradient.
const DELTA_STEP: f64 = 1e-5;

/// Relative standard error above which a read-off is reported without an interval, as not
/// determined by the data: beyond it the log-scale interval spans more than a factor e^(2 z)
/// (50 at 95%), which says nothing a filter could use, and `--conservative` would export noise.
pub(crate) const UNDETERMINED_SE_REL: f64 = 1.0;

/// Relative agreement below which a canonical term is a function of the fitted estimates
/// (terms computed by a refit are not, and get no interval from the fit's covariance).
const SAME_VALUE_REL: f64 = 1e-6;

/// Options of [`Calibration`]. The default is what `gmwm calibrate` runs.
#[derive(Debug, Clone, PartialEq)]
pub struct CalibrationOptions {
    /// Full model of the selection (default [`DEFAULT_FULL_MODEL`]).
    pub full_model: Model,
    /// Wavelet-variance settings (default classical Haar MODWT, 95% intervals).
    pub wv: WvOptions,
    /// How the WV covariance V behind the WIC and the intervals is obtained (default
    /// [`CovarianceMethod::Auto`]: exact when the full model is covered, which the default
    /// one is).
    pub covariance: CovarianceMethod,
    /// Bootstrap replicates of a bootstrap V (default 50, the selection's default: enough for
    /// a J x J covariance with J up to 47).
    pub bootstrap: usize,
    /// Starting-value draws of every fit (default `None`: the selection's size-dependent G).
    pub draws: Option<usize>,
    /// Seed of every search and simulation (default 1337, as the package).
    pub seed: u64,
    /// How the selected model is chosen among the equivalent ones (default navigation).
    pub rule: SelectionRule,
    /// Unit of the gyroscope samples (default: the recording's, e.g. its sidecar).
    pub gyro_unit: Option<SignalUnit>,
    /// Unit of the accelerometer samples (default: the recording's).
    pub accel_unit: Option<SignalUnit>,
    /// The robust estimator the classical WV is compared with to tell whether contamination
    /// matters (paper Fig. 2; default `eff = 0.6`, the package's; `None` skips the check).
    pub robust_check: Option<RobustOptions>,
    /// Samples per column from which [`Calibration::run_source`] streams a raw binary recording
    /// instead of reading it into memory (default [`crate::calib::STREAM_FROM`], 2^24).
    pub stream_from: u64,
    /// The verdict's practical tolerance, relative to the empirical WV (default
    /// [`DEFAULT_TOLERANCE`], 10%): a scale is explained inside the band or within it.
    pub tolerance: f64,
    /// Apply `gyro_unit`/`accel_unit` to a ROS recording too (SI by definition, refused
    /// otherwise: [`CalibError::UnitOnRos`]).
    pub force_units: bool,
    /// The sensor's datasheet, compared with each axis of its sensor (default `None`).
    pub datasheet: Option<Datasheet>,
    /// A mission horizon, s: each axis gets the white-noise + random-walk pair that bounds its
    /// model up to it ([`AxisCalibration::horizon_bound`]; default `None`).
    pub horizon_s: Option<f64>,
    /// How gaps in the time stamps enter the WV (default [`GapPolicy::Aware`]: the observed
    /// samples on their time grid, docs/methods.md §1.11).
    pub gaps: GapPolicy,
}

impl Default for CalibrationOptions {
    fn default() -> Self {
        Self {
            full_model: DEFAULT_FULL_MODEL
                .parse()
                .expect("the default full model parses"),
            wv: WvOptions::default(),
            covariance: CovarianceMethod::Auto,
            bootstrap: 50,
            draws: None,
            seed: 1337,
            rule: SelectionRule::Navigation,
            gyro_unit: None,
            accel_unit: None,
            robust_check: Some(RobustOptions::default()),
            stream_from: crate::calib::STREAM_FROM,
            tolerance: DEFAULT_TOLERANCE,
            force_units: false,
            datasheet: None,
            horizon_s: None,
            gaps: GapPolicy::Aware,
        }
    }
}

/// Why a calibration failed.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum CalibError {
    /// The recording has no gyroscope or accelerometer column to calibrate.
    #[error("no gyroscope or accelerometer column to calibrate (columns: {columns}); name them like gyro_x, accel_z or give the sidecar's meaning")]
    NoInertialAxis {
        /// The columns present.
        columns: String,
    },
    /// A unit does not fit the axis (a g unit given for a gyroscope, say).
    #[error("column {column}: unit {unit} is not a {expected} unit")]
    WrongUnit {
        /// Column.
        column: String,
        /// The unit.
        unit: String,
        /// What the column measures.
        expected: &'static str,
    },
    /// A unit flag given for a ROS recording, whose `sensor_msgs/Imu` messages are SI by
    /// definition (REP 103), without `force_units`.
    #[error("{flag} {unit} on a ROS recording: sensor_msgs/Imu is in rad/s and m/s^2 by definition (REP 103), so the flag would rescale correct data; drop it, or add --force-units if the publisher broke the convention")]
    UnitOnRos {
        /// The flag (`--gyro-unit`, `--accel-unit`).
        flag: &'static str,
        /// The unit given.
        unit: String,
    },
    /// Selecting or fitting one axis failed.
    #[error("column {column}: {source}")]
    Selection {
        /// Column.
        column: String,
        /// Cause.
        source: Box<SelectionError>,
    },
    /// Fitting or inference on one axis failed.
    #[error("column {column}: {source}")]
    Fit {
        /// Column.
        column: String,
        /// Cause.
        source: FitError,
    },
    /// Recordings that cannot be pooled into one calibration (docs/methods.md §5.12).
    #[error("{recording}: {reason}")]
    Pool {
        /// The recording, as named by the caller.
        recording: String,
        /// What is wrong.
        reason: String,
    },
    /// The Allan variance or a setting was unusable.
    #[error("column {column}: {source}")]
    Engine {
        /// Column.
        column: String,
        /// Cause.
        source: crate::InputError,
    },
    /// Reading the recording failed.
    #[error(transparent)]
    Read(#[from] crate::imu::ReadError),
    /// A setting or the recording's rate is unusable.
    #[error(transparent)]
    Input(#[from] crate::InputError),
}

crate::error::input_error_from!(CalibError);

/// What kind of number an [`Estimate`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum EstimateStatus {
    /// An estimate (with its interval when the fit's covariance gives one).
    Estimated,
    /// An estimate the data do not determine: no interval
    /// (`UNDETERMINED_SE_REL`).
    Undetermined,
    /// The term was not detected; `value` (= `ci_high`) is an upper bound.
    UpperBound,
}

/// A read-off quantity with its interval, in `unit`.
///
/// Wire format: `value`, `ci_low`, `ci_high` (null where no interval exists), `unit`,
/// `status` (`estimated`, `undetermined`, `upper-bound`), `source` (which term or rule gave
/// it), `forms` (continuous SI, discrete and datasheet forms, docs/methods.md §14.2; null for
/// quantities in the data unit).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// Lower end of the `1 - alpha` interval.
    pub ci_low: Option<f64>,
    /// Upper end.
    pub ci_high: Option<f64>,
    /// Unit (continuous-time SI for a gyroscope or accelerometer of known unit).
    pub unit: String,
    /// What kind of number `value` is.
    pub status: EstimateStatus,
    /// Where the value comes from, in words.
    pub source: String,
    /// The value in every form (SI, discrete, datasheet).
    pub forms: Option<UnitForms>,
}

/// The Gauss–Markov form of the bias (the slowest correlated term the canonical model keeps):
/// what PX4/Gazebo-style IMU models take.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GaussMarkovBias {
    /// Correlation time `1 / beta`, s.
    pub correlation_time: Estimate,
    /// Stationary standard deviation `sqrt(sigma2_gm)`.
    pub sigma: Estimate,
    /// Driving-noise density `sqrt(2 beta sigma2_gm)`.
    pub driving_density: Estimate,
}

/// One axis calibrated.
///
/// Wire format: `column`, `kind` (`gyro`, `accel` or null), `axis` (`X`, ...), `data_unit` (as read or given),
/// `unit` (the unit of the analysis: SI for a known unit, else the data unit), `samples`,
/// `model` (the selected candidate), `canonical_model`, `identified_model`, `noise_density`, `random_walk`,
/// `bias_instability`, `quantization`, `rate_ramp` ([`Estimate`] or null),
/// `gauss_markov_bias`, `ieee`, `verdict`, `canonical`, `inference`, `selection` (the table),
/// `wv`, `allan`, `psd` (the log-frequency binned Welch PSD in `unit`²/Hz, one-sided:
/// `frequency_hz`, `density`, `unit`, ...; null with a note when it was not computed),
/// `notes`, with a datasheet `datasheet` ([`DatasheetComparison`]), and for a pooled
/// calibration `recording_wvs`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisCalibration {
    /// Column name.
    pub column: String,
    /// What the column measures, when known.
    pub kind: Option<SignalKind>,
    /// The sensor axis it measures along (`X`, `Y`, `Z`, as the reader recognised it).
    pub axis: String,
    /// Unit of the samples as read (`None` when unknown).
    pub data_unit: Option<String>,
    /// Unit of every result of this axis (SI for a gyroscope/accelerometer of known unit).
    pub unit: String,
    /// Samples.
    pub samples: usize,
    /// The selected candidate as fitted (guess mode).
    pub model: String,
    /// Its canonical model: what the estimates are reported as.
    pub canonical_model: String,
    /// The model the estimates and intervals come from (the canonical model's reduced model,
    /// fitted), guess mode.
    pub identified_model: String,
    /// White-noise density N (angle / velocity random walk), continuous time.
    pub noise_density: Option<Estimate>,
    /// Random-walk density K (rate / acceleration random walk), continuous time.
    pub random_walk: Option<Estimate>,
    /// Bias instability B of the IEEE read-off (min Allan deviation / 0.664).
    pub bias_instability: Option<Estimate>,
    /// Quantization coefficient Q, when the model has quantization noise.
    pub quantization: Option<Estimate>,
    /// Rate ramp R, when the model has a drift.
    pub rate_ramp: Option<Estimate>,
    /// The dominant Gauss–Markov term, when the model has one.
    pub gauss_markov_bias: Option<GaussMarkovBias>,
    /// IEEE Std 952 read-off from the Allan deviation.
    pub ieee: IeeeReadoff,
    /// The verdict on the fit.
    pub verdict: FitVerdict,
    /// The canonical model with its terms.
    pub canonical: CanonicalModel,
    /// Inference on the identified fit (the canonical model's reduced model).
    pub inference: Inference,
    /// The identified fit.
    pub fit: GmwmFit,
    /// The selection.
    pub selection: ModelSelection,
    /// The wavelet variance (unit²).
    pub wv: WaveletVariance,
    /// The overlapping Allan variance (unit²).
    pub allan: AllanVariance,
    /// The Welch power spectral density (one-sided, unit²/Hz), binned on
    /// `BINNED_POINTS` log-spaced frequencies (`crate::variance::psd`); `None`, with a note,
    /// when the samples were not at hand (a pooled calibration, a streamed one without its
    /// spectral pass) or too short for one segment.
    pub psd: Option<Psd>,
    /// The classical WV against the robust one: whether contamination matters (`None` when
    /// the check is off or the robust WV could not be computed, with a note).
    pub contamination: Option<Contamination>,
    /// What the read-off did that a user should know, one line each.
    pub notes: Vec<String>,
    /// The datasheet's N, B, K against this axis' (`None`, and left out of the JSON, without a
    /// datasheet value for the axis' sensor or when its unit is unknown).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub datasheet: Option<DatasheetComparison>,
    /// The white-noise + random-walk pair bounding the model up to the mission horizon of
    /// [`CalibrationOptions::horizon_s`] (left out of the JSON without one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub horizon: Option<HorizonBound>,
    /// The precision of K, B and the correlation times at this recording's length and at two
    /// and four times it, under the identified model ([`Plan`]; left out of the JSON when the
    /// model has none of them).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plan: Option<Plan>,
    /// The self-audit of this axis ([`Calibration::audit`]; left out of the JSON when none
    /// was run).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub audit: Option<Audit>,
    /// A pooled calibration's recordings' own WVs of this axis (unit², the estimator of
    /// `wv`), input order, which `wv` pools; empty (and left out of the JSON) for one
    /// recording.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub recording_wvs: Vec<WaveletVariance>,
    /// What the gaps in the time stamps cost the WV, when the recording has gaps and they
    /// are analysed as such ([`CalibrationOptions::gaps`]; left out of the JSON otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gaps: Option<GapAccount>,
}

/// The calibration of a recording: one [`AxisCalibration`] per gyroscope and accelerometer
/// axis, in the recording's order.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CalibrationReport {
    /// Name of the recording, if known.
    pub name: Option<String>,
    /// Sampling rate, Hz.
    pub freq_hz: f64,
    /// Samples per axis.
    pub samples: usize,
    /// Length of the recording, s.
    pub duration_s: f64,
    /// Full model of the selection.
    pub full_model: String,
    /// Selection rule.
    pub rule: SelectionRule,
    /// Confidence level of every interval is `1 - alpha`.
    pub alpha: f64,
    /// Per axis.
    pub axes: Vec<AxisCalibration>,
    /// Checks on the recording as a whole that a user should read, one line each.
    pub checks: Vec<String>,
    /// The recordings of a pooled calibration (`CalibrationSource::Pooled`), input order;
    /// empty (and left out of the JSON) for one recording.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub recordings: Vec<super::pooled::PooledInput>,
}

/// Longest scale, in seconds, below which a recording is reported as too short to show the
/// bias instability and the random walk: those of MEMS and tactical IMUs show between 10 s and
/// 1000 s, and the WV's longest scale is about a quarter of the recording.
pub(crate) const SHORT_RECORDING_SCALE_S: f64 = 1000.0;

/// The calibration pipeline (module doc).
///
/// ```no_run
/// use gmwm::{Calibration, CalibrationOptions};
/// use gmwm::{read_table, Imu, ReadOptions};
/// let table = read_table("imu.csv.gz".as_ref(), &ReadOptions::default())?;
/// let imu = Imu::from_table(table)?;
/// let report = Calibration::new(CalibrationOptions::default()).run(&imu)?;
/// for axis in &report.axes {
///     println!("{}: {}", axis.column, axis.canonical_model);
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Calibration {
    options: CalibrationOptions,
}

impl Calibration {
    /// A pipeline with these options.
    pub fn new(options: CalibrationOptions) -> Self {
        Self { options }
    }

    /// The options.
    pub fn options(&self) -> &CalibrationOptions {
        &self.options
    }

    /// Number of candidate fits per axis (for progress totals).
    ///
    /// # Errors
    /// [`SelectionError`] for a full model that cannot be enumerated.
    pub fn candidates_per_axis(&self) -> Result<usize, SelectionError> {
        Ok(Wic::nested(self.options.full_model.clone())?
            .candidates()
            .len())
    }

    /// Calibrates every gyroscope and accelerometer axis of `imu` (in parallel).
    ///
    /// # Errors
    /// [`CalibError`] naming the axis that failed.
    pub fn run(&self, imu: &Imu) -> Result<CalibrationReport, CalibError> {
        self.run_with_progress(imu, &crate::inference::NoProgress)
    }

    /// [`Calibration::run`] reporting each scored candidate of every axis to `progress`
    /// (`start` once with axes x candidates, then one `advance` per candidate).
    ///
    /// # Errors
    /// As [`Calibration::run`].
    pub fn run_with_progress(
        &self,
        imu: &Imu,
        progress: &dyn Progress,
    ) -> Result<CalibrationReport, CalibError> {
        self.run_timed(imu, imu.timing(), progress)
    }

    /// [`Calibration::run_with_progress`] with `timing` as what the samples' stamps say (a
    /// ROS recording's are the [`Recording`](crate::imu::Recording)'s, not its IMU's).
    pub(crate) fn run_timed(
        &self,
        imu: &Imu,
        timing: Option<&crate::imu::TimingReport>,
        progress: &dyn Progress,
    ) -> Result<CalibrationReport, CalibError> {
        // gaps in the stamps: the samples on their time grid (§1.11)
        let gaps: &[crate::imu::Gap] = match (self.options.gaps, timing) {
            (GapPolicy::Aware, Some(t)) => &t.gaps,
            _ => &[],
        };
        let axes: Vec<InputAxis<'_>> = imu
            .axes()
            .iter()
            .map(|a| InputAxis {
                column: &a.column.name,
                info: &a.info,
                data: if gaps.is_empty() {
                    AxisData::Series(a.values())
                } else {
                    AxisData::Gapped {
                        series: a.values(),
                        gaps,
                    }
                },
            })
            .collect();
        let mut checks = Vec::new();
        if let (GapPolicy::Contiguous, Some(t)) = (self.options.gaps, timing) {
            if !t.gaps.is_empty() {
                checks.push(format!(
                    "{} {} in the time stamps analysed as one contiguous series (gaps: contiguous): the scales are mislabelled by the missing samples",
                    t.gaps.len(),
                    if t.gaps.len() == 1 { "gap" } else { "gaps" }
                ));
            }
        }
        self.run_axes(imu.name(), imu.freq_hz(), imu.len(), axes, checks, progress)
    }

    /// A static accelerometer measures gravity: the magnitude of its axes' means, under the
    /// unit in force, should be near 1 g. Far from it (outside 0.5 g to 1.5 g with every axis of
    /// the triad present) the unit is probably wrong; the check line names the unit under which
    /// the magnitude would be 1 g. Only in-memory series are checked (a streamed recording
    /// keeps no mean); the unit read or given is kept.
    fn gravity_check(&self, axes: &[InputAxis<'_>]) -> Option<String> {
        const G: f64 = 9.80665;
        let mut sum_sq = 0.0;
        let mut count = 0;
        let mut chosen = None;
        for a in axes
            .iter()
            .filter(|a| a.info.sensor == Sensor::Accelerometer)
        {
            let (AxisData::Series(x) | AxisData::Gapped { series: x, .. }) = &a.data else {
                return None;
            };
            let unit = self
                .options
                .accel_unit
                .or_else(|| a.info.unit.as_deref().and_then(|u| u.parse().ok()))?;
            if chosen.is_some_and(|c| c != unit) {
                return None;
            }
            chosen = Some(unit);
            let mean = x.iter().sum::<f64>() / x.len().max(1) as f64;
            sum_sq += (mean * unit.to_si()).powi(2);
            count += 1;
        }
        let unit: SignalUnit = chosen?;
        let magnitude = sum_sq.sqrt();
        if count < 3 || (0.5 * G..=1.5 * G).contains(&magnitude) {
            return None;
        }
        let raw = magnitude / unit.to_si();
        let likely = ["m/s^2", "g", "mg"]
            .iter()
            .filter_map(|u| u.parse::<SignalUnit>().ok())
            .find(|u| (0.5 * G..=1.5 * G).contains(&(raw * u.to_si())));
        Some(format!(
            "the accelerometer's mean reads {} {} ({:.3} g) in magnitude, where a static sensor reads 1 g{}: check --accel-unit",
            crate::fit::report::significant(raw, 4),
            unit.symbol(),
            magnitude / G,
            likely.map_or_else(String::new, |u| format!("; the data look like {}", u.symbol()))
        ))
    }

    /// The pipeline on the inertial axes among `axes` of a recording of `samples` samples per
    /// axis at `freq_hz`; `checks` are recording-level lines of the caller.
    pub(crate) fn run_axes(
        &self,
        name: Option<&str>,
        freq_hz: f64,
        samples: usize,
        all: Vec<InputAxis<'_>>,
        mut checks: Vec<String>,
        progress: &dyn Progress,
    ) -> Result<CalibrationReport, CalibError> {
        let columns = all.iter().map(|a| a.column).collect::<Vec<_>>().join(", ");
        let axes: Vec<InputAxis<'_>> = all
            .into_iter()
            .filter(|a| a.info.sensor != Sensor::Other)
            .collect();
        if axes.is_empty() {
            return Err(CalibError::NoInertialAxis { columns });
        }
        let per_axis = self
            .candidates_per_axis()
            .map_err(|source| CalibError::Selection {
                column: axes[0].column.to_string(),
                source: Box::new(source),
            })?;
        checks.extend(self.gravity_check(&axes));
        progress.start(axes.len() * per_axis);
        let done = AtomicUsize::new(0);
        let shared = |_: usize| progress.advance(done.fetch_add(1, Ordering::Relaxed) + 1);
        let results: Vec<Result<AxisCalibration, CalibError>> = axes
            .into_par_iter()
            .map(|axis| {
                let kind = match axis.info.sensor {
                    Sensor::Gyroscope => Some(SignalKind::Gyroscope),
                    Sensor::Accelerometer => Some(SignalKind::Accelerometer),
                    Sensor::Other => None,
                };
                self.axis(
                    axis.column,
                    &axis.info.axis,
                    kind,
                    axis.info.unit.as_deref(),
                    axis.data,
                    freq_hz,
                    &shared,
                )
            })
            .collect();
        // an axis that cannot be calibrated (a dead, constant channel, say) is left out with a
        // check line; only when none can is the calibration an error
        let mut axes = Vec::new();
        let mut first_error = None;
        for r in results {
            match r {
                Ok(a) => axes.push(a),
                // a unit of the wrong kind is the caller's mistake, not the data's
                Err(e @ CalibError::WrongUnit { .. }) => return Err(e),
                Err(e) => {
                    checks.push(format!("not calibrated: {e}"));
                    first_error.get_or_insert(e);
                }
            }
        }
        if axes.is_empty() {
            if let Some(e) = first_error {
                return Err(e);
            }
        }
        let duration_s = samples as f64 / freq_hz;
        if let Some(longest) = axes
            .iter()
            .filter_map(|a| a.wv.tau_s.last().copied())
            .reduce(f64::max)
        {
            if longest < SHORT_RECORDING_SCALE_S {
                checks.push(format!(
                    "the recording lasts {} s, so the longest scale observed is {} s: the bias instability and random walk of most IMUs show between 10 s and 1000 s; record for 2-3 hours (a MEMS IMU) or more to pin them down",
                    crate::fit::report::significant(duration_s, 3),
                    crate::fit::report::significant(longest, 3)
                ));
            }
        }
        Ok(CalibrationReport {
            name: name.map(str::to_string),
            freq_hz,
            samples,
            duration_s,
            full_model: self.options.full_model.to_string(),
            rule: self.options.rule,
            alpha: self.options.wv.alpha,
            axes,
            checks,
            recordings: Vec::new(),
        })
    }

    /// The unit of one axis: the option for its kind, else the recording's text parsed.
    pub(crate) fn unit_of(
        &self,
        column: &str,
        kind: Option<SignalKind>,
        recorded: Option<&str>,
        notes: &mut Vec<String>,
    ) -> Result<Option<SignalUnit>, CalibError> {
        let given = match kind {
            Some(SignalKind::Gyroscope) => self.options.gyro_unit,
            Some(SignalKind::Accelerometer) => self.options.accel_unit,
            None => None,
        };
        let unit = match (given, recorded) {
            (Some(u), Some(text)) => {
                if text.parse::<SignalUnit>().ok() != Some(u) {
                    // the unit itself, without the sidecar's comment
                    let recorded = text.split(" (").next().unwrap_or(text).trim();
                    notes.push(format!(
                        "the unit flag ({}) overrides the recording's unit ({recorded}): check which is right",
                        u.symbol()
                    ));
                }
                Some(u)
            }
            (Some(u), None) => Some(u),
            (None, Some(text)) => match text.parse::<SignalUnit>() {
                Ok(u) => Some(u),
                Err(_) => {
                    notes.push(format!(
                        "unit {text:?} of the recording is not a known inertial unit: results are in the data unit"
                    ));
                    None
                }
            },
            (None, None) => {
                if kind.is_some() {
                    notes.push(
                        "unit unknown (no sidecar or header unit, no --gyro-unit/--accel-unit): results are in the data unit \"u\"".to_string(),
                    );
                }
                None
            }
        };
        match (unit, kind) {
            (Some(u), Some(k)) if u.kind() != k => Err(CalibError::WrongUnit {
                column: column.to_string(),
                unit: u.symbol().to_string(),
                expected: match k {
                    SignalKind::Gyroscope => "gyroscope (rad/s, deg/s, deg/h)",
                    SignalKind::Accelerometer => "accelerometer (m/s^2, g, mg)",
                },
            }),
            _ => Ok(unit),
        }
    }

    /// One axis (module doc), step by step: its unit and SI values ([`Calibration::unit_of`],
    /// [`in_si`]), the selection ([`Calibration::select`]), the identified fit with its
    /// inference and canonical model ([`Calibration::identify`]), the Allan variance and the
    /// IEEE read-off ([`allan_of`]), the navigation read-offs ([`Readoff::read`]), the verdict
    /// ([`verdict`]), the readings and the contamination check.
    #[allow(clippy::too_many_arguments)]
    fn axis(
        &self,
        column: &str,
        axis_label: &str,
        kind: Option<SignalKind>,
        recorded_unit: Option<&str>,
        data: AxisData<'_>,
        freq_hz: f64,
        progress: &dyn Progress,
    ) -> Result<AxisCalibration, CalibError> {
        let mut notes = Vec::new();
        let unit = self.unit_of(column, kind, recorded_unit, &mut notes)?;
        // every result in SI: the samples (or the streamed WVs) are converted once, before any
        // statistic
        let si_values = in_si(&data, unit);
        let data = match (&si_values, data) {
            (Some(x), AxisData::Gapped { gaps, .. }) => AxisData::Gapped { series: x, gaps },
            (Some(x), _) => AxisData::Series(x),
            (None, d) => d.scaled(unit.map_or(1.0, |u| u.to_si())),
        };
        let samples = data.samples();
        // a kind without a known unit reads in the data unit: no SI names, no datasheet forms
        let unit_kind = kind.filter(|_| unit.is_some());
        // results of an axis whose unit is not understood are in the data unit, named "u" (the
        // recorded text, which may be a sentence, is kept in `data_unit`)
        let unit_label = match (unit, kind) {
            (Some(_), Some(k)) => SignalUnit::si(k).symbol().to_string(),
            _ => "u".to_string(),
        };
        let errors = AxisErrors { column };
        let mut gaps = None;
        let data = match data {
            AxisData::Gapped { series, gaps: g } => {
                let (pooled, account) = self
                    .gap_aware(series, g, freq_hz, &mut notes)
                    .map_err(|e| errors.engine(e))?;
                notes.push(account.to_string());
                gaps = Some(account);
                pooled
            }
            d => d,
        };
        let selection = self.select(&data, freq_hz, progress, &errors)?;
        let wv = selection.fit.empirical.clone().ok_or_else(|| {
            errors.fit(FitError::Length {
                what: "stored WV",
                expected: selection.fit.nu_hat.len(),
                found: 0,
            })
        })?;
        let (fit, inference, canonical) = self.identify(&selection).map_err(|e| errors.fit(e))?;
        let verdict = verdict(
            &fit,
            &wv,
            &inference,
            self.options.wv.alpha,
            self.options.tolerance,
        );
        // the spectrum: in the results, and where a vibration line is looked for
        let psd = psd_of(&data, freq_hz, &unit_label, &mut notes);
        // at most two refinements: a term for the worst miss, then one for the next
        let mut current = (
            selection.selected.to_string(),
            fit,
            inference,
            canonical,
            verdict,
        );
        for _ in 0..2 {
            match self.refine(
                &selection,
                &current.1,
                &wv,
                &current.4,
                (freq_hz, psd.as_ref(), &vibration_lines(&current.3)),
                &mut notes,
            ) {
                Some(r) => current = r,
                None => break,
            }
        }
        if let Some(r) =
            self.flicker_for_gauss_markov(&selection, &current, &wv, psd.as_ref(), &mut notes)
        {
            current = r;
        }
        let (model, fit, inference, canonical, verdict) = current;
        let allan =
            allan_of(&data, freq_hz, self.options.wv.alpha).map_err(|e| errors.engine(e))?;
        let ieee = ieee_readoff(&allan).map_err(|e| errors.engine(e.into()))?;
        let readoff = Readoff::new(
            &fit,
            &canonical,
            &inference,
            unit_kind,
            &unit_label,
            freq_hz,
        );
        let mut read = readoff.read(&allan, &ieee, &mut notes);
        notes.extend(readings(&selection, &canonical));
        let plan =
            super::plan::longer_recording(&fit.model, freq_hz, samples).map(|(plan, line)| {
                notes.push(line);
                plan
            });
        let effective = plan.as_ref().and_then(|plan| {
            self.effective_random_walk(
                (&selection, &wv, &fit, plan),
                (&allan, &ieee),
                (unit_kind, &unit_label, freq_hz),
                &mut read,
                &mut notes,
            )
        });
        if matches!(data, AxisData::Series(_) | AxisData::Streamed { .. }) {
            read.random_walk = read.random_walk.map(|k| {
                self.random_walk_under_model_v(
                    k,
                    (effective.as_ref().unwrap_or(&fit), &selection, &wv),
                    (&allan, &ieee),
                    (unit_kind, &unit_label, freq_hz),
                )
            });
        }
        let contamination = self.contamination(&data, freq_hz, &wv, &mut notes);
        let datasheet = self.datasheet(kind, unit_kind, &read, &mut notes);
        let mut axis = AxisCalibration {
            column: column.to_string(),
            kind,
            axis: axis_label.to_string(),
            data_unit: unit
                .map(|u| u.symbol().to_string())
                .or_else(|| recorded_unit.map(str::to_string)),
            unit: unit_label,
            samples,
            model,
            canonical_model: canonical.model.to_string(),
            identified_model: fit.model.without_values().to_string(),
            noise_density: read.noise_density,
            random_walk: read.random_walk,
            bias_instability: read.bias_instability,
            quantization: read.quantization,
            rate_ramp: read.rate_ramp,
            gauss_markov_bias: read.gauss_markov_bias,
            ieee,
            verdict,
            canonical,
            inference,
            fit,
            selection,
            wv,
            allan,
            psd,
            contamination,
            datasheet,
            notes,
            horizon: None,
            plan,
            audit: None,
            recording_wvs: Vec::new(),
            gaps,
        };
        if let Some(t) = self.options.horizon_s {
            axis.horizon = Some(axis.horizon_bound(t).map_err(|e| errors.engine(e))?);
        }
        Ok(axis)
    }

    /// The WIC selection of the full model's sub-models on the axis' WV (docs/methods.md §8).
    fn select(
        &self,
        data: &AxisData<'_>,
        freq_hz: f64,
        progress: &dyn Progress,
        errors: &AxisErrors<'_>,
    ) -> Result<ModelSelection, CalibError> {
        let mut wic = Wic::nested(self.options.full_model.clone())
            .map_err(|source| errors.selection(source))?
            .with_bootstrap(self.options.bootstrap)
            .with_covariance(self.options.covariance)
            .with_seed(self.options.seed)
            .with_rule(self.options.rule)
            .with_wv_options(self.options.wv);
        if let Some(g) = self.options.draws {
            wic = wic.with_draws(g);
        }
        match data {
            AxisData::Series(x) => wic.select_with_progress(x, freq_hz, progress),
            AxisData::Streamed { wv, .. } => wic.select_wv_with_progress(wv, progress),
            AxisData::Pooled {
                classical, robust, ..
            } => match (self.options.wv.robust, robust) {
                (None, _) => wic.select_pooled_wv_with_progress(classical, progress),
                (Some(_), Some(Ok(r))) => wic.select_pooled_wv_with_progress(r, progress),
                (Some(_), Some(Err(e))) => {
                    return Err(errors.engine(
                        crate::ParamError::new("robust wavelet variance", e, "computable").into(),
                    ))
                }
                (Some(_), None) => unreachable!("run_pooled computes the robust WV it fits"),
            },
            AxisData::Gapped { .. } => {
                unreachable!("Calibration::axis turns a gapped series into its gap-aware WV first")
            }
        }
        .map_err(|source| errors.selection(source))
    }

    /// Guided by the WV's shape (issue 28): when the verdict misses, the term its likely cause
    /// names is added to the identified model and fitted on the same WV, starting from the
    /// miss: a hump at `tau` samples or a flat start is a sinusoid whose WV peaks there
    /// (`SIN(omega = 0.742 / tau)`, `process/sin.rs`), a floor a flicker term (`FN()`), the
    /// longest scales above the model a random walk (`RW()`, when the model may take one). The
    /// refined model is kept when it explains more scales and lowers the objective; its
    /// inference uses the selection's V (the WV's covariance, not the model's). Returns the
    /// model text, fit, inference, canonical model and verdict; `None` to keep the selection's.
    #[allow(clippy::type_complexity)]
    fn refine(
        &self,
        selection: &ModelSelection,
        base: &GmwmFit,
        wv: &WaveletVariance,
        verdict: &FitVerdict,
        (freq_hz, psd, base_lines): (f64, Option<&Psd>, &[f64]),
        notes: &mut Vec<String>,
    ) -> Option<(String, GmwmFit, Inference, CanonicalModel, FitVerdict)> {
        let worst = verdict.worst.as_ref()?;
        let terms = refinement_terms(base, verdict, freq_hz, self.options.tolerance, psd);
        let base_objective = base.objective;
        // the lines a refit must keep where they were (without a spectrum): the model's and the
        // one a term proposes
        let required = |term: &str| -> Vec<f64> {
            base_lines
                .iter()
                .copied()
                .chain(proposed_line_hz(term, freq_hz))
                .collect()
        };
        // each candidate term fitted on the same WV; the one that explains the most scales,
        // then the lowest objective, if it explains more than the base and lowers the objective
        let (term, fit, inference, canonical, refined) = terms
            .into_iter()
            .filter_map(|term| {
                let base_text = base.model.without_values().to_string();
                // the filter takes the white noise's place (both are white beyond the filter)
                let kept: Vec<&str> = base_text
                    .split('+')
                    .filter(|c| !(term.starts_with("MAF") && *c == "WN()"))
                    .collect();
                let text = format!("{}+{term}", kept.join("+"));
                let (fit, inference, canonical, refined) =
                    self.judged(text.parse().ok()?, selection, wv)?;
                (refined.scales_missed < verdict.scales_missed
                    && fit.objective < base_objective
                    && lines_hold(&canonical, psd, &required(&term)))
                .then_some((term, fit, inference, canonical, refined))
            })
            .min_by(|a, b| {
                (a.4.scales_missed, a.1.objective)
                    .partial_cmp(&(b.4.scales_missed, b.1.objective))
                    .unwrap_or(std::cmp::Ordering::Equal)
            })?;
        // the refined fit's canonical model fitted as such (as `identify` does for the
        // selection), so that every reported term has estimates and intervals, when it
        // explains as many scales
        let reduced = &canonical.reduced;
        let identified = (reduced.without_values().to_string()
            != fit.model.without_values().to_string())
        .then(|| self.judged(reduced.clone(), selection, wv))
        .flatten()
        .filter(|j| {
            j.3.scales_missed <= refined.scales_missed && lines_hold(&j.2, psd, &required(&term))
        });
        let (fit, inference, canonical, refined) =
            identified.unwrap_or((fit, inference, canonical, refined));
        let replaced = term.starts_with("MAF")
            && base
                .model
                .without_values()
                .to_string()
                .split('+')
                .any(|c| c == "WN()");
        let how = if replaced {
            "in the white noise's place"
        } else {
            "added"
        };
        let sig = |x: f64| crate::fit::report::significant(x, 3);
        notes.push(format!(
            "guided by the WV's shape: the selected model missed {} of {} scales (worst {:.0}% at {} s, likely {}); with {term} {how} it misses {} (objective {} -> {}); the WIC table ranks the selection's candidates, not this refinement",
            verdict.scales_missed,
            verdict.levels,
            100.0 * worst.deviation.abs(),
            sig(worst.tau_s),
            worst.cause,
            refined.scales_missed,
            sig(base_objective),
            sig(fit.objective),
        ));
        let model = fit.model.without_values().to_string();
        Some((model, fit, inference, canonical, refined))
    }

    /// A bias-instability floor spent on Gauss–Markov terms (issue 28): when the model has two
    /// or more AR1/GM terms, the same model with a flicker term `FN()` in their place is fitted
    /// on the same WV and kept when it explains every scale the model explains and its
    /// objective is no more than `2` per parameter it saves above the model's (the AIC's
    /// penalty on the GMWM objective, a chi-square statistic under the efficient weights):
    /// a floor is then one term with the bias instability as its parameter, instead of
    /// invented correlation times and a random walk inflated by their tails.
    #[allow(clippy::type_complexity)]
    fn flicker_for_gauss_markov(
        &self,
        selection: &ModelSelection,
        current: &(String, GmwmFit, Inference, CanonicalModel, FitVerdict),
        wv: &WaveletVariance,
        psd: Option<&Psd>,
        notes: &mut Vec<String>,
    ) -> Option<(String, GmwmFit, Inference, CanonicalModel, FitVerdict)> {
        let (_, base, _, base_canonical, verdict) = current;
        let lines = vibration_lines(base_canonical);
        let text = base.model.without_values().to_string();
        let parts: Vec<&str> = text.split('+').collect();
        let correlated = |c: &str| c.ends_with("AR1()") || c.ends_with("GM()");
        let count: usize = parts
            .iter()
            .filter(|c| correlated(c))
            .map(|c| {
                c.split('*')
                    .next()
                    .and_then(|k| k.parse().ok())
                    .unwrap_or(1)
            })
            .sum();
        if count == 0 || parts.contains(&"FN()") {
            return None;
        }
        // a single correlated term is taken for a floor only when the recording determines its
        // correlation time: an undetermined slow one is the effective random walk's
        // (`super::effective`), a hump or a floor the data cannot tell
        if count == 1 {
            let length = wv.n() as f64 / base.freq_hz();
            let plan = Plan::new(&base.model, base.freq_hz(), &[length], 0.05, &[]).ok()?;
            if !super::effective::unresolved_slow_terms(&plan, 0.0).is_empty() {
                return None;
            }
        }
        let kept: Vec<&str> = parts.into_iter().filter(|c| !correlated(c)).collect();
        // every correlated term replaced, or all but one (the sensor's sub-sample filter, or a
        // hump, may need its own)
        let keep_one: &[&str] = if count >= 2 { &["", "AR1()+"] } else { &[""] };
        let (candidate, fit, inference, canonical, refined) = keep_one
            .iter()
            .filter_map(|one| {
                let candidate = format!(
                    "{one}{}",
                    kept.iter()
                        .chain(["FN()"].iter())
                        .copied()
                        .collect::<Vec<_>>()
                        .join("+")
                );
                let (fit, inference, canonical, refined) =
                    self.judged(candidate.parse().ok()?, selection, wv)?;
                let saved = base.theta.len().saturating_sub(fit.theta.len()) as f64;
                let explains_as_much = verdict
                    .scales
                    .iter()
                    .zip(&refined.scales)
                    .all(|(b, r)| r.explained || !b.explained);
                (explains_as_much
                    && fit.objective <= base.objective + 2.0 * saved
                    && lines_hold(&canonical, psd, &lines))
                .then_some((candidate, fit, inference, canonical, refined))
            })
            .min_by(|a, b| a.1.theta.len().cmp(&b.1.theta.len()))?;
        let saved = base.theta.len().saturating_sub(fit.theta.len());
        let sig = |x: f64| crate::fit::report::significant(x, 3);
        notes.push(format!(
            "a bias-instability floor: {candidate} explains every scale {text} explains with {} fewer parameters (objective {} -> {}), so a flicker term takes the place of Gauss-Markov terms",
            saved,
            sig(base.objective),
            sig(fit.objective),
        ));
        Some((
            fit.model.without_values().to_string(),
            fit,
            inference,
            canonical,
            refined,
        ))
    }

    /// K as the effective random walk (`super::effective`, docs/methods.md §20) when the
    /// identified model has a slow correlated term the planner leaves undetermined at this
    /// length: that model without those terms, with a random walk, fitted on the same WV and
    /// read off into `read.random_walk` (the term's Gauss–Markov bias marked undetermined);
    /// `None`, `read`'s K kept, when there is no such term or the refit gives no K.
    #[allow(clippy::type_complexity)]
    fn effective_random_walk(
        &self,
        (selection, wv, fit, plan): (&ModelSelection, &WaveletVariance, &GmwmFit, &Plan),
        (allan, ieee): (&AllanVariance, &IeeeReadoff),
        (kind, unit, freq_hz): (Option<SignalKind>, &str, f64),
        read: &mut ReadOffs,
        notes: &mut Vec<String>,
    ) -> Option<GmwmFit> {
        let terms = super::effective::unresolved_slow_terms(plan, ieee.b.at_tau_s);
        if terms.is_empty() {
            return None;
        }
        // the Gauss–Markov bias of an undetermined term: its values, no intervals
        if let Some(g) = read.gauss_markov_bias.as_mut() {
            let t = g.correlation_time.value;
            if terms.iter().any(|(_, tt)| (tt / t - 1.0).abs() < 1e-6) {
                for e in [
                    &mut g.correlation_time,
                    &mut g.sigma,
                    &mut g.driving_density,
                ] {
                    e.ci_low = None;
                    e.ci_high = None;
                    e.status = EstimateStatus::Undetermined;
                    e.source.push_str(
                        "; its correlation time is not determined at this length (gmwm plan)",
                    );
                }
            }
        }
        let dropped: Vec<usize> = terms.iter().map(|t| t.0).collect();
        let model = super::effective::with_random_walk_for(&fit.model, &dropped, freq_hz)?;
        let (fit, inference, canonical, _) = self.judged(model, selection, wv)?;
        let readoff = Readoff::new(&fit, &canonical, &inference, kind, unit, freq_hz);
        let mut scratch = Vec::new();
        let effective = readoff.read(allan, ieee, &mut scratch).random_walk?;
        if effective.status == EstimateStatus::UpperBound {
            return None;
        }
        let (note, source) = super::effective::effective_random_walk_note(
            &terms,
            &fit.model,
            read.random_walk.as_ref(),
            &effective,
            wv.n() as f64 / freq_hz,
        );
        notes.push(note);
        read.random_walk = Some(Estimate {
            source,
            ..effective
        });
        Some(fit)
    }

    /// K's interval over both covariances of the WV (docs/methods.md §20): the selection's V
    /// (at the full model's fit) and the exact V implied by `fit`'s own model at this length.
    /// At the longest scales, which fix K, the full model may explain the power with
    /// stationary terms whose WV varies less than a random walk's, and which reading holds is
    /// the question the data cannot settle there; on a Gauss–Markov + random-walk truth the
    /// selection's V gave K's standard error 20% below the Monte Carlo spread, the model's 10%.
    /// `k` unchanged without an interval, for a robust WV, or when the model's V cannot be
    /// computed.
    fn random_walk_under_model_v(
        &self,
        k: Estimate,
        (fit, selection, wv): (&GmwmFit, &ModelSelection, &WaveletVariance),
        (allan, ieee): (&AllanVariance, &IeeeReadoff),
        (kind, unit, freq_hz): (Option<SignalKind>, &str, f64),
    ) -> Estimate {
        let (Some(lo), Some(hi)) = (k.ci_low, k.ci_high) else {
            return k;
        };
        if k.status != EstimateStatus::Estimated || wv.robust.is_some() {
            return k;
        }
        let other = (|| {
            let v = crate::variance::implied_cov::exact_wv_covariance(
                &fit.model,
                wv.n(),
                freq_hz,
                fit.nu_hat.len(),
            )
            .ok()?;
            let inference = infer_with_covariance(
                &Gmwm::new(fit.model.clone()),
                fit,
                &v,
                None,
                &self.options.wv,
                &InferenceOptions {
                    alpha: self.options.wv.alpha,
                    seed: self.options.seed,
                    ..InferenceOptions::default()
                },
            )
            .ok()?;
            let canonical = fit.canonical_with(selection.separation_limit).ok()?;
            let readoff = Readoff::new(fit, &canonical, &inference, kind, unit, freq_hz);
            readoff.read(allan, ieee, &mut Vec::new()).random_walk
        })();
        match other {
            Some(Estimate {
                ci_low: Some(l),
                ci_high: Some(h),
                status: EstimateStatus::Estimated,
                ..
            }) if l < lo || h > hi => Estimate {
                ci_low: Some(lo.min(l)),
                ci_high: Some(hi.max(h)),
                source: format!(
                    "{}; interval over the selection's and the model's WV covariance",
                    k.source
                ),
                ..k
            },
            _ => k,
        }
    }

    /// The identified fit (the canonical model's reduced model, fitted: a candidate of the
    /// selection when it is one) so that every reported term has estimates and intervals, its
    /// inference on the selection's V, and its canonical model.
    fn identify(
        &self,
        selection: &ModelSelection,
    ) -> Result<(GmwmFit, Inference, CanonicalModel), FitError> {
        let reduced = &selection.selected_canonical.reduced;
        let fit = match selection.candidate_fit(reduced) {
            Some(f) => f.clone(),
            None => self.refit(reduced.clone(), selection)?,
        };
        let (inference, canonical) = self.infer_on(selection, &fit)?;
        Ok((fit, inference, canonical))
    }

    /// `model` fitted on the selection's WV, its inference on the selection's V, its canonical
    /// model and its verdict: a candidate of refinement, judged as the selection is. `None`
    /// when it cannot be fitted.
    fn judged(
        &self,
        model: Model,
        selection: &ModelSelection,
        wv: &WaveletVariance,
    ) -> Option<(GmwmFit, Inference, CanonicalModel, FitVerdict)> {
        let fit = self.refit(model, selection).ok()?;
        let (inference, canonical) = self.infer_on(selection, &fit).ok()?;
        let v = verdict(
            &fit,
            wv,
            &inference,
            self.options.wv.alpha,
            self.options.tolerance,
        );
        Some((fit, inference, canonical, v))
    }

    /// `model` fitted on the selection's WV, with the options' seed and draws.
    fn refit(&self, model: Model, selection: &ModelSelection) -> Result<GmwmFit, FitError> {
        let mut g = Gmwm::new(model).with_seed(self.options.seed);
        if let Some(d) = self.options.draws {
            g = g.with_draws(d);
        }
        g.update(&selection.fit)
    }

    /// The inference of `fit` on the selection's V (the WV's covariance, whatever the model)
    /// and its canonical model.
    fn infer_on(
        &self,
        selection: &ModelSelection,
        fit: &GmwmFit,
    ) -> Result<(Inference, CanonicalModel), FitError> {
        let inference = infer_with_covariance(
            &Gmwm::new(fit.model.clone()),
            fit,
            &selection.wv_covariance,
            selection.v_replicates(),
            &self.options.wv,
            &InferenceOptions {
                alpha: self.options.wv.alpha,
                seed: self.options.seed,
                ..InferenceOptions::default()
            },
        )?;
        let canonical = fit.canonical_with(selection.separation_limit)?;
        Ok((inference, canonical))
    }

    /// The datasheet's values of the axis' sensor against its N, B, K (module doc of
    /// [`super::datasheet`]); a note when the sensor's unit is unknown.
    fn datasheet(
        &self,
        kind: Option<SignalKind>,
        unit_kind: Option<SignalKind>,
        read: &ReadOffs,
        notes: &mut Vec<String>,
    ) -> Option<DatasheetComparison> {
        let sheet = self.options.datasheet.as_ref()?;
        let Some(k) = unit_kind else {
            if kind.is_some_and(|k| sheet.has(k)) {
                notes.push(
                    "datasheet not compared: the unit of the samples is unknown (give \
                     --gyro-unit/--accel-unit)"
                        .to_string(),
                );
            }
            return None;
        };
        let measured = |e: &Option<Estimate>| {
            e.as_ref().map(|e| Measured {
                value: e.value,
                interval: e.ci_low.zip(e.ci_high),
                upper_bound: e.status == EstimateStatus::UpperBound,
            })
        };
        sheet.compare(
            k,
            measured(&read.noise_density),
            measured(&read.bias_instability),
            measured(&read.random_walk),
        )
    }

    /// The classical WV of the axis against the robust one ([`compare_classical_robust`]);
    /// `wv` is the axis' WV, classical or robust as the options ask, so only the other is
    /// computed (a streamed axis brings its robust WV).
    /// A gapped axis' WV (docs/methods.md §1.11): the gap-aware classical WV, calibrated as a
    /// streamed recording's, with the spectrum of the longest gap-free stretch; no robust WV
    /// (the gap-aware estimator is the classical one's), said in a note.
    fn gap_aware<'a>(
        &self,
        series: &'a [f64],
        gaps: &[crate::imu::Gap],
        freq_hz: f64,
        notes: &mut Vec<String>,
    ) -> Result<(AxisData<'a>, GapAccount), crate::InputError> {
        let (wv, account) = gap_aware_wavelet_variance(series, gaps, freq_hz, &self.options.wv)?;
        let rows: Vec<usize> = gaps.iter().map(|g| g.row).collect();
        let psd = crate::variance::gaps::segments(series.len(), &rows)
            .into_iter()
            .max_by_key(|s| s.len())
            .map(|s| {
                welch_psd(&series[s], freq_hz)
                    .map(Box::new)
                    .map_err(|e| format!("the longest gap-free stretch: {e}"))
            });
        if self.options.robust_check.is_some() {
            notes.push(
                "no contamination check: the gap-aware estimator is the classical wavelet variance's (--gaps contiguous compares it with the robust one over the samples as one series)"
                    .to_string(),
            );
        }
        Ok((
            AxisData::Streamed {
                wv: Box::new(wv),
                robust: None,
                psd,
            },
            account,
        ))
    }

    fn contamination(
        &self,
        data: &AxisData<'_>,
        freq_hz: f64,
        wv: &WaveletVariance,
        notes: &mut Vec<String>,
    ) -> Option<Contamination> {
        let robust_options = self.options.robust_check?;
        let alpha = self.options.wv.alpha;
        let x = match data {
            AxisData::Series(x) => *x,
            AxisData::Pooled {
                classical, robust, ..
            } => {
                let uses = match self.options.wv.robust {
                    Some(_) => FitUses::Robust,
                    None => FitUses::Classical,
                };
                let robust = robust.as_ref().map(|r| r.as_ref().map(|p| p.wv()));
                return compared(
                    classical.wv(),
                    robust,
                    uses,
                    alpha,
                    self.options.tolerance,
                    notes,
                );
            }
            AxisData::Gapped { .. } => {
                unreachable!("Calibration::axis turns a gapped series into its gap-aware WV first")
            }
            AxisData::Streamed { robust, .. } => {
                let robust = robust.as_ref().map(|r| r.as_ref().map(|w| &**w));
                return compared(
                    wv,
                    robust,
                    FitUses::Classical,
                    alpha,
                    self.options.tolerance,
                    notes,
                );
            }
        };
        let other = WvOptions {
            levels: Some(wv.levels()),
            robust: match wv.robust {
                Some(_) => None,
                None => Some(robust_options),
            },
            ..self.options.wv
        };
        match wavelet_variance(x, freq_hz, &other) {
            Ok(w) => Some(match wv.robust {
                Some(_) => compare_classical_robust(
                    w,
                    wv.clone(),
                    FitUses::Robust,
                    alpha,
                    self.options.tolerance,
                ),
                None => compare_classical_robust(
                    wv.clone(),
                    w,
                    FitUses::Classical,
                    alpha,
                    self.options.tolerance,
                ),
            }),
            Err(e) => {
                notes.push(format!(
                    "the classical and robust WVs could not be compared: {e}"
                ));
                None
            }
        }
    }
}

/// The contamination check of WVs computed before (streamed or pooled): `robust` is `None`
/// when the check is off, an error text when the robust WV could not be computed (a note).
fn compared(
    classical: &WaveletVariance,
    robust: Option<Result<&WaveletVariance, &String>>,
    uses: FitUses,
    alpha: f64,
    tolerance: f64,
    notes: &mut Vec<String>,
) -> Option<Contamination> {
    match robust? {
        Ok(r) => Some(compare_classical_robust(
            classical.clone(),
            r.clone(),
            uses,
            alpha,
            tolerance,
        )),
        Err(e) => {
            notes.push(format!(
                "the classical and robust WVs could not be compared: {e}"
            ));
            None
        }
    }
}

/// The column an axis' errors name.
struct AxisErrors<'a> {
    column: &'a str,
}

impl AxisErrors<'_> {
    fn engine(&self, source: crate::InputError) -> CalibError {
        CalibError::Engine {
            column: self.column.to_string(),
            source,
        }
    }
    fn fit(&self, source: FitError) -> CalibError {
        CalibError::Fit {
            column: self.column.to_string(),
            source,
        }
    }
    fn selection(&self, source: SelectionError) -> CalibError {
        CalibError::Selection {
            column: self.column.to_string(),
            source: Box::new(source),
        }
    }
}

impl Calibration {
    /// An axis' samples (`values`, in the recording's unit) in the unit its calibration
    /// reports (SI when the unit is known): what a later analysis of the same axis
    /// (`--covariate`, `--augment`) fits beside the calibration's WV.
    pub(crate) fn samples_in_si(
        &self,
        axis: &AxisCalibration,
        values: &[f64],
    ) -> Result<Vec<f64>, CalibError> {
        let mut notes = Vec::new();
        let unit = self.unit_of(
            &axis.column,
            axis.kind,
            axis.data_unit.as_deref(),
            &mut notes,
        )?;
        let to_si = unit.map_or(1.0, |u| u.to_si());
        Ok(values.iter().map(|v| v * to_si).collect())
    }
}

/// The samples in SI when the unit converts them (`None` when they are SI already or are not
/// in memory).
fn in_si(data: &AxisData<'_>, unit: Option<SignalUnit>) -> Option<Vec<f64>> {
    let to_si = unit.map_or(1.0, |u| u.to_si());
    match data {
        AxisData::Series(values) | AxisData::Gapped { series: values, .. } if to_si != 1.0 => {
            Some(values.iter().map(|v| v * to_si).collect())
        }
        _ => None,
    }
}

/// The overlapping Allan variance of an axis: of its samples, or twice its classical Haar WV
/// (docs/methods.md §3.4: exactly the same), pooled as the pooled WV is.
fn allan_of(
    data: &AxisData<'_>,
    freq_hz: f64,
    alpha: f64,
) -> Result<AllanVariance, crate::InputError> {
    Ok(match data {
        AxisData::Series(x) => allan_variance(
            x,
            freq_hz,
            &AllanOptions {
                alpha,
                ..AllanOptions::default()
            },
        )?,
        AxisData::Streamed { wv, .. } => allan_from_wv(wv)?,
        AxisData::Pooled { classical, .. } => allan_from_wv(classical.wv())?,
        AxisData::Gapped { .. } => {
            unreachable!("Calibration::axis turns a gapped series into its gap-aware WV first")
        }
    })
}

/// The binned Welch PSD of an axis in `unit`²/Hz: of its samples in memory (borrowed, one
/// segment of at most 2^16 samples besides), or as the streamed pass computed it; `None` with a
/// note when neither is at hand or the series is shorter than one segment.
fn psd_of(data: &AxisData<'_>, freq_hz: f64, unit: &str, notes: &mut Vec<String>) -> Option<Psd> {
    let psd = match data {
        AxisData::Series(x) => welch_psd(x, freq_hz).map_err(|e| e.to_string()),
        AxisData::Streamed { psd: Some(p), .. } => p.as_deref().cloned().map_err(String::clone),
        AxisData::Streamed { psd: None, .. } => Err(
            "the recording was streamed without its spectral pass (it rides on the robust check, which the options turn off)".to_string(),
        ),
        AxisData::Pooled { .. } => {
            Err("a pooled calibration has no single series to take it from".to_string())
        }
        AxisData::Gapped { .. } => unreachable!("Calibration::axis turns a gapped series into its gap-aware WV first"),
    };
    match psd {
        Ok(p) => Some(p.binned(BINNED_POINTS).in_unit(unit)),
        Err(why) => {
            notes.push(format!("no power spectral density: {why}"));
            None
        }
    }
}

/// How the selected fit reads as the canonical model (a drift read as a random walk, ...),
/// then what the identified fit's canonical model adds; a reading of both is said once, with the
/// identified fit's values.
fn readings(selection: &ModelSelection, canonical: &CanonicalModel) -> Vec<String> {
    // the selection's readings first, unless the final model reads the same thing of the same
    // process (then with its own values: a refinement refits every term)
    let mut readings: Vec<String> = selection
        .selected_canonical
        .readings
        .iter()
        .filter(|r| !canonical.readings.iter().any(|c| c.same_subject(r)))
        .map(ToString::to_string)
        .collect();
    for r in &canonical.readings {
        let text = r.to_string();
        if !readings.contains(&text) {
            readings.push(text);
        }
    }
    readings
}

/// The navigation read-offs of one axis ([`Readoff::read`]).
struct ReadOffs {
    noise_density: Option<Estimate>,
    random_walk: Option<Estimate>,
    bias_instability: Option<Estimate>,
    quantization: Option<Estimate>,
    rate_ramp: Option<Estimate>,
    gauss_markov_bias: Option<GaussMarkovBias>,
}

/// One column of a recording, as the pipeline takes it.
pub(crate) struct InputAxis<'a> {
    pub(crate) column: &'a str,
    pub(crate) info: &'a SensorInfo,
    pub(crate) data: AxisData<'a>,
}

/// What one axis is calibrated from: its samples in memory, or its WVs computed while the
/// recording was streamed (bounded memory at any length).
#[derive(Debug, Clone)]
pub(crate) enum AxisData<'a> {
    /// The samples.
    Series(&'a [f64]),
    /// The classical WV and, for the contamination check, the robust one (`None`: no check),
    /// and the Welch PSD accumulated in the same pass (`None`: no such pass).
    Streamed {
        wv: Box<WaveletVariance>,
        robust: Option<Result<Box<WaveletVariance>, String>>,
        psd: Option<Result<Box<Psd>, String>>,
    },
    /// The pooled WVs of several recordings (docs/methods.md §5.12), already in SI: the
    /// classical one and the robust one (the fit's when the options ask for a robust WV, else
    /// the contamination check's; `None`: neither).
    Pooled {
        classical: Box<PooledWv>,
        robust: Option<Result<Box<PooledWv>, String>>,
    },
    /// The samples of a recording with gaps in its time stamps, and the gaps (docs/methods.md
    /// §1.11): turned into the gap-aware WV by [`Calibration::axis`], as a streamed one.
    Gapped {
        series: &'a [f64],
        gaps: &'a [crate::imu::Gap],
    },
}

impl AxisData<'_> {
    /// The data times `to_si` in every value (its WVs times `to_si^2`); the samples in memory
    /// are converted by [`in_si`] instead.
    fn scaled(self, to_si: f64) -> Self {
        match self {
            AxisData::Streamed { wv, robust, psd } if to_si != 1.0 => AxisData::Streamed {
                wv: Box::new(wv.scaled(to_si * to_si)),
                robust: robust.map(|r| r.map(|w| Box::new(w.scaled(to_si * to_si)))),
                psd: psd.map(|r| r.map(|p| Box::new(p.scaled(to_si * to_si)))),
            },
            d => d,
        }
    }

    fn samples(&self) -> usize {
        match self {
            AxisData::Series(x) => x.len(),
            AxisData::Streamed { wv, .. } => wv.n,
            AxisData::Pooled { classical, .. } => classical.wv().n(),
            AxisData::Gapped { series, .. } => series.len(),
        }
    }
}

/// The read-off of one axis: canonical terms as functions of the identified fit's estimates,
/// with delta-method intervals from its covariance.
struct Readoff<'a> {
    /// Relative standard errors of the read-offs left without an interval (drained by
    /// [`Readoff::estimate`] into the estimate's `source`).
    undetermined: std::cell::RefCell<Vec<f64>>,
    /// Index of the first parameter of each component of the fit.
    offsets: Vec<usize>,
    fit: &'a GmwmFit,
    canonical: &'a CanonicalModel,
    inference: &'a Inference,
    kind: Option<SignalKind>,
    unit: &'a str,
    freq_hz: f64,
    z: f64,
}

impl<'a> Readoff<'a> {
    fn new(
        fit: &'a GmwmFit,
        canonical: &'a CanonicalModel,
        inference: &'a Inference,
        kind: Option<SignalKind>,
        unit: &'a str,
        freq_hz: f64,
    ) -> Self {
        Readoff {
            undetermined: std::cell::RefCell::new(Vec::new()),
            offsets: fit
                .model
                .components()
                .iter()
                .scan(0, |k, c| {
                    let o = *k;
                    *k += c.kind.n_params();
                    Some(o)
                })
                .collect(),
            fit,
            canonical,
            inference,
            kind,
            unit,
            freq_hz,
            z: inference.z,
        }
    }

    /// Every read-off of the axis: N, K (an upper bound from the Allan variance's band when no
    /// term carries a random walk), Q, R, the Gauss–Markov bias and B of the IEEE read-off;
    /// what a user should know goes to `notes`.
    fn read(&self, allan: &AllanVariance, ieee: &IeeeReadoff, notes: &mut Vec<String>) -> ReadOffs {
        let noise_density = self.noise_density(notes);
        let random_walk = self.bounded_random_walk(allan, notes);
        let quantization = self.single(Role::Quantization, NoiseTerm::Quantization);
        let rate_ramp = self.single(Role::Drift, NoiseTerm::RateRamp);
        let gauss_markov_bias = self.gauss_markov();
        // B from the flicker term when the model has one, else the IEEE read-off (an upper
        // bound when the Allan deviation shows no floor)
        let bias_instability = self
            .single(Role::Flicker, NoiseTerm::BiasInstability)
            .or_else(|| {
                ieee.b.value.map(|value| {
                    let floor = ieee.b.ci_low.is_some();
                    let e = self.estimate(
                        NoiseTerm::BiasInstability,
                        value,
                        (ieee.b.ci_low, ieee.b.ci_high),
                        if floor {
                            format!(
                                "IEEE 952: min Allan deviation / 0.664 at {} s",
                                crate::fit::report::significant(ieee.b.at_tau_s, 4)
                            )
                        } else {
                            format!(
                                "IEEE 952: no Allan floor reached; upper bound min Allan deviation / 0.664 at {} s",
                                crate::fit::report::significant(ieee.b.at_tau_s, 4)
                            )
                        },
                    );
                    if floor {
                        e
                    } else {
                        Estimate {
                            status: EstimateStatus::UpperBound,
                            ..e
                        }
                    }
                })
            });
        ReadOffs {
            noise_density,
            random_walk,
            bias_instability,
            quantization,
            rate_ramp,
            gauss_markov_bias,
        }
    }

    /// Index of the first parameter of each component of the fit.
    fn offsets(&self) -> &[usize] {
        &self.offsets
    }

    /// An estimate with its forms.
    fn estimate(
        &self,
        term: NoiseTerm,
        value: f64,
        (ci_low, ci_high): (Option<f64>, Option<f64>),
        source: String,
    ) -> Estimate {
        let (status, source) = match self.undetermined.borrow_mut().drain(..).reduce(f64::max) {
            Some(se_rel) => (
                EstimateStatus::Undetermined,
                format!(
                    "{source}; not determined by the data (relative standard error {:.0}%): no interval",
                    100.0 * se_rel
                ),
            ),
            None => (EstimateStatus::Estimated, source),
        };
        Estimate {
            value,
            ci_low,
            ci_high,
            unit: si_unit(term, self.kind, self.unit),
            status,
            source,
            forms: Some(forms(term, self.kind, self.unit, value, self.freq_hz)),
        }
    }

    /// The quantity `q(theta)` over the parameters `params` of the fit: value and interval,
    /// the latter on the log scale by the delta method with the inference covariance
    /// (`None` when a parameter has no covariance, e.g. at the boundary).
    fn delta(
        &self,
        params: &[usize],
        q: &dyn Fn(&[f64]) -> f64,
    ) -> (f64, Option<f64>, Option<f64>) {
        let theta = &self.fit.theta;
        let value = q(theta);
        let cov = &self.inference.covariance;
        let mut grad = Vec::with_capacity(params.len());
        for &k in params {
            let h = DELTA_STEP * theta[k].abs().max(f64::MIN_POSITIVE);
            let mut up = theta.clone();
            let mut down = theta.clone();
            up[k] += h;
            down[k] -= h;
            grad.push((q(&up) - q(&down)) / (2.0 * h));
        }
        let mut var = 0.0;
        for (a, &i) in params.iter().enumerate() {
            for (b, &j) in params.iter().enumerate() {
                match cov.get(i).and_then(|r| r.get(j)).copied().flatten() {
                    Some(c) => var += grad[a] * grad[b] * c,
                    None => return (value, None, None),
                }
            }
        }
        if !(value > 0.0 && var.is_finite() && var >= 0.0) {
            return (value, None, None);
        }
        let se_rel = var.sqrt() / value;
        if se_rel > UNDETERMINED_SE_REL {
            self.undetermined.borrow_mut().push(se_rel);
            return (value, None, None);
        }
        let rel = self.z * se_rel;
        (
            value,
            Some(value * elementary::exp(-rel)),
            Some(value * elementary::exp(rel)),
        )
    }

    /// Parameter indices of the components `from`.
    fn params_of(&self, from: &[usize]) -> Vec<usize> {
        let offsets = self.offsets();
        let comps = self.fit.model.components();
        from.iter()
            .filter_map(|&c| Some((offsets.get(c)?, comps.get(c)?.kind.n_params())))
            .flat_map(|(&o, n)| o..o + n)
            .collect()
    }

    /// Long-run per-sample variance of the fit's component `c` at `theta`: `sigma2` of a WN,
    /// `sigma2 / (1 - phi)^2` of an AR1/GM (the white noise it is at long scales).
    fn white_variance(&self, c: usize, theta: &[f64]) -> Option<f64> {
        let o = *self.offsets().get(c)?;
        let kind = self.fit.model.components().get(c)?.kind;
        let values = &theta[o..o + kind.n_params()];
        match spec(kind) {
            s if s.role == Role::WhiteNoise => Some(values[0]),
            s => Some(long_run_variance((s.markov?.ar1)(values, self.freq_hz))),
        }
    }

    /// N from the canonical white-noise term; without one, from the fastest correlated term's
    /// long-run density (saying so).
    fn noise_density(&self, notes: &mut Vec<String>) -> Option<Estimate> {
        let f = self.freq_hz;
        let (from, source) = match self.canonical.term_of(Role::WhiteNoise) {
            Some(t) => (t.from.clone(), "WN term".to_string()),
            None => {
                let fastest = self.fastest_correlated()?;
                notes.push(format!(
                    "no white-noise term: the noise density is the long-run density of the fastest correlated term (component {fastest})"
                ));
                (
                    vec![fastest],
                    "long-run density of the fastest Gauss–Markov term".to_string(),
                )
            }
        };
        let q = |theta: &[f64]| -> f64 {
            (from
                .iter()
                .map(|&c| self.white_variance(c, theta).unwrap_or(f64::NAN))
                .sum::<f64>()
                / f)
                .sqrt()
        };
        let (value, lo, hi) = self.checked(
            &from,
            &q,
            self.canonical
                .physical_of(Role::WhiteNoise, "white_noise_density"),
        );
        Some(self.estimate(NoiseTerm::NoiseDensity, value, (lo, hi), source))
    }

    /// Value and interval of `q` over the components `from`, the interval dropped when the
    /// canonical value (`expected`) is not `q` of the fit (a refit term).
    fn checked(
        &self,
        from: &[usize],
        q: &dyn Fn(&[f64]) -> f64,
        expected: Option<f64>,
    ) -> (f64, Option<f64>, Option<f64>) {
        let params = self.params_of(from);
        let (value, lo, hi) = self.delta(&params, q);
        match expected {
            // a refit term within a quarter of the interval of the fit's own value: the two are
            // the same estimate to the data, and the fit's value keeps its interval
            Some(e) if (e - value).abs() > SAME_VALUE_REL * e.abs() => match (lo, hi) {
                (Some(l), Some(h)) if (e - value).abs() <= 0.25 * (h - l) => (value, lo, hi),
                _ => (e, None, None),
            },
            _ => (value, lo, hi),
        }
    }

    /// The fit's AR1/GM component with the shortest correlation time.
    fn fastest_correlated(&self) -> Option<usize> {
        self.correlated_by_time().into_iter().next().map(|(c, _)| c)
    }

    /// The fit's components that the canonical model keeps as correlated noise (an AR1 it
    /// reads as white noise or a random walk is not one).
    fn kept_correlated(&self) -> Vec<usize> {
        self.canonical
            .terms
            .iter()
            .filter(|t| spec(t.kind).role == Role::Correlated && t.from.len() == 1)
            .map(|t| t.from[0])
            .collect()
    }

    /// The AR1/GM components the canonical model keeps, with their correlation times, fastest
    /// first.
    fn correlated_by_time(&self) -> Vec<(usize, f64)> {
        let offsets = self.offsets();
        let theta = &self.fit.theta;
        let kept = self.kept_correlated();
        let mut out: Vec<(usize, f64)> = self
            .fit
            .model
            .components()
            .iter()
            .enumerate()
            .filter(|(c, _)| kept.contains(c))
            .filter_map(|(c, comp)| {
                let o = offsets[c];
                let values = &theta[o..o + comp.kind.n_params()];
                let t = (spec(comp.kind).markov?.correlation_time_s)(values, self.freq_hz);
                // an AR1 with phi <= 0 has no correlation time
                (t > 0.0 && t.is_finite()).then_some((c, t))
            })
            .collect();
        out.sort_by(|a, b| a.1.total_cmp(&b.1));
        out
    }

    /// K never beyond what the data allow: a random walk adds `K^2 tau / 3` to the Allan
    /// variance, so the upper end of the AV's band bounds K at every cluster time
    /// ([`random_walk_upper_bound`]). With a random-walk term its estimate (and interval) is
    /// capped at that bound, saying so; without one the bound itself is K, marked
    /// [`EstimateStatus::UpperBound`] (a Gauss–Markov term's driving noise is not a random walk
    /// the data show: on a real gyroscope it gave K 30x above the bound).
    fn bounded_random_walk(
        &self,
        allan: &AllanVariance,
        notes: &mut Vec<String>,
    ) -> Option<Estimate> {
        let sig = |x: f64| crate::fit::report::significant(x, 4);
        let bound = random_walk_upper_bound(allan);
        let term = self.random_walk_term();
        match (term, bound) {
            (Some(est), Some((b, tau_s)))
                if est.value > b || est.ci_high.is_some_and(|h| h > b) =>
            {
                let capped_value = est.value > b;
                let what = if capped_value {
                    format!("the random-walk term's K = {}", sig(est.value))
                } else {
                    format!(
                        "the upper end of the random-walk term's interval ({}, K = {})",
                        est.ci_high.map_or_else(|| "none".to_string(), sig),
                        sig(est.value)
                    )
                };
                notes.push(format!(
                    "{what} exceeds what the Allan variance allows: at most {} (the upper end of its band at {} s); {} is exported",
                    sig(b),
                    sig(tau_s),
                    if capped_value { "the bound" } else { "the estimate, its interval capped at the bound," }
                ));
                let value = est.value.min(b);
                Some(Estimate {
                    status: if capped_value {
                        EstimateStatus::UpperBound
                    } else {
                        est.status
                    },
                    ci_low: est.ci_low.map(|l| l.min(value)),
                    ci_high: Some(b),
                    source: format!(
                        "{}; capped at the Allan-band bound at {} s",
                        est.source,
                        sig(tau_s)
                    ),
                    forms: Some(forms(
                        NoiseTerm::RandomWalk,
                        self.kind,
                        self.unit,
                        value,
                        self.freq_hz,
                    )),
                    value,
                    ..est
                })
            }
            (Some(est), _) => Some(est),
            (None, Some((b, tau_s))) => {
                let gm = self
                    .correlated_by_time()
                    .last()
                    .and_then(|&(slowest, _)| self.gm_quantity(slowest, "driving_noise_density"));
                notes.push(format!(
                    "no random walk detected: its density is at most {} (the upper end of the Allan variance's band at {} s, where the bound is tightest), exported as an upper bound{}",
                    sig(b),
                    sig(tau_s),
                    gm.map_or_else(String::new, |g| format!(
                        "; the slowest Gauss–Markov term's driving-noise density, {}, is not a random walk and is not exported as one",
                        sig(g.0)
                    ))
                ));
                Some(Estimate {
                    status: EstimateStatus::UpperBound,
                    ..self.estimate(
                        NoiseTerm::RandomWalk,
                        b,
                        (None, Some(b)),
                        format!(
                            "not detected: upper bound from the Allan variance's band at {} s",
                            sig(tau_s)
                        ),
                    )
                })
            }
            (None, None) => None,
        }
    }

    /// K from the canonical random-walk term, `None` without one.
    fn random_walk_term(&self) -> Option<Estimate> {
        let f = self.freq_hz;
        let t = self.canonical.term_of(Role::RandomWalk)?;
        let from = t.from.clone();
        let o = self.params_of(&from);
        let q = |theta: &[f64]| (o.iter().map(|&k| theta[k]).sum::<f64>() * f).sqrt();
        let (value, lo, hi) = self.checked(
            &from,
            &q,
            self.canonical
                .physical_of(Role::RandomWalk, "rate_random_walk_density"),
        );
        Some(self.estimate(
            NoiseTerm::RandomWalk,
            value,
            (lo, hi),
            "RW term".to_string(),
        ))
    }

    /// A physical quantity of the fit's AR1/GM component `c` with its interval.
    fn gm_quantity(&self, c: usize, name: &str) -> Option<(f64, Option<f64>, Option<f64>)> {
        let comp = self.fit.model.components().get(c)?;
        let o = *self.offsets().get(c)?;
        let n = comp.kind.n_params();
        let kind = comp.kind;
        let f = self.freq_hz;
        let q = |theta: &[f64]| {
            crate::fit::report::physical_parameters(kind, c, &theta[o..o + n], f, None)
                .into_iter()
                .find(|p| p.name == name)
                .map_or(f64::NAN, |p| p.value)
        };
        let params: Vec<usize> = (o..o + n).collect();
        let out = self.delta(&params, &q);
        out.0.is_finite().then_some(out)
    }

    /// Q or R from the canonical term of a role (one parameter, monotone in it).
    fn single(&self, role: Role, term: NoiseTerm) -> Option<Estimate> {
        let t = self.canonical.term_of(role)?;
        let kind = t.kind;
        let source = format!("{} term", t.process);
        let name = t.physical.first()?.name;
        let from = t.from.clone();
        let o = self.params_of(&from);
        let f = self.freq_hz;
        let q = |theta: &[f64]| {
            let v: f64 = o.iter().map(|&k| theta[k]).sum();
            crate::fit::report::physical_parameters(kind, 0, &[v], f, None)
                .into_iter()
                .find(|p| p.name == name)
                .map_or(f64::NAN, |p| p.value)
        };
        let (value, lo, hi) = self.checked(&from, &q, Some(t.physical[0].value));
        Some(self.estimate(term, value, (lo, hi), source))
    }

    /// The slowest correlated term the canonical model keeps, as a Gauss–Markov bias: the bias
    /// a navigation filter carries is the term that wanders longest (a sub-second one is
    /// coloured noise, not bias).
    fn gauss_markov(&self) -> Option<GaussMarkovBias> {
        let (slowest, _) = *self.correlated_by_time().last()?;
        self.gauss_markov_of(slowest)
    }

    /// The Gauss–Markov form of the fit's AR1/GM component `dominant`.
    fn gauss_markov_of(&self, dominant: usize) -> Option<GaussMarkovBias> {
        let t = self.gm_quantity(dominant, "correlation_time")?;
        let s = self.gm_quantity(dominant, "gm_std")?;
        let d = self.gm_quantity(dominant, "driving_noise_density")?;
        let source = format!("Gauss–Markov term (component {dominant})");
        Some(GaussMarkovBias {
            correlation_time: self.estimate(
                NoiseTerm::GmCorrelationTime,
                t.0,
                (t.1, t.2),
                source.clone(),
            ),
            sigma: self.estimate(NoiseTerm::GmSigma, s.0, (s.1, s.2), source.clone()),
            driving_density: self.estimate(NoiseTerm::GmDrivingDensity, d.0, (d.1, d.2), source),
        })
    }
}

/// An upper bound on the random-walk density K of a recording whose model has no random walk:
/// a random walk adds `K^2 tau / 3` to the Allan variance (docs/methods.md §14.2), so at every
/// cluster time `K <= sqrt(3 AV_high(tau) / tau)` with `AV_high` the upper end of the AV's band;
/// the tightest of these, with its cluster time. `None` without a finite positive bound.
fn random_walk_upper_bound(av: &AllanVariance) -> Option<(f64, f64)> {
    av.ci_high
        .iter()
        .zip(&av.tau_s)
        .map(|(&hi, &tau)| ((3.0 * hi / tau).sqrt(), tau))
        .filter(|(k, _)| k.is_finite() && *k > 0.0)
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

/// The terms refinement tries for `base`'s missed scales (at most three for the most deviant
/// misses, then the filter): a vibration line `SIN()` at a hump, at the first scales or at the
/// dip beside an overshoot (its WV peaks at `tau ~ 0.742 / omega` samples), a flicker `FN()`
/// for a floor, a `RW()` for the longest scales above the model; and the sensor's
/// moving-average filter `MAF(2)`, `MAF(4)` when the first scales fall slower than white
/// noise's. A kind that occurs once (FN, RW, MAF, ...) and is already in the model is refused
/// by the model's parser, so its candidate drops out; a `SIN()` may join the model's lines, and
/// [`lines_hold`] keeps each of them where it was.
fn refinement_terms(
    base: &GmwmFit,
    verdict: &FitVerdict,
    freq_hz: f64,
    tolerance: f64,
    psd: Option<&Psd>,
) -> Vec<String> {
    let scales = &verdict.scales;
    // a vibration line whose WV peaks at tau, when the spectrum (where there is one) shows a
    // line near its frequency: else a sinusoid would only bend the model towards the WV's shape
    let sin_at = |tau_s: f64| {
        let omega = (0.742 / (tau_s * freq_hz)).min(0.45);
        psd.map_or(true, |p| has_spectral_line(p, omega * freq_hz))
            .then(|| format!("SIN(omega={omega})"))
    };
    let mut terms: Vec<String> = Vec::new();
    for miss in super::verdict::misses(base, verdict) {
        let term = match miss.cause {
            "hump" => sin_at(miss.tau_s),
            // a vibration line near the Nyquist end (the filter is tried below); not at the
            // first scale, where a line at 0.37 cycles per sample would take the white noise's
            // variance (the filter's shape is the likelier cause there)
            "sensor filter" if miss.tau_s * freq_hz > 2.5 => sin_at(miss.tau_s),
            "floor" => Some("FN()".to_string()),
            "long scales" if miss.deviation < 0.0 => Some("RW()".to_string()),
            "overshoot" => {
                // a sharper hump than the model's correlated term: the dip within two octaves
                let j = scales.iter().position(|s| s.tau_s == miss.tau_s);
                j.and_then(|j| {
                    (j.saturating_sub(2)..(j + 3).min(scales.len().saturating_sub(2)))
                        .filter(|&k| scales[k].deviation < -0.5 * tolerance)
                        .min_by(|&a, &b| scales[a].deviation.total_cmp(&scales[b].deviation))
                        .and_then(|k| sin_at(scales[k].tau_s))
                })
            }
            _ => None,
        };
        if let Some(t) = term {
            if !terms.contains(&t) {
                terms.push(t);
            }
        }
        if terms.len() == 3 {
            break;
        }
    }
    // first scales below white noise's halving (nu2_1 / nu2_2 = 2): the sensor's own filter
    // may shape them, whatever the worst miss
    if scales.len() >= 2 && scales[0].empirical < FILTERED_FIRST_RATIO * scales[1].empirical {
        terms.extend(["MAF(2)".to_string(), "MAF(4)".to_string()]);
    }
    terms
}

/// Whether the binned spectrum `psd` has a line near `f0` Hz, where a sinusoid whose Haar WV
/// peaks at the matching scale would put it: a local maximum within an octave of `f0` at least
/// `LINE_OVER_MEDIAN` times the median density within two octaves (a line, not a slope).
pub(crate) fn has_spectral_line(psd: &Psd, f0: f64) -> bool {
    spectral_line_within(psd, f0, 2.0)
}

/// The vibration lines of `canonical`: each term's physical `frequency`, Hz.
fn vibration_lines(canonical: &CanonicalModel) -> Vec<f64> {
    canonical
        .terms
        .iter()
        .flat_map(|t| &t.physical)
        .filter(|p| p.name == "frequency")
        .map(|p| p.value)
        .collect()
}

/// The line a refinement `term` proposes (`SIN(omega=...)`, [`refinement_terms`]), Hz.
fn proposed_line_hz(term: &str, freq_hz: f64) -> Option<f64> {
    term.strip_prefix("SIN(omega=")
        .and_then(|r| r.strip_suffix(')'))
        .and_then(|w| w.parse::<f64>().ok())
        .map(|omega| omega * freq_hz)
}

/// Whether a refit's vibration lines are measured, not bent into place: with a spectrum, each
/// lies on a spectral line within a factor [`LINE_MATCH`] (the ADIS accelerometers' roll-off
/// above 10 Hz otherwise took a 13.6 Hz "line" of three times the power of the 10 Hz one and
/// cut N by 27%); without one (a saved WV, a pooled calibration), each line of `required` (the
/// refined model's, and the one a term proposed where the WV's shape put it) still has a fitted
/// line within that factor (on the precomputed WV of adis_16405_imu1 accel_x a line proposed
/// at 9.3 Hz moved to 13.6 Hz and N fell 31% below the spectrum's level, while the lines the
/// shared recordings' spectra confirm moved by 0.89 to 1.09 times).
fn lines_hold(canonical: &CanonicalModel, psd: Option<&Psd>, required: &[f64]) -> bool {
    let fitted = vibration_lines(canonical);
    match psd {
        Some(psd) => fitted
            .iter()
            .all(|&f| spectral_line_within(psd, f, LINE_MATCH)),
        None => required.iter().all(|&f0| {
            fitted
                .iter()
                .any(|&f| f >= f0 / LINE_MATCH && f <= f0 * LINE_MATCH)
        }),
    }
}

/// How close to a spectral line a fitted vibration frequency must lie, or, without a spectrum,
/// to where it was proposed ([`lines_hold`]): two bins of the binned spectrum (about 11% apart); the shared recordings'
/// fitted lines lie within 11% of their bins and within 0.89 to 1.09 times their proposals, the
/// roll-off's 1.36 times from its bin and 1.47 times from its proposal.
pub(crate) const LINE_MATCH: f64 = 1.25;

/// [`has_spectral_line`] with the local maximum within a factor `within` of `f0`.
pub(crate) fn spectral_line_within(psd: &Psd, f0: f64, within: f64) -> bool {
    let (f, d) = (psd.frequency_hz(), psd.density());
    let around: Vec<f64> = f
        .iter()
        .zip(d)
        .filter(|(&f, _)| f >= f0 / 4.0 && f <= 4.0 * f0)
        .map(|(_, &d)| d)
        .collect();
    if around.len() < 3 {
        return true; // too coarse to tell: no veto
    }
    let mut sorted = around.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    (1..d.len().saturating_sub(1)).any(|k| {
        f[k] >= f0 / within
            && f[k] <= within * f0
            && d[k] > d[k - 1]
            && d[k] >= d[k + 1]
            && d[k] >= LINE_OVER_MEDIAN * median
    })
}

/// How far above the local median a spectral line must rise ([`has_spectral_line`]): the
/// binned Welch density scatters by about a quarter at the lowest frequencies of 2^18 samples,
/// so that the highest of an octave of white-noise bins stays below 1.7 times the median.
const LINE_OVER_MEDIAN: f64 = 2.0;

/// `nu2_1 / nu2_2` below which the first scales look filtered (white noise gives 2; a
/// 2-sample moving average 0.8).
const FILTERED_FIRST_RATIO: f64 = 1.9;
