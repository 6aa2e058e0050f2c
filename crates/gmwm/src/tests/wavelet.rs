//! Wavelet transforms (docs/methods.md §1.1–§1.4, §1.10): fast pyramids against the
//! direct-convolution oracle for every filter, the test values of docs/methods.md, closed forms,
//! identities and bad input.

use gmwm::wavelet::{Dwt, Modwt, WaveletCoefficients, WaveletFilter, WaveletScratch};
use gmwm::{InputError, SeriesError};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// Fixed seed of every random input (STYLE §6).
const RNG_SEED: u64 = 0x5eed_1a8e;

/// Pyramid versus direct convolution: the two sum the same products in different orders, so
/// they differ by a few ulps of the largest partial sum (at most `L_j ~ 1500` terms of unit
/// size here), far below 1e-12.
const REL_TOL: f64 = 1e-12;

/// A seeded test series: white noise plus a slow random walk (so levels differ in size).
fn series(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(RNG_SEED ^ seed);
    let mut walk = 0.0;
    (0..n)
        .map(|_| {
            let e: f64 = rng.sample(StandardNormal);
            walk += 0.05 * rng.sample::<f64, _>(StandardNormal);
            e + walk + 3.0
        })
        .collect()
}

/// Largest absolute value: the absolute floor of a relative comparison.
fn scale(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m, v| m.max(v.abs()))
}

/// `|a - b| <= REL_TOL max(|b|, floor)` element by element.
fn assert_close(a: &[f64], b: &[f64], floor: f64, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: lengths");
    for (t, (x, y)) in a.iter().zip(b).enumerate() {
        let tol = REL_TOL * y.abs().max(floor);
        assert!((x - y).abs() <= tol, "{what}, t = {t}: {x} vs oracle {y}");
    }
}

fn sum_sq(x: &[f64]) -> f64 {
    x.iter().map(|v| v * v).sum()
}

/// Periodic MODWT and DWT preserve energy (docs/methods.md §1.2, §1.4):
/// `sum_j ||W_j||^2 + ||V_J||^2 = ||x||^2`, to the precision of the filter's table.
#[test]
fn wavelet_transforms_preserve_energy() {
    let x = series(1024, 7);
    let energy = sum_sq(&x);
    for filter in WaveletFilter::ALL {
        // each level multiplies energy by 1 + O(L tol) through the table's inexact orthonormality
        let tol = 1e-12 + 4.0 * (filter.len() as f64) * filter.orthonormality_tolerance();
        let mut out = WaveletCoefficients::default();
        let mut scratch = WaveletScratch::new();
        let levels = Modwt::max_levels(filter, x.len()).min(8);
        Modwt::new(filter, levels)
            .unwrap()
            .transform_with_scratch(&x, &mut out, &mut scratch)
            .unwrap();
        let total: f64 = out.w.iter().map(|w| sum_sq(w)).sum::<f64>() + sum_sq(scratch.scaling());
        let r = (total - energy).abs() / energy;
        assert!(
            r <= levels as f64 * tol,
            "MODWT {filter}: relative energy error {r}"
        );
        let levels = Dwt::max_levels(filter, x.len());
        Dwt::new(filter, levels)
            .unwrap()
            .transform_with_scratch(&x, &mut out, &mut scratch)
            .unwrap();
        assert_eq!(scratch.scaling().len(), x.len() >> levels);
        let total: f64 = out.w.iter().map(|w| sum_sq(w)).sum::<f64>() + sum_sq(scratch.scaling());
        let r = (total - energy).abs() / energy;
        assert!(
            r <= levels as f64 * tol,
            "DWT {filter}: relative energy error {r}"
        );
    }
}

/// docs/methods.md §1.10 test values: x = 1..8, Haar, J = 3. Level 3 keeps its single boundary-free
/// coefficient W_{3,7} = (mean(5..8) - mean(1..4)) / 2 = 2 (the package keeps none, §1.3/§13.1).
#[test]
fn modwt_haar_ramp_methods_1_10() {
    let x: Vec<f64> = (1..=8).map(f64::from).collect();
    let w = Modwt::new(WaveletFilter::Haar, 3)
        .unwrap()
        .transform(&x)
        .unwrap();
    assert_eq!(w.boundary, vec![1, 3, 7]);
    assert_close(w.kept(1), &[0.5; 7], 1.0, "level 1");
    assert_close(w.kept(2), &[1.0; 5], 1.0, "level 2");
    assert_close(w.kept(3), &[2.0], 1.0, "level 3");
    let wv: Vec<f64> = (1..=2)
        .map(|j| sum_sq(w.kept(j)) / w.kept(j).len() as f64)
        .collect();
    assert_close(&wv, &[0.25, 1.0], 1.0, "WV (docs/methods.md §1.10)");
}

/// docs/methods.md §1.10 test values: x = (1,3,2,5,4,6,8,7), Haar, J = 2.
#[test]
fn modwt_haar_second_series_methods_1_10() {
    let x = [1.0, 3.0, 2.0, 5.0, 4.0, 6.0, 8.0, 7.0];
    let w = Modwt::new(WaveletFilter::Haar, 2)
        .unwrap()
        .transform(&x)
        .unwrap();
    assert_close(
        w.kept(1),
        &[1.0, -0.5, 1.5, -0.5, 1.0, 1.0, -0.5],
        1.0,
        "level 1",
    );
    assert_close(w.kept(2), &[0.75, 1.0, 0.75, 1.25, 1.25], 1.0, "level 2");
    assert!((sum_sq(w.kept(1)) / 7.0 - 6.0 / 7.0).abs() < 1e-15);
    assert!((sum_sq(w.kept(2)) / 5.0 - 1.05).abs() < 1e-15);
}

/// docs/methods.md §1.2 Haar closed form, m = 2^{j-1}, periodic indices:
/// `W_{j,t} = (1/2) [mean(x_{t-m+1..t}) - mean(x_{t-2m+1..t-m})]`.
#[test]
fn modwt_haar_closed_form() {
    let x = series(100, 11);
    let n = x.len() as isize;
    let w = Modwt::new(WaveletFilter::Haar, 6)
        .unwrap()
        .transform(&x)
        .unwrap();
    let at = |i: isize| x[i.rem_euclid(n) as usize];
    for j in 1..=6usize {
        let m = 1isize << (j - 1);
        let expected: Vec<f64> = (0..n)
            .map(|t| {
                let newer: f64 = (t - m + 1..=t).map(at).sum::<f64>() / m as f64;
                let older: f64 = (t - 2 * m + 1..=t - m).map(at).sum::<f64>() / m as f64;
                0.5 * (newer - older)
            })
            .collect();
        assert_close(&w.w[j - 1], &expected, scale(&x), &format!("level {j}"));
        assert_eq!(w.kept(j).len(), x.len() + 1 - (1 << j)); // M_j = N - 2^j + 1 (§1.3)
    }
}

/// docs/methods.md §1.3 counts for a longer filter: `n_j = (2^j - 1)(L - 1)`, `M_j = N - L_j + 1`.
#[test]
fn modwt_boundary_counts_la8() {
    let x = series(64, 12);
    let w = Modwt::new(WaveletFilter::La8, 3)
        .unwrap()
        .transform(&x)
        .unwrap();
    assert_eq!(w.boundary, vec![7, 21, 49]);
    let kept: Vec<usize> = (1..=3).map(|j| w.kept(j).len()).collect();
    assert_eq!(kept, vec![57, 43, 15]);
}

/// docs/methods.md §1.4 Haar: `W_{1,t} = (x_{2t+1} - x_{2t}) / sqrt2`, no boundary coefficients.
#[test]
fn dwt_haar_closed_form() {
    let x = series(64, 13);
    let w = Dwt::new(WaveletFilter::Haar, 3)
        .unwrap()
        .transform(&x)
        .unwrap();
    assert_eq!(w.boundary, vec![0, 0, 0]);
    let expected: Vec<f64> = x
        .chunks(2)
        .map(|p| (p[1] - p[0]) * std::f64::consts::FRAC_1_SQRT_2)
        .collect();
    assert_close(w.kept(1), &expected, scale(&x), "level 1");
    assert_eq!(w.kept(3).len(), 8);
}

/// docs/methods.md §1.10 test values: package DWT "WV" (mean of squared coefficients).
#[test]
fn dwt_haar_wv_methods_1_10() {
    let cases: [(&[f64], [f64; 2]); 2] = [
        (&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0], [0.5, 4.0]),
        (&[1.0, 3.0, 2.0, 5.0, 4.0, 6.0, 8.0, 7.0], [2.25, 4.25]),
    ];
    for (x, expected) in cases {
        let w = Dwt::new(WaveletFilter::Haar, 2)
            .unwrap()
            .transform(x)
            .unwrap();
        let wv: Vec<f64> = (1..=2)
            .map(|j| sum_sq(w.kept(j)) / w.kept(j).len() as f64)
            .collect();
        assert_close(&wv, &expected, 1.0, "DWT WV");
    }
}

#[test]
fn wavelet_empty_series_rejected() {
    for e in [
        Modwt::new(WaveletFilter::Haar, 1).unwrap().transform(&[]),
        Dwt::new(WaveletFilter::Haar, 1).unwrap().transform(&[]),
    ] {
        assert!(
            matches!(e, Err(InputError::Series(SeriesError::Empty))),
            "{e:?}"
        );
    }
}

/// docs/methods.md §1.2: `2^J > N` is an error.
#[test]
fn modwt_too_short_rejected() {
    let x = [1.0, 2.0, 3.0, 5.0, 4.0, 6.0, 8.0];
    let e = Modwt::new(WaveletFilter::Haar, 3).unwrap().transform(&x);
    match e {
        Err(InputError::Series(SeriesError::TooShort { n, needed, what })) => {
            assert_eq!((n, needed), (7, 8));
            assert_eq!(what, "a 3-level MODWT");
        }
        other => panic!("{other:?}"),
    }
    assert!(Modwt::new(WaveletFilter::Haar, 2)
        .unwrap()
        .transform(&x)
        .is_ok());
}

/// docs/methods.md §1.3: every level must keep at least one coefficient, `N >= L_j`.
#[test]
fn modwt_level_without_kept_coefficient_rejected() {
    let x = series(21, 14);
    // la8: L_2 = 3 * 7 + 1 = 22 > 21, though 2^2 <= 21
    match Modwt::new(WaveletFilter::La8, 2).unwrap().transform(&x) {
        Err(InputError::Series(SeriesError::TooShort { n, needed, what })) => {
            assert_eq!((n, needed), (21, 22));
            assert!(what.contains("level 2") && what.contains("la8"), "{what}");
        }
        other => panic!("{other:?}"),
    }
    let w = Modwt::new(WaveletFilter::La8, 2)
        .unwrap()
        .transform(&series(22, 14))
        .unwrap();
    assert_eq!(w.kept(2).len(), 1);
}

/// docs/methods.md §1.4: N must be divisible by 2^J; the error names the largest valid J and the
/// nearest valid lengths.
#[test]
fn dwt_not_divisible_rejected() {
    let x = series(100, 15);
    let e = Dwt::new(WaveletFilter::Haar, 3)
        .unwrap()
        .transform(&x)
        .unwrap_err();
    match &e {
        InputError::Param(p) => {
            assert_eq!(p.name, "levels");
            assert!(p.expected.contains("at most 2 levels"), "{e}");
            assert!(p.expected.contains("96 or 104 samples"), "{e}");
        }
        other => panic!("{other:?}"),
    }
    assert!(Dwt::new(WaveletFilter::Haar, 2)
        .unwrap()
        .transform(&x)
        .is_ok());
}

/// docs/methods.md §1.4: too few samples for 2^J, or no boundary-free coefficient at some level.
#[test]
fn dwt_too_short_rejected() {
    let e = Dwt::new(WaveletFilter::Haar, 3)
        .unwrap()
        .transform(&[1.0, 2.0, 3.0, 4.0]);
    assert!(
        matches!(
            e,
            Err(InputError::Series(SeriesError::TooShort {
                n: 4,
                needed: 8,
                ..
            }))
        ),
        "{e:?}"
    );
    // la8 level 2: N_2 = 4 coefficients, ceil(6 * 3/4) = 5 boundary ones
    let e = Dwt::new(WaveletFilter::La8, 2)
        .unwrap()
        .transform(&series(16, 16));
    match e {
        Err(InputError::Series(SeriesError::TooShort { n, needed, what })) => {
            assert_eq!((n, needed), (16, 24));
            assert!(what.contains("level 2"), "{what}");
        }
        other => panic!("{other:?}"),
    }
    let w = Dwt::new(WaveletFilter::La8, 2)
        .unwrap()
        .transform(&series(24, 16))
        .unwrap();
    assert_eq!(w.kept(2).len(), 1);
}

#[test]
fn wavelet_plans_are_send_sync_clone() {
    fn check<T: Send + Sync + Clone + Copy + PartialEq + std::fmt::Debug>(_: &T) {}
    let m = Modwt::new(WaveletFilter::D6, 2).unwrap();
    let d = Dwt::new(WaveletFilter::D6, 2).unwrap();
    check(&m);
    check(&d);
    assert_eq!((m.filter(), m.levels()), (WaveletFilter::D6, 2));
    assert_eq!((d.filter(), d.levels()), (WaveletFilter::D6, 2));
    fn send_sync<T: Send + Sync + Clone>() {}
    send_sync::<WaveletCoefficients>();
    send_sync::<WaveletScratch>();
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// MODWT is linear and commutes with circular shifts (docs/methods.md §1.2, periodic boundary).
    #[test]
    fn modwt_is_linear_and_shift_equivariant(
        fi in 0usize..18,
        n in 8usize..200,
        shift in 0usize..200,
        a in -3.0f64..3.0,
        seed in 0u64..1000,
    ) {
        let filter = WaveletFilter::ALL[fi];
        let levels = Modwt::max_levels(filter, n).min(4);
        prop_assume!(levels >= 1);
        let plan = Modwt::new(filter, levels).unwrap();
        let x = series(n, seed);
        let y = series(n, seed + 5000);
        let k = shift % n;
        let shifted: Vec<f64> = (0..n).map(|t| x[(t + n - k) % n]).collect();
        let combo: Vec<f64> = x.iter().zip(&y).map(|(u, v)| a * u + v).collect();
        let (wx, wy) = (plan.transform(&x).unwrap(), plan.transform(&y).unwrap());
        let ws = plan.transform(&shifted).unwrap();
        let wc = plan.transform(&combo).unwrap();
        let floor = 10.0 * scale(&combo).max(scale(&x));
        for j in 0..levels {
            let expected: Vec<f64> = (0..n).map(|t| wx.w[j][(t + n - k) % n]).collect();
            assert_close(&ws.w[j], &expected, floor, "shift");
            let expected: Vec<f64> = wx.w[j].iter().zip(&wy.w[j]).map(|(u, v)| a * u + v).collect();
            assert_close(&wc.w[j], &expected, floor, "linear");
        }
    }
}
