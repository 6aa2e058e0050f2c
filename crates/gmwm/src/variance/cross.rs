//! Haar MODWT wavelet cross-covariance of two series and the exact covariance of the stacked
//! wavelet moments of several series sharing a latent process (docs/methods.md §15).
//!
//! # Estimator (docs/methods.md §15.1)
//! For two series `x`, `y` of the same length `N` with Haar MODWT coefficients `W^x_{j,t}`,
//! `W^y_{j,t}` (docs/methods.md §1.2), the wavelet cross-covariance at level `j` is the mean of
//! the products over the `M_j` boundary-free coefficients (§1.3), no mean removed (as §1.5):
//!
//! `c_hat_j = (1 / M_j) sum_{kept t} W^x_{j,t} W^y_{j,t}`.
//!
//! The MODWT is linear, so `W^{x+y} = W^x + W^y` and `W^{x-y} = W^x - W^y` coefficient by
//! coefficient, and the polarisation identity `ab = ((a + b)^2 - (a - b)^2) / 4` gives
//!
//! `c_hat_j = (nu2_hat_j(x + y) - nu2_hat_j(x - y)) / 4`
//!
//! exactly (up to rounding): the cross-covariance is computed by the one Haar WV kernel of
//! [`crate::wavelet_variance`], with its blocking, compensated sums and thread-count
//! independence, and no second transform.
//!
//! # Covariance of the stacked moments (docs/methods.md §15.3)
//! Axes `i = 1..P` observe `x_i = V + U_i`, with `V` (the shared process) and the `U_i`
//! independent, zero-mean and Gaussian. The moments are `m_ab(j) = (1/M_j) sum_t W_{a,j,t}
//! W_{b,j,t}` (`a = b`: the WV of axis `a`; `a < b`: a cross-covariance). For jointly Gaussian
//! zero-mean coefficients Isserlis' theorem gives
//! `Cov(W_a W_b, W_c W_d) = g_ac g_bd + g_ad g_bc`, with `g_ac(h) = Cov(W_{a,j,t}, W_{c,k,t+h})`,
//! so, summing over the kept pairs (`n_jk(h)` of them at lag `h`),
//!
//! `Cov(m_ab(j), m_cd(k)) = T_jk(g_ac, g_bd) + T_jk(g_ad, g_bc)`,
//! `T_jk(g, g') = (1 / (M_j M_k)) sum_h n_jk(h) g(h) g'(h)`
//!
//! (Whitcher, Guttorp & Percival 2000 give the large-sample form
//! `(1/M_j) sum_h [s_aa(h) s_bb(h) + s_ab(h) s_ba(h)]` for `j = k`). With the components
//! independent, `g_ac = g_V + [a = c] g_{U_a}`, and `T` is bilinear, so every entry is a sum of
//! `T(P, Q)` over the components `P, Q` in `{V, U_1, .., U_P}`. The exact WV covariance of a
//! model (`crate::variance::implied_cov`) is `C(P) = 2 T(g_P, g_P)` (its Gaussian part), and
//! `g` of a union of independent processes is the sum of theirs, hence
//!
//! `T(P, P) = C(P) / 2`,  `T(P, Q) = (C(P u Q) - C(P) - C(Q)) / 4`:
//!
//! the whole `(P + P(P-1)/2) J` square matrix follows from `C` of the `P + 1` components and of
//! their `P (P + 1) / 2` pairwise unions, each exact in `O(J^2)` work. Check: `Cov(m_aa, m_aa)
//! = 2 T(g_aa, g_aa) = C(V u U_a)`, the exact covariance of axis `a`'s WV. A drift (a mean, not a
//! covariance) is refused; quantisation noise is exact when it sits in one component of each
//! pair (its fourth-cumulant term cancels in the differences), as in every model the
//! shared-process fit accepts with QN in one place only.

use crate::error::{InputError, ParamError};
use crate::process::{LatentProcess, Process};
use crate::variance::implied_cov::exact_covariance_of;
use crate::variance::wv::{wavelet_variance, WvOptions};
use nalgebra::DMatrix;

/// The Haar MODWT wavelet cross-covariance of `x` and `y` at levels `1..=levels` (module docs,
/// docs/methods.md §15.1): `(nu2_hat(x + y) - nu2_hat(x - y)) / 4`.
///
/// Worked example: the test `tests::examples::example_cross_wavelet_cross_covariance`.
///
/// # Errors
/// [`ParamError`] named `y` when the lengths differ; as [`wavelet_variance`] (non-finite
/// samples, a series too short for `levels`).
pub(crate) fn wavelet_cross_covariance(
    x: &[f64],
    y: &[f64],
    levels: usize,
) -> Result<Vec<f64>, InputError> {
    if x.len() != y.len() {
        return Err(
            ParamError::new("y", y.len(), format!("as many samples as x ({})", x.len())).into(),
        );
    }
    let opts = WvOptions {
        levels: Some(levels),
        ..WvOptions::default()
    };
    // x + y or x - y is constant (y = -x, y = x): its coefficients, hence its WV, are exactly
    // zero, where the WV estimator refuses a constant series
    let wv_of = |z: Vec<f64>| -> Result<Vec<f64>, InputError> {
        if z.iter().all(|&v| v == z[0]) && !z.is_empty() {
            let other = wavelet_variance(x, 1.0, &opts)?;
            return Ok(vec![0.0; other.wv().len()]);
        }
        Ok(wavelet_variance(&z, 1.0, &opts)?.wv().to_vec())
    };
    let plus = wv_of(x.iter().zip(y).map(|(a, b)| a + b).collect())?;
    let minus = wv_of(x.iter().zip(y).map(|(a, b)| a - b).collect())?;
    Ok(plus
        .iter()
        .zip(&minus)
        .map(|(p, m)| (p - m) / 4.0)
        .collect())
}

/// The pairs `(a, b)`, `a < b`, of `axes` axes in the order of the stacked moments.
pub(crate) fn axis_pairs(axes: usize) -> Vec<(usize, usize)> {
    (0..axes)
        .flat_map(|a| (a + 1..axes).map(move |b| (a, b)))
        .collect()
}

/// The exact covariance of the stacked moments (module docs, docs/methods.md §15.3) of `n`-sample
/// series `x_i = V + U_i`, `i = 1..P`, at levels `1..=levels`: `shared` the processes of `V`
/// (empty for no shared process), `specific[i]` those of `U_i`. Rows and columns: the `P` WVs
/// (`levels` each, axis order), then the cross-covariances of [`axis_pairs`].
///
/// # Errors
/// [`ParamError`] for a drift or a process the exact WV covariance does not cover (generic
/// ARMA, a negative autoregressive coefficient), or more levels than `n` holds.
pub(crate) fn stacked_moment_covariance(
    shared: &[Process],
    specific: &[Vec<Process>],
    n: usize,
    levels: usize,
) -> Result<DMatrix<f64>, ParamError> {
    let p = specific.len();
    let comps: Vec<&[Process]> = std::iter::once(shared)
        .chain(specific.iter().map(Vec::as_slice))
        .collect();
    if comps
        .iter()
        .any(|c| c.iter().any(|q| q.spectral_density(0.0).is_none()))
    {
        return Err(ParamError::new(
            "model",
            "DR",
            "no drift in a shared-process model (a drift is a mean, not a covariance)",
        ));
    }
    let k = comps.len();
    // C of each component and of each pairwise union
    let c_of = |procs: &[Process]| -> Result<DMatrix<f64>, ParamError> {
        if procs.is_empty() {
            Ok(DMatrix::zeros(levels, levels))
        } else {
            exact_covariance_of(procs, n, levels)
        }
    };
    let singles: Vec<DMatrix<f64>> = comps.iter().map(|c| c_of(c)).collect::<Result<_, _>>()?;
    let mut t = vec![DMatrix::zeros(levels, levels); k * k];
    for u in 0..k {
        t[u * k + u] = &singles[u] / 2.0;
        for v in u + 1..k {
            let both: Vec<Process> = comps[u].iter().chain(comps[v]).cloned().collect();
            let tuv = (c_of(&both)? - &singles[u] - &singles[v]) / 4.0;
            t[v * k + u] = tuv.clone();
            t[u * k + v] = tuv;
        }
    }
    // g_ac as coefficients over the components {V, U_1..U_P}
    let g = |a: usize, c: usize| -> Vec<f64> {
        let mut e = vec![0.0; k];
        e[0] = 1.0;
        if a == c {
            e[a + 1] += 1.0;
        }
        e
    };
    let bil = |x: &[f64], y: &[f64]| -> DMatrix<f64> {
        let mut out = DMatrix::zeros(levels, levels);
        for (u, &xu) in x.iter().enumerate() {
            for (v, &yv) in y.iter().enumerate() {
                if xu != 0.0 && yv != 0.0 {
                    out += &t[u * k + v] * (xu * yv);
                }
            }
        }
        out
    };
    let moments: Vec<(usize, usize)> = (0..p).map(|a| (a, a)).chain(axis_pairs(p)).collect();
    let m = moments.len();
    let mut out = DMatrix::zeros(m * levels, m * levels);
    for (r, &(a, b)) in moments.iter().enumerate() {
        for (s, &(c, d)) in moments.iter().enumerate().skip(r) {
            let block = bil(&g(a, c), &g(b, d)) + bil(&g(a, d), &g(b, c));
            out.view_mut((r * levels, s * levels), (levels, levels))
                .copy_from(&block);
            if s != r {
                out.view_mut((s * levels, r * levels), (levels, levels))
                    .copy_from(&block.transpose());
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Model;

    fn procs(text: &str) -> Vec<Process> {
        Model::parse(text).unwrap().processes(1.0).unwrap()
    }

    #[test]
    fn wv_blocks_are_the_exact_wv_covariance_of_each_axis() {
        let shared = procs("AR1(phi=0.9, sigma2=0.5)");
        let spec = vec![procs("WN(sigma2=1)"), procs("WN(sigma2=2)+RW(gamma2=1e-4)")];
        let (n, j) = (4096, 6);
        let m = stacked_moment_covariance(&shared, &spec, n, j).unwrap();
        for (a, s) in spec.iter().enumerate() {
            let all: Vec<Process> = shared.iter().chain(s).cloned().collect();
            let c = exact_covariance_of(&all, n, j).unwrap();
            let block = m.view((a * j, a * j), (j, j));
            assert!((block - &c).abs().max() <= 1e-12 * c.abs().max());
        }
        // the cross-covariance of independent white noises: Var c_j = nu_1 nu_2 sum rho^2 / M
        let two = vec![spec[0].clone(), spec[0].clone()];
        let m0 = stacked_moment_covariance(&[], &two, n, 1).unwrap();
        // level 1 of WN(1): coefficients (x_t - x_{t-1}) / 2, rho(1) = -1/2; nu = 1/2
        let mm = (n - 1) as f64;
        let want = 0.25 * (mm + 2.0 * (mm - 1.0) * 0.25) / (mm * mm);
        assert!(
            (m0[(2, 2)] - want).abs() < 1e-12 * want,
            "{} {want}",
            m0[(2, 2)]
        );
    }
}
