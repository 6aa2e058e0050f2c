//! Starting values (docs/methods.md §6) and the two-stage fit (§5.4–§5.5): hand values,
//! reproducible draws, recovery from guess mode, and the objective against the R package.

use crate::tests::common::{f64s, read_column, read_ref};
use gmwm::fit::{
    starting_values, Gmwm, Objective, Parametrisation, PhiOrder, StartInputs, StartOptions,
    TransformPreset, Weights,
};
use gmwm::model::Model;
use gmwm::sim::simulate_model;
use gmwm::{wavelet_variance, WvOptions};

/// Guessed fit vs the fit from the exact start (brief: within 5 %).
const GUESS_FACTOR: f64 = 1.05;
/// Ours vs R's exact-start objective (brief: within 1 %; R's CG stops short, §5.4).
const R_FACTOR: f64 = 1.01;
/// Our Q at R's estimate vs R's `obj_fun`: the same objective definition (fast Omega, no
/// factor N) up to the JSON's printed precision and tiny WV rounding.
const SAME_Q_TOL: f64 = 1e-6;

fn model(text: &str) -> Model {
    Model::parse(text).unwrap()
}

fn ar1_wn_rw_wv(n: usize, seed: u64) -> (Vec<f64>, gmwm::WaveletVariance) {
    let truth = model("AR1(phi=0.99, sigma2=0.01)+WN(sigma2=1)+RW(gamma2=1e-4)");
    let x = simulate_model(&truth, n, 1.0, seed).unwrap();
    let wv = wavelet_variance(&x, 1.0, &WvOptions::default()).unwrap();
    (x, wv)
}

#[test]
fn draws_reproducible_across_threads() {
    let (x, wv) = ar1_wn_rw_wv(10_000, 5);
    let m = model("AR1()+WN()+RW()");
    let opts = StartOptions {
        seed: 42,
        draws: Some(3000),
    };
    let inputs = StartInputs::from_series(&x);
    let run = |k: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(k)
            .build()
            .unwrap()
            .install(|| starting_values(&m, &wv, &inputs, &opts).unwrap())
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(a, b);
    let other = starting_values(&m, &wv, &inputs, &StartOptions { seed: 43, ..opts }).unwrap();
    assert_ne!(a.theta, other.theta);
    // the drawn start obeys the §6.3 domains: phi in (0, 1), variances > 0
    assert!(a.theta[0] > 0.0 && a.theta[0] < 1.0);
    assert!(a.theta[1..].iter().all(|&v| v > 0.0));
}

#[test]
fn partly_specified_values_are_kept_in_draws() {
    let (x, wv) = ar1_wn_rw_wv(10_000, 6);
    let m = model("AR1()+WN(sigma2=0.7)+RW()");
    let s = starting_values(
        &m,
        &wv,
        &StartInputs::from_series(&x),
        &StartOptions {
            seed: 1,
            draws: Some(2000),
        },
    )
    .unwrap();
    assert_eq!(s.theta[2], 0.7);
}

#[test]
fn recovery_ar1_wn_rw_guess_mode() {
    let (x, _) = ar1_wn_rw_wv(100_000, 11);
    let opts = WvOptions::default();
    let guess = Gmwm::new(model("AR1()+WN()+RW()"))
        .fit(&x, 1.0, &opts)
        .unwrap();
    let exact = Gmwm::new(model(
        "AR1(phi=0.99, sigma2=0.01)+WN(sigma2=1)+RW(gamma2=1e-4)",
    ))
    .fit(&x, 1.0, &opts)
    .unwrap();
    assert_eq!(exact.start(), vec![0.99, 0.01, 1.0, 1e-4]);
    eprintln!(
        "AR1+WN+RW: guess Q = {:e} theta {:?}, exact-start Q = {:e}",
        guess.objective(),
        guess.theta(),
        exact.objective()
    );
    assert!(guess.objective() <= exact.objective() * GUESS_FACTOR);
    // loose bounds: phi within 0.01, sigma2 and WN within 30 %, RW within a factor 10 (the
    // RW is seen only at the last few, noisy levels)
    let t = guess.theta();
    assert!((t[0] - 0.99).abs() < 0.01, "{t:?}");
    assert!((t[1] / 0.01 - 1.0).abs() < 0.3, "{t:?}");
    assert!((t[2] - 1.0).abs() < 0.3, "{t:?}");
    assert!(t[3] > 1e-5 && t[3] < 1e-3, "{t:?}");
}

#[test]
fn recovery_two_gm_wn_guess_mode() {
    let freq = 100.0;
    let truth = model("GM(beta=0.5, sigma2_gm=1e-4)+GM(beta=20, sigma2_gm=1e-3)+WN(sigma2=1e-3)");
    let x = simulate_model(&truth, 1 << 17, freq, 21).unwrap();
    let opts = WvOptions::default();
    let guess = Gmwm::new(model("2*GM()+WN()"))
        .fit(&x, freq, &opts)
        .unwrap();
    let exact = Gmwm::new(truth).fit(&x, freq, &opts).unwrap();
    eprintln!(
        "2GM+WN: guess Q = {:e} theta {:?}, exact-start Q = {:e} theta {:?}",
        guess.objective(),
        guess.theta(),
        exact.objective(),
        exact.theta()
    );
    assert!(guess.objective() <= exact.objective() * GUESS_FACTOR);
    // loose bounds: rates within a factor 3, variances within a factor 3, WN within 30 %
    let t = guess.theta();
    let within = |v: f64, truth: f64, f: f64| v > truth / f && v < truth * f;
    assert!(within(t[0], 0.5, 3.0), "{t:?}");
    assert!(within(t[1], 1e-4, 3.0), "{t:?}");
    assert!(within(t[2], 20.0, 3.0), "{t:?}");
    assert!(within(t[3], 1e-3, 3.0), "{t:?}");
    assert!(within(t[4], 1e-3, 1.3), "{t:?}");
}

#[test]
fn reference_ar1_wn_rw_vs_r() {
    let r = read_ref("sim_ar1_wn_rw.json");
    let run = &r["runs"]["N100000"];
    let x = read_column("sim/ar1_wn_rw_N100000", "x");
    assert_eq!(x.len(), 100_000);
    let r_guess = run["fit_guess"]["obj_fun"].as_f64().unwrap();
    let r_exact = run["fit_exact_start"]["obj_fun"].as_f64().unwrap();
    let opts = WvOptions::default();
    let fit = Gmwm::new(model("AR1()+WN()+RW()"))
        .fit(&x, 1.0, &opts)
        .unwrap();
    // same objective definition: our WV and our Q at R's exact-start estimate
    let wv_r = f64s(&run["fit_guess"]["wv_empir"]);
    assert_eq!(fit.nu_hat().len(), wv_r.len());
    for (a, b) in fit.nu_hat().iter().zip(&wv_r) {
        assert!((a / b - 1.0).abs() < SAME_Q_TOL, "{a} vs {b}");
    }
    let est = f64s(&run["fit_exact_start"]["estimate"]);
    let m = model("AR1()+WN()+RW()");
    let wv = wavelet_variance(&x, 1.0, &opts).unwrap();
    let weights = Weights::fast(&wv).unwrap();
    let param = Parametrisation::new(&m, TransformPreset::Imu, PhiOrder::Ordered, 1.0).unwrap();
    let ours_at_r = Objective::new(&m, param, wv.wv(), &weights, 1.0)
        .unwrap()
        .value_at_theta(&est)
        .unwrap();
    eprintln!(
        "ref N=1e5: ours Q = {:e} (theta {:?}, start {:?}); R guess {:e}, R exact-start {:e}, \
         our Q at R's exact-start estimate {:e}",
        fit.objective(),
        fit.theta(),
        fit.start(),
        r_guess,
        r_exact,
        ours_at_r
    );
    assert!(
        (ours_at_r / r_exact - 1.0).abs() < 1e-4,
        "{ours_at_r} vs {r_exact}"
    );
    assert!(fit.objective() <= r_exact * R_FACTOR);
    assert!(fit.objective() <= r_guess);
}

#[test]
fn fit_from_precomputed_wv() {
    let (x, wv) = ar1_wn_rw_wv(10_000, 8);
    let g = Gmwm::new(model("AR1()+WN()+RW()"))
        .with_seed(3)
        .with_draws(2000);
    let from_wv = g.fit_from_wv(&wv, StartInputs::from_wv(&wv)).unwrap();
    let from_x = g.fit(&x, 1.0, &WvOptions::default()).unwrap();
    // the range R only feeds DR draws (none here), so both searches are identical
    assert_eq!(from_wv.start(), from_x.start());
    assert_eq!(from_wv.objective(), from_x.objective());
    assert_eq!(StartInputs::from_wv(&wv).range, 0.0);
    // the diag weighting needs the series: an error, not a panic
    let diag = Gmwm::new(model("AR1()+WN()+RW()")).with_weighting(gmwm::fit::Weighting::Diag);
    assert!(diag.fit_from_wv(&wv, StartInputs::from_wv(&wv)).is_err());
}

#[test]
fn early_stop_and_default_draws() {
    let (x, wv) = ar1_wn_rw_wv(10_000, 9);
    let s = starting_values(
        &model("AR1()+WN()+RW()"),
        &wv,
        &StartInputs::from_series(&x),
        &StartOptions::default(),
    )
    .unwrap();
    assert!(
        s.draws >= gmwm::fit::start::MIN_DRAWS && s.draws <= 20_000,
        "{}",
        s.draws
    );
    assert_eq!(gmwm::fit::start::default_draws(10_000), 20_000);
    assert_eq!(gmwm::fit::start::default_draws(10_001), 100_000);
}

/// The smaller reference runs: ours <= R's exact-start objective x 1.01 and <= R's guessed
/// fit (measured: N=1e3 0.07637 vs R exact 0.07645, guess 0.08251; N=1e4 0.1406 vs 0.1553,
/// 0.1412). The RW variance goes to the lower edge there (the RW is not visible at these N).
#[test]
fn reference_ar1_wn_rw_small_n_vs_r() {
    let r = read_ref("sim_ar1_wn_rw.json");
    for n in ["N1000", "N10000"] {
        let run = &r["runs"][n];
        let x = read_column(&format!("sim/ar1_wn_rw_{n}"), "x");
        let fit = Gmwm::new(model("AR1()+WN()+RW()"))
            .fit(&x, 1.0, &WvOptions::default())
            .unwrap();
        let r_guess = run["fit_guess"]["obj_fun"].as_f64().unwrap();
        let r_exact = run["fit_exact_start"]["obj_fun"].as_f64().unwrap();
        eprintln!(
            "{n}: ours Q = {:e} theta {:?}; R guess {r_guess:e}, R exact-start {r_exact:e}",
            fit.objective(),
            fit.theta()
        );
        assert!(fit.objective() <= r_exact * R_FACTOR, "{n}");
        assert!(fit.objective() <= r_guess, "{n}");
    }
}

/// The R reference's 3*GM simulations (`sim_gm3.json`, files in `shared/data/sim`): R's
/// guessed fits end at Q = 7.8, 0.12, 15.2 and 13.6 for N = 1e3 .. 1e6 against 0.036, 0.058,
/// 0.027 and 0.091 from the exact start (its README, finding 3). Our guess-mode fit of
/// `3*GM()` reaches R's exact-start objective (within R_FACTOR) at every N.
#[test]
fn reference_gm3_guess_mode_vs_r() {
    let r = read_ref("sim_gm3.json");
    for n in ["N1000", "N10000", "N100000", "N1000000"] {
        let run = &r["runs"][n];
        let x = if n == "N1000000" {
            // raw little-endian float64, no header (the reference's notes)
            let path = crate::tests::common::data_dir().join("sim/gm3_N1000000.f64le.bin");
            let bytes = std::fs::read(&path).unwrap();
            bytes
                .chunks_exact(8)
                .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
                .collect()
        } else {
            read_column(&format!("sim/gm3_{n}"), "x")
        };
        assert_eq!(x.len() as f64, run["N"].as_f64().unwrap());
        let fit = Gmwm::new(model("3*GM()"))
            .fit(&x, 1.0, &WvOptions::default())
            .unwrap();
        let r_guess = run["fit_guess"]["obj_fun"].as_f64().unwrap();
        let r_exact = run["fit_exact_start"]["obj_fun"].as_f64().unwrap();
        // the same objective: ours at R's exact-start estimate is R's value
        let m = model("3*GM()");
        let wv = wavelet_variance(&x, 1.0, &WvOptions::default()).unwrap();
        let param = Parametrisation::new(&m, TransformPreset::Imu, PhiOrder::Free, 1.0).unwrap();
        let ours_at_r = Objective::new(&m, param, wv.wv(), &Weights::fast(&wv).unwrap(), 1.0)
            .unwrap()
            .value_at_theta(&f64s(&run["fit_exact_start"]["estimate"]))
            .unwrap();
        eprintln!(
            "{n}: ours Q = {:e}; R guess {r_guess:e}, R exact-start {r_exact:e}, our Q at R's \
             exact-start estimate {ours_at_r:e}",
            fit.objective()
        );
        assert!(
            (ours_at_r / r_exact - 1.0).abs() < 1e-4,
            "{ours_at_r} vs {r_exact}"
        );
        assert!(
            fit.objective() <= r_exact * R_FACTOR,
            "{n}: {} vs {r_exact}",
            fit.objective()
        );
        assert!(fit.objective() <= r_guess, "{n}");
    }
}
