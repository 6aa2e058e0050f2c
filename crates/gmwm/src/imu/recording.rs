//! A recording opened for calibration: whatever the container (text, raw binary, binary IMU
//! records), an [`Imu`] with its rate, where it came from and what the reader noticed.

use super::read::{read_imu_record_file, read_table, ImuRecordType, ReadOptions};
use super::Imu;
use crate::Error;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// How to open a recording ([`Recording::open`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RecordingOptions {
    /// Options of delimited text and raw binary tables (columns, time column, rate, ...).
    pub read: ReadOptions,
    /// Binary IMU records of this type (METHODS §9.2) instead of a table.
    pub record_type: Option<ImuRecordType>,
}

/// What a recording was read from.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "kebab-case", tag = "kind")]
#[non_exhaustive]
pub enum RecordingSource {
    /// Delimited text or raw binary columns.
    Table,
    /// Binary IMU records (METHODS §9.2).
    Records {
        /// The record type.
        record_type: String,
    },
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
    /// What the reader noticed (time column, rate, gaps, units), one line each.
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
        let mut notes = Vec::new();
        let (imu, source) = match opts.record_type {
            Some(t) => {
                let mut imu = read_imu_record_file(path, t)?;
                if !opts.read.columns.is_empty() {
                    imu = imu.select(path, &opts.read.columns)?;
                }
                notes.push(format!(
                    "{t} records: rates from increments x {} Hz x the type's scale factors, in rad/s and m/s^2",
                    imu.freq_hz()
                ));
                (
                    imu,
                    RecordingSource::Records {
                        record_type: t.name().to_string(),
                    },
                )
            }
            None => {
                let table = read_table(path, &opts.read)?;
                (Imu::from_table(table)?, RecordingSource::Table)
            }
        };
        Ok(Self {
            path: path.to_path_buf(),
            imu,
            source,
            topic: None,
            notes,
        })
    }
}
