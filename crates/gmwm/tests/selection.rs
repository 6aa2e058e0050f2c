//! Model selection by WIC (METHODS §8): the model Hessian (§4.6), the §8 test values,
//! candidate enumeration, seeded Monte Carlo and the R package's auto_imu on real data.

use crate::common::{data_dir, f64s, read_column, read_ref};
use gmwm::imu::{read_table, Imu, ReadOptions};
use gmwm::model::Model;
use gmwm::selection::{
    asymptotic_optimism, auto_imu, common_denominator, d_matrix, nested_candidates, terms,
    OptimismConvention, OptimismMethod, SelectionError, Wic,
};
use gmwm::sim::simulate_model;
use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;

fn model(text: &str) -> Model {
    Model::parse(text).unwrap_or_else(|e| panic!("{text}: {e}"))
}

/// The METHODS §8 test values are printed with 7 significant digits.
const METHODS_TOL: f64 = 5e-7;

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-12)
}

// ---------------------------------------------------------------- Model::hessian (§4.6)

/// Central differences of the analytic Jacobian; step relative to each parameter.
fn fd_hessian(m: &Model, levels: usize, freq: f64) -> Vec<Vec<Vec<f64>>> {
    let theta: Vec<f64> = m.values().into_iter().map(Option::unwrap).collect();
    let p = theta.len();
    let mut out = vec![vec![vec![0.0; p]; p]; levels];
    for l in 0..p {
        let h = 1e-5 * theta[l].abs().max(1e-300);
        let mut up = theta.clone();
        let mut dn = theta.clone();
        up[l] += h;
        dn[l] -= h;
        let ju = m.with_values(&up).unwrap().jacobian(levels, freq).unwrap();
        let jd = m.with_values(&dn).unwrap().jacobian(levels, freq).unwrap();
        for j in 0..levels {
            for k in 0..p {
                out[j][k][l] = (ju[j][k] - jd[j][k]) / (2.0 * h);
            }
        }
    }
    out
}

fn check_hessian(text: &str, levels: usize, freq: f64) {
    let m = model(text);
    let h = m.hessian(levels, freq).unwrap();
    let fd = fd_hessian(&m, levels, freq);
    let p = m.n_params();
    assert_eq!(h.len(), levels);
    for j in 0..levels {
        // scale of the level's block: second differences of a smooth function with a relative
        // step of 1e-5 carry a relative error of about 1e-9 of the largest entry
        let scale = h[j].iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        for k in 0..p {
            for l in 0..p {
                assert!(
                    (h[j][k][l] - fd[j][k][l]).abs() <= 1e-6 * scale,
                    "{text}: level {} d2/d{k}d{l}: {} vs fd {}",
                    j + 1,
                    h[j][k][l],
                    fd[j][k][l]
                );
                assert_eq!(h[j][k][l], h[j][l][k], "symmetric");
            }
        }
    }
}

#[test]
fn model_hessian_matches_central_differences_of_the_jacobian() {
    check_hessian(
        "AR1(phi=0.9, sigma2=0.1)+AR1(phi=0.5, sigma2=1)+WN(sigma2=2)+QN(q2=0.3)+RW(gamma2=1e-3)+DR(omega=0.01)",
        12,
        1.0,
    );
    check_hessian(
        "GM(beta=0.25, sigma2_gm=7.08e-9)+WN(sigma2=6.94e-7)+RW(gamma2=3.9e-14)",
        16,
        250.0,
    );
    // the cross-component blocks are exactly zero
    let m = model("AR1(phi=0.5, sigma2=1)+DR(omega=0.2)");
    let h = m.hessian(3, 1.0).unwrap();
    for j in 0..3 {
        assert_eq!(h[j][0][2], 0.0);
        assert_eq!(h[j][1][2], 0.0);
        assert_eq!(h[j][1][1], 0.0, "(sigma2, sigma2) = 0");
    }
    // METHODS §4.6: AR1(0.5, 1) (phi, phi) at tau = 2, 4, 8, 16; DR (omega, omega) = tau^2/8
    let h = model("AR1(phi=0.5, sigma2=1)+DR(omega=0.2)")
        .hessian(4, 1.0)
        .unwrap();
    for (j, want) in [0.2962963, 0.0, 1.015625, 2.2801971].iter().enumerate() {
        assert!((h[j][0][0] - want).abs() <= METHODS_TOL * want.abs().max(1.0));
        let tau = 2f64.powi(j as i32 + 1);
        assert!(close(h[j][2][2], tau * tau / 8.0, 1e-14));
    }
    assert!(model("WN(sigma2=1)").hessian(0, 1.0).is_err());
}

// ---------------------------------------------------------------- optimism (§8.2 test values)

fn wn_rw() -> (DMatrix<f64>, DMatrix<f64>) {
    let a = DMatrix::from_column_slice(3, 2, &[0.5, 0.25, 0.125, 0.25, 0.375, 0.6875]);
    let omega = DMatrix::from_diagonal(&DVector::from_vec(vec![1.0, 2.0, 3.0]));
    (a, omega)
}

#[test]
fn optimism_matches_methods_8_test_values() {
    let (a, omega) = wn_rw();
    // the A columns are the §4.5 derivatives of WN and RW at tau = 2, 4, 8
    let jac = model("WN(sigma2=1)+RW(gamma2=1)").jacobian(3, 1.0).unwrap();
    for j in 0..3 {
        assert!(close(jac[j][0], a[(j, 0)], 1e-15) && close(jac[j][1], a[(j, 1)], 1e-15));
    }
    let d = DMatrix::zeros(2, 2);
    let v_inv = omega.clone().try_inverse().unwrap();
    let v_band = DMatrix::from_row_slice(3, 3, &[1.0, 0.5, 0.2, 0.5, 1.0, 0.5, 0.2, 0.5, 1.0]);
    for conv in [OptimismConvention::Corrected, OptimismConvention::Package] {
        let o = |v: &DMatrix<f64>| asymptotic_optimism(&a, &d, &omega, v, conv).unwrap();
        // V = Omega^{-1}, D = 0: 2p (AIC-like)
        assert!(close(o(&v_inv), 4.0, 1e-12), "{conv:?}: {}", o(&v_inv));
        // V = I (diagonal: both trace orders agree)
        assert!(
            close(o(&DMatrix::identity(3, 3)), 8.299065, METHODS_TOL),
            "{conv:?}: {}",
            o(&DMatrix::identity(3, 3))
        );
    }
    let corrected =
        asymptotic_optimism(&a, &d, &omega, &v_band, OptimismConvention::Corrected).unwrap();
    let package =
        asymptotic_optimism(&a, &d, &omega, &v_band, OptimismConvention::Package).unwrap();
    assert!(close(package, 10.61682, METHODS_TOL), "{package}");
    assert!(close(corrected, 10.36262, METHODS_TOL), "{corrected}");
    // wrong sizes are errors, not panics
    assert!(asymptotic_optimism(
        &a,
        &d,
        &omega,
        &DMatrix::identity(2, 2),
        OptimismConvention::Corrected
    )
    .is_err());
}

#[test]
fn d_matrix_matches_methods_8_test_value() {
    // AR1(0.5, 1) + DR(0.2), tau = 2, 4, 8, Omega = I, nu_hat = nu x (1.1, 0.9, 1.05)
    let m = model("AR1(phi=0.5, sigma2=1)+DR(omega=0.2)");
    let nu = m.implied_wv(3, 1.0).unwrap().wv;
    let nu_hat: Vec<f64> = nu
        .iter()
        .zip([1.1, 0.9, 1.05])
        .map(|(a, b)| a * b)
        .collect();
    let d = d_matrix(
        &m.hessian(3, 1.0).unwrap(),
        &DMatrix::identity(3, 3),
        &nu,
        &nu_hat,
    )
    .unwrap();
    let want = [
        [-0.032034564, 0.001735644, 0.0],
        [0.001735644, 0.0, 0.0],
        [0.0, 0.0, -0.1188698],
    ];
    for k in 0..3 {
        for l in 0..3 {
            assert!(
                (d[(k, l)] - want[k][l]).abs() <= METHODS_TOL * want[k][l].abs().max(1e-3),
                "D[{k}][{l}] = {} vs {}",
                d[(k, l)],
                want[k][l]
            );
        }
    }
}

#[test]
fn optimism_derivative_uses_b_plus_d() {
    // dTheta = d theta_hat / d nu_hat' (METHODS §8.2, §13.15): refit AR1(phi, sigma2) exactly
    // (Newton on Q to convergence) to a WV it cannot match, perturb nu_hat level by level, and
    // compare the finite differences with (B + D)^{-1} A' Omega; (B - D)^{-1} must miss.
    let levels = 6;
    let freq = 1.0;
    let omega_w: Vec<f64> = (1..=levels).map(|j| 1.0 + j as f64).collect();
    let omega = DMatrix::from_diagonal(&DVector::from_column_slice(&omega_w));
    // target: AR1 + WN, so an AR1 alone leaves residuals and D != 0
    let nu_hat = model("AR1(phi=0.7, sigma2=1)+WN(sigma2=0.5)")
        .implied_wv(levels, freq)
        .unwrap()
        .wv;
    let template = model("AR1()");
    let fit = |nu_hat: &[f64]| -> Vec<f64> {
        let mut theta = vec![0.75, 1.2];
        for _ in 0..100 {
            let m = template.with_values(&theta).unwrap();
            let nu = m.implied_wv(levels, freq).unwrap().wv;
            let jac = m.jacobian(levels, freq).unwrap();
            let a = DMatrix::from_fn(levels, 2, |j, k| jac[j][k]);
            let d = d_matrix(&m.hessian(levels, freq).unwrap(), &omega, &nu, nu_hat).unwrap();
            let r = DVector::from_iterator(levels, nu.iter().zip(nu_hat).map(|(a, b)| a - b));
            let g = a.transpose() * &omega * r;
            let h = a.transpose() * &omega * &a + d;
            let step = h.try_inverse().unwrap() * g;
            theta[0] -= step[0];
            theta[1] -= step[1];
        }
        theta
    };
    let theta = fit(&nu_hat);
    let m = template.with_values(&theta).unwrap();
    let jac = m.jacobian(levels, freq).unwrap();
    let a = DMatrix::from_fn(levels, 2, |j, k| jac[j][k]);
    let nu = m.implied_wv(levels, freq).unwrap().wv;
    let d = d_matrix(&m.hessian(levels, freq).unwrap(), &omega, &nu, &nu_hat).unwrap();
    let b = a.transpose() * &omega * &a;
    assert!(d.norm() > 1e-2 * b.norm(), "D is visible: {d} vs B {b}");
    let plus = (&b + &d).try_inverse().unwrap() * a.transpose() * &omega;
    let minus = (&b - &d).try_inverse().unwrap() * a.transpose() * &omega;
    let mut miss = 0.0f64;
    for j in 0..levels {
        let h = 1e-6 * nu_hat[j];
        let mut up = nu_hat.clone();
        let mut dn = nu_hat.clone();
        up[j] += h;
        dn[j] -= h;
        let (tu, td) = (fit(&up), fit(&dn));
        for k in 0..2 {
            let fd = (tu[k] - td[k]) / (2.0 * h);
            // central differences of an exact refit: ~1e-8 relative of the column's scale
            let scale = plus.row(k).iter().fold(0.0f64, |s, v| s.max(v.abs()));
            assert!(
                (fd - plus[(k, j)]).abs() <= 1e-5 * scale,
                "theta_{k} level {j}: fd {fd} vs (B + D)^-1 A' Omega {}",
                plus[(k, j)]
            );
            miss = miss.max((fd - minus[(k, j)]).abs() / scale);
        }
    }
    assert!(
        miss > 1e-3,
        "(B - D)^-1 A' Omega should differ visibly: {miss}"
    );
}

/// Random fully specified models of the selection family (distinct AR1 phis keep A of full rank).
fn arb_model() -> impl Strategy<Value = Model> {
    (
        0usize..=2,
        prop::array::uniform4(any::<bool>()),
        prop::array::uniform4(0.0f64..1.0),
    )
        .prop_filter_map("non-empty", |(k, have, u)| {
            let mut terms = Vec::new();
            let phis = [0.2 + 0.3 * u[0], 0.9 + 0.09 * u[1]];
            for (i, phi) in phis.iter().take(k).enumerate() {
                terms.push(format!("AR1(phi={phi}, sigma2={})", 0.1 + u[2 + i]));
            }
            let values = [
                format!("WN(sigma2={})", 0.5 + u[0]),
                format!("QN(q2={})", 0.1 + u[1]),
                format!("RW(gamma2={})", 1e-4 * (1.0 + u[2])),
                format!("DR(omega={})", 1e-3 * (1.0 + u[3])),
            ];
            for (h, t) in have.iter().zip(values) {
                if *h {
                    terms.push(t);
                }
            }
            (!terms.is_empty()).then(|| Model::parse(&terms.join("+")).unwrap())
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// METHODS §8.2 sanity identity: D = 0 and V = Omega^{-1} give 2p, for any positive
    /// diagonal Omega, in both conventions.
    #[test]
    fn optimism_is_twice_the_parameter_count_when_v_is_omega_inverse(
        m in arb_model(),
        w in prop::collection::vec(0.1f64..10.0, 12),
    ) {
        let levels = 12;
        let jac = m.jacobian(levels, 1.0).unwrap();
        let p = m.n_params();
        let a = DMatrix::from_fn(levels, p, |j, k| jac[j][k]);
        let omega = DMatrix::from_diagonal(&DVector::from_column_slice(&w));
        let v = DMatrix::from_diagonal(&DVector::from_iterator(levels, w.iter().map(|x| 1.0 / x)));
        for conv in [OptimismConvention::Corrected, OptimismConvention::Package] {
            let o = asymptotic_optimism(&a, &DMatrix::zeros(p, p), &omega, &v, conv).unwrap();
            // the column scaling keeps B well conditioned; 1e-8 leaves room for AR1 columns
            // that are close to collinear
            prop_assert!(close(o, 2.0 * p as f64, 1e-8), "{m}: {conv:?} {o} vs {}", 2 * p);
        }
    }
}

// ---------------------------------------------------------------- candidates (§8.4, §8.5)

#[test]
fn nested_candidates_match_methods_8_4() {
    let c = nested_candidates(&model("3*AR1()+WN()+RW()+QN()+DR()")).unwrap();
    assert_eq!(c.len(), 63);
    let t: Vec<String> = c.iter().map(terms).collect();
    assert_eq!(&t[..3], ["AR1", "AR1 AR1", "AR1 AR1 AR1"]);
    assert_eq!(t.last().unwrap(), "WN RW QN DR");
    // byte order of the term lists, no duplicates, all in guess mode
    let lists: Vec<Vec<String>> = t
        .iter()
        .map(|s| s.split(' ').map(String::from).collect())
        .collect();
    assert!(lists.windows(2).all(|w| w[0] < w[1]));
    assert!(c.iter().all(Model::is_guess_mode));
    // the R reference's 31 candidates of 3*AR1()+WN()+RW()+QN()
    let c = nested_candidates(&model("3*AR1(phi=0.5, sigma2=1)+WN()+RW()+QN()")).unwrap();
    assert_eq!(c.len(), 31);
    let r = read_ref("auto_imu_adis_16405_imu1_gyro_x.json");
    let mut want: Vec<String> = r["auto_imu"]["candidates"]["model"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap().to_string())
        .collect();
    let mut got: Vec<String> = c.iter().map(terms).collect();
    want.sort();
    got.sort();
    assert_eq!(got, want);
}

#[test]
fn common_denominator_matches_methods_8_5() {
    let list = [
        model("AR1()+WN()"),
        model("2*AR1()+RW()"),
        model("QN()+DR()"),
    ];
    let d = common_denominator(&list).unwrap();
    assert_eq!(terms(&d), "AR1 AR1 WN QN RW DR");
    // added as an extra candidate when absent, and the full model
    let wic = Wic::list(&list).unwrap();
    assert_eq!(wic.candidates().len(), 4);
    assert_eq!(wic.full_model(), &d);
    assert_eq!(wic.candidates()[3], d);
    // a given model with the same terms (any order) plays the full model; duplicates merge
    let wic =
        Wic::parse_list(&["AR1()+WN()", "WN()+2*AR1()", "AR1(phi=0.5, sigma2=1)+WN()"]).unwrap();
    assert_eq!(wic.candidates().len(), 2);
    assert_eq!(wic.full_model().to_string(), "WN()+2*AR1()");
    // GM lists count GM
    assert_eq!(
        terms(&common_denominator(&[model("GM()+WN()"), model("2*GM()")]).unwrap()),
        "GM GM WN"
    );
}

#[test]
fn selection_refuses_unsupported_candidates_by_name() {
    let e = Wic::parse_list(&["AR1()+WN()", "ARMA(1,1)+WN()"]).unwrap_err();
    assert!(matches!(e, SelectionError::ArmaNotSupported { .. }), "{e}");
    assert!(e.to_string().contains("candidate ARMA(1,1)+WN()"), "{e}");
    for full in ["AR1()+MA1()", "ARMA11()", "AR(2)+WN()"] {
        let e = Wic::nested(model(full)).unwrap_err();
        assert!(
            e.to_string().contains("not supported in model selection"),
            "{e}"
        );
    }
    let e = Wic::parse_list(&["GM()+WN()", "AR1()+RW()"]).unwrap_err();
    assert!(matches!(e, SelectionError::GmAr1Mixed { .. }), "{e}");
    // duplicated WN: refused by the model rules, reported with the candidate's position
    let e = Wic::parse_list(&["AR1()+WN()", "WN()+RW()+WN()"]).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.starts_with("candidate 2 (\"WN()+RW()+WN()\"):"),
        "{msg}"
    );
    assert!(msg.contains("found WN 2 times"), "{msg}");
    assert!(matches!(
        Wic::parse_list::<&str>(&[]),
        Err(SelectionError::NoCandidates)
    ));
    // settings
    let x = simulate_model(&model("WN(sigma2=1)"), 512, 1.0, 1).unwrap();
    let wic = Wic::nested(model("WN()+RW()")).unwrap();
    assert!(matches!(
        wic.clone().with_bootstrap(1).select(&x, 1.0),
        Err(SelectionError::Setting { .. })
    ));
    assert!(wic.clone().with_draws(0).select(&x, 1.0).is_err());
    assert!(wic.select(&x, 0.0).is_err());
    assert!(wic.select(&[1.0; 100], 1.0).is_err());
}
