//! Robust wavelet variance (docs/methods.md §2): reference values, Monte Carlo checks and bad
//! input. (Brent's methods, docs/methods.md §12, are crate-internal and tested in `math::brent`.)

use gmwm::error::{InputError, SeriesError};
use gmwm::variance::robust::{
    a_of_c, efficiency, package_efficiency, robust_ci, robust_scale, truncated_normal_moments,
    tuning_constant, RobustConvention, RobustOptions,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// The test values of docs/methods.md are printed with 7 significant digits: half a unit in the
/// last place.
const PRINTED_7: f64 = 5e-7;
/// Correct tuning constants are printed to 6 decimals (docs/methods.md §2.3 table).
const C_TABLE_TOL: f64 = 1e-6;
/// The package constant is only as good as R's `optimize` tolerance eps^0.25 ~ 1.22e-4
/// (docs/methods.md §2.3, §2.5 "c = 4.9734 (+-2e-4)").
const PACKAGE_C_TOL: f64 = 2e-4;
/// Our Brent minimiser takes R's steps, so its iterate matches R's printed 6 decimals.
const PACKAGE_PATH_TOL: f64 = 1e-6;
/// Efficiencies in the §2.3 table are printed to 5 decimals.
const EFF_TABLE_TOL: f64 = 5e-6;
/// Monte Carlo bound of docs/methods.md §2.5: "within 0.05 of 1".
const CONTAMINATED_TOL: f64 = 0.05;
/// Clean Gaussian n = 1e5: the robust variance has sd ~ sqrt(2 / (eff n)) ~ 0.006 at eff 0.6;
/// 3% is five standard deviations.
const CLEAN_TOL: f64 = 0.03;

/// docs/methods.md §2.5 test coefficients.
const Y10: [f64; 10] = [-1.2, 0.3, 0.8, -0.4, 1.1, -0.9, 0.2, -0.1, 0.6, -0.7];
/// docs/methods.md §2.5 pathological coefficients.
const Y_PATH: [f64; 10] = [-2.0, -1.5, -1.0, -0.5, 0.0, 0.5, 1.0, 1.5, 2.0, 30.0];
/// Correct constant for eff 0.6 as printed in docs/methods.md §2.3/§2.5.
const C_EXACT_06: f64 = 4.400278;
/// Package constant for eff 0.6 as printed in docs/methods.md §2.5.
const C_PACKAGE_06: f64 = 4.973361;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

// ---- §2.2 / §2.3 constants ----

#[test]
fn a_of_c_matches_methods_2_5() {
    // docs/methods.md §2.5: a(4.400278) = 0.5691689, a(4.973361) = 0.6367236
    assert!((a_of_c(4.400278) - 0.5691689).abs() < PRINTED_7);
    assert!((a_of_c(4.973361) - 0.6367236).abs() < PRINTED_7);
}

#[test]
fn a_of_c_equals_expected_psi_squared_by_quadrature() {
    // a(c) = E[psi_c(Z)^2] (docs/methods.md §2.1): Simpson's rule on [-c, c]
    let c = 4.5;
    let n = 20_000;
    let h = 2.0 * c / n as f64;
    let g = |z: f64| {
        let t = 1.0 - z * z / (c * c);
        let psi = z * t * t;
        psi * psi * (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt()
    };
    let mut s = g(-c) + g(c);
    for i in 1..n {
        s += g(-c + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    assert!((a_of_c(c) - s * h / 3.0).abs() < 1e-12);
}

#[test]
fn truncated_normal_moments_match_closed_forms() {
    // docs/methods.md §2.2: mu_0 = 2 Phi(c) - 1, mu_2 = mu_0 - 2 c phi(c); at c = 1.96, mu_0 ~ 0.95
    let mu = truncated_normal_moments(1.959963984540054);
    assert!((mu[0] - 0.95).abs() < 1e-15, "{}", mu[0] - 0.95);
    let phi = (-0.5f64 * 1.959963984540054 * 1.959963984540054).exp()
        / (2.0 * std::f64::consts::PI).sqrt();
    assert!((mu[1] - (0.95 - 2.0 * 1.959963984540054 * phi)).abs() < 1e-12);
}

#[test]
fn tuning_constant_exact_matches_methods_2_3_table() {
    // docs/methods.md §2.3 table: correct c and a(correct c)
    let table = [
        (0.5, 4.060125, 0.522277),
        (0.6, 4.400278, 0.569169),
        (0.8, 5.448855, 0.683091),
        (0.9, 6.583979, 0.766182),
    ];
    for (eff, c_ref, a_ref) in table {
        let c = tuning_constant(eff, RobustConvention::Exact).unwrap();
        assert!((c - c_ref).abs() < C_TABLE_TOL, "eff {eff}: c = {c}");
        assert!((efficiency(c) - eff).abs() < 1e-12, "eff {eff}");
        assert!(
            (a_of_c(c) - a_ref).abs() < 5e-7,
            "eff {eff}: a = {}",
            a_of_c(c)
        );
    }
}

#[test]
fn tuning_constant_package_matches_methods_2_3_table() {
    // docs/methods.md §2.3 table: package c and the true efficiency at the package c
    let table = [
        (0.5, 4.777414, 0.68898),
        (0.6, 4.973361, 0.72700),
        (0.8, 5.649325, 0.82403),
        (0.9, 6.622235, 0.90217),
    ];
    for (eff, c_ref, true_eff) in table {
        let c = tuning_constant(eff, RobustConvention::Package).unwrap();
        assert!((c - c_ref).abs() < PACKAGE_C_TOL, "eff {eff}: c = {c}");
        // same Brent path as R's optimize: the printed digits themselves are reproduced
        assert!((c - c_ref).abs() < PACKAGE_PATH_TOL, "eff {eff}: c = {c}");
        assert!(
            (efficiency(c_ref) - true_eff).abs() < EFF_TABLE_TOL,
            "eff {eff}: true eff {}",
            efficiency(c_ref)
        );
        // the package's own (slipped) formula is met at its constant
        assert!((package_efficiency(c) - eff).abs() < 1e-3, "eff {eff}");
    }
    // docs/methods.md §2.5: "Package constant for eff 0.6: c = 4.9734 (+-2e-4)"
    let c = tuning_constant(0.6, RobustConvention::Package).unwrap();
    assert!((c - 4.9734).abs() < PACKAGE_C_TOL);
}

#[test]
fn efficiency_is_increasing_past_the_zero_of_m() {
    // docs/methods.md §2.3: the root finder relies on eff increasing in c
    let mut prev = 0.0;
    let mut c = 2.4;
    while c < 100.0 {
        let e = efficiency(c);
        assert!(e > prev, "c = {c}: {e} <= {prev}");
        prev = e;
        c += 0.05;
    }
    assert!(prev > 0.99);
}

#[test]
fn tuning_constant_rejects_bad_eff() {
    for conv in [RobustConvention::Exact, RobustConvention::Package] {
        for bad in [0.0, 1.0, f64::NAN, -0.5, 0.995] {
            let err = tuning_constant(bad, conv).unwrap_err();
            assert_eq!(err.name, "eff", "{bad}");
        }
    }
    // extremes of the valid range are solvable
    for eff in [1e-6, 0.01, 0.99] {
        let c = tuning_constant(eff, RobustConvention::Exact).unwrap();
        assert!((efficiency(c) - eff).abs() < 1e-10, "{eff}: {c}");
    }
}

#[test]
fn robust_options_new_rejects_eff_0_1_nan() {
    for bad in [0.0, 1.0, f64::NAN] {
        assert!(RobustOptions::new(bad, RobustConvention::Exact).is_err());
    }
    let o = RobustOptions::new(0.8, RobustConvention::Package).unwrap();
    assert!((o.tuning_constant() - 5.649325).abs() < PACKAGE_C_TOL);
}

// ---- §2.4 / §2.5 scale ----

#[test]
fn robust_scale_package_route_matches_methods_2_5() {
    // docs/methods.md §2.5: package robust (eff 0.6) 0.6481826; robust (eff 0.8) 0.616337
    let c = tuning_constant(0.6, RobustConvention::Package).unwrap();
    let s2 = robust_scale(&Y10, c, RobustConvention::Package).unwrap();
    assert!((s2 - 0.6481826).abs() < PRINTED_7, "{s2}");
    let c = tuning_constant(0.8, RobustConvention::Package).unwrap();
    let s2 = robust_scale(&Y10, c, RobustConvention::Package).unwrap();
    assert!((s2 - 0.616337).abs() < 5e-7, "{s2}");
}

#[test]
fn robust_scale_package_route_reproduces_local_minimum() {
    // docs/methods.md §2.5 pathology: package robust (eff 0.6) 176.0876, larger than classical 91.5
    let c = tuning_constant(0.6, RobustConvention::Package).unwrap();
    let s2 = robust_scale(&Y_PATH, c, RobustConvention::Package).unwrap();
    assert!(rel(s2, 176.0876) < 1e-6, "{s2}");
}

#[test]
fn robust_scale_exact_matches_methods_2_5() {
    // docs/methods.md §2.5 "Port default mode": 0.6909524 / 1.902038 (c = 4.400278),
    // 0.6481894 / 1.800190 (c = 4.973361)
    let cases = [
        (&Y10, C_EXACT_06, 0.6909524),
        (&Y_PATH, C_EXACT_06, 1.902038),
        (&Y10, C_PACKAGE_06, 0.6481894),
        (&Y_PATH, C_PACKAGE_06, 1.800190),
    ];
    for (y, c, expected) in cases {
        let s2 = robust_scale(y, c, RobustConvention::Exact).unwrap();
        assert!(rel(s2, expected) < 1e-6, "c {c}: {s2} vs {expected}");
    }
    // "a correct root-finder must return a value well below 91.5"
    let classical = Y_PATH.iter().map(|v| v * v).sum::<f64>() / Y_PATH.len() as f64;
    assert!((classical - 91.5).abs() < 1e-12);
}

#[test]
fn robust_scale_solves_the_scale_equation() {
    // docs/methods.md §2.1: (1/n) sum psi_c(y_i / s)^2 = a(c) at the returned s^2
    for y in [&Y10, &Y_PATH] {
        let s2 = robust_scale(y, C_EXACT_06, RobustConvention::Exact).unwrap();
        let s = s2.sqrt();
        let m = y
            .iter()
            .map(|v| {
                let p = gmwm::variance::robust::psi_biweight(v / s, C_EXACT_06);
                p * p
            })
            .sum::<f64>()
            / y.len() as f64;
        assert!((m - a_of_c(C_EXACT_06)).abs() < 1e-10, "{m}");
    }
}

#[test]
fn robust_scale_is_scale_equivariant() {
    // s^2(k y) = k^2 s^2(y)
    let base = robust_scale(&Y10, C_EXACT_06, RobustConvention::Exact).unwrap();
    for k in [1e-6, 3.0, 1e5] {
        let ky: Vec<f64> = Y10.iter().map(|v| k * v).collect();
        let s2 = robust_scale(&ky, C_EXACT_06, RobustConvention::Exact).unwrap();
        assert!(rel(s2, k * k * base) < 1e-10, "k = {k}");
    }
}

#[test]
fn robust_ci_matches_methods_2_5() {
    // docs/methods.md §2.5: classical 0.525 CI [0.2045587, 3.158041]; robust 0.6481826 CI
    // [0.1374296, 4.844999]
    let (lo, hi) = robust_ci(0.6481826, 0.525, 0.2045587, 3.158041, 0.6, None);
    assert!((lo - 0.1374296).abs() < PRINTED_7, "{lo}");
    assert!(rel(hi, 4.844999) < 1e-6, "{hi}");
    // and end to end from the package robust value
    let c = tuning_constant(0.6, RobustConvention::Package).unwrap();
    let nu_r = robust_scale(&Y10, c, RobustConvention::Package).unwrap();
    let (lo, hi) = robust_ci(nu_r, 0.525, 0.2045587, 3.158041, 0.6, Some(1e-3));
    assert!((lo - 0.1374296).abs() < 1e-6 && rel(hi, 4.844999) < 1e-6);
}

#[test]
fn robust_ci_substitutes_non_positive_lower_bound() {
    // docs/methods.md §2.5: lo_r <= 0 -> min(nu_r / 2, smallest earlier lower bound); level 1 ->
    // nu_r / 2
    let (lo, hi) = robust_ci(1.0, 1.0, 0.05, 2.0, 0.5, None);
    assert_eq!(lo, 0.5);
    assert!((hi - (1.0 + 2f64.sqrt())).abs() < 1e-15);
    assert_eq!(robust_ci(1.0, 1.0, 0.05, 2.0, 0.5, Some(0.2)).0, 0.2);
    assert_eq!(robust_ci(1.0, 1.0, 0.05, 2.0, 0.5, Some(0.9)).0, 0.5);
}

fn gaussian(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| rng.sample(StandardNormal)).collect()
}

#[test]
fn robust_scale_resists_one_percent_gross_outliers() {
    // docs/methods.md §2.5: 1e5 N(0,1), 1% replaced by 100: classical ~101, robust within 0.05 of 1
    let mut y = gaussian(100_000, 20_251_122);
    for v in y.iter_mut().step_by(100) {
        *v = 100.0;
    }
    let classical = y.iter().map(|v| v * v).sum::<f64>() / y.len() as f64;
    assert!((classical - 101.0).abs() < 1.0, "{classical}");
    let c = tuning_constant(0.6, RobustConvention::Exact).unwrap();
    let s2 = robust_scale(&y, c, RobustConvention::Exact).unwrap();
    assert!((s2 - 1.0).abs() < CONTAMINATED_TOL, "{s2}");
}

#[test]
fn robust_scale_is_consistent_at_the_gaussian() {
    // docs/methods.md §2.1: s^2 is Fisher-consistent for the variance at the Gaussian
    let y: Vec<f64> = gaussian(100_000, 7).iter().map(|v| 3.0 * v).collect();
    for conv in [RobustConvention::Exact, RobustConvention::Package] {
        let c = tuning_constant(0.6, conv).unwrap();
        let s2 = robust_scale(&y, c, conv).unwrap();
        assert!(rel(s2, 9.0) < CLEAN_TOL, "{conv}: {s2}");
    }
}

/// Slow, obviously right twin of the port route (docs/methods.md §2.4 "Port"): MAD start and the
/// plain fixed point `s^2 <- s^2 mean(psi_c(y/s)^2) / a(c)` to a relative change of 1e-14.
fn fixed_point_oracle(y: &[f64], c: f64) -> f64 {
    let mut abs: Vec<f64> = y.iter().map(|v| v.abs()).collect();
    abs.sort_by(f64::total_cmp);
    let n = abs.len();
    let median = if n % 2 == 1 {
        abs[n / 2]
    } else {
        0.5 * (abs[n / 2 - 1] + abs[n / 2])
    };
    let a = a_of_c(c);
    let mut s2 = (median / 0.6744897501960817).powi(2);
    for _ in 0..100_000 {
        let s = s2.sqrt();
        let m = y
            .iter()
            .map(|v| gmwm::variance::robust::psi_biweight(v / s, c).powi(2))
            .sum::<f64>()
            / n as f64;
        let next = s2 * m / a;
        if (next - s2).abs() <= 1e-14 * next {
            return next;
        }
        s2 = next;
    }
    panic!("oracle did not converge");
}

/// Agreement between the polished fixed point and the plain one: both solve the equation to
/// ~1e-12 relative; 1e-9 leaves room for the oracle's slower linear convergence.
const ORACLE_TOL: f64 = 1e-9;

#[test]
fn robust_scale_matches_fixed_point_oracle() {
    let c = tuning_constant(0.6, RobustConvention::Exact).unwrap();
    for seed in 0..6u64 {
        let mut y = gaussian(3_000 + 17 * seed as usize, 100 + seed);
        // contaminate 0%, 2%, 4%, ... with outliers of growing size
        for v in y.iter_mut().step_by(50).take(30 * seed as usize) {
            *v = 5.0 * (seed as f64 + 1.0);
        }
        let expected = fixed_point_oracle(&y, c);
        let got = robust_scale(&y, c, RobustConvention::Exact).unwrap();
        assert!(
            rel(got, expected) < ORACLE_TOL,
            "seed {seed}: {got} vs {expected}"
        );
    }
    for y in [&Y10[..], &Y_PATH[..]] {
        for c in [C_EXACT_06, C_PACKAGE_06] {
            let got = robust_scale(y, c, RobustConvention::Exact).unwrap();
            assert!(rel(got, fixed_point_oracle(y, c)) < ORACLE_TOL);
        }
    }
}

// ---- bad input ----

#[test]
fn robust_scale_rejects_empty_and_zero_input() {
    for conv in [RobustConvention::Exact, RobustConvention::Package] {
        assert!(matches!(
            robust_scale(&[], C_EXACT_06, conv),
            Err(InputError::Series(SeriesError::Empty))
        ));
        // all-zero coefficients (e.g. a level of a period-2 series): the exact estimator's scale
        // is 0, like the classical WV; the package's route divides by sd = 0 and fails
        match conv {
            RobustConvention::Exact => {
                assert_eq!(robust_scale(&[0.0; 8], C_EXACT_06, conv).unwrap(), 0.0)
            }
            _ => assert!(matches!(
                robust_scale(&[0.0; 8], C_EXACT_06, conv),
                Err(InputError::Series(SeriesError::Constant { .. }))
            )),
        }
        assert!(matches!(
            robust_scale(&[1.0, f64::NAN], C_EXACT_06, conv),
            Err(InputError::Series(SeriesError::NonFinite { index: 1, .. }))
        ));
        for bad_c in [f64::NAN, f64::INFINITY, 0.0, -1.0] {
            assert!(matches!(
                robust_scale(&Y10, bad_c, conv),
                Err(InputError::Param(ref p)) if p.name == "c"
            ));
        }
    }
    // tiny tuning constants (far below any from tuning_constant): a value or an error, no panic
    for c in [1e-3, 0.1, 0.5, 1.0] {
        for conv in [RobustConvention::Exact, RobustConvention::Package] {
            if let Ok(s2) = robust_scale(&Y10, c, conv) {
                assert!(s2.is_finite() && s2 > 0.0, "c {c} {conv}: {s2}");
            }
        }
    }
    // more than half exactly zero (quantised data): MAD = 0 gives no start, the RMS starts the
    // iteration and the result still solves the scale equation mean psi^2(y/s) = a(c)
    let y = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, -1.0, 1.0, -1.0, 1.0];
    let s2 = robust_scale(&y, C_EXACT_06, RobustConvention::Exact).unwrap();
    let s = s2.sqrt();
    let psi2 = y
        .iter()
        .map(|v| gmwm::variance::robust::psi_biweight(v / s, C_EXACT_06).powi(2))
        .sum::<f64>()
        / y.len() as f64;
    assert!(
        (psi2 / a_of_c(C_EXACT_06) - 1.0).abs() < 1e-9,
        "{s2}: {psi2}"
    );
    // exactly half zero is fine (median of |y| is positive)
    assert!(robust_scale(&[0.0, 0.0, 1.0, -2.0], C_EXACT_06, RobustConvention::Exact).is_ok());
}

#[test]
fn robust_scale_reports_missing_root() {
    // values spread over many orders of magnitude: at any s at most ~one residual sits near the
    // peak of psi_c^2, so mean psi_c^2 < a(c) everywhere (docs/methods.md §2.4 non-monotone
    // equation)
    let y: Vec<f64> = (0..12).map(|k| 10f64.powi(3 * k)).collect();
    let err = robust_scale(&y, C_EXACT_06, RobustConvention::Exact).unwrap_err();
    assert!(
        matches!(
            err,
            gmwm::InputError::Series(gmwm::SeriesError::NoRobustScale { .. })
        ),
        "{err}"
    );
}
