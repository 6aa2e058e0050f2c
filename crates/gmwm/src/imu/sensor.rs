//! The [`Imu`] object of docs/methods.md §9.1: sensor columns with their sensor type, axis, unit
//! and a common sampling rate.

use super::read::{Column, ColumnSelector, ImuRecordType, ReadWarning, Table};
use super::sidecar::Sidecar;
use super::timing::TimingReport;
use super::ReadError;
use crate::error::{check_freq, ParamError};
use crate::imu::ReadError as Error;
use serde::{Deserialize, Serialize};
use std::fmt;

/// Kind of sensor behind a column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Sensor {
    /// Gyroscope (angular rate).
    Gyroscope,
    /// Accelerometer (specific force).
    Accelerometer,
    /// Anything else (temperature, an unnamed column, ...).
    Other,
}

impl Sensor {
    /// Short tag used in axis tags: `gyro`, `accel`, `other`.
    pub fn tag(self) -> &'static str {
        match self {
            Self::Gyroscope => "gyro",
            Self::Accelerometer => "accel",
            Self::Other => "other",
        }
    }
}

impl fmt::Display for Sensor {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Gyroscope => "Gyroscope",
            Self::Accelerometer => "Accelerometer",
            Self::Other => "Other",
        })
    }
}

/// What a column measures.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct SensorInfo {
    /// Sensor type.
    pub sensor: Sensor,
    /// Axis label, e.g. `X` (for [`Sensor::Other`], usually the column name).
    pub axis: String,
    /// Unit, free text (e.g. `rad/s`), if known.
    pub unit: Option<String>,
}

impl SensorInfo {
    /// Infers sensor and axis from a column name or a meaning text (a trailing `[..]` or `(..)`
    /// unit is ignored):
    ///
    /// - gyroscope: a word starting with `gyr` (`gyro_x`, `Gyro. X`, `gyr_z`), `angular`
    ///   followed by `velocity`/`vel`/`rate` (`angular_velocity.x`,
    ///   `field.angular_velocity.x`), or a first word `w`, `omega` or `g` (`w_RS_S_x` of
    ///   EuRoC/TUM-VI, `wx`, `gx`);
    /// - accelerometer: a word starting with `acc` (`accel_z`, `acc_x`,
    ///   `linear_acceleration.x`) or a first word `a` (`a_RS_S_x`, `ax`);
    ///
    /// the axis is a one-letter word `x`/`y`/`z` after the sensor word or a suffix glued to it
    /// (`gyrox`, `accz`, `wx`). `gyro_x`, `Gyro. X`, `"gyroscope X axis, ..."`,
    /// `w_RS_S_x [rad s^-1]` all give gyroscope X. `None` when either part is missing.
    pub fn infer(text: &str) -> Option<(Sensor, String)> {
        let lower = strip_unit(text).to_ascii_lowercase();
        let words: Vec<&str> = lower
            .split(|c: char| !c.is_ascii_alphanumeric())
            .filter(|w| !w.is_empty())
            .collect();
        let is_axis = |w: &str| matches!(w, "x" | "y" | "z");
        // sensor words anywhere first, then the one-letter forms of the first word
        let (pos, sensor, rest) = words
            .iter()
            .enumerate()
            .find_map(|(i, w)| {
                if let Some(r) = strip_any(w, &["gyroscope", "gyro", "gyr"]) {
                    Some((i, Sensor::Gyroscope, r))
                } else if let Some(r) = strip_any(w, &["accelerometer", "accel", "acc"]) {
                    Some((i, Sensor::Accelerometer, r))
                } else if *w == "angular"
                    && words
                        .get(i + 1)
                        .is_some_and(|n| matches!(*n, "velocity" | "vel" | "rate"))
                {
                    Some((i + 1, Sensor::Gyroscope, ""))
                } else {
                    None
                }
            })
            .or_else(|| {
                let w = words.first()?;
                first_letter(w).map(|(s, r)| (0, s, r))
            })?;
        let axis = if is_axis(rest) {
            rest
        } else {
            words.iter().skip(pos + 1).copied().find(|w| is_axis(w))?
        };
        Some((sensor, axis.to_ascii_uppercase()))
    }

    /// Sensor, axis and unit of every column of `table`, as [`Imu::from_table`] reads them:
    /// sensor and axis from the column name, else the sidecar's meaning; the unit the name
    /// states, else the sidecar's, else rad/s and m/s^2 for binary IMU records (docs/methods.md
    /// §9.3).
    pub fn of_table(table: &Table) -> Vec<SensorInfo> {
        let sidecar = table.facts.sidecar.as_ref();
        let record = table.facts.record_type.is_some();
        table
            .columns
            .iter()
            .map(|c| SensorInfo::of_column(&c.name, sidecar, record))
            .collect()
    }

    /// What the column `name` measures: [`SensorInfo::infer`] on its name, else on the
    /// sidecar's meaning of it, with [`SensorInfo::column_unit`] (`record`: binary IMU records).
    pub(crate) fn of_column(name: &str, sidecar: Option<&Sidecar>, record: bool) -> SensorInfo {
        let inferred = SensorInfo::infer(name).or_else(|| {
            sidecar
                .and_then(|s| s.meaning(name))
                .and_then(SensorInfo::infer)
        });
        let (sensor, axis) = inferred.unwrap_or((Sensor::Other, name.to_string()));
        let unit = SensorInfo::column_unit(name, sensor, sidecar, record);
        SensorInfo { sensor, axis, unit }
    }

    /// The unit of a column, as text: the one its name states, else the sidecar's for the
    /// column (`columns[k].unit`), else the sidecar's for its sensor, else rad/s and m/s^2
    /// for binary IMU records (`record`, docs/methods.md §9.3).
    pub fn column_unit(
        name: &str,
        sensor: Sensor,
        sidecar: Option<&Sidecar>,
        record: bool,
    ) -> Option<String> {
        let units = sidecar.and_then(|s| s.units.as_ref());
        let column = sidecar.and_then(|s| s.unit_of(name)).map(str::to_string);
        SensorInfo::unit_from_name(name)
            .or(column)
            .or_else(|| match sensor {
                Sensor::Gyroscope => units
                    .and_then(|u| u.gyro.clone())
                    .or_else(|| record.then(|| "rad/s".to_string())),
                Sensor::Accelerometer => units
                    .and_then(|u| u.accel.clone())
                    .or_else(|| record.then(|| "m/s^2".to_string())),
                Sensor::Other => None,
            })
    }

    /// The unit a column name states in a trailing `[..]` or `(..)`, as text:
    /// `w_RS_S_x [rad s^-1]` → `rad s^-1`, `acc_x (m/s^2)` → `m/s^2`; `None` without one.
    pub(crate) fn unit_from_name(name: &str) -> Option<String> {
        let stripped = strip_unit(name);
        let rest = name.trim()[stripped.len()..].trim();
        let inner = rest.get(1..rest.len().saturating_sub(1))?.trim();
        (!inner.is_empty()).then(|| inner.to_string())
    }
}

/// The one-letter sensor forms of a first word: `w`, `omega`, `g` (gyroscope), `a`
/// (accelerometer), alone or with a glued axis (`wx`, `ax`); the rest is the glued axis.
fn first_letter(w: &str) -> Option<(Sensor, &str)> {
    let is_axis = |w: &str| matches!(w, "x" | "y" | "z");
    for (p, sensor) in [
        ("omega", Sensor::Gyroscope),
        ("w", Sensor::Gyroscope),
        ("g", Sensor::Gyroscope),
        ("a", Sensor::Accelerometer),
    ] {
        if let Some(r) = w.strip_prefix(p) {
            if r.is_empty() || is_axis(r) {
                return Some((sensor, r));
            }
        }
    }
    None
}

/// `name` without a trailing `[..]` or `(..)` group (and the blanks before it).
fn strip_unit(name: &str) -> &str {
    let t = name.trim();
    for (open, close) in [('[', ']'), ('(', ')')] {
        if t.ends_with(close) {
            if let Some(at) = t.rfind(open) {
                return t[..at].trim_end();
            }
        }
    }
    t
}

fn strip_any<'a>(w: &'a str, prefixes: &[&str]) -> Option<&'a str> {
    prefixes.iter().find_map(|p| w.strip_prefix(p))
}

/// One column of an [`Imu`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Axis {
    /// What the column measures.
    pub info: SensorInfo,
    /// The data (name as in the file, finite values).
    pub column: Column,
}

impl Axis {
    /// Tag such as `gyro_x` or `accel_z`; for [`Sensor::Other`] the column name.
    pub fn tag(&self) -> String {
        match self.info.sensor {
            Sensor::Other => self.column.name.clone(),
            s => format!("{}_{}", s.tag(), self.info.axis.to_ascii_lowercase()),
        }
    }

    /// Sensor type.
    pub fn sensor(&self) -> Sensor {
        self.info.sensor
    }

    /// The samples.
    pub fn values(&self) -> &[f64] {
        &self.column.values
    }
}

/// An inertial measurement unit recording (docs/methods.md §9.1): gyroscope columns first, then
/// accelerometers, then other columns, all of the same length, sampled at `freq_hz`.
#[derive(Debug, Clone, PartialEq)]
pub struct Imu {
    axes: Vec<Axis>,
    freq_hz: f64,
    name: Option<String>,
    record_type: Option<ImuRecordType>,
    timing: Option<TimingReport>,
    warnings: Vec<ReadWarning>,
}

impl Imu {
    /// Builds an IMU from columns and what each measures.
    ///
    /// Columns are reordered stably: gyroscopes, accelerometers, others (docs/methods.md §9.1).
    ///
    /// # Errors
    /// [`ParamError`] if there are no columns, `info` and `columns` differ in length, columns
    /// differ in length or are empty, an axis label is empty, an axis repeats within one sensor
    /// (docs/methods.md §9.1 "duplicates within one sensor are refused"), or `freq_hz` is not
    /// positive and finite.
    pub fn new(
        columns: Vec<Column>,
        info: Vec<SensorInfo>,
        freq_hz: f64,
    ) -> Result<Self, ParamError> {
        check_freq(freq_hz)?;
        if columns.is_empty() {
            return Err(ParamError::new("columns", 0, "at least one column"));
        }
        if info.len() != columns.len() {
            return Err(ParamError::new(
                "sensors",
                info.len(),
                format!("one entry per column ({})", columns.len()),
            ));
        }
        let n = columns[0].values.len();
        if let Some(c) = columns.iter().find(|c| c.values.len() != n || n == 0) {
            return Err(ParamError::new(
                "columns",
                format!("{} with {} samples", c.name, c.values.len()),
                format!("non-empty columns of equal length ({n})"),
            ));
        }
        let mut axes: Vec<Axis> = columns
            .into_iter()
            .zip(info)
            .map(|(column, info)| Axis { info, column })
            .collect();
        for (i, a) in axes.iter().enumerate() {
            if a.info.axis.trim().is_empty() {
                return Err(ParamError::new(
                    "axis",
                    format!("\"\" for column {}", a.column.name),
                    "a non-empty label such as X",
                ));
            }
            if a.info.sensor == Sensor::Other {
                continue;
            }
            let dup = axes[..i].iter().any(|b| {
                b.info.sensor == a.info.sensor && b.info.axis.eq_ignore_ascii_case(&a.info.axis)
            });
            if dup {
                return Err(ParamError::new(
                    "axis",
                    format!("{} {} twice", a.info.sensor, a.info.axis),
                    "each axis at most once per sensor",
                ));
            }
        }
        axes.sort_by_key(|a| a.info.sensor);
        Ok(Self {
            axes,
            freq_hz,
            name: None,
            record_type: None,
            timing: None,
            warnings: Vec::new(),
        })
    }

    /// This IMU with `timing` as what its time stamps say (a simulated recording with gaps).
    #[cfg(test)]
    pub(crate) fn with_timing(mut self, timing: TimingReport) -> Self {
        self.timing = Some(timing);
        self
    }

    /// Builds an IMU from a table, inferring sensor and axis of each column from its name, else
    /// from the sidecar's meaning ([`SensorInfo::infer`]); columns that match neither become
    /// [`Sensor::Other`] with the column name as label. Units: the one the column name states
    /// (`SensorInfo::unit_from_name`), else the sidecar's, else rad/s and m/s^2 for binary
    /// IMU records (docs/methods.md §9.3), as text. The name comes from the sidecar, else the file
    /// name. The table's timing report and warnings are kept ([`Imu::timing`], [`Imu::warnings`]).
    ///
    /// # Errors
    /// [`ReadError::FreqNotDerivable`] if `table.freq_hz` is `None`; [`ParamError`] as
    /// [`Imu::new`] (e.g. two `gyro_x` columns).
    pub fn from_table(table: Table) -> Result<Self, Error> {
        let Some(freq_hz) = table.facts.freq_hz else {
            return Err(ReadError::FreqNotDerivable {
                path: table.facts.path,
                reason: "no freq_hz given, no time column, no sampling_frequency_hz in a sidecar",
            });
        };
        let info = SensorInfo::of_table(&table);
        let sidecar = table.facts.sidecar.as_ref();
        let name = sidecar.and_then(|s| s.name.clone()).or_else(|| {
            table
                .facts
                .path
                .file_name()
                .map(|f| f.to_string_lossy().into_owned())
        });
        let mut imu = Self::new(table.columns, info, freq_hz)?;
        imu.name = name;
        imu.record_type = table.facts.record_type;
        imu.timing = table.facts.timing;
        imu.warnings = table.facts.warnings;
        Ok(imu)
    }

    /// Sets the name.
    pub(crate) fn with_name(mut self, name: impl Into<String>) -> Self {
        self.name = Some(name.into());
        self
    }

    /// All axes: gyroscopes, then accelerometers, then others.
    pub fn axes(&self) -> &[Axis] {
        &self.axes
    }

    /// Iterates over `(tag, axis)` pairs, tags like `gyro_x`.
    pub fn iter(&self) -> impl Iterator<Item = (String, &Axis)> {
        self.axes.iter().map(|a| (a.tag(), a))
    }

    /// The axes, consumed (their columns move out without a copy).
    pub fn into_axes(self) -> Vec<Axis> {
        self.axes
    }

    /// The gyroscope axes.
    pub fn gyroscopes(&self) -> impl Iterator<Item = &Axis> {
        self.axes
            .iter()
            .filter(|a| a.info.sensor == Sensor::Gyroscope)
    }

    /// The accelerometer axes.
    pub fn accelerometers(&self) -> impl Iterator<Item = &Axis> {
        self.axes
            .iter()
            .filter(|a| a.info.sensor == Sensor::Accelerometer)
    }

    /// The axis with this tag (`gyro_x`, case-insensitive).
    pub fn axis(&self, tag: &str) -> Option<&Axis> {
        self.axes.iter().find(|a| a.tag().eq_ignore_ascii_case(tag))
    }

    /// `(number of gyroscopes, number of accelerometers)` (docs/methods.md §9.1 `num.sensor`).
    #[cfg(test)]
    pub(crate) fn num_sensor(&self) -> (usize, usize) {
        (self.gyroscopes().count(), self.accelerometers().count())
    }

    /// Sampling rate in Hz.
    pub fn freq_hz(&self) -> f64 {
        self.freq_hz
    }

    /// Name, if known.
    pub fn name(&self) -> Option<&str> {
        self.name.as_deref()
    }

    /// Binary record type, if read from one (docs/methods.md §9.1 `stype`).
    pub fn record_type(&self) -> Option<ImuRecordType> {
        self.record_type
    }

    /// What the time column of the file said about the sampling, if it had one.
    pub fn timing(&self) -> Option<&TimingReport> {
        self.timing.as_ref()
    }

    /// Soft problems found while reading the file ([`TableFacts::warnings`](crate::TableFacts::warnings)).
    pub fn warnings(&self) -> &[ReadWarning] {
        &self.warnings
    }

    /// Number of samples per axis.
    pub fn len(&self) -> usize {
        self.axes.first().map_or(0, |a| a.column.values.len())
    }

    /// Always `false`: an [`Imu`] holds at least one sample.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Keeps the axes named by `columns` (a column name, a tag such as `gyro_x`, or a 1-based
    /// index into [`Imu::axes`]), in the IMU's order.
    ///
    /// # Errors
    /// [`ReadError::UnknownColumn`] or [`ReadError::ColumnOutOfRange`] naming `path`.
    pub fn select(
        mut self,
        path: &std::path::Path,
        columns: &[ColumnSelector],
    ) -> Result<Self, ReadError> {
        let mut keep = vec![false; self.axes.len()];
        for sel in columns {
            let k = match sel {
                ColumnSelector::Index(i) if (1..=self.axes.len()).contains(i) => i - 1,
                ColumnSelector::Index(i) => {
                    return Err(ReadError::ColumnOutOfRange {
                        path: path.to_path_buf(),
                        index: *i,
                        ncols: self.axes.len(),
                    })
                }
                ColumnSelector::Name(n) => self
                    .axes
                    .iter()
                    .position(|a| a.column.name == *n || a.tag().eq_ignore_ascii_case(n))
                    .ok_or_else(|| ReadError::UnknownColumn {
                        path: path.to_path_buf(),
                        name: n.clone(),
                        available: self.axes.iter().map(|a| a.column.name.clone()).collect(),
                    })?,
            };
            keep[k] = true;
        }
        let mut k = 0;
        self.axes.retain(|_| {
            k += 1;
            keep[k - 1]
        });
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn col(name: &str) -> Column {
        Column {
            name: name.into(),
            values: vec![1.0, 2.0],
        }
    }

    fn info(sensor: Sensor, axis: &str) -> SensorInfo {
        SensorInfo {
            sensor,
            axis: axis.into(),
            unit: None,
        }
    }

    #[test]
    fn sensor_info_infer() {
        let g = |s: &str| SensorInfo::infer(s);
        assert_eq!(g("gyro_x"), Some((Sensor::Gyroscope, "X".into())));
        assert_eq!(g("Accel. Z"), Some((Sensor::Accelerometer, "Z".into())));
        assert_eq!(g("accy"), Some((Sensor::Accelerometer, "Y".into())));
        assert_eq!(
            g("gyroscope X axis, static error signal"),
            Some((Sensor::Gyroscope, "X".into()))
        );
        assert_eq!(g("temperature"), None);
        assert_eq!(g("gyro"), None);
        // EuRoC / TUM-VI, ROS and short headers
        assert_eq!(
            g("w_RS_S_x [rad s^-1]"),
            Some((Sensor::Gyroscope, "X".into()))
        );
        assert_eq!(
            g("a_RS_S_z [m s^-2]"),
            Some((Sensor::Accelerometer, "Z".into()))
        );
        for (name, sensor, axis) in [
            ("gx", Sensor::Gyroscope, "X"),
            ("wy", Sensor::Gyroscope, "Y"),
            ("ax", Sensor::Accelerometer, "X"),
            ("acc_x", Sensor::Accelerometer, "X"),
            ("gyr_z", Sensor::Gyroscope, "Z"),
            ("angular_velocity.x", Sensor::Gyroscope, "X"),
            ("field.angular_velocity.y", Sensor::Gyroscope, "Y"),
            ("linear_acceleration.z", Sensor::Accelerometer, "Z"),
            ("field.linear_acceleration.x", Sensor::Accelerometer, "X"),
        ] {
            assert_eq!(g(name), Some((sensor, axis.to_string())), "{name}");
        }
        for name in [
            "a",
            "x",
            "time",
            "field.orientation.x",
            "field.angular_velocity_covariance0",
            "field.header.seq",
            "temperature x",
        ] {
            assert_eq!(g(name), None, "{name}");
        }
        assert_eq!(
            g("a gyroscope X axis"),
            Some((Sensor::Gyroscope, "X".into()))
        );
        for name in ["gps_x", "wheel_x", "axis"] {
            assert_eq!(g(name), None, "{name}");
        }
    }

    #[test]
    fn unit_from_name() {
        let u = SensorInfo::unit_from_name;
        assert_eq!(u("w_RS_S_x [rad s^-1]").as_deref(), Some("rad s^-1"));
        assert_eq!(u("acc_x (m/s^2)").as_deref(), Some("m/s^2"));
        assert_eq!(u("gyro_x"), None);
        assert_eq!(u("gyro_x []"), None);
    }

    #[test]
    fn imu_new_orders_and_validates() {
        let imu = Imu::new(
            vec![col("a"), col("g")],
            vec![
                info(Sensor::Accelerometer, "X"),
                info(Sensor::Gyroscope, "X"),
            ],
            100.0,
        )
        .unwrap();
        let tags: Vec<String> = imu.iter().map(|(t, _)| t).collect();
        assert_eq!(tags, ["gyro_x", "accel_x"]);
        assert_eq!(imu.num_sensor(), (1, 1));

        let dup = Imu::new(
            vec![col("a"), col("b")],
            vec![info(Sensor::Gyroscope, "X"), info(Sensor::Gyroscope, "x")],
            100.0,
        );
        assert_eq!(
            dup.unwrap_err().to_string(),
            "invalid axis = Gyroscope x twice: each axis at most once per sensor"
        );
        for f in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(Imu::new(vec![col("a")], vec![info(Sensor::Other, "a")], f).is_err());
        }
        assert!(Imu::new(vec![], vec![], 1.0).is_err());
        let short = Column {
            name: "s".into(),
            values: vec![1.0],
        };
        assert!(Imu::new(
            vec![col("a"), short],
            vec![info(Sensor::Other, "a"), info(Sensor::Other, "s")],
            1.0
        )
        .is_err());
    }
}
