//! Criterion benches of inference on a GMWM fit (docs/methods.md §7) for the 3*GM truth of
//! `shared/ref/timings_gmwm_3gm.json` (AR1 (0.9, 1), (0.99, 0.1), (0.999, 0.01) at 1 Hz):
//! parametric-bootstrap inference with B = 100 at N = 1e5 (with and without the bootstrap GoF
//! refits, G = 10000) and asymptotic inference (sandwich, V from H = 100 replicates) at N = 1e6.
//! The fit itself (from the truth, stage 2) is setup, not timed. R's `summary(inference = TRUE)`
//! at N = 1e6 takes 68–99 s (classical) on the reference machine.
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use gmwm::{
    infer, simulate_model, wavelet_variance, Gmwm, GmwmFit, InferenceOptions, Model, WvOptions,
};
use std::time::Duration;

fn truth() -> Model {
    let gm = |phi: f64, sigma2: f64| {
        format!(
            "GM(beta={}, sigma2_gm={})",
            -phi.ln(),
            sigma2 / (1.0 - phi * phi)
        )
    };
    Model::parse(&format!(
        "{}+{}+{}",
        gm(0.9, 1.0),
        gm(0.99, 0.1),
        gm(0.999, 0.01)
    ))
    .expect("valid model")
}

fn fitted(n: usize, seed: u64) -> (Gmwm, GmwmFit, WvOptions) {
    let truth = truth();
    let x = simulate_model(&truth, n, 1.0, seed).expect("simulates");
    let wv = wavelet_variance(&x, 1.0, &WvOptions::default()).expect("wv");
    let opts = WvOptions {
        levels: Some(wv.levels()),
        ..WvOptions::default()
    };
    let gmwm = Gmwm::new(truth.without_values());
    let start: Vec<f64> = truth.values().into_iter().flatten().collect();
    let fit = gmwm.fit_wv(&wv, 1.0, &start).expect("fits");
    (gmwm, fit, opts)
}

fn benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("inference/3gm");
    // seconds per iteration: criterion's minimum of 10 samples
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(20));

    let n = 100_000;
    let (gmwm, fit, opts) = fitted(n, 4004);
    group.throughput(Throughput::Elements(n as u64));
    let boot = InferenceOptions {
        bootstrap: Some(100),
        gof_draws: None,
        ..InferenceOptions::default()
    };
    group.bench_function(format!("bootstrap/{n}"), |b| {
        b.iter(|| infer(&gmwm, &fit, n, &opts, &boot).expect("infers"))
    });
    let boot_gof = InferenceOptions {
        gof_draws: Some(10_000),
        ..boot
    };
    group.bench_function(format!("bootstrap_gof/{n}"), |b| {
        b.iter(|| infer(&gmwm, &fit, n, &opts, &boot_gof).expect("infers"))
    });

    let n = 1_000_000;
    let (gmwm, fit, opts) = fitted(n, 4005);
    group.throughput(Throughput::Elements(n as u64));
    let asym = InferenceOptions::default();
    group.bench_function(format!("asymptotic/{n}"), |b| {
        b.iter(|| infer(&gmwm, &fit, n, &opts, &asym).expect("infers"))
    });
    group.finish();
}

criterion_group!(inference, benches);
criterion_main!(inference);
