//! Issue 31 item 3: the non-stationary AR1 of the paper's §IV-B (`crate::dynamics`,
//! docs/methods.md §5.16) against known truths: the estimator recovers the dependence, and what
//! the stationary fit that ignores the dynamics makes of the same series.

use gmwm::{fit_ns_ar1, NsAr1, NsAr1Options};
use rayon::prelude::*;

/// The dynamics: three slow cycles of a unit sinusoid over the recording (an angular-rate
/// magnitude, normalised).
fn dynamics(n: usize) -> Vec<f64> {
    (0..n)
        .map(|t| (6.0 * std::f64::consts::PI * t as f64 / n as f64).sin())
        .collect()
}

fn truth(beta1: f64) -> NsAr1 {
    NsAr1 {
        beta: [2.0, beta1],
        alpha: [0.0, 0.0],
        gamma: Some([0.0, 0.0]),
    }
}

#[test]
fn ns_ar1_recovers_a_dependence_the_stationary_fit_cannot_follow() {
    let n = 1 << 15;
    let z = dynamics(n);
    let x = truth(0.6).simulate(&z, 9).unwrap();
    let fit = fit_ns_ar1(&x, &z, 1.0, &NsAr1Options::default()).unwrap();
    assert!(fit.converged);
    let (b1, se) = (fit.theta[1], fit.se[1].unwrap());
    // one replicate: within 4 SE of the truth, and the slope clearly not 0
    assert!((b1 - 0.6).abs() < 4.0 * se, "beta1 {b1} +- {se}");
    assert!(b1 / se > 4.0, "beta1 {b1} +- {se}");
    // the windowed objective of the stationary model is far above the dynamic one's
    assert!(
        fit.stationary_objective > 5.0 * fit.objective,
        "{} vs {}",
        fit.stationary_objective,
        fit.objective
    );
    let json = serde_json::to_value(&fit).unwrap();
    assert_eq!(json["names"][1], "beta1");
}

/// 200 replicates with the dynamics (beta1 = 0.6) and 200 without (beta1 = 0): bias, RMSE and
/// interval coverage of every parameter, the size of the Wald test of beta1 = 0, and what the
/// stationary AR1 + WN fit makes of the series (its phi and GM variance against the truth's
/// range along the dynamics).
/// `cargo test --release --workspace --lib ns_ar1_study -- --ignored --nocapture`
#[test]
#[ignore]
fn ns_ar1_study() {
    const REPLICATES: u64 = 200;
    let n = 1 << 15;
    let z = dynamics(n);
    for beta1 in [0.6, 0.0] {
        let t = truth(beta1);
        let fits: Vec<gmwm::NsAr1Fit> = (0..REPLICATES)
            .into_par_iter()
            .filter_map(|i| {
                let x = t.simulate(&z, 7000 + i).ok()?;
                fit_ns_ar1(&x, &z, 1.0, &NsAr1Options::default()).ok()
            })
            .collect();
        let truth_theta = [2.0, beta1, 0.0, 0.0, 0.0];
        println!(
            "\nbeta1 = {beta1}: {} of {REPLICATES} fits ({} converged), N = {n}, 8 windows",
            fits.len(),
            fits.iter().filter(|f| f.converged).count()
        );
        println!("| parameter | truth | mean | bias | RMSE | mean SE | 95% coverage |");
        println!("|---|---:|---:|---:|---:|---:|---:|");
        for k in 0..5 {
            let v: Vec<f64> = fits.iter().map(|f| f.theta[k]).collect();
            let m = v.iter().sum::<f64>() / v.len() as f64;
            let rmse = (v.iter().map(|x| (x - truth_theta[k]).powi(2)).sum::<f64>()
                / v.len() as f64)
                .sqrt();
            let ses: Vec<f64> = fits.iter().filter_map(|f| f.se[k]).collect();
            let mean_se = ses.iter().sum::<f64>() / ses.len().max(1) as f64;
            let cover = fits
                .iter()
                .filter(|f| {
                    f.se[k].is_some_and(|s| (f.theta[k] - truth_theta[k]).abs() <= 1.96 * s)
                })
                .count() as f64
                / fits.len() as f64;
            println!(
                "| {} | {} | {m:.4} | {:+.4} | {rmse:.4} | {mean_se:.4} | {cover:.3} |",
                fits[0].names[k],
                truth_theta[k],
                m - truth_theta[k]
            );
        }
        let rejections = fits
            .iter()
            .filter(|f| f.se[1].is_some_and(|s| (f.theta[1] / s).abs() > 1.96))
            .count() as f64
            / fits.len() as f64;
        println!("Wald test of beta1 = 0 rejects in {rejections:.3} of the replicates");
        // the stationary fit
        let phis: Vec<f64> = fits.iter().map(|f| f.stationary.theta()[0]).collect();
        let gm_var: Vec<f64> = fits
            .iter()
            .map(|f| {
                let th = f.stationary.theta();
                th[1] / (1.0 - th[0] * th[0])
            })
            .collect();
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let rho = |zv: f64| (2.0 + beta1 * zv).tanh();
        let var = |zv: f64| 1.0 / (1.0 - rho(zv).powi(2));
        let ratio: Vec<f64> = fits
            .iter()
            .map(|f| f.stationary_objective / f.objective)
            .collect();
        println!(
            "stationary AR1 + WN fit: phi {:.4} (truth rho from {:.4} to {:.4}), AR variance {:.2} \
             (truth from {:.2} at z = -1 to {:.2} at z = +1); windowed objective of the \
             stationary model / the dynamic one: median {:.2}",
            mean(&phis),
            rho(-1.0),
            rho(1.0),
            mean(&gm_var),
            var(-1.0),
            var(1.0),
            {
                let mut r = ratio.clone();
                r.sort_by(f64::total_cmp);
                r[r.len() / 2]
            }
        );
        assert!(fits.len() as u64 >= REPLICATES * 9 / 10);
    }
}
