//! Rendering cost of the figures: the fit decomposition of a 2^20-sample series (20 levels,
//! four components) as SVG and as PNG, and the six-panel WV grid as SVG.

use criterion::{criterion_group, criterion_main, Criterion};
use gmwm::{simulate_model, Gmwm, WvOptions};
use gmwm_plot::{fit_figure, wv_figure, Column, Layout};

fn bench(c: &mut Criterion) {
    let model: gmwm::Model =
        "AR1(phi=0.999, sigma2=1e-8)+AR1(phi=0.9, sigma2=1e-6)+WN(sigma2=1e-4)+RW(gamma2=1e-12)"
            .parse()
            .unwrap();
    let x = simulate_model(&model, 1 << 20, 100.0, 1).unwrap();
    let fit = Gmwm::new("2*AR1()+WN()+RW()".parse().unwrap())
        .with_seed(1)
        .with_draws(2000)
        .fit(&x, 100.0, &WvOptions::default())
        .unwrap();
    let figure = fit_figure(&[Column::new("gyro_x", "rad/s", &fit)]);
    c.bench_function("fit_figure_svg", |b| b.iter(|| figure.svg().unwrap()));
    c.bench_function("fit_figure_png", |b| b.iter(|| figure.png().unwrap()));
    let wv = fit.empirical().cloned().unwrap();
    let names = [
        "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z",
    ];
    let columns: Vec<Column<'_, gmwm::WaveletVariance>> =
        names.iter().map(|n| Column::new(n, "u", &wv)).collect();
    let grid = wv_figure(&columns, Layout::Grid);
    c.bench_function("wv_grid_svg", |b| b.iter(|| grid.svg().unwrap()));
}

criterion_group!(benches, bench);
criterion_main!(benches);
