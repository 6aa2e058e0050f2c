//! rosbag2 sqlite3 storage (`.db3`, the default up to ROS 2 Humble), read-only through
//! `rusqlite` (SQLite compiled in).
//!
//! Tables used: `topics(id, name, type, serialization_format, ...)` and
//! `messages(id, topic_id, timestamp, data)`; messages are read `ORDER BY timestamp, id`, which
//! the `timestamp_idx` index of rosbag2 serves without sorting, one row at a time.

use super::error::RosError;
use super::{Collector, Encoding, RosContainer};
use crate::imu::error::one_line;
use crate::imu::ReadError;
use rusqlite::limits::Limit;
pub(crate) use rusqlite::Connection;
use rusqlite::OpenFlags;
use std::collections::HashMap;
use std::path::Path;

pub(crate) use super::SqliteTopic as Topic;

fn sql_error(path: &Path, e: rusqlite::Error) -> RosError {
    use rusqlite::ErrorCode::{OperationInterrupted, TooBig};
    match e.sqlite_error_code() {
        Some(OperationInterrupted) => {
            return corrupt(
                path,
                "reading it takes more work than a database of its size can need (a crafted \
                 view, index or generated column?); stopped"
                    .into(),
            )
        }
        Some(TooBig) => {
            return corrupt(
                path,
                format!(
                    "it holds or computes a value longer than {} MiB, more than any topic \
                     name or IMU message",
                    MAX_VALUE_BYTES >> 20
                ),
            )
        }
        _ => {}
    }
    RosError::Sqlite {
        path: path.to_path_buf(),
        // SQLite's messages may quote the file's schema, newlines and all
        reason: one_line(&e.to_string()),
    }
}

fn corrupt(path: &Path, reason: String) -> RosError {
    RosError::Corrupt {
        path: path.to_path_buf(),
        container: RosContainer::Sqlite3,
        reason,
    }
}

/// Checks the file size against the database header (<https://sqlite.org/fileformat.html>,
/// §1.3): SQLite itself reads a missing tail as zeros and may not notice a cut-short file.
fn check_size(path: &Path, head: &[u8], len: u64) -> Result<(), RosError> {
    if head.len() < 100 {
        return Err(corrupt(
            path,
            format!(
                "the 100-byte database header is cut off ({} bytes)",
                head.len()
            ),
        ));
    }
    let be32 = |at: usize| u32::from_be_bytes([head[at], head[at + 1], head[at + 2], head[at + 3]]);
    let page_size = match u16::from_be_bytes([head[16], head[17]]) {
        1 => 65_536,
        p => u64::from(p),
    };
    if !(512..=65_536).contains(&page_size) || !page_size.is_power_of_two() {
        return Err(corrupt(
            path,
            format!("the header gives a page size of {page_size} bytes"),
        ));
    }
    let pages = u64::from(be32(28));
    // the in-header size is valid when the change counter matches "version-valid-for"
    if be32(24) == be32(92) && pages > 0 && len < pages * page_size {
        return Err(corrupt(
            path,
            format!(
                "the header declares {pages} pages of {page_size} bytes ({} bytes) but the \
                 file has {len}: it is cut short",
                pages * page_size
            ),
        ));
    }
    if len % page_size != 0 {
        return Err(corrupt(
            path,
            format!(
                "{len} bytes is not a whole number of {page_size}-byte pages: the file is cut \
                 short"
            ),
        ));
    }
    Ok(())
}

/// Longest string or blob SQLite may make (its `SQLITE_LIMIT_LENGTH`): an IMU message is a
/// few hundred bytes and a topic name a few dozen; a generated column or function asked for
/// more fails with "string or blob too big" instead of allocating it.
const MAX_VALUE_BYTES: i32 = 16 << 20;

/// Virtual-machine steps between two calls of the progress handler.
const STEPS_PER_CALL: i32 = 100_000;

/// Work SQLite may do on a file, in virtual-machine steps: a floor for small files plus a
/// share per byte. Reading a rosbag2 table costs a few dozen steps per row and a row takes
/// at least a dozen bytes, so a real bag stays far below this; a crafted file (an expensive
/// expression in a generated column, say) is stopped instead of running for hours.
fn step_budget(len: u64) -> u64 {
    1_000_000_000u64.saturating_add(len.saturating_mul(1_000))
}

/// Opens the database read-only, after checking its size against its header: values capped
/// at [`MAX_VALUE_BYTES`], work at [`step_budget`], and `topics` and `messages` required to
/// be ordinary tables (a view can compute any number of rows from nothing).
pub(crate) fn open(path: &Path) -> Result<Connection, ReadError> {
    open_within(path, None)
}

/// [`open`] with a work budget of `steps` (default [`step_budget`] of the file's size).
fn open_within(path: &Path, steps: Option<u64>) -> Result<Connection, ReadError> {
    let io = |source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut file = std::fs::File::open(path).map_err(io)?;
    let len = file.metadata().map_err(io)?.len();
    let mut head = Vec::with_capacity(100);
    std::io::Read::read_to_end(&mut std::io::Read::take(&mut file, 100), &mut head).map_err(io)?;
    check_size(path, &head, len)?;
    let mut db = Connection::open_with_flags(
        path,
        OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX,
    )
    .map_err(|e| sql_error(path, e))?;
    let err = |e| ReadError::from(sql_error(path, e));
    db.set_limit(Limit::SQLITE_LIMIT_LENGTH, MAX_VALUE_BYTES)
        .map_err(err)?;
    let calls = steps.unwrap_or_else(|| step_budget(len)) / STEPS_PER_CALL as u64;
    let mut made = 0u64;
    db.progress_handler(
        STEPS_PER_CALL,
        Some(move || {
            made += 1;
            made > calls
        }),
    )
    .map_err(err)?;
    check_tables(path, &db)?;
    Ok(db)
}

/// `topics` and `messages` must be ordinary tables of the database.
fn check_tables(path: &Path, db: &Connection) -> Result<(), RosError> {
    let err = |e| sql_error(path, e);
    for name in ["topics", "messages"] {
        let kind: Option<(String, String)> = db
            .query_row(
                "SELECT type, coalesce(sql, '') FROM sqlite_schema WHERE name = ?1",
                [name],
                |row| Ok((row.get(0)?, row.get(1)?)),
            )
            .map(Some)
            .or_else(|e| match e {
                rusqlite::Error::QueryReturnedNoRows => Ok(None),
                e => Err(err(e)),
            })?;
        let virtual_table = |sql: &str| {
            sql.split_whitespace()
                .take(2)
                .any(|w| w.eq_ignore_ascii_case("virtual"))
        };
        match kind {
            None => {
                return Err(corrupt(
                    path,
                    format!("the database has no `{name}` table: it is not a rosbag2 bag"),
                ))
            }
            Some((kind, sql)) if kind != "table" || virtual_table(&sql) => {
                let what = match kind.as_str() {
                    "table" => "a virtual table",
                    "index" => "an index",
                    "trigger" => "a trigger",
                    _ => "a view",
                };
                return Err(corrupt(
                    path,
                    format!(
                        "`{name}` is {what}, not a table: rosbag2 stores its {name} in a \
                         table, and a view can compute rows without end"
                    ),
                ));
            }
            Some(_) => {}
        }
    }
    Ok(())
}

/// Lists the topics with their message counts (one pass over `messages`).
pub(crate) fn catalog(path: &Path, db: &Connection) -> Result<Vec<Topic>, RosError> {
    let err = |e| sql_error(path, e);
    let mut counts: HashMap<i64, u64> = HashMap::new();
    let mut stmt = db
        .prepare("SELECT topic_id, COUNT(*) FROM messages GROUP BY topic_id")
        .map_err(err)?;
    let mut rows = stmt.query([]).map_err(err)?;
    while let Some(row) = rows.next().map_err(err)? {
        let id: i64 = row.get(0).map_err(err)?;
        let n: i64 = row.get(1).map_err(err)?;
        counts.insert(id, u64::try_from(n).unwrap_or(0));
    }
    let mut stmt = db
        .prepare("SELECT id, name, type, serialization_format FROM topics ORDER BY id")
        .map_err(err)?;
    let mut rows = stmt.query([]).map_err(err)?;
    let mut topics = Vec::new();
    while let Some(row) = rows.next().map_err(err)? {
        let id: i64 = row.get(0).map_err(err)?;
        topics.push(Topic {
            id,
            name: row.get(1).map_err(err)?,
            message_type: row.get(2).map_err(err)?,
            encoding: row.get(3).map_err(err)?,
            messages: counts.get(&id).copied().unwrap_or(0),
        });
    }
    Ok(topics)
}

/// Reads the messages of the topic ids in `wanted` (id -> encoding) into `out`, ordered by
/// timestamp (ties by row id).
pub(crate) fn read(
    path: &Path,
    db: &Connection,
    wanted: &HashMap<i64, Encoding>,
    out: &mut Collector<'_>,
) -> Result<(), ReadError> {
    let err = |e| sql_error(path, e);
    // ids come from the database itself (integers): safe to inline
    let ids: Vec<String> = wanted.keys().map(i64::to_string).collect();
    let sql = format!(
        "SELECT topic_id, timestamp, data FROM messages WHERE topic_id IN ({}) \
         ORDER BY timestamp, id",
        ids.join(", ")
    );
    let mut stmt = db.prepare(&sql).map_err(err)?;
    let mut rows = stmt.query([]).map_err(err)?;
    while let Some(row) = rows.next().map_err(err)? {
        let id: i64 = row.get(0).map_err(err)?;
        let t: i64 = row.get(1).map_err(err)?;
        let data = row.get_ref(2).map_err(err)?;
        let bytes = data.as_blob().map_err(|e| err(e.into()))?;
        let encoding = wanted.get(&id).copied().unwrap_or(Encoding::Cdr);
        out.push(encoding, t, bytes)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rosbag2 database of `rows` messages on one topic.
    fn bag(path: &Path, rows: i64) {
        let db = Connection::open(path).unwrap();
        db.execute_batch(
            "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT, type TEXT, \
             serialization_format TEXT, offered_qos_profiles TEXT); \
             INSERT INTO topics VALUES (1, '/imu', 'sensor_msgs/msg/Imu', 'cdr', ''); \
             CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER, \
             timestamp INTEGER, data BLOB); \
             CREATE INDEX timestamp_idx ON messages (timestamp ASC);",
        )
        .unwrap();
        let mut insert = db
            .prepare("INSERT INTO messages(topic_id, timestamp, data) VALUES (1, ?1, x'00')")
            .unwrap();
        for t in 0..rows {
            insert.execute([t]).unwrap();
        }
    }

    #[test]
    fn work_past_the_budget_is_stopped_with_a_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.db3");
        bag(&path, 20_000);
        // the default budget reads it; a budget of one handler call does not
        let db = open(&path).unwrap();
        assert_eq!(catalog(&path, &db).unwrap()[0].messages, 20_000);
        let db = open_within(&path, Some(STEPS_PER_CALL as u64)).unwrap();
        let e = catalog(&path, &db).unwrap_err().to_string();
        assert!(e.contains("more work than a database of its size"), "{e}");
        assert!(!e.contains('\n'));
    }
}
