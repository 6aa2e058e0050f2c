//! Model selection by the Wavelet Information Criterion (docs/methods.md §8, paper eq. 5).
//!
//! `WIC = Q(theta_hat) + optimism`: the apparent loss of a candidate (its GMWM objective against
//! the data's WV, §5.1) plus an estimate of how much that loss flatters it (`optimism`).
//! Smaller is better.
//!
//! - `candidates`: the nested candidates of a full model (§8.4) and the common denominator
//!   of a user's list (§8.5), with the refusals of §8.5;
//! - `optimism`: the asymptotic optimism (§8.2, corrected derivative and trace order by
//!   default, the package's variant on request) and the bootstrap one (§8.3);
//! - [`wic`]: the selection procedure (§8.6), [`Wic`] and its result [`ModelSelection`];
//! - [`imu`]: every axis of an [`Imu`](crate::imu::Imu) in parallel (`auto.imu`).
//!
//! # What the criterion promises
//! The WIC estimates each candidate's expected loss on new data (an AIC-type criterion):
//! it is loss efficient and never underfits asymptotically (paper §III.C), but it is not
//! consistent. A superfluous term whose fit lowers the objective by more than its optimism
//! wins with a probability that does not vanish with N: about 8% for a variance term whose
//! true value is 0 (half of `P(chi2_1 > 2)`, the other half of the fits collapse it and tie).
//!
//! # Canonical rows and the choice among equivalent ones (issue 10)
//! The criterion compares what the candidates' fits *are*, not their names. Each candidate's
//! fit is read as its canonical model ([`crate::fit::canonical`]): components fitted to
//! nothing are left out, an AR1 the WV cannot tell from white noise or from a random walk is
//! that, two AR1s the WV cannot separate are one, a drift the WV cannot tell from a random walk
//! is the random walk, and an AR1 below the sampling interval is reported as white noise.
//! Candidates with the same canonical model are one row of the table, scored by its best
//! member or, when the data cannot tell a smaller member's fit from the best one's, by the
//! smallest such: a superset whose extra terms collapsed or stand in for others never wins on
//! the noise of its optimism, and a member that fits far better than a smaller one is not
//! hidden behind it.
//!
//! The rows are ranked by WIC. Rows whose WIC exceeds the minimum by at most one standard
//! error of the difference (`wic::wic_difference_se`: a first-order term from the two fits'
//! WVs and the WV's covariance, and the chi-square spread of the objective drop that extra
//! parameters buy on noise alone) are ones the criterion cannot tell apart from the minimum;
//! the [`SelectionRule`] chooses among them: by default ([`SelectionRule::Navigation`]) the
//! canonical model with white noise and a random walk if one of them has both, then the
//! fewest parameters. The criterion itself, its weights (the package's fast weights, for which
//! the asymptotic optimism is calibrated: tests/selection.rs
//! `asymptotic_optimism_is_calibrated_for_the_fast_weights_only`) and its optimism are the
//! package's.
//!
//! Measured (tests/selection.rs, 200 replicates of N = 1e5, B = 50, seeds 1000..1199), truth
//! `AR1(phi = 0.99, sigma2 = 1e-3) + WN(1) + RW(1e-6)`, whose random walk shows only at the
//! last three or four scales:
//!
//! | full model | one AR1 + WN + RW | exactly AR1+WN+RW | WN / RW densities within 10% / 50% of the true model's fit |
//! |---|---|---|---|
//! | `2*AR1()+WN()+RW()+QN()+DR()` | 183 | 182 | 193 |
//! | `3*AR1()+WN()+RW()+QN()+DR()` | 182 | 181 | 193 |
//!
//! (before: the selected model was exactly `AR1()+WN()+RW()` in 24/200 and 26/200; a drift
//! stood for the random walk in 62, the random walk was dropped in 52, a second AR1 stood for
//! the white noise or the random walk in most of the rest). Of the 17 replicates without
//! a random walk, 12 are ones where the true model's own fit has none: the fast weights
//! discount the last levels (their chi-square intervals are tens to thousands of times wider
//! than their standard errors), so at this length no fit with these weights sees a random walk
//! there. On data without a random walk (the same AR1 and WN), the navigation rule reports one
//! in 26/100 replicates (the parsimonious rule in none, the WIC minimum in 1): a random walk
//! the data at this length cannot exclude, of at most half the density of the one above. With
//! the random walk strong at every scale (truth `AR1(0.95, 0.1) + WN(1) + RW(1e-3)`), the
//! nested candidates of `AR1()+WN()+RW()+QN()+DR()` give the true model in 100/100 replicates
//! and those of `2*AR1()+WN()+RW()+QN()+DR()` in 191/200 (as fitted; 94/100 and 138/200
//! before), never an underfit.
//!
//! ```
//! use gmwm::Model;
//! use gmwm::Wic;
//! use gmwm::simulate_model;
//! let truth = Model::parse("AR1(phi=0.9, sigma2=1)+WN(sigma2=4)").unwrap();
//! let x = simulate_model(&truth, 4000, 1.0, 3).unwrap();
//! let wic = Wic::nested(Model::parse("AR1()+WN()+RW()").unwrap())
//!     .unwrap()
//!     .with_draws(500)
//!     .with_bootstrap(20);
//! let s = wic.select(&x, 1.0).unwrap();
//! assert_eq!(s.candidates().len(), 7);
//! // one row per canonical model; the selected one is the minimum or within one standard
//! // error of it, and it names the canonical model it stands for
//! let row = s.selected_row();
//! assert!(row.delta_wic <= row.delta_wic_se);
//! assert_eq!(row.score.canonical_model, s.selected_canonical().model);
//! assert!(s.rows().iter().all(|r| r.score.wic >= s.rows()[0].score.wic * (1.0 - 1e-6)));
//! ```

pub(crate) mod candidates;
pub(crate) mod imu;
pub(crate) mod optimism;
pub(crate) mod pooled;
pub(crate) mod wic;

#[cfg(test)]
pub(crate) use candidates::terms;

#[cfg(test)]
pub(crate) use candidates::{common_denominator, nested_candidates};
pub use imu::{auto_imu, AxisSelection, ImuSelection};
#[cfg(test)]
pub(crate) use optimism::asymptotic_optimism;
#[cfg(test)]
pub(crate) use optimism::d_matrix;
pub use optimism::{OptimismConvention, OptimismMethod};
pub use pooled::{select_pooled, PooledCandidate, PooledSelection};
pub use wic::{
    CandidateScore, ModelSelection, RowStatus, SelectionRow, SelectionRule, SelectionTable, Wic,
};

use crate::fit::FitError;
use crate::model::ProcessKind;
use thiserror::Error;

/// Why a model selection could not be set up or run (docs/methods.md §8).
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum SelectionError {
    /// An ARMA-family term in a candidate: selection supports WN, QN, RW, DR, AR1 and GM only
    /// (docs/methods.md §8.5; the package's guard is inert, §13.17).
    #[error(
        "candidate {candidate}: {kind} is not supported in model selection; use only WN, QN, RW, \
         DR and AR1 or GM terms (docs/methods.md §8.5)"
    )]
    ArmaNotSupported {
        /// Canonical text of the candidate.
        candidate: String,
        /// The offending term.
        kind: ProcessKind,
    },
    /// WN, QN, RW or DR more than once in a candidate.
    #[error(
        "candidate {candidate}: {kind} appears more than once; only AR1, GM and SIN may repeat"
    )]
    Repeated {
        /// Text of the candidate.
        candidate: String,
        /// The repeated term.
        kind: ProcessKind,
    },
    /// GM in one candidate and AR1 in another (or both in one).
    #[error(
        "candidate {gm} uses GM but candidate {ar1} uses AR1; all candidates must use the same \
         one (docs/methods.md §8.5)"
    )]
    GmAr1Mixed {
        /// A candidate with GM terms.
        gm: String,
        /// A candidate with AR1 terms.
        ar1: String,
    },
    /// A candidate text that does not parse.
    #[error("candidate {index} ({text:?}): {source}")]
    Parse {
        /// 1-based position in the list.
        index: usize,
        /// The text given.
        text: String,
        /// Why it does not parse.
        #[source]
        source: crate::model::ModelParseError,
    },
    /// No candidate given.
    #[error("no candidate models given; give at least one model")]
    NoCandidates,
    /// The full model has too many terms to enumerate its sub-models.
    #[error(
        "the full model has {terms} terms; nested selection enumerates 2^terms subsets and \
         accepts at most {max} terms"
    )]
    TooManyTerms {
        /// Terms of the full model.
        terms: usize,
        /// `MAX_NESTED_TERMS`.
        max: usize,
    },
    /// A setting out of range (e.g. fewer than 2 bootstrap replicates).
    #[error("invalid {name} = {value}: {expected}")]
    Setting {
        /// The setting.
        name: &'static str,
        /// Its value.
        value: String,
        /// What would be valid.
        expected: &'static str,
    },
    /// A candidate's fit (or its optimism or GoF) failed.
    #[error("candidate {candidate}: {source}")]
    Fit {
        /// Canonical text of the candidate.
        candidate: String,
        /// The fit error.
        #[source]
        source: FitError,
    },
    /// The selection on one axis of an IMU failed.
    #[error("axis {axis}: {source}")]
    Axis {
        /// Axis tag, e.g. `gyro_x`.
        axis: String,
        /// What failed.
        #[source]
        source: Box<SelectionError>,
    },
    /// A computation the selection builds on could not run: the series, a parameter or the model is
    /// unusable.
    #[error(transparent)]
    Input(#[from] crate::InputError),
}

crate::error::input_error_from!(SelectionError);
