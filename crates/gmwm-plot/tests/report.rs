//! The HTML report of a calibration of a simulated IMU: structure, figures, numbers from the
//! calibration, self-containment, and an axis whose contamination check is off.

use gmwm::{
    simulate_model, Calibration, CalibrationOptions, Column as ImuColumn, Imu, Sensor, SensorInfo,
};
use gmwm_plot::report::{render, ReportContext};
use gmwm_plot::style::number;

fn imu() -> Imu {
    let model: gmwm::Model = "WN(sigma2=1e-4)+RW(gamma2=1e-10)".parse().unwrap();
    let columns = ["gyro_x", "accel_x"]
        .iter()
        .enumerate()
        .map(|(k, name)| ImuColumn {
            name: name.to_string(),
            values: simulate_model(&model, 1 << 14, 100.0, k as u64 + 1).unwrap(),
        })
        .collect();
    let info = vec![
        SensorInfo {
            sensor: Sensor::Gyroscope,
            axis: "X".into(),
            unit: Some("rad/s".into()),
        },
        SensorInfo {
            sensor: Sensor::Accelerometer,
            axis: "X".into(),
            unit: Some("m/s^2".into()),
        },
    ];
    Imu::new(columns, info, 100.0).unwrap()
}

fn options() -> CalibrationOptions {
    CalibrationOptions {
        full_model: "AR1()+WN()+RW()".parse().unwrap(),
        bootstrap: 10,
        draws: Some(1000),
        ..CalibrationOptions::default()
    }
}

#[test]
fn report_holds_every_section_and_the_calibration_numbers() {
    let report = Calibration::new(options()).run(&imu()).unwrap();
    let ctx = ReportContext {
        file: "sim.csv".into(),
        json: serde_json::to_string(&report).unwrap(),
        exports: vec![(
            "kalibr".into(),
            "imu.yaml".into(),
            "accelerometer_noise_density: 1\n".into(),
        )],
        ..ReportContext::default()
    };
    let html = render(&report, &ctx).unwrap();
    // one WV grid and one PSD grid, then per axis selection, fit, IEEE and classical-vs-robust
    // figures
    assert_eq!(html.matches("<figure>").count(), 2 + 4 * report.axes.len());
    assert_eq!(
        html.matches("data:image/svg+xml;base64,").count(),
        2 + 4 * report.axes.len()
    );
    assert!(html.contains("Power spectral density of every axis"));
    assert!(report.axes.iter().all(|a| a.psd.is_some()));
    for section in [
        "id=\"recording\"",
        "id=\"overview\"",
        "id=\"wv\"",
        "id=\"filters\"",
        "id=\"axis-gyro_x\"",
        "id=\"axis-accel_x\"",
    ] {
        assert!(html.contains(section), "{section}");
    }
    for axis in &report.axes {
        let n = axis.noise_density.as_ref().unwrap();
        assert!(html.contains(&number(n.value)), "{}: N", axis.column);
        assert!(
            html.contains(&axis.verdict.summary),
            "{}: verdict",
            axis.column
        );
    }
    assert!(html.contains("imu.yaml") && html.contains("accelerometer_noise_density"));
    assert!(!html.contains("src=\"http") && !html.contains("href=\"http"));
    assert!(html.contains("@media print"));
}

#[test]
fn report_without_a_psd_says_so_instead_of_a_figure() {
    let mut report = Calibration::new(options()).run(&imu()).unwrap();
    report.axes.iter_mut().for_each(|a| a.psd = None);
    let html = render(&report, &ReportContext::default()).unwrap();
    assert_eq!(html.matches("<figure>").count(), 1 + 4 * report.axes.len());
    assert!(html.contains("No power spectral density"));
}

#[test]
fn report_says_when_contamination_was_not_checked() {
    let report = Calibration::new(CalibrationOptions {
        robust_check: None,
        ..options()
    })
    .run(&imu())
    .unwrap();
    let html = render(&report, &ReportContext::default()).unwrap();
    assert_eq!(html.matches("<figure>").count(), 2 + 3 * report.axes.len());
    assert!(html.contains("Not compared"));
    assert!(html.contains("No filter file was exported"));
}
