//! Time columns: which column holds time stamps, in which unit, and what the stamps say about
//! the sampling (rate, gaps, duplicates, reordering, jitter).
//!
//! - [`time_column_unit`]: whether a header name is a time column (`time`, `timestamp`, `t`,
//!   `stamp`, `%time`, `#timestamp [ns]`, `timestamp_ns`, `time_s`, `time [s]`,
//!   `field.header.stamp`, ...) and the unit the name states, if any;
//! - `infer_time_unit`: the unit of unlabelled stamps, from their magnitude (Unix epoch) or
//!   their step (a plausible IMU rate);
//! - `check_times`: a [`TimingReport`] of any sequence of stamps in seconds, monotonic or not,
//!   and its typed [`TimingWarning`]s.
//!
//! # Rate from time stamps
//! The rate is `1 / nominal step`, the nominal step being the mean of the *regular* steps: the
//! positive steps no longer than `GAP_FACTOR` times the median step (first the steps within
//! twice the median set a provisional nominal step, then the gap threshold is 1.5 times that).
//! The median makes the rate robust to gaps (a 0.5 s hole in a 200 Hz log does not lower it);
//! averaging the regular steps makes it robust to quantised stamps (300 Hz stamped in whole
//! milliseconds has steps 3, 3, 4 ms: the median says 333 Hz, the regular mean 300 Hz). On
//! evenly stamped data both equal `1 / median step`.

use serde::Serialize;
use std::fmt;
use std::str::FromStr;

use crate::error::ParamError;
use crate::math::sum::NeumaierSum;

/// 1 / Phi^-1(3/4): the median absolute deviation times this estimates a Gaussian standard
/// deviation.
const MAD_TO_SD: f64 = 1.4826;

/// A step longer than this many nominal steps is a gap (1.5: one missing sample at a perfectly
/// regular rate makes a step of 2, a jittery but complete log stays well below 1.5).
pub(crate) const GAP_FACTOR: f64 = 1.5;

/// Relative jitter (robust spread of the steps over the nominal step) above which the stamps
/// are reported as irregular: 10%, far above the quantisation of stamps in ns or µs at IMU
/// rates and below the spread of host-side receive times.
pub(crate) const JITTER_WARN: f64 = 0.1;

/// Plausible IMU rates used to infer the unit of unlabelled stamps from their step:
/// `[10 Hz, 10 kHz)`. The four units are a factor 1000 apart and this band spans exactly a
/// factor 1000, so every median step selects exactly one unit.
pub(crate) const PLAUSIBLE_RATE_HZ: (f64, f64) = (10.0, 10_000.0);

/// Unix-epoch seconds of plausible recording dates: 2001-09-09 (1e9 s) to 2103 (4.2e9 s).
/// A first stamp of that size in s, ms, µs or ns (x 1, 1e3, 1e6, 1e9) names the unit.
pub(crate) const EPOCH_S: (f64, f64) = (1.0e9, 4.2e9);

/// Unit of a time column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum TimeUnit {
    /// Seconds.
    Seconds,
    /// Milliseconds.
    Milliseconds,
    /// Microseconds.
    Microseconds,
    /// Nanoseconds.
    Nanoseconds,
}

impl TimeUnit {
    /// Every unit, coarsest first.
    pub const ALL: [Self; 4] = [
        Self::Seconds,
        Self::Milliseconds,
        Self::Microseconds,
        Self::Nanoseconds,
    ];

    /// Seconds per unit: 1, 1e-3, 1e-6, 1e-9.
    pub(crate) fn to_seconds(self) -> f64 {
        match self {
            Self::Seconds => 1.0,
            Self::Milliseconds => 1e-3,
            Self::Microseconds => 1e-6,
            Self::Nanoseconds => 1e-9,
        }
    }

    /// Short symbol: `s`, `ms`, `us`, `ns`.
    pub fn symbol(self) -> &'static str {
        match self {
            Self::Seconds => "s",
            Self::Milliseconds => "ms",
            Self::Microseconds => "us",
            Self::Nanoseconds => "ns",
        }
    }

    /// Parses a unit word as found in headers: `s`, `sec`, `secs`, `second(s)`; `ms`, `msec`,
    /// `millisecond(s)`; `us`, `µs`, `μs`, `usec`, `microsecond(s)`; `ns`, `nsec`,
    /// `nanosecond(s)` (case-insensitive).
    fn from_word(word: &str) -> Option<Self> {
        match word.trim().to_lowercase().as_str() {
            "s" | "sec" | "secs" | "second" | "seconds" => Some(Self::Seconds),
            "ms" | "msec" | "msecs" | "millisecond" | "milliseconds" | "millis" => {
                Some(Self::Milliseconds)
            }
            "us" | "µs" | "μs" | "usec" | "usecs" | "microsecond" | "microseconds" | "micros" => {
                Some(Self::Microseconds)
            }
            "ns" | "nsec" | "nsecs" | "nanosecond" | "nanoseconds" | "nanos" => {
                Some(Self::Nanoseconds)
            }
            _ => None,
        }
    }
}

impl fmt::Display for TimeUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.symbol())
    }
}

impl FromStr for TimeUnit {
    type Err = ParamError;

    /// `s`, `ms`, `us` (or `µs`), `ns` and the longer words of headers (`seconds`, `nsec`, ...).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::from_word(s).ok_or_else(|| ParamError::new("time unit", s, "one of s, ms, us, ns"))
    }
}

impl crate::names::Named for TimeUnit {
    const WHAT: &'static str = "time unit";
    const VALUES: &'static [Self] = &TimeUnit::ALL;

    /// The symbol (`s`, `ms`, `us`, `ns`); [`FromStr`] also reads the longer words.
    fn name(self) -> &'static str {
        self.symbol()
    }
}

/// Where the unit of a time column came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub(crate) enum UnitSource {
    /// Stated by the column name (`[ns]`, `_ms`, `(s)`, ...) or by the convention of the tool
    /// that names columns so (`%time` and `field.header.stamp` of `rostopic echo -p` are ns).
    Stated,
    /// Fixed by the file format (the seconds of binary IMU records, docs/methods.md §9.2).
    Format,
    /// Inferred from the values ([`infer_time_unit`]).
    Inferred,
    /// Given by the caller (`ReadOptions::time_unit`, the CLI's `--time-unit`).
    Flag,
}

impl fmt::Display for UnitSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Stated => "from the header",
            Self::Format => "from the format",
            Self::Inferred => "inferred from the values",
            Self::Flag => "as given",
        })
    }
}

/// Whether a header name is a time column and, if so, the unit its name states.
///
/// `None`: not a time column. `Some(None)`: a time column of unstated unit. `Some(Some(u))`:
/// a time column in `u`. Case-insensitive; a leading `#` or `%` and a `field.` prefix are
/// ignored; the unit is a trailing `[..]` or `(..)` (`time [s]`, `#timestamp [ns]`,
/// `time (ms)`) or a `_unit` / ` unit` suffix (`timestamp_ns`, `time_s`, `t_us`). The base
/// names are `time`, `times`, `timestamp`, `timestamps`, `time_stamp`, `t`, `stamp`,
/// `header.stamp`. `%time` and `field.header.stamp` (the `rostopic echo -p` columns) are
/// nanoseconds.
pub fn time_column_unit(name: &str) -> Option<Option<TimeUnit>> {
    let lower = name.trim().to_lowercase();
    let ros = matches!(lower.as_str(), "%time" | "field.header.stamp");
    if ros {
        return Some(Some(TimeUnit::Nanoseconds));
    }
    let (base, unit) = split_unit(&lower);
    let base = base.trim_start_matches(['#', '%']).trim();
    let base = base.strip_prefix("field.").unwrap_or(base);
    let is_time = matches!(
        base,
        "time" | "times" | "timestamp" | "timestamps" | "time_stamp" | "t" | "stamp"
    ) || base == "header.stamp";
    is_time.then_some(unit)
}

/// Splits a lowercase name into its base and a stated time unit (see [`time_column_unit`]).
fn split_unit(name: &str) -> (&str, Option<TimeUnit>) {
    let name = name.trim();
    for (open, close) in [('[', ']'), ('(', ')')] {
        if let Some(inner) = name.strip_suffix(close) {
            if let Some(at) = inner.rfind(open) {
                if let Some(u) = TimeUnit::from_word(&inner[at + open.len_utf8()..]) {
                    return (name[..at].trim(), Some(u));
                }
            }
        }
    }
    for sep in ['_', ' '] {
        if let Some(at) = name.rfind(sep) {
            if let Some(u) = TimeUnit::from_word(&name[at + 1..]) {
                return (name[..at].trim(), Some(u));
            }
        }
    }
    (name, None)
}

/// Infers the unit of unlabelled time stamps (raw values, in file order).
///
/// 1. Magnitude: a first stamp that is a Unix-epoch date ([`EPOCH_S`]) in s, ms, µs or ns
///    (about 1.7e9, 1.7e12, 1.7e15, 1.7e18 today) names the unit.
/// 2. Otherwise stamps with a fractional part and a median step of at most 1 are seconds (at
///    least 1 Hz; ms, µs and ns stamps are counters, fractional ones rare).
/// 3. Otherwise the step: the unit for which `1 / median positive step` is a plausible IMU
///    rate ([`PLAUSIBLE_RATE_HZ`], 10 Hz to 10 kHz): a median step in `(1e-4, 0.1]` is seconds,
///    `(0.1, 100]` milliseconds, `(100, 1e5]` microseconds, `(1e5, 1e8]` nanoseconds; shorter
///    steps are seconds, longer ones nanoseconds. Whole-number stamps at 1 to 10 Hz are
///    therefore read as ms (1 to 10 kHz): give the unit for such files.
///
/// `None` when neither rule applies (fewer than two stamps and no epoch-sized first stamp, or
/// no positive step).
#[cfg(test)]
pub(crate) fn infer_time_unit(raw: &[f64]) -> Option<TimeUnit> {
    infer_unit(0.0, raw)
}

/// [`infer_time_unit`] of the stamps `origin + raw[i]` (the readers give stamps relative to
/// the first one to keep their precision).
pub(crate) fn infer_unit(origin: f64, raw: &[f64]) -> Option<TimeUnit> {
    let first = (origin + *raw.first()?).abs();
    if let Some(u) = TimeUnit::ALL.into_iter().find(|u| {
        let s = first * u.to_seconds();
        s >= EPOCH_S.0 && s <= EPOCH_S.1
    }) {
        return Some(u);
    }
    let mut steps: Vec<f64> = raw
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| *d > 0.0)
        .collect();
    let step = median(&mut steps)?;
    if step <= 1.0 && raw.iter().any(|t| (origin + t).fract() != 0.0) {
        return Some(TimeUnit::Seconds);
    }
    let unit = TimeUnit::ALL
        .into_iter()
        // the coarsest unit giving at least 10 Hz: below 10 kHz unless it is seconds
        .find(|u| 1.0 / (step * u.to_seconds()) >= PLAUSIBLE_RATE_HZ.0)
        .unwrap_or(TimeUnit::Nanoseconds);
    Some(unit)
}

/// A gap: a step longer than `GAP_FACTOR` nominal steps.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Gap {
    /// 0-based index of the first sample after the gap.
    pub row: usize,
    /// 1-based physical line of that sample in a text file (`None` when not read from text).
    pub line: Option<u64>,
    /// Start of the gap (time of the sample before it), in seconds after the first sample.
    pub time_s: f64,
    /// Time without samples beyond the nominal step: the step less one nominal step, in
    /// seconds (a 0.5 s hole in a 200 Hz log is a step of 0.505 s and a gap of 0.5 s).
    pub duration_s: f64,
    /// Samples missing at the nominal rate: `round(duration / nominal step) - 1` (>= 1).
    pub missing: usize,
}

/// What a time column says about the sampling (`check_times`).
///
/// Wire format: `column`, `unit` (`seconds`, ...), `unit_source` (`stated`, `inferred`,
/// `flag`), `samples`, `start_s`, `span_s`, `rate_hz`, `mean_rate_hz`, `gaps` ([`Gap`]: `row`, `line`,
/// `time_s`, `duration_s`, `missing`), `duplicates`, `reordered`, `jitter` (`null` when
/// undefined).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TimingReport {
    /// Name of the time column.
    pub column: String,
    /// Its unit.
    pub unit: TimeUnit,
    /// Where the unit came from.
    pub(crate) unit_source: UnitSource,
    /// Number of stamps.
    pub samples: usize,
    /// The first stamp, in seconds (e.g. Unix time; an f64, so to about 0.2 µs at 1.7e9 s).
    pub start_s: f64,
    /// Latest minus earliest stamp, in seconds.
    pub(crate) span_s: f64,
    /// Rate in Hz: `1 / nominal step`, the mean of the regular steps (module docs; equal to
    /// `1 / median step` on evenly stamped data), to 12 significant digits; NaN when no step is
    /// positive.
    pub(crate) rate_hz: f64,
    /// `(samples - 1) / span_s`: what the rate would be without gaps (NaN for a zero span).
    pub(crate) mean_rate_hz: f64,
    /// Steps longer than `GAP_FACTOR` nominal steps, in order.
    pub gaps: Vec<Gap>,
    /// Steps of exactly zero (a stamp repeated).
    pub(crate) duplicates: usize,
    /// Negative steps (a stamp earlier than its predecessor).
    pub reordered: usize,
    /// Robust relative spread of the regular steps: `1.4826 · MAD / nominal step` (0 for evenly
    /// spaced stamps; NaN when no step is positive).
    pub(crate) jitter: f64,
}

/// Median of a non-empty slice (sorted in place); `None` when empty.
fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_unstable_by(f64::total_cmp);
    let m = v.len() / 2;
    Some(if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    })
}

/// Significant digits kept in [`TimingReport::rate_hz`]: 12, far finer than any time stamp
/// resolves a rate (ns stamps over 1 s: 1e-9), so that a 200 Hz log reads 200 and not
/// 199.99999999999997 from the rounding of its steps.
const RATE_DIGITS: i32 = 12;

fn round_significant(x: f64) -> f64 {
    if !x.is_finite() || x == 0.0 {
        return x;
    }
    let d = RATE_DIGITS - 1 - x.abs().log10().floor() as i32;
    let p = 10f64.powi(d.abs());
    let r = if d >= 0 {
        (x * p).round() / p
    } else {
        (x / p).round() * p
    };
    if r.is_finite() {
        r
    } else {
        x
    }
}

/// Mean of the positive steps no longer than `limit`, `sorted` being the positive steps in
/// ascending order (each repeated as often as it occurs); `None` if there is none. Summed in
/// ascending order, so that the mean depends on the multiset of steps only: the streamed check
/// ([`StepStats`]), which holds each distinct step once with its count, adds the same values in
/// the same order and gets the same bits.
fn mean_within(sorted: impl Iterator<Item = f64>, limit: f64) -> Option<f64> {
    let mut sum = NeumaierSum::default();
    let mut count = 0usize;
    for d in sorted.take_while(|&d| d <= limit) {
        sum.add(d);
        count += 1;
    }
    (count > 0).then(|| sum.total() / count as f64)
}

/// The weighted median of `(value, count)` pairs (sorted in place by value), as [`median`]
/// takes it of the values each repeated `count` times; `None` when empty.
fn weighted_median(v: &mut [(f64, u64)]) -> Option<f64> {
    let total: u64 = v.iter().map(|p| p.1).sum();
    if total == 0 {
        return None;
    }
    v.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    // the value of 0-based rank r
    let at = |r: u64| {
        let mut seen = 0;
        for &(x, c) in v.iter() {
            seen += c;
            if r < seen {
                return x;
            }
        }
        v[v.len() - 1].0
    };
    let m = total / 2;
    Some(if total % 2 == 1 {
        at(m)
    } else {
        0.5 * (at(m - 1) + at(m))
    })
}

/// `(samples - 1) / span`, NaN for a zero span.
fn mean_rate(samples: usize, span_s: f64) -> f64 {
    if span_s > 0.0 {
        (samples - 1) as f64 / span_s
    } else {
        f64::NAN
    }
}

/// The nominal step (module docs) from the median positive step and the positive steps in
/// ascending order: a provisional one over the steps within twice the median, then the mean
/// of the regular steps, those within [`GAP_FACTOR`] of it.
fn nominal_step<I: Iterator<Item = f64>>(med: f64, sorted: impl Fn() -> I) -> f64 {
    let provisional = mean_within(sorted(), 2.0 * med).unwrap_or(med);
    mean_within(sorted(), GAP_FACTOR * provisional).unwrap_or(provisional)
}

/// The gap before 0-based sample `row`, a step `d` starting `time_s` after the first stamp.
fn gap(row: usize, time_s: f64, d: f64, nominal: f64) -> Gap {
    let missing = ((d / nominal).round() as usize).saturating_sub(1).max(1);
    Gap {
        row,
        line: None,
        time_s,
        duration_s: d - nominal,
        missing,
    }
}

/// Checks time stamps in seconds (any order; duplicates and reordering are counted, not
/// refused): rate, gaps, duplicates, reordering and jitter, as documented on
/// [`TimingReport`] and the module. Gaps carry no line numbers (`Gap::line` is `None`).
///
/// Cost: O(n log n) (two sorts), one buffer of n values.
pub(crate) fn check_times(
    column: &str,
    times_s: &[f64],
    unit: TimeUnit,
    unit_source: UnitSource,
) -> TimingReport {
    // the steps are recomputed on each pass: one buffer of n values at most (the sorted
    // positive steps, then their deviations)
    let steps = || times_s.windows(2).map(|w| w[1] - w[0]);
    let duplicates = steps().filter(|&d| d == 0.0).count();
    let reordered = steps().filter(|&d| d < 0.0).count();
    let mut buffer: Vec<f64> = steps().filter(|&d| d > 0.0).collect();
    let (lo, hi) = times_s
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &t| {
            (lo.min(t), hi.max(t))
        });
    let span_s = if times_s.is_empty() { 0.0 } else { hi - lo };
    let mean_rate_hz = mean_rate(times_s.len(), span_s);
    let first = times_s.first().copied().unwrap_or(0.0);
    let mut gaps = Vec::new();
    let (rate_hz, jitter) = match median(&mut buffer) {
        None => (f64::NAN, f64::NAN),
        Some(med) => {
            // `buffer` is sorted now
            let nominal = nominal_step(med, || buffer.iter().copied());
            for (i, d) in steps().enumerate() {
                if d > GAP_FACTOR * nominal {
                    gaps.push(gap(i + 1, times_s[i] - first, d, nominal));
                }
            }
            buffer.retain(|&d| d <= GAP_FACTOR * nominal);
            buffer.iter_mut().for_each(|d| *d = (*d - nominal).abs());
            let mad = median(&mut buffer).unwrap_or(0.0);
            (round_significant(1.0 / nominal), MAD_TO_SD * mad / nominal)
        }
    };
    TimingReport {
        column: column.to_string(),
        unit,
        unit_source,
        samples: times_s.len(),
        start_s: first,
        span_s,
        rate_hz,
        mean_rate_hz,
        gaps,
        duplicates,
        reordered,
        jitter,
    }
}

/// Distinct positive steps a streamed check (`StepStats`) holds: 2^16. Stamps from a clock
/// are quantised, so their steps take few values (a 200 Hz log stamped in ns: a handful; the
/// relative stamps of a text file in seconds: a few a binade); beyond this many the check
/// cannot be exact in bounded memory, and the readers check the column in memory instead.
pub(crate) const STREAM_DISTINCT_STEPS: usize = 1 << 16;

/// Largest steps a streamed check holds with their place, to find the gaps among them once the
/// nominal step is known: 2^16 (more gaps than this: checked in memory, as
/// [`STREAM_DISTINCT_STEPS`]).
pub(crate) const STREAM_LARGEST_STEPS: usize = 1 << 16;

/// A step with its place, for the gaps of [`StepStats`].
#[derive(Debug, Clone, Copy)]
struct Step {
    d: f64,
    row: usize,
    time_s: f64,
    line: Option<u64>,
}

impl PartialEq for Step {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == std::cmp::Ordering::Equal
    }
}
impl Eq for Step {}
impl PartialOrd for Step {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Step {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.d.total_cmp(&other.d).then(self.row.cmp(&other.row))
    }
}

/// [`check_times`] streamed: the stamps are pushed one by one and never held; the report is
/// the same, bit for bit (tests: `streamed_check_equals_check_times`), from
/// - the counts, extremes and first stamp, in one pass;
/// - each distinct positive step once with its count (at most [`STREAM_DISTINCT_STEPS`]):
///   the median, both means (summed in ascending order, as [`check_times`] sums them) and the
///   jitter's median deviation are those of the multiset of steps, exact from it;
/// - the [`STREAM_LARGEST_STEPS`] largest steps with their rows and lines: the gaps are the
///   steps above 1.5 nominal steps, all among them unless every step held is a gap.
///
/// [`finish`](Self::finish) gives `None` when a bound was passed (the caller then checks the
/// column in memory). Memory: at most about 6 MB whatever the number of stamps.
#[derive(Debug, Clone, Default)]
pub(crate) struct StepStats {
    samples: usize,
    first: f64,
    previous: f64,
    lo: f64,
    hi: f64,
    duplicates: usize,
    reordered: usize,
    /// Positive steps by their bits (ordered as the values) and their counts.
    steps: std::collections::BTreeMap<u64, u64>,
    /// The last positive step and how many times it repeated since it was put in `steps`.
    run: Option<(u64, u64)>,
    largest: std::collections::BinaryHeap<std::cmp::Reverse<Step>>,
    overflow: bool,
}

impl StepStats {
    /// Pushes the next stamp (seconds), on physical line `line` of a text file if known.
    #[inline]
    pub(crate) fn push(&mut self, t: f64, line: Option<u64>) {
        if self.samples == 0 {
            self.first = t;
            self.lo = f64::INFINITY;
            self.hi = f64::NEG_INFINITY;
        } else {
            let d = t - self.previous;
            if d == 0.0 {
                self.duplicates += 1;
            } else if d < 0.0 {
                self.reordered += 1;
            } else if d > 0.0 {
                self.positive(d, line);
            }
        }
        self.lo = self.lo.min(t);
        self.hi = self.hi.max(t);
        self.previous = t;
        self.samples += 1;
    }

    #[inline]
    fn positive(&mut self, d: f64, line: Option<u64>) {
        let bits = d.to_bits();
        match &mut self.run {
            Some((b, c)) if *b == bits => *c += 1,
            run => {
                if let Some((b, c)) = run.replace((bits, 1)) {
                    if !self.overflow {
                        *self.steps.entry(b).or_insert(0) += c;
                        if self.steps.len() > STREAM_DISTINCT_STEPS {
                            // the report cannot be exact: the memory is let go
                            self.overflow = true;
                            self.steps = Default::default();
                        }
                    }
                }
            }
        }
        let full = self.largest.len() >= STREAM_LARGEST_STEPS;
        if full && self.largest.peek().is_some_and(|m| d <= m.0.d) {
            return;
        }
        self.largest.push(std::cmp::Reverse(Step {
            d,
            row: self.samples,
            time_s: self.previous - self.first,
            line,
        }));
        if full {
            self.largest.pop();
        }
    }

    /// The report [`check_times`] gives of the stamps pushed (with the gaps' lines), `None`
    /// when a bound was passed.
    pub(crate) fn finish(
        mut self,
        column: &str,
        unit: TimeUnit,
        unit_source: UnitSource,
    ) -> Option<TimingReport> {
        if let Some((b, c)) = self.run.take() {
            if !self.overflow {
                *self.steps.entry(b).or_insert(0) += c;
            }
        }
        if self.overflow || self.steps.len() > STREAM_DISTINCT_STEPS {
            return None;
        }
        let span_s = if self.samples == 0 {
            0.0
        } else {
            self.hi - self.lo
        };
        let first = if self.samples == 0 { 0.0 } else { self.first };
        let counted: Vec<(f64, u64)> = self
            .steps
            .iter()
            .map(|(&b, &c)| (f64::from_bits(b), c))
            .collect();
        let sorted = || {
            counted
                .iter()
                .flat_map(|&(d, c)| std::iter::repeat(d).take(c as usize))
        };
        let mut gaps = Vec::new();
        let (rate_hz, jitter) = match weighted_median(&mut counted.clone()) {
            None => (f64::NAN, f64::NAN),
            Some(med) => {
                let nominal = nominal_step(med, sorted);
                let limit = GAP_FACTOR * nominal;
                let held = self.largest.into_vec();
                if held.len() >= STREAM_LARGEST_STEPS && held.iter().all(|s| s.0.d > limit) {
                    // every step held is a gap: others may have been let go
                    return None;
                }
                let mut large: Vec<Step> = held
                    .into_iter()
                    .map(|s| s.0)
                    .filter(|s| s.d > limit)
                    .collect();
                large.sort_unstable_by_key(|s| s.row);
                gaps = large
                    .into_iter()
                    .map(|s| Gap {
                        line: s.line,
                        ..gap(s.row, s.time_s, s.d, nominal)
                    })
                    .collect();
                let mut deviations: Vec<(f64, u64)> = counted
                    .iter()
                    .filter(|&&(d, _)| d <= limit)
                    .map(|&(d, c)| ((d - nominal).abs(), c))
                    .collect();
                let mad = weighted_median(&mut deviations).unwrap_or(0.0);
                (round_significant(1.0 / nominal), MAD_TO_SD * mad / nominal)
            }
        };
        Some(TimingReport {
            column: column.to_string(),
            unit,
            unit_source,
            samples: self.samples,
            start_s: first,
            span_s,
            rate_hz,
            mean_rate_hz: mean_rate(self.samples, span_s),
            gaps,
            duplicates: self.duplicates,
            reordered: self.reordered,
            jitter,
        })
    }
}

impl TimingReport {
    /// Samples missing over all gaps at the nominal rate (saturating: a gap of absurd length,
    /// a corrupt stamp, counts `usize::MAX`).
    pub(crate) fn missing_samples(&self) -> usize {
        self.gaps
            .iter()
            .fold(0usize, |sum, g| sum.saturating_add(g.missing))
    }

    /// The soft problems of the stamps, one per kind: gaps (count, largest, where), duplicates,
    /// reordering, jitter above `JITTER_WARN`.
    pub fn warnings(&self) -> Vec<TimingWarning> {
        let mut out = Vec::new();
        if let Some(largest) = self
            .gaps
            .iter()
            .max_by(|a, b| a.duration_s.total_cmp(&b.duration_s))
        {
            out.push(TimingWarning::Gaps {
                column: self.column.clone(),
                count: self.gaps.len(),
                missing: self.missing_samples(),
                largest: largest.clone(),
                rate_hz: self.rate_hz,
            });
        }
        if self.duplicates > 0 {
            out.push(TimingWarning::Duplicates {
                column: self.column.clone(),
                count: self.duplicates,
            });
        }
        if self.reordered > 0 {
            out.push(TimingWarning::Reordered {
                column: self.column.clone(),
                count: self.reordered,
            });
        }
        if self.jitter > JITTER_WARN {
            out.push(TimingWarning::Jitter {
                column: self.column.clone(),
                jitter: self.jitter,
            });
        }
        out
    }

    /// Where a gap is: `line L` for text files, else `sample R (0-based)`.
    fn place(gap: &Gap) -> String {
        match gap.line {
            Some(l) => format!("line {l}"),
            None => format!("sample {} (0-based)", gap.row),
        }
    }
}

impl fmt::Display for TimingReport {
    /// One line: `time column "t" (ns, from the header): 200 Hz from the time steps, gaps left
    /// out`; gaps,
    /// duplicates, reordering and jitter are [`TimingReport::warnings`], not repeated here.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "time column \"{}\" ({}, {}): {} Hz from the time steps, gaps left \
             out",
            crate::imu::error::quote(&self.column),
            self.unit,
            self.unit_source,
            fmt_hz(self.rate_hz)
        )
    }
}

/// A rate for messages: up to 6 significant digits, no trailing zeros (`200`, `62.5`).
pub(crate) fn fmt_hz(hz: f64) -> String {
    if !hz.is_finite() {
        return "undefined".into();
    }
    let s = format!("{:.*}", decimals(hz, 6), hz);
    trim_zeros(&s)
}

/// A duration for messages: 3 significant digits, at least 2 decimals (`0.50`, `12.3`).
fn fmt_s(s: f64) -> String {
    format!("{:.*}", decimals(s, 2).max(2), s)
}

fn decimals(x: f64, significant: i32) -> usize {
    if x == 0.0 || !x.is_finite() {
        return 0;
    }
    (significant - 1 - x.abs().log10().floor() as i32).max(0) as usize
}

fn trim_zeros(s: &str) -> String {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s.to_string()
    }
}

/// A soft problem of a time column ([`TimingReport::warnings`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
#[non_exhaustive]
pub enum TimingWarning {
    /// Steps longer than `GAP_FACTOR` nominal steps.
    Gaps {
        /// Time column.
        column: String,
        /// Number of gaps.
        count: usize,
        /// Samples missing over all gaps, at the nominal rate.
        missing: usize,
        /// The longest gap.
        largest: Gap,
        /// The rate from the regular steps, which the gaps do not lower.
        rate_hz: f64,
    },
    /// Repeated stamps.
    Duplicates {
        /// Time column.
        column: String,
        /// Number of zero steps.
        count: usize,
    },
    /// Stamps earlier than their predecessor.
    Reordered {
        /// Time column.
        column: String,
        /// Number of negative steps.
        count: usize,
    },
    /// Irregular steps.
    Jitter {
        /// Time column.
        column: String,
        /// Robust relative spread of the steps (`TimingReport::jitter`).
        jitter: f64,
    },
}

impl fmt::Display for TimingWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use crate::imu::error::quote;
        match self {
            Self::Gaps {
                column,
                count,
                missing,
                largest,
                rate_hz,
            } => write!(
                f,
                "time column \"{}\": {count} gap{} ({missing} sample{} missing), largest {} s at \
                 {} ({} s after the start); {} Hz between them",
                quote(column),
                if *count == 1 { "" } else { "s" },
                if *missing == 1 { "" } else { "s" },
                fmt_s(largest.duration_s),
                TimingReport::place(largest),
                fmt_s(largest.time_s),
                fmt_hz(*rate_hz)
            ),
            Self::Duplicates { column, count } => write!(
                f,
                "time column \"{}\": {count} repeated time stamp{}",
                quote(column),
                if *count == 1 { "" } else { "s" }
            ),
            Self::Reordered { column, count } => write!(
                f,
                "time column \"{}\": {count} time stamp{} earlier than the previous one",
                quote(column),
                if *count == 1 { "" } else { "s" }
            ),
            Self::Jitter { column, jitter } => write!(
                f,
                "time column \"{}\": irregular steps (robust spread {:.0}% of the step)",
                quote(column),
                100.0 * jitter
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The streamed check gives the report of `check_times`, bit for bit, on stamps with
    /// gaps, jitter, duplicates and reordering (and the lines it was given).
    fn streamed(t: &[f64]) -> Option<TimingReport> {
        let mut s = StepStats::default();
        for &x in t {
            s.push(x, None);
        }
        s.finish("t", TimeUnit::Seconds, UnitSource::Stated)
    }

    fn same(a: &TimingReport, b: &TimingReport) -> bool {
        let bits = |x: f64| x.to_bits();
        a.samples == b.samples
            && bits(a.start_s) == bits(b.start_s)
            && bits(a.span_s) == bits(b.span_s)
            && bits(a.rate_hz) == bits(b.rate_hz)
            && bits(a.mean_rate_hz) == bits(b.mean_rate_hz)
            && bits(a.jitter) == bits(b.jitter)
            && a.duplicates == b.duplicates
            && a.reordered == b.reordered
            && a.gaps.len() == b.gaps.len()
            && a.gaps.iter().zip(&b.gaps).all(|(x, y)| {
                x.row == y.row
                    && x.missing == y.missing
                    && bits(x.time_s) == bits(y.time_s)
                    && bits(x.duration_s) == bits(y.duration_s)
            })
            && a.warnings() == b.warnings()
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(400))]
        #[test]
        fn streamed_check_equals_check_times(
            n in 0usize..3000,
            period in 1e-4f64..1.0,
            quantum_exp in 0u32..4,
            jitter in 0.0f64..0.4,
            events in proptest::collection::vec((0usize..3000, 0u8..4, 1u32..200), 0..40),
            seed in 0u64..u64::MAX,
        ) {
            // stamps in units of a clock quantum (whole numbers, as a clock gives them, or
            // seconds with the roundings of a decimal file), with jitter, gaps, repeats and
            // stamps out of order
            let mut state = seed | 1;
            let mut next = || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64
            };
            let quantum = [1e-9, 1e-6, 1e-3, 0.0][quantum_exp as usize];
            let mut t = Vec::with_capacity(n);
            let mut now = 0.0f64;
            for i in 0..n {
                now += period * (1.0 + jitter * (next() - 0.5));
                for &(at, kind, size) in &events {
                    if at == i {
                        match kind {
                            0 => now += period * f64::from(size),
                            1 if !t.is_empty() => now = *t.last().unwrap(),
                            2 => now -= period * f64::from(size % 5),
                            _ => {}
                        }
                    }
                }
                let v = if quantum > 0.0 { (now / quantum).round() * quantum } else { now };
                t.push(v);
            }
            let a = check_times("t", &t, TimeUnit::Seconds, UnitSource::Stated);
            let b = streamed(&t).expect("within the bounds");
            proptest::prop_assert!(same(&a, &b), "{a:?}\n{b:?}");
        }
    }

    #[test]
    fn streamed_check_of_nothing_and_one_stamp() {
        for t in [&[][..], &[5.0][..], &[1.0, 1.0][..], &[2.0, 1.0][..]] {
            let a = check_times("t", t, TimeUnit::Seconds, UnitSource::Stated);
            let b = streamed(t).unwrap();
            assert!(same(&a, &b), "{a:?} {b:?}");
        }
    }

    #[test]
    fn streamed_check_gives_up_beyond_its_bounds() {
        // every step distinct: more distinct steps than held
        let t: Vec<f64> = (0..STREAM_DISTINCT_STEPS as u64 + 10)
            .map(|i| (i * i) as f64)
            .collect();
        assert!(streamed(&t).is_none());
        // more gaps than held steps
        let mut t = Vec::new();
        let mut now = 0.0;
        for i in 0..(4 * STREAM_LARGEST_STEPS) {
            now += if i % 3 == 2 { 5.0 } else { 1.0 };
            t.push(now);
        }
        assert!(streamed(&t).is_none());
        // many large steps, but fewer gaps than held: exact
        let mut t = Vec::new();
        let mut now = 0.0;
        for i in 0..(3 * STREAM_LARGEST_STEPS) {
            now += if i % 1000 == 7 {
                5.0
            } else if i % 2 == 0 {
                1.25
            } else {
                1.0
            };
            t.push(now);
        }
        let a = check_times("t", &t, TimeUnit::Seconds, UnitSource::Stated);
        assert!(same(&a, &streamed(&t).unwrap()));
        assert!(!a.gaps.is_empty());
    }

    #[test]
    fn time_unit_from_str_display_and_factor() {
        assert_eq!("ns".parse::<TimeUnit>().unwrap(), TimeUnit::Nanoseconds);
        assert_eq!("µs".parse::<TimeUnit>().unwrap(), TimeUnit::Microseconds);
        assert_eq!("Seconds".parse::<TimeUnit>().unwrap(), TimeUnit::Seconds);
        assert_eq!(
            "min".parse::<TimeUnit>().unwrap_err().to_string(),
            "invalid time unit = min: one of s, ms, us, ns"
        );
        assert_eq!(TimeUnit::Milliseconds.to_string(), "ms");
        assert_eq!(TimeUnit::Microseconds.to_seconds(), 1e-6);
    }

    #[test]
    fn time_column_names() {
        let u = time_column_unit;
        assert_eq!(u("time"), Some(None));
        assert_eq!(u("Timestamp"), Some(None));
        assert_eq!(u("t"), Some(None));
        assert_eq!(u("stamp"), Some(None));
        assert_eq!(u("%time"), Some(Some(TimeUnit::Nanoseconds)));
        assert_eq!(u("field.header.stamp"), Some(Some(TimeUnit::Nanoseconds)));
        assert_eq!(u("header.stamp"), Some(None));
        assert_eq!(u("#timestamp [ns]"), Some(Some(TimeUnit::Nanoseconds)));
        assert_eq!(u("timestamp_ns"), Some(Some(TimeUnit::Nanoseconds)));
        assert_eq!(u("time_s"), Some(Some(TimeUnit::Seconds)));
        assert_eq!(u("time [s]"), Some(Some(TimeUnit::Seconds)));
        assert_eq!(u("Time (ms)"), Some(Some(TimeUnit::Milliseconds)));
        assert_eq!(u("t_us"), Some(Some(TimeUnit::Microseconds)));
        assert_eq!(u("gyro_x"), None);
        assert_eq!(u("temperature"), None);
        assert_eq!(u("x"), None);
        assert_eq!(u("time_of_day_x"), None);
    }

    #[test]
    fn infer_unit_from_epoch_and_step() {
        assert_eq!(
            infer_time_unit(&[1.7e9, 1.7e9 + 0.005]),
            Some(TimeUnit::Seconds)
        );
        assert_eq!(infer_time_unit(&[1.7e12]), Some(TimeUnit::Milliseconds));
        assert_eq!(infer_time_unit(&[1.7e15]), Some(TimeUnit::Microseconds));
        assert_eq!(
            infer_time_unit(&[1.7e18, 1.7e18 + 5e6]),
            Some(TimeUnit::Nanoseconds)
        );
        // relative stamps: the step decides
        assert_eq!(
            infer_time_unit(&[0.0, 0.005, 0.01]),
            Some(TimeUnit::Seconds)
        );
        assert_eq!(
            infer_time_unit(&[0.0, 5.0, 10.0]),
            Some(TimeUnit::Milliseconds)
        );
        assert_eq!(
            infer_time_unit(&[0.0, 5000.0, 10000.0]),
            Some(TimeUnit::Microseconds)
        );
        assert_eq!(
            infer_time_unit(&[0.0, 5e6, 1e7]),
            Some(TimeUnit::Nanoseconds)
        );
        assert_eq!(infer_time_unit(&[0.0, 1e-6]), Some(TimeUnit::Seconds));
        // fractional stamps at 1 Hz or more are seconds; whole ones follow the step
        assert_eq!(infer_time_unit(&[0.0, 0.5, 1.0]), Some(TimeUnit::Seconds));
        assert_eq!(
            infer_time_unit(&[0.0, 1.0, 2.0]),
            Some(TimeUnit::Milliseconds)
        );
        assert_eq!(
            infer_time_unit(&[0.5, 5.5, 10.5]),
            Some(TimeUnit::Milliseconds)
        );
        assert_eq!(infer_time_unit(&[0.0, 1e9]), Some(TimeUnit::Nanoseconds));
        assert_eq!(infer_time_unit(&[3.0]), None);
        assert_eq!(infer_time_unit(&[]), None);
    }

    #[test]
    fn check_times_regular_gap_duplicate_reordered() {
        let t: Vec<f64> = (0..1000).map(|i| i as f64 * 0.005).collect();
        let r = check_times("t", &t, TimeUnit::Seconds, UnitSource::Inferred);
        assert!((r.rate_hz - 200.0).abs() < 1e-9, "{}", r.rate_hz);
        assert!(r.gaps.is_empty() && r.duplicates == 0 && r.reordered == 0);
        assert!(r.jitter < 1e-9);
        assert!(r.warnings().is_empty());
        // a 0.5 s gap after sample 400
        let t: Vec<f64> = (0..1000)
            .map(|i| i as f64 * 0.005 + if i >= 400 { 0.5 } else { 0.0 })
            .collect();
        let r = check_times("t", &t, TimeUnit::Seconds, UnitSource::Inferred);
        assert!((r.rate_hz - 200.0).abs() < 1e-9);
        assert!((r.mean_rate_hz - 999.0 / 5.495).abs() < 1e-9);
        assert_eq!(r.gaps.len(), 1);
        assert_eq!(r.gaps[0].row, 400);
        assert_eq!(r.gaps[0].missing, 100);
        assert!((r.gaps[0].duration_s - 0.5).abs() < 1e-12);
        let w = r.warnings();
        assert_eq!(w.len(), 1);
        assert_eq!(
            w[0].to_string(),
            "time column \"t\": 1 gap (100 samples missing), largest 0.50 s at sample 400 \
             (0-based) (2.00 s after the start); 200 Hz between them"
        );
        // duplicates and reordering are counted, not refused
        let r = check_times(
            "stamp",
            &[0.0, 0.01, 0.01, 0.03, 0.02, 0.04],
            TimeUnit::Seconds,
            UnitSource::Flag,
        );
        assert_eq!((r.duplicates, r.reordered), (1, 1));
        let kinds: Vec<String> = r.warnings().iter().map(|w| w.to_string()).collect();
        assert!(kinds.iter().any(|w| w.contains("1 repeated time stamp")));
        assert!(kinds
            .iter()
            .any(|w| w.contains("earlier than the previous one")));
    }

    /// 300 Hz stamped in whole milliseconds: steps 3, 3, 4 ms; the median alone says 333 Hz.
    #[test]
    fn check_times_quantised_stamps() {
        let t: Vec<f64> = (0..3000)
            .map(|i| (i as f64 * 1000.0 / 300.0).floor() * 1e-3)
            .collect();
        let r = check_times("t", &t, TimeUnit::Milliseconds, UnitSource::Stated);
        assert!((r.rate_hz - 300.0).abs() < 0.1, "{}", r.rate_hz);
        assert!(r.gaps.is_empty());
    }

    #[test]
    fn check_times_degenerate_inputs() {
        let r = check_times("t", &[], TimeUnit::Seconds, UnitSource::Flag);
        assert!(r.rate_hz.is_nan() && r.samples == 0 && r.span_s == 0.0);
        let r = check_times("t", &[1.0, 1.0], TimeUnit::Seconds, UnitSource::Flag);
        assert!(r.rate_hz.is_nan());
        assert_eq!(r.duplicates, 1);
    }

    #[test]
    fn report_display() {
        let t: Vec<f64> = (0..10).map(|i| i as f64 * 0.016).collect();
        let r = check_times(
            "#timestamp [ns]",
            &t,
            TimeUnit::Nanoseconds,
            UnitSource::Stated,
        );
        assert_eq!(
            r.to_string(),
            "time column \"#timestamp [ns]\" (ns, from the header): 62.5 Hz from the time steps, \
             gaps left out"
        );
    }
}
