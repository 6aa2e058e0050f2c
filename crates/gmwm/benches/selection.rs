//! Criterion bench of WIC model selection (docs/methods.md §8.6): the asymptotic optimism over the
//! 63 nested candidates of `3*AR1()+WN()+RW()+QN()+DR()` on N = 1e6 samples of AR1 + WN + RW at
//! 100 Hz, with the defaults (B = 50 bootstrap replicates of V, G = 1e5 draws with early stop,
//! seed 1337). The R package's `auto_imu` with 31 candidates (3*AR1()+WN()+RW()+QN()) took
//! 106 s on gyro_x of adis_16405_imu1 (N = 1e6) on the reference machine
//! (`shared/ref/auto_imu_adis_16405_imu1_gyro_x.json`, `elapsed_s`).
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use gmwm::{simulate_model, Model, Wic};

const N: usize = 1_000_000;

fn benches(c: &mut Criterion) {
    let truth = Model::parse("AR1(phi=0.995, sigma2=1e-4)+WN(sigma2=1e-2)+RW(gamma2=1e-9)")
        .expect("valid model");
    let x = simulate_model(&truth, N, 100.0, 2024).expect("simulates");
    let wic =
        Wic::nested(Model::parse("3*AR1()+WN()+RW()+QN()+DR()").expect("valid")).expect("valid");
    let mut group = c.benchmark_group("selection/asymptotic_63");
    // seconds per run: ten samples are the minimum criterion accepts
    group.sample_size(10);
    group.throughput(Throughput::Elements(N as u64));
    group.bench_function(format!("{N}"), |b| {
        b.iter(|| wic.select(&x, 100.0).expect("selects"))
    });
    group.finish();
}

criterion_group!(selection, benches);
criterion_main!(selection);
