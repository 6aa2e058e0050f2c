//! The pooled calibration (`gmwm calibrate --pool`, docs/methods.md §5.12): one model for a
//! sensor from several of its recordings.
//!
//! Each recording's axis is converted to SI with its own unit, its WV (and the robust one the
//! options ask for) computed, and the recordings' WVs pooled level by level
//! ([`PooledWv`]: their inverse-variance mean, whose covariance is the recordings' own). The
//! pipeline then runs on the pooled WV as on one recording's: the WIC selection with the pooled
//! covariance behind the optimism, the identified fit with its sandwich intervals, the read-off,
//! the IEEE read-off from the pooled Allan variance (twice the pooled Haar WV, docs/methods.md
//! §3.4) and the verdict against the pooled band. A single GMWM on the pooled WV is MS-GMWM
//! with precision weights (§5.12), so the estimates are those of one model fitted to all the
//! recordings.
//!
//! What a pooled calibration adds: for each axis and recording, a note comparing the
//! recording's WV with the pooled WV of the others, scale by scale and without a model (the
//! distribution-free comparison of §7.7), and a check line when a recording differs at more
//! scales than chance: those recordings may not share one model, and the pooled model is then
//! their average (which `gmwm same-model` tests with a model).

use super::pipeline::{AxisData, InputAxis};
use super::{CalibError, Calibration, CalibrationReport};
use crate::error::ParamError;
use crate::imu::{Imu, Sensor, SensorInfo};
use crate::inference::same_model::{compare_wvs, WvComparison};
use crate::inference::Progress;
use crate::math::elementary;
use crate::units::{SignalKind, SignalUnit};
use crate::variance::pooled::PooledWv;
use crate::variance::wv::{wavelet_variance, WaveletVariance, WvOptions};
use rayon::prelude::*;
use serde::Serialize;

/// One recording of a pooled calibration.
///
/// Wire format: `name`, `samples` (per axis), `duration_s`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PooledInput {
    /// The recording's name, as the caller gave it (`gmwm` gives the file).
    pub name: String,
    /// Samples per axis.
    pub samples: usize,
    /// Its length, s.
    pub duration_s: f64,
}

impl Calibration {
    /// Calibrates one model for the sensor of all `recordings` (named, module doc): the
    /// report of [`Calibration::run`] on their pooled WVs, its `recordings` listing them; each
    /// scored candidate is reported to `progress`. Reached through
    /// [`CalibrationSource::Pooled`](crate::calib::CalibrationSource::Pooled).
    ///
    /// # Errors
    /// [`CalibError::Pool`] naming the recording: fewer than two, a rate more than 1% from
    /// the first's, an inertial axis of the first that it lacks, a unit known in one recording
    /// and not in another, a WV that cannot be computed; the errors of [`Calibration::run`].
    pub(crate) fn run_pooled(
        &self,
        recordings: &[(&str, &Imu)],
        progress: &dyn Progress,
    ) -> Result<CalibrationReport, CalibError> {
        let freq_hz = check_pool(recordings)?;
        let names: Vec<String> = recordings.iter().map(|(n, _)| n.to_string()).collect();
        let mut checks = Vec::new();
        let columns = self.pooled_columns(recordings, &mut checks)?;
        let (classical_opts, robust_opts) = self.pooled_wv_options();
        let mut wvs = recording_wvs(
            &columns,
            recordings.len(),
            freq_hz,
            &classical_opts,
            robust_opts,
        )
        .into_iter();
        let mut data = Vec::with_capacity(columns.len());
        let mut agreement = Vec::with_capacity(columns.len());
        for column in &columns {
            let (pooled, agreed) =
                self.pool_column(column.name, recordings, &mut wvs, robust_opts, &names)?;
            data.push(pooled);
            agreement.push(agreed);
        }
        // the pooled WVs are in SI already; the first recording's unit names the data's
        let infos: Vec<SensorInfo> = columns
            .iter()
            .map(|c| SensorInfo {
                unit: c.units[0].map(|u| u.symbol().to_string()),
                ..c.axis.info.clone()
            })
            .collect();
        let axes: Vec<InputAxis<'_>> = columns
            .iter()
            .zip(&infos)
            .zip(data)
            .map(|((c, info), (classical, robust))| InputAxis {
                column: c.name,
                info,
                data: AxisData::Pooled { classical, robust },
            })
            .collect();
        let samples: usize = recordings.iter().map(|(_, imu)| imu.len()).sum();
        let label = format!("{} recordings pooled", names.len());
        let mut report = self.run_axes(Some(&label), freq_hz, samples, axes, checks, progress)?;
        report.recordings = recordings
            .iter()
            .map(|(name, imu)| PooledInput {
                name: name.to_string(),
                samples: imu.len(),
                duration_s: imu.len() as f64 / freq_hz,
            })
            .collect();
        annotate_agreement(&mut report, &columns, agreement, names.len());
        Ok(report)
    }

    /// Per inertial axis of the first recording: the axis of every recording and its unit
    /// (docs/methods.md §5.12: the recordings are converted to SI before pooling, with a check
    /// line when their units differ).
    fn pooled_columns<'a>(
        &self,
        recordings: &[(&str, &'a Imu)],
        checks: &mut Vec<String>,
    ) -> Result<Vec<PoolColumn<'a>>, CalibError> {
        let (first_name, first) = recordings[0];
        let mut columns = Vec::new();
        for axis in first.axes() {
            let column = axis.column.name.as_str();
            let kind = match axis.info.sensor {
                Sensor::Gyroscope => Some(SignalKind::Gyroscope),
                Sensor::Accelerometer => Some(SignalKind::Accelerometer),
                Sensor::Other => continue,
            };
            let mut series = Vec::with_capacity(recordings.len());
            let mut units = Vec::with_capacity(recordings.len());
            for (name, imu) in recordings {
                let Some(a) = imu.axes().iter().find(|a| a.column.name == column) else {
                    return Err(pool_error(
                        name,
                        format!(
                            "no column {} ({first_name} has it): pooled recordings need the same columns",
                            crate::imu::quote(column)
                        ),
                    ));
                };
                let mut ignored = Vec::new();
                let unit = self.unit_of(column, kind, a.info.unit.as_deref(), &mut ignored)?;
                series.push(a.values());
                units.push(unit);
            }
            if let Some(k) = units.iter().position(|u| u.is_some() != units[0].is_some()) {
                let (known, unknown) = if units[0].is_some() { (0, k) } else { (k, 0) };
                return Err(pool_error(
                    recordings[unknown].0,
                    format!(
                        "column {column}: unit unknown, while {} states {}: give --gyro-unit/--accel-unit or convert the recordings to one unit",
                        recordings[known].0,
                        units[known].map(|u| u.symbol()).unwrap_or_default()
                    ),
                ));
            }
            let mut distinct: Vec<&str> = units.iter().flatten().map(|u| u.symbol()).collect();
            distinct.dedup();
            if distinct.len() > 1 {
                checks.push(format!(
                    "column {column}: the recordings are in {}; each is converted to SI before pooling",
                    distinct.join(", ")
                ));
            }
            columns.push(PoolColumn {
                name: column,
                axis,
                series,
                units,
            });
        }
        Ok(columns)
    }

    /// The options of the recordings' classical WVs and of their robust ones (the fit's when
    /// the options ask for a robust WV, else the contamination check's; `None`: neither).
    fn pooled_wv_options(&self) -> (WvOptions, Option<WvOptions>) {
        let wv = self.options().wv;
        let classical = WvOptions { robust: None, ..wv };
        let robust = wv
            .robust
            .or(self.options().robust_check)
            .map(|r| WvOptions {
                robust: Some(r),
                ..wv
            });
        (classical, robust)
    }

    /// One column's pooled WVs (classical, and robust when asked) from the recordings' own
    /// (`wvs`, in recording order), and each recording against the others, without a model:
    /// its lines, how many differ, and the WVs the fit uses.
    fn pool_column(
        &self,
        column: &str,
        recordings: &[(&str, &Imu)],
        wvs: &mut impl Iterator<Item = RecordingWvs>,
        robust_opts: Option<WvOptions>,
        names: &[String],
    ) -> Result<(PooledPair, Agreement), CalibError> {
        let engine = |e: crate::ParamError| CalibError::Engine {
            column: column.to_string(),
            source: e.into(),
        };
        let mut classical = Vec::with_capacity(recordings.len());
        let mut robust: Option<Result<Vec<_>, String>> = robust_opts.map(|_| Ok(Vec::new()));
        for (name, _) in recordings {
            let (c, r) = wvs.next().expect("one job per column and recording");
            classical.push(c.map_err(|e| pool_error(name, format!("column {column}: {e}")))?);
            if let (Some(Ok(list)), Some(r)) = (&mut robust, r) {
                match r {
                    Ok(w) => list.push(w),
                    Err(e) => robust = Some(Err(format!("{name}: {e}"))),
                }
            }
        }
        let classical = Box::new(PooledWv::new(classical).map_err(engine)?);
        let robust = match robust {
            Some(Ok(parts)) => Some(
                PooledWv::new(parts)
                    .map(Box::new)
                    .map_err(|e| engine(e).to_string()),
            ),
            Some(Err(e)) => Some(Err(e)),
            None => None,
        };
        // the WV the fit uses: each recording against the others, without a model
        let fitted = match (self.options().wv.robust, &robust) {
            (Some(_), Some(Ok(r))) => r.parts(),
            _ => classical.parts(),
        };
        let agreement = (
            recording_agreement(fitted, names).map_err(engine)?,
            fitted.to_vec(),
        );
        Ok(((classical, robust), agreement))
    }
}

/// One inertial axis of a pooled calibration: the column, the first recording's axis, every
/// recording's samples and unit.
struct PoolColumn<'a> {
    name: &'a str,
    axis: &'a crate::imu::Axis,
    series: Vec<&'a [f64]>,
    units: Vec<Option<SignalUnit>>,
}

/// A recording's classical WV of one column, and its robust one when asked.
type RecordingWvs = (
    Result<WaveletVariance, crate::InputError>,
    Option<Result<WaveletVariance, crate::InputError>>,
);

/// A column's pooled classical WV and its robust one (or why not).
type PooledPair = (Box<PooledWv>, Option<Result<Box<PooledWv>, String>>);

/// A column's recordings against the others: their lines and how many differ, and their WVs.
type Agreement = ((Vec<String>, usize), Vec<WaveletVariance>);

/// A pooling error naming the recording.
fn pool_error(recording: &str, reason: String) -> CalibError {
    CalibError::Pool {
        recording: recording.to_string(),
        reason,
    }
}

/// At least two recordings, all at the first one's rate (1%): that rate.
fn check_pool(recordings: &[(&str, &Imu)]) -> Result<f64, CalibError> {
    let [(first_name, first), ..] = recordings else {
        return Err(pool_error(
            "(none)",
            "no recording given: a pooled calibration needs at least two".to_string(),
        ));
    };
    if recordings.len() < 2 {
        return Err(pool_error(
            first_name,
            "the only recording: a pooled calibration needs at least two (calibrate one recording without --pool)".to_string(),
        ));
    }
    let freq_hz = first.freq_hz();
    for (name, imu) in &recordings[1..] {
        if (imu.freq_hz() - freq_hz).abs() > crate::imu::read::RATE_TOLERANCE * freq_hz {
            return Err(pool_error(
                name,
                format!(
                    "sampled at {} Hz, {first_name} at {freq_hz} Hz: the recordings of one model need one rate (its parameters are per sample)",
                    imu.freq_hz()
                ),
            ));
        }
    }
    Ok(freq_hz)
}

/// Every recording's WVs of every column, in SI, in parallel over columns and recordings
/// (column-major: the recordings of the first column first).
fn recording_wvs(
    columns: &[PoolColumn<'_>],
    recordings: usize,
    freq_hz: f64,
    classical_opts: &WvOptions,
    robust_opts: Option<WvOptions>,
) -> Vec<RecordingWvs> {
    let jobs: Vec<(usize, usize)> = (0..columns.len())
        .flat_map(|c| (0..recordings).map(move |k| (c, k)))
        .collect();
    jobs.par_iter()
        .map(|&(c, k)| {
            let column = &columns[c];
            let to_si = column.units[k].map_or(1.0, |u| u.to_si());
            let si: Vec<f64>;
            let x: &[f64] = if to_si == 1.0 {
                column.series[k]
            } else {
                si = column.series[k].iter().map(|v| v * to_si).collect();
                &si
            };
            let classical = wavelet_variance(x, freq_hz, classical_opts);
            let robust = robust_opts.as_ref().map(|o| {
                let levels = classical.as_ref().ok().map(|w| w.levels());
                wavelet_variance(
                    x,
                    freq_hz,
                    &WvOptions {
                        levels: o.levels.or(levels),
                        ..*o
                    },
                )
            });
            (classical, robust)
        })
        .collect()
}

/// The per-recording lines on the axes calibrated (an axis may be left out), and a check line
/// naming the columns where some recordings differ from the others.
fn annotate_agreement(
    report: &mut CalibrationReport,
    columns: &[PoolColumn<'_>],
    agreement: Vec<Agreement>,
    recordings: usize,
) {
    let mut disagreeing = Vec::new();
    for (column, ((lines, differing), wvs)) in columns.iter().zip(agreement) {
        if let Some(a) = report.axes.iter_mut().find(|a| a.column == column.name) {
            a.notes.extend(lines);
            a.recording_wvs = wvs;
            if differing > 0 {
                disagreeing.push(format!("{} ({differing} of {recordings})", column.name));
            }
        }
    }
    if !disagreeing.is_empty() {
        report.checks.push(format!(
            "some recordings' WVs differ from the others' at more scales than chance: {}; those recordings may not share one model, and the pooled one is their average (test it: gmwm same-model FILE... --model MODEL)",
            disagreeing.join(", ")
        ));
    }
}

/// docs/methods.md §5.12: each recording's WV against the pooled WV of the others, scale by
/// scale by the distribution-free comparison of §7.7 ([`compare_wvs`]), no model involved:
/// one line per recording, and how many recordings differ at more scales than `alpha` of the
/// scales compared (rounded up) allows by chance.
fn recording_agreement(
    parts: &[WaveletVariance],
    names: &[String],
) -> Result<(Vec<String>, usize), ParamError> {
    let mut lines = Vec::with_capacity(parts.len());
    let mut differing = 0;
    for (k, (wv, name)) in parts.iter().zip(names).enumerate() {
        let others = PooledWv::new(
            parts
                .iter()
                .enumerate()
                .filter(|&(i, _)| i != k)
                .map(|(_, p)| p.clone())
                .collect(),
        )?;
        let scales = compare_wvs(wv, others.wv())?;
        let outside: Vec<&WvComparison> = scales.iter().filter(|c| c.differs).collect();
        let allowed = (wv.alpha() * scales.len() as f64).ceil() as usize;
        let level = format!("{:.0}%", 100.0 * (1.0 - wv.alpha()));
        let line = match outside.iter().max_by(|a, b| a.z.abs().total_cmp(&b.z.abs())) {
            None => format!(
                "recording {name}: its WV agrees with the other recordings' at all {} scales ({level} level)",
                scales.len()
            ),
            Some(worst) => {
                let verdict = if outside.len() > allowed {
                    differing += 1;
                    "differs from the other recordings'"
                } else {
                    "agrees with the other recordings' within chance: it differs"
                };
                format!(
                    "recording {name}: its WV {verdict} at {} of {} scales ({level} level), the largest difference {:+.0}% at {} s (z = {:.1})",
                    outside.len(),
                    scales.len(),
                    100.0 * elementary::expm1(worst.log_ratio),
                    crate::fit::report::significant(worst.tau_s, 3),
                    worst.z
                )
            }
        };
        lines.push(line);
    }
    Ok((lines, differing))
}

#[cfg(test)]
mod tests {
    use crate::fit::pooled::{pooled_objective, FitRecording};
    use crate::fit::{Objective, Parametrisation, StartInputs, Weights};
    use crate::model::Model;
    use crate::sim::simulate_model;
    use crate::variance::pooled::PooledWv;
    use crate::variance::wv::{wavelet_variance, WvOptions};

    /// docs/methods.md §5.12: with recording weights `omega_kj = Omega_j w_kj`, the pooled GMWM
    /// objective (§5.11) is the single objective of the pooled WV with weights `Omega_j` plus a
    /// constant: their difference is the same at every theta (to rounding, 1e-9 of Q).
    #[test]
    fn the_pooled_wv_objective_is_the_pooled_gmwm_objective_up_to_a_constant() {
        let truth = Model::parse("AR1(phi=0.9, sigma2=0.5)+WN(sigma2=1)+RW(gamma2=1e-4)").unwrap();
        let xs: Vec<Vec<f64>> = [3000, 7000, 20000]
            .iter()
            .enumerate()
            .map(|(k, &n)| simulate_model(&truth, n, 10.0, 70 + k as u64).unwrap())
            .collect();
        let parts = xs
            .iter()
            .map(|x| wavelet_variance(x, 10.0, &WvOptions::default()).unwrap())
            .collect();
        let pooled = PooledWv::new(parts).unwrap();
        let omega = Weights::fast(pooled.wv()).unwrap();
        let model = Model::parse("AR1()+WN()+RW()").unwrap();
        let param = || {
            Parametrisation::new(
                &model,
                crate::fit::TransformPreset::Imu,
                crate::fit::PhiOrder::Ordered,
                10.0,
            )
            .unwrap()
        };
        let single = Objective::new(&model, param(), &pooled.wv().wv, &omega, 10.0).unwrap();
        let recordings: Vec<FitRecording> = pooled
            .parts()
            .iter()
            .zip(&xs)
            .enumerate()
            .map(|(k, (wv, x))| FitRecording {
                wv: wv.clone(),
                weights: Weights::from_variances(
                    pooled
                        .weights(k)
                        .iter()
                        .zip(&omega.omega)
                        .map(|(w, o)| 1.0 / (o * w))
                        .collect(),
                )
                .unwrap(),
                inputs: StartInputs::from_series(x),
            })
            .collect();
        let stacked = pooled_objective(&model, param(), &recordings, None, 10.0).unwrap();
        let thetas = [
            [0.9, 0.5, 1.0, 1e-4],
            [0.5, 2.0, 0.3, 1e-3],
            [0.99, 0.1, 3.0, 1e-6],
        ];
        let differences: Vec<(f64, f64)> = thetas
            .iter()
            .map(|t| {
                let q = stacked.value_at_theta(t).unwrap();
                (q - single.value_at_theta(t).unwrap(), q)
            })
            .collect();
        for (d, q) in &differences[1..] {
            assert!(
                (d - differences[0].0).abs() <= 1e-9 * q,
                "{d} vs {} (Q = {q})",
                differences[0].0
            );
        }
    }
}
