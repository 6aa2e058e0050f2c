//! Criterion benches of the wavelet-variance kernels (STYLE §7): Haar MODWT WV at N = 1e6 and
//! 1e7 and robust WV at 1e6, on seeded white noise. Compare with `shared/ref/README.md`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use gmwm::{wavelet_variance, RobustConvention, RobustOptions, WvOptions};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

fn white_noise(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| StandardNormal.sample(&mut rng)).collect()
}

fn bench_wv(c: &mut Criterion) {
    let mut group = c.benchmark_group("wv");
    group.sample_size(10);
    for n in [1_000_000usize, 10_000_000] {
        let x = white_noise(n, 42);
        group.throughput(Throughput::Elements(n as u64));
        group.bench_with_input(BenchmarkId::new("haar-modwt", n), &x, |b, x| {
            b.iter(|| wavelet_variance(x, 1.0, &WvOptions::default()).expect("valid series"))
        });
    }
    let n = 1_000_000usize;
    let x = white_noise(n, 43);
    let opts = WvOptions {
        robust: Some(RobustOptions::new(0.6, RobustConvention::Exact).expect("valid eff")),
        ..WvOptions::default()
    };
    group.throughput(Throughput::Elements(n as u64));
    group.bench_with_input(BenchmarkId::new("robust-haar-modwt", n), &x, |b, x| {
        b.iter(|| wavelet_variance(x, 1.0, &opts).expect("valid series"))
    });
    group.finish();
}

criterion_group!(variance, bench_wv);
criterion_main!(variance);
