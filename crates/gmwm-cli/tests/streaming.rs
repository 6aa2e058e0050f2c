//! Issue 14: the wavelet variance streamed from a raw binary file (`gmwm wv FILE --format
//! f64|f32`, one pass in blocks, memory independent of N) equals the in-memory one of the same
//! values, on every shared recording and for both raw formats.
//!
//! The in-memory path is taken on the very same file by giving it a time column (which turns
//! streaming off). Both subtract the same offset (the mean of the first 2048 samples) and run
//! the same Haar pyramid, but sum the squared coefficients in different groupings (the
//! in-memory kernel in tiles of levels and phases, the accumulator block by block, each
//! compensated), so they agree to rounding, not bit for bit: 1e-12 relative at every level.

mod common;

use common::{gmwm, run_json};
use std::path::{Path, PathBuf};

const TOL: f64 = 1e-12;

fn shared_data() -> PathBuf {
    std::env::var_os("GMWM_DATA_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"))
}

/// Every recording of the shared data: (file name, columns).
type Columns = Vec<(String, Vec<f64>)>;

fn recordings() -> Vec<(String, Columns)> {
    let mut names: Vec<String> = std::fs::read_dir(shared_data())
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".csv.gz"))
        .collect();
    names.sort();
    assert!(names.len() >= 7, "the shared recordings: {names:?}");
    names
        .into_iter()
        .map(|name| {
            let table = gmwm::read_table(&shared_data().join(&name), &gmwm::ReadOptions::default())
                .unwrap();
            let columns = table
                .columns
                .into_iter()
                .map(|c| (c.name, c.values))
                .collect();
            (name, columns)
        })
        .collect()
}

/// Writes the columns interleaved as little-endian `f64` or `f32`, optionally after a time
/// column (seconds at 100 Hz), with a sidecar naming the columns.
fn write_raw(
    dir: &Path,
    stem: &str,
    columns: &[(String, Vec<f64>)],
    f32: bool,
    time: bool,
) -> PathBuf {
    let ext = if f32 { "f32" } else { "f64" };
    let path = dir.join(format!("{stem}{}.{ext}", if time { "_t" } else { "" }));
    let n = columns[0].1.len();
    let mut bytes = Vec::with_capacity(n * (columns.len() + 1) * 8);
    for t in 0..n {
        let row = time
            .then_some(t as f64 / 100.0)
            .into_iter()
            .chain(columns.iter().map(|c| c.1[t]));
        for v in row {
            if f32 {
                bytes.extend_from_slice(&(v as f32).to_le_bytes());
            } else {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    std::fs::write(&path, bytes).unwrap();
    let names: Vec<serde_json::Value> = time
        .then(|| serde_json::json!({"name": "time"}))
        .into_iter()
        .chain(columns.iter().map(|c| serde_json::json!({"name": c.0})))
        .collect();
    let sidecar = serde_json::json!({ "sampling_frequency_hz": 100.0, "columns": names });
    std::fs::write(
        dir.join(format!(
            "{}.json",
            path.file_name().unwrap().to_str().unwrap()
        )),
        sidecar.to_string(),
    )
    .unwrap();
    path
}

fn wv_json(file: &Path, format: &str, ncols: usize, time: bool) -> serde_json::Value {
    let mut cmd = gmwm();
    cmd.arg("wv")
        .arg(file)
        .args(["--format", format, "--ncols", &ncols.to_string(), "--json"]);
    if time {
        cmd.args(["--time-column", "1", "--time-unit", "s"]);
    }
    run_json(&mut cmd)
}

#[test]
fn streaming_equals_in_memory_on_every_shared_recording_and_raw_format() {
    let dir = tempfile::tempdir().unwrap();
    let mut compared = 0;
    for (name, columns) in recordings() {
        let stem = name.trim_end_matches(".csv.gz");
        for f32 in [false, true] {
            let format = if f32 { "f32" } else { "f64" };
            let streamed = write_raw(dir.path(), stem, &columns, f32, false);
            let in_memory = write_raw(dir.path(), stem, &columns, f32, true);
            let a = wv_json(&streamed, format, columns.len(), false);
            let b = wv_json(&in_memory, format, columns.len() + 1, true);
            let (sa, sb) = (
                a["series"].as_array().unwrap(),
                b["series"].as_array().unwrap(),
            );
            assert_eq!(sa.len(), columns.len(), "{name} {format}");
            assert_eq!(
                sb.len(),
                columns.len(),
                "{name} {format}: the time column is not a series"
            );
            for (x, y) in sa.iter().zip(sb) {
                assert_eq!(x["name"], y["name"]);
                assert_eq!(x["n"], y["n"], "{name} {format} {}", x["name"]);
                let (wx, wy) = (x["wv"].as_array().unwrap(), y["wv"].as_array().unwrap());
                assert_eq!(wx.len(), wy.len(), "{name} {format} {}: levels", x["name"]);
                for (j, (u, v)) in wx.iter().zip(wy).enumerate() {
                    let (u, v) = (u.as_f64().unwrap(), v.as_f64().unwrap());
                    assert!(
                        ((u - v) / v).abs() < TOL,
                        "{name} {format} {} level {}: streamed {u} against in memory {v}",
                        x["name"],
                        j + 1
                    );
                }
                compared += 1;
            }
        }
        std::fs::remove_dir_all(dir.path()).ok();
        std::fs::create_dir_all(dir.path()).unwrap();
    }
    println!("{compared} series compared");
}

/// Issue 14: `gmwm fit` of a raw binary file streams it too (the WV and the range of the start
/// search in one pass, [`gmwm::binary_columns_wv`]); its fit equals the fit of the
/// same values loaded (through a time column, which turns streaming off), with the same N and
/// range, to the optimiser's precision (the two WVs differ by rounding only).
#[test]
fn fit_of_a_raw_binary_file_streams_to_the_fit_of_the_loaded_values() {
    let dir = tempfile::tempdir().unwrap();
    let sim = common::simulate(
        dir.path(),
        "sim.f64",
        "AR1(phi=0.99, sigma2=0.1)+WN(sigma2=1)",
        300_000,
        100.0,
        14,
    );
    let values: Vec<f64> = std::fs::read(&sim)
        .unwrap()
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
        .collect();
    let columns = vec![("x".to_string(), values)];
    let streamed = write_raw(dir.path(), "walk", &columns, false, false);
    let loaded = write_raw(dir.path(), "walk", &columns, false, true);
    let fit = |file: &Path, extra: &[&str]| {
        let mut cmd = gmwm();
        cmd.arg("fit")
            .arg(file)
            .args(["--format", "f64", "--model", "AR1()+WN()", "--json"])
            .args(extra);
        run_json(&mut cmd)["fits"][0]["fit"].clone()
    };
    let a = fit(&streamed, &["--ncols", "1"]);
    let b = fit(
        &loaded,
        &["--ncols", "2", "--time-column", "1", "--time-unit", "s"],
    );
    assert_eq!(
        a["inputs"], b["inputs"],
        "N and the range of the start search"
    );
    let (ta, tb) = (
        a["theta"].as_array().unwrap(),
        b["theta"].as_array().unwrap(),
    );
    assert_eq!(ta.len(), tb.len());
    for (u, v) in ta.iter().zip(tb) {
        let (u, v) = (u.as_f64().unwrap(), v.as_f64().unwrap());
        assert!(
            ((u - v) / v).abs() < 1e-8,
            "streamed {u} against loaded {v}"
        );
    }
}

#[test]
fn streamed_columns_are_the_ones_the_loader_analyses() {
    // a raw f64 file of three interleaved columns, a gyroscope axis among them: streamed, `gmwm
    // wv` analyses the sensor axis and notes the others, as the loader does for a CSV
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("imu.f64");
    let n = 4096;
    let bytes: Vec<u8> = (0..n)
        .flat_map(|i| {
            let x = (i as f64 * 0.37).sin();
            [20.0 + 0.001 * i as f64, x, (i % 7) as f64]
        })
        .flat_map(f64::to_le_bytes)
        .collect();
    std::fs::write(&path, bytes).unwrap();
    std::fs::write(
        dir.path().join("imu.f64.json"),
        r#"{"sampling_frequency_hz": 100, "format": "f64", "n_columns": 3,
            "columns": [{"name": "temp"}, {"name": "gyro_x"}, {"name": "counter"}]}"#,
    )
    .unwrap();
    let out = gmwm().arg("wv").arg(&path).arg("--json").output().unwrap();
    assert!(out.status.success(), "{out:?}");
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let names: Vec<&str> = doc["series"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["gyro_x"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("not analysed: temp, counter"), "{stderr}");
    // --columns still takes any column
    let doc = run_json(
        gmwm()
            .arg("wv")
            .arg(&path)
            .args(["--json", "--columns", "counter,gyro_x"]),
    );
    assert_eq!(doc["series"][0]["name"], "counter");
    assert_eq!(doc["series"][1]["name"], "gyro_x");
}

// ---- issue 14: text and binary IMU records streamed (`--stream-from`) ----

/// `gmwm wv FILE --json` with extra flags: the document and stderr.
fn wv_doc(file: &Path, extra: &[&str]) -> (serde_json::Value, String) {
    let out = gmwm()
        .arg("wv")
        .arg(file)
        .arg("--json")
        .args(extra)
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    (
        serde_json::from_slice(&out.stdout).unwrap(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Streamed (`--stream-from 1`) and loaded (the default: these files are below 2^24 rows)
/// give the same series, N, rate and WV within 1e-12 (the same values, summed in another
/// grouping, as for raw binary above), and the same notes and warnings on stderr.
fn streamed_equals_loaded(file: &Path, extra: &[&str]) -> usize {
    // the streamed pass splices across gaps; the loaded one does when asked to
    let extra = &[extra, &["--gaps", "contiguous"]].concat();
    let (a, ea) = wv_doc(file, &[extra, &["--stream-from", "1"][..]].concat());
    let (b, eb) = wv_doc(file, extra);
    assert_eq!(ea, eb, "{}: stderr", file.display());
    let (sa, sb) = (
        a["series"].as_array().unwrap(),
        b["series"].as_array().unwrap(),
    );
    assert_eq!(sa.len(), sb.len(), "{}", file.display());
    for (x, y) in sa.iter().zip(sb) {
        assert_eq!(x["name"], y["name"]);
        assert_eq!(x["n"], y["n"]);
        assert_eq!(x["freq_hz"], y["freq_hz"]);
        let (wx, wy) = (x["wv"].as_array().unwrap(), y["wv"].as_array().unwrap());
        assert_eq!(wx.len(), wy.len());
        for (u, v) in wx.iter().zip(wy) {
            let (u, v) = (u.as_f64().unwrap(), v.as_f64().unwrap());
            assert!(((u - v) / v).abs() < TOL, "{}: {u} {v}", file.display());
        }
    }
    sa.len()
}

#[test]
fn streamed_text_equals_loaded_on_every_shared_recording() {
    let mut names: Vec<String> = std::fs::read_dir(shared_data())
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".csv.gz"))
        .collect();
    names.sort();
    assert!(names.len() >= 7);
    let series: usize = names
        .iter()
        .map(|n| streamed_equals_loaded(&shared_data().join(n), &[]))
        .sum();
    assert!(series >= 37, "{series}");
}

fn record_bytes(kind: &str, time: f64, counts: [i32; 6]) -> Vec<u8> {
    let mut out = time.to_le_bytes().to_vec();
    for c in counts {
        if matches!(kind, "ixsea" | "navchip-flt") {
            out.extend_from_slice(&f64::from(c).to_le_bytes());
        } else {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    out
}

#[test]
fn streamed_records_equal_loaded_for_every_type() {
    let dir = tempfile::tempdir().unwrap();
    for kind in [
        "imar",
        "ln200",
        "ln200ig",
        "ixsea",
        "navchip-int",
        "navchip-flt",
    ] {
        let path = dir.path().join(format!("{kind}.bin"));
        let mut bytes = Vec::new();
        let mut state = 11u64;
        for i in 0..30_000u32 {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let c = |k: u64| ((state >> (8 * k)) % 2001) as i32 - 1000;
            // 400 Hz with a gap of 40 epochs
            let time = 50.0 + f64::from(i + if i >= 9000 { 40 } else { 0 }) / 400.0;
            bytes.extend(record_bytes(
                kind,
                time,
                [c(0), c(1), c(2), c(3), c(4), 8000 + c(5)],
            ));
        }
        std::fs::write(&path, bytes).unwrap();
        assert_eq!(streamed_equals_loaded(&path, &["--format", kind]), 6);
    }
}

#[test]
fn streamed_csv_with_time_column_equals_loaded() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("imu.csv");
    let mut text = String::from("timestamp [ns],gyro_x,gyro_y,accel_z,temp\n");
    let mut t: i64 = 1_700_000_000_000_000_000;
    for i in 0..40_000i64 {
        t += 5_000_000 + (i * 7919 % 97) * 1000 + if i % 15_000 == 3 { 60_000_000 } else { 0 };
        let x = ((i * 31337) % 1000) as f64 / 1000.0;
        text.push_str(&format!("{t},{x},{},{},{}\n", 1.0 - x, 9.8 + x * 1e-3, 25));
    }
    std::fs::write(&path, text).unwrap();
    assert_eq!(streamed_equals_loaded(&path, &[]), 3);
    let (_, stderr) = wv_doc(&path, &["--stream-from", "1"]);
    assert!(stderr.contains("gap"), "{stderr}");
    assert!(stderr.contains("not analysed"), "{stderr}");
}

/// `gmwm calibrate` of a CSV streamed: the spool's streamed calibration, which says so, with
/// the same axes as the loaded one.
#[test]
fn calibrate_streams_a_csv_from_the_threshold() {
    let dir = tempfile::tempdir().unwrap();
    let sim = common::simulate(
        dir.path(),
        "sim.f64",
        "WN(sigma2=1e-4)+RW(gamma2=1e-10)",
        200_000,
        100.0,
        3,
    );
    let values: Vec<f64> = std::fs::read(&sim)
        .unwrap()
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
        .collect();
    let path = dir.path().join("imu.csv");
    let mut text = String::from("time,gyro_x,accel_x\n");
    for (i, v) in values.iter().enumerate() {
        text.push_str(&format!("{},{v},{}\n", i as f64 / 100.0, 9.8 + v));
    }
    std::fs::write(&path, text).unwrap();
    let report = |extra: &[&str]| {
        run_json(
            gmwm()
                .arg("calibrate")
                .arg(&path)
                .args(["--json", "-"])
                .args(extra),
        )
    };
    let streamed = report(&["--stream-from", "1"]);
    let loaded = report(&[]);
    let s = streamed.to_string();
    assert!(s.contains("streamed from the file"), "{s}");
    assert!(!loaded.to_string().contains("streamed from the file"));
    let axes = |d: &serde_json::Value| -> Vec<String> {
        d["report"]["axes"]
            .as_array()
            .map(|a| a.iter().map(|x| x["column"].to_string()).collect())
            .unwrap_or_default()
    };
    assert_eq!(axes(&streamed), axes(&loaded));
}

// ---- issue 14: ROS recordings streamed (`--stream-from`) ----

/// Writes a ROS recording with the real writer (Python `rosbags`,
/// `crates/gmwm/tests/fixtures/write_imu_bag.py`): 5000 messages at 200 Hz on /imu0 and
/// /imu1, plus a String topic.
fn write_ros(dir: &Path, name: &str, container: &str, compression: &str) -> PathBuf {
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../gmwm/tests/fixtures/write_imu_bag.py"
    );
    let path = dir.join(name);
    let out = std::process::Command::new("python3")
        .arg(script)
        .args(["--container", container, "--compression", compression])
        .arg("--out")
        .arg(&path)
        .args(["--n", "5000", "--rate", "200", "--seed", "11"])
        .args(["--topic", "/imu0", "--topic", "/imu1"])
        .args(["--gyro-wn-density", "1e-4", "--gyro-rw-density", "1e-6"])
        .args(["--accel-wn-density", "1e-3", "--accel-rw-density", "1e-5"])
        .args(["--extra-topic", "/status:std_msgs/msg/String"])
        .output()
        .unwrap_or_else(|e| panic!("cannot run python3 ({e}): python3 -m pip install rosbags"));
    assert!(
        out.status.success(),
        "the fixture writer failed (python3 -m pip install rosbags): {}",
        String::from_utf8_lossy(&out.stderr)
    );
    path
}

/// `gmwm wv BAG --stream-from 1` (the streamed ROS reader) and the default (in memory: these
/// recordings are far below 2^24 messages) give the same series within 1e-12 and the same
/// notes on stderr, on every container; with a topic, a selection and a rate too.
#[test]
fn streamed_ros_equals_loaded_on_every_container() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (name, container, compression) in [
        ("plain.bag", "ros1", "none"),
        ("lz4.bag", "ros1", "lz4"),
        ("bz2.bag", "ros1", "bz2"),
        ("mcap_bag", "mcap", "none"),
        ("zstd_bag", "mcap", "zstd"),
        ("db3_bag", "sqlite3", "none"),
    ] {
        let path = write_ros(d, name, container, compression);
        assert_eq!(streamed_equals_loaded(&path, &["--topic", "/imu1"]), 6);
        assert_eq!(
            streamed_equals_loaded(
                &path,
                &[
                    "--topic",
                    "/imu0",
                    "--columns",
                    "gyro_z,accel_x",
                    "--freq",
                    "100"
                ]
            ),
            2
        );
    }
}

/// `gmwm calibrate BAG --stream-from 1`: the spool's streamed calibration, of the same axes
/// and with the same notes on the recording (topic, timing, samples' account) as the loaded
/// one.
#[test]
fn calibrate_streams_a_ros_recording_from_the_threshold() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_ros(dir.path(), "run.bag", "ros1", "lz4");
    let report = |extra: &[&str]| {
        run_json(
            gmwm()
                .arg("calibrate")
                .arg(&path)
                .args(["--json", "-", "--topic", "/imu0"])
                .args(extra),
        )
    };
    let streamed = report(&["--stream-from", "1"]);
    let loaded = report(&[]);
    let s = streamed.to_string();
    assert!(s.contains("streamed from the file"), "{s}");
    assert!(!loaded.to_string().contains("streamed from the file"));
    let axes = |d: &serde_json::Value| -> Vec<String> {
        d["axes"]
            .as_array()
            .map(|a| {
                a.iter()
                    .map(|x| format!("{} {} {} {}", x["column"], x["kind"], x["axis"], x["unit"]))
                    .collect()
            })
            .unwrap_or_default()
    };
    assert_eq!(axes(&streamed).len(), 6);
    assert_eq!(axes(&streamed), axes(&loaded));
    for key in ["notes", "rows", "name", "freq_hz", "samples"] {
        assert_eq!(streamed[key], loaded[key], "{key}");
    }
}
