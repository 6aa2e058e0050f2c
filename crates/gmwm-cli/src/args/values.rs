//! Value parsers of the flags: numbers refused outside their domain with a usage error, and
//! the engine's named choices ([`gmwm::Named`]) parsed by the engine's `FromStr`, with
//! their possible values (and the help of each, in the CLI's words) listed by `--help`.

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use gmwm::{
    AllanKind, AvConvention, AxisPolicy, CovarianceMethod, GapPolicy, HeaderMode, ImuRecordType,
    InputFormat, Named, OptimismConvention, OptimismMethod, RobustConvention, SelectionRule,
    TimePolicy, TimeUnit, Transform, Weighting,
};
use std::str::FromStr;

/// An engine choice as `--help` shows it: each value's help, in the CLI's words (the engine
/// names the values; the `match` makes every value documented).
pub trait ValueHelp: Named {
    /// One line on what the value does.
    fn help(self) -> &'static str;
}

/// The parser of an engine choice `T`: its names are the possible values (clap refuses any
/// other with `[possible values: ...]`), each read by `T`'s `FromStr`.
pub fn choice<T>() -> impl TypedValueParser<Value = T>
where
    T: ValueHelp + FromStr + Clone + Send + Sync + 'static,
    T::Err: std::error::Error + Send + Sync + 'static,
{
    PossibleValuesParser::new(
        T::VALUES
            .iter()
            .map(|v| PossibleValue::new(v.name()).help(v.help())),
    )
    .try_map(|name| name.parse::<T>())
}

impl ValueHelp for InputFormat {
    fn help(self) -> &'static str {
        match self {
            Self::Auto => {
                "From the name, the JSON sidecar and the first bytes (.csv, .tsv, .txt, .gz, \
                 .f64, .f32)"
            }
            Self::Csv => "Comma-separated text",
            Self::Tsv => "Tab-separated text",
            Self::ImuRecord(t) => match t {
                ImuRecordType::Imar => {
                    "iMAR binary IMU records (docs/methods.md §9.2-9.3: f64 time + 6 int32 \
                     increments)"
                }
                ImuRecordType::Ln200 => {
                    "Northrop Grumman LN-200 records (int32 increments, gyro 2^-21 rad)"
                }
                ImuRecordType::Ln200Ig => "LN-200 IG records (int32 increments, gyro 2^-19 rad)",
                ImuRecordType::Ixsea => "iXblue (IXSEA) records (f64 increments, gyro 1 arcsec)",
                ImuRecordType::NavchipInt => "NavChip integer records (int32 increments)",
                ImuRecordType::NavchipFlt => "NavChip float records (f64 increments)",
            },
            Self::F64 => "Raw little-endian 64-bit floats",
            Self::F32 => "Raw little-endian 32-bit floats",
        }
    }
}

impl ValueHelp for HeaderMode {
    fn help(self) -> &'static str {
        match self {
            Self::Auto => "A header iff the first row has a non-numeric field",
            Self::Present => "The first row is a header",
            Self::Absent => "There is no header",
        }
    }
}

impl ValueHelp for TimePolicy {
    fn help(self) -> &'static str {
        match self {
            Self::Strict => "An error naming the line (the default)",
            Self::DropDuplicates => "Drop the row, counted in a warning",
            Self::Sort => "Sort the rows by stamp, then drop repeats (read in memory only)",
        }
    }
}

impl ValueHelp for GapPolicy {
    fn help(self) -> &'static str {
        match self {
            Self::Aware => "The observed samples on their time grid (the default)",
            Self::Contiguous => "The samples as one series, the gaps ignored",
        }
    }
}

impl ValueHelp for TimeUnit {
    fn help(self) -> &'static str {
        match self {
            Self::Seconds => "Seconds",
            Self::Milliseconds => "Milliseconds",
            Self::Microseconds => "Microseconds",
            Self::Nanoseconds => "Nanoseconds",
        }
    }
}

impl ValueHelp for Transform {
    fn help(self) -> &'static str {
        match self {
            Self::Modwt => "Maximal-overlap DWT",
            Self::Dwt => "Decimated DWT",
        }
    }
}

impl ValueHelp for RobustConvention {
    fn help(self) -> &'static str {
        match self {
            Self::Exact => "Correct tuning constant, root-finder from a robust start",
            Self::Package => "The R package's constant and solver (for comparisons)",
        }
    }
}

impl ValueHelp for AllanKind {
    fn help(self) -> &'static str {
        match self {
            Self::Overlapping => "Maximal-overlap Allan variance",
            Self::NonOverlapping => "Non-overlapping Allan variance",
            Self::Modified => "Modified Allan variance",
            Self::Hadamard => "Overlapping Hadamard variance",
            Self::HadamardNonOverlapping => "Non-overlapping Hadamard variance",
        }
    }
}

impl ValueHelp for AvConvention {
    fn help(self) -> &'static str {
        match self {
            Self::Textbook => "Textbook estimators",
            Self::Package => "The R package's estimators",
        }
    }
}

impl ValueHelp for SelectionRule {
    fn help(self) -> &'static str {
        match self {
            Self::Navigation => {
                "The most of white noise and random walk (the terms a navigation filter \
                 carries), then the fewest parameters"
            }
            Self::Parsimonious => "The fewest parameters (the one-standard-error rule)",
            Self::WicMinimum => "The smallest WIC (the package's rule, on canonical models)",
        }
    }
}

impl ValueHelp for OptimismMethod {
    fn help(self) -> &'static str {
        match self {
            Self::Asymptotic => {
                "Closed form with the full model's V, exact or simulated as --covariance says \
                 (the package default)"
            }
            Self::Bootstrap => {
                "Parametric bootstrap per candidate (about K times slower for K candidates)"
            }
        }
    }
}

impl ValueHelp for OptimismConvention {
    fn help(self) -> &'static str {
        match self {
            Self::Corrected => "(B + D)^+ A' Omega and tr(Omega A dTheta V)",
            Self::Package => "The R package's formula",
        }
    }
}

impl ValueHelp for CovarianceMethod {
    fn help(self) -> &'static str {
        match self {
            Self::Auto => "Exact when the model is covered, else simulated",
            Self::Exact => "Exact (an error for a model it does not cover)",
            Self::Bootstrap => "Parametric bootstrap, as the R package",
        }
    }
}

impl ValueHelp for Weighting {
    fn help(self) -> &'static str {
        match self {
            Self::Fast => "Inverse squared CI widths (package \"fast\")",
            Self::Diag => {
                "Inverse of the Percival asymptotic diagonal covariance (docs/methods.md §1.10)"
            }
            Self::Bootstrap => {
                "Inverse of the parametric-bootstrap WV variances at the fast fit, then refit \
                 (§5.2)"
            }
        }
    }
}

impl ValueHelp for AxisPolicy {
    fn help(self) -> &'static str {
        match self {
            Self::Worst => "The largest value over the axes, per key",
            Self::Mean => "The root mean square over the axes",
            Self::PerAxis => "One file per axis letter (FILE.x.yaml, ...)",
        }
    }
}

/// `--gyro-unit`, `--accel-unit`.
pub fn signal_unit(s: &str) -> Result<gmwm::SignalUnit, String> {
    s.parse::<gmwm::SignalUnit>().map_err(|_| {
        "must be rad/s, deg/s, deg/h (gyroscope) or m/s^2, g, mg (accelerometer)".into()
    })
}

/// `--datasheet`: the engine's reading, its error naming the bad item.
pub fn datasheet(s: &str) -> Result<gmwm::Datasheet, String> {
    s.parse::<gmwm::Datasheet>().map_err(|e| e.to_string())
}

/// `--inflate`: a factor of at least 1.
pub fn inflation(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 1.0 => Ok(v),
        _ => Err("must be a factor >= 1, e.g. 2".into()),
    }
}

/// `--horizon`: a mission length in seconds, > 0.
pub fn horizon_seconds(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err("must be a mission length in seconds > 0, e.g. 600".into()),
    }
}

/// `--tolerance`: a fraction in (0, 1].
pub fn tolerance(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v > 0.0 && v <= 1.0 => Ok(v),
        _ => Err("must be a fraction in (0, 1], e.g. 0.1 for 10%".into()),
    }
}

/// `--freq`: a positive finite number of hertz.
pub fn positive_hz(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err("must be a positive number of hertz, e.g. 100".into()),
    }
}

/// `--eff`: a Gaussian efficiency in (0, 0.99].
pub fn efficiency(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v > 0.0 && v <= 0.99 => Ok(v),
        _ => Err("must be a Gaussian efficiency in (0, 0.99], e.g. 0.6".into()),
    }
}

/// `--alpha`: a significance level in (0, 0.5]
/// ([`gmwm::significance_level_problem`]).
pub fn alpha(s: &str) -> Result<f64, String> {
    let v = s
        .trim()
        .parse::<f64>()
        .map_err(|_| "must be a significance level in (0, 0.5]: 0.05 gives 95% intervals")?;
    match gmwm::significance_level_problem(v) {
        None => Ok(v),
        Some(why) => Err(why),
    }
}

/// A count of at least `min`: digits, or a whole number in exponent notation (`1e6`).
fn count_at_least(s: &str, min: usize) -> Result<usize, String> {
    let t = s.trim();
    let v = t.parse::<usize>().ok().or_else(|| {
        t.parse::<f64>()
            .ok()
            .filter(|x| x.is_finite() && *x >= 0.0 && x.fract() == 0.0 && *x < 9.0e15)
            .map(|x| x as usize)
    });
    match v {
        Some(v) if v >= min => Ok(v),
        _ => Err(format!("must be a whole number >= {min}")),
    }
}

/// A whole number >= 1 (`--G`, `--levels`, `--ncols`, `--n`).
pub fn at_least_1(s: &str) -> Result<usize, String> {
    count_at_least(s, 1)
}

/// A whole number >= 2 (`--bootstrap`: a covariance needs two replicates).
pub fn at_least_2(s: &str) -> Result<usize, String> {
    count_at_least(s, 2).map_err(|e| format!("{e} (a covariance needs two replicates)"))
}

/// A number of windows (`--windows`): a whole number >= 2 (a dependence needs two levels).
pub fn window_count(s: &str) -> Result<usize, String> {
    count_at_least(s, 2)
        .map_err(|e| format!("{e} (a dependence needs windows at two levels at least)"))
}

/// `--augment`: `mean`, `acf:K` or both (docs/methods.md §5.15).
pub fn augment(s: &str) -> Result<gmwm::Augment, String> {
    s.parse().map_err(|_| {
        "expected mean, acf:K (K from 1 to 16) or both, comma-separated, e.g. mean,acf:3".into()
    })
}

/// A whole number >= 0 (`--top`).
pub fn whole(s: &str) -> Result<usize, String> {
    count_at_least(s, 0)
}

/// A seed: a whole number from 0 to 2^64 - 1.
pub fn seed(s: &str) -> Result<u64, String> {
    s.trim()
        .parse::<u64>()
        .map_err(|_| "must be a whole number from 0 to 18446744073709551615".into())
}
