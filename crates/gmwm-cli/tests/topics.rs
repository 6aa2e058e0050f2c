//! End-to-end tests of `gmwm topics` on recordings written by the Python `rosbags` package
//! (`crates/gmwm/tests/fixtures/write_imu_bag.py`): the table, the JSON shape, and one test per
//! bad-input class. Without Python 3 and rosbags these tests fail, saying
//! `python3 -m pip install rosbags`.

mod common;

use common::{assert_one_line_error, gmwm, run_json};
use std::path::{Path, PathBuf};
use std::process::Command;

const SCRIPT: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../gmwm/tests/fixtures/write_imu_bag.py"
);

/// Writes `dir/name` with the fixture script (100 messages per IMU topic at 100 Hz).
fn write(dir: &Path, name: &str, container: &str, extra: &[&str]) -> PathBuf {
    let path = dir.join(name);
    let out = Command::new("python3")
        .arg(SCRIPT)
        .args(["--container", container, "--out"])
        .arg(&path)
        .args(["--n", "100", "--rate", "100", "--seed", "3"])
        .args(["--gyro-wn-density", "1e-4", "--gyro-rw-density", "1e-6"])
        .args(["--accel-wn-density", "1e-3", "--accel-rw-density", "1e-5"])
        .args(extra)
        .output()
        .unwrap_or_else(|e| {
            panic!("cannot run python3 ({e}): install Python 3 and: python3 -m pip install rosbags")
        });
    assert!(
        out.status.success(),
        "write_imu_bag.py failed (needs: python3 -m pip install rosbags):\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    path
}

#[test]
fn topics_table_marks_the_imu_topic_read_by_default() {
    let dir = tempfile::tempdir().unwrap();
    let bag = write(
        dir.path(),
        "run.bag",
        "ros1",
        &["--extra-topic", "/chatter:std_msgs/msg/String"],
    );
    let out = gmwm().arg("topics").arg(&bag).output().unwrap();
    assert!(out.status.success(), "{out:?}");
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines,
        [
            format!("{} (ROS1 bag): 2 topics", bag.display()).as_str(),
            "  topic     type               messages  imu",
            "  /chatter  std_msgs/String          10",
            "  /imu0     sensor_msgs/Imu         100  IMU (default)",
        ]
    );
}

#[test]
fn topics_json_has_the_documented_shape() {
    let dir = tempfile::tempdir().unwrap();
    let bag = write(
        dir.path(),
        "run",
        "mcap",
        &[
            "--topic",
            "/imu0",
            "--topic",
            "/imu1",
            "--extra-topic",
            "/tf:tf2_msgs/msg/TFMessage",
        ],
    );
    let doc = run_json(gmwm().arg("topics").arg(&bag).arg("--json"));
    assert_eq!(doc["file"], bag.display().to_string());
    assert_eq!(doc["container"], "mcap");
    let topics = doc["topics"].as_array().unwrap();
    assert_eq!(topics.len(), 3);
    assert_eq!(
        topics[0],
        serde_json::json!({"topic": "/imu0", "message_type": "sensor_msgs/msg/Imu",
                           "messages": 100, "is_imu": true})
    );
    assert_eq!(topics[1]["topic"], "/imu1");
    assert_eq!(
        topics[2],
        serde_json::json!({"topic": "/tf", "message_type": "tf2_msgs/msg/TFMessage",
                           "messages": 10, "is_imu": false})
    );
}

#[test]
fn topics_with_two_imu_topics_says_none_is_the_default() {
    let dir = tempfile::tempdir().unwrap();
    let db = write(
        dir.path(),
        "run",
        "sqlite3",
        &["--topic", "/imu0", "--topic", "/imu1"],
    );
    let out = gmwm().arg("topics").arg(&db).output().unwrap();
    assert!(out.status.success(), "{out:?}");
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("(rosbag2 sqlite3): 2 topics"), "{text}");
    assert!(!text.contains("(default)"), "{text}");
    assert!(
        text.ends_with(
            "note: several sensor_msgs/Imu topics: /imu0, /imu1; choose one with --topic\n"
        ),
        "{text}"
    );
}

#[test]
fn topics_not_a_recording_is_a_one_line_error() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("notes.txt");
    std::fs::write(&p, "just text\n").unwrap();
    assert_one_line_error(
        gmwm().arg("topics").arg(&p),
        &["notes.txt: not a ROS recording: expected a ROS1 bag"],
    );
    assert_one_line_error(
        gmwm().arg("topics").arg(dir.path().join("missing.bag")),
        &["missing.bag"],
    );
}

#[test]
fn topics_truncated_recording_is_a_one_line_error() {
    let dir = tempfile::tempdir().unwrap();
    let bag = write(dir.path(), "run.bag", "ros1", &[]);
    let bytes = std::fs::read(&bag).unwrap();
    let cut = dir.path().join("cut.bag");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    assert_one_line_error(
        gmwm().arg("topics").arg(&cut),
        &["cut.bag: corrupt or truncated ROS1 bag: ", "cut short"],
    );
}
