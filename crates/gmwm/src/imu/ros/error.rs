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
    /// No topic of the recording answers to a covariate's name (`--covariate NAME`).
    #[error(
        "{}: no covariate {}: expected a topic of that name (or ending in /{}) carrying \
         sensor_msgs/Temperature, sensor_msgs/FluidPressure, std_msgs/Float64 or \
         std_msgs/Float32, or angular_rate or specific_force of the IMU messages; {}",
        .path.display(),
        escape_name(.name),
        escape_name(.name.trim_start_matches('/')),
        topic_list(.available)
    )]
    NoCovariate {
        /// Path as given.
        path: PathBuf,
        /// The covariate asked for.
        name: String,
        /// Every topic present, as `name (type)`.
        available: Vec<String>,
    },
    /// The topic named as a covariate carries a type that is not a scalar measurement.
    #[error(
        "{}: topic {} carries {}, not a scalar covariate (sensor_msgs/Temperature, \
         sensor_msgs/FluidPressure, std_msgs/Float64, std_msgs/Float32)",
        .path.display(),
        escape_name(.topic),
        escape_name(.message_type)
    )]
    NotScalar {
        /// Path as given.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// Its message type.
        message_type: String,
    },
    /// Several scalar topics answer to a covariate's name.
    #[error(
        "{}: several topics answer to covariate {}: {}; name one with --covariate TOPIC",
        .path.display(),
        escape_name(.name),
        topic_names(.topics)
    )]
    AmbiguousCovariate {
        /// Path as given.
        path: PathBuf,
        /// The covariate asked for.
        name: String,
        /// The topics answering to it.
        topics: Vec<String>,
    },
    /// A covariate topic's messages and the IMU topic's do not overlap in time.
    #[error(
        "{}: covariate topic {} ({messages} messages, log times {} to {}) does not overlap \
         the IMU topic {} ({} to {}) in time ({}): nothing to align",
        .path.display(),
        escape_name(.topic),
        format_ns(*.from_ns),
        format_ns(*.to_ns),
        escape_name(.imu_topic),
        format_ns(*.imu_from_ns),
        format_ns(*.imu_to_ns),
        apart(*.from_ns, *.to_ns, *.imu_from_ns, *.imu_to_ns)
    )]
    NoOverlap {
        /// Path as given.
        path: PathBuf,
        /// The covariate topic.
        topic: String,
        /// Its messages.
        messages: usize,
        /// Its first and last log times, ns since the epoch.
        from_ns: i64,
        /// See `from_ns`.
        to_ns: i64,
        /// The IMU topic.
        imu_topic: String,
        /// Its first and last log times.
        imu_from_ns: i64,
        /// See `imu_from_ns`.
        imu_to_ns: i64,
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

/// What is wrong with one serialized `sensor_msgs/Imu` (or scalar covariate) message.
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
        /// `angular_velocity.x` ... `linear_acceleration.z`, or a covariate's field
        /// (`temperature`).
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

/// How far apart two time spans that do not overlap are: `it begins 9990.005000000 s after the IMU
/// topic ends` (or `ends ... before ... begins`).
fn apart(from_ns: i64, to_ns: i64, imu_from_ns: i64, imu_to_ns: i64) -> String {
    if from_ns > imu_to_ns {
        format!(
            "it begins {} after the IMU topic ends",
            format_ns(from_ns.saturating_sub(imu_to_ns))
        )
    } else {
        format!(
            "it ends {} before the IMU topic begins",
            format_ns(imu_from_ns.saturating_sub(to_ns))
        )
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
