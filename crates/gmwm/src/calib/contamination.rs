//! Does contamination matter? The classical wavelet variance of an axis against its robust
//! one (paper Fig. 2, docs/methods.md §2): on clean Gaussian data both estimate the same WV and the
//! classical estimate lies inside the robust interval at all but about `alpha` of the scales;
//! outliers inflate the classical estimate above the robust interval at the scales they reach.

use super::pipeline::CHANCE_MISS_REL;
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
    /// Whether the classical estimate, and so a classical fit, is affected: more scales outside
    /// than `alpha` of them allows by chance, or one outside by more than
    /// `CHANCE_MISS_REL`.
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
/// interval; the verdict is the fit verdict's rule (more than `ceil(alpha J)` levels outside, or
/// one outside by more than `CHANCE_MISS_REL` relative).
pub(crate) fn compare_classical_robust(
    classical: WaveletVariance,
    robust: WaveletVariance,
    fit_uses: FitUses,
    alpha: f64,
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
    let allowed = (alpha * compared.len() as f64).ceil() as usize;
    let matters = outside > allowed || max_ratio - 1.0 > CHANCE_MISS_REL;
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
        format!(
            "The classical WV leaves the robust {band} interval at {outside} of {} scales, by at most a factor {}: no more than chance allows, so contamination does not matter here.",
            compared.len(),
            significant(max_ratio, 3)
        )
    } else {
        let mut parts = Vec::new();
        if !levels_above.is_empty() {
            parts.push(format!(
                "above the robust {band} interval at {} scale(s) ({})",
                levels_above.len(),
                span(&levels_above)
            ));
        }
        if !levels_below.is_empty() {
            parts.push(format!(
                "below it at {} scale(s) ({})",
                levels_below.len(),
                span(&levels_below)
            ));
        }
        let at = furthest.map(|(l, _)| tau(l)).unwrap_or_default();
        format!(
            "The classical WV lies {} of {} compared, up to a factor {} at {at} s: contamination matters; {advice}.",
            parts.join(" and "),
            compared.len(),
            significant(max_ratio, 3)
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
