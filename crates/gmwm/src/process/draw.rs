//! What every process's starting-value draw of docs/methods.md §6.3 shares (paper Appendix C):
//! the summary of the WV ([`DrawContext`]) and the state of one draw ([`Draw`]), the random
//! stream and the correlated components drawn so far. Each process draws its own parameters
//! ([`Spec::draw`](super::Spec)); `crate::fit::start` runs the search.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// Which process dominates the first scales (docs/methods.md §6.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub(crate) enum Dominance {
    /// Quantisation noise (slope below -1/2 for both CI bounds).
    Qn,
    /// White noise (the CI straddles slope -1/2).
    Wn,
    /// A slow AR1 (slope above -1/2 for both CI bounds).
    Ar1,
}

/// The summary of the WV the draws need (docs/methods.md §6.1–§6.2).
#[derive(Debug, Clone)]
pub(crate) struct DrawContext {
    /// The empirical WV at levels `1..=J` (for a draw that reads its shape, such as SIN's
    /// hump).
    pub(crate) wv: Vec<f64>,
    /// `sigma2_T`, the sum of the empirical WV.
    pub(crate) sigma2_t: f64,
    /// Series length N.
    pub(crate) n: f64,
    /// `R = (max x - min x) / N`.
    pub(crate) range: f64,
    /// Sampling rate, Hz.
    pub(crate) freq_hz: f64,
    /// What dominates the first scales.
    pub(crate) dom: Dominance,
    /// The model's only term (besides the ARMA family) is white noise.
    pub(crate) only_wn: bool,
    /// The model's only term (besides the ARMA family) is quantisation noise.
    pub(crate) only_qn: bool,
    /// The smallest empirical WV over the levels (the floor a flicker term cannot exceed).
    pub(crate) wv_min: f64,
}

/// One draw in progress, component by component in model order.
pub(crate) struct Draw<'a> {
    /// The WV's summary.
    pub(crate) ctx: &'a DrawContext,
    /// The draw's own stream.
    pub(crate) rng: &'a mut ChaCha8Rng,
    /// The §6.3 condition of the next correlated component: the count of correlated
    /// components drawn so far, plus one when white noise dominates the first scales.
    pub(crate) condition: u32,
    /// The `phi` of the last correlated component drawn.
    pub(crate) last_phi: f64,
}

impl Draw<'_> {
    /// `U(lo, hi)` from the draw's stream ([`unif`]).
    pub(crate) fn unif(&mut self, lo: f64, hi: f64) -> f64 {
        unif(self.rng, lo, hi)
    }
}

/// `U(lo, hi)`; `lo` when the interval is empty or degenerate.
pub(crate) fn unif(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    if hi > lo {
        rng.random_range(lo..hi)
    } else {
        lo
    }
}
