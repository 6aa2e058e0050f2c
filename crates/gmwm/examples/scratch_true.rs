use gmwm::fit::Gmwm;
use gmwm::model::Model;
use gmwm::sim::simulate_model;
use gmwm::{Weighting, WvOptions};
use rayon::prelude::*;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let reps: usize = args.get(1).map(|s| s.parse().unwrap()).unwrap_or(20);
    let n: usize = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(100_000);
    let truth = Model::parse("AR1(phi=0.99, sigma2=1e-3)+WN(sigma2=1)+RW(gamma2=1e-6)").unwrap();
    for w in [Weighting::Fast, Weighting::Diag, Weighting::Bootstrap] {
        let res: Vec<f64> = (0..reps)
            .into_par_iter()
            .map(|r| {
                let x = simulate_model(&truth, n, 100.0, 1000 + r as u64).unwrap();
                let f = Gmwm::parse("AR1()+WN()+RW()")
                    .unwrap()
                    .with_draws(2000)
                    .with_weighting(w)
                    .fit(&x, 100.0, &WvOptions::default())
                    .unwrap();
                f.theta[3] / 1e-6
            })
            .collect();
        let zero = res.iter().filter(|v| **v < 1e-2).count();
        let mut s = res.clone();
        s.sort_by(|a, b| a.partial_cmp(b).unwrap());
        println!(
            "{w:?}: rw~0 {zero}/{reps}; quantiles {:.2} {:.2} {:.2} {:.2} {:.2}",
            s[reps / 20],
            s[reps / 4],
            s[reps / 2],
            s[3 * reps / 4],
            s[19 * reps / 20]
        );
    }
}
