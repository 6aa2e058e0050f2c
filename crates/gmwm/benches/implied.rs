//! Criterion benches of the implied Haar WV and its Jacobian (docs/methods.md §4.2, §4.5) for the
//! model 3*AR1 + WN + QN + RW at J = 20 levels (a navigation-grade gyro fit), summing per-process
//! results as the GMWM objective does.
use criterion::{criterion_group, criterion_main, Criterion};
use gmwm::{Ar1, LatentProcess, Process, Qn, Rw, Wn};

/// Levels of a 1e6-sample (or longer) record.
const LEVELS: usize = 20;

fn model() -> Vec<Process> {
    vec![
        Ar1::new(0.9990005, 1.414585e-11).expect("valid").into(),
        Ar1::new(0.9999749, 6.430559e-13).expect("valid").into(),
        Ar1::new(0.9666488, 4.250234e-10).expect("valid").into(),
        Wn::new(6.94e-7).expect("valid").into(),
        Qn::new(2.29e-6).expect("valid").into(),
        Rw::new(3.90e-14).expect("valid").into(),
    ]
}

fn benches(c: &mut Criterion) {
    let model = model();
    let mut group = c.benchmark_group("implied/3ar1_wn_qn_rw");
    // microsecond kernels: 20 samples are plenty and keep the run short on two cores
    group.sample_size(20);
    group.bench_function("wv/20", |b| {
        b.iter(|| {
            let mut total = vec![0.0; LEVELS];
            for p in &model {
                for (t, v) in total.iter_mut().zip(p.wv(LEVELS)) {
                    *t += v;
                }
            }
            total
        })
    });
    group.bench_function("jacobian/20", |b| {
        b.iter(|| model.iter().map(|p| p.jacobian(LEVELS)).collect::<Vec<_>>())
    });
    group.bench_function("wv_and_jacobian/20", |b| {
        b.iter(|| {
            let mut total = vec![0.0; LEVELS];
            let mut jac = Vec::with_capacity(model.len());
            for p in &model {
                for (t, v) in total.iter_mut().zip(p.wv(LEVELS)) {
                    *t += v;
                }
                jac.push(p.jacobian(LEVELS));
            }
            (total, jac)
        })
    });
    group.finish();
}

criterion_group!(implied, benches);
criterion_main!(implied);
