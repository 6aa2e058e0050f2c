//! Hostile inputs (issue 30): small files crafted to make a reader hold far more than their
//! content, each generated here (no large fixture) and run under a 1.5 GB address-space limit
//! and a time bound (`common::gmwm_bounded`): one error line naming the file and what is wrong,
//! exit 1, no abort, no panic, no hang. The MCAP summaries are in `topics.rs`; the chunk
//! decompression bounds in the engine's `imu::ros::decompress` tests.

mod common;

use flate2::write::GzEncoder;
use flate2::Compression;
use std::io::Write;
use std::path::Path;

/// A gzip file of `head` then `repeat` copies of `unit` (written in blocks: the test holds
/// megabytes, the file decompresses to `repeat * unit.len()` bytes).
fn gzip_bomb(path: &Path, head: &[u8], unit: &[u8], repeat: usize) {
    let mut enc = GzEncoder::new(std::fs::File::create(path).unwrap(), Compression::default());
    enc.write_all(head).unwrap();
    let block = unit.repeat((1 << 20) / unit.len().max(1));
    let mut left = repeat * unit.len();
    while left > 0 {
        let n = left.min(block.len());
        enc.write_all(&block[..n]).unwrap();
        left -= n;
    }
    enc.finish().unwrap();
}

fn assert_one_error(path: &Path, args: &[&str], needle: &str) {
    let out = common::gmwm_bounded()
        .args(args)
        .arg(path)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
    let errors: Vec<&str> = stderr
        .lines()
        .filter(|l| !l.starts_with("gmwm: note:") && !l.starts_with("gmwm: warning:"))
        .collect();
    assert_eq!(errors.len(), 1, "{args:?}: {stderr}");
    assert!(
        errors[0].starts_with("gmwm: error: ") && errors[0].contains(needle),
        "{args:?}: {stderr}"
    );
}

/// A 1 GiB line in a 1 MB gzip file, and a 1 GiB cell after a header: both were read whole.
#[test]
fn gzip_bombs_of_one_line_or_cell_stop_at_the_line_cap() {
    let dir = tempfile::tempdir().unwrap();
    let line = dir.path().join("line.csv.gz");
    gzip_bomb(&line, b"", b"1,", 1 << 29);
    let cell = dir.path().join("cell.csv.gz");
    gzip_bomb(&cell, b"time,gyro_x\n0.000,", b"1", 1 << 30);
    let size = std::fs::metadata(&cell).unwrap().len();
    assert!(size < 8 << 20, "{size} bytes");
    for path in [&line, &cell] {
        for command in ["wv", "calibrate"] {
            assert_one_error(path, &[command], "a line longer than 1 MiB");
        }
    }
}

/// A CSV of 10^6 columns (a 2.4 MB gzip): `wv`, `avar` and `plot` aborted; its header line is
/// beyond the line cap.
#[test]
fn a_million_columns_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("wide.csv.gz");
    let mut header: Vec<u8> = (0..1_000_000)
        .flat_map(|k| format!("c{k},").into_bytes())
        .collect();
    header.pop();
    header.push(b'\n');
    gzip_bomb(&path, &header, b"0.5,", 1_000_000);
    for command in ["wv", "avar"] {
        assert_one_error(&path, &[command], "a line longer than 1 MiB");
    }
}

/// `gmwm wv /dev/zero` (also `topics`, `calibrate`, and `-` fed from it) copied the device into
/// TMPDIR until the disk was full: a character device is refused before anything is copied.
#[test]
fn a_character_device_is_refused() {
    for command in ["wv", "topics", "calibrate"] {
        assert_one_error(Path::new("/dev/zero"), &[command], "is a character device");
    }
    let out = std::process::Command::new("bash")
        .args([
            "-c",
            &format!(
                "ulimit -v {} && exec timeout {} \"$0\" wv - --freq 100 < /dev/zero",
                common::MEMORY_LIMIT_KB,
                common::TIME_LIMIT_S
            ),
        ])
        .arg(assert_cmd::cargo::cargo_bin("gmwm"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("<stdin>: is a character device"),
        "{stderr}"
    );
}

/// A rosbag2 sqlite3 file whose schema is `schema` (the bag's real tables, views or crafted
/// columns), written by SQLite itself: a few KB.
fn sqlite_bag(path: &Path, schema: &str) {
    let db = rusqlite::Connection::open(path).unwrap();
    db.execute_batch(schema).unwrap();
}

/// Views in place of rosbag2's tables: one without end (`topics` hung), one of 10^9 rows
/// (sorted), one naming a topic with 900 MB; and a generated column of 900 MB in a table.
#[test]
fn sqlite_views_and_huge_values_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let topics = "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT, type TEXT, \
                  serialization_format TEXT, offered_qos_profiles TEXT); \
                  INSERT INTO topics VALUES (1, '/imu', 'sensor_msgs/msg/Imu', 'cdr', '');";
    let messages = "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER, \
                    timestamp INTEGER, data BLOB);";
    let cases = [
        (
            "endless",
            format!(
                "{topics} CREATE VIEW messages AS WITH RECURSIVE r(i) AS (SELECT 1 UNION ALL \
                 SELECT i + 1 FROM r) SELECT i AS id, 1 AS topic_id, i AS timestamp, \
                 x'00' AS data FROM r;"
            ),
            "`messages` is a view, not a table",
        ),
        (
            "billion",
            format!(
                "{topics} CREATE VIEW messages AS WITH RECURSIVE r(i) AS (SELECT 1 UNION ALL \
                 SELECT i + 1 FROM r WHERE i < 1000000000) SELECT i AS id, 1 AS topic_id, \
                 -i AS timestamp, x'00' AS data FROM r;"
            ),
            "`messages` is a view, not a table",
        ),
        (
            "name_view",
            format!(
                "{messages} CREATE VIEW topics AS SELECT 1 AS id, \
                 printf('%.*c', 900000000, 'x') AS name, 'sensor_msgs/msg/Imu' AS type, \
                 'cdr' AS serialization_format;"
            ),
            "`topics` is a view, not a table",
        ),
        (
            "name_column",
            format!(
                "{messages} CREATE TABLE topics(id INTEGER PRIMARY KEY, type TEXT, \
                 serialization_format TEXT, name TEXT GENERATED ALWAYS AS \
                 (printf('%.*c', 900000000, 'x')) VIRTUAL); \
                 INSERT INTO topics(id, type, serialization_format) \
                 VALUES (1, 'sensor_msgs/msg/Imu', 'cdr');"
            ),
            "longer than 16 MiB",
        ),
    ];
    for (name, schema, needle) in &cases {
        let path = dir.path().join(format!("{name}.db3"));
        sqlite_bag(&path, schema);
        for cmd in ["topics", "wv"] {
            assert_one_error(&path, &[cmd], needle);
        }
    }
}

/// Runs `gmwm ARGS` under the memory and time bounds and asserts it succeeds.
fn assert_bounded_success(args: &[&str]) -> String {
    let out = common::gmwm_bounded().args(args).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{args:?}: {stderr}");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A 3 KB saved WV claiming n = 2^40 over 40 levels: an ARMA fit summed 2^40 autocovariances
/// (4 TB); `implied` at 30 levels took 8.4 GB. Both now run in memory linear in the levels.
#[test]
fn arma_at_forty_levels_is_bounded() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("wv40.json");
    let tau: Vec<f64> = (1..=40).map(|j| 2f64.powi(j)).collect();
    let wv: Vec<f64> = tau.iter().map(|t| 1.0 / t).collect();
    let doc = serde_json::json!({
        "freq_hz": 100.0,
        "series": [{
            "name": "x", "n": 2f64.powi(40), "tau": tau, "wv": wv,
            "ci_low": wv.iter().map(|w| 0.9 * w).collect::<Vec<_>>(),
            "ci_high": wv.iter().map(|w| 1.1 * w).collect::<Vec<_>>(),
        }]
    });
    std::fs::write(&path, doc.to_string()).unwrap();
    assert!(std::fs::metadata(&path).unwrap().len() < 4096);
    let file = path.to_str().unwrap();
    for model in ["ARMA(2,1)", "AR(2)", "MA(2)"] {
        let out = assert_bounded_success(&["fit", file, "--model", model, "--json"]);
        let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
        let sigma2 = doc["fits"][0]["parameters"]
            .as_array()
            .and_then(|p| {
                p.iter()
                    .find(|p| p["name"].as_str().is_some_and(|n| n.ends_with("sigma2")))
            })
            .map(|p| p["value"].as_f64().unwrap());
        // the WV is white noise's (1/tau): the fitted innovation variance is about 1
        assert!(
            sigma2.is_some_and(|s| (s - 1.0).abs() < 0.05),
            "{model}: {out}"
        );
    }
    let out = assert_bounded_success(&[
        "implied",
        "--model",
        "ARMA(2,1)(ar1=0.5, ar2=-0.3, ma1=0.4, sigma2=1)",
        "--levels",
        "30",
        "--json",
    ]);
    assert!(out.contains("1073741824"), "{out}");
}

/// `gmwm shared` over 50 columns grew with the fourth power of the count (89 s, then an
/// abort): more than 16 series is refused before any work.
#[test]
fn shared_over_too_many_columns_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("wide.csv");
    let mut text: String = (0..50).map(|k| format!("c{k},")).collect();
    text.pop();
    text.push('\n');
    for r in 0..2000u64 {
        let row: Vec<String> = (0..50u64)
            .map(|k| ((r * 31 + k * 17) % 101).to_string())
            .collect();
        text.push_str(&row.join(","));
        text.push('\n');
    }
    std::fs::write(&path, text).unwrap();
    assert_one_error(
        &path,
        &[
            "shared", "--freq", "100", "--shared", "GM()", "--model", "WN()",
        ],
        "at most 16 series for a shared process",
    );
}

/// A 0.5 MB gzip of 2^28 valid rows: the streaming switch took its rows from the compressed
/// size and read it into memory (abort). Now its lines are counted as they decompress: `wv`
/// streams it in bounded memory, and `fit`, which holds the recording, stops with one line.
#[test]
fn a_gzip_of_2_pow_28_rows_streams_or_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rows.csv.gz");
    // "1" and "2" alternate: not constant, so the WV is computed to the end
    gzip_bomb(&path, b"x\n", b"1\n2\n", 1 << 27);
    assert!(std::fs::metadata(&path).unwrap().len() < 8 << 20);
    assert_one_error(
        &path,
        &["fit", "--freq", "100", "--model", "WN()"],
        "in memory failed",
    );
    // 2^27 rows for `wv` (a 1 GB spool), twice what an in-memory WV could hold here
    let half = dir.path().join("half.csv.gz");
    gzip_bomb(&half, b"x\n", b"1\n2\n", 1 << 26);
    // 2^27 rows fit once in the limit but not twice, as an in-memory WV holds them
    assert_one_error(
        &half,
        &["fit", "--freq", "100", "--model", "WN()"],
        "in memory failed",
    );
    let out = common::gmwm_bounded()
        .args(["wv", "--freq", "100"])
        .arg(&half)
        .env("TMPDIR", dir.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(stderr.contains("134217728 rows read"), "{stderr}");
}

/// A small IMU-like CSV: `header`, then white noise in two columns plus a slow walk.
fn small_csv(path: &Path, header: &str, rows: usize) {
    let mut text = format!("{header}\n");
    let (mut s, mut walk) = (0x9e37_79b9_7f4a_7c15u64, 0.0);
    let mut next = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for _ in 0..rows {
        walk += 1e-3 * next();
        text.push_str(&format!("{:.6},{:.6}\n", next() + walk, next()));
    }
    std::fs::write(path, text).unwrap();
}

const FAST: [&str; 8] = [
    "--freq",
    "100",
    "--model",
    "WN()+RW()",
    "--bootstrap",
    "2",
    "--G",
    "200",
];

/// A FIFO named like a recording in a batch folder hung the batch (opened, never written):
/// it is skipped with a warning, the other recordings are calibrated.
#[test]
fn a_fifo_in_a_batch_folder_is_skipped() {
    let dir = tempfile::tempdir().unwrap();
    small_csv(&dir.path().join("a.csv"), "gyro_x,gyro_y", 4096);
    small_csv(&dir.path().join("c.csv"), "gyro_x,gyro_y", 4096);
    let fifo = dir.path().join("b.csv");
    assert!(std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let out = common::gmwm_bounded()
        .arg("calibrate")
        .arg(dir.path())
        .args(FAST)
        .output()
        .unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert_eq!(out.status.code(), Some(0), "{stdout}\n{stderr}");
    assert!(
        stderr.contains("b.csv: not a regular file (a FIFO, socket or device): skipped"),
        "{stderr}"
    );
    assert!(
        stdout.contains("a.csv") && stdout.contains("c.csv"),
        "{stdout}"
    );
}

/// Control characters in a header's names (a backspace, an escape sequence) reached the
/// terminal raw and made the Kalibr YAML unparseable: they are escaped in every output.
#[test]
fn control_characters_in_names_are_escaped_in_every_output() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("imu.csv");
    small_csv(&csv, "gyro\u{8}_x,accel\u{1b}[31m_x", 4096);
    let yaml = dir.path().join("imu.yaml");
    let json = dir.path().join("cal.json");
    let out = common::gmwm_bounded()
        .arg("calibrate")
        .arg(&csv)
        .args(FAST)
        .args([
            "--gyro-unit",
            "rad/s",
            "--accel-unit",
            "m/s^2",
            "--export",
            "kalibr",
        ])
        .arg(&yaml)
        .arg("--json")
        .arg(&json)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    let raw = |bytes: &[u8]| bytes.iter().any(|&b| b < 0x20 && b != b'\n' || b == 0x7f);
    assert!(
        !raw(&out.stdout),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(!raw(&out.stderr), "{stderr}");
    let yaml = std::fs::read(&yaml).unwrap();
    assert!(!raw(&yaml), "{}", String::from_utf8_lossy(&yaml));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains(r"gyro\u{8}_x"), "{text}");
    // the JSON names the column as shown, JSON-escaped as JSON is
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(doc["axes"][0]["column"], r"gyro\u{8}_x", "{doc}");
}

/// A sidecar's keys that are not read (a typo, a misspelt unit key) are named in a warning;
/// a column's `unit` is read.
#[test]
fn unread_sidecar_keys_are_warned_and_column_units_read() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("imu.csv");
    small_csv(&csv, "gyro_x,accel_x", 2048);
    std::fs::write(
        dir.path().join("imu.json"),
        r#"{"sampling_frequency_hz": 100, "sampling_rate": 100, "license": "CC0",
            "columns": [{"name": "gyro_x", "unit": "deg/s"},
                        {"name": "accel_x", "unit": "g", "units": "g"}]}"#,
    )
    .unwrap();
    let out = common::gmwm_bounded()
        .arg("calibrate")
        .arg(&csv)
        .args(&FAST[2..])
        .output()
        .unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    // calibrate's summary carries the reader's warnings (other commands print them on stderr)
    let warning = stdout
        .lines()
        .find(|l| l.contains("not read"))
        .unwrap_or_else(|| panic!("{stdout}"));
    assert!(
        warning.contains("imu.json: keys not read: sampling_rate, columns[1].units")
            && warning.contains("a column's unit: columns[k].unit"),
        "{warning}"
    );
    // the columns' units, read from the sidecar, convert the data to SI
    assert!(
        stdout.contains("data in deg/s converted to rad/s"),
        "{stdout}"
    );
    assert!(stdout.contains("data in g converted to m/s^2"), "{stdout}");
}

/// A rosbag2 database listing 10^6 topics: merging them searched the list for every topic
/// (10^12 comparisons). They are merged through a map: `gmwm topics` lists them in seconds.
#[test]
fn a_million_topics_merge_in_n_log_n() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("topics.db3");
    let mut db = rusqlite::Connection::open(&path).unwrap();
    db.execute_batch(
        "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT, type TEXT, \
         serialization_format TEXT, offered_qos_profiles TEXT); \
         CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER, \
         timestamp INTEGER, data BLOB);",
    )
    .unwrap();
    let tx = db.transaction().unwrap();
    {
        let mut insert = tx
            .prepare("INSERT INTO topics VALUES (?1, '/t' || ?1, 'std_msgs/msg/Empty', 'cdr', '')")
            .unwrap();
        for k in 1..=1_000_000i64 {
            insert.execute([k]).unwrap();
        }
    }
    tx.commit().unwrap();
    drop(db);
    let out = common::gmwm_bounded()
        .args(["topics", "--json"])
        .arg(&path)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let topics = doc["topics"].as_array().expect("topics listed");
    assert_eq!(topics.len(), 1_000_000);
}
