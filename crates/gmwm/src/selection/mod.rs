//! Model selection by the Wavelet Information Criterion (METHODS §8, paper eq. 5).
//!
//! `WIC = Q(theta_hat) + optimism`: the apparent loss of a candidate (its GMWM objective against
//! the data's WV, §5.1) plus an estimate of how much that loss flatters it ([`optimism`]).
//! Smaller is better.
//!
//! - [`candidates`]: the nested candidates of a full model (§8.4) and the common denominator
//!   of a user's list (§8.5), with the refusals of §8.5;
//! - [`optimism`]: the asymptotic optimism (§8.2, corrected derivative and trace order by
//!   default, the package's variant on request) and the bootstrap one (§8.3);
//! - [`wic`]: the selection procedure (§8.6), [`Wic`] and its result [`ModelSelection`];
//! - [`imu`]: every axis of an [`Imu`](crate::imu::Imu) in parallel (`auto.imu`).
//!
//! # What the criterion promises
//! The WIC estimates each candidate's expected loss on new data (an AIC-type criterion):
//! it is loss efficient and never underfits asymptotically (paper §III.C), but it is not
//! consistent. A superfluous term whose fit lowers the objective by more than its optimism
//! wins with a probability that does not vanish with N: about 8% for a variance term whose
//! true value is 0 (half of `P(chi2_1 > 2)`, the other half of the fits collapse it and tie),
//! more for a second AR1, whose phi is not identified when its variance is 0 and which can
//! also stand in for a random walk (phi -> 1) or a white noise (phi -> 0). Measured at
//! N = 1e5, truth `AR1+WN+RW` (tests/selection.rs): the true model is picked in 94/100
//! replicates among the nested candidates of `AR1()+WN()+RW()+QN()+DR()` and in 138/200 among
//! those of `2*AR1()+WN()+RW()+QN()+DR()`, never an underfit.
//!
//! ```
//! use gmwm::model::Model;
//! use gmwm::selection::Wic;
//! use gmwm::sim::simulate_model;
//! let truth = Model::parse("AR1(phi=0.9, sigma2=1)+WN(sigma2=4)").unwrap();
//! let x = simulate_model(&truth, 4000, 1.0, 3).unwrap();
//! let wic = Wic::nested(Model::parse("AR1()+WN()+RW()").unwrap())
//!     .unwrap()
//!     .with_draws(500)
//!     .with_bootstrap(20);
//! let s = wic.select(&x, 1.0).unwrap();
//! assert_eq!(s.candidates.len(), 7);
//! assert_eq!(s.selected, s.candidates[0].model);
//! assert!(s.candidates.iter().all(|c| c.wic >= s.candidates[0].wic * (1.0 - 1e-6)));
//! ```

pub mod candidates;
pub mod imu;
pub mod optimism;
pub mod wic;

pub use candidates::{common_denominator, nested_candidates, terms, MAX_NESTED_TERMS};
pub use imu::{auto_imu, AxisSelection, ImuSelection};
pub use optimism::{
    asymptotic_optimism, bootstrap_optimism, d_matrix, OptimismConvention, OptimismMethod,
};
pub use wic::{
    CandidateScore, ModelSelection, RowStatus, SelectionRow, SelectionRule, SelectionTable, Wic,
};

use crate::fit::FitError;
use crate::model::ProcessKind;
use thiserror::Error;

/// Why a model selection could not be set up or run (METHODS §8).
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum SelectionError {
    /// An ARMA-family term in a candidate: selection supports WN, QN, RW, DR, AR1 and GM only
    /// (METHODS §8.5; the package's guard is inert, §13.17).
    #[error(
        "candidate {candidate}: {kind} is not supported in model selection; use only WN, QN, RW, \
         DR and AR1 or GM terms (METHODS §8.5)"
    )]
    ArmaNotSupported {
        /// Canonical text of the candidate.
        candidate: String,
        /// The offending term.
        kind: ProcessKind,
    },
    /// WN, QN, RW or DR more than once in a candidate.
    #[error("candidate {candidate}: {kind} appears more than once; only AR1 and GM may repeat")]
    Repeated {
        /// Text of the candidate.
        candidate: String,
        /// The repeated term.
        kind: ProcessKind,
    },
    /// GM in one candidate and AR1 in another (or both in one).
    #[error(
        "candidate {gm} uses GM but candidate {ar1} uses AR1; all candidates must use the same \
         one (METHODS §8.5)"
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
        /// [`MAX_NESTED_TERMS`].
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
    /// An engine computation failed (WV of the series, bootstrap of V).
    #[error(transparent)]
    Engine(Box<crate::Error>),
}

impl From<crate::Error> for SelectionError {
    fn from(e: crate::Error) -> Self {
        SelectionError::Engine(Box::new(e))
    }
}
