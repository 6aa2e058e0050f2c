//! `sensor_msgs/Imu` from ROS recordings: ROS1 bags, ROS2 MCAP and rosbag2 sqlite3.
//!
//! | container | path | order of the messages |
//! |---|---|---|
//! | [`RosContainer::Ros1Bag`] | `.bag` (format 2.0; chunks none, lz4 or bz2) | receive time |
//! | [`RosContainer::Mcap`] | `.mcap` (chunks none, zstd or lz4), or a rosbag2 folder | log time |
//! | [`RosContainer::Sqlite3`] | `.db3`, or a rosbag2 folder | `timestamp` column |
//!
//! A rosbag2 folder holds `metadata.yaml` and one or more storage files (split bags are read in
//! the order `metadata.yaml` lists them); a storage file of such a folder may also be given
//! alone. The container is recognised by its magic bytes, so a misnamed file still opens.
//! Messages are returned in log (receive) time order, ties in file order; both the header stamp
//! and the log time of every message are kept.
//!
//! ROS1 bags and MCAP files are read record by record with positioned reads (not
//! memory-mapped), sqlite3 databases queried row by row: only one chunk (as read and
//! decompressed) and the output vectors are held, about 64 bytes per message. A file truncated
//! by another process while it is read gives [`ReadError::Io`] (`the file shrank while it was
//! read`). The same decoder also feeds the streamed reader
//! ([`StreamedTable::open_recording`](crate::imu::read::stream::StreamedTable::open_recording)),
//! which holds none of the messages.
//!
//! ```no_run
//! use gmwm::{list_topics, read_imu_messages};
//! use std::path::Path;
//! let (container, topics) = list_topics(Path::new("run.mcap"))?;
//! for t in &topics {
//!     println!("{container}: {} {} {}", t.topic, t.message_type, t.messages);
//! }
//! let imu = read_imu_messages(Path::new("run.mcap"), None)?; // the single IMU topic
//! println!("{} messages on {}", imu.len(), imu.topic);
//! # Ok::<(), gmwm::ReadError>(())
//! ```

mod cdr;
mod covariate;
mod decompress;
mod error;
mod file;
mod mcap;
mod ros1;
#[cfg(feature = "sqlite")]
mod sqlite;
#[cfg(not(feature = "sqlite"))]
#[path = "sqlite_absent.rs"]
mod sqlite;

pub use covariate::{read_ros_covariate, RosCovariate};
pub use error::{MessageError, RosError};

use crate::imu::ReadError;
use file::StorageFile;
use serde::Serialize;
use std::collections::{HashMap, HashSet};
use std::fmt;
use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

/// The message types read as IMU samples (ROS1 and ROS2 spellings).
const IMU_TYPES: [&str; 2] = ["sensor_msgs/Imu", "sensor_msgs/msg/Imu"];

/// Magic of an SQLite 3 database file.
const SQLITE_MAGIC: &[u8] = b"SQLite format 3\0";

/// The smallest serialized `sensor_msgs/Imu` is about 300 bytes; compressed chunks may shrink
/// it, so output vectors are reserved for at most one message per 16 bytes of file.
const MIN_BYTES_PER_MESSAGE: u64 = 16;

/// A ROS recording format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RosContainer {
    /// ROS1 bag, format version 2.0.
    Ros1Bag,
    /// MCAP (ROS2's default storage since Iron; also ROS1 messages converted to MCAP).
    Mcap,
    /// rosbag2 sqlite3 storage (`.db3`, the default up to Humble).
    Sqlite3,
}

impl fmt::Display for RosContainer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            RosContainer::Ros1Bag => "ROS1 bag",
            RosContainer::Mcap => "MCAP",
            RosContainer::Sqlite3 => "rosbag2 sqlite3",
        })
    }
}

/// One topic of a recording.
///
/// JSON: `{"topic": "/imu0", "message_type": "sensor_msgs/msg/Imu", "messages": 1000}`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct TopicInfo {
    /// Topic name, e.g. `/imu0`.
    pub topic: String,
    /// Message type as the container spells it (`sensor_msgs/Imu` in ROS1,
    /// `sensor_msgs/msg/Imu` in ROS2); empty if the container gives none.
    pub message_type: String,
    /// Number of messages.
    pub messages: u64,
}

impl TopicInfo {
    /// Whether the topic carries `sensor_msgs/Imu` (or `sensor_msgs/msg/Imu`).
    pub fn is_imu(&self) -> bool {
        is_imu_type(&self.message_type)
    }
}

fn is_imu_type(t: &str) -> bool {
    IMU_TYPES.contains(&t)
}

/// The IMU messages of one topic, in log-time order.
///
/// Vectors are parallel: element `k` of each belongs to message `k`.
#[derive(Debug, Clone, PartialEq)]
pub struct ImuMessages {
    /// The recording as given.
    pub path: PathBuf,
    /// Its container format.
    pub container: RosContainer,
    /// The topic read.
    pub topic: String,
    /// `header.frame_id` of the first message (`None` if empty).
    pub frame_id: Option<String>,
    /// `header.stamp` of each message in ns since the epoch (as recorded: not sorted, not
    /// checked).
    pub header_stamp_ns: Vec<i64>,
    /// Log (receive) time of each message in ns since the epoch, non-decreasing.
    pub log_time_ns: Vec<i64>,
    /// `angular_velocity` x, y, z in rad/s (SI by the message definition).
    pub angular_velocity: [Vec<f64>; 3],
    /// `linear_acceleration` x, y, z in m/s^2.
    pub linear_acceleration: [Vec<f64>; 3],
    /// Messages of the recording on other topics (not read).
    pub(crate) other_messages: u64,
}

impl ImuMessages {
    /// Number of messages.
    pub fn len(&self) -> usize {
        self.log_time_ns.len()
    }

    /// Whether there are no messages (never true for a value returned by
    /// [`read_imu_messages`]).
    pub fn is_empty(&self) -> bool {
        self.log_time_ns.is_empty()
    }
}

/// How a topic's messages are serialized.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Encoding {
    Ros1,
    Cdr,
}

fn encoding(path: &Path, topic: &str, name: &str) -> Result<Encoding, RosError> {
    match name {
        "cdr" => Ok(Encoding::Cdr),
        "ros1" => Ok(Encoding::Ros1),
        other => Err(RosError::UnsupportedEncoding {
            path: path.to_path_buf(),
            topic: topic.to_owned(),
            encoding: other.to_owned(),
        }),
    }
}

/// Start of a Zstandard frame: a rosbag2 message compressed one by one
/// (`compression_mode: message`); a CDR message starts with 0x00.
const ZSTD_MAGIC: [u8; 4] = [0x28, 0xB5, 0x2F, 0xFD];

/// What a topic's messages are decoded as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum MessageKind {
    /// `sensor_msgs/Imu`: six values.
    Imu,
    /// A scalar measurement read as a covariate: one value.
    Scalar(cdr::ScalarType),
}

impl MessageKind {
    /// Whether a topic of `message_type` is decoded as this kind.
    fn accepts(self, message_type: &str) -> bool {
        match self {
            MessageKind::Imu => is_imu_type(message_type),
            MessageKind::Scalar(t) => cdr::ScalarType::of(message_type) == Some(t),
        }
    }
}

/// Where [`Collector`] puts each decoded, checked message, in file order: the in-memory
/// vectors ([`Gathered`]) or a streamed reader's reorder buffer.
pub(crate) trait MessageSink {
    /// One message: its header stamp and log time (ns; a message without a header gives its
    /// log time twice), and its values, all finite: for an IMU message six (angular velocity
    /// x, y, z then linear acceleration x, y, z), for a scalar one.
    fn message(&mut self, header_ns: i64, log_ns: i64, values: &[f64]) -> Result<(), ReadError>;
}

/// The one decoder of IMU messages: decodes and checks each message and hands it to a
/// [`MessageSink`].
pub(crate) struct Collector<'a> {
    /// Storage file being read (for messages).
    file: PathBuf,
    /// A decompressed message (rosbag2 per-message compression).
    scratch: Vec<u8>,
    topic: &'a str,
    kind: MessageKind,
    frame_id: Option<String>,
    /// Messages decoded so far.
    count: u64,
    sink: &'a mut dyn MessageSink,
}

impl<'a> Collector<'a> {
    /// A collector of `sensor_msgs/Imu` messages.
    #[cfg(test)]
    pub(crate) fn new(topic: &'a str, sink: &'a mut dyn MessageSink) -> Self {
        Self::of_kind(topic, MessageKind::Imu, sink)
    }

    fn of_kind(topic: &'a str, kind: MessageKind, sink: &'a mut dyn MessageSink) -> Self {
        Self {
            file: PathBuf::new(),
            scratch: Vec::new(),
            topic,
            kind,
            frame_id: None,
            count: 0,
            sink,
        }
    }

    #[cold]
    fn error(&self, log_time_ns: i64, reason: MessageError) -> RosError {
        RosError::Message {
            path: self.file.clone(),
            topic: self.topic.to_owned(),
            index: self.count,
            log_time_ns,
            reason,
        }
    }

    /// Decodes one message logged at `log_time_ns` and hands it to the sink.
    pub(crate) fn push(
        &mut self,
        encoding: Encoding,
        log_time_ns: i64,
        data: &[u8],
    ) -> Result<(), ReadError> {
        let mut scratch = std::mem::take(&mut self.scratch);
        let data = if encoding == Encoding::Cdr && data.starts_with(&ZSTD_MAGIC) {
            scratch.clear();
            decompress::zstd_frame(data, &mut scratch)
                .map_err(|reason| self.error(log_time_ns, MessageError::Decompress { reason }))?;
            &scratch
        } else {
            data
        };
        if let MessageKind::Scalar(ty) = self.kind {
            let decoded = match encoding {
                Encoding::Ros1 => cdr::decode_scalar_ros1(data, ty),
                Encoding::Cdr => cdr::decode_scalar_cdr(data, ty),
            };
            let m = decoded.map_err(|r| self.error(log_time_ns, r))?;
            if !m.value.is_finite() {
                let reason = MessageError::NonFinite {
                    field: ty.field(),
                    value: m.value,
                };
                return Err(self.error(log_time_ns, reason).into());
            }
            let stamp = m.stamp_ns.unwrap_or(log_time_ns);
            self.sink.message(stamp, log_time_ns, &[m.value])?;
            self.count += 1;
            self.scratch = scratch;
            return Ok(());
        }
        let decoded = match encoding {
            Encoding::Ros1 => cdr::decode_ros1(data),
            Encoding::Cdr => cdr::decode_cdr(data),
        };
        let m = decoded.map_err(|r| self.error(log_time_ns, r))?;
        let [gx, gy, gz] = m.angular_velocity;
        let [ax, ay, az] = m.linear_acceleration;
        let values = [gx, gy, gz, ax, ay, az];
        if let Some(k) = values.iter().position(|v| !v.is_finite()) {
            return Err(self
                .error(
                    log_time_ns,
                    MessageError::NonFinite {
                        field: cdr::VALUE_FIELDS[k],
                        value: values[k],
                    },
                )
                .into());
        }
        if self.count == 0 && !m.frame_id.is_empty() {
            self.frame_id = Some(String::from_utf8_lossy(m.frame_id).into_owned());
        }
        self.sink.message(m.stamp_ns, log_time_ns, &values)?;
        self.count += 1;
        self.scratch = scratch;
        Ok(())
    }
}

/// The in-memory sink: every message in vectors, sorted by log time at the end.
#[derive(Debug, Default)]
struct Gathered {
    header_stamp_ns: Vec<i64>,
    log_time_ns: Vec<i64>,
    angular_velocity: [Vec<f64>; 3],
    linear_acceleration: [Vec<f64>; 3],
}

impl MessageSink for Gathered {
    fn message(&mut self, header_ns: i64, log_ns: i64, values: &[f64]) -> Result<(), ReadError> {
        self.header_stamp_ns.push(header_ns);
        self.log_time_ns.push(log_ns);
        for a in 0..3 {
            self.angular_velocity[a].push(values[a]);
            self.linear_acceleration[a].push(values[3 + a]);
        }
        Ok(())
    }
}

impl Gathered {
    fn with_capacity(capacity: usize) -> Self {
        let f = || Vec::with_capacity(capacity);
        Self {
            header_stamp_ns: Vec::with_capacity(capacity),
            log_time_ns: Vec::with_capacity(capacity),
            angular_velocity: [f(), f(), f()],
            linear_acceleration: [f(), f(), f()],
        }
    }

    /// Sorts by log time (stable: ties keep reading order) unless already sorted.
    fn sort(&mut self) {
        let t = &self.log_time_ns;
        if t.windows(2).all(|w| w[0] <= w[1]) {
            return;
        }
        let mut order: Vec<usize> = (0..t.len()).collect();
        order.sort_by_key(|&i| t[i]);
        fn apply<T: Copy>(v: &mut Vec<T>, order: &[usize]) {
            *v = order.iter().map(|&i| v[i]).collect();
        }
        apply(&mut self.header_stamp_ns, &order);
        apply(&mut self.log_time_ns, &order);
        for a in 0..3 {
            apply(&mut self.angular_velocity[a], &order);
            apply(&mut self.linear_acceleration[a], &order);
        }
    }
}

/// Where a recording's data lives.
struct Source {
    container: RosContainer,
    files: Vec<PathBuf>,
}

/// The container of a file by its first bytes.
fn sniff(path: &Path) -> Result<Option<RosContainer>, ReadError> {
    let mut head = [0u8; 16];
    let mut file = File::open(path).map_err(|e| io_error(path, e))?;
    let mut n = 0;
    while n < head.len() {
        match file.read(&mut head[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(io_error(path, e)),
        }
    }
    let head = &head[..n];
    Ok(if head.starts_with(b"#ROSBAG V2.0") {
        Some(RosContainer::Ros1Bag)
    } else if head.starts_with(::mcap::MAGIC) {
        Some(RosContainer::Mcap)
    } else if head.starts_with(SQLITE_MAGIC) {
        Some(RosContainer::Sqlite3)
    } else {
        None
    })
}

#[cold]
fn io_error(path: &Path, source: std::io::Error) -> ReadError {
    ReadError::Io {
        path: path.to_path_buf(),
        source,
    }
}

fn not_recording(path: &Path, expected: impl Into<String>) -> ReadError {
    RosError::NotRecording {
        path: path.to_path_buf(),
        expected: expected.into(),
    }
    .into()
}

fn extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default()
}

/// The storage files of a single file or a rosbag2 folder.
fn source(path: &Path) -> Result<Source, ReadError> {
    if path.is_dir() {
        return folder(path);
    }
    if path.file_name().is_some_and(|n| n == "metadata.yaml") {
        if let Some(dir) = path.parent() {
            return folder(if dir.as_os_str().is_empty() {
                Path::new(".")
            } else {
                dir
            });
        }
    }
    let ext = extension(path);
    if ext == "zstd" {
        return Err(RosError::UnsupportedCompression {
            path: path.to_path_buf(),
            what: "a zstd-compressed rosbag2 storage file".into(),
            hint: "decompress it first (zstd -d FILE)",
        }
        .into());
    }
    match sniff(path)? {
        Some(container) => Ok(Source {
            container,
            files: vec![path.to_path_buf()],
        }),
        None => Err(not_recording(
            path,
            match ext.as_str() {
                "bag" => "expected \"#ROSBAG V2.0\" at the start of a ROS1 bag",
                "mcap" => "expected the MCAP magic (0x89 MCAP0 \\r\\n) at the start",
                "db3" => "expected an SQLite 3 database (\"SQLite format 3\")",
                _ => {
                    "expected a ROS1 bag (#ROSBAG V2.0), an MCAP file, a rosbag2 sqlite3 .db3 \
                     or a rosbag2 folder"
                }
            },
        )),
    }
}

/// `relative_file_paths` of a rosbag2 `metadata.yaml` (a list of plain scalars), if present.
fn metadata_files(text: &str) -> Option<Vec<String>> {
    let mut lines = text.lines();
    let key_indent = loop {
        let line = lines.next()?;
        let t = line.trim_start();
        if t.starts_with("relative_file_paths:") {
            break line.len() - t.len();
        }
    };
    let mut files = Vec::new();
    for line in lines {
        let t = line.trim_start();
        if t.is_empty() {
            continue;
        }
        let indent = line.len() - t.len();
        match t.strip_prefix("- ") {
            Some(item) if indent >= key_indent => {
                files.push(
                    item.trim()
                        .trim_matches(|c| c == '"' || c == '\'')
                        .to_owned(),
                );
            }
            _ => break,
        }
    }
    Some(files)
}

/// The storage files a `metadata.yaml` lists: each inside the bag folder (a relative path
/// without `..`) and listed once; a list that repeats a file would read its messages again,
/// one that leaves the folder would read another recording.
fn checked_storage_names(meta: &Path, names: &[String]) -> Result<(), ReadError> {
    use std::path::Component;
    let mut seen = std::collections::HashSet::new();
    for name in names {
        let inside = Path::new(name)
            .components()
            .all(|c| matches!(c, Component::Normal(_) | Component::CurDir));
        if !inside {
            return Err(not_recording(
                meta,
                format!(
                    "expected storage files inside the bag folder; relative_file_paths lists {}",
                    super::quote(name)
                ),
            ));
        }
        if !seen.insert(name.as_str()) {
            let times = names.iter().filter(|n| *n == name).count();
            return Err(not_recording(
                meta,
                format!(
                    "expected each storage file listed once; relative_file_paths lists {} {times} times",
                    super::quote(name)
                ),
            ));
        }
    }
    Ok(())
}

/// Sort key putting `bag_2.mcap` before `bag_10.mcap`.
fn split_index(name: &str) -> (String, u64) {
    let stem = name.rsplit_once('.').map_or(name, |(s, _)| s);
    let digits = stem.len() - stem.trim_end_matches(|c: char| c.is_ascii_digit()).len();
    let (head, tail) = stem.split_at(stem.len() - digits);
    (head.to_owned(), tail.parse().unwrap_or(0))
}

fn folder(dir: &Path) -> Result<Source, ReadError> {
    let meta = dir.join("metadata.yaml");
    let listed = match std::fs::read_to_string(&meta) {
        Ok(text) => metadata_files(&text).filter(|f| !f.is_empty()),
        Err(_) => None,
    };
    let files: Vec<PathBuf> = match listed {
        Some(names) => {
            checked_storage_names(&meta, &names)?;
            names.iter().map(|n| dir.join(n)).collect()
        }
        None => {
            let mut names: Vec<String> = std::fs::read_dir(dir)
                .map_err(|e| io_error(dir, e))?
                .filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| {
                    let ext = extension(Path::new(n));
                    ext == "mcap"
                        || ext == "db3"
                        || n.ends_with(".mcap.zstd")
                        || n.ends_with(".db3.zstd")
                })
                .collect();
            names.sort_by_key(|n| split_index(n));
            names.iter().map(|n| dir.join(n)).collect()
        }
    };
    if files.is_empty() {
        return Err(not_recording(
            dir,
            "expected a rosbag2 folder with metadata.yaml and .mcap or .db3 storage files",
        ));
    }
    let mut container = None;
    for f in &files {
        if extension(f) == "zstd" {
            return Err(RosError::UnsupportedCompression {
                path: f.clone(),
                what: "a zstd-compressed rosbag2 storage file (compression_mode: file)".into(),
                hint: "decompress it first (zstd -d FILE)",
            }
            .into());
        }
        let c = sniff(f)?.ok_or_else(|| {
            not_recording(
                f,
                "expected an MCAP or sqlite3 storage file of a rosbag2 folder",
            )
        })?;
        match container {
            None => container = Some(c),
            Some(first) if first != c => {
                return Err(not_recording(
                    dir,
                    format!("expected one storage format, found {first} and {c} files"),
                ))
            }
            Some(_) => {}
        }
    }
    Ok(Source {
        container: container.unwrap_or(RosContainer::Mcap),
        files,
    })
}

/// The container format of `path` (a file or a rosbag2 folder), recognised by magic bytes:
/// `#ROSBAG V2.0`, the MCAP magic `0x89 M C A P 0x30 \r \n`, or `SQLite format 3\0`; `None`
/// if it is none of them (or cannot be read).
pub(crate) fn container_of(path: &Path) -> Option<RosContainer> {
    source(path).ok().map(|s| s.container)
}

/// One row of a rosbag2 sqlite3 file's `topics`, with its message count (`sqlite`; never built
/// in a build without SQLite).
#[derive(Debug, Clone)]
pub(crate) struct SqliteTopic {
    pub(crate) id: i64,
    pub(crate) name: String,
    pub(crate) message_type: String,
    /// `serialization_format`, `cdr` for ROS 2.
    pub(crate) encoding: String,
    pub(crate) messages: u64,
}

/// One storage file, opened and catalogued.
enum Opened {
    Ros1(StorageFile, ros1::Catalog),
    Mcap(StorageFile, mcap::Catalog),
    Sqlite(PathBuf, sqlite::Connection, Vec<sqlite::Topic>),
}

impl Opened {
    /// (topic, type, messages) of every connection/channel/topic row.
    fn entries(&self) -> Vec<(&str, &str, u64)> {
        match self {
            Opened::Ros1(_, c) => c
                .connections
                .iter()
                .map(|c| (c.topic.as_str(), c.message_type.as_str(), c.messages))
                .collect(),
            Opened::Mcap(_, c) => c
                .channels
                .iter()
                .map(|c| (c.topic.as_str(), c.message_type.as_str(), c.messages))
                .collect(),
            Opened::Sqlite(_, _, t) => t
                .iter()
                .map(|t| (t.name.as_str(), t.message_type.as_str(), t.messages))
                .collect(),
        }
    }

    fn size(&self) -> u64 {
        match self {
            Opened::Ros1(f, _) | Opened::Mcap(f, _) => f.len() as u64,
            Opened::Sqlite(p, _, _) => std::fs::metadata(p).map(|m| m.len()).unwrap_or(0),
        }
    }

    /// Reads the messages of `topic` of the collector's kind into `out`.
    fn read(&mut self, topic: &str, out: &mut Collector<'_>) -> Result<(), ReadError> {
        match self {
            Opened::Ros1(file, cat) => {
                out.file = file.path().to_path_buf();
                let wanted: HashSet<u32> = cat
                    .connections
                    .iter()
                    .filter(|c| c.topic == topic && out.kind.accepts(&c.message_type))
                    .map(|c| c.id)
                    .collect();
                if wanted.is_empty() {
                    return Ok(());
                }
                let read = ros1::read(file, cat, &wanted, out);
                file.release();
                read
            }
            Opened::Mcap(file, cat) => {
                out.file = file.path().to_path_buf();
                let mut wanted = HashMap::new();
                for c in &cat.channels {
                    if c.topic == topic && out.kind.accepts(&c.message_type) {
                        wanted.insert(c.id, encoding(file.path(), topic, &c.encoding)?);
                    }
                }
                if wanted.is_empty() {
                    return Ok(());
                }
                let read = mcap::read(file, cat, &wanted, out);
                file.release();
                read
            }
            Opened::Sqlite(path, db, topics) => {
                out.file.clone_from(path);
                let mut wanted = HashMap::new();
                for t in topics {
                    if t.name == topic && out.kind.accepts(&t.message_type) {
                        wanted.insert(t.id, encoding(path, topic, &t.encoding)?);
                    }
                }
                if wanted.is_empty() {
                    return Ok(());
                }
                sqlite::read(path, db, &wanted, out)
            }
        }
    }
}

fn open(source: &Source) -> Result<Vec<Opened>, ReadError> {
    let mut out = Vec::with_capacity(source.files.len());
    for f in &source.files {
        // a later file of a folder may differ from the first; each is sniffed
        let container = match source.files.len() {
            1 => source.container,
            _ => sniff(f)?.unwrap_or(source.container),
        };
        out.push(match container {
            RosContainer::Ros1Bag => {
                let mut file = StorageFile::open(f)?;
                let cat = ros1::catalog(&mut file)?;
                file.release();
                Opened::Ros1(file, cat)
            }
            RosContainer::Mcap => {
                let mut file = StorageFile::open(f)?;
                let cat = mcap::catalog(&mut file)?;
                file.release();
                Opened::Mcap(file, cat)
            }
            RosContainer::Sqlite3 => {
                let db = sqlite::open(f)?;
                let topics = sqlite::catalog(f, &db)?;
                Opened::Sqlite(f.clone(), db, topics)
            }
        });
    }
    Ok(out)
}

/// Topics of all files, merged by (topic, type), sorted by topic (a map: a file may list a
/// million topics).
fn merged_topics(opened: &[Opened]) -> Vec<TopicInfo> {
    let mut merged: std::collections::BTreeMap<(&str, &str), u64> = Default::default();
    for o in opened {
        for (topic, message_type, messages) in o.entries() {
            let count = merged.entry((topic, message_type)).or_insert(0);
            *count = count.saturating_add(messages);
        }
    }
    merged
        .into_iter()
        .map(|((topic, message_type), messages)| TopicInfo {
            topic: topic.to_owned(),
            message_type: message_type.to_owned(),
            messages,
        })
        .collect()
}

/// Lists the topics of a recording (a file or a rosbag2 folder) with their message types and
/// counts, sorted by topic name.
///
/// Counts come from the index (ROS1), the summary statistics (MCAP) or a `COUNT(*)` over the
/// messages table (sqlite3); an unindexed ROS1 bag or an MCAP file without statistics is
/// scanned.
///
/// # Errors
/// [`ReadError::Io`]; [`ReadError::Ros`] with [`RosError::NotRecording`], [`RosError::Corrupt`]
/// (truncated or inconsistent file), [`RosError::Sqlite`] or
/// [`RosError::UnsupportedCompression`].
pub fn list_topics(path: &Path) -> Result<(RosContainer, Vec<TopicInfo>), ReadError> {
    let source = source(path)?;
    let opened = open(&source)?;
    Ok((source.container, merged_topics(&opened)))
}

fn described(topics: &[TopicInfo]) -> Vec<String> {
    topics
        .iter()
        .map(|t| format!("{} ({})", t.topic, t.message_type))
        .collect()
}

/// The topic [`read_imu_messages`] reads: `topic` if given (it must exist, carry
/// `sensor_msgs/Imu` and hold messages), else the single IMU topic holding messages.
///
/// # Errors
/// [`RosError::TopicNotFound`], [`RosError::NotImu`], [`RosError::EmptyTopic`],
/// [`RosError::NoImuTopic`], [`RosError::AmbiguousImuTopic`]; `path` is only used in the
/// messages.
pub fn choose_topic<'t>(
    path: &Path,
    topics: &'t [TopicInfo],
    topic: Option<&str>,
) -> Result<&'t TopicInfo, RosError> {
    let path = path.to_path_buf();
    if let Some(name) = topic {
        let named: Vec<&TopicInfo> = topics.iter().filter(|t| t.topic == name).collect();
        let Some(first) = named.first() else {
            return Err(RosError::TopicNotFound {
                path,
                topic: name.to_owned(),
                available: described(topics),
            });
        };
        let Some(imu) = named.iter().find(|t| t.is_imu()) else {
            return Err(RosError::NotImu {
                path,
                topic: name.to_owned(),
                message_type: first.message_type.clone(),
            });
        };
        if imu.messages == 0 {
            return Err(RosError::EmptyTopic {
                path,
                topics: vec![name.to_owned()],
            });
        }
        return Ok(imu);
    }
    let imu: Vec<&TopicInfo> = topics.iter().filter(|t| t.is_imu()).collect();
    let full: Vec<&TopicInfo> = imu.iter().copied().filter(|t| t.messages > 0).collect();
    match (imu.len(), full.as_slice()) {
        (0, _) => Err(RosError::NoImuTopic {
            path,
            available: described(topics),
        }),
        (_, [one]) => Ok(one),
        (_, []) => Err(RosError::EmptyTopic {
            path,
            topics: imu.iter().map(|t| t.topic.clone()).collect(),
        }),
        (_, more) => Err(RosError::AmbiguousImuTopic {
            path,
            topics: more.iter().map(|t| t.topic.clone()).collect(),
        }),
    }
}

/// Reads the `sensor_msgs/Imu` messages of one topic of a recording (a file or a rosbag2
/// folder): `topic`, or with `None` the single IMU topic holding messages.
///
/// Messages are returned in log-time order (ROS1: receive time; MCAP: log time; sqlite3: the
/// `timestamp` column), ties in file order. Every message's length is checked against the
/// message definition and its six measurements must be finite. A file truncated while it is
/// read gives [`ReadError::Io`] (`the file shrank while it was read`). Cost: one pass over the chunks holding the topic
/// (plus one counting pass for sqlite3 and unindexed files); memory: the output (64 bytes per
/// message) and one decompressed chunk.
///
/// # Errors
/// Those of [`list_topics`] and [`choose_topic`]; [`RosError::UnsupportedEncoding`];
/// [`RosError::Message`] naming the topic and 0-based message index for a short or garbled
/// message or a non-finite value.
pub fn read_imu_messages(path: &Path, topic: Option<&str>) -> Result<ImuMessages, ReadError> {
    let mut out = Gathered::default();
    let read = read_topic(path, topic, |chosen, bytes| {
        let capacity = chosen.messages.min(bytes / MIN_BYTES_PER_MESSAGE);
        out = Gathered::with_capacity(usize::try_from(capacity).unwrap_or(0));
        &mut out
    })?;
    out.sort();
    Ok(ImuMessages {
        path: path.to_path_buf(),
        container: read.container,
        topic: read.topic,
        frame_id: read.frame_id,
        header_stamp_ns: out.header_stamp_ns,
        log_time_ns: out.log_time_ns,
        angular_velocity: out.angular_velocity,
        linear_acceleration: out.linear_acceleration,
        other_messages: read.other_messages,
    })
}

/// What [`read_topic`] read, apart from the messages.
#[derive(Debug, Clone)]
pub(crate) struct TopicRead {
    pub(crate) container: RosContainer,
    pub(crate) topic: String,
    /// `header.frame_id` of the first message in file order (`None` if empty).
    pub(crate) frame_id: Option<String>,
    /// Messages on the topic (as counted by the index, and read).
    pub(crate) messages: u64,
    /// Messages on other topics.
    pub(crate) other_messages: u64,
}

/// Reads the IMU messages of `topic` (as [`read_imu_messages`] chooses it) in file order into
/// the sink `sink` gives once the topic is chosen (from the chosen topic and the recording's
/// size in bytes), checking the count against the index.
pub(crate) fn read_topic<'s>(
    path: &Path,
    topic: Option<&str>,
    sink: impl FnOnce(&TopicInfo, u64) -> &'s mut dyn MessageSink,
) -> Result<TopicRead, ReadError> {
    read_messages(
        path,
        |topics| Ok((choose_topic(path, topics, topic)?.clone(), MessageKind::Imu)),
        sink,
    )
}

/// Reads the messages of the topic `choose` picks from the recording's topics (with the kind
/// its messages are decoded as) in file order into the sink `sink` gives, checking the count
/// against the index.
pub(crate) fn read_messages<'s>(
    path: &Path,
    choose: impl FnOnce(&[TopicInfo]) -> Result<(TopicInfo, MessageKind), ReadError>,
    sink: impl FnOnce(&TopicInfo, u64) -> &'s mut dyn MessageSink,
) -> Result<TopicRead, ReadError> {
    let source = source(path)?;
    let mut opened = open(&source)?;
    let topics = merged_topics(&opened);
    let (chosen, kind) = choose(&topics)?;
    let chosen = &chosen;
    let bytes: u64 = opened.iter().map(Opened::size).sum();
    let mut out = Collector::of_kind(&chosen.topic, kind, sink(chosen, bytes));
    for o in &mut opened {
        o.read(&chosen.topic, &mut out)?;
    }
    if out.count != chosen.messages {
        // the index (ROS1), statistics (MCAP) or COUNT(*) (sqlite3) disagrees with the data
        return Err(RosError::Corrupt {
            path: path.to_path_buf(),
            container: source.container,
            reason: format!(
                "the index counts {} messages on {}, the data holds {}",
                chosen.messages,
                crate::imu::quote(&chosen.topic),
                out.count
            ),
        }
        .into());
    }
    Ok(TopicRead {
        container: source.container,
        topic: chosen.topic.clone(),
        frame_id: out.frame_id,
        messages: chosen.messages,
        // counts from the file's index or statistics: summed without overflow
        other_messages: topics
            .iter()
            .fold(0u64, |n, t| n.saturating_add(t.messages))
            .saturating_sub(chosen.messages),
    })
}

/// Messages of the largest `sensor_msgs/Imu` topic of a recording, from the index (ROS1),
/// the statistics (MCAP) or `COUNT(*)` (sqlite3): what a streamed read holds at most (0 when
/// there is no IMU topic).
///
/// # Errors
/// As [`list_topics`].
pub(crate) fn imu_messages_count(path: &Path) -> Result<u64, ReadError> {
    let (_, topics) = list_topics(path)?;
    Ok(topics
        .iter()
        .filter(|t| t.is_imu())
        .map(|t| t.messages)
        .max()
        .unwrap_or(0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metadata_lists_each_storage_file_once_inside_the_folder() {
        let d = tempfile::tempdir().unwrap();
        let meta = d.path().join("metadata.yaml");
        let cases = [
            (
                "  - a_0.mcap\n  - a_0.mcap\n  - a_0.mcap\n",
                "lists a_0.mcap 3 times",
            ),
            ("  - /etc/passwd\n", "inside the bag folder"),
            ("  - ../other/b_0.mcap\n", "inside the bag folder"),
        ];
        for (list, said) in cases {
            std::fs::write(
                &meta,
                format!("rosbag2_bagfile_information:\n  relative_file_paths:\n{list}"),
            )
            .unwrap();
            let e = source(d.path()).err().unwrap().to_string();
            assert!(
                e.starts_with(&format!(
                    "{}: not a ROS recording: expected",
                    meta.display()
                )) && e.contains(said),
                "{e}"
            );
        }
    }

    #[test]
    fn metadata_files_reads_the_list() {
        let yaml = "rosbag2_bagfile_information:\n  relative_file_paths:\n  - a_0.mcap\n  - \
                    'a_1.mcap'\n  ros_distro: x\n";
        assert_eq!(
            metadata_files(yaml),
            Some(vec!["a_0.mcap".to_owned(), "a_1.mcap".to_owned()])
        );
        assert_eq!(metadata_files("version: 5\n"), None);
    }

    #[test]
    fn split_index_orders_numerically() {
        let mut names = vec!["b_10.mcap", "b_2.mcap", "b_0.mcap"];
        names.sort_by_key(|n| split_index(n));
        assert_eq!(names, ["b_0.mcap", "b_2.mcap", "b_10.mcap"]);
    }

    /// A topic of `n` messages of type `ty` (also for the covariate tests).
    pub(super) fn t(topic: &str, ty: &str, n: u64) -> TopicInfo {
        TopicInfo {
            topic: topic.into(),
            message_type: ty.into(),
            messages: n,
        }
    }

    #[test]
    fn choose_topic_rules() {
        let p = Path::new("x.bag");
        let topics = [
            t("/a", "sensor_msgs/Imu", 5),
            t("/b", "sensor_msgs/msg/Imu", 0),
            t("/c", "std_msgs/String", 3),
        ];
        assert_eq!(choose_topic(p, &topics, None).unwrap().topic, "/a");
        assert_eq!(choose_topic(p, &topics, Some("/a")).unwrap().topic, "/a");
        let e = choose_topic(p, &topics, Some("/b"))
            .unwrap_err()
            .to_string();
        assert_eq!(e, "x.bag: topic /b holds no messages");
        let e = choose_topic(p, &topics, Some("/c"))
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "x.bag: topic /c carries std_msgs/String, not sensor_msgs/Imu"
        );
        let e = choose_topic(p, &topics[2..], None).unwrap_err().to_string();
        assert_eq!(
            e,
            "x.bag: no sensor_msgs/Imu topic; topics: /c (std_msgs/String)"
        );
        let e = choose_topic(p, &[], None).unwrap_err().to_string();
        assert_eq!(
            e,
            "x.bag: no sensor_msgs/Imu topic; the recording holds no topics"
        );
        let e = choose_topic(p, &topics[1..2], None)
            .unwrap_err()
            .to_string();
        assert_eq!(e, "x.bag: topic /b holds no messages");
        let two = [t("/a", "sensor_msgs/Imu", 5), t("/b", "sensor_msgs/Imu", 5)];
        let e = choose_topic(p, &two, None).unwrap_err().to_string();
        assert_eq!(
            e,
            "x.bag: several sensor_msgs/Imu topics: /a, /b; choose one with --topic"
        );
    }

    /// Writes a recording of `n` messages on /imu0 with the real writer (Python `rosbags`,
    /// `tests/fixtures/write_imu_bag.py`) and returns its storage file.
    fn written(dir: &Path, container: &str, compression: &str, n: usize) -> PathBuf {
        let script = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/fixtures/write_imu_bag.py"
        );
        let out = dir.join(container);
        let status = std::process::Command::new("python3")
            .arg(script)
            .args(["--container", container, "--compression", compression])
            .arg("--out")
            .arg(&out)
            .args(["--n", &n.to_string(), "--rate", "200", "--seed", "3"])
            .args(["--gyro-wn-density", "1e-4", "--gyro-rw-density", "1e-6"])
            .args(["--accel-wn-density", "1e-3", "--accel-rw-density", "1e-5"])
            .args(["--extra-topic", "/status:std_msgs/msg/String"])
            .output()
            .expect("python3 runs (the ROS tests need: python3 -m pip install rosbags)");
        assert!(
            status.status.success(),
            "write_imu_bag.py failed (needs: python3 -m pip install rosbags):\n{}",
            String::from_utf8_lossy(&status.stderr)
        );
        match container {
            "ros1" => out,
            _ => {
                let source = source(&out).unwrap();
                assert_eq!(source.files.len(), 1);
                source.files[0].clone()
            }
        }
    }

    /// Opens and catalogues `path`, cuts the file to `keep` of its bytes, then reads /imu0.
    fn read_after_truncation(path: &Path, keep: f64) -> Result<usize, ReadError> {
        let source = source(path).unwrap();
        let mut opened = open(&source).unwrap();
        let topics = merged_topics(&opened);
        let chosen = choose_topic(path, &topics, None).unwrap();
        let size = std::fs::metadata(path).unwrap().len();
        let file = std::fs::OpenOptions::new().write(true).open(path).unwrap();
        file.set_len((size as f64 * keep) as u64).unwrap();
        let mut sink = Gathered::default();
        let mut out = Collector::new(&chosen.topic, &mut sink);
        for o in &mut opened {
            o.read(&chosen.topic, &mut out)?;
        }
        Ok(sink.log_time_ns.len())
    }

    #[test]
    fn a_file_truncated_after_it_was_catalogued_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        // 7000 messages: three chunks of the writers' 1 MiB
        for (container, compression) in [("ros1", "none"), ("ros1", "lz4"), ("mcap", "zstd")] {
            let sub = dir.path().join(format!("{container}-{compression}"));
            std::fs::create_dir(&sub).unwrap();
            let path = written(&sub, container, compression, 7000);
            // untouched, every message is read
            let source = source(&path).unwrap();
            let mut opened = open(&source).unwrap();
            let mut sink = Gathered::default();
            let mut out = Collector::new("/imu0", &mut sink);
            for o in &mut opened {
                o.read("/imu0", &mut out).unwrap();
            }
            assert_eq!(sink.log_time_ns.len(), 7000, "{container} {compression}");
            for keep in [0.0, 0.5, 0.99] {
                let copy = sub.join(format!("cut-{keep}"));
                std::fs::copy(&path, &copy).unwrap();
                let e = read_after_truncation(&copy, keep).unwrap_err();
                assert!(
                    matches!(&e, ReadError::Io { path, .. } if path == &copy),
                    "{container} {compression} {keep}: {e:?}"
                );
                assert_eq!(
                    e.to_string(),
                    format!("{}: the file shrank while it was read", copy.display()),
                );
            }
        }
    }

    #[test]
    fn sort_is_stable_and_moves_every_vector() {
        let mut c = Gathered {
            log_time_ns: vec![3, 1, 2, 1],
            header_stamp_ns: vec![30, 10, 20, 11],
            angular_velocity: [vec![3.0, 1.0, 2.0, 1.5], vec![0.0; 4], vec![0.0; 4]],
            linear_acceleration: [vec![0.0; 4], vec![0.0; 4], vec![-3.0, -1.0, -2.0, -1.5]],
        };
        c.sort();
        assert_eq!(c.log_time_ns, [1, 1, 2, 3]);
        assert_eq!(c.header_stamp_ns, [10, 11, 20, 30]);
        assert_eq!(c.angular_velocity[0], [1.0, 1.5, 2.0, 3.0]);
        assert_eq!(c.linear_acceleration[2], [-1.0, -1.5, -2.0, -3.0]);
    }
}
