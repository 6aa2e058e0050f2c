//! Criterion bench of the streaming simulator (STYLE §7, docs/methods.md §10): 10^7 samples of the
//! NavChip-like truth 3*AR1 + WN + QN + RW (per-sample parameters, docs/methods.md §5.10, as
//! processes), simulator
//! built outside the timed loop, output buffer reused.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use gmwm::{Ar1, Process, Qn, Rw, Simulator, Wn};

fn navchip() -> Vec<Process> {
    vec![
        Ar1::new(0.9990005, 1.414585e-11).unwrap().into(),
        Ar1::new(0.9999749, 6.430559e-13).unwrap().into(),
        Ar1::new(0.9666488, 4.250234e-10).unwrap().into(),
        Wn::new(6.94e-7).unwrap().into(),
        Qn::new(2.29e-6).unwrap().into(),
        Rw::new(3.90e-14).unwrap().into(),
    ]
}

fn bench_simulate(c: &mut Criterion) {
    let mut group = c.benchmark_group("simulate");
    group.sample_size(10);
    let n = 10_000_000usize;
    let mut sim = Simulator::new(navchip(), 42).expect("valid parameters");
    let mut out = vec![0.0; n];
    group.throughput(Throughput::Elements(n as u64));
    group.bench_function(BenchmarkId::new("3ar1-wn-qn-rw", n), |b| {
        b.iter(|| {
            sim.fill(&mut out);
            out[n - 1]
        })
    });
    group.finish();
}

criterion_group!(simulate, bench_simulate);
criterion_main!(simulate);
