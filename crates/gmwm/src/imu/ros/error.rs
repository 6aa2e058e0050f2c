//! [`RosError`]: what can go wrong while reading a ROS recording, and [`MessageError`]: what is
//! wrong with one serialized message.
//!
//! Messages follow STYLE §5: one lowercase line naming the file, then the topic and the 0-based
//! message index where there is one, then what is wrong and what was expected:
//! `bag.mcap: topic /imu1: message 17 (log time 1700000000.085000000 s): 52 bytes, too short
//! for linear_acceleration (needs 196)`.

use super::RosContainer;
use crate::imu::error::{escape_control, escape_name};
use std::fmt;
use std::path::PathBuf;
use thiserror::Error;

/// Reading a ROS recording failed.
///
/// File-level variants name the storage file (inside a rosbag2 folder, the `.mcap`/`.db3`
/// file); topic-selection variants name the path the caller gave.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum RosError {
    /// The path is none of the supported containers (checked by magic bytes, not by name).
    #[error("{}: not a ROS recording: {expected}", .path.display())]
    NotRecording {
        /// File or folder as given.
        path: PathBuf,
        /// What was expected there, e.g. `expected "#ROSBAG V2.0" at the start of a .bag file`.
        expected: String,
    },
    /// The container's structure is broken: cut short, or a record/index is inconsistent.
    #[error("{}: corrupt or truncated {container}: {}", .path.display(), escape_control(.reason))]
    Corrupt {
        /// Storage file.
        path: PathBuf,
        /// Container format.
        container: RosContainer,
        /// What is wrong, with byte offsets where known (`chunk at byte 4109 declares 800000
        /// bytes but only 1200 remain`).
        reason: String,
    },
    /// The sqlite3 database refused a query (malformed image, missing table, locked, ...).
    #[error("{}: rosbag2 sqlite3 database: {reason}", .path.display())]
    Sqlite {
        /// Storage file.
        path: PathBuf,
        /// SQLite's message.
        reason: String,
    },
    /// A compression this reader cannot decode (chunk or whole-file compression).
    #[error("{}: {} is not supported; {hint}", .path.display(), escape_name(.what))]
    UnsupportedCompression {
        /// Storage file.
        path: PathBuf,
        /// What is compressed how, e.g. `MCAP chunk compression "brotli"` (the name is the
        /// file's: control characters are escaped in the message).
        what: String,
        /// What is supported or how to convert.
        hint: &'static str,
    },
    /// The recording has no `sensor_msgs/Imu` topic.
    #[error("{}: no sensor_msgs/Imu topic; {}", .path.display(), topic_list(.available))]
    NoImuTopic {
        /// Path as given.
        path: PathBuf,
        /// Every topic present, as `name (type)`.
        available: Vec<String>,
    },
    /// More than one IMU topic holds messages and none was named.
    #[error(
        "{}: several sensor_msgs/Imu topics: {}; choose one with --topic",
        .path.display(),
        topic_names(.topics)
    )]
    AmbiguousImuTopic {
        /// Path as given.
        path: PathBuf,
        /// The IMU topics with messages.
        topics: Vec<String>,
    },
    /// The named topic is not in the recording.
    #[error(
        "{}: no topic {}; {}",
        .path.display(),
        escape_name(.topic),
        topic_list(.available)
    )]
    TopicNotFound {
        /// Path as given.
        path: PathBuf,
        /// The requested topic.
        topic: String,
        /// Every topic present, as `name (type)`.
        available: Vec<String>,
    },
    /// The named topic carries another message type.
    #[error(
        "{}: topic {} carries {}, not sensor_msgs/Imu",
        .path.display(),
        escape_name(.topic),
        escape_name(.message_type)
    )]
    NotImu {
        /// Path as given.
        path: PathBuf,
        /// The requested topic.
        topic: String,
        /// Its message type.
        message_type: String,
    },
    /// The chosen IMU topic (or every IMU topic) holds no messages.
    #[error("{}: {} no messages", .path.display(), empty_topics(.topics))]
    EmptyTopic {
        /// Path as given.
        path: PathBuf,
        /// The topic(s) without messages.
        topics: Vec<String>,
    },
    /// The topic's messages use a serialization this reader does not decode.
    #[error(
        "{}: topic {}: message encoding \"{}\" is not supported (expected cdr or ros1)",
        .path.display(),
        escape_name(.topic),
        escape_name(.encoding)
    )]
    UnsupportedEncoding {
        /// Storage file.
        path: PathBuf,
        /// Topic.
        topic: String,
        /// The encoding declared by the container.
        encoding: String,
    },
    /// One message cannot be decoded or holds a non-finite value.
    #[error(
        "{}: topic {}: message {index} (log time {}): {reason}",
        .path.display(),
        escape_name(.topic),
        format_ns(*.log_time_ns)
    )]
    Message {
        /// Storage file.
        path: PathBuf,
        /// Topic.
        topic: String,
        /// 0-based index of the message among the topic's messages, in reading order.
        index: u64,
        /// Its log (receive) time, ns since the epoch.
        log_time_ns: i64,
        /// What is wrong.
        reason: MessageError,
    },
}

/// What is wrong with one serialized `sensor_msgs/Imu` message.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum MessageError {
    /// The message ends before a field.
    #[error("{len} bytes, too short for {field} (needs {needed})")]
    Short {
        /// Message length in bytes (without a CDR encapsulation header: with it).
        len: usize,
        /// The field that does not fit, e.g. `header.frame_id` or `linear_acceleration`.
        field: &'static str,
        /// Bytes the message would need to hold that field.
        needed: usize,
    },
    /// The CDR encapsulation header is not plain CDR.
    #[error(
        "CDR encapsulation 0x{0:02x}{1:02x} is not supported (expected 0x0001 little-endian or \
         0x0000 big-endian CDR)"
    )]
    Encapsulation(u8, u8),
    /// A zstd-compressed message (rosbag2 `compression_mode: message`) does not decompress.
    #[error("zstd-compressed message does not decompress: {reason}")]
    Decompress {
        /// The decoder's message.
        reason: String,
    },
    /// A measurement is NaN or infinite.
    #[error("{field} = {value} is not a finite number")]
    NonFinite {
        /// `angular_velocity.x` ... `linear_acceleration.z`.
        field: &'static str,
        /// The value read.
        value: f64,
    },
}

/// Names from the file, escaped ([`escape_name`]) and joined by `, `.
fn topic_names(names: &[String]) -> String {
    let names: Vec<String> = names.iter().map(|n| escape_name(n)).collect();
    names.join(", ")
}

/// `topics: /a (T), /b (U)` or `the recording holds no topics`.
fn topic_list(available: &[String]) -> String {
    if available.is_empty() {
        "the recording holds no topics".to_owned()
    } else {
        format!("topics: {}", topic_names(available))
    }
}

fn empty_topics(topics: &[String]) -> String {
    match topics {
        [one] => format!("topic {} holds", escape_name(one)),
        more => format!("IMU topics {} hold", topic_names(more)),
    }
}

/// Nanoseconds since the epoch as `seconds.nanoseconds s`.
pub(crate) fn format_ns(ns: i64) -> impl fmt::Display {
    struct Ns(i64);
    impl fmt::Display for Ns {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            let sign = if self.0 < 0 { "-" } else { "" };
            let abs = self.0.unsigned_abs();
            write!(
                f,
                "{sign}{}.{:09} s",
                abs / 1_000_000_000,
                abs % 1_000_000_000
            )
        }
    }
    Ns(ns)
}
