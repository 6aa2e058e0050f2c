//! The streamed calibration of a raw binary recording (`gmwm::calib::streamed`) against the
//! in-memory one, and its block-wise robust WV against the robust WV of the whole series.

use gmwm::calib::{Calibration, CalibrationOptions, ROBUST_LEVELS};
use gmwm::imu::{read_table, Imu, ReadOptions};
use gmwm::inference::NoProgress;
use gmwm::model::Model;
use gmwm::sim::simulate_model;
use gmwm::{wavelet_variance, RobustOptions, WvOptions};
use std::path::Path;

fn write_f64(path: &Path, columns: &[Vec<f64>]) {
    let n = columns[0].len();
    let mut bytes = Vec::with_capacity(8 * n * columns.len());
    for t in 0..n {
        for c in columns {
            bytes.extend_from_slice(&c[t].to_le_bytes());
        }
    }
    std::fs::write(path, bytes).unwrap();
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Two gyroscope axes in deg/s and a temperature column, 2^20 samples at 100 Hz: streamed and
/// in memory give the same WV (1e-12: the accumulator sums per block, the kernel per tile),
/// the same Allan variance (docs/methods.md §3.4, exact up to rounding; the in-memory one may have
/// one more cluster length, of one term), the same selected models, and
/// the same noise density and random walk within 1e-4 (the two fits start from different
/// values, the streamed one from the WV alone, and stop at the optimiser's tolerance).
#[test]
fn streamed_calibration_matches_in_memory() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("imu.f64");
    let n = 1 << 20;
    let m1 =
        Model::parse("WN(sigma2=1e-4)+RW(gamma2=1e-10)+GM(beta=0.05, sigma2_gm=1e-6)").unwrap();
    let m2 = Model::parse("WN(sigma2=4e-4)+RW(gamma2=4e-10)").unwrap();
    let x = simulate_model(&m1, n, 100.0, 1).unwrap();
    let y = simulate_model(&m2, n, 100.0, 2).unwrap();
    let temp: Vec<f64> = (0..n).map(|t| 25.0 + (t % 7) as f64 * 0.01).collect();
    write_f64(&path, &[x, y, temp]);
    std::fs::write(
        dir.path().join("imu.f64.json"),
        r#"{"sampling_frequency_hz": 100, "format": "f64", "n_columns": 3, "units": {"gyro": "deg/s"},
            "columns": [{"name": "gyro_x"}, {"name": "gyro_y"}, {"name": "temperature"}]}"#,
    )
    .unwrap();
    let read = ReadOptions::default();
    let streaming = Calibration::new(CalibrationOptions {
        stream_from: 1,
        ..CalibrationOptions::default()
    });
    let probe = gmwm::imu::Probe::of(&path, &read);
    assert!(streaming.streams(&probe, &read).unwrap());
    let streamed = streamed_calibration(&streaming, &path, &read);
    let imu = Imu::from_table(read_table(&path, &read).unwrap()).unwrap();
    let in_memory = Calibration::new(CalibrationOptions::default())
        .run(&imu)
        .unwrap();
    assert!(!Calibration::new(CalibrationOptions::default())
        .streams(&probe, &read)
        .unwrap());
    assert_eq!(streamed.axes.len(), 2);
    assert!(streamed.checks.iter().any(|c| c.starts_with("streamed")));
    for (s, m) in streamed.axes.iter().zip(&in_memory.axes) {
        assert_eq!(s.column, m.column);
        assert_eq!(s.samples, n);
        assert_eq!(s.unit, "rad/s");
        for j in 0..m.wv.wv().len() {
            assert!(
                rel(s.wv.wv()[j], m.wv.wv()[j]) < 1e-12,
                "{} WV level {}",
                s.column,
                j + 1
            );
            assert!(rel(s.wv.ci_high()[j], m.wv.ci_high()[j]) < 1e-12);
        }
        // the in-memory AV also has the one-term cluster m = N/2 beyond the WV's last level
        assert!(m.allan.avar().len() - s.allan.avar().len() <= 1);
        for (a, b) in s.allan.avar().iter().zip(m.allan.avar()) {
            assert!(rel(*a, *b) < 1e-12, "{} AV {a} vs {b}", s.column);
        }
        assert_eq!(s.model, m.model, "{}", s.column);
        let pairs = [
            (&s.noise_density, &m.noise_density),
            (&s.random_walk, &m.random_walk),
        ];
        for (es, em) in pairs {
            let (vs, vm) = (es.as_ref().unwrap().value, em.as_ref().unwrap().value);
            assert!(rel(vs, vm) < 1e-4, "{}: {vs} vs {vm}", s.column);
        }
        let c = s.contamination.as_ref().expect("a robust check");
        assert_eq!(c.levels, ROBUST_LEVELS.min(m.wv.wv().len()));
        assert!(!c.matters, "{}: {}", s.column, c.summary);
        // the PSD fed block by block is the in-memory one: the same segments, in order
        let (ps, pm) = (s.psd.as_ref().unwrap(), m.psd.as_ref().unwrap());
        assert_eq!(ps.frequency_hz(), pm.frequency_hz());
        assert_eq!(ps.unit(), "(rad/s)^2/Hz");
        for (a, b) in ps.density().iter().zip(pm.density()) {
            assert!(rel(*a, *b) < 1e-12, "{} PSD {a} vs {b}", s.column);
        }
    }
}

/// The robust WV of blocks of 2^21 samples, averaged, against the robust WV of the whole
/// series (2^23 samples, so 4 blocks), on white noise with 0.1% spikes: within a quarter of the
/// whole-series robust interval's half-width at every level up to 2^15 samples, and so far
/// from the classical WV the spikes inflate. Measured (this seed): at most 3.9% of the
/// half-width.
#[test]
fn streamed_robust_matches_whole_series() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("spiky.f64");
    let n = 1 << 23;
    let mut x = simulate_model(&Model::parse("WN(sigma2=1)").unwrap(), n, 1.0, 5).unwrap();
    for t in (0..n).step_by(997) {
        x[t] += 50.0;
    }
    write_f64(&path, &[x.clone()]);
    std::fs::write(
        dir.path().join("spiky.f64.json"),
        r#"{"sampling_frequency_hz": 1, "format": "f64", "units": {"gyro": "rad/s"},
            "columns": [{"name": "gyro_x"}]}"#,
    )
    .unwrap();
    let streamed = Calibration::new(CalibrationOptions {
        stream_from: 1,
        ..CalibrationOptions::default()
    });
    let streamed = streamed_calibration(&streamed, &path, &ReadOptions::default());
    let c = streamed.axes[0].contamination.as_ref().unwrap();
    assert!(c.matters, "{}", c.summary);
    let whole = wavelet_variance(
        &x,
        1.0,
        &WvOptions {
            levels: Some(ROBUST_LEVELS),
            robust: Some(RobustOptions::default()),
            ..WvOptions::default()
        },
    )
    .unwrap();
    let mut worst: f64 = 0.0;
    for j in 0..ROBUST_LEVELS {
        let half = 0.5 * (whole.ci_high()[j] - whole.ci_low()[j]);
        let off = (c.robust.wv()[j] - whole.wv()[j]).abs() / half;
        worst = worst.max(off);
        assert!(
            off < 0.25,
            "level {}: {} vs {} (half-width {half})",
            j + 1,
            c.robust.wv()[j],
            whole.wv()[j]
        );
    }
    eprintln!("streamed robust: worst difference {worst:.3} of the half-width");
}

/// A constant (dead) gyroscope column among live ones: the streamed calibration leaves it out
/// with a check line naming it and calibrates the others, as the in-memory one does.
#[test]
fn streamed_calibration_names_a_dead_column() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("dead.f64");
    let n = 1 << 16;
    let x = simulate_model(
        &Model::parse("WN(sigma2=1e-4)+RW(gamma2=1e-10)").unwrap(),
        n,
        100.0,
        3,
    )
    .unwrap();
    write_f64(&path, &[x, vec![0.25; n]]);
    std::fs::write(
        dir.path().join("dead.f64.json"),
        r#"{"sampling_frequency_hz": 100, "format": "f64", "n_columns": 2, "units": {"gyro": "rad/s"},
            "columns": [{"name": "gyro_x"}, {"name": "gyro_z"}]}"#,
    )
    .unwrap();
    let report = Calibration::new(CalibrationOptions {
        stream_from: 1,
        ..CalibrationOptions::default()
    });
    let report = streamed_calibration(&report, &path, &ReadOptions::default());
    assert_eq!(report.axes.len(), 1);
    assert_eq!(report.axes[0].column, "gyro_x");
    assert!(
        report.checks.iter().any(|c| c.contains("not calibrated")
            && c.contains("gyro_z")
            && c.contains("constant")),
        "{:?}",
        report.checks
    );
}

// ---- issue 14: streamed text and IMU records (gmwm::imu::read::stream) ----

use gmwm::imu::read::stream::StreamedTable;
use gmwm::imu::{ImuRecordType, Table};

/// The streamed table says what `read_table` says (columns, rows, rate, timing report bit for
/// bit, warnings, left-out columns) and its WVs equal the in-memory ones within 1e-12: the
/// spool holds the very values `read_table` gives (the same parser), and the streamed pass
/// differs from the in-memory kernel only in how it groups the compensated sums of squares.
fn same_as_in_memory(path: &Path, read: &ReadOptions) -> (Table, StreamedTable) {
    let table = read_table(path, read).unwrap();
    let streamed = StreamedTable::open(path, read).unwrap();
    let names: Vec<&str> = table.columns.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(streamed.names, names, "{}", path.display());
    assert_eq!(streamed.rows as usize, table.len());
    assert_eq!(
        streamed.facts.freq_hz.map(f64::to_bits),
        table.facts.freq_hz.map(f64::to_bits)
    );
    assert_eq!(
        streamed.facts.timing,
        table.facts.timing,
        "{}",
        path.display()
    );
    assert_eq!(streamed.facts.warnings, table.facts.warnings);
    assert_eq!(streamed.facts.skipped, table.facts.skipped);
    assert_eq!(streamed.facts.record_type, table.facts.record_type);
    let freq = table.facts.freq_hz.unwrap_or(1.0);
    let wvs = streamed
        .wavelet_variance(freq, &WvOptions::default())
        .unwrap();
    for (c, s) in table.columns.iter().zip(&wvs) {
        let m = wavelet_variance(&c.values, freq, &WvOptions::default()).unwrap();
        assert_eq!(m.wv().len(), s.wv().len());
        for (a, b) in m.wv().iter().zip(s.wv()) {
            assert!(
                rel(*b, *a) < 1e-12,
                "{} {}: {a} {b}",
                path.display(),
                c.name
            );
        }
        assert_eq!(m.n_coefficients(), s.n_coefficients());
    }
    (table, streamed)
}

#[test]
fn streamed_text_equals_in_memory_on_every_shared_recording() {
    let dir = std::env::var_os("GMWM_DATA_DIR")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".csv.gz"))
        .collect();
    names.sort();
    assert!(names.len() >= 7, "{names:?}");
    for name in names {
        same_as_in_memory(&dir.join(name), &ReadOptions::default());
    }
}

#[test]
fn streamed_records_equal_in_memory_for_every_type() {
    let dir = tempfile::tempdir().unwrap();
    for t in ImuRecordType::ALL {
        let path = dir.path().join(format!("{}.bin", t.name()));
        let mut bytes = Vec::new();
        let mut state = 7u64;
        let mut time = 1000.0;
        for i in 0..20_000 {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let c = |k: u64| ((state >> (8 * k)) % 2001) as i32 - 1000;
            // a gap of 50 epochs and quantised jitter
            time += if i == 5000 {
                0.25
            } else {
                0.005 + 1e-6 * (i % 3) as f64
            };
            bytes.extend(crate::tests::read::record(
                t,
                time,
                [c(0), c(1), c(2), 100 + c(3), c(4), -16000 + c(5)],
            ));
        }
        std::fs::write(&path, bytes).unwrap();
        let read = ReadOptions {
            format: gmwm::imu::InputFormat::ImuRecord(t),
            ..ReadOptions::default()
        };
        let (table, streamed) = same_as_in_memory(&path, &read);
        assert_eq!(table.facts.timing.unwrap().gaps.len(), 1, "{t}");
        assert!(streamed.notes.is_empty(), "{:?}", streamed.notes);
        // a column subset too
        let read = ReadOptions {
            columns: vec!["accel_z".parse().unwrap(), "2".parse().unwrap()],
            ..read
        };
        same_as_in_memory(&path, &read);
    }
}

/// A CSV with a time column in ns (epoch), with jitter and gaps; one in ms whose unit is
/// inferred from the steps (checked in memory, with a note); one in s with jitter on every
/// step (more distinct steps than the streamed check holds: checked in memory, with a note).
#[test]
fn streamed_text_with_time_column_equals_in_memory() {
    let dir = tempfile::tempdir().unwrap();
    let n = 50_000;
    let mut state = 3u64;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut ns = String::from("timestamp,gyro_x,accel_y,temp\n");
    let mut ms = String::from("time,gyro_x,accel_y\n");
    let mut s = String::from("time [s],gyro_x\n");
    let mut t_ns: i64 = 1_700_000_000_000_000_000;
    let mut t_ms: i64 = 0;
    for i in 0..n {
        let jitter = (next() * 200_000.0) as i64;
        t_ns += 5_000_000 + jitter - 100_000 + if i % 9000 == 17 { 40_000_000 } else { 0 };
        t_ms += if i % 7000 == 5 { 30 } else { 5 };
        let (g, a) = (next() - 0.5, 9.8 + 0.01 * (next() - 0.5));
        ns.push_str(&format!("{t_ns},{g},{a},{}\n", 25 + i % 3));
        ms.push_str(&format!("{t_ms},{g},{a}\n"));
    }
    // more rows than the streamed check holds distinct steps
    for i in 0..(gmwm::imu::timing::STREAM_DISTINCT_STEPS + 5000) {
        s.push_str(&format!(
            "{},{}\n",
            0.005 * i as f64 + 1e-5 * next(),
            next()
        ));
    }
    let write = |name: &str, text: &str| {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        path
    };
    let (table, streamed) = same_as_in_memory(&write("ns.csv", &ns), &ReadOptions::default());
    let timing = table.facts.timing.unwrap();
    assert!(!timing.gaps.is_empty() && timing.gaps[0].line.is_some());
    assert!(timing.jitter > 0.0);
    assert_eq!(table.facts.skipped, ["temp"]);
    assert!(streamed.notes.is_empty(), "{:?}", streamed.notes);
    let (_, streamed) = same_as_in_memory(&write("ms.csv", &ms), &ReadOptions::default());
    assert!(
        streamed.notes[0].contains("inferred"),
        "{:?}",
        streamed.notes
    );
    let (_, streamed) = same_as_in_memory(&write("s.csv", &s), &ReadOptions::default());
    assert!(
        streamed.notes[0].contains("distinct steps"),
        "{:?}",
        streamed.notes
    );
    // a bad cell: the same error, with its line
    let bad = ns.replacen(",9.8", ",x9.8", 1);
    let path = write("bad.csv", &bad);
    assert_eq!(
        StreamedTable::open(&path, &ReadOptions::default())
            .unwrap_err()
            .to_string(),
        read_table(&path, &ReadOptions::default())
            .unwrap_err()
            .to_string()
    );
}

/// The calibration of `path` as `gmwm calibrate` runs it ([`Calibration::open`] from its probe,
/// then [`Calibration::run_source`]), which must have chosen to stream it.
fn streamed_calibration(
    calibration: &Calibration,
    path: &std::path::Path,
    read: &ReadOptions,
) -> gmwm::calib::CalibrationReport {
    let source = calibration
        .open(
            &gmwm::imu::Probe::of(path, read),
            &gmwm::imu::RecordingOptions {
                read: read.clone(),
                topic: None,
            },
        )
        .unwrap();
    assert!(
        !matches!(source, gmwm::calib::CalibrationSource::Memory(_)),
        "{} read into memory, not streamed",
        path.display()
    );
    calibration.run_source(&source, &NoProgress).unwrap()
}
