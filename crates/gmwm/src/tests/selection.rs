//! Model selection by WIC (docs/methods.md §8): the model Hessian (§4.6), the §8 test values,
//! candidate enumeration, seeded Monte Carlo and the R package's auto_imu on real data.

use crate::tests::common::{data_dir, f64s, read_column, read_ref};
use gmwm::imu::{read_table, Imu, ReadOptions};
use gmwm::model::Model;
use gmwm::selection::wic::WIC_TIE_REL;
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

/// The docs/methods.md §8 test values are printed with 7 significant digits.
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
    // docs/methods.md §4.6: AR1(0.5, 1) (phi, phi) at tau = 2, 4, 8, 16; DR (omega, omega) =
    // tau^2/8
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
    // dTheta = d theta_hat / d nu_hat' (docs/methods.md §8.2, §13.15): refit AR1(phi, sigma2)
    // exactly (Newton on Q to convergence) to a WV it cannot match, perturb nu_hat level by level,
    // and compare the finite differences with (B + D)^{-1} A' Omega; (B - D)^{-1} must miss.
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

    /// docs/methods.md §8.2 sanity identity: D = 0 and V = Omega^{-1} give 2p, for any positive
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

// ---------------------------------------------------------------- the procedure (§8.6)

#[test]
fn selection_is_deterministic_and_consistent() {
    let truth = model("AR1(phi=0.95, sigma2=0.1)+WN(sigma2=1)+RW(gamma2=1e-2)");
    let x = simulate_model(&truth, 4000, 100.0, 21).unwrap();
    let wic = Wic::nested(model("AR1()+WN()+RW()+QN()"))
        .unwrap()
        .with_draws(400)
        .with_bootstrap(30);
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| wic.select(&x, 100.0).unwrap())
    };
    let s = run(2);
    assert_eq!(
        s,
        run(1),
        "same seed, same result, whatever the thread count"
    );
    assert_eq!(s.candidates().len(), 15);
    // sorted by WIC; within a tie (WIC_TIE_REL) the smaller model comes first
    assert!(s
        .candidates()
        .windows(2)
        .all(|w| w[0].wic <= w[1].wic * (1.0 + WIC_TIE_REL)));
    for c in s.candidates() {
        assert_eq!(c.wic, c.objective + c.optimism);
        assert!(c.optimism > 0.0, "{c:?}");
        // J = 11 levels, B = 30 > J + 2: every candidate has a J-test p-value in [0, 1]
        let p = c.gof_p_value.unwrap();
        assert!((0.0..=1.0).contains(&p), "{c:?}");
    }
    assert_eq!(*s.selected(), s.candidates()[0].model);
    assert_eq!(s.fit().model().without_values(), *s.selected());
    assert_eq!(s.fit().objective(), s.candidates()[0].objective);
    // the full model's row is the full fit against the same WV
    let full = s
        .candidates()
        .iter()
        .find(|c| c.model == *s.full_model())
        .unwrap();
    let direct = gmwm::Gmwm::new(s.full_model().clone())
        .with_draws(400)
        .fit(&x, 100.0, &gmwm::WvOptions::default())
        .unwrap();
    assert_eq!(full.objective, direct.objective());
    // white noise alone cannot follow the AR1 bump around tau ~ 40 samples
    let wn = s
        .candidates()
        .iter()
        .find(|c| terms(&c.model) == "WN")
        .unwrap();
    assert!(wn.wic > s.candidates()[0].wic + 1.0, "{wn:?}");
    // the package's formula gives other optimism values on the same fits
    let pkg = wic
        .clone()
        .with_convention(OptimismConvention::Package)
        .select(&x, 100.0)
        .unwrap();
    let (a, b) = (
        &s.candidates()[0],
        pkg.candidates()
            .iter()
            .find(|c| c.model == s.candidates()[0].model)
            .unwrap(),
    );
    assert_eq!(a.objective, b.objective);
    assert_ne!(a.optimism, b.optimism);
}

#[test]
fn bootstrap_optimism_agrees_with_the_asymptotic_one() {
    // docs/methods.md §8.3 vs §8.2 on the true model: both estimate the same expected excess loss.
    let truth = model("AR1(phi=0.9, sigma2=1)+WN(sigma2=2)");
    let x = simulate_model(&truth, 4000, 1.0, 5).unwrap();
    let base = Wic::parse_list(&["AR1()+WN()"]).unwrap().with_draws(300);
    let asym = base.clone().with_bootstrap(200).select(&x, 1.0).unwrap();
    let boot = base
        .with_bootstrap(200)
        .with_optimism(OptimismMethod::Bootstrap)
        .with_bootstrap_draws(200)
        .select(&x, 1.0)
        .unwrap();
    let (a, b) = (&asym.candidates()[0], &boot.candidates()[0]);
    assert_eq!(a.objective, b.objective);
    // 200 replicates: a covariance estimate with ~10% relative error; allow 30%
    assert!(
        (b.optimism / a.optimism - 1.0).abs() < 0.3,
        "bootstrap {} vs asymptotic {}",
        b.optimism,
        a.optimism
    );
    let p = b.gof_p_value.unwrap();
    assert!((0.0..=1.0).contains(&p));
    // a p-value is a share of 200 replicates
    assert_eq!((p * 200.0).round() / 200.0, p);
}

#[test]
fn bootstrap_optimism_refits_a_candidate_whose_drift_collapsed() {
    // A drift fitted to a driftless series goes to omega = 0, the boundary of its transform:
    // the replicates' refits start from the active sub-model instead (they used to fail with
    // "DR[2].omega = 0 is outside the domain of its transform").
    let truth = model("AR1(phi=0.9, sigma2=1)+WN(sigma2=2)");
    // seed 6: the drift's estimate is exactly 0 (seeds 17 and 26 too; most seeds stop at
    // omega ~ 1e-7, which the transforms accept)
    let x = simulate_model(&truth, 4000, 1.0, 6).unwrap();
    // the candidate's fit as the selection makes it (seed 1337, G = 300) has omega exactly 0
    let dr_fit = gmwm::Gmwm::parse("AR1()+WN()+DR()")
        .unwrap()
        .with_seed(1337)
        .with_draws(300)
        .fit(&x, 1.0, &gmwm::WvOptions::default())
        .unwrap();
    assert_eq!(dr_fit.theta()[3], 0.0);
    let s = Wic::parse_list(&["AR1()+WN()", "AR1()+WN()+DR()"])
        .unwrap()
        .with_draws(300)
        .with_bootstrap(20)
        .with_optimism(OptimismMethod::Bootstrap)
        .with_bootstrap_draws(100)
        .select(&x, 1.0)
        .unwrap();
    let with_dr = s
        .candidates()
        .iter()
        .find(|c| c.model.n_components() == 3)
        .unwrap();
    let without = s
        .candidates()
        .iter()
        .find(|c| c.model.n_components() == 2)
        .unwrap();
    // the drift is inactive: same objective as the sub-model (optimiser tolerance)
    assert!(close(with_dr.objective, without.objective, 1e-6));
    assert!(with_dr.optimism.is_finite() && with_dr.optimism > 0.0);
    assert_eq!(s.selected().to_string(), "AR1()+WN()");
}

#[test]
fn bootstrap_optimism_runs_once_per_tie_group() {
    // A drift fitted to a driftless random walk is fitted to nothing: RW() and RW()+DR() are one
    // fit. Their bootstrap is the representative's (the smaller one's), as their asymptotic
    // optimisms agree; bootstrapped apart, the drift's refits on the replicates (where it is
    // active) gave RW()+DR() 0.60 against RW()'s -0.0001 on adis_16405_imu1 gyro_x.
    let truth = model("RW(gamma2=1e-4)+WN(sigma2=1)");
    // seed 22: the drift stops at a tiny positive omega (objectives 1e-11 apart), which the
    // refits on the replicates can grow; at seeds where it is exactly 0 the active sub-model
    // leaves it out anyway
    let x = simulate_model(&truth, 20_000, 1.0, 22).unwrap();
    let select = |list: &[&str]| {
        Wic::parse_list(list)
            .unwrap()
            .with_draws(300)
            .with_bootstrap(10)
            .with_optimism(OptimismMethod::Bootstrap)
            .with_bootstrap_draws(100)
            .select(&x, 1.0)
            .unwrap()
    };
    let pair = select(&["RW()+WN()", "RW()+WN()+DR()"]);
    let [a, b] = pair.candidates() else {
        panic!("two candidates")
    };
    assert_eq!(a.canonical_model, b.canonical_model);
    assert!(
        close(a.objective, b.objective, 1e-6),
        "{} {}",
        a.objective,
        b.objective
    );
    assert_eq!(a.optimism, b.optimism);
    assert_eq!(a.gof_p_value, b.gof_p_value);
    // and it is the smaller candidate's own bootstrap, bit for bit (same seed, same fit)
    let alone = select(&["RW()+WN()"]);
    assert_eq!(alone.candidates()[0].optimism, a.optimism);
    assert_eq!(alone.candidates()[0].gof_p_value, a.gof_p_value);
}

/// The expected excess of the out-of-sample loss over the in-sample loss, by Monte Carlo:
/// `R` fits of `candidate` to series from `truth`, each scored against the WV of an independent
/// series with the fit's own weights; returns (mean excess, its standard error, mean
/// asymptotic optimism with the true V).
fn excess_loss(truth: &Model, candidate: &str, n: usize, reps: usize) -> (f64, f64, f64) {
    use gmwm::fit::{Gmwm, StartInputs};
    use gmwm::inference::wv_bootstrap;
    use gmwm::{wavelet_variance, WvOptions};
    use rayon::prelude::*;
    let freq = 100.0;
    let opts = WvOptions::default();
    let x0 = simulate_model(truth, n, freq, 1).unwrap();
    let levels = wavelet_variance(&x0, freq, &opts).unwrap().levels();
    let fixed = WvOptions {
        levels: Some(levels),
        ..opts
    };
    // "true" V from 400 replicates (its own error ~7%, well inside the tolerance below)
    let v = wv_bootstrap(truth, n, freq, &fixed, 400, 77).unwrap().cov;
    let cand = model(candidate);
    let res: Vec<(f64, f64)> = (0..reps)
        .into_par_iter()
        .map(|r| {
            let x = simulate_model(truth, n, freq, 10_000 + r as u64).unwrap();
            let y = simulate_model(truth, n, freq, 90_000 + r as u64).unwrap();
            let wv = wavelet_variance(&x, freq, &fixed).unwrap();
            let wv_new = wavelet_variance(&y, freq, &fixed).unwrap();
            let fit = Gmwm::new(cand.clone())
                .with_draws(2000)
                .fit_from_wv(&wv, StartInputs::from_series(&x))
                .unwrap();
            let w = &fit.weights().omega;
            let q_new: f64 = (0..levels)
                .map(|j| w[j] * (wv_new.wv()[j] - fit.implied_wv().wv[j]).powi(2))
                .sum();
            let jac = fit.model().jacobian(levels, freq).unwrap();
            let p = fit.theta().len();
            let a = DMatrix::from_fn(levels, p, |j, k| jac[j][k]);
            let omega = DMatrix::from_diagonal(&DVector::from_column_slice(w));
            let h = fit.model().hessian(levels, freq).unwrap();
            let d = d_matrix(&h, &omega, &fit.implied_wv().wv, fit.nu_hat()).unwrap();
            let o = asymptotic_optimism(&a, &d, &omega, &v, OptimismConvention::Corrected).unwrap();
            (q_new - fit.objective(), o)
        })
        .collect();
    let k = reps as f64;
    let mean = res.iter().map(|r| r.0).sum::<f64>() / k;
    let sd = (res.iter().map(|r| (r.0 - mean).powi(2)).sum::<f64>() / (k - 1.0)).sqrt();
    let opt = res.iter().map(|r| r.1).sum::<f64>() / k;
    (mean, sd / k.sqrt(), opt)
}

#[test]
fn asymptotic_optimism_estimates_the_out_of_sample_excess_loss() {
    // docs/methods.md §8.1: optimism = E[loss on new data] - E[apparent loss], checked against its
    // definition by Monte Carlo for the true model and two over-fitted ones (a superfluous QN
    // and DR; a second AR1, whose phi is not identified at the truth).
    let truth = model("AR1(phi=0.95, sigma2=0.1)+WN(sigma2=1)+RW(gamma2=1e-2)");
    for candidate in [
        "AR1()+WN()+RW()",
        "AR1()+WN()+RW()+QN()+DR()",
        "2*AR1()+WN()+RW()",
    ] {
        let (excess, se, opt) = excess_loss(&truth, candidate, 10_000, 200);
        // 4 standard errors of the Monte Carlo mean plus 10% for the asymptotic
        // approximation and the estimated V
        assert!(
            (opt - excess).abs() <= 4.0 * se + 0.1 * excess.abs(),
            "{candidate}: mean optimism {opt} vs excess loss {excess} +- {se}"
        );
    }
}

/// Seeded Monte Carlo of docs/methods.md §8.6 selection: `reps` series of length `n` at 100 Hz from
/// the truth, the nested candidates of `full`, G = `draws`, B = `replicates` for V; returns
/// (true model selected, a strict sub-model of the truth selected) counts.
fn selection_mc(
    truth: &Model,
    full: &str,
    n: usize,
    reps: usize,
    draws: usize,
    replicates: usize,
) -> (usize, usize) {
    let wic = Wic::nested(model(full))
        .unwrap()
        .with_draws(draws)
        .with_bootstrap(replicates);
    let kinds = truth.kinds();
    let (mut hits, mut under) = (0, 0);
    for r in 0..reps {
        let x = simulate_model(truth, n, 100.0, 1000 + r as u64).unwrap();
        let s = wic.select(&x, 100.0).unwrap();
        let sel = s.selected().kinds();
        if sel == kinds {
            hits += 1;
        } else if sel.len() < kinds.len() && sel.iter().all(|k| kinds.contains(k)) {
            under += 1;
        }
    }
    eprintln!("{full}: true model {hits}/{reps}, a sub-model {under}/{reps}");
    (hits, under)
}

/// The truth of the selection Monte Carlo: AR1, WN and RW each dominate a band of scales
/// (WN below tau ~ 8, the AR1 bump around tau ~ 40, RW above tau ~ 200).
const MC_TRUTH: &str = "AR1(phi=0.95, sigma2=0.1)+WN(sigma2=1)+RW(gamma2=1e-3)";

#[test]
fn wic_selects_the_true_model_among_nested_candidates() {
    // Issue 5's must-show at its size: N = 1e5, 100 replicates, the package's B = 50, G =
    // 2000 (about 20 s on 2 cores). Every term of the full model AR1+WN+RW+QN+DR is identified
    // when present, so the only errors an AIC-type criterion makes are the superfluous QN
    // or DR (about 8% each, see the selection module docs): 94/100 measured with the WIC
    // minimum alone; 100/100 since the choice among the rows within one standard error of it
    // (issue 10). Bound: issue 10's 0.9 (0.97 less 3 binomial standard errors at 100
    // replicates is 0.92). An underfit (a strict sub-model of the truth) must not happen: each
    // term dominates a band of scales.
    let truth = model(MC_TRUTH);
    let reps = 100;
    let (hits, under) = selection_mc(&truth, "AR1()+WN()+RW()+QN()+DR()", 100_000, reps, 2000, 50);
    assert!(hits >= 90, "true model selected in {hits}/{reps}");
    assert_eq!(
        under, 0,
        "a sub-model of the truth selected in {under}/{reps}"
    );
}

#[test]
fn wic_with_a_second_ar1_in_the_full_model_still_never_underfits() {
    // Issue 5's example of a full model, 2*AR1+WN+RW+QN+DR, at N = 1e4 (seconds): a second
    // AR1 is not identified when its variance is 0 (its phi is free) and can stand in for the
    // RW (phi -> 1) or the WN (phi -> 0); with the WIC minimum alone the true model won 74/100
    // at N = 1e4 and 138/200 at N = 1e5 with the RW of MC_TRUTH. Since the canonical rows and
    // the choice within one standard error (issue 10): 39/40 here, 191/200 at N = 1e5 (the
    // ignored test below). Bounds: 0.9 less 3 binomial standard errors at 40 replicates is
    // 0.76; at most one underfit (none measured). At N = 1e4 the RW needs gamma2 = 1e-2 to
    // dominate the coarse scales.
    let truth = model("AR1(phi=0.95, sigma2=0.1)+WN(sigma2=1)+RW(gamma2=1e-2)");
    let reps = 40;
    let (hits, under) = selection_mc(
        &truth,
        "2*AR1()+WN()+RW()+QN()+DR()",
        10_000,
        reps,
        1000,
        20,
    );
    assert!(hits >= 30, "true model selected in {hits}/{reps}");
    assert!(
        under <= 1,
        "a sub-model of the truth selected in {under}/{reps}"
    );
}

#[test]
#[ignore = "about 90 s in release on 2 cores; run with cargo test --release -p gmwm --lib wic_second_ar1_full_size -- --ignored --nocapture"]
fn wic_second_ar1_full_size() {
    // The figure quoted above for issue 5's example at its size: N = 1e5, 200 replicates,
    // full model 2*AR1+WN+RW+QN+DR, B = 50: 191/200 measured (138/200 with the WIC minimum
    // alone, whose misses were a second AR1 standing in for the RW 25, for the WN 9, added to
    // the truth 12, and a superfluous QN or DR 16).
    let truth = model(MC_TRUTH);
    let reps = 200;
    let (hits, under) = selection_mc(
        &truth,
        "2*AR1()+WN()+RW()+QN()+DR()",
        100_000,
        reps,
        2000,
        50,
    );
    eprintln!("true model selected in {hits}/{reps}, a sub-model in {under}/{reps}");
    assert!(hits >= 175, "true model selected in {hits}/{reps}");
    assert_eq!(under, 0);
}

#[test]
fn auto_imu_tags_every_axis() {
    use gmwm::imu::{Column, Sensor, SensorInfo};
    let truth = model("AR1(phi=0.9, sigma2=1)+WN(sigma2=2)");
    let col = |name: &str, seed| Column {
        name: name.into(),
        values: simulate_model(&truth, 2000, 50.0, seed).unwrap(),
    };
    let info = |sensor, axis: &str| SensorInfo {
        sensor,
        axis: axis.into(),
        unit: None,
    };
    let imu = Imu::new(
        vec![col("a_z", 1), col("g_x", 2)],
        vec![
            info(Sensor::Accelerometer, "Z"),
            info(Sensor::Gyroscope, "X"),
        ],
        50.0,
    )
    .unwrap();
    let wic = Wic::nested(model("AR1()+WN()"))
        .unwrap()
        .with_draws(200)
        .with_bootstrap(10);
    let s = auto_imu(&imu, &wic).unwrap();
    assert_eq!(s.freq_hz, 50.0);
    let tags: Vec<(&str, Sensor, &str)> = s
        .axes
        .iter()
        .map(|a| (a.axis.as_str(), a.sensor, a.label.as_str()))
        .collect();
    assert_eq!(
        tags,
        [
            ("gyro_x", Sensor::Gyroscope, "X"),
            ("accel_z", Sensor::Accelerometer, "Z")
        ]
    );
    // each axis is the single-series selection of its column
    let alone = wic.select(imu.axes()[0].values(), 50.0).unwrap();
    assert_eq!(s.axes[0].selection, alone);
    assert!(s
        .to_string()
        .starts_with("gyro_x (Gyroscope X)\nWIC model selection"));
}

// ---------------------------------------------------------------- real data vs the R package

#[test]
fn auto_imu_gyro_x_objectives_are_no_worse_than_the_r_package() {
    // R: auto_imu(x[, 1], model = 3*AR1()+WN()+RW()+QN()) on adis_16405_imu1 gyro_x (G = 1e6,
    // seed 1337). Every candidate is fitted against the same WV and fast weights in both, so
    // the objectives are comparable: ours must be at least as low (README finding 3: the
    // package's guessed fits often stop in poor local minima). The optimism depends on the
    // bootstrap V (RNG) and the formula (§13.15), so only the objectives are compared.
    let r = read_ref("auto_imu_adis_16405_imu1_gyro_x.json");
    let x = read_column("adis_16405_imu1", "gyro_x");
    let s = Wic::nested(model("3*AR1()+WN()+RW()+QN()"))
        .unwrap()
        .with_bootstrap(10)
        .select(&x, 100.0)
        .unwrap();
    let rc = &r["auto_imu"]["candidates"];
    let names: Vec<&str> = rc["model"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    let obj = f64s(&rc["obj_fun"]);
    assert_eq!(s.candidates().len(), names.len());
    for (name, r_obj) in names.iter().zip(&obj) {
        let ours = s
            .candidates()
            .iter()
            .find(|c| terms(&c.model) == *name)
            .unwrap();
        // 1e-6 relative: the two objectives agree to the optimiser's tolerance when both reach
        // the same minimum
        assert!(
            ours.objective <= r_obj * (1.0 + 1e-6),
            "{name}: ours {} vs R {r_obj}",
            ours.objective
        );
    }
    // the same weights: R's selected estimate scored with our WV and weights gives R's value
    let sel = &r["auto_imu"]["selected"];
    let est = f64s(&sel["estimate"]);
    let r_model = model(&format!(
        "AR1(phi={}, sigma2={})+AR1(phi={}, sigma2={})+RW(gamma2={})",
        est[0], est[1], est[2], est[3], est[4]
    ));
    let implied = r_model
        .implied_wv(s.fit().nu_hat().len(), 100.0)
        .unwrap()
        .wv;
    let q: f64 = (0..implied.len())
        .map(|j| s.fit().weights().omega[j] * (s.fit().nu_hat()[j] - implied[j]).powi(2))
        .sum();
    let r_q = sel["obj_fun"].as_f64().unwrap();
    // the estimates are printed to 16 digits; 1e-6 relative covers their rounding in Q
    assert!(close(q, r_q, 1e-6), "Q at R's estimate: {q} vs R {r_q}");
}

#[test]
#[ignore = "six axes of 1e6 samples, 63 candidates each: about 3 minutes in release on 2 cores; run with cargo test --release -p gmwm --lib auto_imu_adis_six_axes -- --ignored --nocapture"]
fn auto_imu_adis_six_axes() {
    let path = data_dir().join("adis_16405_imu1.csv.gz");
    let table = read_table(
        &path,
        &ReadOptions {
            freq_hz: Some(100.0),
            ..ReadOptions::default()
        },
    )
    .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let imu = Imu::from_table(table).unwrap();
    let wic = Wic::nested(model("3*AR1()+WN()+RW()+QN()+DR()")).unwrap();
    let s = auto_imu(&imu, &wic).unwrap();
    assert_eq!(s.axes.len(), 6);
    for a in &s.axes {
        let full = a
            .selection
            .candidates()
            .iter()
            .find(|c| c.model == *a.selection.full_model())
            .unwrap();
        eprintln!(
            "{}: selected {} (WIC {:.6}, objective {:.6}); full model WIC {:.6}",
            a.axis,
            a.selection.selected(),
            a.selection.candidates()[0].wic,
            a.selection.candidates()[0].objective,
            full.wic
        );
        assert_eq!(a.selection.candidates().len(), 63);
        // the full model is a candidate: the winner is no worse, up to the tie rule (a
        // smaller model within WIC_TIE_REL of a larger one ranks first)
        assert!(
            a.selection.candidates()[0].wic <= full.wic * (1.0 + gmwm::selection::wic::WIC_TIE_REL)
        );
    }
    let tags: Vec<&str> = s.axes.iter().map(|a| a.axis.as_str()).collect();
    assert_eq!(
        tags,
        ["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"]
    );
}

// ---------------------------------------------------------------- canonical rows (issue 10)

#[test]
fn selection_rows_fold_the_candidates_by_canonical_model() {
    use gmwm::selection::RowStatus;
    let truth = model("AR1(phi=0.95, sigma2=0.1)+WN(sigma2=1)+RW(gamma2=1e-3)");
    let x = simulate_model(&truth, 20_000, 100.0, 31).unwrap();
    let s = Wic::nested(model("2*AR1()+WN()+RW()+QN()+DR()"))
        .unwrap()
        .with_draws(500)
        .with_bootstrap(30)
        .select(&x, 100.0)
        .unwrap();
    // one row per canonical model; the rows' members partition the candidates
    let keys: Vec<String> = s
        .rows()
        .iter()
        .map(|r| r.score.canonical_model.to_string())
        .collect();
    let mut unique = keys.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), keys.len(), "{keys:?}");
    let mut members: Vec<String> = s
        .rows()
        .iter()
        .flat_map(|r| r.members.iter().map(Model::to_string))
        .collect();
    members.sort();
    let mut all: Vec<String> = s.candidates().iter().map(|c| c.model.to_string()).collect();
    all.sort();
    assert_eq!(members, all);
    let log_variance = gmwm::wavelet_variance(&x, 100.0, &gmwm::WvOptions::default())
        .unwrap()
        .log_variance();
    for row in s.rows() {
        // the row shows its best member's scores, or those of a smaller member whose fit the
        // data cannot tell from the best one's (the smallest such); each member reads as the row
        let fit_of = |m: &Model| s.candidate_fit(m).unwrap();
        let best = row
            .members
            .iter()
            .min_by(|a, b| {
                let wic = |m: &Model| s.candidates().iter().find(|c| &c.model == m).unwrap().wic;
                wic(a).total_cmp(&wic(b))
            })
            .unwrap();
        let close = |m: &Model| {
            gmwm::fit::canonical::wv_separation(
                &fit_of(m).implied_wv().wv,
                &fit_of(best).implied_wv().wv,
                &log_variance,
            ) <= gmwm::fit::SEPARATION_LIMIT
        };
        assert!(close(&row.score.model), "{}", row.score.canonical_model);
        for m in &row.members {
            if m.n_params() < row.score.model.n_params() {
                assert!(
                    !close(m),
                    "{m} is smaller and as good as {}",
                    row.score.model
                );
            }
        }
        for m in &row.members {
            let c = s.candidates().iter().find(|c| &c.model == m).unwrap();
            assert_eq!(c.canonical_model, row.score.canonical_model);
            let f = s.candidate_fit(m).unwrap();
            assert_eq!(f.canonical().unwrap().model, row.score.canonical_model);
        }
        let c = s
            .candidates()
            .iter()
            .find(|c| c.model == row.score.model)
            .unwrap();
        assert_eq!(c, &row.score);
        assert!(row.delta_wic_se >= 0.0 && row.delta_wic >= -1e-12 * row.score.wic.abs());
    }
    // sorted by WIC; the first row is the minimum, exactly one row is selected, and it is
    // the minimum or within one standard error of it
    assert!(s
        .rows()
        .windows(2)
        .all(|w| w[0].score.wic <= w[1].score.wic * (1.0 + WIC_TIE_REL)));
    assert_eq!(s.rows()[0].delta_wic, 0.0);
    let selected: Vec<_> = s
        .rows()
        .iter()
        .filter(|r| r.status == RowStatus::Selected)
        .collect();
    assert_eq!(selected.len(), 1);
    let sel = selected[0];
    assert!(sel.delta_wic <= sel.delta_wic_se, "{sel:?}");
    assert_eq!(sel.score.canonical_model, s.selected_canonical().model);
    assert_eq!(sel.score.model, *s.selected());
    assert_eq!(s.fit().model().without_values(), *s.selected());
    assert_eq!(
        s.selected_canonical().model.to_string(),
        "AR1()+WN()+RW()",
        "{s}"
    );
}

#[test]
fn wic_difference_se_matches_its_formula() {
    use gmwm::selection::wic::wic_difference_se;
    // one level, Omega = V = 1, fits 1 apart, equal optimisms: 2 |d| = 2
    let v = DMatrix::identity(1, 1);
    let se = wic_difference_se((&[2.0], 0.5, 3), (&[1.0], 0.5, 3), &[1.0], &v);
    assert!(close(se, 2.0, 1e-15), "{se}");
    // plus the second-order term of one extra parameter: (opt_a - opt_b)^2 / 2
    let se = wic_difference_se((&[2.0], 2.5, 4), (&[1.0], 0.5, 3), &[1.0], &v);
    assert!(close(se, (4.0f64 + 2.0).sqrt(), 1e-15), "{se}");
    // two levels with a correlated V: 4 g' V g with g = Omega d
    let v = DMatrix::from_row_slice(2, 2, &[2.0, 0.5, 0.5, 1.0]);
    let se = wic_difference_se(
        (&[1.0, 3.0], 1.0, 2),
        (&[0.0, 1.0], 1.0, 2),
        &[3.0, 0.5],
        &v,
    );
    // g = (3, 1): g' V g = 18 + 3 + 1 = 22
    assert!(close(se, (4.0f64 * 22.0).sqrt(), 1e-15), "{se}");
}

#[test]
fn estimation_refuses_a_non_haar_wavelet_variance() {
    use gmwm::fit::FitError;
    use gmwm::{WaveletFilter, WvOptions};
    let x = simulate_model(&model("AR1(phi=0.9, sigma2=1)+WN(sigma2=1)"), 4000, 1.0, 2).unwrap();
    let la8 = WvOptions {
        filter: WaveletFilter::La8,
        ..WvOptions::default()
    };
    let g = gmwm::Gmwm::parse("AR1()+WN()").unwrap().with_draws(100);
    for r in [
        g.fit(&x, 1.0, &la8),
        g.fit_series(&x, 1.0, &la8, &[0.9, 1.0, 1.0]),
        g.fit_from_wv(
            &gmwm::wavelet_variance(&x, 1.0, &la8).unwrap(),
            gmwm::fit::StartInputs::from_series(&x),
        ),
    ] {
        let e = r.unwrap_err();
        assert!(matches!(e, FitError::NotHaar { .. }), "{e}");
        assert!(e.to_string().contains("la8"), "{e}");
    }
    let e = Wic::nested(model("AR1()+WN()"))
        .unwrap()
        .with_draws(100)
        .with_wv_options(la8)
        .select(&x, 1.0)
        .unwrap_err();
    assert!(e.to_string().contains("Haar"), "{e}");
    let fit = g.fit(&x, 1.0, &WvOptions::default()).unwrap();
    let e = gmwm::inference::infer(&g, &fit, x.len(), &la8, &Default::default()).unwrap_err();
    assert!(matches!(e, FitError::NotHaar { .. }), "{e}");
}

#[test]
fn bootstrap_gof_p_value_is_a_bound_when_no_replicate_exceeds() {
    // white noise alone on AR1 + WN data: every fresh fit of a replicate lies far below the
    // observed objective, so the p-value is reported as below 1 / (B + 1)
    let x = simulate_model(
        &model("AR1(phi=0.99, sigma2=0.1)+WN(sigma2=1)"),
        4000,
        1.0,
        7,
    )
    .unwrap();
    let b = 20;
    let s = Wic::parse_list(&["WN()", "AR1()+WN()"])
        .unwrap()
        .with_draws(200)
        .with_bootstrap(b)
        .with_optimism(OptimismMethod::Bootstrap)
        .with_bootstrap_draws(100)
        .select(&x, 1.0)
        .unwrap();
    let wn = s
        .candidates()
        .iter()
        .find(|c| terms(&c.model) == "WN")
        .unwrap();
    assert!(wn.gof_p_value_upper_bound, "{wn:?}");
    assert_eq!(wn.gof_p_value, Some(1.0 / (b as f64 + 1.0)));
    let row = s.rows().iter().find(|r| r.score.model == wn.model).unwrap();
    assert!(row.score.gof_p_value_upper_bound);
    assert!(
        s.to_string()
            .contains(&format!("<{:.2e}", 1.0 / (b as f64 + 1.0))),
        "{s}"
    );
}

/// The issue 10 Monte Carlo (figures of one replicate set): per replicate, the selected
/// canonical model against the truth `AR1(phi=0.99, sigma2=1e-3) + WN(1) + RW(1e-6)` at N =
/// 1e5 (the random walk shows only at the last three or four scales), and the white-noise and
/// random-walk densities of the selected canonical model against those of the true model
/// fitted to the same replicate (read the same way).
struct Issue10 {
    reps: usize,
    /// Exactly one AR1, a WN and a RW (any QN or DR allowed).
    core: usize,
    /// Exactly AR1()+WN()+RW().
    exact: usize,
    /// WN density within 10% and RW density within 50% of the true model's fit.
    densities: usize,
    /// Replicates where the true model's own fit has no random walk.
    truth_without_rw: usize,
    /// Superfluous QN or DR in the selected canonical model.
    superfluous: usize,
    /// How often each canonical model was selected.
    selected: std::collections::BTreeMap<String, usize>,
}

fn issue_10_mc(full: &str, reps: usize) -> Issue10 {
    use gmwm::model::ProcessKind;
    use rayon::prelude::*;
    let truth = model("AR1(phi=0.99, sigma2=1e-3)+WN(sigma2=1)+RW(gamma2=1e-6)");
    let true_model = model("AR1()+WN()+RW()");
    let wic = Wic::nested(model(full))
        .unwrap()
        .with_draws(2000)
        .with_bootstrap(50);
    let rows: Vec<([bool; 5], String)> = (0..reps)
        .into_par_iter()
        .map(|r| {
            let x = simulate_model(&truth, 100_000, 100.0, 1000 + r as u64).unwrap();
            let s = wic.select(&x, 100.0).unwrap();
            let c = &s.selected_canonical();
            let t = s.candidate_fit(&true_model).unwrap().canonical().unwrap();
            let density =
                |m: &gmwm::fit::CanonicalModel, k, name| m.physical(k, name).unwrap_or(0.0);
            let (n, n0) = (
                density(c, ProcessKind::Wn, "white_noise_density"),
                density(&t, ProcessKind::Wn, "white_noise_density"),
            );
            let (k, k0) = (
                density(c, ProcessKind::Rw, "rate_random_walk_density"),
                density(&t, ProcessKind::Rw, "rate_random_walk_density"),
            );
            let flags = [
                c.correlated_terms() == 1
                    && c.model.count(ProcessKind::Wn) == 1
                    && c.model.count(ProcessKind::Rw) == 1,
                c.model.to_string() == "AR1()+WN()+RW()",
                (n - n0).abs() <= 0.1 * n0 && (k - k0).abs() <= 0.5 * k0,
                k0 == 0.0,
                c.model.count(ProcessKind::Qn) + c.model.count(ProcessKind::Dr) > 0,
            ];
            (flags, c.model.to_string())
        })
        .collect();
    let count = |i: usize| rows.iter().filter(|r| r.0[i]).count();
    let mut selected = std::collections::BTreeMap::new();
    for (_, name) in &rows {
        *selected.entry(name.clone()).or_insert(0) += 1;
    }
    Issue10 {
        reps,
        core: count(0),
        exact: count(1),
        densities: count(2),
        truth_without_rw: count(3),
        superfluous: count(4),
        selected,
    }
}

impl std::fmt::Display for Issue10 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} replicates: one AR1 + WN + RW {}, exactly AR1()+WN()+RW() {}, densities within \
             10% / 50% of the true model's fit {}, true model's fit without RW {}, superfluous \
             QN or DR {}; selected {:?}",
            self.reps,
            self.core,
            self.exact,
            self.densities,
            self.truth_without_rw,
            self.superfluous,
            self.selected
        )
    }
}

#[test]
fn issue_10_selection_reports_the_canonical_truth() {
    // CI size of the issue's Monte Carlo (the full one, 200 replicates per full model, is the
    // ignored test below): 40 replicates of N = 1e5 with the 2*AR1 full model, B = 50, G = 2000
    // (about 20 s on 2 cores). Measured at 200 replicates (module docs of gmwm::selection):
    // one AR1 + WN + RW 183/200, exactly AR1+WN+RW 182/200, densities 193/200. Bounds: the
    // measured rate less 3 binomial standard errors at 40 replicates. Before this issue the
    // selected model was AR1+WN+RW (as fitted) in 1 of 20 replicates (a drift in 11, no RW in 5).
    let mc = issue_10_mc("2*AR1()+WN()+RW()+QN()+DR()", 40);
    eprintln!("{mc}");
    assert!(mc.core >= 31, "{mc}");
    assert!(mc.exact >= 31, "{mc}");
    assert!(mc.densities >= 35, "{mc}");
}

#[test]
#[ignore = "the issue's full Monte Carlo: 200 replicates of N = 1e5 for both full models, about \
            90 s on 2 cores; run with cargo test --release -p gmwm --lib \
            issue_10_selection_full_size -- --ignored --nocapture"]
fn issue_10_selection_full_size() {
    for full in ["2*AR1()+WN()+RW()+QN()+DR()", "3*AR1()+WN()+RW()+QN()+DR()"] {
        let mc = issue_10_mc(full, 200);
        eprintln!("{full}: {mc}");
        // the issue's bars: exactly AR1+WN+RW in 85% (2*AR1) / 80% (3*AR1), densities in 95%;
        // one AR1 + WN + RW in 95% is out of reach with the package's fast weights (module docs
        // of gmwm::selection): 183/200 measured, and in 12 of the 17 misses the true model's
        // own fit has no random walk
        let exact_bar = if full.starts_with('2') { 170 } else { 160 };
        assert!(mc.exact >= exact_bar, "{mc}");
        assert!(mc.densities >= 190, "{mc}");
        assert!(mc.core >= 175, "{mc}");
    }
}

#[test]
fn asymptotic_optimism_is_calibrated_for_the_fast_weights_only() {
    // Why the selection keeps the package's fast weights: the WIC's optimism estimates the
    // excess of the out-of-sample loss over the apparent one for weights that do not follow
    // each level's own noise. The fast weights (squared CI widths) all but ignore the coarsest
    // levels, whose chi-square intervals are far wider than their standard errors; weights
    // from each level's own variance (Percival's diag) give those near-empty levels a weight
    // that moves with their noise (~ 1 / nu2_hat^2), the loss becomes heavy-tailed and the
    // optimism stops describing it. Measured, 200 fits of AR1+WN+RW at N = 1e4: fast, optimism
    // 0.47 vs excess loss 0.43 +- 0.03 (median 0.35); diag, optimism 6682 vs excess loss 1892 +-
    // 884 with a median of 19.
    use gmwm::fit::{Gmwm, StartInputs, Weights};
    use gmwm::inference::wv_bootstrap;
    use gmwm::{wavelet_variance, Weighting, WvOptions};
    use rayon::prelude::*;
    let truth = model("AR1(phi=0.95, sigma2=0.1)+WN(sigma2=1)+RW(gamma2=1e-2)");
    let (n, freq, reps) = (10_000, 100.0, 200);
    let x0 = simulate_model(&truth, n, freq, 1).unwrap();
    let levels = wavelet_variance(&x0, freq, &WvOptions::default())
        .unwrap()
        .levels();
    let fixed = WvOptions {
        levels: Some(levels),
        ..WvOptions::default()
    };
    let v = wv_bootstrap(&truth, n, freq, &fixed, 400, 77).unwrap().cov;
    let cand = model("AR1()+WN()+RW()");
    let study = |w: Weighting| {
        let res: Vec<(f64, f64)> = (0..reps)
            .into_par_iter()
            .map(|r| {
                let x = simulate_model(&truth, n, freq, 10_000 + r as u64).unwrap();
                let y = simulate_model(&truth, n, freq, 90_000 + r as u64).unwrap();
                let wv = wavelet_variance(&x, freq, &fixed).unwrap();
                let wv_new = wavelet_variance(&y, freq, &fixed).unwrap();
                let g = Gmwm::new(cand.clone()).with_draws(2000);
                let start = g.fit_from_wv(&wv, StartInputs::from_series(&x)).unwrap();
                let weights = Weights::new(w, &wv, Some(&x)).unwrap();
                let f = g
                    .fit_weighted(wv.wv(), weights, freq, start.theta())
                    .unwrap();
                let om = &f.weights().omega;
                let q_new: f64 = (0..levels)
                    .map(|j| om[j] * (wv_new.wv()[j] - f.implied_wv().wv[j]).powi(2))
                    .sum();
                let jac = f.model().jacobian(levels, freq).unwrap();
                let a = DMatrix::from_fn(levels, f.theta().len(), |j, k| jac[j][k]);
                let omega = DMatrix::from_diagonal(&DVector::from_column_slice(om));
                let h = f.model().hessian(levels, freq).unwrap();
                let d = d_matrix(&h, &omega, &f.implied_wv().wv, f.nu_hat()).unwrap();
                let o =
                    asymptotic_optimism(&a, &d, &omega, &v, OptimismConvention::Corrected).unwrap();
                (q_new - f.objective(), o)
            })
            .collect();
        let k = reps as f64;
        let excess = res.iter().map(|r| r.0).sum::<f64>() / k;
        let sd = (res.iter().map(|r| (r.0 - excess).powi(2)).sum::<f64>() / (k - 1.0)).sqrt();
        let optimism = res.iter().map(|r| r.1).sum::<f64>() / k;
        let mut sorted: Vec<f64> = res.iter().map(|r| r.0).collect();
        sorted.sort_by(f64::total_cmp);
        (optimism, excess, sd / k.sqrt(), sorted[reps / 2])
    };
    let (o, e, se, median) = study(Weighting::Fast);
    // 4 Monte Carlo standard errors plus 10% for the asymptotics and the estimated V; a
    // light-tailed loss (mean within a factor 2 of the median)
    assert!(
        (o - e).abs() <= 4.0 * se + 0.1 * e,
        "fast: {o} vs {e} +- {se}"
    );
    assert!(e < 2.0 * median, "fast: mean {e}, median {median}");
    let (o, e, se, median) = study(Weighting::Diag);
    // heavy-tailed (mean over 20 times the median) and the optimism far from both
    assert!(
        e > 20.0 * median && o > 50.0 * median,
        "diag: {o} vs {e} +- {se}, median {median}"
    );
}

#[test]
fn issue_10_candidates_with_one_fit_have_one_gof_p_value() {
    // adis_16405_imu1 gyro_y: candidates with the same objective had J-test p-values of
    // 7.29e-127 and 5.20e-126
    let x = read_column("adis_16405_imu1", "gyro_y");
    let s = Wic::nested(model("2*AR1()+WN()+RW()+QN()+DR()"))
        .unwrap()
        .select(&x, 100.0)
        .unwrap();
    // B = 50 > J + 2: every candidate has a J-test
    assert!(s.candidates().iter().all(|c| c.gof_p_value.is_some()));
    for a in s.candidates() {
        for b in s.candidates() {
            if a.canonical_model == b.canonical_model
                && (a.objective - b.objective).abs() <= 1e-9 * a.objective
            {
                assert_eq!(a.gof_p_value, b.gof_p_value, "{} vs {}", a.model, b.model);
            }
        }
    }
}
