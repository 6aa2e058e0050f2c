//! Allan, modified Allan and Hadamard variances (docs/methods.md §3).
//!
//! One entry point, [`allan_variance`], computes any of five estimators at a standard set of
//! cluster lengths `m` (in samples), with a chi-square confidence interval on the variance scale.
//!
//! # Conventions
//! - [`AvConvention::Textbook`] (default): the textbook estimators, every available term summed,
//!   cluster lengths starting at `m = 1` (octaves `1, 2, 4, ...` for the Allan kinds, powers of
//!   three `1, 3, 9, ...` for the Hadamard kinds). The overlapping Allan variance then satisfies
//!   `AV(m) = 2 WV(tau = 2m)` exactly (docs/methods.md §3.4).
//! - [`AvConvention::Package`]: the R package's estimators, defects included (docs/methods.md
//!   §13.8–§13.10), at the package's cluster lengths, so that results compare with
//!   `gmwm::avar`/`gmwm::hadam`.
//!
//! How far apart the two conventions are on real data (adis_16405_imu1 gyro_x and accel_x, first
//! 1e5 samples; bounds checked in `tests/allan.rs`):
//! - overlapping AV ("mo"): the package drops one of the `N - 2m + 1` terms but keeps the divisor,
//!   so it is low by a relative 1e-7 to 1.6e-4 (ratio to `2 WV` 0.99984 to 1); overlapping HV: low
//!   by 0 to 1e-4;
//! - non-overlapping AV ("to"): disjoint pairs use about half the differences, so the two differ
//!   by sampling noise: 0.2% to 5% for `m <= 256`, up to 70% at the largest `m` (always inside the
//!   textbook 95% interval);
//! - non-overlapping HV ("to"): disjoint triples and the `6(M-2)` divisor (a factor `M/(M-2)`,
//!   1.00002 at `m = 3` up to 5/3 at `m = 6561`): 0.02% to 3% for `m <= 243`, up to a factor 2.9
//!   at the largest `m`.
//!
//! # Cost
//! O(N) per cluster length through prefix sums (and prefix sums of prefix sums for the modified
//! AV), O(N log N) for all octaves; cluster lengths are computed in parallel with rayon.

use crate::error::{check_series, InputError, ParamError, SeriesError};
use crate::math::elementary;
use crate::math::sum::NeumaierSum;
use crate::variance::ci::{check_alpha, interval_unchecked};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Which variance of docs/methods.md §3 to compute.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AllanKind {
    /// Maximal-overlap Allan variance, docs/methods.md §3.2 (package type "mo"). Default: the most
    /// efficient Allan estimator, and the one equal to twice the Haar WV (§3.4).
    #[default]
    Overlapping,
    /// Non-overlapping Allan variance, docs/methods.md §3.1 (package type "to").
    NonOverlapping,
    /// Modified Allan variance, docs/methods.md §3.6 (Riley; not in the package).
    Modified,
    /// Maximal-overlap Hadamard variance, docs/methods.md §3.5 (package `hadam` type "mo").
    Hadamard,
    /// Non-overlapping Hadamard variance, docs/methods.md §3.5 (package `hadam` type "to").
    HadamardNonOverlapping,
}

impl AllanKind {
    /// Every kind, in declaration order (docs/methods.md §3).
    pub const ALL: [AllanKind; 5] = [
        AllanKind::Overlapping,
        AllanKind::NonOverlapping,
        AllanKind::Modified,
        AllanKind::Hadamard,
        AllanKind::HadamardNonOverlapping,
    ];

    /// The CLI / serde name of the kind (docs/methods.md §3), e.g. `"non-overlapping"`.
    pub fn name(self) -> &'static str {
        match self {
            AllanKind::Overlapping => "overlapping",
            AllanKind::NonOverlapping => "non-overlapping",
            AllanKind::Modified => "modified",
            AllanKind::Hadamard => "hadamard",
            AllanKind::HadamardNonOverlapping => "hadamard-non-overlapping",
        }
    }

    /// What the kind computes, for titles: `"overlapping Allan variance"`, `"modified Allan
    /// variance"`, `"overlapping Hadamard variance"`, ...
    pub fn title(self) -> &'static str {
        match self {
            AllanKind::Overlapping => "overlapping Allan variance",
            AllanKind::NonOverlapping => "non-overlapping Allan variance",
            AllanKind::Modified => "modified Allan variance",
            AllanKind::Hadamard => "overlapping Hadamard variance",
            AllanKind::HadamardNonOverlapping => "non-overlapping Hadamard variance",
        }
    }

    /// The names of the variance and of its square root in tables and CSV headers: `avar`
    /// `adev` (Allan), `mavar` `mdev` (modified Allan), `hvar` `hdev` (Hadamard).
    pub fn columns(self) -> (&'static str, &'static str) {
        match self {
            AllanKind::Overlapping | AllanKind::NonOverlapping => ("avar", "adev"),
            AllanKind::Modified => ("mavar", "mdev"),
            AllanKind::Hadamard | AllanKind::HadamardNonOverlapping => ("hvar", "hdev"),
        }
    }

    /// Whether the kind is a Hadamard variance (cluster lengths `3^i`, docs/methods.md §3.5).
    #[cfg(test)]
    pub(crate) fn is_hadamard(self) -> bool {
        matches!(
            self,
            AllanKind::Hadamard | AllanKind::HadamardNonOverlapping
        )
    }
}

impl crate::names::Named for AllanKind {
    const WHAT: &'static str = "kind";
    const VALUES: &'static [Self] = &AllanKind::ALL;

    fn name(self) -> &'static str {
        AllanKind::name(self)
    }
}

impl fmt::Display for AllanKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for AllanKind {
    type Err = ParamError;

    /// Parses a CLI name (docs/methods.md §3), case-insensitively.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        AllanKind::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| {
                let names: Vec<&str> = AllanKind::ALL.iter().map(|k| k.name()).collect();
                ParamError::new("kind", s, format!("one of {}", names.join(", ")))
            })
    }
}

/// Textbook estimators (default) or the package's, defects included (docs/methods.md §13.8–§13.10).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AvConvention {
    /// Textbook estimators over all available terms, cluster lengths from `m = 1` (docs/methods.md
    /// §3.1, §3.2, §3.5, §3.6). Default: correct, and consistent with the Haar WV (§3.4).
    #[default]
    Textbook,
    /// The R package gmwm's `avar`/`hadam` (docs/methods.md §3.1, §3.2, §3.5, §13.8–§13.10):
    /// disjoint pairs/triples for "to", one term short for "mo", divisor `6(M-2)` for the Hadamard
    /// "to", and its cluster sets (`2^i`, `i = 1..floor(log2 N) - 1`; `3^i`, `i = 1..floor(log3
    /// N) - 1` ("mo") or `- 2` ("to")). The package has no modified AV; [`AllanKind::Modified`] is
    /// computed as in the textbook convention.
    Package,
}

impl AvConvention {
    /// The CLI / serde name (docs/methods.md §13.8): `"textbook"` or `"package"`.
    pub fn name(self) -> &'static str {
        match self {
            AvConvention::Textbook => "textbook",
            AvConvention::Package => "package",
        }
    }
}

impl crate::names::Named for AvConvention {
    const WHAT: &'static str = "convention";
    const VALUES: &'static [Self] = &[AvConvention::Textbook, AvConvention::Package];

    fn name(self) -> &'static str {
        AvConvention::name(self)
    }
}

impl fmt::Display for AvConvention {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for AvConvention {
    type Err = ParamError;

    /// Parses `"textbook"` or `"package"` (docs/methods.md §13.8), case-insensitively.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        [AvConvention::Textbook, AvConvention::Package]
            .into_iter()
            .find(|c| c.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| ParamError::new("convention", s, "one of textbook, package"))
    }
}

/// Options of [`allan_variance`] (docs/methods.md §3).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AllanOptions {
    /// Which variance (default [`AllanKind::Overlapping`], docs/methods.md §3.2).
    pub kind: AllanKind,
    /// Confidence level of the chi-square interval, in (0, 1) (default 0.05 for 95% intervals,
    /// as the WV's, docs/methods.md §1.7).
    pub alpha: f64,
    /// Estimator convention (default [`AvConvention::Textbook`], docs/methods.md §13.8–§13.10).
    pub convention: AvConvention,
}

impl Default for AllanOptions {
    fn default() -> Self {
        Self {
            kind: AllanKind::Overlapping,
            alpha: 0.05,
            convention: AvConvention::Textbook,
        }
    }
}

/// Allan-type variances of one series across cluster lengths (docs/methods.md §3).
///
/// All vectors have one entry per cluster length, in increasing order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AllanVariance {
    /// Which variance (docs/methods.md §3).
    pub(crate) kind: AllanKind,
    /// Estimator convention used (docs/methods.md §13.8–§13.10).
    pub(crate) convention: AvConvention,
    /// Number of samples of the series.
    pub(crate) n: usize,
    /// Sampling rate in Hz.
    pub(crate) freq_hz: f64,
    /// Confidence level of the intervals.
    pub(crate) alpha: f64,
    /// Cluster lengths `m` in samples (docs/methods.md §3.1: `tau` samples).
    pub(crate) tau: Vec<f64>,
    /// Cluster lengths in seconds, `m / freq_hz`.
    pub(crate) tau_s: Vec<f64>,
    /// The variance estimate (Allan, modified Allan or Hadamard variance; docs/methods.md
    /// §3.1–§3.6).
    pub(crate) avar: Vec<f64>,
    /// Its square root (Allan / Hadamard deviation, docs/methods.md §3.3).
    pub(crate) adev: Vec<f64>,
    /// Lower chi-square confidence bound, variance scale (docs/methods.md §1.7 through §3.3/§3.4).
    pub(crate) ci_low: Vec<f64>,
    /// Upper chi-square confidence bound, variance scale (docs/methods.md §1.7 through §3.3/§3.4).
    pub(crate) ci_high: Vec<f64>,
    /// The interval on the deviation scale, `sqrt(ci_low)`: what a figure or table that shows
    /// the deviation pairs with it.
    #[serde(default)]
    pub(crate) adev_ci_low: Vec<f64>,
    /// `sqrt(ci_high)`, the interval's upper end on the deviation scale.
    #[serde(default)]
    pub(crate) adev_ci_high: Vec<f64>,
    /// Equivalent degrees of freedom of the chi-square interval (see [`allan_variance`]).
    pub(crate) edf: Vec<f64>,
    /// Number of terms (squared differences) summed by the estimator.
    pub(crate) terms: Vec<usize>,
    /// The package's "error" column `e = 1 / sqrt(2 (N/m - 1))` (docs/methods.md §3.3), in both
    /// conventions; its deviation band is [`AllanVariance::package_band`]. The package itself
    /// calls this band "known to be incorrect"; prefer `ci_low`/`ci_high`.
    pub(crate) error: Vec<f64>,
}

/// Read access to the results; the fields are the engine's own.
impl AllanVariance {
    /// Which variance (docs/methods.md §3).
    pub fn kind(&self) -> AllanKind {
        self.kind
    }

    /// Estimator convention used (docs/methods.md §13.8–§13.10).
    pub fn convention(&self) -> AvConvention {
        self.convention
    }

    /// Number of samples of the series.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Sampling rate in Hz.
    pub fn freq_hz(&self) -> f64 {
        self.freq_hz
    }

    /// Confidence level of the intervals.
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// Cluster lengths `m` in samples (docs/methods.md §3.1: `tau` samples).
    pub fn tau(&self) -> &[f64] {
        &self.tau
    }

    /// Cluster lengths in seconds, `m / freq_hz`.
    pub fn tau_s(&self) -> &[f64] {
        &self.tau_s
    }

    /// The variance estimate (Allan, modified Allan or Hadamard variance; docs/methods.md
    /// §3.1–§3.6).
    pub fn avar(&self) -> &[f64] {
        &self.avar
    }

    /// Its square root (Allan / Hadamard deviation, docs/methods.md §3.3).
    pub fn adev(&self) -> &[f64] {
        &self.adev
    }

    /// Lower chi-square confidence bound, variance scale (docs/methods.md §1.7 through §3.3/§3.4).
    pub fn ci_low(&self) -> &[f64] {
        &self.ci_low
    }

    /// Upper chi-square confidence bound, variance scale (docs/methods.md §1.7 through §3.3/§3.4).
    pub fn ci_high(&self) -> &[f64] {
        &self.ci_high
    }

    /// The interval's lower end on the deviation scale, `sqrt(ci_low)`.
    pub fn adev_ci_low(&self) -> &[f64] {
        &self.adev_ci_low
    }

    /// The interval's upper end on the deviation scale, `sqrt(ci_high)`.
    pub fn adev_ci_high(&self) -> &[f64] {
        &self.adev_ci_high
    }

    /// Equivalent degrees of freedom of the chi-square interval (see [`allan_variance`]).
    #[cfg(test)]
    pub(crate) fn edf(&self) -> &[f64] {
        &self.edf
    }

    /// Number of terms (squared differences) summed by the estimator.
    pub fn terms(&self) -> &[usize] {
        &self.terms
    }

    /// The package's "error" column `e = 1 / sqrt(2 (N/m - 1))` (docs/methods.md §3.3), in both
    /// conventions; its deviation band is `AllanVariance::package_band`. The package itself
    /// calls this band "known to be incorrect"; prefer `ci_low`/`ci_high`.
    pub fn error(&self) -> &[f64] {
        &self.error
    }
}

impl AllanVariance {
    /// The package's deviation-scale band `(adev (1 - e), adev (1 + e))` per cluster length
    /// (docs/methods.md §3.3; the `lci`/`uci` columns of `gmwm::avar`).
    #[cfg(test)]
    pub(crate) fn package_band(&self) -> (Vec<f64>, Vec<f64>) {
        let lo = self
            .adev
            .iter()
            .zip(&self.error)
            .map(|(d, e)| d * (1.0 - e))
            .collect();
        let hi = self
            .adev
            .iter()
            .zip(&self.error)
            .map(|(d, e)| d * (1.0 + e))
            .collect();
        (lo, hi)
    }
}

impl fmt::Display for AllanVariance {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (var, dev) = self.kind.columns();
        writeln!(
            f,
            "{} ({} convention), n = {}, freq = {} Hz, {}% CI",
            self.kind.title(),
            self.convention,
            self.n,
            self.freq_hz,
            100.0 * (1.0 - self.alpha)
        )?;
        writeln!(
            f,
            "{:>10} {:>12} {:>13} {:>13} {:>13} {:>13} {:>13} {:>13}",
            "tau",
            "tau_s",
            var,
            dev,
            "ci_low",
            "ci_high",
            format!("{dev}_low"),
            format!("{dev}_high")
        )?;
        for i in 0..self.tau.len() {
            writeln!(
                f,
                "{:>10} {:>12.6} {:>13.6e} {:>13.6e} {:>13.6e} {:>13.6e} {:>13.6e} {:>13.6e}",
                self.tau[i],
                self.tau_s[i],
                self.avar[i],
                self.adev[i],
                self.ci_low[i],
                self.ci_high[i],
                self.ci_low[i].sqrt(),
                self.ci_high[i].sqrt()
            )?;
        }
        Ok(())
    }
}

/// Computes an Allan-type variance at all standard cluster lengths (docs/methods.md §3).
///
/// # Formula
/// With moving means `ybar_k(m) = mean(x_k .. x_{k+m-1})` and block means
/// `Y_k = ybar_{km}(m)`, `K = floor(N/m)`:
///
/// | kind, textbook | estimator | cluster lengths `m` | edf |
/// |---|---|---|---|
/// | overlapping (§3.2) | `sum_{k=0}^{N-2m} (ybar_{k+m} - ybar_k)^2 / (2(N-2m+1))` | `2^i`, `2m <= N` | `max((N-2m+1)/(2m), 1)` |
/// | non-overlapping (§3.1) | `sum_{k=0}^{K-2} (Y_{k+1} - Y_k)^2 / (2(K-1))` | `2^i`, `K >= 2` | `2D^2/(3D-1)`, `D = K-1` |
/// | modified (§3.6) | Riley's MVAR, `N-3m+2` terms | `2^i`, `3m <= N+1` | `max((N-3m+2)/(3m), 1)` |
/// | Hadamard (§3.5) | `sum_{k=0}^{N-3m} (ybar_{k+2m} - 2ybar_{k+m} + ybar_k)^2 / (6(N-3m+1))` | `3^i`, `3m <= N` | `max((N-3m+1)/(3m), 1)` |
/// | Hadamard non-overlapping (§3.5) | `sum_{k=0}^{K-3} (Y_{k+2} - 2Y_{k+1} + Y_k)^2 / (6(K-2))` | `3^i`, `K >= 3` | `D^2 / (D + 2(D-1)(2/3)^2 + 2(D-2)(1/6)^2)`, `D = K-2` |
///
/// Cluster lengths start at `m = 1` and continue while at least one term exists, so the
/// overlapping AV is defined at the same cluster lengths as the Haar MODWT WV with
/// `J = floor(log2 N)` levels and `AV(2^{j-1}) = 2 nu2_j` (docs/methods.md §3.4, §13.23); these are
/// also allantools' octave taus.
///
/// Equivalent degrees of freedom: the overlapping kinds use the eta3 rule of docs/methods.md §1.7,
/// "terms / filter width" (for the overlapping AV exactly eta3 of the Haar WV at `tau = 2m`, via
/// §3.4); the non-overlapping kinds use the exact edf of a sum of squared Gaussian white-noise
/// differences (lag correlations -1/2 for first differences; -2/3 and 1/6 for second differences).
/// The package convention's disjoint pairs/triples are independent under white noise, so their
/// edf is the number `M` of pairs/triples; its "mo" estimators use the textbook overlapping
/// rule (with the full count `N - 2m + 1` or `N - 3m + 1`). The interval is the chi-square interval
/// of docs/methods.md §1.7 on the variance scale.
///
/// Package convention: see [`AvConvention::Package`] and docs/methods.md §3.1, §3.2, §3.5. A
/// Hadamard "mo" level with `N = 3m` has no term; the package crashes there (§13.10), this port
/// returns 0 (like the package's AV "mo" at `N = 2m`).
///
/// Numerics: the series is demeaned (compensated) and cumulated with compensated summation, so a
/// large offset (e.g. an accelerometer at -1 g) does not cost digits; sums of squares are blocked.
///
/// # Errors
/// - [`SeriesError`] for an empty, non-finite or constant series (`check_series`), or
///   [`SeriesError::TooShort`] when not even one cluster length fits;
/// - [`ParamError`] `freq` unless `freq_hz` is finite and positive; `alpha` outside (0, 1).
///
/// # Cost
/// O(N) time per cluster length, O(N log N) in all; O(N) extra memory per concurrently computed
/// cluster length.
///
/// # Examples
/// ```
/// use gmwm::{allan_variance, AllanOptions};
/// // docs/methods.md §3.4 test values: x = (1,3,2,5,4,6,8,7), textbook overlapping AV(2) = 2.1
/// let x = [1.0, 3.0, 2.0, 5.0, 4.0, 6.0, 8.0, 7.0];
/// let av = allan_variance(&x, 1.0, &AllanOptions::default()).unwrap();
/// assert_eq!(av.tau(), [1.0, 2.0, 4.0]);
/// assert!((av.avar()[1] - 2.1).abs() < 1e-12);
/// ```
pub fn allan_variance(
    x: &[f64],
    freq_hz: f64,
    opts: &AllanOptions,
) -> Result<AllanVariance, InputError> {
    check_series(x)?;
    crate::error::check_freq(freq_hz)?;
    check_alpha(opts.alpha)?;
    let n = x.len();
    let method = Method::of(opts.kind, opts.convention);
    let clusters = method.clusters(n);
    if clusters.is_empty() {
        return Err(SeriesError::TooShort {
            n,
            needed: method.min_len(),
            what: format!(
                "the {} variance ({} convention) at one cluster length",
                opts.kind, opts.convention
            ),
        }
        .into());
    }
    let s = centred_prefix_sums(x);
    let rows: Vec<Row> = clusters
        .par_iter()
        .map(|&m| method.estimate(&s, m))
        .collect();

    let len = rows.len();
    let mut out = AllanVariance {
        kind: opts.kind,
        convention: opts.convention,
        n,
        freq_hz,
        alpha: opts.alpha,
        tau: Vec::with_capacity(len),
        tau_s: Vec::with_capacity(len),
        avar: Vec::with_capacity(len),
        adev: Vec::with_capacity(len),
        ci_low: Vec::with_capacity(len),
        ci_high: Vec::with_capacity(len),
        adev_ci_low: Vec::with_capacity(len),
        adev_ci_high: Vec::with_capacity(len),
        edf: Vec::with_capacity(len),
        terms: Vec::with_capacity(len),
        error: Vec::with_capacity(len),
    };
    for (&m, row) in clusters.iter().zip(rows) {
        let mf = m as f64;
        let edf = row.edf.max(1.0);
        let (lo, hi) = interval_unchecked(row.value, edf, opts.alpha);
        out.tau.push(mf);
        out.tau_s.push(mf / freq_hz);
        out.avar.push(row.value);
        out.adev.push(row.value.sqrt());
        out.ci_low.push(lo);
        out.ci_high.push(hi);
        out.adev_ci_low.push(lo.sqrt());
        out.adev_ci_high.push(hi.sqrt());
        out.edf.push(edf);
        out.terms.push(row.terms);
        out.error.push(package_error(n, m));
    }
    crate::variance::wv::check_finite_result(&out.avar, "variance")?;
    Ok(out)
}

/// The package's "error" column `e = 1 / sqrt(2 (N/m - 1))`, docs/methods.md §3.3.
pub(crate) fn package_error(n: usize, m: usize) -> f64 {
    1.0 / (2.0 * (n as f64 / m as f64 - 1.0)).sqrt()
}

/// One estimator: kind and convention resolved.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Method {
    /// §3.2 textbook.
    AvOverlap,
    /// §3.2 package "mo": N - 2m terms, divisor 2(N - 2m + 1).
    AvOverlapPackage,
    /// §3.1 textbook: all consecutive differences.
    AvNonOverlap,
    /// §3.1 package "to": disjoint pairs.
    AvNonOverlapPackage,
    /// §3.6.
    Modified,
    /// §3.5 textbook overlapping.
    HvOverlap,
    /// §3.5 package "mo": N - 3m terms, divisor 6(N - 3m + 1).
    HvOverlapPackage,
    /// §3.5 textbook non-overlapping: all consecutive second differences.
    HvNonOverlap,
    /// §3.5 package "to": disjoint triples, divisor 6(M - 2).
    HvNonOverlapPackage,
}

/// One cluster length's estimate.
struct Row {
    value: f64,
    edf: f64,
    terms: usize,
}

impl Method {
    fn of(kind: AllanKind, convention: AvConvention) -> Self {
        let package = convention == AvConvention::Package;
        match (kind, package) {
            (AllanKind::Overlapping, false) => Method::AvOverlap,
            (AllanKind::Overlapping, true) => Method::AvOverlapPackage,
            (AllanKind::NonOverlapping, false) => Method::AvNonOverlap,
            (AllanKind::NonOverlapping, true) => Method::AvNonOverlapPackage,
            (AllanKind::Modified, _) => Method::Modified,
            (AllanKind::Hadamard, false) => Method::HvOverlap,
            (AllanKind::Hadamard, true) => Method::HvOverlapPackage,
            (AllanKind::HadamardNonOverlapping, false) => Method::HvNonOverlap,
            (AllanKind::HadamardNonOverlapping, true) => Method::HvNonOverlapPackage,
        }
    }

    /// Cluster lengths (docs/methods.md §3.1, §3.5; textbook rule in [`allan_variance`]).
    fn clusters(self, n: usize) -> Vec<usize> {
        match self {
            // at least one term: N - 2m + 1 >= 1 (and K = floor(N/m) >= 2, the same condition)
            Method::AvOverlap | Method::AvNonOverlap => powers(2, 0, |m| 2 * m <= n),
            // N - 3m + 2 >= 1
            Method::Modified => powers(2, 0, |m| 3 * m <= n + 1),
            // N - 3m + 1 >= 1 (and K >= 3, the same condition)
            Method::HvOverlap | Method::HvNonOverlap => powers(3, 0, |m| 3 * m <= n),
            // package: i = 1..floor(log10(N)/log10(2)) - 1, evaluated as the C++ does
            // (the filters only guard against a floating-point level count one too high, so that
            // no index can leave the series; they never bind for the package's own counts)
            Method::AvOverlapPackage | Method::AvNonOverlapPackage => {
                package_levels(n, 2.0, 1, 2, |m| 2 * m <= n)
            }
            Method::HvOverlapPackage => package_levels(n, 3.0, 1, 3, |m| 3 * m <= n),
            Method::HvNonOverlapPackage => package_levels(n, 3.0, 2, 3, |m| 9 * m <= n),
        }
    }

    /// Smallest N with at least one cluster length (for the error message).
    fn min_len(self) -> usize {
        match self {
            Method::AvOverlap | Method::AvNonOverlap | Method::Modified => 2,
            Method::HvOverlap | Method::HvNonOverlap => 3,
            Method::AvOverlapPackage | Method::AvNonOverlapPackage => 4,
            Method::HvOverlapPackage => 9,
            Method::HvNonOverlapPackage => 27,
        }
    }

    /// The estimate at cluster length `m` from centred prefix sums `s` (`s.len() = N + 1`).
    fn estimate(self, s: &[f64], m: usize) -> Row {
        let n = s.len() - 1;
        let mf = m as f64;
        match self {
            Method::AvOverlap | Method::AvOverlapPackage => {
                let full = n - 2 * m + 1;
                let terms = if self == Method::AvOverlap {
                    full
                } else {
                    full - 1
                };
                let ss = sum_sq_second_diff(s, m, terms);
                Row {
                    value: ss / (mf * mf) / (2.0 * full as f64),
                    edf: full as f64 / (2.0 * mf),
                    terms,
                }
            }
            Method::HvOverlap | Method::HvOverlapPackage => {
                let full = n - 3 * m + 1;
                let terms = if self == Method::HvOverlap {
                    full
                } else {
                    full - 1
                };
                let ss = sum_sq_third_diff(s, m, terms);
                Row {
                    value: ss / (mf * mf) / (6.0 * full as f64),
                    edf: full as f64 / (3.0 * mf),
                    terms,
                }
            }
            Method::AvNonOverlap => {
                let y = block_means(s, m);
                let d = y.len() - 1;
                let ss = blocked_sum(d, |k| {
                    let v = y[k + 1] - y[k];
                    v * v
                });
                let df = d as f64;
                Row {
                    value: ss / (2.0 * df),
                    edf: 2.0 * df * df / (3.0 * df - 1.0),
                    terms: d,
                }
            }
            Method::AvNonOverlapPackage => {
                let y = block_means(s, m);
                let pairs = n / (2 * m);
                let ss = blocked_sum(pairs, |k| {
                    let v = y[2 * k + 1] - y[2 * k];
                    v * v
                });
                Row {
                    value: ss / (2.0 * pairs as f64),
                    edf: pairs as f64,
                    terms: pairs,
                }
            }
            Method::HvNonOverlap => {
                let y = block_means(s, m);
                let d = y.len() - 2;
                let ss = blocked_sum(d, |k| {
                    let v = y[k + 2] - 2.0 * y[k + 1] + y[k];
                    v * v
                });
                let df = d as f64;
                // lag correlations of white-noise second differences: -2/3 (lag 1), 1/6 (lag 2)
                let denom =
                    df + 2.0 * (df - 1.0).max(0.0) * (4.0 / 9.0) + 2.0 * (df - 2.0).max(0.0) / 36.0;
                Row {
                    value: ss / (6.0 * df),
                    edf: df * df / denom,
                    terms: d,
                }
            }
            Method::HvNonOverlapPackage => {
                let y = block_means(s, m);
                let triples = n / (3 * m);
                let ss = blocked_sum(triples, |k| {
                    let v = y[3 * k + 2] - 2.0 * y[3 * k + 1] + y[3 * k];
                    v * v
                });
                // package levels guarantee triples >= 3 (N >= 9m), so the divisor is positive
                Row {
                    value: ss / (6.0 * (triples as f64 - 2.0)),
                    edf: triples as f64,
                    terms: triples,
                }
            }
            Method::Modified => {
                let terms = n + 2 - 3 * m;
                Row {
                    value: modified_sum(s, m, terms) / (2.0 * mf.powi(4) * terms as f64),
                    edf: terms as f64 / (3.0 * mf),
                    terms,
                }
            }
        }
    }
}

/// `base^i` for `i = first..` while `keep` holds.
fn powers(base: usize, first: u32, keep: impl Fn(usize) -> bool) -> Vec<usize> {
    let mut out = Vec::new();
    let mut m = base.pow(first);
    while keep(m) {
        out.push(m);
        match m.checked_mul(base) {
            Some(next) => m = next,
            None => break,
        }
    }
    out
}

/// The package's cluster set `base^i`, `i = 1..floor(log10(N)/log10(base)) - drop`, with the
/// level count evaluated in floating point exactly as `avar_*_cpp`/`hadam_*_cpp` do
/// (docs/methods.md §3.1, §3.5).
fn package_levels(
    n: usize,
    base: f64,
    drop: i64,
    base_int: usize,
    fits: impl Fn(usize) -> bool,
) -> Vec<usize> {
    let levels = (elementary::log10(n as f64) / elementary::log10(base)).floor() as i64 - drop;
    (1..=levels.max(0))
        .map(|i| base_int.pow(i as u32))
        .take_while(|&m| fits(m))
        .collect()
}

/// Prefix sums `S_0 = 0`, `S_{i+1} = sum_{t<=i} (x_t - mean)` of the centred series, each computed
/// with Neumaier-compensated summation and rounded once (docs/methods.md §3 numerics).
fn centred_prefix_sums(x: &[f64]) -> Vec<f64> {
    let n = x.len() as f64;
    let mean = NeumaierSum::of(x.iter().copied()) / n;
    // second pass removes the rounding left in the first mean
    let mean = mean + NeumaierSum::of(x.iter().map(|&v| v - mean)) / n;
    let mut s = Vec::with_capacity(x.len() + 1);
    s.push(0.0);
    let mut sum = NeumaierSum::default();
    for &v in x {
        sum.add(v - mean);
        s.push(sum.total());
    }
    s
}

/// Block of the blocked summation: partial sums of this many terms are added together, so the
/// rounding error grows like `BLOCK + len/BLOCK` instead of `len`.
const BLOCK: usize = 2048;

/// `sum_{k < len} f(k)` in blocks of [`BLOCK`] with four interleaved accumulators.
fn blocked_sum(len: usize, f: impl Fn(usize) -> f64) -> f64 {
    let mut total = 0.0;
    let mut start = 0;
    while start < len {
        let end = (start + BLOCK).min(len);
        let mut acc = [0.0_f64; 4];
        let mut k = start;
        while k + 4 <= end {
            for (lane, a) in acc.iter_mut().enumerate() {
                *a += f(k + lane);
            }
            k += 4;
        }
        while k < end {
            acc[0] += f(k);
            k += 1;
        }
        total += (acc[0] + acc[1]) + (acc[2] + acc[3]);
        start = end;
    }
    total
}

/// `sum_{k < terms} (S_{k+2m} - 2 S_{k+m} + S_k)^2` = `m^2 sum (ybar_{k+m} - ybar_k)^2`
/// (docs/methods.md §3.2).
fn sum_sq_second_diff(s: &[f64], m: usize, terms: usize) -> f64 {
    let a = &s[2 * m..2 * m + terms];
    let b = &s[m..m + terms];
    let c = &s[..terms];
    let mut total = 0.0;
    for ((a, b), c) in a.chunks(BLOCK).zip(b.chunks(BLOCK)).zip(c.chunks(BLOCK)) {
        let mut acc = [0.0_f64; 4];
        let mut ia = a.chunks_exact(4);
        let mut ib = b.chunks_exact(4);
        let mut ic = c.chunks_exact(4);
        for ((a4, b4), c4) in (&mut ia).zip(&mut ib).zip(&mut ic) {
            for l in 0..4 {
                let v = (a4[l] - b4[l]) - (b4[l] - c4[l]);
                acc[l] += v * v;
            }
        }
        for ((a, b), c) in ia
            .remainder()
            .iter()
            .zip(ib.remainder())
            .zip(ic.remainder())
        {
            let v = (a - b) - (b - c);
            acc[0] += v * v;
        }
        total += (acc[0] + acc[1]) + (acc[2] + acc[3]);
    }
    total
}

/// `sum_{k < terms} (S_{k+3m} - 3 S_{k+2m} + 3 S_{k+m} - S_k)^2`
/// = `m^2 sum (ybar_{k+2m} - 2 ybar_{k+m} + ybar_k)^2` (docs/methods.md §3.5).
fn sum_sq_third_diff(s: &[f64], m: usize, terms: usize) -> f64 {
    let a = &s[3 * m..3 * m + terms];
    let b = &s[2 * m..2 * m + terms];
    let c = &s[m..m + terms];
    let d = &s[..terms];
    blocked_sum(terms, |k| {
        let v = ((a[k] - b[k]) - (b[k] - c[k])) - ((b[k] - c[k]) - (c[k] - d[k]));
        v * v
    })
}

/// Block means `Y_k = (S_{(k+1)m} - S_{km}) / m`, `k < floor(N/m)` (docs/methods.md §3.1).
fn block_means(s: &[f64], m: usize) -> Vec<f64> {
    let k = (s.len() - 1) / m;
    let mf = m as f64;
    (0..k).map(|i| (s[(i + 1) * m] - s[i * m]) / mf).collect()
}

/// `sum_{j < terms} [sum_{i=j}^{j+m-1} (S_{i+2m} - 2 S_{i+m} + S_i)]^2`, i.e.
/// `m^4 * 2 (N - 3m + 2) MVAR(m)` (docs/methods.md §3.6), in O(N): the inner window sums are
/// differences of a compensated running sum `Q` of the second differences `D_i = S_{i+2m} -
/// 2S_{i+m} + S_i`.
fn modified_sum(s: &[f64], m: usize, terms: usize) -> f64 {
    // D_i for i = 0..terms + m - 1 (= N - 2m + 1 values), Q_0 = 0, Q_{i+1} = Q_i + D_i
    let nd = terms + m - 1;
    let mut q = Vec::with_capacity(nd + 1);
    q.push(0.0);
    let mut sum = NeumaierSum::default();
    for i in 0..nd {
        sum.add((s[i + 2 * m] - s[i + m]) - (s[i + m] - s[i]));
        q.push(sum.total());
    }
    blocked_sum(terms, |j| {
        let w = q[j + m] - q[j];
        w * w
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kind_names_round_trip() {
        for k in AllanKind::ALL {
            assert_eq!(k.to_string().parse::<AllanKind>().unwrap(), k);
            assert_eq!(
                k.to_string().to_uppercase().parse::<AllanKind>().unwrap(),
                k
            );
            let json = serde_json::to_string(&k).unwrap();
            assert_eq!(json, format!("\"{k}\""));
        }
        let err = "allan".parse::<AllanKind>().unwrap_err();
        assert_eq!(err.name, "kind");
        assert!(err.expected.contains("hadamard-non-overlapping"));
        for c in [AvConvention::Textbook, AvConvention::Package] {
            assert_eq!(c.to_string().parse::<AvConvention>().unwrap(), c);
        }
        assert_eq!("PACKAGE".parse::<AvConvention>(), Ok(AvConvention::Package));
        assert_eq!("r".parse::<AvConvention>().unwrap_err().name, "convention");
    }

    #[test]
    fn package_levels_match_the_cpp_counts() {
        // docs/methods.md §3.1, §3.5: N = 1e5 gives 15 AV, 9 HV "mo" and 8 HV "to" levels
        assert_eq!(package_levels(100_000, 2.0, 1, 2, |_| true).len(), 15);
        assert_eq!(package_levels(100_000, 3.0, 1, 3, |_| true).len(), 9);
        assert_eq!(package_levels(100_000, 3.0, 2, 3, |_| true).len(), 8);
        assert_eq!(package_levels(8, 2.0, 1, 2, |_| true), vec![2, 4]);
        assert_eq!(package_levels(27, 3.0, 2, 3, |_| true), vec![3]);
        assert!(package_levels(3, 2.0, 1, 2, |_| true).is_empty());
    }

    #[test]
    fn blocked_sum_matches_plain_sum() {
        for len in [0, 1, 3, 4, 5, 2047, 2048, 2049, 10_001] {
            let plain: f64 = (0..len).map(|k| k as f64).sum();
            assert_eq!(blocked_sum(len, |k| k as f64), plain, "len {len}");
        }
    }
}
