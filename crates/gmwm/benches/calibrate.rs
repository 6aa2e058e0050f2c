//! `calibrate/{raw,ros}/N`: the whole calibration of a simulated six-axis IMU read from disk,
//! as `gmwm calibrate` runs it (open the recording, then per axis WV, 63-candidate WIC
//! selection, identified fit, inference, canonical and IEEE read-off, all axes in parallel).
//!
//! `raw` reads IXSEA binary records (docs/methods.md §9.2: f64 time + six f64 increments, 56 bytes
//! per epoch); `ros` reads an MCAP file of `sensor_msgs/Imu` messages (CDR). N defaults to 10^6
//! per axis; `GMWM_BENCH_CALIBRATE_N=10000000` runs the size (one iteration takes
//! minutes: run it with `--sample-size 10` and expect a long wait).

// parallel per-axis arrays are indexed by sample throughout
#![allow(clippy::needless_range_loop)]

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use gmwm::{
    simulate_model, Calibration, CalibrationOptions, ImuRecordType, InputFormat, Model,
    ReadOptions, Recording, RecordingOptions,
};
use std::io::Write;
use std::path::Path;

const FREQ: f64 = 100.0;

fn n() -> usize {
    std::env::var("GMWM_BENCH_CALIBRATE_N")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000)
}

/// Six axes: gyroscopes in rad/s, accelerometers in m/s^2, each white noise, a random walk and
/// a Gauss–Markov bias of an industrial MEMS unit.
fn axes(n: usize) -> Vec<Vec<f64>> {
    let gyro: Model = "GM(beta=0.01, sigma2_gm=1e-8)+WN(sigma2=1e-5)+RW(gamma2=1e-12)"
        .parse()
        .unwrap();
    let accel: Model = "GM(beta=0.05, sigma2_gm=1e-6)+WN(sigma2=4e-4)+RW(gamma2=1e-10)"
        .parse()
        .unwrap();
    (0..6)
        .map(|k| {
            let m = if k < 3 { &gyro } else { &accel };
            simulate_model(m, n, FREQ, 100 + k as u64).unwrap()
        })
        .collect()
}

fn write_ixsea(path: &Path, axes: &[Vec<f64>]) {
    let t = ImuRecordType::Ixsea;
    let mut out = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    for i in 0..axes[0].len() {
        out.write_all(&(i as f64 / FREQ).to_le_bytes()).unwrap();
        for (k, a) in axes.iter().enumerate() {
            let scale = if k < 3 {
                t.scale_gyro()
            } else {
                t.scale_accel()
            };
            out.write_all(&(a[i] / (FREQ * scale)).to_le_bytes())
                .unwrap();
        }
    }
    out.flush().unwrap();
}

/// One `sensor_msgs/msg/Imu` in CDR (little-endian encapsulation, doubles aligned to 8).
fn imu_cdr(sec: i32, nsec: u32, gyro: [f64; 3], accel: [f64; 3], buf: &mut Vec<u8>) {
    buf.clear();
    buf.extend_from_slice(&[0, 1, 0, 0]);
    buf.extend_from_slice(&sec.to_le_bytes());
    buf.extend_from_slice(&nsec.to_le_bytes());
    let frame = b"imu_link\0";
    buf.extend_from_slice(&(frame.len() as u32).to_le_bytes());
    buf.extend_from_slice(frame);
    while (buf.len() - 4) % 8 != 0 {
        buf.push(0);
    }
    let mut doubles = |v: &[f64]| {
        for x in v {
            buf.extend_from_slice(&x.to_le_bytes());
        }
    };
    doubles(&[0.0, 0.0, 0.0, 1.0]);
    doubles(&[0.0; 9]);
    doubles(&gyro);
    doubles(&[0.0; 9]);
    doubles(&accel);
    doubles(&[0.0; 9]);
}

fn write_mcap(path: &Path, axes: &[Vec<f64>]) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut w = mcap::Writer::new(file).unwrap();
    let schema = w.add_schema("sensor_msgs/msg/Imu", "ros2msg", b"").unwrap();
    let channel = w
        .add_channel(schema, "/imu0", "cdr", &Default::default())
        .unwrap();
    let mut buf = Vec::with_capacity(400);
    let t0: u64 = 1_700_000_000_000_000_000;
    for i in 0..axes[0].len() {
        let t = t0 + (i as u64) * 10_000_000;
        let g = [axes[0][i], axes[1][i], axes[2][i]];
        let a = [axes[3][i], axes[4][i], axes[5][i]];
        imu_cdr(
            (t / 1_000_000_000) as i32,
            (t % 1_000_000_000) as u32,
            g,
            a,
            &mut buf,
        );
        w.write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id: channel,
                sequence: i as u32,
                log_time: t,
                publish_time: t,
            },
            &buf,
        )
        .unwrap();
    }
    w.finish().unwrap();
}

fn calibrate(path: &Path, format: InputFormat) -> usize {
    let rec = Recording::open(
        path,
        &RecordingOptions {
            read: ReadOptions {
                format,
                ..ReadOptions::default()
            },
            ..RecordingOptions::default()
        },
    )
    .unwrap();
    let report = Calibration::new(CalibrationOptions::default())
        .run(&rec.imu)
        .unwrap();
    report.axes.len()
}

fn bench_calibrate(c: &mut Criterion) {
    let n = n();
    let dir = tempfile::tempdir().unwrap();
    let data = axes(n);
    let raw = dir.path().join("imu.ixsea");
    let ros = dir.path().join("imu.mcap");
    write_ixsea(&raw, &data);
    write_mcap(&ros, &data);
    drop(data);
    let mut g = c.benchmark_group("calibrate");
    g.sample_size(10);
    g.throughput(Throughput::Elements((6 * n) as u64));
    g.bench_function(format!("raw/{n}"), |b| {
        b.iter(|| calibrate(&raw, InputFormat::ImuRecord(ImuRecordType::Ixsea)))
    });
    g.bench_function(format!("ros/{n}"), |b| {
        b.iter(|| calibrate(&ros, InputFormat::Auto))
    });
    g.finish();
}

criterion_group!(benches, bench_calibrate);
criterion_main!(benches);
