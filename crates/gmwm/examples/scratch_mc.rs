use gmwm::fit::Gmwm;
use gmwm::model::{Model, ProcessKind};
use gmwm::selection::{SelectionRule, Wic};
use gmwm::sim::simulate_model;
use gmwm::WvOptions;
use rayon::prelude::*;
use std::collections::BTreeMap;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let full = args
        .get(1)
        .cloned()
        .unwrap_or("2*AR1()+WN()+RW()+QN()+DR()".into());
    let reps: usize = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(20);
    let n: usize = args.get(3).map(|s| s.parse().unwrap()).unwrap_or(100_000);
    let limit: f64 = args.get(4).map(|s| s.parse().unwrap()).unwrap_or(2.0);
    let verbose = std::env::var("V").is_ok();
    let truth = Model::parse(
        &std::env::var("TRUTH")
            .unwrap_or("AR1(phi=0.99, sigma2=1e-3)+WN(sigma2=1)+RW(gamma2=1e-6)".into()),
    )
    .unwrap();
    let truth_fit = std::env::var("TRUTHFIT").unwrap_or("AR1()+WN()+RW()".into());
    let freq = 100.0;
    let rules: Vec<SelectionRule> = if std::env::var("NAVONLY").is_ok() {
        vec![SelectionRule::Navigation]
    } else {
        vec![
            SelectionRule::WicMinimum,
            SelectionRule::Parsimonious,
            SelectionRule::Navigation,
        ]
    };
    for rule in rules {
        let wic = Wic::nested(Model::parse(&full).unwrap())
            .unwrap()
            .with_draws(2000)
            .with_bootstrap(50)
            .with_rule(rule)
            .with_separation_limit(limit)
            .with_weighting(match std::env::var("W").as_deref() {
                Ok("diag") => gmwm::Weighting::Diag,
                Ok("boot") => gmwm::Weighting::Bootstrap,
                _ => gmwm::Weighting::Fast,
            });
        let res: Vec<(String, bool, bool, bool, bool, bool, String)> = (0..reps)
            .into_par_iter()
            .map(|r| {
                let x = simulate_model(&truth, n, freq, 1000 + r as u64).unwrap();
                let s = wic.select(&x, freq).unwrap();
                let c = &s.selected_canonical;
                let tm = Model::parse(&truth_fit).unwrap();
                let tf = match s.candidate_fit(&tm) {
                    Some(f) => f.clone(),
                    None => Gmwm::parse(&truth_fit)
                        .unwrap()
                        .with_draws(2000)
                        .fit(&x, freq, &WvOptions::default())
                        .unwrap(),
                };
                let tc = tf.canonical().unwrap();
                let get =
                    |m: &gmwm::fit::CanonicalModel, k, name| m.physical(k, name).unwrap_or(0.0);
                let (n_sel, n_true) = (
                    get(c, ProcessKind::Wn, "white_noise_density"),
                    get(&tc, ProcessKind::Wn, "white_noise_density"),
                );
                let (k_sel, k_true) = (
                    get(c, ProcessKind::Rw, "rate_random_walk_density"),
                    get(&tc, ProcessKind::Rw, "rate_random_walk_density"),
                );
                let core = c.correlated_terms() == 1
                    && c.model.count(ProcessKind::Wn) == 1
                    && c.model.count(ProcessKind::Rw) == 1;
                let exact = c.model.to_string() == truth_fit;
                let wn_ok = (n_sel - n_true).abs() <= 0.1 * n_true;
                let rw_ok = (k_sel - k_true).abs() <= 0.5 * k_true;
                let true_rw0 = k_true == 0.0;
                let detail = format!(
                    "{} | sel {} | top {} | N {:.4}/{:.4} K {:.3e}/{:.3e} | true canon {}",
                    c.model,
                    s.selected,
                    s.rows
                        .iter()
                        .take(4)
                        .map(|r| format!(
                            "{} {:.4} se{:.4}",
                            r.canonical_model, r.wic, r.delta_wic_se
                        ))
                        .collect::<Vec<_>>()
                        .join(" ; "),
                    n_sel,
                    n_true,
                    k_sel,
                    k_true,
                    tc.model
                );
                (
                    c.model.to_string(),
                    core,
                    exact,
                    wn_ok && rw_ok,
                    true_rw0,
                    wn_ok,
                    detail,
                )
            })
            .collect();
        let mut counts: BTreeMap<String, usize> = BTreeMap::new();
        for r in &res {
            *counts.entry(r.0.clone()).or_default() += 1;
        }
        let core = res.iter().filter(|r| r.1).count();
        let exact = res.iter().filter(|r| r.2).count();
        let dens = res.iter().filter(|r| r.3).count();
        let wn = res.iter().filter(|r| r.5).count();
        let rw0 = res.iter().filter(|r| r.4).count();
        println!("{full} rule {rule} limit {limit}: core {core}/{reps} exact {exact}/{reps} densities {dens}/{reps} (wn {wn}) true-fit RW absent {rw0}");
        println!("  {counts:?}");
        if verbose {
            for (i, r) in res.iter().enumerate() {
                if !r.2 || !r.3 {
                    println!("  {i}: {}", r.6);
                }
            }
        }
    }
}
