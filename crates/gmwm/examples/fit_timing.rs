//! Wall time of one GMWM fit through the Rust API, for comparison with the same call from
//! Python (`crates/gmwm-py/benches/bench_python.py`): the series is simulated with the same
//! model, length and seed as the Python bench, so both fit the same numbers.
//!
//! `cargo run --release -p gmwm --example fit_timing -- [N] [RUNS]`

use gmwm::{simulate_model, Gmwm, Model, WvOptions};
use std::time::Instant;

/// The bench's truth: a Gauss–Markov bias, white noise and a random walk at 100 Hz.
const TRUTH: &str = "AR1(phi=0.999, sigma2=1e-8)+WN(sigma2=1e-4)+RW(gamma2=1e-10)";

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().map_or(Ok(1_000_000), |a| a.parse())?;
    let runs: usize = args.next().map_or(Ok(7), |a| a.parse())?;
    let truth: Model = TRUTH.parse()?;
    let x = simulate_model(&truth, n, 100.0, 1)?;
    let gmwm = Gmwm::new("AR1()+WN()+RW()".parse()?)
        .with_draws(2000)
        .with_seed(1337);
    // the fit alone, and the fit with what `gmwm fit --json` and Python's `gmwm.fit` return:
    // its canonical reading and the JSON document (gmwm::document::fits)
    let mut fit_only = Vec::with_capacity(runs);
    let mut with_document = Vec::with_capacity(runs);
    for _ in 0..runs {
        let t = Instant::now();
        let fit = gmwm.fit(&x, 100.0, &WvOptions::default())?;
        fit_only.push(t.elapsed().as_secs_f64());
        std::hint::black_box(&fit);
        let t = Instant::now();
        let fit = gmwm.fit(&x, 100.0, &WvOptions::default())?;
        let canonical = fit.canonical()?;
        let doc = gmwm::document::fits(&[gmwm::document::FitItem {
            column: "x",
            fit: &fit,
            canonical: &canonical,
            inference: None,
            augmented: None,
        }])
        .to_string();
        with_document.push(t.elapsed().as_secs_f64());
        std::hint::black_box(doc);
    }
    for (label, times) in [
        ("fit", &mut fit_only),
        ("fit + document", &mut with_document),
    ] {
        times.sort_by(f64::total_cmp);
        println!(
            "rust {label}: n = {n}, runs = {runs}, median {:.4} s, min {:.4} s",
            times[runs / 2],
            times[0]
        );
    }
    Ok(())
}
