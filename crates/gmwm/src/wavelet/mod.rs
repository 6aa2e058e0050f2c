//! Wavelet filters and transforms: the MODWT and DWT pyramids with periodic boundary
//! (docs/methods.md §1.1–§1.4, §1.8).
//!
//! - [`WaveletFilter`]: the published scaling filters and their quadrature mirrors (§1.1, §1.8).
//! - [`Modwt`] and [`Dwt`]: plans (filter + number of levels, validated once) that run the
//!   pyramid algorithm on any number of series (§1.2, §1.4).
//! - [`WaveletCoefficients`]: every coefficient of every level plus the count of leading boundary
//!   coefficients to drop (the "brick wall", §1.3, §1.4).
//! - `naive` (crate-internal, test builds only): slow direct-convolution twins of both
//!   transforms, the test oracle.
//!
//! Deviation from the R package (docs/methods.md §1.3, §13.1): when exactly one boundary-free
//! coefficient remains at a level, it is **kept** (the package keeps none and returns a NaN
//! variance); a level with no boundary-free coefficient at all is refused with
//! [`SeriesError::TooShort`](crate::error::SeriesError::TooShort).

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::error::ParamError;

mod dwt;
mod filter;
mod modwt;
#[cfg(test)]
pub(crate) mod naive;
#[cfg(test)]
mod tests_oracle;

pub(crate) use dwt::Dwt;
#[cfg(test)]
pub(crate) use filter::quadrature_mirror;
pub use filter::WaveletFilter;
pub(crate) use modwt::Modwt;

/// Largest number of levels a [`Modwt`] or [`Dwt`] plan accepts (`2^60` samples would be
/// needed; the bound keeps every `2^j` representable in a 64-bit `usize`).
pub(crate) const MAX_LEVELS: usize = 60;

/// Decimated or maximal-overlap wavelet transform (docs/methods.md §1.2, §1.4).
///
/// Serialised, displayed and parsed as `"modwt"` / `"dwt"`; parsing ignores ASCII case.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Transform {
    /// Maximal-overlap DWT (docs/methods.md §1.2), the default.
    #[default]
    Modwt,
    /// Decimated DWT (docs/methods.md §1.4).
    Dwt,
}

impl Transform {
    /// Lower-case name, `"modwt"` or `"dwt"` (docs/methods.md §1.2, §1.4).
    pub fn name(&self) -> &'static str {
        match self {
            Transform::Modwt => "modwt",
            Transform::Dwt => "dwt",
        }
    }
}

impl crate::names::Named for Transform {
    const WHAT: &'static str = "transform";
    const VALUES: &'static [Self] = &[Transform::Modwt, Transform::Dwt];

    fn name(self) -> &'static str {
        Transform::name(&self)
    }
}

impl fmt::Display for Transform {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.pad(self.name())
    }
}

impl FromStr for Transform {
    type Err = ParamError;

    /// Parses `modwt` or `dwt`, ignoring ASCII case and surrounding whitespace.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim();
        [Transform::Modwt, Transform::Dwt]
            .into_iter()
            .find(|x| x.name().eq_ignore_ascii_case(t))
            .ok_or_else(|| ParamError::new("transform", s, "one of modwt, dwt"))
    }
}

/// `2^j`, saturating at `usize::MAX` (never reached for `j <= MAX_LEVELS` on 64-bit targets).
pub(crate) fn pow2(j: usize) -> usize {
    u32::try_from(j)
        .ok()
        .and_then(|j| 1usize.checked_shl(j))
        .unwrap_or(usize::MAX)
}

/// Number of leading level-`j` MODWT coefficients touched by the periodic wrap-around,
/// `n_j = (2^j - 1)(L - 1)` (docs/methods.md §1.3).
///
/// The level-j equivalent filter has width `L_j = n_j + 1`; coefficient `t` is boundary-free iff
/// `t >= n_j`. Saturates at `usize::MAX` instead of overflowing.
///
/// # Examples
/// Worked example: the test `tests::examples::example_modwt_boundary`.
pub(crate) fn modwt_boundary(filter_len: usize, j: usize) -> usize {
    (pow2(j) - 1).saturating_mul(filter_len.saturating_sub(1))
}

/// Number of leading level-`j` DWT coefficients touched by the periodic wrap-around,
/// `ceil((L - 2)(1 - 2^-j))` (docs/methods.md §1.4); 0 for Haar.
///
/// Computed exactly in integers as `(L - 2) - floor((L - 2) / 2^j)`.
///
/// # Examples
/// Worked example: the test `tests::examples::example_dwt_boundary`.
pub(crate) fn dwt_boundary(filter_len: usize, j: usize) -> usize {
    let m = filter_len.saturating_sub(2);
    m - m / pow2(j)
}

/// Wavelet coefficients of every level of a MODWT or DWT, boundary coefficients included
/// (docs/methods.md §1.2–§1.4).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct WaveletCoefficients {
    /// `w[j-1]` = all coefficients `W_{j,0..}` of level `j` (N of them for the MODWT,
    /// `N / 2^j` for the DWT), boundary ones included.
    pub(crate) w: Vec<Vec<f64>>,
    /// `boundary[j-1]` = number of leading level-`j` coefficients touched by the periodic
    /// boundary, to drop before estimation (docs/methods.md §1.3, §1.4).
    pub(crate) boundary: Vec<usize>,
}

impl WaveletCoefficients {
    /// Kept (boundary-free) coefficients of level `j`, 1-based (docs/methods.md §1.3, §1.4); never
    /// empty for a transform output.
    ///
    /// # Panics
    /// If `j == 0` or `j > self.levels()` (a caller bug, not a data problem).
    pub(crate) fn kept(&self, j: usize) -> &[f64] {
        assert!(
            j >= 1 && j <= self.levels(),
            "level {j} out of range 1..={}",
            self.levels()
        );
        let w = &self.w[j - 1];
        &w[self.boundary[j - 1].min(w.len())..]
    }

    /// Number of levels `J`.
    pub(crate) fn levels(&self) -> usize {
        self.w.len()
    }
}

/// Reusable work buffers of [`Modwt::transform_with_scratch`] and
/// [`Dwt::transform_with_scratch`]; after a run it holds the final scaling coefficients `V_J`
/// (docs/methods.md §1.2, §1.4).
#[derive(Debug, Clone, Default)]
pub(crate) struct WaveletScratch {
    /// Current scaling coefficients `V_j`.
    v: Vec<f64>,
    /// Next scaling coefficients `V_{j+1}` while a level is computed.
    next: Vec<f64>,
}

impl WaveletScratch {
    /// Empty buffers; they grow on first use and are then reused.
    pub(crate) fn new() -> Self {
        Self::default()
    }

    /// Scaling coefficients `V_J` of the last level of the last successful transform
    /// (docs/methods.md §1.2, §1.4): length N for the MODWT, `N / 2^J` for the DWT; empty before
    /// the first run.
    #[cfg(test)]
    pub(crate) fn scaling(&self) -> &[f64] {
        &self.v
    }
}

/// Resizes `out` to `levels` rows of `len(j)` coefficients, reusing its allocations.
pub(crate) fn shape_output(
    out: &mut WaveletCoefficients,
    levels: usize,
    len: impl Fn(usize) -> usize,
    boundary: impl Fn(usize) -> usize,
) {
    out.w.resize_with(levels, Vec::new);
    out.boundary.clear();
    for (i, row) in out.w.iter_mut().enumerate() {
        row.clear();
        row.resize(len(i + 1), 0.0);
        out.boundary.push(boundary(i + 1));
    }
}

/// Validates a number of levels, `1 <= levels <= MAX_LEVELS`.
pub(crate) fn check_levels(levels: usize) -> Result<(), ParamError> {
    if (1..=MAX_LEVELS).contains(&levels) {
        Ok(())
    } else {
        Err(ParamError::new(
            "levels",
            levels,
            format!("an integer from 1 to {MAX_LEVELS}"),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transform_names_round_trip() {
        for t in [Transform::Modwt, Transform::Dwt] {
            assert_eq!(t.to_string().parse::<Transform>(), Ok(t));
            assert_eq!(t.name().to_uppercase().parse::<Transform>(), Ok(t));
            let json = serde_json::to_string(&t).unwrap();
            assert_eq!(json, format!("\"{t}\""));
            assert_eq!(serde_json::from_str::<Transform>(&json).unwrap(), t);
        }
        assert_eq!(Transform::default(), Transform::Modwt);
        let e = "fft".parse::<Transform>().unwrap_err();
        assert_eq!((e.name, e.value.as_str()), ("transform", "fft"));
    }

    /// docs/methods.md §1.3: `n_j = (2^j - 1)(L - 1)`.
    #[test]
    fn modwt_boundary_formula() {
        assert_eq!(modwt_boundary(2, 1), 1);
        assert_eq!(modwt_boundary(2, 3), 7);
        assert_eq!(modwt_boundary(4, 2), 9);
        assert_eq!(modwt_boundary(24, 60), usize::MAX); // saturates
    }

    /// docs/methods.md §1.4: `ceil((L - 2)(1 - 2^-j))`, checked against the real-valued formula.
    #[test]
    fn dwt_boundary_formula() {
        for len in (2..=24).step_by(2) {
            for j in 1..=8 {
                let exact = ((len as f64 - 2.0) * (1.0 - 0.5f64.powi(j as i32))).ceil() as usize;
                assert_eq!(dwt_boundary(len, j), exact, "L = {len}, j = {j}");
            }
        }
        assert_eq!(dwt_boundary(24, 60), 22);
    }

    #[test]
    fn pow2_saturates() {
        assert_eq!(pow2(0), 1);
        assert_eq!(pow2(10), 1024);
        assert_eq!(pow2(200), usize::MAX);
    }

    #[test]
    #[should_panic(expected = "out of range")]
    fn wavelet_coefficients_kept_rejects_level_zero() {
        WaveletCoefficients::default().kept(0);
    }
}
