//! Inference on a GMWM fit (METHODS §7): J-test, sandwich covariance, intervals, parametric
//! bootstrap, with METHODS test values, closed forms and seeded Monte Carlo.

use gmwm::fit::weights::FullWeights;
use gmwm::fit::{Gmwm, Objective, Parametrisation, PhiOrder, TransformPreset, Weights};
use gmwm::inference::gof::{chi_square_upper_tail, j_test};
use gmwm::model::Model;
use gmwm::sim::simulate_model;
use gmwm::{wavelet_variance, WvOptions};
use nalgebra::{DMatrix, DVector};

fn model(text: &str) -> Model {
    Model::parse(text).unwrap()
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

/// A fit of `AR1()+WN()`-like `template` to a seeded simulation of `truth` from the truth.
fn simulated_fit(
    truth: &str,
    n: usize,
    levels: usize,
    seed: u64,
) -> (Gmwm, gmwm::GmwmFit, Vec<f64>, WvOptions) {
    let truth = model(truth);
    let x = simulate_model(&truth, n, 1.0, seed).unwrap();
    let opts = WvOptions {
        levels: Some(levels),
        ..WvOptions::default()
    };
    let wv = wavelet_variance(&x, 1.0, &opts).unwrap();
    let gmwm = Gmwm::new(truth.without_values());
    let start: Vec<f64> = truth.values().into_iter().flatten().collect();
    let fit = gmwm.fit_wv(&wv, 1.0, &start).unwrap();
    (gmwm, fit, x, opts)
}

/// An equicorrelated-by-distance covariance `V_ij = s_i s_j rho^|i-j|` with the fast-weight
/// variances as `s^2`: full, positive definite, scales decades apart.
fn ar_correlated(v_diag: &[f64], rho: f64) -> DMatrix<f64> {
    let n = v_diag.len();
    DMatrix::from_fn(n, n, |i, j| {
        rho.powi((i as i32 - j as i32).abs()) * (v_diag[i] * v_diag[j]).sqrt()
    })
}

#[test]
fn j_test_with_the_fit_weights_is_the_fit_objective() {
    // V = diag(fast V): the efficient refit is the fit itself, so T = Q(theta_hat)
    let (gmwm, fit, _, _) = simulated_fit("AR1(phi=0.95, sigma2=0.1)+WN(sigma2=1)", 5000, 10, 3);
    let v = DMatrix::from_diagonal(&DVector::from_vec(fit.weights.v.clone()));
    let t = j_test(&gmwm, &fit, &v).unwrap();
    assert_eq!(t.df, 10 - 3);
    // both minima are converged to ~1e-15 relative in Q; 1e-9 allows for the LM stop rule
    assert!(
        rel(t.statistic, fit.objective) < 1e-9,
        "{} vs {}",
        t.statistic,
        fit.objective
    );
    assert_eq!(t.p_value, chi_square_upper_tail(t.statistic, t.df));
}

#[test]
fn j_test_matches_generalised_least_squares_on_a_linear_model() {
    // WN + RW: the implied WV is linear in (sigma2, gamma2), so the efficient-weight estimate
    // is GLS, theta = (A' W A)^{-1} A' W nu_hat with W = V^{-1}, and T = r' W r (closed form).
    let (gmwm, fit, _, _) = simulated_fit("WN(sigma2=1)+RW(gamma2=0.001)", 4000, 9, 5);
    let v = ar_correlated(&fit.weights.v, 0.6);
    let t = j_test(&gmwm, &fit, &v).unwrap();
    let a = fit.model.jacobian(9, 1.0).unwrap();
    let a = DMatrix::from_fn(9, 2, |i, j| a[i][j]);
    let w = v.clone().try_inverse().unwrap();
    let nu = DVector::from_vec(fit.nu_hat.clone());
    let ata = a.transpose() * &w * &a;
    let theta = ata.try_inverse().unwrap() * a.transpose() * &w * &nu;
    assert!(
        theta.iter().all(|v| *v > 0.0),
        "GLS solution must be interior: {theta}"
    );
    let r = &nu - &a * &theta;
    let want = (r.transpose() * &w * &r)[(0, 0)];
    // GLS by explicit inverse of a matrix with condition ~1e8 in V: 1e-7 relative
    assert!(rel(t.statistic, want) < 1e-7, "{} vs {want}", t.statistic);
    assert_eq!(t.df, 7);
}

#[test]
fn full_weight_objective_is_the_quadratic_form() {
    let truth = model("AR1(phi=0.9, sigma2=1)+WN(sigma2=2)");
    let nu_hat: Vec<f64> = truth
        .implied_wv(6, 1.0)
        .unwrap()
        .wv
        .iter()
        .enumerate()
        .map(|(j, v)| v * (1.0 + 0.05 * (j as f64 - 2.5)))
        .collect();
    let v = ar_correlated(
        &nu_hat.iter().map(|x| x * x * 0.01).collect::<Vec<_>>(),
        0.8,
    );
    let template = truth.without_values();
    let param =
        Parametrisation::new(&template, TransformPreset::Imu, PhiOrder::Ordered, 1.0).unwrap();
    let fw = FullWeights::from_covariance(&v).unwrap();
    let obj = Objective::with_full_weights(&template, param.clone(), &nu_hat, &fw, 1.0).unwrap();
    let theta = [0.8, 1.5, 1.5];
    let nu = Model::parse("AR1(phi=0.8, sigma2=1.5)+WN(sigma2=1.5)")
        .unwrap()
        .implied_wv(6, 1.0)
        .unwrap()
        .wv;
    let e = DVector::from_vec(nu_hat.iter().zip(&nu).map(|(h, n)| h - n).collect());
    let want = (e.transpose() * v.clone().try_inverse().unwrap() * &e)[(0, 0)];
    // explicit inverse vs whitening of a correlation matrix with condition ~ 80: 1e-10
    assert!(rel(obj.value_at_theta(&theta).unwrap(), want) < 1e-10);
    // gradient = central differences in u
    let u = param.to_u(&theta).unwrap();
    let g = obj.gradient(&u).unwrap();
    for k in 0..3 {
        let h = 1e-6;
        let mut up = u.clone();
        up[k] += h;
        let mut dn = u.clone();
        dn[k] -= h;
        let fd = (obj.value(&up).unwrap() - obj.value(&dn).unwrap()) / (2.0 * h);
        // central differences with h = 1e-6: truncation ~1e-12, rounding ~1e-10 relative
        assert!(
            (g[k] - fd).abs() < 1e-6 * g[k].abs().max(1e-3),
            "{k}: {} vs {fd}",
            g[k]
        );
    }
    // the diagonal constructor agrees with a diagonal full weighting
    let d: Vec<f64> = (0..6).map(|j| v[(j, j)]).collect();
    let diag = Objective::new(
        &template,
        param.clone(),
        &nu_hat,
        &Weights::from_variances(d.clone()).unwrap(),
        1.0,
    )
    .unwrap();
    let full = Objective::with_full_weights(
        &template,
        param,
        &nu_hat,
        &FullWeights::from_covariance(&DMatrix::from_diagonal(&DVector::from_vec(d))).unwrap(),
        1.0,
    )
    .unwrap();
    assert!(rel(diag.value(&u).unwrap(), full.value(&u).unwrap()) < 1e-13);
}

#[test]
fn j_test_rejects_bad_input() {
    let (gmwm, fit, _, _) = simulated_fit("AR1(phi=0.95, sigma2=0.1)+WN(sigma2=1)", 3000, 8, 3);
    assert!(j_test(&gmwm, &fit, &DMatrix::identity(7, 7)).is_err());
    let bad = DMatrix::from_element(8, 8, 1.0); // rank 1
    assert!(j_test(&gmwm, &fit, &bad).is_err());
    let (gmwm, fit, _, _) = simulated_fit("AR1(phi=0.95, sigma2=0.1)+WN(sigma2=1)", 3000, 3, 3);
    let v = DMatrix::from_diagonal(&DVector::from_vec(fit.weights.v.clone()));
    let e = j_test(&gmwm, &fit, &v).unwrap_err();
    assert!(e.to_string().contains("df"), "{e}");
}
