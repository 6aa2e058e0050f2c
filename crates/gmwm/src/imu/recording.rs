//! A recording opened for calibration: whatever the container (text, raw binary, binary IMU
//! records, a ROS bag), an [`Imu`] with its rate, where it came from and what the reader
//! noticed.

use super::read::{read_table, Column, ReadOptions, ReadWarning, RATE_TOLERANCE};
use super::ros::{read_imu_messages, ImuMessages, RosContainer};
use super::timing::{check_times, TimeUnit, TimingReport, UnitSource};
use super::{Imu, ReadError, SampleAccount, Sensor, SensorInfo};
use crate::imu::ReadError as Error;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// How to open a recording ([`Recording::open`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RecordingOptions {
    /// Options of text, raw binary and binary IMU record files (format, columns, time column,
    /// rate, ...); the columns and the rate apply to ROS recordings too.
    pub read: ReadOptions,
    /// The `sensor_msgs/Imu` topic of a ROS recording (default: its only IMU topic).
    pub topic: Option<String>,
}

/// What a recording was read from.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "kebab-case", tag = "kind")]
#[non_exhaustive]
pub enum RecordingSource {
    /// Delimited text or raw binary columns.
    Table,
    /// Binary IMU records (docs/methods.md §9.2).
    Records {
        /// The record type.
        record_type: String,
    },
    /// A ROS recording's `sensor_msgs/Imu` topic.
    Ros {
        /// Container (`ROS1 bag`, `MCAP`, `rosbag2 sqlite3`).
        container: String,
        /// The topic.
        topic: String,
    },
    /// Wavelet variances saved without the samples (`gmwm wv --json`,
    /// `crate::calib::Calibration::run_wv`).
    SavedWv,
}

/// A recording opened for calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// The file, as given.
    pub path: PathBuf,
    /// The axes and their rate.
    pub imu: Imu,
    /// What it was read from.
    pub source: RecordingSource,
    /// The ROS topic it came from, if any.
    pub topic: Option<String>,
    /// What the time stamps say (rate, gaps, duplicates, reordering), when there are stamps.
    pub timing: Option<TimingReport>,
    /// How many samples were read and used per axis, and what held none (row accounting).
    pub samples: SampleAccount,
    /// What the reader noticed (time column, rate, gaps, units, the samples' account), one
    /// line each.
    pub notes: Vec<String>,
}

impl Recording {
    /// Opens `path`: binary IMU records when `opts.record_type` is set, else a table whose
    /// columns are read as IMU axes ([`Imu::from_table`]).
    ///
    /// # Errors
    /// Any read error of the container, or [`crate::imu::ReadError::FreqNotDerivable`] when no
    /// rate can be found.
    pub fn open(path: &Path, opts: &RecordingOptions) -> Result<Self, Error> {
        Self::open_probed(&super::Probe::of(path, &opts.read), opts)
    }

    /// [`Recording::open`] of a path probed before ([`Probe`](super::Probe)).
    ///
    /// # Errors
    /// As [`Recording::open`].
    pub fn open_probed(probe: &super::Probe, opts: &RecordingOptions) -> Result<Self, Error> {
        let path = probe.path();
        if probe.is_ros() {
            return Self::open_ros(path, opts);
        }
        if let Some(topic) = &opts.topic {
            return Err(crate::error::ParamError::new(
                "topic",
                topic,
                format!(
                    "a topic of a ROS recording; {} is not one (ROS1 bag, MCAP, rosbag2 sqlite3)",
                    path.display()
                ),
            )
            .into());
        }
        let table = read_table(path, &opts.read)?;
        let notes = table_notes(
            table.facts.record_type,
            table.facts.timing.as_ref(),
            &table.facts.skipped,
            &table.facts.samples,
            &table.facts.warnings,
        );
        let source = match table.facts.record_type {
            Some(t) => RecordingSource::Records {
                record_type: t.name().to_string(),
            },
            None => RecordingSource::Table,
        };
        let timing = table.facts.timing.clone();
        let samples = table.facts.samples.clone();
        let imu = Imu::from_table(table)?;
        Ok(Self {
            path: path.to_path_buf(),
            imu,
            source,
            topic: None,
            timing,
            samples,
            notes,
        })
    }

    /// A ROS recording: the IMU topic's angular velocity and linear acceleration (SI by the
    /// message definition) as six axes, the rate from the header stamps (the log times when
    /// every header stamp is the same, as with drivers that leave them unset), the stamps
    /// checked and reported.
    fn open_ros(path: &Path, opts: &RecordingOptions) -> Result<Self, Error> {
        let msgs = read_imu_messages(path, opts.topic.as_deref())?;
        let about = RosAbout {
            container: msgs.container,
            topic: msgs.topic.clone(),
            frame_id: msgs.frame_id.clone(),
            messages: msgs.len() as u64,
            other_messages: msgs.other_messages,
        };
        let header = stamps_report(HEADER_STAMP, &msgs.header_stamp_ns);
        let (mut notes, timing, freq_hz) =
            ros_timing(path, &about, opts.read.freq_hz, header, || {
                Ok(stamps_report(LOG_TIME, &msgs.log_time_ns))
            })?;
        let mut imu = imu_of_messages(msgs, freq_hz)?;
        if !opts.read.columns.is_empty() {
            imu = imu.select(path, &opts.read.columns)?;
        }
        let names = imu.axes().iter().map(|a| a.column.name.clone()).collect();
        let samples = ros_samples(names, &about, &timing);
        notes.push(samples.to_string());
        Ok(Self {
            samples,
            path: path.to_path_buf(),
            imu,
            source: RecordingSource::Ros {
                container: about.container.to_string(),
                topic: about.topic.clone(),
            },
            topic: Some(about.topic),
            timing: Some(timing),
            notes,
        })
    }
}

/// The column of a ROS topic's timing report from the header stamps.
pub(crate) const HEADER_STAMP: &str = "header.stamp";
/// The column of a ROS topic's timing report from the log times.
pub(crate) const LOG_TIME: &str = "log time";

/// What a ROS topic read was, for the notes.
pub(crate) struct RosAbout {
    pub(crate) container: RosContainer,
    pub(crate) topic: String,
    pub(crate) frame_id: Option<String>,
    pub(crate) messages: u64,
    pub(crate) other_messages: u64,
}

/// The notes (topic, timing, its warnings, the rate), the timing report and the rate of a ROS
/// topic read: the header stamps' report, or the log times' (`log`) when the header stamps do
/// not advance; the rate `--freq` else the report's. The samples' note is the caller's.
pub(crate) fn ros_timing(
    path: &Path,
    about: &RosAbout,
    given_hz: Option<f64>,
    header: TimingReport,
    log: impl FnOnce() -> Result<TimingReport, ReadError>,
) -> Result<(Vec<String>, TimingReport, f64), ReadError> {
    let mut notes = vec![format!(
        "{} topic {} (sensor_msgs/Imu{}): {} messages; angular velocity in rad/s and linear acceleration in m/s^2 by the message definition",
        about.container,
        // names from the file: escaped, so that the note stays one line
        super::quote(&about.topic),
        about
            .frame_id
            .as_deref()
            .map(|f| format!(", frame {}", super::quote(f)))
            .unwrap_or_default(),
        about.messages
    )];
    let mut timing = header;
    if !(timing.rate_hz.is_finite() && timing.rate_hz > 0.0) {
        notes.push(
            "the header stamps do not advance: the rate comes from the bag's log times".to_string(),
        );
        timing = log()?;
    }
    notes.push(timing.to_string());
    notes.extend(timing.warnings().iter().map(ToString::to_string));
    let freq_hz = match given_hz {
        Some(f) => {
            if (f / timing.rate_hz - 1.0).abs() > RATE_TOLERANCE {
                let disagrees = ReadWarning::FreqDisagrees {
                    path: path.to_path_buf(),
                    given_hz: f,
                    column: timing.column.clone(),
                    time_hz: timing.rate_hz,
                };
                notes.push(disagrees.to_string());
            }
            f
        }
        None => timing.rate_hz,
    };
    if !(freq_hz.is_finite() && freq_hz > 0.0) {
        return Err(ReadError::FreqNotDerivable {
            path: path.to_path_buf(),
            reason: "the stamps of the IMU topic do not advance; give the rate",
        });
    }
    Ok((notes, timing, freq_hz))
}

/// The samples' account of a ROS topic read into the axes `names`.
pub(crate) fn ros_samples(
    names: Vec<String>,
    about: &RosAbout,
    timing: &TimingReport,
) -> SampleAccount {
    SampleAccount {
        missing: timing.missing_samples() as u64,
        ..SampleAccount::all_used(names, "message", about.messages)
            .without(about.other_messages, "message on other topics")
    }
}

/// The axes of a ROS topic (0-based among gyro_x .. accel_z) that `columns` selects, as
/// [`Imu::select`] selects them (all six when `columns` is empty).
pub(crate) fn ros_selection(
    path: &Path,
    columns: &[super::read::ColumnSelector],
) -> Result<Vec<usize>, ReadError> {
    let all = imu_of_columns(std::array::from_fn(|_| vec![0.0]), 1.0, String::new())?;
    if columns.is_empty() {
        return Ok((0..6).collect());
    }
    let names: Vec<String> = all.axes().iter().map(|a| a.column.name.clone()).collect();
    let kept = all.select(path, columns)?;
    Ok(kept
        .axes()
        .iter()
        .filter_map(|a| names.iter().position(|n| *n == a.column.name))
        .collect())
}

/// The timing report of nanosecond stamps, in seconds after the first (whole nanoseconds
/// subtracted exactly, so epoch stamps keep their precision).
fn stamps_report(column: &str, ns: &[i64]) -> TimingReport {
    let first = ns.first().copied().unwrap_or(0);
    let s: Vec<f64> = ns
        .iter()
        .map(|&t| t.wrapping_sub(first) as f64 * 1e-9)
        .collect();
    check_times(column, &s, TimeUnit::Nanoseconds, UnitSource::Stated)
}

/// Six axes from the IMU messages (consumed: the vectors move into the columns).
fn imu_of_messages(msgs: ImuMessages, freq_hz: f64) -> Result<Imu, Error> {
    let [gx, gy, gz] = msgs.angular_velocity;
    let [ax, ay, az] = msgs.linear_acceleration;
    let name = msgs
        .path
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(imu_of_columns([gx, gy, gz, ax, ay, az], freq_hz, name)?)
}

/// The names of the six axes of a ROS topic.
pub(crate) const ROS_AXES: [&str; 6] = [
    "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z",
];

/// The six axes of a ROS topic: gyro_x .. accel_z, in rad/s and m/s^2.
fn imu_of_columns(
    values: [Vec<f64>; 6],
    freq_hz: f64,
    name: String,
) -> Result<Imu, crate::error::ParamError> {
    let mut columns = Vec::with_capacity(6);
    let mut info = Vec::with_capacity(6);
    for (k, values) in values.into_iter().enumerate() {
        let (sensor, prefix, unit) = if k < 3 {
            (Sensor::Gyroscope, "gyro", "rad/s")
        } else {
            (Sensor::Accelerometer, "accel", "m/s^2")
        };
        let axis = ["x", "y", "z"][k % 3];
        debug_assert_eq!(ROS_AXES[k], format!("{prefix}_{axis}"));
        columns.push(Column {
            name: ROS_AXES[k].to_string(),
            values,
        });
        info.push(SensorInfo {
            sensor,
            axis: axis.to_ascii_uppercase(),
            unit: Some(unit.to_string()),
        });
    }
    Ok(Imu::new(columns, info, freq_hz)?.with_name(name))
}

/// What the reader of a table noticed, one line each: how IMU records are scaled, the time
/// column's report, the columns left out, the samples' account, the warnings
/// ([`Recording::notes`]; a streamed table's too).
pub fn table_notes(
    record_type: Option<crate::imu::ImuRecordType>,
    timing: Option<&TimingReport>,
    skipped: &[String],
    samples: &SampleAccount,
    warnings: &[crate::imu::ReadWarning],
) -> Vec<String> {
    let mut notes = Vec::new();
    if let Some(t) = record_type {
        notes.push(format!(
            "{t} records: rates are the increments x the rate from the time stamps x the \
             type's scale factors (docs/methods.md §9.3), in rad/s and m/s^2"
        ));
    }
    if let Some(timing) = timing {
        notes.push(timing.to_string());
    }
    notes.extend(left_out_note(skipped));
    notes.push(samples.to_string());
    notes.extend(warnings.iter().map(ToString::to_string));
    notes
}

/// The note on the columns a reader left out (`None` when it left out none).
pub fn left_out_note(skipped: &[String]) -> Option<String> {
    (!skipped.is_empty()).then(|| {
        // names from a file: escaped and cut, so that the note stays one line
        let names: Vec<String> = skipped.iter().map(|n| super::quote(n)).collect();
        format!("columns left out: {}", names.join(", "))
    })
}
