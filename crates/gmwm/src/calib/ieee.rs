//! IEEE Std 952 read-offs from the Allan deviation (docs/methods.md §14.3).
//!
//! # The region rule
//! Each coefficient is read off the part of the Allan deviation curve where its own noise term
//! dominates. Which scales those are is decided on a smooth model, not on noisy local slopes:
//! the five IEEE terms (docs/methods.md §14.2 derivation check) are fitted to the Allan variance by
//! non-negative least squares,
//!
//! `AV(tau) ~ c_Q 3/tau^2 + c_N / tau + c_B + c_K tau/3 + c_R tau^2/2`, every `c >= 0`,
//!
//! in relative terms (residual `AV_model / AV - 1`, weight `min(edf, EDF_CAP)`), exactly: every
//! subset of the five columns is solved by unconstrained least squares and the best solution
//! with no negative coefficient is kept (the NNLS optimum is such a solution). A scale belongs
//! to the region of a term when that term carries at least `DOMINANCE` of the fitted AV
//! there. The fitted model is a posynomial in `tau`, so each region is an interval of scales
//! (the longest contiguous run is taken all the same). Fitting all five terms, the flicker
//! floor included, keeps a neighbouring term from being mistaken for the one read.
//!
//! On its region (narrowed to the scales within a factor `READ_OFF_WINDOW` of the read-off
//! time when two or more are there) the term's line of fixed slope (−1/2 for N, +1/2 for K, −1 for Q, +1 for R in
//! the deviation) is fitted through the **data** (not the model): the per-scale coefficients
//! `N_i = sigma_i sqrt(tau_i)`, `K_i = sigma_i sqrt(3 / tau_i)`, `Q_i = sigma_i tau_i / sqrt(3)`,
//! `R_i = sigma_i sqrt(2) / tau_i` are averaged in logarithms with weights `edf_i` (the inverse
//! variance of `ln sigma_i` is `2 edf_i`), which is the line's value at its read-off time
//! (1 s, 3 s, sqrt(3) s, sqrt(2) s). The interval is the same weighted fit through the square
//! roots of the band bounds `ci_low`, `ci_high`: the typical single-scale interval, not one
//! narrowed by pooling, because adjacent octaves of the overlapping AV share most of their
//! terms and are far from independent.
//!
//! A region with fewer than two scales gives no value, only a note saying so. Where the other
//! terms carry up to `1 - DOMINANCE` of the AV on the region, a per-scale coefficient is biased
//! high by at most `1 / sqrt(DOMINANCE) - 1` (5.4%), and their average by less.
//!
//! B is the minimum of the Allan deviation divided by [`FLICKER_FACTOR`]. Since every term
//! adds to the AV, `min sigma / 0.664` is always an upper bound on B; it is the estimate only
//! when the minimum is interior (a floor). At the first or last scale it is reported as
//! `ci_high` alone, with no value.

use crate::error::ParamError;
use crate::math::elementary;
use crate::units::{si_unit, NoiseTerm};
use crate::variance::allan::{AllanKind, AllanVariance};
use nalgebra::{DMatrix, DVector};
use serde::Serialize;
use std::fmt;

/// docs/methods.md §14.3: the flicker-floor factor `sqrt(2 ln 2 / π) = 0.6643`, rounded to 0.664 as
/// in IEEE Std 952 and docs/methods.md §14.5 (min ADEV 1e-4 gives B = 1.506024e-4 only with 0.664).
pub(crate) const FLICKER_FACTOR: f64 = 0.664;

/// Share of the fitted AV a term must carry at a scale for the scale to join its region.
/// 0.9 bounds the contamination of a read-off by the other terms to 5.4% (module doc) while
/// leaving regions of several octaves on real sensors, whose terms cross within a decade.
pub(crate) const DOMINANCE: f64 = 0.9;

/// Cap on the edf weight of a scale in the model fit: the five-term model is an idealisation
/// (real sensors add Gauss–Markov bumps), so once a scale's AV is known to about 14%
/// (`sqrt(2 / 100)`) its exact precision should not let it dominate the classification.
const EDF_CAP: f64 = 100.0;

/// Singular values below this fraction of the largest are dropped in the subset least squares
/// (columns are normalised to unit length first): collinear subsets then give the minimum-norm
/// solution instead of noise.
const SVD_EPS: f64 = 1e-13;

/// One IEEE Std 952 coefficient read off the Allan deviation (docs/methods.md §14.3).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CoefficientReadoff {
    /// The coefficient (data unit), or `None` where its region holds fewer than two scales.
    pub value: Option<f64>,
    /// Lower confidence bound (module doc).
    pub ci_low: Option<f64>,
    /// Upper confidence bound (module doc); for B also the upper bound when there is no value.
    pub ci_high: Option<f64>,
    /// Cluster times (seconds) used.
    pub tau_s: Vec<f64>,
    /// Where the line is read, seconds: 1 (N), 3 (K), √3 (Q), √2 (R), or the minimum's tau (B).
    pub at_tau_s: f64,
    /// How the value was obtained, or why there is none.
    pub note: Option<String>,
}

/// The five IEEE Std 952 coefficients (docs/methods.md §14.3), in the data unit `u`.
///
/// Wire format: `N`, `B`, `K`, `Q`, `R`, each a [`CoefficientReadoff`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct IeeeReadoff {
    /// Angle / velocity random walk N (u/√Hz), −1/2-slope line at 1 s.
    #[serde(rename = "N")]
    pub n: CoefficientReadoff,
    /// Bias instability B (u), minimum deviation / 0.664.
    #[serde(rename = "B")]
    pub b: CoefficientReadoff,
    /// Rate random walk K (u/s/√Hz), +1/2-slope line at 3 s.
    #[serde(rename = "K")]
    pub k: CoefficientReadoff,
    /// Quantization Q (u·s), −1-slope line at √3 s.
    #[serde(rename = "Q")]
    pub q: CoefficientReadoff,
    /// Rate ramp R (u/s), +1-slope line at √2 s.
    #[serde(rename = "R")]
    pub r: CoefficientReadoff,
}

/// A term of the five-term model.
struct Term {
    /// What its region is called in notes.
    region: &'static str,
    /// Slope of its line in the Allan deviation.
    slope: &'static str,
    /// AV per unit squared coefficient at cluster time `tau` (docs/methods.md §14.2 derivation
    /// check).
    basis: fn(f64) -> f64,
    /// Read-off time, seconds (docs/methods.md §14.3); `basis(at) = 1` there.
    at_tau_s: f64,
}

/// docs/methods.md §14.2, §14.3: the five terms in model-column order Q, N, B, K, R.
const TERMS: [Term; 5] = [
    Term {
        region: "quantization",
        slope: "−1",
        basis: |t| 3.0 / (t * t),
        at_tau_s: 1.732_050_807_568_877_2,
    },
    Term {
        region: "white-noise",
        slope: "−1/2",
        basis: |t| 1.0 / t,
        at_tau_s: 1.0,
    },
    Term {
        region: "flicker",
        slope: "0",
        basis: |_| 1.0,
        at_tau_s: f64::NAN,
    },
    Term {
        region: "random-walk",
        slope: "+1/2",
        basis: |t| t / 3.0,
        at_tau_s: 3.0,
    },
    Term {
        region: "rate-ramp",
        slope: "+1",
        basis: |t| t * t / 2.0,
        at_tau_s: std::f64::consts::SQRT_2,
    },
];
const Q: usize = 0;
const N: usize = 1;
const B: usize = 2;
const K: usize = 3;
const R: usize = 4;

/// docs/methods.md §14.2, §14.3: the Allan variance at cluster time `tau_s` of one IEEE term of
/// coefficient `c` alone, the line each read-off fits: `N²/τ` (N), `(0.664 B)²` (B, the
/// flicker floor with `FLICKER_FACTOR`), `K² τ/3` (K), `3 Q²/τ²` (Q), `R² τ²/2` (R); `None`
/// for a term that is not one of the five. The IEEE figure and the datasheet lines draw
/// their square roots.
///
/// ```
/// use gmwm::term_avar;
/// use gmwm::NoiseTerm;
/// // N = 2e-3 at 4 s: AV = 4e-6 / 4
/// assert!((term_avar(NoiseTerm::NoiseDensity, 2e-3, 4.0).unwrap() - 1e-6).abs() < 1e-18);
/// // K read at 3 s: the deviation equals K there
/// assert!((term_avar(NoiseTerm::RandomWalk, 5.0, 3.0).unwrap() - 25.0).abs() < 1e-12);
/// ```
pub fn term_avar(term: NoiseTerm, c: f64, tau_s: f64) -> Option<f64> {
    let (j, factor) = match term {
        NoiseTerm::Quantization => (Q, 1.0),
        NoiseTerm::NoiseDensity => (N, 1.0),
        NoiseTerm::BiasInstability => (B, FLICKER_FACTOR * FLICKER_FACTOR),
        NoiseTerm::RandomWalk => (K, 1.0),
        NoiseTerm::RateRamp => (R, 1.0),
        _ => return None,
    };
    Some(factor * c * c * (TERMS[j].basis)(tau_s))
}

/// docs/methods.md §14.3: the cluster time at which a line term is read (1 s for N, 3 s for K,
/// √3 s for Q, √2 s for R); `None` for B (read at the minimum) and the other terms.
pub(crate) fn read_off_tau_s(term: NoiseTerm) -> Option<f64> {
    let j = match term {
        NoiseTerm::Quantization => Q,
        NoiseTerm::NoiseDensity => N,
        NoiseTerm::RandomWalk => K,
        NoiseTerm::RateRamp => R,
        _ => return None,
    };
    Some(TERMS[j].at_tau_s)
}

/// The usable scales of an Allan variance: finite positive tau and AV.
struct Scales {
    tau_s: Vec<f64>,
    avar: Vec<f64>,
    edf: Vec<f64>,
    ci_low: Vec<f64>,
    ci_high: Vec<f64>,
}

impl Scales {
    fn of(av: &AllanVariance) -> Scales {
        let mut s = Scales {
            tau_s: Vec::new(),
            avar: Vec::new(),
            edf: Vec::new(),
            ci_low: Vec::new(),
            ci_high: Vec::new(),
        };
        for (i, (&t, &v)) in av.tau_s.iter().zip(&av.avar).enumerate() {
            if !(t.is_finite() && t > 0.0 && v.is_finite() && v > 0.0) {
                continue;
            }
            let edf = av.edf.get(i).copied().unwrap_or(f64::NAN);
            s.tau_s.push(t);
            s.avar.push(v);
            s.edf.push(if edf.is_finite() && edf > 0.0 {
                edf
            } else {
                1.0
            });
            s.ci_low.push(av.ci_low.get(i).copied().unwrap_or(f64::NAN));
            s.ci_high
                .push(av.ci_high.get(i).copied().unwrap_or(f64::NAN));
        }
        s
    }

    fn len(&self) -> usize {
        self.tau_s.len()
    }
}

/// docs/methods.md §14.3 (module doc): the non-negative least-squares fit of the five-term model,
/// in relative terms; returns the AV coefficients `c_Q, c_N, c_B, c_K, c_R` (all `>= 0`).
fn fit_terms(s: &Scales) -> [f64; 5] {
    let n = s.len();
    let w: Vec<f64> = s.edf.iter().map(|e| e.min(EDF_CAP).sqrt()).collect();
    let mut a = DMatrix::<f64>::zeros(n, 5);
    for i in 0..n {
        for (j, term) in TERMS.iter().enumerate() {
            a[(i, j)] = w[i] * (term.basis)(s.tau_s[i]) / s.avar[i];
        }
    }
    let norms: Vec<f64> = (0..5).map(|j| a.column(j).norm()).collect();
    for (j, &norm) in norms.iter().enumerate() {
        if norm > 0.0 && norm.is_finite() {
            a.column_mut(j).unscale_mut(norm);
        }
    }
    let b = DVector::from_vec(w.clone());
    let scale = b.norm_squared();
    let mut best: Option<(f64, [f64; 5])> = None;
    // subsets by increasing size, so that a tie keeps the simpler model
    let mut masks: Vec<u32> = (1..32u32).collect();
    masks.sort_by_key(|m| m.count_ones());
    for mask in masks {
        let cols: Vec<usize> = (0..5).filter(|j| mask & (1 << j) != 0).collect();
        if cols.len() > n
            || cols
                .iter()
                .any(|&j| !(norms[j] > 0.0 && norms[j].is_finite()))
        {
            continue;
        }
        let sub = DMatrix::from_fn(n, cols.len(), |i, k| a[(i, cols[k])]);
        let svd = sub.clone().svd(true, true);
        let max_sv = svd.singular_values.max();
        let Ok(x) = svd.solve(&b, SVD_EPS * max_sv) else {
            continue;
        };
        if x.iter().any(|v| !v.is_finite() || *v < 0.0) {
            continue;
        }
        let resid = (&sub * &x - &b).norm_squared();
        let better = match &best {
            None => true,
            Some((r, _)) => resid < r - 1e-12 * scale,
        };
        if better {
            let mut c = [0.0; 5];
            for (k, &j) in cols.iter().enumerate() {
                c[j] = x[k] / norms[j];
            }
            best = Some((resid, c));
        }
    }
    best.map(|(_, c)| c).unwrap_or([0.0; 5])
}

/// The longest contiguous run of scales where term `j` carries at least [`DOMINANCE`] of the
/// fitted AV (module doc).
fn region(s: &Scales, c: &[f64; 5], j: usize) -> Vec<usize> {
    let mut best: Vec<usize> = Vec::new();
    let mut run: Vec<usize> = Vec::new();
    for i in 0..s.len() {
        let parts: Vec<f64> = TERMS
            .iter()
            .zip(c)
            .map(|(t, c)| c * (t.basis)(s.tau_s[i]))
            .collect();
        let total: f64 = parts.iter().sum();
        if total > 0.0 && parts[j] >= DOMINANCE * total {
            run.push(i);
            if run.len() > best.len() {
                best = run.clone();
            }
        } else {
            run.clear();
        }
    }
    best
}

/// docs/methods.md §14.3: the fixed-slope line of term `j` through the data on `idx`, read at its
/// read-off time (module doc); `None` when a value is not finite.
fn line(s: &Scales, j: usize, idx: &[usize], values: &[f64]) -> Option<f64> {
    let basis = TERMS[j].basis;
    let (mut num, mut den) = (0.0, 0.0);
    for &i in idx {
        let coef = (values[i] / basis(s.tau_s[i])).sqrt();
        if !(coef.is_finite() && coef > 0.0) {
            return None;
        }
        num += s.edf[i] * elementary::log(coef);
        den += s.edf[i];
    }
    let v = elementary::exp(num / den);
    v.is_finite().then_some(v)
}

/// Half-width, as a factor, of the window of cluster times around the read-off time that a
/// line is fitted through when the region has at least two scales there: the line is read
/// where it is used, so that the first scales, which a sensor's anti-alias filter lowers below
/// the white-noise line, do not pull the N read at 1 s (ADIS16405 gyro X: 6.06e-4 through
/// 0.01–2.56 s, 7.0e-4 through 0.16–2.56 s, where the deviation's local slope is −1/2 within
/// 0.02).
pub(crate) const READ_OFF_WINDOW: f64 = 8.0;

/// The scales of `idx` within [`READ_OFF_WINDOW`] of `at_tau_s` when there are two or more,
/// else `idx`.
fn near_read_off(s: &Scales, idx: Vec<usize>, at_tau_s: f64) -> Vec<usize> {
    let near: Vec<usize> = idx
        .iter()
        .copied()
        .filter(|&i| {
            elementary::log(s.tau_s[i] / at_tau_s).abs() <= elementary::log(READ_OFF_WINDOW) + 1e-12
        })
        .collect();
    if near.len() >= 2 {
        near
    } else {
        idx
    }
}

/// A cluster time in notes and tables: 4 significant digits, trailing zeros dropped.
fn seconds(t: f64) -> String {
    let s = crate::fit::report::significant(t, 4);
    if s.contains('.') && !s.contains('e') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// docs/methods.md §14.3: the read-off of a line term (N, K, Q or R).
fn line_readoff(s: &Scales, c: &[f64; 5], j: usize) -> CoefficientReadoff {
    let term = &TERMS[j];
    let idx = near_read_off(s, region(s, c, j), term.at_tau_s);
    let tau_s: Vec<f64> = idx.iter().map(|&i| s.tau_s[i]).collect();
    let share = format!("{:.0}%", DOMINANCE * 100.0);
    if idx.len() < 2 {
        let why = if idx.is_empty() {
            format!(
                "no scale where the {} term carries {share} of the fitted AV: no value",
                term.region
            )
        } else {
            format!(
                "the {} region holds 1 scale ({} s; 2 needed): no value",
                term.region,
                seconds(tau_s[0])
            )
        };
        return CoefficientReadoff {
            value: None,
            ci_low: None,
            ci_high: None,
            tau_s,
            at_tau_s: term.at_tau_s,
            note: Some(why),
        };
    }
    let value = line(s, j, &idx, &s.avar);
    let ci_low = line(s, j, &idx, &s.ci_low);
    let ci_high = line(s, j, &idx, &s.ci_high);
    let (lo, hi) = (tau_s[0], tau_s[tau_s.len() - 1]);
    let extrapolated = if term.at_tau_s < lo || term.at_tau_s > hi {
        ", extrapolated"
    } else {
        ""
    };
    let note = format!(
        "{} slope line through {} scales ({} to {} s, {} term ≥ {share} of the fitted AV), \
         read at {} s{extrapolated}",
        term.slope,
        idx.len(),
        seconds(lo),
        seconds(hi),
        term.region,
        seconds(term.at_tau_s),
    );
    CoefficientReadoff {
        value,
        ci_low,
        ci_high,
        tau_s,
        at_tau_s: term.at_tau_s,
        note: Some(note),
    }
}

/// The widest Allan-variance interval (`ci_high / ci_low`) a scale may have for the bias
/// read-off to rest on it: 10, about nine clusters or more. The last points of a recording
/// rest on a handful of clusters, their intervals span 40x and more, and one of them dipping
/// would hide a floor the earlier scales show.
pub(crate) const RELIABLE_SPAN: f64 = 10.0;

/// docs/methods.md §14.3: bias instability, minimum deviation / [`FLICKER_FACTOR`] (module doc),
/// over the scales whose interval spans at most [`RELIABLE_SPAN`] (all scales when fewer than
/// three do). An interior minimum is a floor: B with its interval. A minimum at either end of
/// those scales is no floor: B is then the bound `min ADEV / 0.664` there, given as the value
/// without a lower end, and the note says which end and its cluster time.
fn bias_readoff(s: &Scales) -> CoefficientReadoff {
    let reliable: Vec<usize> = (0..s.len())
        .filter(|&i| s.ci_low[i] > 0.0 && s.ci_high[i] / s.ci_low[i] <= RELIABLE_SPAN)
        .collect();
    let scales: Vec<usize> = if reliable.len() >= 3 {
        reliable
    } else {
        (0..s.len()).collect()
    };
    let dropped = s.len() - scales.len();
    // the minimum; an interior scale attaining it is preferred, so a flat floor counts
    let min = scales
        .iter()
        .map(|&i| s.avar[i])
        .fold(f64::INFINITY, f64::min);
    let at_min: Vec<usize> = (0..scales.len())
        .filter(|&k| s.avar[scales[k]] == min)
        .collect();
    let interior = at_min
        .iter()
        .copied()
        .find(|&k| k > 0 && k + 1 < scales.len());
    let Some(k) = interior.or_else(|| at_min.first().copied()) else {
        return CoefficientReadoff {
            value: None,
            ci_low: None,
            ci_high: None,
            tau_s: Vec::new(),
            at_tau_s: f64::NAN,
            note: Some("no usable scale: no value".to_string()),
        };
    };
    let i = scales[k];
    let bound = |v: f64| {
        let b = v.sqrt() / FLICKER_FACTOR;
        (b.is_finite() && b > 0.0).then_some(b)
    };
    let b = bound(s.avar[i]);
    let tau = s.tau_s[i];
    let skipped = if dropped > 0 {
        format!(
            " ({dropped} longest cluster time{} left out: interval wider than {RELIABLE_SPAN:.0}x)",
            if dropped == 1 { "" } else { "s" }
        )
    } else {
        String::new()
    };
    let (value, ci_low, ci_high, note) = if scales.len() >= 3 && k > 0 && k + 1 < scales.len() {
        (
            b,
            bound(s.ci_low[i]),
            bound(s.ci_high[i]),
            format!(
                "min ADEV / 0.664 (flicker-floor factor applied), minimum at {} s{skipped}",
                seconds(tau)
            ),
        )
    } else {
        let why = if scales.len() < 3 {
            "fewer than 3 scales: no floor can be seen"
        } else if k == 0 {
            "ADEV rising from the shortest cluster time: no floor reached"
        } else {
            "ADEV still falling at the longest reliable cluster time: no floor reached"
        };
        (
            b,
            None,
            b,
            format!(
                "{why}; B <= min ADEV / 0.664 at {} s, given as an upper bound{skipped}",
                seconds(tau)
            ),
        )
    };
    CoefficientReadoff {
        value,
        ci_low,
        ci_high,
        tau_s: vec![tau],
        at_tau_s: tau,
        note: Some(note),
    }
}

/// docs/methods.md §14.3: the IEEE Std 952 read-offs N, B, K, Q, R of an Allan variance (region
/// rule and constants in the module doc), in the unit of the data the AV was computed from.
///
/// # Errors
/// [`ParamError`] named `kind` unless `av` is an Allan variance (overlapping or not): the
/// Hadamard and modified variances have other constants in the slope laws.
pub fn ieee_readoff(av: &AllanVariance) -> Result<IeeeReadoff, ParamError> {
    if !matches!(av.kind, AllanKind::Overlapping | AllanKind::NonOverlapping) {
        return Err(ParamError::new(
            "kind",
            av.kind,
            "an Allan variance (overlapping or non-overlapping): IEEE Std 952 read-offs use the \
             Allan slope laws, which differ for the Hadamard and modified variances",
        ));
    }
    let s = Scales::of(av);
    let c = if s.len() >= 2 {
        fit_terms(&s)
    } else {
        [0.0; 5]
    };
    Ok(IeeeReadoff {
        n: line_readoff(&s, &c, N),
        b: bias_readoff(&s),
        k: line_readoff(&s, &c, K),
        q: line_readoff(&s, &c, Q),
        r: line_readoff(&s, &c, R),
    })
}

impl IeeeReadoff {
    /// The read-offs with their symbols, in table order N, B, K, Q, R.
    pub fn rows(&self) -> [(&'static str, NoiseTerm, &CoefficientReadoff); 5] {
        [
            ("N", NoiseTerm::NoiseDensity, &self.n),
            ("B", NoiseTerm::BiasInstability, &self.b),
            ("K", NoiseTerm::RandomWalk, &self.k),
            ("Q", NoiseTerm::Quantization, &self.q),
            ("R", NoiseTerm::RateRamp, &self.r),
        ]
    }
}

impl fmt::Display for IeeeReadoff {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let opt = |v: Option<f64>| v.map_or("—".to_string(), |v| format!("{v:.6e}"));
        writeln!(f, "IEEE Std 952 read-offs (u = data unit)")?;
        writeln!(
            f,
            "{:<3} {:<10} {:>13} {:>13} {:>13} {:>9} {:>6}",
            "", "unit", "value", "ci_low", "ci_high", "at tau_s", "scales"
        )?;
        for (sym, term, r) in self.rows() {
            writeln!(
                f,
                "{sym:<3} {:<10} {:>13} {:>13} {:>13} {:>9} {:>6}",
                si_unit(term, None, "u"),
                opt(r.value),
                opt(r.ci_low),
                opt(r.ci_high),
                if r.at_tau_s.is_finite() {
                    seconds(r.at_tau_s)
                } else {
                    "—".to_string()
                },
                r.tau_s.len()
            )?;
        }
        let notes: Vec<String> = self
            .rows()
            .iter()
            .filter_map(|(sym, _, r)| r.note.as_ref().map(|n| format!("{sym}: {n}")))
            .collect();
        write!(f, "{}", notes.join("\n"))
    }
}
