//! ROS recordings (`gmwm::imu::ros`): fixtures written by a real writer (the Python `rosbags`
//! package, through `tests/fixtures/write_imu_bag.py`) in every container, read back exactly;
//! topic listing and choice; one test per bad-input class.
//!
//! Python 3 with `rosbags` is required: without it these tests fail, saying how to install it
//! (`python3 -m pip install rosbags`; CI's `.ci/run` does).

use gmwm::imu::ros::{
    choose_topic, container_of, list_topics, read_imu_messages, ImuMessages, RosContainer,
    RosError, TopicInfo,
};
use gmwm::imu::ReadError;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

const SCRIPT: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/fixtures/write_imu_bag.py"
);
const INSTALL: &str = "python3 -m pip install rosbags";

/// Messages per IMU topic of the round-trip fixtures: about 2.3 MB of messages, so that ROS1
/// and MCAP writers (1 MiB chunks) spread them over three chunks.
const N: usize = 7000;
const RATE: f64 = 200.0;
/// Header stamps of message k: T0 + k / RATE (the script's t0).
const T0_NS: i64 = 1_700_000_000_000_000_000;
const LOG_DELAY_NS: i64 = 1234;

/// Runs the fixture writer; a missing Python or `rosbags` fails the test with the install hint.
fn write_fixture(args: &[&str]) {
    let out = Command::new("python3")
        .arg(SCRIPT)
        .args(args)
        .output()
        .unwrap_or_else(|e| {
            panic!("cannot run python3 ({e}): the ROS tests need Python 3 with rosbags: {INSTALL}")
        });
    assert!(
        out.status.success(),
        "write_imu_bag.py {args:?} failed (the ROS tests need Python 3 with rosbags: \
         {INSTALL}):\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn noise_args(n: usize, seed: u64) -> Vec<String> {
    [
        "--n",
        &n.to_string(),
        "--rate",
        &RATE.to_string(),
        "--seed",
        &seed.to_string(),
        "--gyro-wn-density",
        "1e-4",
        "--gyro-rw-density",
        "1e-6",
        "--accel-wn-density",
        "1e-3",
        "--accel-rw-density",
        "1e-5",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

/// One written recording and the values the writer put in it.
struct Fixture {
    path: PathBuf,
    /// topic -> rows of (header stamp, log time, frame_id, 6 values).
    values: BTreeMap<String, Vec<Row>>,
}

#[derive(Debug, Clone, PartialEq)]
struct Row {
    stamp: i64,
    log: i64,
    frame: String,
    v: [f64; 6],
}

fn read_values(path: &Path) -> BTreeMap<String, Vec<Row>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut out: BTreeMap<String, Vec<Row>> = BTreeMap::new();
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let mut v = [0.0; 6];
        for (k, x) in v.iter_mut().enumerate() {
            *x = f[5 + k].parse().unwrap();
        }
        out.entry(f[0].to_owned()).or_default().push(Row {
            stamp: f[2].parse().unwrap(),
            log: f[3].parse().unwrap(),
            frame: f[4].to_owned(),
            v,
        });
    }
    out
}

/// Writes `name` in `dir` with `extra` flags (plus the noise flags of `n`, `seed`).
fn make(dir: &Path, name: &str, container: &str, n: usize, seed: u64, extra: &[&str]) -> Fixture {
    let path = dir.join(name);
    let csv = dir.join(format!("{name}.values.csv"));
    let mut args: Vec<String> = vec![
        "--container".into(),
        container.into(),
        "--out".into(),
        path.display().to_string(),
        "--values-out".into(),
        csv.display().to_string(),
    ];
    args.extend(noise_args(n, seed));
    args.extend(extra.iter().map(|s| s.to_string()));
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    write_fixture(&refs);
    Fixture {
        path,
        values: read_values(&csv),
    }
}

/// The shared fixtures, written once per test run.
struct Fixtures {
    _dir: tempfile::TempDir,
    ros1: Fixture,
    ros1_lz4: Fixture,
    ros1_bz2: Fixture,
    mcap: Fixture,
    mcap_zstd: Fixture,
    sqlite: Fixture,
    /// /imu0 and /imu1, plus /chatter (String) and /tf (TFMessage), 300 messages each.
    two_imu: [Fixture; 3],
}

fn fixtures() -> &'static Fixtures {
    static F: OnceLock<Fixtures> = OnceLock::new();
    F.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let delay = LOG_DELAY_NS.to_string();
        let common = [
            "--log-delay-ns",
            &delay,
            "--frame-id",
            "imu_link",
            "--extra-topic",
            "/chatter:std_msgs/msg/String",
        ];
        let with = |more: &[&'static str]| -> Vec<&str> {
            common.iter().copied().chain(more.iter().copied()).collect()
        };
        let extras = [
            "--topic",
            "/imu0",
            "--topic",
            "/imu1",
            "--extra-topic",
            "/chatter:std_msgs/msg/String",
            "--extra-topic",
            "/tf:tf2_msgs/msg/TFMessage",
        ];
        Fixtures {
            ros1: make(d, "plain.bag", "ros1", N, 1, &with(&[])),
            ros1_lz4: make(d, "lz4.bag", "ros1", N, 2, &with(&["--compression", "lz4"])),
            ros1_bz2: make(d, "bz2.bag", "ros1", N, 3, &with(&["--compression", "bz2"])),
            mcap: make(d, "mcap_bag", "mcap", N, 4, &with(&[])),
            mcap_zstd: make(
                d,
                "zstd_bag",
                "mcap",
                N,
                5,
                &with(&["--compression", "zstd"]),
            ),
            sqlite: make(d, "db3_bag", "sqlite3", N, 6, &with(&[])),
            two_imu: [
                make(d, "two.bag", "ros1", 300, 7, &extras),
                make(d, "two_mcap", "mcap", 300, 8, &extras),
                make(d, "two_db3", "sqlite3", 300, 9, &extras),
            ],
            _dir: dir,
        }
    })
}

/// The storage file inside a rosbag2 folder.
fn storage_file(folder: &Path, ext: &str) -> PathBuf {
    let name = folder.file_name().unwrap().to_string_lossy();
    folder.join(format!("{name}.{ext}"))
}

/// Asserts that `m` holds exactly the written rows of `topic`.
fn assert_exact(m: &ImuMessages, fx: &Fixture, topic: &str) {
    let rows = &fx.values[topic];
    assert_eq!(m.topic, topic);
    assert_eq!(m.len(), rows.len(), "{}", m.path.display());
    assert_eq!(m.frame_id.as_deref(), Some(rows[0].frame.as_str()));
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(m.header_stamp_ns[k], r.stamp, "header stamp of message {k}");
        assert_eq!(m.log_time_ns[k], r.log, "log time of message {k}");
        for a in 0..3 {
            // exact: the values are float64 copied bit for bit
            assert_eq!(
                m.angular_velocity[a][k].to_bits(),
                r.v[a].to_bits(),
                "gyro {a} of {k}"
            );
            assert_eq!(
                m.linear_acceleration[a][k].to_bits(),
                r.v[3 + a].to_bits(),
                "accel {a} of {k}"
            );
        }
    }
    // the writer's stamps, independently: t_k = t0 + k / rate
    assert_eq!(m.header_stamp_ns[0], T0_NS);
    assert_eq!(m.header_stamp_ns[200], T0_NS + 1_000_000_000);
    assert_eq!(m.log_time_ns[1], T0_NS + 5_000_000 + LOG_DELAY_NS);
    // a static IMU: the accelerometer z axis measures gravity
    assert!((m.linear_acceleration[2][0] - 9.80665).abs() < 0.1);
}

fn read(path: &Path) -> ImuMessages {
    read_imu_messages(path, None).unwrap_or_else(|e| panic!("{e}"))
}

fn err(path: &Path, topic: Option<&str>) -> String {
    let e = read_imu_messages(path, topic).expect_err("an error");
    let text = e.to_string();
    assert!(!text.contains('\n'), "one line: {text}");
    text
}

#[test]
fn ros_ros1_bag_round_trips_values_exactly() {
    let f = fixtures();
    let m = read(&f.ros1.path);
    assert_eq!(m.container, RosContainer::Ros1Bag);
    assert_exact(&m, &f.ros1, "/imu0");
}

#[test]
fn ros_ros1_compressed_chunks_round_trip() {
    let f = fixtures();
    for fx in [&f.ros1_lz4, &f.ros1_bz2] {
        let m = read(&fx.path);
        assert_eq!(m.container, RosContainer::Ros1Bag);
        assert_exact(&m, fx, "/imu0");
    }
}

#[test]
fn ros_mcap_round_trips_from_folder_file_and_metadata() {
    let f = fixtures();
    for fx in [&f.mcap, &f.mcap_zstd] {
        let file = storage_file(&fx.path, "mcap");
        for p in [fx.path.clone(), file, fx.path.join("metadata.yaml")] {
            assert_eq!(
                container_of(&p),
                Some(RosContainer::Mcap),
                "{}",
                p.display()
            );
            let m = read(&p);
            assert_eq!(m.container, RosContainer::Mcap);
            assert_eq!(m.path, p);
            assert_exact(&m, fx, "/imu0");
        }
    }
}

#[test]
fn ros_sqlite3_round_trips_from_folder_and_file() {
    let f = fixtures();
    let file = storage_file(&f.sqlite.path, "db3");
    for p in [f.sqlite.path.clone(), file] {
        assert_eq!(container_of(&p), Some(RosContainer::Sqlite3));
        let m = read(&p);
        assert_eq!(m.container, RosContainer::Sqlite3);
        assert_exact(&m, &f.sqlite, "/imu0");
    }
}

#[test]
fn ros_per_message_zstd_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    for (container, name) in [("sqlite3", "msg_db3"), ("mcap", "msg_mcap")] {
        let delay = LOG_DELAY_NS.to_string();
        let extra = ["--compression", "message", "--log-delay-ns", &delay];
        let fx = make(dir.path(), name, container, 300, 11, &extra);
        let m = read(&fx.path);
        assert_exact_values(&m, &fx, "/imu0");
        assert_eq!(m.frame_id.as_deref(), Some("imu_link"));
    }
}

/// The bag as a recorder leaves it when stopped before closing: `index_pos = 0` in the bag
/// header and no index section.
fn unindexed_copy(src: &Path, dst: &Path) {
    let mut bytes = std::fs::read(src).unwrap();
    let key = b"index_pos=";
    let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len();
    let mut index_pos = [0u8; 8];
    index_pos.copy_from_slice(&bytes[at..at + 8]);
    bytes.truncate(u64::from_le_bytes(index_pos) as usize);
    bytes[at..at + 8].fill(0);
    std::fs::write(dst, bytes).unwrap();
}

#[test]
fn ros_unindexed_ros1_bag_is_scanned() {
    let f = fixtures();
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("unindexed.bag");
    unindexed_copy(&f.ros1_lz4.path, &p);
    assert_eq!(
        topics(&p),
        [
            info("/chatter", "std_msgs/String", 700),
            info("/imu0", "sensor_msgs/Imu", N as u64)
        ]
    );
    assert_exact(&read(&p), &f.ros1_lz4, "/imu0");
}

#[test]
fn ros_misnamed_files_are_recognised_by_magic() {
    let f = fixtures();
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (f.ros1_lz4.path.clone(), RosContainer::Ros1Bag, &f.ros1_lz4),
        (
            storage_file(&f.mcap.path, "mcap"),
            RosContainer::Mcap,
            &f.mcap,
        ),
        (
            storage_file(&f.sqlite.path, "db3"),
            RosContainer::Sqlite3,
            &f.sqlite,
        ),
    ];
    for (k, (src, container, fx)) in cases.iter().enumerate() {
        let p = dir.path().join(format!("recording{k}.dat"));
        std::fs::copy(src, &p).unwrap();
        assert_eq!(container_of(&p), Some(*container));
        assert_exact(&read(&p), fx, "/imu0");
    }
}

fn topics(path: &Path) -> Vec<TopicInfo> {
    list_topics(path).unwrap_or_else(|e| panic!("{e}")).1
}

fn info(topic: &str, ty: &str, n: u64) -> TopicInfo {
    TopicInfo {
        topic: topic.into(),
        message_type: ty.into(),
        messages: n,
    }
}

#[test]
fn ros_list_topics_gives_names_types_and_counts() {
    let f = fixtures();
    let [bag, mcap, db3] = &f.two_imu;
    let (c, t) = list_topics(&bag.path).unwrap();
    assert_eq!(c, RosContainer::Ros1Bag);
    assert_eq!(
        t,
        [
            info("/chatter", "std_msgs/String", 30),
            info("/imu0", "sensor_msgs/Imu", 300),
            info("/imu1", "sensor_msgs/Imu", 300),
            info("/tf", "tf2_msgs/TFMessage", 30),
        ]
    );
    assert!(t[1].is_imu() && t[2].is_imu() && !t[0].is_imu() && !t[3].is_imu());
    for (fx, container) in [(mcap, RosContainer::Mcap), (db3, RosContainer::Sqlite3)] {
        let (c, t) = list_topics(&fx.path).unwrap();
        assert_eq!(c, container);
        assert_eq!(
            t,
            [
                info("/chatter", "std_msgs/msg/String", 30),
                info("/imu0", "sensor_msgs/msg/Imu", 300),
                info("/imu1", "sensor_msgs/msg/Imu", 300),
                info("/tf", "tf2_msgs/msg/TFMessage", 30),
            ]
        );
    }
    assert_eq!(
        topics(&f.ros1_bz2.path),
        [
            info("/chatter", "std_msgs/String", 700),
            info("/imu0", "sensor_msgs/Imu", N as u64)
        ]
    );
    assert_eq!(
        topics(&f.mcap_zstd.path)[1],
        info("/imu0", "sensor_msgs/msg/Imu", N as u64)
    );
}

#[test]
fn ros_two_imu_topics_need_a_choice() {
    let f = fixtures();
    for fx in &f.two_imu {
        let e = err(&fx.path, None);
        assert!(
            e.contains("several sensor_msgs/Imu topics: /imu0, /imu1; choose one with --topic"),
            "{e}"
        );
        for topic in ["/imu0", "/imu1"] {
            let m = read_imu_messages(&fx.path, Some(topic)).unwrap();
            assert_exact_values(&m, fx, topic);
        }
        // the two topics carry different noise
        assert_ne!(fx.values["/imu0"][5].v, fx.values["/imu1"][5].v);
    }
}

/// Values, stamps and frame of `topic` (fixtures without the round-trip's log delay).
fn assert_exact_values(m: &ImuMessages, fx: &Fixture, topic: &str) {
    let rows = &fx.values[topic];
    assert_eq!(m.topic, topic);
    assert_eq!(m.len(), rows.len());
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(
            (m.header_stamp_ns[k], m.log_time_ns[k]),
            (r.stamp, r.log),
            "{k}"
        );
        let got = [
            m.angular_velocity[0][k],
            m.angular_velocity[1][k],
            m.angular_velocity[2][k],
            m.linear_acceleration[0][k],
            m.linear_acceleration[1][k],
            m.linear_acceleration[2][k],
        ];
        assert_eq!(got, r.v, "message {k}");
    }
}

#[test]
fn ros_unknown_topic_lists_the_topics() {
    let f = fixtures();
    let e = err(&f.two_imu[0].path, Some("/imu2"));
    assert!(
        e.ends_with(
            "two.bag: no topic /imu2; topics: /chatter (std_msgs/String), /imu0 \
             (sensor_msgs/Imu), /imu1 (sensor_msgs/Imu), /tf (tf2_msgs/TFMessage)"
        ),
        "{e}"
    );
    let e = err(&f.two_imu[1].path, Some("/imu2"));
    assert!(
        e.contains("no topic /imu2; topics: /chatter (std_msgs/msg/String)"),
        "{e}"
    );
}

#[test]
fn ros_non_imu_topic_gives_its_type() {
    let f = fixtures();
    let e = err(&f.two_imu[2].path, Some("/tf"));
    assert!(
        e.ends_with("two_db3: topic /tf carries tf2_msgs/msg/TFMessage, not sensor_msgs/Imu"),
        "{e}"
    );
    let e = err(&f.ros1.path, Some("/chatter"));
    assert!(
        e.ends_with("topic /chatter carries std_msgs/String, not sensor_msgs/Imu"),
        "{e}"
    );
}

#[test]
fn ros_recording_without_imu_topic_lists_what_it_has() {
    let dir = tempfile::tempdir().unwrap();
    let fx = make(
        dir.path(),
        "noimu.bag",
        "ros1",
        20,
        1,
        &["--no-imu", "--extra-topic", "/chatter:std_msgs/msg/String"],
    );
    let e = err(&fx.path, None);
    assert!(
        e.ends_with("noimu.bag: no sensor_msgs/Imu topic; topics: /chatter (std_msgs/String)"),
        "{e}"
    );
}

#[test]
fn ros_topic_without_messages_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    write_fixture(&[
        "--container",
        "mcap",
        "--out",
        &dir.path().join("empty").display().to_string(),
        "--topic",
        "/imu0",
        "--n",
        "0",
        "--rate",
        "100",
        "--seed",
        "1",
        "--gyro-wn-density",
        "1",
        "--gyro-rw-density",
        "0",
        "--accel-wn-density",
        "1",
        "--accel-rw-density",
        "0",
    ]);
    let e = err(&dir.path().join("empty"), None);
    assert!(e.ends_with("empty: topic /imu0 holds no messages"), "{e}");
    let e = err(&dir.path().join("empty"), Some("/imu0"));
    assert!(e.ends_with("empty: topic /imu0 holds no messages"), "{e}");
}

#[test]
fn ros_non_finite_value_names_message_and_field() {
    let dir = tempfile::tempdir().unwrap();
    for (container, name) in [
        ("ros1", "nan.bag"),
        ("mcap", "nan_mcap"),
        ("sqlite3", "nan_db3"),
    ] {
        let fx = make(dir.path(), name, container, 50, 1, &["--nan-at", "17"]);
        let e = err(&fx.path, None);
        assert!(
            e.contains(
                ": topic /imu0: message 17 (log time 1700000000.085000000 s): \
                        angular_velocity.y = NaN is not a finite number"
            ),
            "{e}"
        );
        match read_imu_messages(&fx.path, None) {
            Err(ReadError::Ros(RosError::Message { index, .. })) => assert_eq!(index, 17),
            other => panic!("{other:?}"),
        }
    }
}

/// Copies the first `len` bytes of `src` to `dst`.
fn truncated(src: &Path, dst: &Path, len: usize) {
    let bytes = std::fs::read(src).unwrap();
    std::fs::write(dst, &bytes[..len.min(bytes.len())]).unwrap();
}

#[test]
fn ros_truncated_files_give_one_line_errors() {
    let f = fixtures();
    let dir = tempfile::tempdir().unwrap();
    let files = [
        (f.ros1.path.clone(), "bag"),
        (f.ros1_lz4.path.clone(), "bag"),
        (f.ros1_bz2.path.clone(), "bag"),
        (storage_file(&f.mcap.path, "mcap"), "mcap"),
        (storage_file(&f.mcap_zstd.path, "mcap"), "mcap"),
        (storage_file(&f.sqlite.path, "db3"), "db3"),
    ];
    for (k, (src, ext)) in files.iter().enumerate() {
        let size = std::fs::metadata(src).unwrap().len() as usize;
        for cut in [size / 3, size / 2, size * 9 / 10, size - 1, 100, 20] {
            let p = dir.path().join(format!("cut{k}_{cut}.{ext}"));
            truncated(src, &p, cut);
            let e = err(&p, None);
            assert!(e.starts_with(&p.display().to_string()), "{e}");
            assert!(
                e.contains("truncated")
                    || e.contains("cut short")
                    || e.contains("malformed")
                    || e.contains("not a ROS recording"),
                "{}: {e}",
                p.display()
            );
            // listing fails too, or at least does not panic
            let _ = list_topics(&p);
        }
    }
}

#[test]
fn ros_random_bytes_are_not_a_recording() {
    let dir = tempfile::tempdir().unwrap();
    // a fixed xorshift stream: no magic of any container
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    let bytes: Vec<u8> = (0..65_536)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 24) as u8
        })
        .collect();
    for name in ["random.bag", "random.mcap", "random.db3", "random.bin"] {
        let p = dir.path().join(name);
        std::fs::write(&p, &bytes).unwrap();
        assert_eq!(container_of(&p), None);
        let e = err(&p, None);
        assert!(
            e.contains(&format!("{name}: not a ROS recording: expected")),
            "{e}"
        );
        assert!(list_topics(&p).is_err());
    }
    let e = err(&dir.path().join("random.bag"), None);
    assert!(
        e.ends_with("expected \"#ROSBAG V2.0\" at the start of a ROS1 bag"),
        "{e}"
    );
    // an empty folder is not a rosbag2 folder
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let e = err(&empty, None);
    assert!(
        e.contains("not a ROS recording: expected a rosbag2 folder"),
        "{e}"
    );
}

#[test]
fn ros_choose_topic_is_what_read_takes() {
    let f = fixtures();
    let t = topics(&f.sqlite.path);
    assert_eq!(
        choose_topic(&f.sqlite.path, &t, None).unwrap().topic,
        "/imu0"
    );
    let t = topics(&f.two_imu[0].path);
    assert!(choose_topic(&f.two_imu[0].path, &t, None).is_err());
    assert_eq!(
        choose_topic(&f.two_imu[0].path, &t, Some("/imu1"))
            .unwrap()
            .messages,
        300
    );
}

#[test]
#[ignore = "throughput on a large recording: GMWM_ROS_BENCH=PATH cargo test --release -p gmwm \
            --lib ros_read_throughput -- --ignored --nocapture"]
fn ros_read_throughput() {
    let path = PathBuf::from(std::env::var_os("GMWM_ROS_BENCH").expect("GMWM_ROS_BENCH=PATH"));
    let start = std::time::Instant::now();
    let m = read(&path);
    let s = start.elapsed().as_secs_f64();
    println!(
        "{}: {} messages of {} in {s:.3} s: {:.3e} messages/s",
        path.display(),
        m.len(),
        m.topic,
        m.len() as f64 / s
    );
}

#[test]
fn ros_flipped_bytes_never_panic() {
    let f = fixtures();
    let dir = tempfile::tempdir().unwrap();
    let files = [
        (f.two_imu[0].path.clone(), "bag"),
        (storage_file(&f.two_imu[1].path, "mcap"), "mcap"),
        (storage_file(&f.two_imu[2].path, "db3"), "db3"),
    ];
    for (src, ext) in files {
        let bytes = std::fs::read(&src).unwrap();
        let p = dir.path().join(format!("flipped.{ext}"));
        // 150 positions spread over the file, headers and indexes included
        for k in 0..150 {
            let at = (k * 7919 + k * k * 31) % bytes.len();
            let mut b = bytes.clone();
            b[at] ^= 0xA5;
            std::fs::write(&p, &b).unwrap();
            // an error or (a flipped value byte) data; never a panic
            if let Err(e) = read_imu_messages(&p, Some("/imu0")) {
                assert!(!e.to_string().contains('\n'), "{e}");
            }
            let _ = list_topics(&p);
        }
    }
}

/// Row accounting of a ROS recording: the messages read on the chosen IMU topic, all used in
/// each axis (or each selected one), and the messages on the other topics (the second IMU
/// topic, /chatter and /tf, as the container lists them) counted as holding no sample of it.
#[test]
fn ros_recording_accounts_for_other_topics() {
    let f = fixtures();
    for fx in &f.two_imu {
        let opts = gmwm::imu::RecordingOptions {
            topic: Some("/imu1".into()),
            ..Default::default()
        };
        let rec = gmwm::imu::Recording::open(&fx.path, &opts).unwrap();
        let s = &rec.samples;
        assert_eq!(
            (s.unit, s.read, s.used, s.missing),
            ("message", 300, 300, 0)
        );
        assert_eq!(s.columns.len(), 6);
        assert_eq!(s.without_samples.len(), 1);
        let others: u64 = topics(&fx.path)
            .iter()
            .filter(|t| t.topic != "/imu1")
            .map(|t| t.messages)
            .sum();
        assert!(others >= 300, "/imu0 alone has 300");
        assert_eq!(s.without_samples[0].count, others, "{}", fx.path.display());
        assert!(rec.notes.contains(&s.to_string()));
        assert!(
            s.to_string()
                .contains(&format!("no samples in {others} messages on other topics")),
            "{s}"
        );
        let opts = gmwm::imu::RecordingOptions {
            read: gmwm::imu::ReadOptions {
                columns: vec!["gyro_z".parse().unwrap()],
                ..Default::default()
            },
            ..opts
        };
        let rec = gmwm::imu::Recording::open(&fx.path, &opts).unwrap();
        assert_eq!(rec.samples.columns, ["gyro_z"]);
    }
}

// ---- issue 14: ROS recordings streamed (StreamedTable::open_recording) ----

/// A ROS recording streamed (reorder buffer, spool, streamed timing checks) says what
/// `Recording::open` says: the axes, rows, rate (bit for bit), timing report (bit for bit:
/// the same stamps, `StepStats` reproduces `check_times`), samples' account and notes (the
/// streamed reader adds none when the log times are in order and the checks within bounds),
/// and its WVs equal the in-memory ones within 1e-12: the spool holds the very values of the
/// messages, and the streamed pass differs from the in-memory kernel only in how it groups
/// the compensated sums of squares.
fn ros_streamed_equals_in_memory(path: &Path, opts: &gmwm::imu::RecordingOptions) {
    ros_streamed_equals_in_memory_noting(path, opts, &[]);
}

/// [`ros_streamed_equals_in_memory`], the streamed reader adding the notes `added`.
fn ros_streamed_equals_in_memory_noting(
    path: &Path,
    opts: &gmwm::imu::RecordingOptions,
    added: &[&str],
) {
    use gmwm::imu::read::stream::StreamedTable;
    let rec = gmwm::imu::Recording::open(path, opts).unwrap();
    let probe = gmwm::imu::Probe::of(path, &opts.read);
    let s = StreamedTable::open_recording(&probe, opts).unwrap();
    let names: Vec<String> = rec
        .imu
        .axes()
        .iter()
        .map(|a| a.column.name.clone())
        .collect();
    let shown = path.display();
    assert_eq!(s.names, names, "{shown}");
    assert_eq!(s.rows as usize, rec.imu.len(), "{shown}");
    assert_eq!(
        s.facts.freq_hz.map(f64::to_bits),
        Some(rec.imu.freq_hz().to_bits())
    );
    assert_eq!(s.facts.timing, rec.timing, "{shown}");
    assert_eq!(s.facts.samples, rec.samples, "{shown}");
    let notes: Vec<String> = rec
        .notes
        .iter()
        .cloned()
        .chain(added.iter().map(|a| a.to_string()))
        .collect();
    assert_eq!(s.notes, notes, "{shown}");
    assert_eq!(s.topic, rec.topic);
    let infos: Vec<_> = rec.imu.axes().iter().map(|a| a.info.clone()).collect();
    assert_eq!(s.sensor_infos(), infos, "{shown}");
    let freq = rec.imu.freq_hz();
    let wvs = s
        .wavelet_variance(freq, &gmwm::WvOptions::default())
        .unwrap();
    assert_eq!(wvs.len(), names.len());
    for (a, w) in rec.imu.axes().iter().zip(&wvs) {
        let m = gmwm::wavelet_variance(a.values(), freq, &gmwm::WvOptions::default()).unwrap();
        assert_eq!(m.wv().len(), w.wv().len());
        assert_eq!(m.n_coefficients(), w.n_coefficients());
        for (x, y) in m.wv().iter().zip(w.wv()) {
            assert!(
                (x - y).abs() <= 1e-12 * x.abs(),
                "{shown} {}: {x} {y}",
                a.column.name
            );
        }
    }
}

#[test]
fn ros_streamed_equals_in_memory_on_every_container() {
    let f = fixtures();
    let all = Default::default();
    for fx in [
        &f.ros1,
        &f.ros1_lz4,
        &f.ros1_bz2,
        &f.mcap,
        &f.mcap_zstd,
        &f.sqlite,
    ] {
        ros_streamed_equals_in_memory(&fx.path, &all);
    }
    // a storage file of a folder, alone
    ros_streamed_equals_in_memory(&storage_file(&f.mcap.path, "mcap"), &all);
    ros_streamed_equals_in_memory(&storage_file(&f.sqlite.path, "db3"), &all);
    for fx in &f.two_imu {
        // a topic chosen among two, other topics counted; a selection; a rate given
        let opts = gmwm::imu::RecordingOptions {
            topic: Some("/imu1".into()),
            ..Default::default()
        };
        ros_streamed_equals_in_memory(&fx.path, &opts);
        let opts = gmwm::imu::RecordingOptions {
            read: gmwm::imu::ReadOptions {
                columns: vec!["accel_y".parse().unwrap(), "2".parse().unwrap()],
                freq_hz: Some(150.0),
                ..Default::default()
            },
            ..opts
        };
        ros_streamed_equals_in_memory(&fx.path, &opts);
    }
}

/// The streamed reader's errors are the in-memory reader's: no choice among two IMU topics,
/// an unknown column, a non-finite value (named by message and field).
#[test]
fn ros_streamed_errors_are_the_in_memory_ones() {
    use gmwm::imu::read::stream::StreamedTable;
    let f = fixtures();
    let dir = tempfile::tempdir().unwrap();
    let nan = make(dir.path(), "nan.bag", "ros1", 50, 1, &["--nan-at", "7"]);
    let cases: Vec<(&Path, gmwm::imu::RecordingOptions)> = vec![
        (&f.two_imu[0].path, Default::default()),
        (&nan.path, Default::default()),
        (
            &f.ros1.path,
            gmwm::imu::RecordingOptions {
                read: gmwm::imu::ReadOptions {
                    columns: vec!["mag_x".parse().unwrap()],
                    ..Default::default()
                },
                ..Default::default()
            },
        ),
    ];
    for (path, opts) in cases {
        let m = gmwm::imu::Recording::open(path, &opts).unwrap_err();
        let probe = gmwm::imu::Probe::of(path, &opts.read);
        let s = StreamedTable::open_recording(&probe, &opts).unwrap_err();
        assert_eq!(s.to_string(), m.to_string(), "{}", path.display());
    }
}

/// Log times out of order in the file (the writer's `--late EVERY:BY`: every EVERY-th message
/// written BY messages late): within the reorder buffer (4096 messages) the streamed reader
/// puts them back in order on the fly; beyond it, it reads the topic again in memory and says
/// so. Either way it gives what `Recording::open` gives.
#[test]
fn ros_streamed_log_times_out_of_order() {
    let dir = tempfile::tempdir().unwrap();
    let fallback = "log times out of order beyond the streamed reader's buffer (4096 messages): \
                    the topic was read again in memory (64 bytes a message), sorted and spooled";
    for container in ["ros1", "mcap", "sqlite3"] {
        for (late, added) in [("7:10", &[][..]), ("97:5000", &[fallback][..])] {
            let name = format!("{container}-{}", late.replace(':', "-"));
            let delay = LOG_DELAY_NS.to_string();
            let args = ["--late", late, "--log-delay-ns", &delay];
            let fx = make(dir.path(), &name, container, N, 4, &args);
            let msgs = read(&fx.path);
            assert_exact(&msgs, &fx, "/imu0");
            // sqlite3 is read ordered by its timestamp column: never out of order
            let added = if container == "sqlite3" {
                &[][..]
            } else {
                added
            };
            ros_streamed_equals_in_memory_noting(&fx.path, &Default::default(), added);
        }
    }
}

/// A temperature topic at 1 Hz carrying a linear ramp from 5 to 35 °C over the IMU topic's
/// 20 s: read as a covariate, every IMU sample gets the ramp's value at its time (linear
/// interpolation of a linear function is exact), in every container; a topic shifted away in
/// time is one clear line.
#[test]
fn ros_temperature_topic_is_aligned_to_the_imu_samples() {
    let dir = tempfile::tempdir().unwrap();
    let n = 4001; // 20 s at 200 Hz: the last temperature message is at the last IMU sample
    let ramp = [
        "--temperature-topic",
        "/imu/temperature",
        "--temperature-ramp",
        "5:35",
        "--log-delay-ns",
        "1000",
    ];
    for (name, container) in [("t.bag", "ros1"), ("t_mcap", "mcap"), ("t_db3", "sqlite3")] {
        let fx = make(dir.path(), name, container, n, 11, &ramp);
        for asked in ["temperature", "/imu/temperature", "imu/temperature"] {
            let c = gmwm::read_ros_covariate(&fx.path, None, asked).unwrap();
            assert_eq!(c.topic.as_deref(), Some("/imu/temperature"));
            assert_eq!(c.unit, Some("degC"));
            assert_eq!(c.values.len(), n);
            for (k, v) in c.values.iter().enumerate() {
                let truth = 5.0 + 30.0 * k as f64 / (n - 1) as f64;
                // the stamps are whole ns of k / 200 s: the ramp's value to 1e-9 °C
                assert!(
                    (v - truth).abs() < 1e-9,
                    "{container} sample {k}: {v} vs {truth}"
                );
            }
            assert!(
                c.notes[0].contains("21 messages over 20.00 s"),
                "{:?}",
                c.notes
            );
        }
        // the magnitude of the IMU messages' own fields
        let f = gmwm::read_ros_covariate(&fx.path, None, "specific_force").unwrap();
        let rows = &fx.values["/imu0"];
        for (k, r) in rows.iter().enumerate() {
            let norm = (r.v[3].powi(2) + r.v[4].powi(2) + r.v[5].powi(2)).sqrt();
            assert!((f.values[k] - norm).abs() <= 1e-15 * norm, "{k}");
        }
    }
    // no overlap in time: one line naming both topics and how far apart they are
    let fx = make(
        dir.path(),
        "late.bag",
        "ros1",
        400,
        12,
        &["--temperature-topic", "/t", "--temperature-offset-s", "100"],
    );
    let e = gmwm::read_ros_covariate(&fx.path, None, "temperature")
        .unwrap_err()
        .to_string();
    assert!(!e.contains('\n'), "{e}");
    assert!(
        e.contains("covariate topic /t (2 messages")
            && e.contains("does not overlap the IMU topic /imu0")
            && e.contains("it begins 98.005000000 s after the IMU topic ends"),
        "{e}"
    );
}
