//! The fast pyramids against the direct-convolution oracle ([`super::naive`], crate-internal)
//! for every filter (docs/methods.md §1.2, §1.4); moved from the integration tests when the oracle
//! stopped being public.

use gmwm::wavelet::naive;
use gmwm::wavelet::{
    dwt_boundary, modwt_boundary, Dwt, Modwt, WaveletCoefficients, WaveletFilter, WaveletScratch,
};
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

/// The transform under test, both entry points driven by one harness.
#[derive(Clone, Copy, Debug)]
enum Kind {
    Modwt,
    Dwt,
}

/// Runs `kind` on `x` through `transform` and through `transform_with_scratch` with the given
/// (dirty) buffers, checks both agree with the oracle, boundary counts and `V_J`.
fn check_transform(
    kind: Kind,
    filter: WaveletFilter,
    levels: usize,
    x: &[f64],
    out: &mut WaveletCoefficients,
    scratch: &mut WaveletScratch,
) {
    let what = format!("{kind:?} {filter} J = {levels} N = {}", x.len());
    let (fresh, oracle) = match kind {
        Kind::Modwt => {
            let plan = Modwt::new(filter, levels).unwrap();
            plan.transform_with_scratch(x, out, scratch).unwrap();
            (plan.transform(x).unwrap(), naive::modwt(filter, levels, x))
        }
        Kind::Dwt => {
            let plan = Dwt::new(filter, levels).unwrap();
            plan.transform_with_scratch(x, out, scratch).unwrap();
            (plan.transform(x).unwrap(), naive::dwt(filter, levels, x))
        }
    };
    assert_eq!(&fresh, out, "{what}: scratch and fresh runs differ");
    assert_eq!(out.levels(), levels, "{what}");
    let floor = scale(x);
    for j in 1..=levels {
        let w = &out.w[j - 1];
        assert_close(w, &oracle.w[j - 1], floor, &format!("{what} level {j}"));
        let (len, boundary) = match kind {
            Kind::Modwt => (x.len(), modwt_boundary(filter.len(), j)),
            Kind::Dwt => (x.len() >> j, dwt_boundary(filter.len(), j)),
        };
        assert_eq!(
            (w.len(), out.boundary[j - 1]),
            (len, boundary),
            "{what} level {j}"
        );
        assert_eq!(out.kept(j), &w[boundary..], "{what} level {j}");
        assert!(!out.kept(j).is_empty(), "{what} level {j}");
    }
    assert_close(
        scratch.scaling(),
        &oracle.scaling,
        floor,
        &format!("{what} V_J"),
    );
}

/// docs/methods.md §1.2: the pyramid equals direct circular convolution with the level-j equivalent
/// filter, for every filter, several lengths (powers of two and not) and level counts, reusing
/// dirty output and scratch buffers throughout.
#[test]
fn modwt_matches_naive() {
    let mut out = WaveletCoefficients::default();
    let mut scratch = WaveletScratch::new();
    for (i, filter) in WaveletFilter::ALL.into_iter().enumerate() {
        let x = series(256, i as u64);
        let max = Modwt::max_levels(filter, 256);
        assert!(max >= 2, "{filter}");
        for levels in (1..=max).filter(|j| (4..=6).contains(j) || *j == max) {
            check_transform(Kind::Modwt, filter, levels, &x, &mut out, &mut scratch);
        }
        let x = series(2048, 100 + i as u64);
        check_transform(Kind::Modwt, filter, 6, &x, &mut out, &mut scratch);
        let x = series(250, 200 + i as u64);
        let max = Modwt::max_levels(filter, 250);
        check_transform(Kind::Modwt, filter, max, &x, &mut out, &mut scratch);
        check_transform(
            Kind::Modwt,
            filter,
            1,
            &x[..filter.len()],
            &mut out,
            &mut scratch,
        );
    }
}

/// docs/methods.md §1.4: the pyramid equals decimated direct convolution with the level-j
/// equivalent filter, for every filter, including levels shorter than the filter (multiple
/// wrap-around).
#[test]
fn dwt_matches_naive() {
    let mut out = WaveletCoefficients::default();
    let mut scratch = WaveletScratch::new();
    for (i, filter) in WaveletFilter::ALL.into_iter().enumerate() {
        for (n, seed) in [(256usize, 300), (2048, 400), (96, 500), (8, 600), (24, 700)] {
            let x = series(n, seed + i as u64);
            let max = Dwt::max_levels(filter, n);
            for levels in (1..=max).filter(|j| *j <= 2 || (4..=6).contains(j) || *j == max) {
                check_transform(Kind::Dwt, filter, levels, &x, &mut out, &mut scratch);
            }
        }
    }
}

/// The oracle really can fail: a one-ulp-scale perturbation is tolerated, a 1e-9 one is not.
#[test]
fn modwt_oracle_comparison_detects_errors() {
    let x = series(64, 1);
    let w = Modwt::new(WaveletFilter::D4, 2)
        .unwrap()
        .transform(&x)
        .unwrap();
    let oracle = naive::modwt(WaveletFilter::D4, 2, &x);
    let mut bad = w.w[1].clone();
    bad[40] += 1e-9 * scale(&x);
    let r = std::panic::catch_unwind(|| assert_close(&bad, &oracle.w[1], scale(&x), "bad"));
    assert!(r.is_err());
}
