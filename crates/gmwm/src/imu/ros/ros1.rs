//! ROS1 bag format 2.0 (<http://wiki.ros.org/Bags/Format/2.0>), read record by record
//! ([`StorageFile`]).
//!
//! The file is `#ROSBAG V2.0\n` followed by records: `header_len u32, header, data_len u32,
//! data`, the header being `field_len u32, name=value` fields with an `op` byte. The bag header
//! record (op 0x03) gives `index_pos`; chunks (0x05, compression none/bz2/lz4) hold connection
//! (0x07) and message (0x02) records; after `index_pos` come the connections and one chunk info
//! (0x06, per-connection message counts) per chunk. Topics are listed from that index (or from a
//! scan of the chunks when the bag was never indexed); messages are read by walking the chunks
//! that hold the topic, in file order, each chunk read whole into the file's window and
//! decompressed into one reused buffer; the other chunks' data is not read.

use super::decompress::{Codec, Decompressor};
use super::error::RosError;
use super::file::{Bytes, Memory, StorageFile};
use super::{Collector, Encoding, RosContainer};
use crate::imu::ReadError;
use std::collections::{BTreeMap, HashSet};
use std::path::Path;

/// Magic line of a version 2.0 bag.
pub(crate) const MAGIC: &[u8] = b"#ROSBAG V2.0\n";

const OP_MESSAGE: u8 = 0x02;
const OP_BAG_HEADER: u8 = 0x03;
const OP_CHUNK: u8 = 0x05;
const OP_CHUNK_INFO: u8 = 0x06;
const OP_CONNECTION: u8 = 0x07;

/// One connection (publisher of a topic) of a bag.
#[derive(Debug, Clone)]
pub(crate) struct Connection {
    pub(crate) id: u32,
    pub(crate) topic: String,
    pub(crate) message_type: String,
    pub(crate) messages: u64,
}

/// The bag's connections and which chunks (file positions) hold which connections.
#[derive(Debug)]
pub(crate) struct Catalog {
    pub(crate) connections: Vec<Connection>,
    /// chunk position -> connections with messages in it; `None` for an unindexed bag.
    chunks: Option<Vec<(u64, Vec<u32>)>>,
}

/// Where a record lies, for messages.
#[derive(Clone, Copy)]
enum Origin {
    File,
    /// Inside the chunk record starting at this file byte.
    Chunk(u64),
}

struct Record<'a> {
    op: u8,
    header: &'a [u8],
    data: &'a [u8],
}

fn at(origin: Origin, pos: usize) -> String {
    match origin {
        Origin::File => format!("record at byte {pos}"),
        Origin::Chunk(c) => format!("chunk at byte {c}: record at byte {pos} of the chunk"),
    }
}

fn u32_le(b: &[u8], pos: usize) -> Option<u32> {
    let s = b.get(pos..pos.checked_add(4)?)?;
    Some(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
}

fn u64_le(b: &[u8]) -> Option<u64> {
    let s: [u8; 8] = b.try_into().ok()?;
    Some(u64::from_le_bytes(s))
}

/// The record starting at `pos` of `buf`, and the position after it; its data is read only if
/// `with_data(op)` (else it is empty). Lengths are checked against `buf.end()` before anything is
/// read.
fn record<'b, B: Bytes>(
    path: &Path,
    buf: &'b mut B,
    pos: usize,
    origin: Origin,
    with_data: impl FnOnce(u8) -> bool,
) -> Result<(Record<'b>, usize), ReadError> {
    let end = buf.end();
    let left = end - pos;
    let fail = |reason: String| -> ReadError { corrupt(path, reason).into() };
    if left < 4 {
        return Err(fail(format!(
            "{}: header length needs 4 bytes, {left} remain",
            at(origin, pos)
        )));
    }
    let hlen = u32_le(buf.get(pos, 4)?, 0).unwrap_or(0) as usize;
    let h0 = pos + 4;
    let h1 = h0.checked_add(hlen).filter(|&e| e <= end).ok_or_else(|| {
        fail(format!(
            "{}: header of {hlen} bytes runs past the end ({} bytes remain)",
            at(origin, pos),
            left - 4
        ))
    })?;
    if end - h1 < 4 {
        return Err(fail(format!("{}: data length is cut off", at(origin, pos))));
    }
    let dlen = u32_le(buf.get(h1, 4)?, 0).unwrap_or(0) as usize;
    let d0 = h1 + 4;
    let d1 = d0.checked_add(dlen).filter(|&e| e <= end).ok_or_else(|| {
        fail(format!(
            "{}: data of {dlen} bytes runs past the end ({} bytes remain)",
            at(origin, pos),
            end - d0
        ))
    })?;
    let op = match field(buf.get(h0, hlen)?, b"op")
        .map_err(|e| fail(format!("{}: {e}", at(origin, pos))))?
    {
        Some([op]) => *op,
        Some(v) => {
            return Err(fail(format!(
                "{}: op field has {} bytes, expected 1",
                at(origin, pos),
                v.len()
            )))
        }
        None => return Err(fail(format!("{}: header has no op field", at(origin, pos)))),
    };
    let (header, data): (&[u8], &[u8]) = if with_data(op) {
        let bytes = buf.get(h0, d1 - h0)?;
        (&bytes[..hlen], &bytes[hlen + 4..])
    } else {
        (buf.get(h0, hlen)?, &[])
    };
    Ok((Record { op, header, data }, d1))
}

/// The value of field `name` in a record header (`len u32, name=value` repeated).
fn field<'a>(header: &'a [u8], name: &[u8]) -> Result<Option<&'a [u8]>, String> {
    let mut pos = 0;
    while pos < header.len() {
        let len = u32_le(header, pos).ok_or("header field length is cut off")? as usize;
        let f = header
            .get(pos + 4..)
            .and_then(|h| h.get(..len))
            .ok_or("header field runs past the header")?;
        let eq = f
            .iter()
            .position(|&c| c == b'=')
            .ok_or("header field has no '='")?;
        if &f[..eq] == name {
            return Ok(Some(&f[eq + 1..]));
        }
        pos += 4 + len;
    }
    Ok(None)
}

fn need<'a>(header: &'a [u8], name: &str, what: &str) -> Result<&'a [u8], String> {
    field(header, name.as_bytes())?.ok_or_else(|| format!("{what} has no {name} field"))
}

fn need_u32(header: &[u8], name: &str, what: &str) -> Result<u32, String> {
    let v = need(header, name, what)?;
    v.try_into()
        .map(u32::from_le_bytes)
        .map_err(|_| format!("{what}: field {name} has {} bytes, expected 4", v.len()))
}

fn need_u64(header: &[u8], name: &str, what: &str) -> Result<u64, String> {
    let v = need(header, name, what)?;
    u64_le(v).ok_or_else(|| format!("{what}: field {name} has {} bytes, expected 8", v.len()))
}

/// A connection record: `conn` and `topic` in the header, `type` in the data (header format).
fn connection(rec: &Record<'_>) -> Result<Connection, String> {
    let id = need_u32(rec.header, "conn", "connection record")?;
    let topic = need(rec.header, "topic", "connection record")?;
    let message_type = need(rec.data, "type", "connection record data")?;
    Ok(Connection {
        id,
        topic: String::from_utf8_lossy(topic).into_owned(),
        message_type: String::from_utf8_lossy(message_type).into_owned(),
        messages: 0,
    })
}

/// Receive time of a message record (`time`: sec u32, nsec u32) in ns.
fn time_ns(header: &[u8]) -> Result<i64, String> {
    let t = need(header, "time", "message record")?;
    if t.len() != 8 {
        return Err(format!(
            "message record: field time has {} bytes, expected 8",
            t.len()
        ));
    }
    let sec = u32_le(t, 0).unwrap_or(0);
    let nsec = u32_le(t, 4).unwrap_or(0);
    Ok(i64::from(sec) * 1_000_000_000 + i64::from(nsec))
}

fn corrupt(path: &Path, reason: String) -> RosError {
    RosError::Corrupt {
        path: path.to_path_buf(),
        container: RosContainer::Ros1Bag,
        reason,
    }
}

/// The bag header: (index_pos, conn_count, chunk_count) and the position after it.
fn bag_header(file: &mut StorageFile) -> Result<(u64, u32, u32, usize), ReadError> {
    let path = file.path().to_path_buf();
    let path = path.as_path();
    let n = MAGIC.len().min(file.len());
    if file.get(0, n)? != MAGIC {
        return Err(RosError::NotRecording {
            path: path.to_path_buf(),
            expected: "expected \"#ROSBAG V2.0\" at the start of a ROS1 bag".into(),
        }
        .into());
    }
    let pos = MAGIC.len();
    let (rec, next) = record(path, file, pos, Origin::File, |_| false)?;
    if rec.op != OP_BAG_HEADER {
        return Err(corrupt(
            path,
            format!(
                "{}: expected the bag header (op 0x03), found op 0x{:02x}",
                at(Origin::File, pos),
                rec.op
            ),
        )
        .into());
    }
    let what = "bag header";
    let index_pos = need_u64(rec.header, "index_pos", what).map_err(|e| corrupt(path, e))?;
    let conn_count = need_u32(rec.header, "conn_count", what).map_err(|e| corrupt(path, e))?;
    let chunk_count = need_u32(rec.header, "chunk_count", what).map_err(|e| corrupt(path, e))?;
    Ok((index_pos, conn_count, chunk_count, next))
}

/// Lists the connections with their message counts.
pub(crate) fn catalog(file: &mut StorageFile) -> Result<Catalog, ReadError> {
    let path = file.path().to_path_buf();
    let path = path.as_path();
    let (index_pos, conn_count, chunk_count, first) = bag_header(file)?;
    if index_pos == 0 {
        // never indexed (recording interrupted): count by walking every chunk
        let mut conns: BTreeMap<u32, Connection> = BTreeMap::new();
        let end = file.len();
        walk(path, file, first, end, None, &mut |item| {
            match item {
                Item::Connection(c) => {
                    conns.entry(c.id).or_insert(c);
                }
                Item::Message { conn, .. } => {
                    if let Some(c) = conns.get_mut(&conn) {
                        c.messages += 1;
                    }
                }
            }
            Ok(())
        })?;
        return Ok(Catalog {
            connections: conns.into_values().collect(),
            chunks: None,
        });
    }
    let start = usize::try_from(index_pos)
        .ok()
        .filter(|&p| p >= first && p <= file.len())
        .ok_or_else(|| {
            corrupt(
                path,
                format!(
                    "the bag header puts the index at byte {index_pos}, past the end of the \
                     file ({} bytes): the file is cut short",
                    file.len()
                ),
            )
        })?;
    let mut conns: BTreeMap<u32, Connection> = BTreeMap::new();
    let mut chunks = Vec::new();
    let mut pos = start;
    while pos < file.len() {
        let (rec, next) = record(path, file, pos, Origin::File, |op| {
            op == OP_CONNECTION || op == OP_CHUNK_INFO
        })?;
        match rec.op {
            OP_CONNECTION => {
                let c = connection(&rec)
                    .map_err(|e| corrupt(path, format!("{}: {e}", at(Origin::File, pos))))?;
                conns.entry(c.id).or_insert(c);
            }
            OP_CHUNK_INFO => {
                let what = "chunk info record";
                let chunk_pos =
                    need_u64(rec.header, "chunk_pos", what).map_err(|e| corrupt(path, e))?;
                let count = need_u32(rec.header, "count", what).map_err(|e| corrupt(path, e))?;
                if rec.data.len() as u64 != u64::from(count) * 8 {
                    return Err(corrupt(
                        path,
                        format!(
                            "{}: chunk info lists {count} connections in {} bytes, expected {}",
                            at(Origin::File, pos),
                            rec.data.len(),
                            u64::from(count) * 8
                        ),
                    )
                    .into());
                }
                let mut ids = Vec::with_capacity(count as usize);
                for pair in rec.data.chunks_exact(8) {
                    let id = u32_le(pair, 0).unwrap_or(0);
                    let n = u32_le(pair, 4).unwrap_or(0);
                    ids.push(id);
                    let entry = conns.entry(id).or_insert_with(|| Connection {
                        id,
                        topic: String::new(),
                        message_type: String::new(),
                        messages: 0,
                    });
                    entry.messages += u64::from(n);
                }
                chunks.push((chunk_pos, ids));
            }
            _ => {}
        }
        pos = next;
    }
    let named = conns.values().filter(|c| !c.topic.is_empty()).count();
    if named != conn_count as usize || chunks.len() != chunk_count as usize {
        return Err(corrupt(
            path,
            format!(
                "the index holds {named} connections and {} chunk infos; the bag header \
                 declares {conn_count} and {chunk_count}",
                chunks.len()
            ),
        )
        .into());
    }
    Ok(Catalog {
        connections: conns.into_values().collect(),
        chunks: Some(chunks),
    })
}

/// What a walk over the chunks meets.
enum Item<'a> {
    Connection(Connection),
    Message {
        conn: u32,
        time_ns: i64,
        data: &'a [u8],
    },
}

/// Called with each connection and message of a walk.
type Visitor<'v> = dyn FnMut(Item<'_>) -> Result<(), ReadError> + 'v;

/// Walks the records in `[from, to)` of the file, opening the chunks (all of them, or those at
/// the positions in `only`; the others' data is not read), and hands connections and messages
/// to `visit` in file order.
fn walk(
    path: &Path,
    file: &mut StorageFile,
    from: usize,
    to: usize,
    only: Option<&HashSet<u64>>,
    visit: &mut Visitor<'_>,
) -> Result<(), ReadError> {
    let mut region = file.region(to);
    let end = region.end();
    let mut dec = Decompressor::new();
    let mut buf = Vec::new();
    let mut pos = from;
    while pos < end {
        let open = |p: usize| only.map_or(true, |o| o.contains(&(p as u64)));
        let (rec, next) = record(path, &mut region, pos, Origin::File, |op| match op {
            OP_CHUNK => open(pos),
            OP_CONNECTION | OP_MESSAGE => true,
            _ => false,
        })?;
        match rec.op {
            OP_CHUNK if open(pos) => {
                let fail = |e: String| corrupt(path, format!("{}: {e}", at(Origin::File, pos)));
                let what = "chunk record";
                let compression = need(rec.header, "compression", what).map_err(fail)?;
                let size = need_u32(rec.header, "size", what).map_err(fail)? as usize;
                let codec = match compression {
                    b"none" => None,
                    b"lz4" => Some(Codec::Lz4),
                    b"bz2" => Some(Codec::Bz2),
                    other => {
                        return Err(RosError::UnsupportedCompression {
                            path: path.to_path_buf(),
                            what: format!(
                                "ROS1 chunk compression \"{}\"",
                                String::from_utf8_lossy(other)
                            ),
                            hint: "supported: none, lz4, bz2",
                        }
                        .into())
                    }
                };
                let inner: &[u8] = match codec {
                    None => {
                        if rec.data.len() != size {
                            return Err(corrupt(
                                path,
                                format!(
                                    "{}: uncompressed chunk holds {} bytes, its header says {size}",
                                    at(Origin::File, pos),
                                    rec.data.len()
                                ),
                            )
                            .into());
                        }
                        rec.data
                    }
                    Some(codec) => {
                        dec.decompress(codec, rec.data, size, &mut buf)
                            .map_err(fail)?;
                        &buf
                    }
                };
                walk_chunk(path, inner, pos as u64, visit)?;
            }
            OP_CONNECTION => {
                let c = connection(&rec)
                    .map_err(|e| corrupt(path, format!("{}: {e}", at(Origin::File, pos))))?;
                visit(Item::Connection(c))?;
            }
            OP_MESSAGE => message(path, &rec, Origin::File, pos, visit)?,
            _ => {}
        }
        pos = next;
    }
    Ok(())
}

fn walk_chunk(
    path: &Path,
    chunk: &[u8],
    chunk_pos: u64,
    visit: &mut Visitor<'_>,
) -> Result<(), ReadError> {
    let origin = Origin::Chunk(chunk_pos);
    let mut chunk = Memory(chunk);
    let mut pos = 0;
    while pos < chunk.end() {
        let (rec, next) = record(path, &mut chunk, pos, origin, |_| true)?;
        match rec.op {
            OP_MESSAGE => message(path, &rec, origin, pos, visit)?,
            OP_CONNECTION => {
                let c = connection(&rec)
                    .map_err(|e| corrupt(path, format!("{}: {e}", at(origin, pos))))?;
                visit(Item::Connection(c))?;
            }
            _ => {}
        }
        pos = next;
    }
    Ok(())
}

fn message(
    path: &Path,
    rec: &Record<'_>,
    origin: Origin,
    pos: usize,
    visit: &mut Visitor<'_>,
) -> Result<(), ReadError> {
    let conn = need_u32(rec.header, "conn", "message record")
        .map_err(|e| corrupt(path, format!("{}: {e}", at(origin, pos))))?;
    let time_ns =
        time_ns(rec.header).map_err(|e| corrupt(path, format!("{}: {e}", at(origin, pos))))?;
    visit(Item::Message {
        conn,
        time_ns,
        data: rec.data,
    })
}

/// Reads the messages of the connections `wanted` into `out`, in file order.
pub(crate) fn read(
    file: &mut StorageFile,
    catalog: &Catalog,
    wanted: &HashSet<u32>,
    out: &mut Collector<'_>,
) -> Result<(), ReadError> {
    let path = file.path().to_path_buf();
    let (index_pos, _, _, first) = bag_header(file)?;
    let to = match index_pos {
        0 => file.len(),
        p => usize::try_from(p).unwrap_or(file.len()).min(file.len()),
    };
    let only: Option<HashSet<u64>> = catalog.chunks.as_ref().map(|chunks| {
        chunks
            .iter()
            .filter(|(_, ids)| ids.iter().any(|id| wanted.contains(id)))
            .map(|(p, _)| *p)
            .collect()
    });
    walk(
        &path,
        file,
        first,
        to,
        only.as_ref(),
        &mut |item| match item {
            Item::Message {
                conn,
                time_ns,
                data,
            } if wanted.contains(&conn) => Ok(out.push(Encoding::Ros1, time_ns, data)?),
            _ => Ok(()),
        },
    )
}
