//! The worked examples of crate-internal items: they were doc examples while the items were
//! public; the items are internal now, so their examples run here, on the same values.
#![allow(clippy::unreadable_literal)]

/// The worked example of `wavelet::modwt::Modwt` (wavelet/modwt.rs).
#[test]
fn example_modwt_modwt() {
    use gmwm::wavelet::{Modwt, WaveletFilter};
    // docs/methods.md §1.10: x = 1..8, Haar, J = 3
    let x: Vec<f64> = (1..=8).map(f64::from).collect();
    let w = Modwt::new(WaveletFilter::Haar, 3)
        .unwrap()
        .transform(&x)
        .unwrap();
    assert_eq!(w.kept(1), &[0.5; 7]);
    assert_eq!(w.kept(2), &[1.0; 5]);
    assert_eq!(w.kept(3), &[2.0]); // the single remaining coefficient is kept (§1.3)
}

/// The worked example of `wavelet::modwt_boundary` (wavelet/mod.rs).
#[test]
fn example_modwt_boundary() {
    use gmwm::wavelet::modwt_boundary;
    assert_eq!(modwt_boundary(2, 3), 7); // Haar: 2^j - 1
    assert_eq!(modwt_boundary(8, 2), 21); // la8: 3 * 7
}

/// The worked example of `wavelet::dwt_boundary` (wavelet/mod.rs).
#[test]
fn example_dwt_boundary() {
    use gmwm::wavelet::dwt_boundary;
    assert_eq!(dwt_boundary(2, 5), 0); // Haar
    assert_eq!(dwt_boundary(8, 1), 3); // ceil(6 * 1/2)
    assert_eq!(dwt_boundary(8, 2), 5); // ceil(6 * 3/4)
}

/// The worked example of `wavelet::dwt::Dwt` (wavelet/dwt.rs).
#[test]
fn example_dwt_dwt() {
    use gmwm::wavelet::{Dwt, WaveletFilter};
    // docs/methods.md §1.4: Haar W_{1,t} = (x_{2t+1} - x_{2t}) / sqrt2
    let w = Dwt::new(WaveletFilter::Haar, 1)
        .unwrap()
        .transform(&[1.0, 3.0, 2.0, 5.0])
        .unwrap();
    assert!((w.kept(1)[0] - 2.0 / 2f64.sqrt()).abs() < 1e-15);
    assert!((w.kept(1)[1] - 3.0 / 2f64.sqrt()).abs() < 1e-15);
}

/// The worked example of `variance::robust::a_of_c` (variance/robust.rs).
#[test]
fn example_robust_a_of_c() {
    // docs/methods.md §2.5 test value: a(4.400278) = 0.5691689
    assert!((gmwm::variance::robust::a_of_c(4.400278) - 0.5691689).abs() < 1e-7);
}

/// The worked example of `variance::robust::tuning_constant` (variance/robust.rs).
#[test]
fn example_robust_tuning_constant() {
    use gmwm::variance::robust::{tuning_constant, RobustConvention};
    let c = tuning_constant(0.6, RobustConvention::Exact).unwrap();
    assert!((c - 4.400278).abs() < 1e-6);
}

/// The worked example of `variance::robust::robust_scale` (variance/robust.rs).
#[test]
fn example_robust_robust_scale() {
    use gmwm::variance::robust::{robust_scale, RobustConvention};
    let y = [-1.2, 0.3, 0.8, -0.4, 1.1, -0.9, 0.2, -0.1, 0.6, -0.7];
    // docs/methods.md §2.5 test value (port default with c = 4.400278)
    let s2 = robust_scale(&y, 4.400278, RobustConvention::Exact).unwrap();
    assert!((s2 - 0.6909524).abs() < 1e-6);
}

/// The worked example of `variance::robust::robust_ci` (variance/robust.rs).
#[test]
fn example_robust_robust_ci() {
    // docs/methods.md §2.5 test value
    let (lo, hi) =
        gmwm::variance::robust::robust_ci(0.6481826, 0.525, 0.2045587, 3.158041, 0.6, None);
    assert!((lo - 0.1374296).abs() < 1e-6 && (hi - 4.844999).abs() < 1e-5);
}

/// The worked example of `variance::pooled::PooledWv` (variance/pooled.rs).
#[test]
fn example_pooled_pooledwv() {
    use gmwm::variance::pooled::PooledWv;
    use gmwm::{simulate_model, wavelet_variance, Model, WvOptions};
    let wn = Model::parse("WN(sigma2=1)").unwrap();
    let wvs = [4000, 16000]
        .iter()
        .enumerate()
        .map(|(k, &n)| {
            let x = simulate_model(&wn, n, 1.0, k as u64).unwrap();
            wavelet_variance(&x, 1.0, &WvOptions::default()).unwrap()
        })
        .collect();
    let pooled = PooledWv::new(wvs).unwrap();
    // the longer recording reaches two more levels; at level 1 it has four times the weight
    assert_eq!(pooled.wv().levels(), pooled.parts()[1].levels());
    assert!((pooled.weights(1)[0] / pooled.weights(0)[0] - 4.0).abs() < 0.01);
    assert_eq!(pooled.wv().n(), 20000);
}

/// The worked example of `variance::implied_cov::exact_wv_covariance` (variance/implied_cov.rs).
#[test]
fn example_implied_cov_exact_wv_covariance() {
    use gmwm::variance::implied_cov::exact_wv_covariance;
    use gmwm::Model;
    let model = Model::parse("WN(sigma2=1)").unwrap();
    let v = exact_wv_covariance(&model, 4096, 1.0, 3).unwrap();
    // level 1 of white noise: nu2 = 1/2, Var(nu2_hat) = (3 M - 1) / (4 M^2) with M = N - 1
    let m = 4095.0;
    assert!((v[(0, 0)] - (3.0 * m - 1.0) / (4.0 * m * m)).abs() < 1e-12 * v[(0, 0)]);
}

/// The worked example of `variance::cross::wavelet_cross_covariance` (variance/cross.rs).
#[test]
fn example_cross_wavelet_cross_covariance() {
    use gmwm::variance::cross::wavelet_cross_covariance;
    // the cross-covariance of a series with itself is its wavelet variance (§1.10 test values)
    let x: Vec<f64> = (1..=8).map(f64::from).collect();
    let c = wavelet_cross_covariance(&x, &x, 2).unwrap();
    assert!((c[0] - 0.25).abs() < 1e-12 && (c[1] - 1.0).abs() < 1e-12);
    // and with its negative, minus it
    let y: Vec<f64> = x.iter().map(|v| -v).collect();
    assert!((wavelet_cross_covariance(&x, &y, 2).unwrap()[0] + 0.25).abs() < 1e-12);
}

/// The worked example of `selection::optimism::asymptotic_optimism` (selection/optimism.rs).
#[test]
fn example_optimism_asymptotic_optimism() {
    use gmwm::selection::{asymptotic_optimism, OptimismConvention};
    use nalgebra::DMatrix;
    // docs/methods.md §8 test values: WN + RW at tau = 2, 4, 8, Omega = diag(1, 2, 3), D = 0, V = I
    let a = DMatrix::from_column_slice(3, 2, &[0.5, 0.25, 0.125, 0.25, 0.375, 0.6875]);
    let omega = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![1.0, 2.0, 3.0]));
    let o = asymptotic_optimism(
        &a,
        &DMatrix::zeros(2, 2),
        &omega,
        &DMatrix::identity(3, 3),
        OptimismConvention::Corrected,
    )
    .unwrap();
    assert!((o - 8.299065).abs() < 1e-6);
}

/// The worked example of `model` (model/mod.rs).
#[test]
fn example_model_builder() {
    use gmwm::model::{gm, qn, rw, wn, Model};
    let text: Model = "3*GM()+WN()+QN()+RW()".parse().unwrap();
    let built = (3 * gm() + wn() + qn() + rw()).build().unwrap();
    assert_eq!(text, built);
    assert_eq!(built.n_params(), 9);
    assert!(built.is_guess_mode());
    assert_eq!(built.to_string(), "3*GM()+WN()+QN()+RW()");
}

/// The worked example of `model::format_value` (model/mod.rs).
#[test]
fn example_format_value() {
    use gmwm::model::format_value;
    assert_eq!(format_value(0.1), "0.1");
    assert_eq!(format_value(7.08e-9), "7.08e-9");
    assert_eq!(format_value(2.5e6), "2.5e6");
}

/// The worked example of `inference::asymptotic::wald_interval` (inference/asymptotic.rs).
#[test]
fn example_asymptotic_wald_interval() {
    use gmwm::inference::asymptotic::{wald_interval, IntervalScale};
    // docs/methods.md §7 test value: theta 1, SE 1.745743, package z 1.644854
    let (lo, hi) = wald_interval(1.0, 1.745743, 1.644854, None, IntervalScale::Natural);
    assert!((lo + 1.871492).abs() < 1e-6 && (hi - 3.871492).abs() < 1e-6);
}

/// The worked example of `imu::read::binary::BinaryChunks` (imu/read/binary.rs).
#[test]
fn example_read_binary_binarychunks() {
    use gmwm::imu::{BinaryChunks, InputFormat};
    // 10 samples 1..=10 as little-endian f64, read back 4 at a time
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.f64le.bin");
    let bytes: Vec<u8> = (1..=10).flat_map(|i| f64::from(i).to_le_bytes()).collect();
    std::fs::write(&path, bytes).unwrap();
    let mut chunks = BinaryChunks::open(&path, InputFormat::F64, 1, 1, 4).unwrap();
    let mut sum = 0.0;
    while let Some(chunk) = chunks.next_chunk().unwrap() {
        sum += chunk.iter().sum::<f64>();
    }
    assert_eq!(sum, 55.0);
}

/// The worked example of `fit::canonical` (fit/canonical.rs).
#[test]
fn example_canonical() {
    use gmwm::Model;
    use gmwm::{simulate_model, Gmwm, WvOptions};
    // two AR1s at nearly one correlation time and a white noise, fitted to data with one AR1
    let truth = Model::parse("AR1(phi=0.99, sigma2=1e-2)+WN(sigma2=1)").unwrap();
    let x = simulate_model(&truth, 100_000, 100.0, 3).unwrap();
    let start = "AR1(phi=0.991, sigma2=5e-3)+AR1(phi=0.989, sigma2=5e-3)+WN(sigma2=1)";
    let fit = Gmwm::parse(start)
        .unwrap()
        .fit(&x, 100.0, &WvOptions::default())
        .unwrap();
    let canonical = fit.canonical().unwrap();
    assert_eq!(canonical.model.to_string(), "AR1()+WN()");
    assert_eq!(canonical.reduced.to_string(), "AR1()+WN()");
    assert!(canonical.separation <= gmwm::fit::SEPARATION_LIMIT);
}

/// The worked example of `fit::canonical::wv_separation` (fit/canonical.rs).
#[test]
fn example_canonical_wv_separation() {
    use gmwm::fit::canonical::wv_separation;
    // one level, a factor e apart, log-variance 0.25 (sd 0.5): two standard errors
    let d = wv_separation(&[1.0], &[std::f64::consts::E], &[0.25]);
    assert!((d - 2.0).abs() < 1e-12);
}
