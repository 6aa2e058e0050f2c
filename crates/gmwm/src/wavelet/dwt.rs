//! Decimated DWT by the pyramid algorithm, periodic boundary (docs/methods.md §1.4).

use crate::error::{InputError, ParamError, SeriesError};

use super::filter::Taps;
use super::{
    check_levels, dwt_boundary, pow2, shape_output, WaveletCoefficients, WaveletFilter,
    WaveletScratch,
};

/// A validated DWT plan: filter and number of levels `J` (docs/methods.md §1.4).
///
/// Plan once, run on every series; the plan is a plain comparable value, `Send + Sync`.
///
/// # Examples
/// Worked example: the test `tests::examples::example_dwt_dwt`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) struct Dwt {
    filter: WaveletFilter,
    levels: usize,
}

impl Dwt {
    /// Plans a `levels`-level DWT with `filter` (docs/methods.md §1.4).
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

    /// Largest `J <= 60` a DWT of `n` samples with `filter` accepts: `2^J` divides `n` and every
    /// level keeps at least one boundary-free coefficient (docs/methods.md §1.4). 0 if none fits.
    #[cfg(test)]
    pub(crate) fn max_levels(filter: WaveletFilter, n: usize) -> usize {
        (1..=super::MAX_LEVELS)
            .take_while(|&j| {
                let p = pow2(j);
                p <= n && n % p == 0 && dwt_boundary(filter.len(), j) < n / p
            })
            .last()
            .unwrap_or(0)
    }

    /// Checks that `n` samples suit this plan (docs/methods.md §1.4).
    ///
    /// # Errors
    /// [`SeriesError::Empty`] for `n = 0`; [`SeriesError::TooShort`] if `2^J > n`;
    /// [`ParamError`] named `levels` if `2^J` does not divide `n` (the message gives the largest
    /// valid `J` and the nearest valid lengths); [`SeriesError::TooShort`] naming the first level
    /// without a boundary-free coefficient.
    pub(crate) fn check_len(&self, n: usize) -> Result<(), InputError> {
        if n == 0 {
            return Err(SeriesError::Empty.into());
        }
        let p = pow2(self.levels);
        if n < p {
            return Err(too_short(n, p, format!("a {}-level DWT", self.levels)).into());
        }
        if n % p != 0 {
            return Err(not_divisible(n, self.levels).into());
        }
        let len = self.filter.len();
        match (1..=self.levels).find(|&j| dwt_boundary(len, j) >= n / pow2(j)) {
            Some(j) => {
                let needed = (dwt_boundary(len, j) + 1).saturating_mul(pow2(j));
                let what = format!(
                    "level {j} of a {} DWT (one boundary-free coefficient)",
                    self.filter
                );
                Err(too_short(n, needed, what).into())
            }
            None => Ok(()),
        }
    }

    /// Runs the DWT of `x` (docs/methods.md §1.4): `w[j-1]` has `N / 2^j` coefficients.
    ///
    /// Non-finite values are not checked here (the caller validates the series once). Cost
    /// `O(N L)` time; memory: the output (`< N` values) plus two length-`N/2` buffers.
    ///
    /// # Errors
    /// As `check_len`.
    pub(crate) fn transform(&self, x: &[f64]) -> Result<WaveletCoefficients, InputError> {
        let mut out = WaveletCoefficients::default();
        self.transform_with_scratch(x, &mut out, &mut WaveletScratch::new())?;
        Ok(out)
    }

    /// Runs the DWT of `x` into `out`, reusing the allocations of `out` and `scratch`
    /// (docs/methods.md §1.4); afterwards `scratch.scaling()` holds `V_J` (`N / 2^J` values).
    ///
    /// # Formula
    /// `V_0 = x`; for `j = 1..J`, `N_{j-1} = N / 2^{j-1}`, `t = 0..N_{j-1}/2 - 1`:
    /// `W_{j,t} = sum_l h_l V_{j-1, (2t + 1 - l) mod N_{j-1}}`, same with `g` for `V_{j,t}`
    /// (unscaled filters).
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
        let taps = Taps::new(self.filter, 1.0);
        shape_output(
            out,
            self.levels,
            |j| n / pow2(j),
            |j| dwt_boundary(taps.len, j),
        );
        scratch.v.clear();
        scratch.v.resize(n / 2, 0.0);
        scratch.next.clear();
        scratch.next.resize(n / 2, 0.0);
        for (j, w) in (1..=self.levels).zip(out.w.iter_mut()) {
            let half = n / pow2(j);
            let src: &[f64] = if j == 1 { x } else { &scratch.v[..2 * half] };
            dwt_level(src, taps.h(), taps.g(), w, &mut scratch.next[..half]);
            std::mem::swap(&mut scratch.v, &mut scratch.next);
        }
        scratch.v.truncate(n / pow2(self.levels));
        Ok(())
    }
}

/// One decimating pyramid step (docs/methods.md §1.4): `w_t = sum_l h_l v_{(2t + 1 - l) mod M}`,
/// same with `g` into `next`, `M = v.len()` even, `t = 0..M/2 - 1`.
///
/// Only the first `floor((L - 1) / 2)` outputs reach back past `v_0`; they alone use modular
/// indexing (possibly wrapping several times when `M < L`).
fn dwt_level(v: &[f64], h: &[f64], g: &[f64], w: &mut [f64], next: &mut [f64]) {
    let m = v.len();
    let half = m / 2;
    debug_assert!(m % 2 == 0 && w.len() == half && next.len() == half);
    let head = ((h.len() - 1) / 2).min(half);
    for t in 0..head {
        let (mut sw, mut sv) = (0.0, 0.0);
        for (l, (&hl, &gl)) in h.iter().zip(g).enumerate() {
            // 2t + 1 + L*M - l > 0 for every l < L; % runs on O(L^2) indices per level only
            let x = v[(2 * t + 1 + h.len() * m - l) % m];
            sw += hl * x;
            sv += gl * x;
        }
        w[t] = sw;
        next[t] = sv;
    }
    for t in head..half {
        let (mut sw, mut sv) = (0.0, 0.0);
        let base = 2 * t + 1;
        for (l, (&hl, &gl)) in h.iter().zip(g).enumerate() {
            let x = v[base - l];
            sw += hl * x;
            sv += gl * x;
        }
        w[t] = sw;
        next[t] = sv;
    }
}

#[cold]
fn too_short(n: usize, needed: usize, what: String) -> SeriesError {
    SeriesError::TooShort { n, needed, what }
}

#[cold]
fn not_divisible(n: usize, levels: usize) -> ParamError {
    let p = pow2(levels);
    let max = n.trailing_zeros();
    let below = n / p * p;
    let above = below.saturating_add(p);
    ParamError::new(
        "levels",
        levels,
        format!(
            "a {levels}-level DWT needs a length divisible by 2^{levels} = {p}, and the series \
             has {n} samples; use at most {max} levels, or {below} or {above} samples"
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dwt_new_accepts_and_rejects_levels() {
        assert!(Dwt::new(WaveletFilter::D4, 1).is_ok());
        assert_eq!(Dwt::new(WaveletFilter::D4, 0).unwrap_err().name, "levels");
        assert!(Dwt::new(WaveletFilter::D4, 61).is_err());
    }

    #[test]
    fn dwt_max_levels_is_the_largest_accepted() {
        for f in WaveletFilter::ALL {
            for n in [1usize, 2, 6, 8, 12, 64, 96, 1000, 4096] {
                let j = Dwt::max_levels(f, n);
                if j > 0 {
                    assert!(Dwt::new(f, j).unwrap().check_len(n).is_ok(), "{f} {n} {j}");
                }
                assert!(
                    Dwt::new(f, j + 1).unwrap().check_len(n).is_err(),
                    "{f} {n} {j}"
                );
            }
        }
        assert_eq!(Dwt::max_levels(WaveletFilter::Haar, 96), 5);
        assert_eq!(Dwt::max_levels(WaveletFilter::Haar, 1000), 3);
    }

    #[test]
    fn dwt_not_divisible_names_the_fix() {
        let e = Dwt::new(WaveletFilter::Haar, 3)
            .unwrap()
            .check_len(12)
            .unwrap_err()
            .to_string();
        assert!(e.contains("divisible by 2^3 = 8"), "{e}");
        assert!(
            e.contains("at most 2 levels") && e.contains("8 or 16 samples"),
            "{e}"
        );
    }
}
