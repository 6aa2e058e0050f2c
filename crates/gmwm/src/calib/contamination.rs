//! Does contamination matter? The classical wavelet variance of an axis against its robust
//! one (paper Fig. 2, docs/methods.md §2): on clean Gaussian data both estimate the same WV and the
//! classical estimate lies inside the robust interval at all but about `alpha` of the scales;
//! outliers inflate the classical estimate above the robust interval at the scales they reach.
//!
//! Only a classical WV **above** the robust interval is evidence of outliers: below it is what
//! quantisation or a light-tailed noise does to the robust estimator's Gaussian calibration
//! (every ADIS gyro_z, at its first two scales), and is reported as such. And contamination
//! matters only when it would change an exported number by more than the verdict's tolerance:
//! the densities a filter reads (N, K, B) are square roots of variances, so a scale above the
//! robust interval by a factor `r` moves them by about `sqrt(r) - 1`.

use crate::fit::report::significant;
use crate::variance::wv::WaveletVariance;
use serde::Serialize;

/// The classical against the robust wavelet variance of one axis.
///
/// Wire format: `classical` and `robust` (the two [`WaveletVariance`]s), `fit_uses` (`classical`
/// or `robust`: which of them the axis' fit used), `levels` (scales compared: both
/// defined), `undefined_levels` (1-based levels whose robust WV is undefined), `levels_above`
/// and `levels_below` (1-based levels where the classical estimate lies above / below the
/// robust interval), `max_ratio` (the largest classical / robust ratio, or its inverse when
/// smaller than one, over the levels outside), `matters`, `summary`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Contamination {
    /// The classical wavelet variance.
    pub classical: WaveletVariance,
    /// The robust wavelet variance (same transform, filter and levels as the classical one).
    pub robust: WaveletVariance,
    /// Which of the two the axis' fit used.
    pub fit_uses: FitUses,
    /// Number of scales where both estimates are defined.
    pub levels: usize,
    /// 1-based levels whose robust WV is undefined (no root of the scale equation).
    pub(crate) undefined_levels: Vec<usize>,
    /// 1-based levels where the classical WV lies above the robust interval.
    pub(crate) levels_above: Vec<usize>,
    /// 1-based levels where the classical WV lies below the robust interval.
    pub(crate) levels_below: Vec<usize>,
    /// Largest factor between the classical and the robust WV over the levels outside (1 when
    /// none is).
    pub(crate) max_ratio: f64,
    /// Whether outliers would change an exported number by more than the tolerance: the
    /// classical WV lies above the robust interval at some scale by a factor `r` with
    /// `sqrt(r) - 1` beyond the tolerance (module doc).
    pub matters: bool,
    /// One sentence for the report.
    pub summary: String,
}

/// Which wavelet variance a fit used.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FitUses {
    /// The classical estimator.
    Classical,
    /// The robust estimator.
    Robust,
}

/// Compares `classical` with `robust` (docs/methods.md §2, paper Fig. 2) at confidence level
/// `1 - alpha`: a level counts as outside when the classical estimate is beyond the robust
/// interval; contamination matters when a level above it would move a density by more than
/// `tolerance` (module doc).
pub(crate) fn compare_classical_robust(
    classical: WaveletVariance,
    robust: WaveletVariance,
    fit_uses: FitUses,
    alpha: f64,
    tolerance: f64,
) -> Contamination {
    let total = classical.wv.len().min(robust.wv.len());
    let defined = |j: usize| {
        robust.wv[j].is_finite()
            && robust.ci_low[j].is_finite()
            && robust.ci_high[j].is_finite()
            && robust.wv[j] > 0.0
            && classical.wv[j].is_finite()
    };
    let undefined_levels: Vec<usize> = (0..total).filter(|&j| !defined(j)).map(|j| j + 1).collect();
    let compared: Vec<usize> = (0..total).filter(|&j| defined(j)).collect();
    let levels_above: Vec<usize> = compared
        .iter()
        .filter(|&&j| classical.wv[j] > robust.ci_high[j])
        .map(|&j| j + 1)
        .collect();
    let levels_below: Vec<usize> = compared
        .iter()
        .filter(|&&j| classical.wv[j] < robust.ci_low[j])
        .map(|&j| j + 1)
        .collect();
    let ratio = |level: usize| {
        let r = classical.wv[level - 1] / robust.wv[level - 1];
        if r >= 1.0 {
            r
        } else {
            1.0 / r
        }
    };
    let furthest = levels_above
        .iter()
        .chain(&levels_below)
        .map(|&l| (l, ratio(l)))
        .filter(|(_, r)| r.is_finite())
        .max_by(|a, b| a.1.total_cmp(&b.1));
    let max_ratio = furthest.map_or(1.0, |(_, r)| r);
    let outside = levels_above.len() + levels_below.len();
    // the largest move of a density (a square root of a variance) the outliers cause
    let density_shift = levels_above
        .iter()
        .map(|&l| ratio(l).sqrt() - 1.0)
        .filter(|d| d.is_finite())
        .fold(0.0, f64::max);
    let matters = density_shift > tolerance;
    let tau = |level: usize| significant(classical.tau_s[level - 1], 3);
    let span = |levels: &[usize]| match (levels.first(), levels.last()) {
        (Some(&a), Some(&b)) if a == b => format!("{} s", tau(a)),
        (Some(&a), Some(&b)) => format!("{} s to {} s", tau(a), tau(b)),
        _ => String::new(),
    };
    let band = format!("{:.0}%", 100.0 * (1.0 - alpha));
    let advice = match fit_uses {
        FitUses::Classical => "compare with a robust fit (--robust)",
        FitUses::Robust => "the robust fit used here is the one to trust",
    };
    let mut summary = if compared.is_empty() {
        "The classical and robust WVs could not be compared: the robust WV is undefined at every scale.".to_string()
    } else if outside == 0 {
        format!(
            "The classical WV lies inside the robust {band} interval at all {} scales compared: contamination does not matter here, and the classical fit stands.",
            compared.len()
        )
    } else if !matters {
        let mut parts = Vec::new();
        if !levels_above.is_empty() {
            parts.push(format!(
                "above the robust {band} interval at {} scale(s) ({}), moving a noise density by at most {:.1}%, within the {:.0}% tolerance",
                levels_above.len(),
                span(&levels_above),
                100.0 * density_shift,
                100.0 * tolerance
            ));
        }
        if !levels_below.is_empty() {
            parts.push(format!(
                "below it at {} scale(s) ({}), which quantisation or a light-tailed noise does, not outliers",
                levels_below.len(),
                span(&levels_below)
            ));
        }
        format!(
            "The classical WV lies {} of {} compared: contamination does not matter here.",
            parts.join(" and "),
            compared.len()
        )
    } else {
        let worst_above = levels_above
            .iter()
            .map(|&l| (l, ratio(l)))
            .filter(|(_, r)| r.is_finite())
            .max_by(|a, b| a.1.total_cmp(&b.1));
        let (at, factor) = worst_above.map_or((String::new(), 1.0), |(l, r)| (tau(l), r));
        let below = if levels_below.is_empty() {
            String::new()
        } else {
            format!(
                "; below it at {} scale(s) ({}), which is not contamination",
                levels_below.len(),
                span(&levels_below)
            )
        };
        format!(
            "The classical WV lies above the robust {band} interval at {} of {} scales compared ({}), up to a factor {} at {at} s, moving a noise density by up to {:.0}%: contamination matters; {advice}{below}.",
            levels_above.len(),
            compared.len(),
            span(&levels_above),
            significant(factor, 3),
            100.0 * density_shift
        )
    };
    if !undefined_levels.is_empty() {
        summary.push_str(&format!(
            " The robust WV is undefined at level(s) {} (too many outlying coefficients there).",
            undefined_levels
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    Contamination {
        classical,
        robust,
        fit_uses,
        levels: compared.len(),
        undefined_levels,
        levels_above,
        levels_below,
        max_ratio,
        matters,
        summary,
    }
}
