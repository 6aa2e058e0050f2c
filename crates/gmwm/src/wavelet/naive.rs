//! Test oracle: slow, obviously correct MODWT and DWT by direct circular convolution with the
//! level-j equivalent filters (docs/methods.md §1.2, §1.4).
//!
//! Public so the integration tests can drive it; not meant for production use (cost
//! `O(N L_j)` per level instead of `O(N L)`). No validation: the only requirement is a non-empty
//! series (and, for the DWT, a length divisible by `2^J`).

use std::f64::consts::FRAC_1_SQRT_2;

use super::{quadrature_mirror, WaveletFilter};

/// Level-j equivalent filters (docs/methods.md §1.2, §1.3): a single convolution of the series with
/// these gives `W_j` and `V_j` directly.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct EquivalentFilters {
    /// Equivalent wavelet filter, width `L_j = (2^j - 1)(L - 1) + 1`.
    pub(crate) wavelet: Vec<f64>,
    /// Equivalent scaling filter, width `L_j`.
    pub(crate) scaling: Vec<f64>,
}

/// Output of the oracle transforms: every wavelet coefficient of every level and the final
/// scaling coefficients `V_J` (docs/methods.md §1.2, §1.4).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct NaiveTransform {
    /// `w[j-1]` = level-j wavelet coefficients (no boundary removal).
    pub(crate) w: Vec<Vec<f64>>,
    /// Scaling coefficients `V_J`.
    pub(crate) scaling: Vec<f64>,
}

/// `c_m = sum_l f_l prev_{m - step l}`: `prev` convolved with `f` upsampled by `step`.
fn upsampled_convolution(f: &[f64], step: usize, prev: &[f64]) -> Vec<f64> {
    let mut c = vec![0.0; (f.len() - 1) * step + prev.len()];
    for (l, &fl) in f.iter().enumerate() {
        for (k, &p) in prev.iter().enumerate() {
            c[step * l + k] += fl * p;
        }
    }
    c
}

/// Level-`j` equivalent filters built from the taps `h`, `g` (docs/methods.md §1.2): `g_1 = g`,
/// `g_k = (g upsampled by 2^{k-1}) * g_{k-1}`, `h_j = (h upsampled by 2^{j-1}) * g_{j-1}`.
///
/// Pass `h~`, `g~` for the MODWT and the unscaled `h`, `g` for the DWT.
pub(crate) fn equivalent_filters(h: &[f64], g: &[f64], j: usize) -> EquivalentFilters {
    let mut scaling = vec![1.0];
    let mut wavelet = vec![1.0];
    for k in 1..=j {
        let step = 1usize << (k - 1);
        wavelet = upsampled_convolution(h, step, &scaling);
        scaling = upsampled_convolution(g, step, &scaling);
    }
    EquivalentFilters { wavelet, scaling }
}

/// MODWT level-`j` equivalent filters `h~_j`, `g~_j` of `filter` (docs/methods.md §1.2).
pub(crate) fn modwt_equivalent_filters(filter: WaveletFilter, j: usize) -> EquivalentFilters {
    let g: Vec<f64> = filter.scaling().iter().map(|c| c * FRAC_1_SQRT_2).collect();
    let h = quadrature_mirror(&g);
    equivalent_filters(&h, &g, j)
}

/// `y_t = sum_l f_l x_{(end(t) - l) mod N}` for `t = 0..count`, by direct summation.
fn circular_filter(f: &[f64], x: &[f64], count: usize, end: impl Fn(usize) -> usize) -> Vec<f64> {
    let n = x.len() as isize;
    (0..count)
        .map(|t| {
            let e = end(t) as isize;
            f.iter()
                .enumerate()
                .map(|(l, &fl)| fl * x[(e - l as isize).rem_euclid(n) as usize])
                .sum()
        })
        .collect()
}

/// Oracle MODWT (docs/methods.md §1.2): `W_{j,t} = sum_l h~_{j,l} x_{(t - l) mod N}`, and `V_J`
/// with `g~_J`, for `j = 1..levels`.
///
/// # Panics
/// If `x` is empty.
pub(crate) fn modwt(filter: WaveletFilter, levels: usize, x: &[f64]) -> NaiveTransform {
    assert!(!x.is_empty(), "the oracle needs a non-empty series");
    let n = x.len();
    let w = (1..=levels)
        .map(|j| circular_filter(&modwt_equivalent_filters(filter, j).wavelet, x, n, |t| t))
        .collect();
    let scaling = circular_filter(
        &modwt_equivalent_filters(filter, levels).scaling,
        x,
        n,
        |t| t,
    );
    NaiveTransform { w, scaling }
}

/// Oracle DWT (docs/methods.md §1.4) by decimated equivalent filters:
/// `W_{j,t} = sum_l h_{j,l} x_{(2^j (t + 1) - 1 - l) mod N}`, `t = 0..N/2^j - 1`, with the
/// unscaled `h_j = 2^{j/2} h~_j`; likewise `V_J`.
///
/// # Panics
/// If `x` is empty or `2^levels` does not divide its length.
pub(crate) fn dwt(filter: WaveletFilter, levels: usize, x: &[f64]) -> NaiveTransform {
    let n = x.len();
    assert!(
        n > 0 && n % (1usize << levels) == 0,
        "N must be a multiple of 2^J"
    );
    let g = filter.scaling();
    let h = filter.wavelet();
    let at = |j: usize| move |t: usize| (t + 1) * (1usize << j) - 1;
    let w = (1..=levels)
        .map(|j| {
            let f = equivalent_filters(&h, g, j).wavelet;
            circular_filter(&f, x, n >> j, at(j))
        })
        .collect();
    let f = equivalent_filters(&h, g, levels).scaling;
    let scaling = circular_filter(&f, x, n >> levels, at(levels));
    NaiveTransform { w, scaling }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// docs/methods.md §1.1: Haar MODWT filters (1/2, -1/2), (1/2, 1/2); level 2 has width 4.
    #[test]
    fn naive_equivalent_filters_haar_by_hand() {
        let e1 = modwt_equivalent_filters(WaveletFilter::Haar, 1);
        assert!(close(&e1.wavelet, &[0.5, -0.5]) && close(&e1.scaling, &[0.5, 0.5]));
        let e2 = modwt_equivalent_filters(WaveletFilter::Haar, 2);
        assert!(close(&e2.wavelet, &[0.25, 0.25, -0.25, -0.25]));
        assert!(close(&e2.scaling, &[0.25; 4]));
        let la8 = modwt_equivalent_filters(WaveletFilter::La8, 3);
        assert_eq!(la8.wavelet.len(), 7 * 7 + 1); // L_3 = (2^3 - 1)(8 - 1) + 1
    }

    /// docs/methods.md §1.10 by hand: x = 1..8, Haar, periodic; W_{1,0} wraps (x_0 - x_7)/2 = -3.5.
    #[test]
    fn naive_modwt_haar_ramp_by_hand() {
        let x: Vec<f64> = (1..=8).map(f64::from).collect();
        let r = modwt(WaveletFilter::Haar, 2, &x);
        assert!(close(&r.w[0], &[-3.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5]));
        // W_{2,t} = (x_t + x_{t-1} - x_{t-2} - x_{t-3}) / 4
        assert!(close(&r.w[1], &[-1.0, -3.0, -1.0, 1.0, 1.0, 1.0, 1.0, 1.0]));
        // V_2 = moving mean of 4
        assert!(close(&r.scaling, &[5.5, 4.5, 3.5, 2.5, 3.5, 4.5, 5.5, 6.5]));
    }

    /// docs/methods.md §1.4 by hand: Haar W_{1,t} = (x_{2t+1} - x_{2t}) / sqrt2.
    #[test]
    fn naive_dwt_haar_by_hand() {
        let x = [1.0, 3.0, 2.0, 5.0, 4.0, 6.0, 8.0, 7.0];
        let r = dwt(WaveletFilter::Haar, 2, &x);
        let s = FRAC_1_SQRT_2;
        assert!(close(&r.w[0], &[2.0 * s, 3.0 * s, 2.0 * s, -s]));
        // W_{2,t} = (x_{4t+3} + x_{4t+2} - x_{4t+1} - x_{4t}) / 2
        assert!(close(&r.w[1], &[1.5, 2.5]));
        assert!(close(&r.scaling, &[5.5, 12.5]));
    }

    fn close(a: &[f64], b: &[f64]) -> bool {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-14)
    }
}
