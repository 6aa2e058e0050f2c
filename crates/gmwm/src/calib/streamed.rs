//! Calibration of a recording streamed from its file, in memory bounded whatever its length
//! (a day at 1 kHz is 8.6·10^7 samples an axis): a raw binary recording as it is, text and
//! binary IMU records through the raw f64 spool that
//! [`StreamedTable`] writes in its one pass over the
//! file (`Calibration::run_table`).
//!
//! The pipeline of [`Calibration::run`] needs the samples only for five things, and each has a
//! streamed form:
//! - **the classical Haar WV**: streamed from the file for every axis at once
//!   ([`binary_wavelet_variance`]); identical to the in-memory estimate within 1e-12;
//! - **the Allan variance**: `AV(m) = 2 nu2(2m)`, exact from that WV (docs/methods.md §3.4,
//!   [`allan_from_wv`](crate::variance::allan_from_wv));
//! - **the model selection and the fit**: they use the WV only (`crate::Wic::select_wv`);
//!   the starting values then come from the WV alone (no series range for drift draws), and
//!   V is the exact covariance ([`crate::variance::implied_cov`]), which needs no series;
//! - **the power spectral density**: Welch's estimator takes the samples chunk by chunk
//!   (`Welch`), so the robust check's pass below feeds it its blocks, in order, and the PSD
//!   is that of those blocks, no segment straddling two blocks that do not follow each other
//!   (without the robust check, no PSD, with a note);
//! - **the contamination check**: the robust WV is a root per level over all the level's
//!   coefficients, which an exact streamed computation would need several passes and the
//!   coefficients near the root for. Here it is estimated on consecutive blocks of
//!   `ROBUST_BLOCK` samples, in memory one block at a time: per level, the blocks' robust
//!   estimates averaged with weights their coefficient counts, at the levels up to
//!   `ROBUST_LEVELS` (scales of at most `2^15` samples, where a block holds at least 64
//!   windows). The interval is the robust one (docs/methods.md §2.5) for the pooled count. The
//!   error of this approximation against the robust WV of the whole series is measured in the
//!   tests (`streamed_robust_matches_whole_series`); contamination (spikes, steps) shows at
//!   the fine scales, which the check covers. A recording of more than `ROBUST_BLOCKS` blocks
//!   (2^24 samples) is checked on that many blocks spread evenly over it, the others skipped
//!   unread: 2^24 samples already pin the fine scales' robust WV to a fraction of a percent,
//!   and the whole-series pass cost a third of a 10^8-sample calibration's CPU time. The
//!   comparison stays honest: the classical WV of every sample against a robust one whose
//!   interval is that of the samples it saw.
//!
//! Memory: that of [`binary_wavelet_variance`] (the rings up to level 20, 8 MiB an axis, and a
//! few chunks of rows per thread) and one block per axis for the robust check: tens of MB an
//! axis whatever the length. Measured (`gmwm calibrate FILE.csv.gz --stream-from 1`, six axes
//! and a time column at 200 Hz, a busy 2-core machine, indicative): 10^6 rows 171 MB peak RSS
//! (in memory: 98 MB), 10^7 rows 346 MB (in memory: 796 MB), in 29 s against 30 s in memory;
//! from 2^21 rows on, the robust check's blocks are full and the memory stays there.

use super::pipeline::{AxisData, Calibration, CalibrationReport, InputAxis};
use crate::calib::CalibError as Error;
use crate::error::ParamError;
use crate::imu::read::stream::{streamed_size, streams_from, StreamedTable};
use crate::imu::{
    binary_layout, find_sidecar, BinaryChunks, BinaryLayout, Imu, Probe, ReadError, ReadOptions,
    Recording, RecordingOptions, SensorInfo,
};
use crate::inference::Progress;
use crate::variance::binary_wavelet_variance;
use crate::variance::ci::eta3;
use crate::variance::default_levels;
use crate::variance::psd::{segment_length, Psd, Welch, MIN_SEGMENT};
use crate::variance::wv::{wavelet_variance, WaveletVariance, WvOptions};
use crate::wavelet::{Transform, WaveletFilter};
use rayon::prelude::*;
use std::path::Path;

/// Default samples per axis from which [`Calibration::run_source`] streams a raw binary
/// recording instead of reading it (2^24, 128 MiB an axis in f64;
/// [`CalibrationOptions::stream_from`](super::CalibrationOptions::stream_from)).
pub const STREAM_FROM: u64 = 1 << 24;
/// Samples per block of the streamed robust check (2^21).
pub(crate) const ROBUST_BLOCK: usize = 1 << 21;
/// Blocks the streamed robust check (and the PSD) takes at most: `2^24` samples an axis,
/// spread evenly over a longer recording ([`robust_blocks`]).
pub(crate) const ROBUST_BLOCKS: usize = 8;
/// Levels of the streamed robust check: scales up to `2^15` samples, at least 64 windows a
/// block.
pub(crate) const ROBUST_LEVELS: usize = 15;

impl Calibration {
    /// Whether [`Calibration::run_source`] streams `path`, calibrated with the classical Haar
    /// MODWT WV: a raw binary f64/f32 file (by `read.format`, its name or its sidecar) of at
    /// least `stream_from` rows whose columns have no time column; or text or binary IMU
    /// records of at least `stream_from` rows
    /// ([`streams_from`]: a text file counts a row for
    /// every 8 bytes, its rows being known only once read).
    ///
    /// # Errors
    /// As [`binary_layout`] and `BinaryChunks::open`.
    pub(crate) fn streams(&self, probe: &Probe, read: &ReadOptions) -> Result<bool, Error> {
        Ok(self.stream_layout(probe, read)?.is_some() || self.streams_table(probe, read)?)
    }

    /// Whether the options calibrate with the classical Haar MODWT WV, the one that streams.
    fn classical_haar(&self) -> bool {
        let wv = &self.options().wv;
        wv.robust.is_none() && wv.transform == Transform::Modwt && wv.filter == WaveletFilter::Haar
    }

    fn streams_table(&self, probe: &Probe, read: &ReadOptions) -> Result<bool, Error> {
        Ok(self.classical_haar() && streams_from(probe, read, self.options().stream_from)?)
    }

    fn stream_layout(
        &self,
        probe: &Probe,
        read: &ReadOptions,
    ) -> Result<Option<(BinaryLayout, u64)>, Error> {
        let path = probe.path();
        if probe.container().is_some() || read.time_column.is_some() || !self.classical_haar() {
            return Ok(None);
        }
        let Some(layout) = binary_layout(path, read)? else {
            return Ok(None);
        };
        if layout
            .names
            .iter()
            .any(|n| crate::imu::time_column_unit(n).is_some())
        {
            return Ok(None);
        }
        let rows = BinaryChunks::open(path, layout.format, layout.ncols, 1, 1)?.rows();
        Ok((rows >= self.options().stream_from.max(1)).then_some((layout, rows)))
    }

    /// Calibrates the recording `probe` streamed from the file (module docs; text and IMU
    /// records through `run_table`): the same report as [`Calibration::run`] on the recording
    /// read into memory, up to the contamination check (on blocks, at the fine scales) and the
    /// starting values (from the WV), in memory bounded whatever the length.
    ///
    /// # Errors
    /// [`ParamError`] when the recording is not streamed ([`Calibration::streams`]); read
    /// errors naming the file (a non-finite value with its sample index or line, a truncated
    /// file); no rate known; the errors of [`Calibration::run`].
    fn run_probed(
        &self,
        probe: &Probe,
        read: &ReadOptions,
        progress: &dyn Progress,
    ) -> Result<CalibrationReport, Error> {
        let path = probe.path();
        if self.stream_layout(probe, read)?.is_none() && self.streams_table(probe, read)? {
            let table = StreamedTable::open(path, read)?;
            return self.run_table(&table, progress);
        }
        let Some((layout, rows)) = self.stream_layout(probe, read)? else {
            return Err(ParamError::new(
                "input",
                path.display().to_string(),
                format!(
                    "a raw binary f64/f32 recording without a time column, or a text or IMU record recording, of at least {} rows, for a streamed calibration",
                    self.options().stream_from
                ),
            )
            .into());
        };
        let sidecar = find_sidecar(path)?;
        let (columns, infos) = selected(path, &layout, read, sidecar.as_ref())?;
        let freq_hz = read
            .freq_hz
            .or_else(|| sidecar.as_ref().and_then(|s| s.sampling_frequency_hz))
            .ok_or_else(|| ReadError::FreqNotDerivable {
                path: path.to_path_buf(),
                reason: "no freq_hz given and no sampling_frequency_hz in a sidecar",
            })?;
        let name = sidecar
            .as_ref()
            .and_then(|s| s.name.clone())
            .or_else(|| path.file_name().map(|f| f.to_string_lossy().into_owned()));
        self.run_streamed(
            path,
            &layout,
            (&columns, &infos),
            (freq_hz, rows),
            name.as_deref(),
            progress,
        )
    }

    /// Calibrates a text or IMU-record recording read by [`StreamedTable::open`], streamed
    /// from its spool: as [`Calibration::run_source`].
    ///
    /// # Errors
    /// No rate known ([`ReadError::FreqNotDerivable`]); the errors of [`Calibration::run`].
    pub(crate) fn run_table(
        &self,
        table: &StreamedTable,
        progress: &dyn Progress,
    ) -> Result<CalibrationReport, Error> {
        let (spool, layout) = table.spooled();
        let columns: Vec<usize> = (1..=table.names.len()).collect();
        let infos: Vec<SensorInfo> = table.sensor_infos();
        let freq_hz = table
            .facts
            .freq_hz
            .ok_or_else(|| ReadError::FreqNotDerivable {
                path: table.facts.path.clone(),
                reason: "no freq_hz given, no time column, no sampling_frequency_hz in a sidecar",
            })?;
        let name = table
            .facts
            .sidecar
            .as_ref()
            .and_then(|s| s.name.clone())
            .or_else(|| {
                table
                    .facts
                    .path
                    .file_name()
                    .map(|f| f.to_string_lossy().into_owned())
            });
        let mut report = self.run_streamed(
            spool,
            &layout,
            (&columns, &infos),
            (freq_hz, table.rows),
            name.as_deref(),
            progress,
        )?;
        // the streamed pass computes the WV as the rows come: the gap-aware estimator needs
        // the segments first (docs/methods.md §1.11)
        if let Some(t) = table.facts.timing.as_ref().filter(|t| !t.gaps.is_empty()) {
            report.checks.push(format!(
                "{} {} in the time stamps analysed as one contiguous series: a streamed recording \
                 is not gap-aware (give a larger --stream-from to read it in memory)",
                t.gaps.len(),
                if t.gaps.len() == 1 { "gap" } else { "gaps" }
            ));
        }
        Ok(report)
    }

    /// The streamed calibration of the 1-based `columns` of the raw binary `path` (a
    /// recording, or the spool of a [`StreamedTable`]).
    fn run_streamed(
        &self,
        path: &Path,
        layout: &BinaryLayout,
        (columns, infos): (&[usize], &[SensorInfo]),
        (freq_hz, rows): (f64, u64),
        name: Option<&str>,
        progress: &dyn Progress,
    ) -> Result<CalibrationReport, Error> {
        crate::error::check_freq(freq_hz)?;
        // only the inertial axes are streamed; the pipeline names the others if none is
        let inertial: Vec<usize> = (0..columns.len())
            .filter(|&k| infos[k].sensor != crate::imu::Sensor::Other)
            .collect();
        let streamed: Vec<usize> = inertial.iter().map(|&k| columns[k]).collect();
        let n = usize::try_from(rows)
            .map_err(|_| ParamError::new("rows", rows, "at most usize::MAX samples per column"))?;
        let levels = self
            .options()
            .wv
            .levels
            .unwrap_or_else(|| default_levels(n, Transform::Modwt, WaveletFilter::Haar));
        let robust_opts = self.options().robust_check.map(|r| WvOptions {
            levels: Some(levels.min(ROBUST_LEVELS)),
            robust: Some(r),
            ..self.options().wv
        });
        // the two passes at once: the robust one only needs the classical WV at the end
        let (classical, pooled) = if streamed.is_empty() {
            (Vec::new(), None)
        } else {
            let (c, r) = rayon::join(
                || {
                    classical_pass(
                        path,
                        layout,
                        &streamed,
                        levels,
                        freq_hz,
                        self.options().wv.alpha,
                    )
                },
                || {
                    robust_opts
                        .as_ref()
                        .map(|o| robust_pass(path, layout, &streamed, o, (n, freq_hz)))
                        .transpose()
                },
            );
            (c?, r?)
        };
        let coverage = pooled.as_ref().map(|(_, c, _)| *c);
        let (pooled, psds) = match pooled {
            Some((p, _, psds)) => (Some(p), Some(psds)),
            None => (None, None),
        };
        let robust = pooled
            .zip(robust_opts)
            .map(|(p, o)| robust_wvs(p, &classical, &o));
        // an axis whose WV fails (a constant column, say) is left out with a check line, as
        // the in-memory pipeline does; only when every axis fails is that an error
        let mut checks = Vec::new();
        let mut data: Vec<Option<AxisData<'_>>> = (0..columns.len()).map(|_| None).collect();
        let mut failed = Vec::new();
        let mut first_error = None;
        for (i, (&k, wv)) in inertial.iter().zip(classical).enumerate() {
            match wv {
                Ok(wv) => {
                    data[k] = Some(AxisData::Streamed {
                        wv: Box::new(wv),
                        robust: robust.as_ref().map(|r| r[i].clone()),
                        psd: psds.as_ref().map(|p| p[i].clone()),
                    })
                }
                Err(e) => {
                    let column = &layout.names[columns[k] - 1];
                    checks.push(format!("not calibrated: column {column}: {e}"));
                    failed.push(k);
                    first_error.get_or_insert(crate::calib::CalibError::Engine {
                        column: column.clone(),
                        source: e,
                    });
                }
            }
        }
        if !inertial.is_empty() && failed.len() == inertial.len() {
            if let Some(e) = first_error {
                return Err(e);
            }
        }
        let axes: Vec<InputAxis<'_>> = columns
            .iter()
            .zip(infos)
            .zip(data)
            .enumerate()
            .filter(|(k, _)| !failed.contains(k))
            .map(|(_, ((&c, info), data))| InputAxis {
                column: &layout.names[c - 1],
                info,
                // a column that is not inertial is only named, never calibrated
                data: data.unwrap_or(AxisData::Series(&[])),
            })
            .collect();
        checks.push(format!(
            "streamed from the file ({n} samples per axis, at least {}): the Allan variance from the WV (exact), starting values from the WV; the contamination check compares the scales up to {} samples with a robust WV estimated on blocks of {ROBUST_BLOCK} samples{}",
            self.options().stream_from,
            1usize << levels.min(ROBUST_LEVELS),
            match coverage {
                // more full blocks than the check takes: it spread its blocks
                Some(c) if n / ROBUST_BLOCK > ROBUST_BLOCKS => format!(
                    " ({} of the {} blocks, spread evenly over the recording: {} of its samples; the PSD is Welch's on the same blocks; the WV uses every sample)",
                    c.blocks, c.of_blocks, c.samples
                ),
                Some(c) if c.samples < n => format!(
                    " (the last {} samples, too few for 64 windows of its coarsest scale, are left out of it; the WV uses them)",
                    n - c.samples
                ),
                _ => String::new(),
            }
        ));
        self.run_axes(name, freq_hz, n, axes, checks, progress)
    }
}

impl Calibration {
    /// Calibrates from wavelet variances computed elsewhere, one per axis named by its column
    /// (`gmwm wv --json`, or the precomputed WVs of recordings not at hand), as a streamed
    /// recording is: the selection, fit, inference and verdict use the WV only, the Allan
    /// variance is exact from it (`AV(m) = 2 nu2(2m)`, docs/methods.md §3.4), and what needs
    /// the samples is left out with a check line saying so: the spectrum (a vibration line is
    /// then not checked against one), the gravity check and the contamination check.
    ///
    /// # Errors
    /// [`ParamError`] for robust options (a robust calibration estimates its own WV from the
    /// samples); naming the series when one is not a classical Haar MODWT WV (the pipeline fits
    /// those), when its intervals are at another level than the options' `alpha`, or when the
    /// series differ in rate or length (one recording's axes); the pipeline's errors.
    pub(crate) fn run_wv(
        &self,
        name: Option<&str>,
        series: &[(String, WaveletVariance)],
        progress: &dyn Progress,
    ) -> Result<CalibrationReport, Error> {
        let Some((_, first)) = series.first() else {
            return Err(ParamError::new("wavelet variances", 0, "at least one series").into());
        };
        if self.options().wv.robust.is_some() {
            return Err(ParamError::new(
                "robust",
                "on (with a saved wavelet variance)",
                "off: a robust calibration estimates its own WV from the samples",
            )
            .into());
        }
        for (column, wv) in series {
            let what = |v: String, expected: &str| -> Error {
                ParamError::new(
                    "wavelet variance",
                    format!("series {column}: {v}"),
                    expected,
                )
                .into()
            };
            if wv.robust().is_some()
                || wv.transform() != Transform::Modwt
                || wv.filter() != WaveletFilter::Haar
            {
                return Err(what(
                    "a robust or non-Haar-MODWT WV".into(),
                    "the classical Haar MODWT WV the calibration fits",
                ));
            }
            if (wv.alpha() - self.options().wv.alpha).abs() > 1e-12 {
                return Err(what(
                    format!("intervals at alpha {}", wv.alpha()),
                    &format!(
                        "intervals at the calibration's alpha {} (give --alpha {}, or save the WV at that level)",
                        self.options().wv.alpha,
                        wv.alpha()
                    ),
                ));
            }
            if wv.freq_hz() != first.freq_hz() || wv.n() != first.n() {
                return Err(what(
                    format!("{} samples at {} Hz", wv.n(), wv.freq_hz()),
                    &format!(
                        "the rate and length of the first series ({} samples at {} Hz): the axes of one recording",
                        first.n(),
                        first.freq_hz()
                    ),
                ));
            }
        }
        let infos: Vec<SensorInfo> = wv_columns(series).into_iter().map(|c| c.1).collect();
        let axes: Vec<InputAxis<'_>> = series
            .iter()
            .zip(&infos)
            .map(|((column, wv), info)| InputAxis {
                column,
                info,
                data: AxisData::Streamed {
                    wv: Box::new(wv.clone()),
                    robust: None,
                    psd: Some(Err(
                        "calibrated from a saved wavelet variance, without the samples".into(),
                    )),
                },
            })
            .collect();
        let checks = vec![format!(
            "calibrated from saved wavelet variances ({} samples per axis): the Allan variance from the WV (exact at its cluster times), starting values from the WV; without the samples there is no spectrum (a vibration line is not checked against one), no gravity check and no contamination check",
            first.n()
        )];
        self.run_axes(name, first.freq_hz(), first.n(), axes, checks, progress)
    }
}

/// The columns of saved wavelet variances (`Calibration::run_wv`) and what each measures, by
/// its name (`gyro_x`, `accel_z`, ...; units from the calibration's flags).
pub fn wv_columns(series: &[(String, WaveletVariance)]) -> Vec<(String, SensorInfo)> {
    series
        .iter()
        .map(|(column, _)| (column.clone(), SensorInfo::of_column(column, None, false)))
        .collect()
}

/// The account of saved wavelet variances (`Calibration::run_wv`) as a recording's, counted
/// in samples (the series' `n`, which the WV was computed from; no row of a file is read), and
/// the note that says so.
pub fn wv_account(series: &[(String, WaveletVariance)]) -> (crate::imu::SampleAccount, String) {
    let n = series.first().map_or(0, |(_, wv)| wv.n());
    let names = series.iter().map(|(c, _)| c.clone()).collect();
    (
        // the WV's samples, not rows of a file at hand
        crate::imu::SampleAccount::all_used(names, "sample", n as u64),
        format!(
            "{} wavelet variance(s) read, of {n} samples each: calibrated from them, without the samples",
            series.len()
        ),
    )
}

/// A recording opened for a calibration, read the way its kind and length ask, as
/// [`Calibration::open`] settled once from the recording's [`Probe`].
#[derive(Debug)]
pub enum CalibrationSource {
    /// Read into memory.
    Memory(Recording),
    /// Text, binary IMU records or a ROS topic, read in one pass and spooled
    /// ([`StreamedTable`]).
    Spooled(StreamedTable),
    /// A raw binary f64/f32 file, streamed from the file as it is.
    Raw {
        /// The file, probed.
        probe: Probe,
        /// How it is read.
        read: ReadOptions,
    },
    /// Several recordings of one sensor, each named, calibrated as one sensor
    /// (docs/methods.md §5.12, `Calibration::run_pooled`).
    Pooled(Vec<(String, Imu)>),
    /// Wavelet variances saved by `gmwm wv --json`, by series name, calibrated as a streamed
    /// recording's (`Calibration::run_wv`); `name` is the file's.
    SavedWv {
        /// The file's name, for the report.
        name: Option<String>,
        /// The series, by name (`gyro_x`, ...).
        series: Vec<(String, WaveletVariance)>,
    },
}

impl Calibration {
    /// Opens the recording probed as `probe` for [`Calibration::run_source`]: a long
    /// recording that the options calibrate with the classical Haar WV is streamed (a raw
    /// binary file from the file, text, IMU records and ROS topics through one spooled pass,
    /// `Calibration::streams`); any other is read into memory ([`Recording::open`]). A topic
    /// is for ROS recordings: with another file the in-memory reader refuses it.
    ///
    /// # Errors
    /// The readers' errors naming the file ([`CalibError::Read`](crate::calib::CalibError::Read));
    /// [`CalibError::UnitOnRos`](crate::calib::CalibError::UnitOnRos) for a unit flag on a ROS
    /// recording without `force_units`.
    pub fn open(&self, probe: &Probe, opts: &RecordingOptions) -> Result<CalibrationSource, Error> {
        if probe.is_ros() && !self.options().force_units {
            let given = [
                ("--gyro-unit", self.options().gyro_unit),
                ("--accel-unit", self.options().accel_unit),
            ];
            if let Some((flag, Some(u))) = given.into_iter().find(|(_, u)| u.is_some()) {
                return Err(Error::UnitOnRos {
                    flag,
                    unit: u.symbol().to_string(),
                });
            }
        }
        let streamed =
            (opts.topic.is_none() || probe.is_ros()) && self.streams(probe, &opts.read)?;
        Ok(if streamed && streamed_size(probe, &opts.read)?.is_some() {
            CalibrationSource::Spooled(StreamedTable::open_recording(probe, opts)?)
        } else if streamed {
            CalibrationSource::Raw {
                probe: probe.clone(),
                read: opts.read.clone(),
            }
        } else {
            CalibrationSource::Memory(Recording::open_probed(probe, opts)?)
        })
    }

    /// Calibrates a recording opened by [`Calibration::open`], or several recordings or saved
    /// wavelet variances given as a [`CalibrationSource`]: [`Calibration::run`] on one in
    /// memory; streamed from its spool (text, IMU records, ROS) or from the file (raw binary),
    /// with the same report up to the contamination check and the starting values (module
    /// docs); pooled over several recordings (docs/methods.md §5.12); from saved WVs as a
    /// streamed recording is.
    ///
    /// ```no_run
    /// use gmwm::{read_table, Calibration, CalibrationOptions, CalibrationSource, Imu, ReadOptions};
    /// let pooled = ["imu1.csv.gz", "imu2.csv.gz"]
    ///     .iter()
    ///     .map(|f| Ok((f.to_string(), Imu::from_table(read_table(f.as_ref(), &ReadOptions::default())?)?)))
    ///     .collect::<Result<Vec<_>, gmwm::Error>>()?;
    /// struct Quiet; // no progress shown
    /// impl gmwm::Progress for Quiet {}
    /// let calibration = Calibration::new(CalibrationOptions::default());
    /// let report = calibration.run_source(&CalibrationSource::Pooled(pooled), &Quiet)?;
    /// assert_eq!(report.recordings.len(), 2);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// As those.
    pub fn run_source(
        &self,
        source: &CalibrationSource,
        progress: &dyn Progress,
    ) -> Result<CalibrationReport, Error> {
        match source {
            CalibrationSource::Memory(recording) => self.run_timed(
                &recording.imu,
                recording.timing.as_ref().or(recording.imu.timing()),
                progress,
            ),
            CalibrationSource::Spooled(table) => self.run_table(table, progress),
            CalibrationSource::Raw { probe, read } => self.run_probed(probe, read, progress),
            CalibrationSource::Pooled(recordings) => {
                let named: Vec<(&str, &Imu)> = recordings
                    .iter()
                    .map(|(n, imu)| (n.as_str(), imu))
                    .collect();
                self.run_pooled(&named, progress)
            }
            CalibrationSource::SavedWv { name, series } => {
                self.run_wv(name.as_deref(), series, progress)
            }
        }
    }
}

/// The selected columns of the raw binary recording `path` (all without a selection) and what
/// each measures (by its name, else the sidecar's meaning; units from the name or sidecar),
/// without reading the samples.
///
/// # Errors
/// A file that is not raw binary f64/f32 ([`ParamError`]); a sidecar that cannot be read; a
/// selected column the file does not have.
pub fn binary_file_columns(
    path: &Path,
    read: &ReadOptions,
) -> Result<Vec<(String, SensorInfo)>, Error> {
    let layout = binary_layout(path, read)?.ok_or_else(|| {
        ParamError::new(
            "input",
            path.display().to_string(),
            "a raw binary f64/f32 recording (by --format, its name or its sidecar)",
        )
    })?;
    let (columns, infos) = selected(path, &layout, read, find_sidecar(path)?.as_ref())?;
    Ok(columns
        .into_iter()
        .zip(infos)
        .map(|(c, info)| (layout.names[c - 1].clone(), info))
        .collect())
}

/// The selected 1-based columns and what each measures.
fn selected(
    path: &Path,
    layout: &BinaryLayout,
    read: &ReadOptions,
    sidecar: Option<&crate::imu::Sidecar>,
) -> Result<(Vec<usize>, Vec<SensorInfo>), Error> {
    let (columns, _) = layout.selection(path, read, sidecar)?;
    let infos = columns
        .iter()
        .map(|&c| SensorInfo::of_column(&layout.names[c - 1], sidecar, false))
        .collect();
    Ok((columns, infos))
}

/// The classical WV of each column ([`binary_wavelet_variance`]: parallel, bounded memory,
/// the same bits on any number of threads); a column that cannot be analysed (a constant one,
/// say) gets its error and the others are computed without it.
fn classical_pass(
    path: &Path,
    layout: &BinaryLayout,
    columns: &[usize],
    levels: usize,
    freq_hz: f64,
    alpha: f64,
) -> Result<Vec<Result<WaveletVariance, crate::InputError>>, Error> {
    let opts = WvOptions {
        levels: Some(levels),
        alpha,
        ..WvOptions::default()
    };
    let mut failed: Vec<(usize, crate::InputError)> = Vec::new();
    let (kept, wvs) = loop {
        let kept: Vec<usize> = columns
            .iter()
            .copied()
            .filter(|c| !failed.iter().any(|(f, _)| f == c))
            .collect();
        if kept.is_empty() {
            break (kept, Vec::new());
        }
        match binary_wavelet_variance(path, layout, &kept, freq_hz, &opts) {
            Ok(wvs) => break (kept, wvs),
            // a column that cannot be analysed: again without it
            Err(ReadError::Series { column, source, .. })
                if kept.iter().any(|&c| layout.names[c - 1] == column) =>
            {
                let c = kept[kept
                    .iter()
                    .position(|&c| layout.names[c - 1] == column)
                    .unwrap_or(0)];
                failed.push((c, source.into()));
            }
            Err(e) => return Err(e.into()),
        }
    };
    // in the order of `columns`
    let mut out: Vec<(usize, Result<WaveletVariance, crate::InputError>)> = kept
        .into_iter()
        .zip(wvs.into_iter().map(Ok))
        .chain(failed.into_iter().map(|(c, e)| (c, Err(e))))
        .collect();
    out.sort_by_key(|(c, _)| columns.iter().position(|x| x == c));
    Ok(out.into_iter().map(|(_, r)| r).collect())
}

/// Per column and level, over the blocks: the sum of count x robust estimate and the sum of
/// counts (`None` once a block has no root at that level).
type Pooled = Vec<Vec<Option<(f64, usize)>>>;

/// Each column's Welch PSD from the streamed pass (an error as text: too short, say).
type StreamedPsds = Vec<Result<Box<Psd>, String>>;

/// Which of the series' blocks of [`ROBUST_BLOCK`] samples the robust check takes, in order
/// (0-based), and whether it takes the short last block: every block when there are at most
/// [`ROBUST_BLOCKS`] full ones (the short last one when it holds `min_rows` samples, or is the
/// only one); otherwise [`ROBUST_BLOCKS`] full blocks spread evenly, block `k` the one holding
/// the point `(2k + 1) / (2 · ROBUST_BLOCKS)` of the full blocks' span.
fn robust_blocks(n: usize, min_rows: usize) -> (Vec<usize>, bool) {
    let full = n / ROBUST_BLOCK;
    let short = n % ROBUST_BLOCK;
    if full <= ROBUST_BLOCKS {
        let with_short = short > 0 && (short >= min_rows || full == 0);
        return ((0..full).collect(), with_short);
    }
    let picked = (0..ROBUST_BLOCKS)
        .map(|k| (2 * k + 1) * full / (2 * ROBUST_BLOCKS))
        .collect();
    (picked, false)
}

/// What the streamed robust check took: `blocks` of the series' `of_blocks` blocks
/// ([`robust_blocks`]), `samples` samples an axis in all.
#[derive(Debug, Clone, Copy)]
struct RobustCoverage {
    blocks: usize,
    of_blocks: usize,
    samples: usize,
}

/// The blocks' robust WVs of each column, pooled (module docs), what they covered, and each
/// column's Welch PSD of the same blocks at `freq_hz` (segments never straddle two blocks that
/// are not consecutive). On a recording of at most [`ROBUST_BLOCKS`] blocks that is every
/// sample but a short last block too short for 64 windows of the coarsest level; on a longer
/// one, [`ROBUST_BLOCKS`] blocks spread over it, the others skipped unread.
fn robust_pass(
    path: &Path,
    layout: &BinaryLayout,
    columns: &[usize],
    opts: &WvOptions,
    (n, freq_hz): (usize, f64),
) -> Result<(Pooled, RobustCoverage, StreamedPsds), Error> {
    let levels = opts.levels.unwrap_or(ROBUST_LEVELS);
    let (picked, with_short) = robust_blocks(n, 64 << levels);
    let mut chunks = BinaryChunks::open(path, layout.format, layout.ncols, 1, ROBUST_BLOCK)?;
    // per column and level: sum of count x estimate, sum of counts; None once undefined
    let mut pooled: Pooled = vec![vec![Some((0.0, 0)); levels]; columns.len()];
    let mut buffers = vec![Vec::with_capacity(ROBUST_BLOCK); columns.len()];
    let analysed = picked.len() * ROBUST_BLOCK + if with_short { n % ROBUST_BLOCK } else { 0 };
    let too_short = || {
        crate::error::SeriesError::TooShort {
            n: analysed,
            needed: MIN_SEGMENT,
            what: "a Welch PSD (one segment)".into(),
        }
        .to_string()
    };
    let mut welch: Vec<Result<Welch, String>> = (0..columns.len())
        .map(|_| {
            let l = segment_length(analysed).ok_or_else(too_short)?;
            Welch::new(l, freq_hz).map_err(|e| e.to_string())
        })
        .collect();
    let mut coverage = RobustCoverage {
        blocks: 0,
        of_blocks: n.div_ceil(ROBUST_BLOCK),
        samples: 0,
    };
    let mut at = 0usize;
    let blocks = picked
        .iter()
        .copied()
        .chain(with_short.then_some(n / ROBUST_BLOCK));
    for block in blocks {
        if block > at {
            chunks.skip_rows(((block - at) * ROBUST_BLOCK) as u64)?;
            welch.iter_mut().flatten().for_each(Welch::discontinue);
        }
        at = block + 1;
        let Some(rows) = chunks.next_chunk_of(columns, &mut buffers)? else {
            break;
        };
        coverage.blocks += 1;
        coverage.samples += rows;
        // a column whose samples fail keeps its error
        welch.par_iter_mut().zip(&buffers).for_each(|(w, x)| {
            if let Ok(acc) = w {
                if let Err(e) = acc.push(x) {
                    *w = Err(e.to_string());
                }
            }
        });
        let block_levels = levels.min(default_levels(rows, Transform::Modwt, WaveletFilter::Haar));
        let results: Vec<Option<WaveletVariance>> = buffers
            .par_iter()
            .map(|x| {
                wavelet_variance(
                    x,
                    1.0,
                    &WvOptions {
                        levels: Some(block_levels),
                        ..*opts
                    },
                )
                .ok()
            })
            .collect();
        for (pool, r) in pooled.iter_mut().zip(results) {
            for (j, slot) in pool.iter_mut().enumerate() {
                let estimate = r
                    .as_ref()
                    .and_then(|w| Some((*w.wv.get(j)?, *w.n_coefficients.get(j)?)));
                *slot = match (*slot, estimate) {
                    (Some((s, m)), Some((v, k))) if v.is_finite() && v > 0.0 => {
                        Some((s + v * k as f64, m + k))
                    }
                    _ => None,
                };
            }
        }
    }
    let psds = welch
        .into_iter()
        .map(|w| Ok(Box::new(w?.finish().map_err(|e| e.to_string())?)))
        .collect();
    Ok((pooled, coverage, psds))
}

/// The pooled robust WV of each column (module docs); `classical` gives the intervals'
/// classical side. A level whose root a block lacks is undefined.
fn robust_wvs(
    pooled: Pooled,
    classical: &[Result<WaveletVariance, crate::InputError>],
    opts: &WvOptions,
) -> Vec<Result<Box<WaveletVariance>, String>> {
    let levels = opts.levels.unwrap_or(ROBUST_LEVELS);
    pooled
        .into_iter()
        .zip(classical)
        .map(|(pool, c)| {
            let c = c.as_ref().map_err(|e| e.to_string())?;
            let robust: Vec<f64> = pool
                .iter()
                .map(|p| p.map_or(f64::NAN, |(s, m)| s / m as f64))
                .collect();
            let counts: Vec<usize> = pool.iter().map(|p| p.map_or(0, |(_, m)| m)).collect();
            let eta: Vec<f64> = counts
                .iter()
                .enumerate()
                .map(|(j, &m)| eta3(m.max(1), j + 1))
                .collect();
            let k = levels.min(c.wv.len());
            Ok(Box::new(WaveletVariance::assemble(
                c.n,
                c.freq_hz,
                opts,
                &c.wv[..k],
                Some(&robust[..k]),
                counts[..k].to_vec(),
                eta[..k].to_vec(),
            )))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::{robust_blocks, ROBUST_BLOCK, ROBUST_BLOCKS};

    /// Up to `ROBUST_BLOCKS` full blocks: all of them, and the short last one when it is long
    /// enough or the only one; beyond: `ROBUST_BLOCKS` distinct full blocks spread evenly.
    #[test]
    fn robust_blocks_take_all_or_spread_evenly() {
        let b = ROBUST_BLOCK;
        assert_eq!(robust_blocks(3 * b + 100, 1000), (vec![0, 1, 2], false));
        assert_eq!(robust_blocks(3 * b + 1000, 1000), (vec![0, 1, 2], true));
        assert_eq!(robust_blocks(100, 1000), (vec![], true));
        assert_eq!(robust_blocks(8 * b, 1000), ((0..8).collect(), false));
        // 10^8 samples: 47 full blocks, the short one left out
        let (picked, short) = robust_blocks(100_000_000, 1000);
        assert!(!short);
        assert_eq!(picked, vec![2, 8, 14, 20, 26, 32, 38, 44]);
        for full in [9, 10, 16, 17, 100, 4097] {
            let (picked, short) = robust_blocks(full * b + 7, 1);
            assert!(!short);
            assert_eq!(picked.len(), ROBUST_BLOCKS);
            assert!(picked.windows(2).all(|w| w[0] < w[1]), "{full}: {picked:?}");
            assert!(*picked.last().unwrap() < full);
            // as many blocks before the first as after the last, within one
            let before = picked[0];
            let after = full - 1 - picked.last().unwrap();
            assert!(before.abs_diff(after) <= 1, "{full}: {picked:?}");
        }
    }
}
