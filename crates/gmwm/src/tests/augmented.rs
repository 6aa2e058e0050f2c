//! Issue 31 item 5: GMWM+ (docs/methods.md §5.15) against known truths, and its efficiency
//! against GMWM on the same replicates (the `#[ignore]` study gives the figures of §5.15).

use crate::augmented::{stacked_fit, AugmentOptions};
use crate::sim::bootstrap::{map_replicates, WvBootstrap};
use gmwm::fit::{Augment, FitError, Gmwm};
use gmwm::model::Model;
use gmwm::sim::{replicate_seed, simulate_model};
use gmwm::{fit_augmented, WvOptions};
use rayon::prelude::*;

fn theta_of(m: &Model) -> Vec<f64> {
    m.values().into_iter().map(Option::unwrap).collect()
}

#[test]
fn gmwm_plus_fits_a_known_truth_with_intervals_and_a_j_test() {
    let truth = Model::parse("AR1(phi=0.9, sigma2=1)+WN(sigma2=2)").unwrap();
    let x = simulate_model(&truth, 1 << 14, 1.0, 11).unwrap();
    let mut opts = AugmentOptions::new("acf:3".parse().unwrap());
    opts.replicates = 100;
    let gmwm = Gmwm::parse("AR1()+WN()").unwrap();
    let fit = fit_augmented(&gmwm, &x, 1.0, &WvOptions::default(), &opts).unwrap();
    assert!(fit.estimates().convergence().converged);
    let truth = theta_of(&truth);
    for (p, t) in fit.parameters().iter().zip(&truth) {
        // N = 2^14: the estimates' relative SEs are about 5-15%; 4 SE
        let se = p.se.unwrap();
        assert!((p.value - t).abs() < 4.0 * se, "{p:?} vs {t}");
        assert!(p.ci_low.unwrap() < p.value && p.value < p.ci_high.unwrap());
    }
    // 13 WV levels + 3 extra moments, 3 parameters
    let j = fit.j_test();
    assert_eq!(j.df, fit.moments().len() - 3);
    assert_eq!(fit.moments().len(), 16);
    assert!(j.p_value.unwrap() > 1e-4, "{j:?}");
    let json = serde_json::to_value(&fit).unwrap();
    assert_eq!(json["augment"], "acf:3");
    assert_eq!(json["moments"][13]["name"], "acf_diff[1]");
    let table = fit.to_string();
    assert!(
        table.contains("GMWM+") && table.contains("acf_diff[3]"),
        "{table}"
    );
}

#[test]
fn gmwm_plus_refuses_what_it_cannot_do() {
    let x = simulate_model(&Model::parse("WN(sigma2=1)").unwrap(), 512, 1.0, 1).unwrap();
    let run = |model: &str, augment: &str, h: usize| {
        let mut opts = AugmentOptions::new(augment.parse().unwrap());
        opts.replicates = h;
        fit_augmented(
            &Gmwm::parse(model).unwrap(),
            &x,
            1.0,
            &WvOptions::default(),
            &opts,
        )
        .unwrap_err()
        .to_string()
    };
    assert!(run("WN()+RW()", "mean", 50).contains("DR()"));
    // 8 levels + 1 extra moment: H must exceed 11
    let e = run("WN()", "acf:1", 10);
    assert!(e.contains("replicates"), "{e}");
}

/// Per replicate: GMWM (the estimator's default weights), the efficient two-step GMWM with the
/// bootstrap V of the WV alone, and GMWM+ with the joint V of the same bootstrap series.
struct Replicate {
    gmwm: Vec<f64>,
    efficient: Vec<f64>,
    plus: Vec<f64>,
    covered: Vec<bool>,
}

fn replicate(
    truth: &Model,
    template: &str,
    augment: Augment,
    n: usize,
    h: usize,
    seed: u64,
) -> Result<Replicate, FitError> {
    let x = simulate_model(truth, n, 1.0, seed)?;
    let gmwm = Gmwm::parse(template).unwrap().with_seed(seed);
    let base = gmwm.fit(&x, 1.0, &WvOptions::default())?;
    let wv = base.empirical().unwrap().clone();
    let j = wv.levels();
    let mut moments = wv.wv.clone();
    moments.extend(augment.sample(&x)?);
    let samples = map_replicates(
        base.model(),
        n,
        1.0,
        &wv.options(),
        h,
        seed ^ 0x5eed,
        |_, w, xs| {
            let mut v = w.wv.clone();
            v.extend(augment.sample(xs)?);
            Ok::<_, FitError>(v)
        },
    )?;
    let cov = WvBootstrap::from_samples(&samples)?.cov;
    let mut opts = AugmentOptions::new(augment);
    opts.replicates = h;
    let plus = stacked_fit(&gmwm, &base, &moments, &cov, &opts)?;
    opts.augment = Augment::none();
    let wv_block = cov.view((0, 0), (j, j)).into_owned();
    let efficient = stacked_fit(&gmwm, &base, &wv.wv, &wv_block, &opts)?;
    let t = theta_of(truth);
    Ok(Replicate {
        gmwm: base.theta().to_vec(),
        efficient: efficient.estimates().theta().to_vec(),
        plus: plus.estimates().theta().to_vec(),
        covered: plus
            .parameters()
            .iter()
            .zip(&t)
            .map(|(p, t)| matches!((p.ci_low, p.ci_high), (Some(lo), Some(hi)) if lo <= *t && *t <= hi))
            .collect(),
    })
}

/// GMWM+ against GMWM, 200 replicates per truth: RMSE per parameter of the three estimators,
/// the ratios, and the coverage of GMWM+'s 95% intervals.
/// `cargo test --release --workspace --lib gmwm_plus_efficiency_study -- --ignored --nocapture`
#[test]
#[ignore]
fn gmwm_plus_efficiency_study() {
    const REPLICATES: u64 = 200;
    let cases = [
        (
            "AR1(phi=0.9, sigma2=1)+WN(sigma2=2)",
            "AR1()+WN()",
            "acf:3",
            1 << 14,
        ),
        (
            "AR1(phi=0.5, sigma2=1)+WN(sigma2=1)",
            "AR1()+WN()",
            "acf:3",
            1 << 14,
        ),
        (
            "WN(sigma2=1)+RW(gamma2=1e-4)+DR(omega=1e-3)",
            "WN()+RW()+DR()",
            "mean,acf:2",
            1 << 14,
        ),
        (
            "WN(sigma2=1)+QN(q2=0.5)+RW(gamma2=1e-5)",
            "WN()+QN()+RW()",
            "acf:2",
            1 << 14,
        ),
        (
            "AR1(phi=0.5, sigma2=1)+WN(sigma2=1)",
            "AR1()+WN()",
            "acf:3",
            1 << 10,
        ),
        (
            "ARMA11(phi=0.8, theta=-0.5, sigma2=1)",
            "ARMA11()",
            "acf:3",
            1 << 12,
        ),
    ];
    for (truth, template, augment, n) in cases {
        let truth = Model::parse(truth).unwrap();
        let augment: Augment = augment.parse().unwrap();
        let reps: Vec<Replicate> = (0..REPLICATES)
            .into_par_iter()
            .filter_map(|i| {
                replicate(&truth, template, augment, n, 200, replicate_seed(31, i)).ok()
            })
            .collect();
        let t = theta_of(&truth);
        println!(
            "\n{truth}, N = {n}, augment {augment}: {} of {REPLICATES} replicates",
            reps.len()
        );
        println!(
            "| parameter | truth | RMSE GMWM | RMSE eff. GMWM | RMSE GMWM+ | GMWM+/GMWM | GMWM+/eff. | bias GMWM+ | coverage GMWM+ |"
        );
        println!("|---|---|---|---|---|---|---|---|---|");
        let names: Vec<String> = truth.param_names().into_iter().map(|(_, s)| s).collect();
        for k in 0..t.len() {
            let rmse = |f: &dyn Fn(&Replicate) -> f64| {
                (reps.iter().map(|r| (f(r) - t[k]).powi(2)).sum::<f64>() / reps.len() as f64).sqrt()
            };
            let (g, e, p) = (
                rmse(&|r| r.gmwm[k]),
                rmse(&|r| r.efficient[k]),
                rmse(&|r| r.plus[k]),
            );
            let bias = reps.iter().map(|r| r.plus[k] - t[k]).sum::<f64>() / reps.len() as f64;
            let cover = reps.iter().filter(|r| r.covered[k]).count() as f64 / reps.len() as f64;
            println!(
                "| {} | {:.3e} | {g:.3e} | {e:.3e} | {p:.3e} | {:.3} | {:.3} | {bias:.2e} | {cover:.3} |",
                names[k],
                t[k],
                p / g,
                p / e
            );
            assert!(cover > 0.8, "coverage {cover} of {}", names[k]);
        }
        assert!(reps.len() as u64 >= REPLICATES * 9 / 10);
    }
}
