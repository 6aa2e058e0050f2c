//! The engine as a library user sees it: only the public API, on a known truth. The engine's
//! own tests (reference data, properties, Monte Carlo) live inside the crate, `src/tests/`,
//! because they reach kernels this API does not show.

use gmwm::{
    read_table, simulate_model, wavelet_variance, Calibration, CalibrationOptions, Gmwm, Imu,
    Model, ReadOptions, WvOptions,
};
use std::io::Write;

const FREQ_HZ: f64 = 100.0;

/// White noise of variance 4e-4 plus a random walk of increment variance 1e-8, 2^16 samples.
fn truth() -> Vec<f64> {
    let model: Model = "WN(4e-4)+RW(1e-8)".parse().expect("a model text");
    simulate_model(&model, 1 << 16, FREQ_HZ, 7).expect("a simulation")
}

#[test]
fn fit_recovers_a_known_truth_through_the_public_api() {
    let x = truth();
    let wv = wavelet_variance(&x, FREQ_HZ, &WvOptions::default()).expect("a WV");
    assert_eq!(
        wv.wv().len(),
        15,
        "floor(log2(2^16)) - 1 levels (docs/methods.md §1.6)"
    );
    let fit = Gmwm::parse("WN()+RW()")
        .expect("a model text")
        .fit(&x, FREQ_HZ, &WvOptions::default())
        .expect("a fit");
    let theta = fit.theta();
    // The white-noise variance is estimated from 65536 samples mostly at the first scales: a
    // relative error of a few percent; the random walk from the last octaves: within a factor 2.
    assert!(
        (theta[0] / 4e-4 - 1.0).abs() < 0.05,
        "sigma2 = {}",
        theta[0]
    );
    assert!(
        (theta[1] / 1e-8).ln().abs() < 2f64.ln(),
        "gamma2 = {}",
        theta[1]
    );
}

#[test]
fn calibrate_a_csv_recording_through_the_public_api() {
    let x = truth();
    let mut file = tempfile::Builder::new()
        .suffix(".csv")
        .tempfile()
        .expect("a temporary file");
    writeln!(file, "time,gyro_x").unwrap();
    for (i, v) in x.iter().enumerate() {
        writeln!(file, "{},{}", i as f64 / FREQ_HZ, v).unwrap();
    }
    file.flush().unwrap();
    let table = read_table(file.path(), &ReadOptions::default()).expect("the CSV reads");
    let imu = Imu::from_table(table).expect("an IMU");
    let report = Calibration::new(CalibrationOptions::default())
        .run(&imu)
        .expect("a calibration");
    assert_eq!(report.axes.len(), 1);
    let axis = &report.axes[0];
    assert_eq!(axis.column, "gyro_x");
    assert!(
        axis.canonical_model.contains("WN"),
        "white noise is selected: {}",
        axis.canonical_model
    );
}
