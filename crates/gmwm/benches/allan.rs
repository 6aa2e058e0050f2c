//! Criterion benches of the Allan variance (docs/methods.md §3.2): the O(N)-per-octave overlapping
//! estimator on seeded white noise, all octave cluster lengths (`2m <= N`).
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use gmwm::{allan_variance, AllanOptions};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// Seed of the benchmark series.
const SEED: u64 = 12_345;
/// Product size of STYLE §7 (and of allantools' 1.33 s timing in `shared/ref`).
const N: usize = 10_000_000;

fn white_noise(n: usize) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let normal = Normal::new(0.0, 1.0).expect("unit normal");
    (0..n).map(|_| normal.sample(&mut rng)).collect()
}

fn benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("avar/overlapping");
    // 10 samples of ~0.5 s each keep the run short on two cores
    group.sample_size(10);
    let n = N;
    let x = white_noise(n);
    let opts = AllanOptions::default();
    group.throughput(Throughput::Elements(n as u64));
    group.bench_with_input(BenchmarkId::from_parameter(n), &x, |b, x| {
        b.iter(|| allan_variance(x, 1.0, &opts).expect("valid series"))
    });
    group.finish();
}

criterion_group!(allan, benches);
criterion_main!(allan);
