//! IMU data and readers (docs/methods.md §9).
//!
//! - [`read_table`]: CSV/TSV text (plain or gzip), raw little-endian f64/f32 binary and binary
//!   IMU records into a [`Table`] of named columns, with the JSON [`Sidecar`], the time column
//!   ([`TimingReport`]), soft problems ([`ReadWarning`]) and the sampling rate;
//! - `check_times`: rate, gaps, duplicates and reordering of any time stamps (module
//!   [`timing`]);
//! - [`BinaryChunks`] / `for_each_chunk`: one column of a huge binary file in bounded memory;
//! - `read_imu_record_file`: the binary IMU epoch records of docs/methods.md §9.2–9.3;
//! - [`write::SeriesWriter`]: series to CSV, TSV, gzip or raw binary by file name;
//! - [`plausible::raw_floats`]: whether raw floats look like samples (f64 read as f32, ...);
//! - [`Imu`]: gyroscope/accelerometer axes with a common rate (docs/methods.md §9.1);
//! - [`SampleAccount`]: how many samples a reader read and used per column, and what held none.
//!
//! This module knows no statistics; every error is a [`ReadError`] (or a
//! [`ParamError`](crate::error::ParamError) for impossible options) naming the file, line and
//! column.
//!
//! ```no_run
//! use gmwm::{read_table, Imu, ReadOptions};
//! use std::path::Path;
//! let table = read_table(Path::new("adis_16405_imu1.csv.gz"), &ReadOptions::default())?;
//! let imu = Imu::from_table(table)?;
//! for (tag, axis) in imu.iter() {
//!     println!("{tag}: {} samples at {} Hz", axis.values().len(), imu.freq_hz());
//! }
//! # Ok::<(), gmwm::Error>(())
//! ```

mod error;
pub(crate) mod plausible;
mod probe;
pub(crate) mod read;
pub(crate) mod recording;
pub(crate) mod ros;
mod samples;
mod sensor;
pub(crate) mod sidecar;
mod temporary;
pub(crate) mod timing;
pub(crate) mod write;

pub(crate) use error::{escape_name, printable};
pub use error::{quote, quote_up_to, ReadError};
pub use probe::Probe;
#[cfg(test)]
pub(crate) use read::sniff;
pub(crate) use read::{
    binary_layout, BinaryChunks, BinaryLayout, ImuRecordType, InputFormat, ReadOptions, ReadWarning,
};
#[cfg(test)]
pub(crate) use read::{
    for_each_chunk, read_imu_record_file, read_table, Column, ColumnSelector, Content, HeaderMode,
    Table,
};
pub use recording::{Recording, RecordingOptions, RecordingSource};
pub use samples::{SampleAccount, Tally};
pub use sensor::{Axis, Imu, Sensor, SensorInfo};
pub use sidecar::{find_sidecar, ColumnSummary, NotASidecar, Sidecar, SidecarColumn, SidecarUnits};
pub use temporary::{
    process_tag, remove_temporary_files, temporary_dir, track_temporary, untrack_temporary,
};
#[cfg(test)]
pub(crate) use timing::{check_times, UnitSource};
pub use timing::{time_column_unit, Gap, TimeUnit, TimingReport, TimingWarning};
pub use write::{OutputFormat, SeriesWriter};
