//! Maximal-overlap DWT by the pyramid algorithm, periodic boundary (docs/methods.md §1.2, §1.3).

use crate::error::{InputError, ParamError, SeriesError};

use super::filter::Taps;
use super::{
    check_levels, modwt_boundary, pow2, shape_output, WaveletCoefficients, WaveletFilter,
    WaveletScratch,
};

/// A validated MODWT plan: filter and number of levels `J` (docs/methods.md §1.2).
///
/// Plan once, run on every series; the plan is a plain comparable value, `Send + Sync`.
///
/// # Examples
/// Worked example: the test `tests::examples::example_modwt_modwt`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) struct Modwt {
    filter: WaveletFilter,
    levels: usize,
}

impl Modwt {
    /// Plans a `levels`-level MODWT with `filter` (docs/methods.md §1.2).
    ///
    /// # Errors
    /// [`ParamError`] named `levels` unless `1 <= levels <= 60`.
    pub(crate) fn new(filter: WaveletFilter, levels: usize) -> Result<Self, ParamError> {
        check_levels(levels)?;
        Ok(Self { filter, levels })
    }

    /// The filter.
    #[cfg(test)]
    pub(crate) fn filter(&self) -> WaveletFilter {
        self.filter
    }

    /// The number of levels `J`.
    #[cfg(test)]
    pub(crate) fn levels(&self) -> usize {
        self.levels
    }

    /// Largest `J <= 60` a MODWT of `n` samples with `filter` accepts: `2^J <= n` and at least
    /// one boundary-free coefficient at every level, `n >= L_J = (2^J - 1)(L - 1) + 1`
    /// (docs/methods.md §1.2, §1.3). 0 if not even one level fits.
    #[cfg(test)]
    pub(crate) fn max_levels(filter: WaveletFilter, n: usize) -> usize {
        (1..=super::MAX_LEVELS)
            .take_while(|&j| pow2(j) <= n && modwt_boundary(filter.len(), j) < n)
            .last()
            .unwrap_or(0)
    }

    /// Checks that `n` samples suffice (docs/methods.md §1.2, §1.3).
    ///
    /// # Errors
    /// [`SeriesError::Empty`] for `n = 0`; [`SeriesError::TooShort`] if `2^J > n`, or naming the
    /// first level `j` without a boundary-free coefficient (`n < L_j`).
    pub(crate) fn check_len(&self, n: usize) -> Result<(), SeriesError> {
        if n == 0 {
            return Err(SeriesError::Empty);
        }
        let needed = pow2(self.levels);
        if n < needed {
            return Err(too_short_levels(n, needed, self.levels));
        }
        let len = self.filter.len();
        match (1..=self.levels).find(|&j| modwt_boundary(len, j) >= n) {
            Some(j) => Err(too_short_level(n, self.filter, j)),
            None => Ok(()),
        }
    }

    /// Runs the MODWT of `x` (docs/methods.md §1.2); boundary counts `n_j` of §1.3.
    ///
    /// Non-finite values are not checked here (the caller validates the series once). Cost
    /// `O(N J L)` time; memory: the output (`J N` values) plus two length-N buffers.
    ///
    /// # Errors
    /// As `check_len`.
    pub(crate) fn transform(&self, x: &[f64]) -> Result<WaveletCoefficients, InputError> {
        let mut out = WaveletCoefficients::default();
        self.transform_with_scratch(x, &mut out, &mut WaveletScratch::new())?;
        Ok(out)
    }

    /// Runs the MODWT of `x` into `out`, reusing the allocations of `out` and `scratch`
    /// (docs/methods.md §1.2); afterwards `scratch.scaling()` holds `V_J`.
    ///
    /// # Formula
    /// `V_0 = x`; for `j = 1..J`, `t = 0..N-1`, indices modulo N:
    /// `W_{j,t} = sum_l h~_l V_{j-1, t - 2^{j-1} l}`, `V_{j,t} = sum_l g~_l V_{j-1, t - 2^{j-1} l}`
    /// with `h~ = h / sqrt2`, `g~ = g / sqrt2`.
    ///
    /// # Errors
    /// As [`check_len`](Self::check_len); `out` and `scratch` are then left unspecified.
    pub(crate) fn transform_with_scratch(
        &self,
        x: &[f64],
        out: &mut WaveletCoefficients,
        scratch: &mut WaveletScratch,
    ) -> Result<(), InputError> {
        self.check_len(x.len())?;
        let n = x.len();
        let len = self.filter.len();
        let taps = Taps::new(self.filter, std::f64::consts::FRAC_1_SQRT_2);
        shape_output(out, self.levels, |_| n, |j| modwt_boundary(len, j));
        scratch.v.clear();
        scratch.v.resize(n, 0.0);
        scratch.next.clear();
        scratch.next.resize(n, 0.0);
        for (j, w) in (1..=self.levels).zip(out.w.iter_mut()) {
            let src: &[f64] = if j == 1 { x } else { &scratch.v };
            modwt_level(src, pow2(j - 1), taps.h(), taps.g(), w, &mut scratch.next);
            std::mem::swap(&mut scratch.v, &mut scratch.next);
        }
        Ok(())
    }
}

/// One pyramid step (docs/methods.md §1.2): `w_t = sum_l h_l v_{t - step l}`, same with `g` into
/// `next`, indices modulo `N = v.len()`.
///
/// Accumulates filter tap by tap; each tap splits `t` into the wrap-around head `t < step l`
/// (reading `v_{t + N - step l}`) and the plain tail (reading `v_{t - step l}`), so no `%` runs.
/// Requires `step (L - 1) < N`, which [`Modwt::check_len`] guarantees for every level.
fn modwt_level(v: &[f64], step: usize, h: &[f64], g: &[f64], w: &mut [f64], next: &mut [f64]) {
    let n = v.len();
    debug_assert!(step * (h.len() - 1) < n && w.len() == n && next.len() == n);
    for ((wt, vt), &x) in w.iter_mut().zip(next.iter_mut()).zip(v) {
        *wt = h[0] * x;
        *vt = g[0] * x;
    }
    for (l, (&hl, &gl)) in h.iter().zip(g).enumerate().skip(1) {
        let off = step * l;
        let (w_head, w_tail) = w.split_at_mut(off);
        let (n_head, n_tail) = next.split_at_mut(off);
        let (v_early, v_late) = v.split_at(n - off);
        for ((wt, vt), &x) in w_tail.iter_mut().zip(n_tail.iter_mut()).zip(v_early) {
            *wt += hl * x;
            *vt += gl * x;
        }
        for ((wt, vt), &x) in w_head.iter_mut().zip(n_head.iter_mut()).zip(v_late) {
            *wt += hl * x;
            *vt += gl * x;
        }
    }
}

#[cold]
fn too_short_levels(n: usize, needed: usize, levels: usize) -> SeriesError {
    SeriesError::TooShort {
        n,
        needed,
        what: format!("a {levels}-level MODWT"),
    }
}

#[cold]
fn too_short_level(n: usize, filter: WaveletFilter, j: usize) -> SeriesError {
    SeriesError::TooShort {
        n,
        needed: modwt_boundary(filter.len(), j).saturating_add(1),
        what: format!("level {j} of a {filter} MODWT (one boundary-free coefficient)"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modwt_new_accepts_and_rejects_levels() {
        assert!(Modwt::new(WaveletFilter::Haar, 1).is_ok());
        assert!(Modwt::new(WaveletFilter::La8, 60).is_ok());
        let e = Modwt::new(WaveletFilter::Haar, 0).unwrap_err();
        assert_eq!(e.name, "levels");
        assert!(Modwt::new(WaveletFilter::Haar, 61).is_err());
    }

    #[test]
    fn modwt_max_levels_is_the_largest_accepted() {
        for f in WaveletFilter::ALL {
            for n in [1usize, 2, 3, 7, 8, 9, 63, 64, 100, 1000, 4096] {
                let j = Modwt::max_levels(f, n);
                if j > 0 {
                    assert!(
                        Modwt::new(f, j).unwrap().check_len(n).is_ok(),
                        "{f} {n} {j}"
                    );
                }
                assert!(
                    Modwt::new(f, j + 1).unwrap().check_len(n).is_err(),
                    "{f} {n} {j}"
                );
            }
        }
        assert_eq!(Modwt::max_levels(WaveletFilter::Haar, 8), 3);
        assert_eq!(Modwt::max_levels(WaveletFilter::Haar, 7), 2);
        // la8: L_2 = 22, L_3 = 50
        assert_eq!(Modwt::max_levels(WaveletFilter::La8, 49), 2);
        assert_eq!(Modwt::max_levels(WaveletFilter::La8, 50), 3);
    }

    #[test]
    fn modwt_level_matches_modular_indexing() {
        let v: Vec<f64> = (0..11).map(|i| ((i * 7 + 3) % 11) as f64 - 4.5).collect();
        let h = [0.3, -0.2, 0.5, 0.1];
        let g = [0.1, 0.4, -0.3, 0.2];
        for step in 1..=3 {
            let mut w = vec![f64::NAN; 11];
            let mut next = vec![f64::NAN; 11];
            modwt_level(&v, step, &h, &g, &mut w, &mut next);
            for t in 0..11 {
                let idx = |l: usize| (t as isize - (step * l) as isize).rem_euclid(11) as usize;
                let ew: f64 = (0..4).map(|l| h[l] * v[idx(l)]).sum();
                let eg: f64 = (0..4).map(|l| g[l] * v[idx(l)]).sum();
                assert!((w[t] - ew).abs() < 1e-14 && (next[t] - eg).abs() < 1e-14);
            }
        }
    }
}
