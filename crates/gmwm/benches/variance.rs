//! Criterion benches of the variance kernels.
use criterion::{criterion_group, criterion_main, Criterion};

fn benches(_c: &mut Criterion) {}

criterion_group!(variance, benches);
criterion_main!(variance);
