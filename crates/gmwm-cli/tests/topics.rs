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

/// A 70 000-character topic name (issue 30): `gmwm topics` panicked ("Formatting argument out
/// of range"); the table now shows the name cut and escaped, under a memory and time bound.
#[test]
fn topics_with_a_huge_topic_name_is_bounded() {
    let dir = tempfile::tempdir().unwrap();
    let name = format!("/{}", "a".repeat(70_000));
    let bag = write(dir.path(), "long.bag", "ros1", &["--topic", &name]);
    let out = common::gmwm_bounded()
        .arg("topics")
        .arg(&bag)
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.contains(&format!("/{}...", "a".repeat(199))),
        "{table}"
    );
    assert!(table.lines().all(|l| l.chars().count() < 400), "{table}");
}

/// The records of an MCAP summary section: `(opcode, position, body length)`.
fn summary_records(bytes: &[u8]) -> Vec<(u8, usize, usize)> {
    let footer = bytes.len() - 8 - 29;
    assert_eq!(bytes[footer], 0x02, "footer record");
    let u64_at = |p: usize| u64::from_le_bytes(bytes[p..p + 8].try_into().unwrap()) as usize;
    let mut pos = u64_at(footer + 9);
    let mut out = Vec::new();
    while pos < footer {
        let len = u64_at(pos + 1);
        out.push((bytes[pos], pos, len));
        pos += 9 + len;
    }
    out
}

/// Hostile MCAP summaries (issue 30), each from a small file under a 1.5 GB address-space
/// limit: a channel's topic claiming 0xFFFFFFFF bytes (the `mcap` crate reserved 4 GiB and
/// aborted), a schema record claiming 4 GiB and 2^48 bytes. One error line, no abort.
#[test]
fn topics_hostile_mcap_summaries_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let bag = write(dir.path(), "small", "mcap", &[]);
    let file = bag.join("small.mcap");
    let bytes = std::fs::read(&file).unwrap();
    let records = summary_records(&bytes);
    let channel = records
        .iter()
        .find(|r| r.0 == 0x04)
        .expect("a channel record");
    let schema = records
        .iter()
        .find(|r| r.0 == 0x03)
        .expect("a schema record");
    let mut cases = Vec::new();
    // channel: id u16, schema id u16, then the topic's u32 length
    let mut topic = bytes.clone();
    topic[channel.1 + 9 + 4..channel.1 + 9 + 8].copy_from_slice(&u32::MAX.to_le_bytes());
    cases.push(("topic length", topic, "claims 4294967295 bytes"));
    for claim in [u32::MAX as u64, 1u64 << 48] {
        let mut long = bytes.clone();
        long[schema.1 + 1..schema.1 + 9].copy_from_slice(&claim.to_le_bytes());
        cases.push(("record length", long, "where the summary holds"));
    }
    for (what, content, needle) in cases {
        let path = dir.path().join("hostile.mcap");
        std::fs::write(&path, content).unwrap();
        let out = common::gmwm_bounded()
            .arg("topics")
            .arg(&path)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{what}: {stderr}");
        let lines: Vec<&str> = stderr.lines().collect();
        assert_eq!(lines.len(), 1, "{what}: {stderr}");
        assert!(
            lines[0].starts_with("gmwm: error: ") && lines[0].contains(needle),
            "{what}: {stderr}"
        );
    }
}
